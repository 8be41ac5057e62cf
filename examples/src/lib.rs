//! The examples of symnlp as a library: each module is one example (its model, its
//! problem and its `main`), run by the binary of the same name in `examples/examples/`
//! (`cargo run --release -p symnlp-examples --example <name>`) and imported by the
//! workspace's tests and benches (`symnlp_examples::mpc_cart_pole::example()`).
pub mod cart_pole;
pub mod goddard_rocket;
pub mod integrator_compare;
pub mod mpc_car;
pub mod mpc_cart_pole;
pub mod mpc_common;
pub mod mpc_quadrotor;
pub mod quadrotor;
pub mod race_car;
pub mod race_car_ocp;
pub mod two_link_arm;
pub mod vdp_collocation;
pub mod vdp_multiple_shooting;
