//! Hash-consing (symx/src/consing.rs): nodes are filed under their newest operand in short
//! lists, overflowing into a hash table. Whichever place holds a node, building the same
//! expression again must return the same node and add none, and different expressions
//! must stay different nodes (checked by evaluating them against plain f64 arithmetic).
use proptest::prelude::*;
use symx::{node_count, with_fresh_arena, Expr, Function, Matrix};

/// One operand shared by far more nodes than a list holds (its list overflows into the
/// table), and nodes anchored on those nodes in turn.
#[test]
fn a_popular_operand_keeps_every_node_unique() {
    with_fresh_arena(|| {
        // x is made after the z's, so it is the newest operand of x·z_k and x + z_k.
        let z = Matrix::sym_vec("z", 300);
        let (x, y) = (Expr::sym("x"), Expr::sym("y"));
        let build = || -> Vec<Expr> {
            let mut e = Vec::new();
            for k in 0..300 {
                let p = x * z[k]; // anchored on x
                e.push(p);
                e.push(p.sin()); // anchored on p
                e.push(p + y); // anchored on p (newer than y)
                e.push(x + z[k]); // anchored on x
            }
            e.extend([x.sin(), x.cos(), x.exp(), x * y, x - y, y - x, x / y]);
            e
        };
        let first = build();
        let nodes = node_count();
        let again = build();
        assert_eq!(node_count(), nodes, "rebuilding created nodes");
        let ids = |v: &[Expr]| v.iter().map(|e| e.id()).collect::<Vec<_>>();
        assert_eq!(ids(&first), ids(&again));
        let mut unique = ids(&first);
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), first.len(), "distinct expressions merged");
        // Values: every entry is what its formula says.
        let f = Function::new(&[&[x, y], &z], &[&first]).unwrap();
        let (xv, yv) = (0.3, -1.7);
        let zv: Vec<f64> = (0..300).map(|k| 2.0 + k as f64).collect();
        let out = f.call(&[&[xv, yv], &zv]).unwrap().remove(0);
        for (k, &c) in zv.iter().enumerate() {
            let p = xv * c;
            assert_eq!(out[4 * k..4 * k + 4], [p, p.sin(), p + yv, xv + c]);
        }
    });
}

/// A random straight-line program over two symbols: each step applies an operation to
/// earlier values (indices taken modulo the number of values so far).
fn program() -> impl Strategy<Value = Vec<(u8, usize, usize)>> {
    prop::collection::vec((0u8..6, any::<usize>(), any::<usize>()), 1..120)
}

fn run_symbolic(prog: &[(u8, usize, usize)], v: &mut Vec<Expr>) {
    for &(op, i, j) in prog {
        let (a, b) = (v[i % v.len()], v[j % v.len()]);
        v.push(match op {
            0 => a + b,
            1 => a * b,
            2 => a - b,
            3 => a.sin(),
            4 => a * 0.5 + 1.0,
            _ => (a * b).cos(),
        });
    }
}

fn run_numeric(prog: &[(u8, usize, usize)], v: &mut Vec<f64>) {
    for &(op, i, j) in prog {
        let (a, b) = (v[i % v.len()], v[j % v.len()]);
        v.push(match op {
            0 => a + b,
            1 => a * b,
            2 => a - b,
            3 => a.sin(),
            4 => a * 0.5 + 1.0,
            _ => (a * b).cos(),
        });
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// Replaying a program returns the same nodes and creates none; the compiled values
    /// match plain arithmetic (to rounding: the simplifier may reorder, e.g. `x − x = 0`).
    #[test]
    fn replaying_a_program_adds_no_nodes(prog in program()) {
        with_fresh_arena(|| -> Result<(), TestCaseError> {
            let (x, y) = (Expr::sym("x"), Expr::sym("y"));
            let mut first = vec![x, y];
            run_symbolic(&prog, &mut first);
            let nodes = node_count();
            let mut again = vec![x, y];
            run_symbolic(&prog, &mut again);
            prop_assert_eq!(node_count(), nodes);
            prop_assert_eq!(
                first.iter().map(|e| e.id()).collect::<Vec<_>>(),
                again.iter().map(|e| e.id()).collect::<Vec<_>>()
            );
            let f = Function::new(&[&[x, y]], &[&first]).unwrap();
            let out = f.call(&[&[0.7, -0.4]]).unwrap().remove(0);
            let mut num = vec![0.7, -0.4];
            run_numeric(&prog, &mut num);
            for (k, (s, n)) in out.iter().zip(&num).enumerate() {
                let scale = 1.0 + n.abs();
                // Relative 1e-9: a few roundings of reassociated sums and products.
                prop_assert!((s - n).abs() <= 1e-9 * scale || (s.is_nan() && n.is_nan()),
                    "value {}: compiled {} vs arithmetic {}", k, s, n);
            }
            Ok(())
        })?;
    }
}
