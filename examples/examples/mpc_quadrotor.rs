//! Runs [`symnlp_examples::mpc_quadrotor`]: `cargo run --release -p symnlp-examples --example mpc_quadrotor`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::mpc_quadrotor::main()
}
