//! Runs [`symnlp_examples::cart_pole`]: `cargo run --release -p symnlp-examples --example cart_pole`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::cart_pole::main()
}
