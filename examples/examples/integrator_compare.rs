//! Runs [`symnlp_examples::integrator_compare`]: `cargo run --release -p symnlp-examples --example integrator_compare`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::integrator_compare::main()
}
