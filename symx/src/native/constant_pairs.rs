//! The pool of constant pairs of one machine-code function: the constant `f64x2` operands
//! of its SIMD instructions ([`super::lanes`]), each distinct pair stored once, 16 bytes
//! apiece, and loaded from there.
//!
//! Cranelift materialises a `vconst` in a register (one `movupd` from its own constant
//! pool) before the instruction using it, but folds a single-use `load` into the
//! instruction as a memory operand (with AVX, which accepts unaligned operands): a
//! constant pair loaded from this pool costs no instruction of its own. On the gap model's
//! ∇f, 1 074 of the 3 816 instructions per call were such constant loads.
use super::lanes::{Operand, Step};
use rustc_hash::FxHashMap;

/// One pair in the pool: 16-byte aligned, so that the load may carry Cranelift's
/// `aligned` flag and fold into SSE instructions too, which need aligned memory operands.
#[repr(C, align(16))]
pub(super) struct Pair(pub [u64; 2]);

/// Where each constant pair of a machine-code function lies in its pool.
#[derive(Default)]
pub(super) struct ConstantPairs {
    offsets: FxHashMap<[u64; 2], i32>,
}

impl ConstantPairs {
    /// The pairs of constants (`constant[r]`, both lanes constant) among the operands of
    /// `steps`, and the pool holding them: the pool must stay alive (and unmoved: its heap
    /// buffer does not move with the `Vec`) as long as the machine code reading it.
    pub(super) fn of(steps: &[Step], constant: &[Option<f64>]) -> (Self, Vec<Pair>) {
        let mut pairs = ConstantPairs::default();
        let mut pool = Vec::new();
        let operands = steps.iter().flat_map(|s| match s {
            Step::Pair { operands, .. } => operands.as_slice(),
            Step::Single(_) => &[],
        });
        for &op in operands.flatten() {
            if let Operand::External(r1, r2) = op {
                if let (Some(x), Some(y)) = (constant[r1 as usize], constant[r2 as usize]) {
                    let bits = [x.to_bits(), y.to_bits()];
                    pairs.offsets.entry(bits).or_insert_with(|| {
                        pool.push(Pair(bits));
                        16 * (pool.len() as i32 - 1)
                    });
                }
            }
        }
        (pairs, pool)
    }

    /// The byte offset in the pool of the pair `(x, y)`, if the pool holds it.
    pub(super) fn offset(&self, x: f64, y: f64) -> Option<i32> {
        self.offsets.get(&[x.to_bits(), y.to_bits()]).copied()
    }
}
