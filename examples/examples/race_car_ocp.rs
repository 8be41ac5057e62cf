//! Runs [`symnlp_examples::race_car_ocp`]: `cargo run --release -p symnlp-examples --example race_car_ocp`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::race_car_ocp::main()
}
