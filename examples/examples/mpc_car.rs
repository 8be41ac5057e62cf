//! Runs [`symnlp_examples::mpc_car`]: `cargo run --release -p symnlp-examples --example mpc_car`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::mpc_car::main()
}
