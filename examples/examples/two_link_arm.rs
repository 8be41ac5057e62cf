//! Runs [`symnlp_examples::two_link_arm`]: `cargo run --release -p symnlp-examples --example two_link_arm`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::two_link_arm::main()
}
