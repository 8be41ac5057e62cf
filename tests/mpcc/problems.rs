//! MPCC test problems: (name, source, builder, published f*, known failures per back end).
use symnlp::nlp;

use nlp::{MpccBackend, Problem, Relation};

pub struct Case {
    pub name: &'static str,
    /// Where the formulation and f* come from.
    pub source: &'static str,
    pub build: fn() -> Problem,
    pub f_star: f64,
    /// Back ends that do not solve it yet, with the reason (asserted as failures).
    pub known_failures: &'static [(MpccBackend, &'static str)],
}

fn scalars(pb: &mut Problem, names: &[&str]) -> Vec<symx::Expr> {
    names.iter().map(|n| pb.scalar_variable(n)).collect()
}

/// min (x−1)² + (y−1)²  s.t. 0 ≤ x ⊥ y ≥ 0, from (1, 0.5): f* = 1 at (1, 0) (by hand: on
/// each half-axis the minimum is 1).
pub fn two_branches() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x", "y"]);
        pb.set_initial(&v, &[1.0, 0.5]).unwrap();
        pb.minimize((v[0] - 1.0).sq() + (v[1] - 1.0).sq());
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "two_branches",
        source: "by hand",
        build,
        f_star: 1.0,
        known_failures: &[],
    }
}

/// min x + y  s.t. x + y ≥ 1, 0 ≤ x ⊥ y ≥ 0, from (0.7, 0.6): f* = 1 (by hand). The
/// linearised product is inconsistent with x + y ≥ 1 at the start (elastic mode).
pub fn linear_objective() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x", "y"]);
        pb.set_initial(&v, &[0.7, 0.6]).unwrap();
        pb.minimize(v[0] + v[1]);
        pb.subject_to((v[0] + v[1]).ge(1.0)).unwrap();
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "linear_objective",
        source: "by hand",
        build,
        f_star: 1.0,
        known_failures: &[],
    }
}

/// MacMPEC bard1 (Bard 1988, bilevel problem with its lower level replaced by its KKT
/// conditions): min (x−5)² + (2y+1)²  s.t.  2(y−1) − 1.5x + l₁ − 0.5l₂ + l₃ = 0,
/// 0 ≤ l₁ ⊥ 3x − y − 3 ≥ 0, 0 ≤ l₂ ⊥ −x + 0.5y + 4 ≥ 0, 0 ≤ l₃ ⊥ −x − y + 7 ≥ 0,
/// x, y ≥ 0. MacMPEC f* = 17 at (x, y) = (1, 0).
pub fn bard1() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x", "y", "l1", "l2", "l3"]);
        let (x, y) = (v[0], v[1]);
        pb.set_bounds(&v, 0.0, f64::INFINITY).unwrap();
        pb.minimize((x - 5.0).sq() + (2.0 * y + 1.0).sq());
        pb.subject_to((2.0 * (y - 1.0) - 1.5 * x + v[2] - 0.5 * v[3] + v[4]).eq(0.0))
            .unwrap();
        pb.complementarity("c1", v[2], 3.0 * x - y - 3.0).unwrap();
        pb.complementarity("c2", v[3], -x + 0.5 * y + 4.0).unwrap();
        pb.complementarity("c3", v[4], -x - y + 7.0).unwrap();
        pb
    }
    Case {
        name: "bard1",
        source: "MacMPEC bard1, f* = 17",
        build,
        f_star: 17.0,
        known_failures: &[],
    }
}

/// MacMPEC ralph1 (Ralph): min 2x − y  s.t. 0 ≤ y ⊥ y − x ≥ 0, x ≥ 0. f* = 0 at the
/// origin (on the branch y = x, f = x ≥ 0; on y = 0, x = 0).
pub fn ralph1() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x", "y"]);
        pb.set_bounds(&v[..1], 0.0, f64::INFINITY).unwrap();
        pb.set_initial(&v, &[1.0, 1.0]).unwrap();
        pb.minimize(2.0 * v[0] - v[1]);
        pb.complementarity("c", v[1], v[1] - v[0]).unwrap();
        pb
    }
    Case {
        name: "ralph1",
        source: "MacMPEC ralph1, f* = 0",
        build,
        f_star: 0.0,
        known_failures: &[],
    }
}

/// MacMPEC ralph2: min x² + y² − 4xy  s.t. 0 ≤ x ⊥ y ≥ 0. f* = 0 at the origin (the
/// objective is x² or y² on the branches).
pub fn ralph2() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x", "y"]);
        pb.set_initial(&v, &[1.0, 1.0]).unwrap();
        pb.minimize(v[0].sq() + v[1].sq() - 4.0 * v[0] * v[1]);
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "ralph2",
        source: "MacMPEC ralph2, f* = 0",
        build,
        f_star: 0.0,
        known_failures: &[],
    }
}

/// MacMPEC scholtes3 (Scholtes): min ½((x−1)² + (y−1)²)  s.t. 0 ≤ x ⊥ y ≥ 0. f* = 0.5
/// at (1, 0) or (0, 1).
pub fn scholtes3() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x", "y"]);
        pb.set_initial(&v, &[0.0, 0.0]).unwrap();
        pb.minimize(0.5 * ((v[0] - 1.0).sq() + (v[1] - 1.0).sq()));
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "scholtes3",
        source: "MacMPEC scholtes3, f* = 0.5",
        build,
        f_star: 0.5,
        known_failures: &[],
    }
}

/// MacMPEC jr1 (Jiang & Ralph): min (z₂−1)² + z₁²  s.t. 0 ≤ z₂ ⊥ z₂ − z₁ ≥ 0. f* = 0.5 at
/// z = (0.5, 0.5) (branch z₂ = z₁; the branch z₂ = 0 costs ≥ 1).
pub fn jr1() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["z1", "z2"]);
        pb.minimize((v[1] - 1.0).sq() + v[0].sq());
        pb.complementarity("c", v[1], v[1] - v[0]).unwrap();
        pb
    }
    Case {
        name: "jr1",
        source: "MacMPEC jr1, f* = 0.5",
        build,
        f_star: 0.5,
        known_failures: &[],
    }
}

/// Ten separable pairs (by hand): min Σᵢ (xᵢ − 2)² + (yᵢ − bᵢ)², 0 ≤ xᵢ ⊥ yᵢ ≥ 0,
/// bᵢ = 1 + i/10, from xᵢ = yᵢ = 1. Each pair's best branch is yᵢ = 0 (cost bᵢ² < 4),
/// so f* = Σ bᵢ² = 21.85.
pub fn lcp_chain() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let x = pb.variable("x", 10);
        let y = pb.variable("y", 10);
        let xs: Vec<_> = x.iter().copied().collect();
        let ys: Vec<_> = y.iter().copied().collect();
        pb.set_initial(&xs, &[1.0; 10]).unwrap();
        pb.set_initial(&ys, &[1.0; 10]).unwrap();
        let mut f = symx::Expr::from(0.0);
        for i in 0..10 {
            let b = 1.0 + i as f64 / 10.0;
            f += (xs[i] - 2.0).sq() + (ys[i] - b).sq();
            pb.complementarity(&format!("c{i}"), xs[i], ys[i]).unwrap();
        }
        pb.minimize(f);
        pb
    }
    Case {
        name: "lcp_chain",
        source: "by hand, f* = 21.85",
        build,
        f_star: 21.85,
        known_failures: &[],
    }
}
