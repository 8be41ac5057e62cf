//! Runs [`symnlp_examples::goddard_rocket`]: `cargo run --release -p symnlp-examples --example goddard_rocket`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::goddard_rocket::main()
}
