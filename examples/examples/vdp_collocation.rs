//! Runs [`symnlp_examples::vdp_collocation`]: `cargo run --release -p symnlp-examples --example vdp_collocation`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    symnlp_examples::vdp_collocation::main()
}
