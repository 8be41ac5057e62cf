//! Runs [`symnlp_examples::vdp_multiple_shooting`]: `cargo run --release -p symnlp-examples --example vdp_multiple_shooting`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::vdp_multiple_shooting::main()
}
