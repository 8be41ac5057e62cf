//! Floating-point operands and comparisons shared by the tests that check a native
//! evaluator (the JIT, generated C, generated Rust) against symx's tape.

/// Operands covering signs, zeros of both signs, integers (pow's fast path), large and
/// subnormal values, infinities and NaN.
pub const SPECIAL: [f64; 14] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    0.5,
    -2.5,
    3.0,
    1e300,
    -1e-310,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NAN,
    std::f64::consts::FRAC_PI_4,
    64.0,
];

/// The same bits, or both NaN: the comparison for generated source, where the compiler may
/// swap the operands of a commutative operation and x86 returns the first operand's NaN
/// (so a NaN's sign and payload may differ from the tape's).
pub fn same_or_both_nan(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}
