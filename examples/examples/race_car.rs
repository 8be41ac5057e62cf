//! Runs [`symnlp_examples::race_car`]: `cargo run --release -p symnlp-examples --example race_car`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::race_car::main()
}
