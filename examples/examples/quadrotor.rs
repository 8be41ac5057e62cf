//! Runs [`symnlp_examples::quadrotor`]: `cargo run --release -p symnlp-examples --example quadrotor`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::quadrotor::main()
}
