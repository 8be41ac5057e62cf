//! Runs [`symnlp_examples::mpc_cart_pole`]: `cargo run --release -p symnlp-examples --example mpc_cart_pole`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::mpc_cart_pole::main()
}
