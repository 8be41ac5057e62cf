//! MPCC test problems: (name, source, builder, published f*, known failures per back end).

use nlp::{MpccBackend, Problem, Relation};

/// Calls macro `$then!` with every case name, in order: the one list of cases, shared
/// by [`ALL`] and `nlp/tests/mpcc.rs` (one `#[test]` per case and back end).
#[macro_export]
macro_rules! mpcc_names {
    ($then:ident) => {
        $then! {
            two_branches, linear_objective, bard1, ralph1, ralph2, scholtes3, jr2, kth1, kth2,
            kth3, scholtes5, nash1, dempe, desilva, gauvin, qpec2, scale1, fl_ex1, fl_ex2,
            lcp_chain, outrata31,
        }
    };
}

macro_rules! mpcc_all {
    ($($name:ident),* $(,)?) => {
        /// Every case, in order.
        pub const ALL: &[fn() -> Case] = &[$($name),*];
    };
}
mpcc_names!(mpcc_all);

pub struct Case {
    pub name: &'static str,
    /// Where the formulation and f* come from.
    pub source: &'static str,
    pub build: fn() -> Problem,
    pub f_star: f64,
    /// Relative tolerance on f* (1e-6 unless the published value has fewer digits).
    pub f_tol: f64,
    /// Back ends that do not solve it yet, with the reason (asserted as failures).
    pub known_failures: &'static [(MpccBackend, &'static str)],
}

fn scalars(pb: &mut Problem, names: &[&str]) -> Vec<symx::Expr> {
    names
        .iter()
        .map(|n| pb.scalar_variable(n).unwrap())
        .collect()
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
        f_tol: 1e-6,
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
        f_tol: 1e-6,
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
        f_tol: 1e-6,
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
        f_tol: 1e-6,
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
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC scholtes3 (Scholtes): min ½((x−1)² + (y−1)²)  s.t. 0 ≤ x ⊥ y ≥ 0. f* = 0.5
/// at (1, 0) or (0, 1); the .mod's start (1e-4, 1e-4), close to the biactive origin.
pub fn scholtes3() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x", "y"]);
        pb.set_initial(&v, &[1e-4, 1e-4]).unwrap();
        pb.minimize(0.5 * ((v[0] - 1.0).sq() + (v[1] - 1.0).sq()));
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "scholtes3",
        source: "MacMPEC scholtes3, f* = 0.5",
        build,
        f_star: 0.5,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC jr2 (QPEC from ideas by Jiang & Ralph): min (z₂−1)² + z₁²  s.t. z₂ ≥ 0,
/// 0 ≤ z₂ ⊥ z₂ − z₁ ≥ 0. f* = 0.5 at z = (0.5, 0.5) (by hand: branch z₂ = z₁; the branch
/// z₂ = 0 costs ≥ 1).
pub fn jr2() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["z1", "z2"]);
        pb.minimize((v[1] - 1.0).sq() + v[0].sq());
        pb.complementarity("c", v[1], v[1] - v[0]).unwrap();
        pb
    }
    Case {
        name: "jr2",
        source: "MacMPEC jr2, f* = 0.5",
        build,
        f_star: 0.5,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC kth1: min z₁ + z₂, z ≥ 0, 0 ≤ z₁ ⊥ z₂ ≥ 0, from (0, 1). f* = 0.
pub fn kth1() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["z1", "z2"]);
        pb.set_initial(&v, &[0.0, 1.0]).unwrap();
        pb.minimize(v[0] + v[1]);
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "kth1",
        source: "MacMPEC kth1, f* = 0",
        build,
        f_star: 0.0,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC kth2: min z₁ + (z₂−1)², 0 ≤ z₁ ⊥ z₂ ≥ 0, from (1, 0). f* = 0 at (0, 1).
pub fn kth2() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["z1", "z2"]);
        pb.set_initial(&v, &[1.0, 0.0]).unwrap();
        pb.minimize(v[0] + (v[1] - 1.0).sq());
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "kth2",
        source: "MacMPEC kth2, f* = 0",
        build,
        f_star: 0.0,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC kth3: min ½(z₁−1)² + (z₂−1)², 0 ≤ z₁ ⊥ z₂ ≥ 0, from (1, 1). f* = 0.5 at (0, 1).
pub fn kth3() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["z1", "z2"]);
        pb.set_initial(&v, &[1.0, 1.0]).unwrap();
        pb.minimize(0.5 * (v[0] - 1.0).sq() + (v[1] - 1.0).sq());
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "kth3",
        source: "MacMPEC kth3, f* = 0.5",
        build,
        f_star: 0.5,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC scholtes5 (Scholtes, SIAM J. Optim. 11(4), 2001): min (z₁−1)² + (z₂−2)² +
/// (z₃+1)², z ≥ 0, 0 ≤ z₁ ⊥ z₃ ≥ 0, 0 ≤ z₂ ⊥ z₃ ≥ 0, from z = 1. f* = 1 at (1, 2, 0).
pub fn scholtes5() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["z1", "z2", "z3"]);
        pb.set_initial(&v, &[1.0, 1.0, 1.0]).unwrap();
        pb.minimize((v[0] - 1.0).sq() + (v[1] - 2.0).sq() + (v[2] + 1.0).sq());
        pb.complementarity("c1", v[0], v[2]).unwrap();
        pb.complementarity("c2", v[1], v[2]).unwrap();
        pb
    }
    Case {
        name: "scholtes5",
        source: "MacMPEC scholtes5, f* = 1",
        build,
        f_star: 1.0,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC nash1 (Facchinei, Jiang & Qi, problem 9): min ½‖x − y‖², 0 ≤ x ≤ 10,
/// −34 + 2y₁ + (8/3)y₂ + l₁ = 0, −24.25 + 1.25y₁ + 2y₂ + l₂ = 0,
/// 0 ≤ 15 − x₂ − y₁ ⊥ l₁ ≥ 0, 0 ≤ 15 − x₁ − y₂ ⊥ l₂ ≥ 0, from 0. f* = 0 (by hand:
/// x = y = (5, 9), l = 0).
pub fn nash1() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x1", "x2", "y1", "y2", "l1", "l2"]);
        let (x1, x2, y1, y2, l1, l2) = (v[0], v[1], v[2], v[3], v[4], v[5]);
        pb.set_bounds(&v[..2], 0.0, 10.0).unwrap();
        pb.set_bounds(&v[4..], 0.0, f64::INFINITY).unwrap();
        pb.minimize(0.5 * ((x1 - y1).sq() + (x2 - y2).sq()));
        pb.subject_to((-34.0 + 2.0 * y1 + (8.0 / 3.0) * y2 + l1).eq(0.0))
            .unwrap();
        pb.subject_to((-24.25 + 1.25 * y1 + 2.0 * y2 + l2).eq(0.0))
            .unwrap();
        pb.complementarity("g1", 15.0 - x2 - y1, l1).unwrap();
        pb.complementarity("g2", 15.0 - x1 - y2, l2).unwrap();
        pb
    }
    Case {
        name: "nash1",
        source: "MacMPEC nash1, f* = 0",
        build,
        f_star: 0.0,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// Ten separable pairs (by hand): min Σᵢ (xᵢ − 2)² + (yᵢ − bᵢ)², 0 ≤ xᵢ ⊥ yᵢ ≥ 0,
/// bᵢ = 1 + i/10, from xᵢ = yᵢ = 1. Each pair's best branch is yᵢ = 0 (cost bᵢ² < 4),
/// so f* = Σ bᵢ² = 21.85.
pub fn lcp_chain() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let x = pb.variable("x", 10).unwrap();
        let y = pb.variable("y", 10).unwrap();
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
        f_tol: 1e-6,
        known_failures: &[],
    }
}

// The following MacMPEC formulations and f* were checked against the JuMP transcription
// of MacMPEC in MathOptInterface's complementarity test instances (from Leyffer's .mod
// files; f* from the MacMPEC table) and re-derived by hand where noted.

/// MacMPEC dempe (Dempe 1992; Luo, Pang & Ralph 1997, p. 354): min (x−3.5)² + (z+4)²
/// s.t. z − 3 + 2zw = 0, 0 ≤ x − z² ⊥ w ≥ 0, from (0.183193, 0.428106, 3.00379).
/// MacMPEC f* = 28.25. By hand: on the branch x = z², z = 3/(1+2w) ∈ (0, 3] and
/// f(z) = (z²−3.5)² + (z+4)² has f' = 4(z−1)²(z+2) ≥ 0, so 28.25 is an infimum (z → 0,
/// w → ∞), not attained.
pub fn dempe() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x", "z", "w"]);
        let (x, z, w) = (v[0], v[1], v[2]);
        pb.set_initial(&v, &[0.183193, 0.428106, 3.00379]).unwrap();
        pb.minimize((x - 3.5).sq() + (z + 4.0).sq());
        pb.subject_to((z - 3.0 + 2.0 * z * w).eq(0.0)).unwrap();
        pb.complementarity("c", x - z.sq(), w).unwrap();
        pb
    }
    Case {
        name: "dempe",
        source: "MacMPEC dempe, f* = 28.25 (infimum)",
        build,
        f_star: 28.25,
        f_tol: 1e-6,
        // The SQP reaches f = 28.25000008 at the acceptable level since the active-set
        // QP (issue 19; before: 28.25036 after 3034 iterations, 28.348 earlier still).
        // The IPM was a known failure (final phase at f = 28.25026 … 28.25036) until
        // `residual_ratio_floor` = 1e-13 (session 18): 107 iterations, f = 28.2500153,
        // within f_tol of the infimum (w grows without bound either way).
        known_failures: &[],
    }
}

/// MacMPEC desilva (Facchinei, Jiang & Qi, problem 5): min x₁² − 2x₁ + x₂² − 2x₂ + y₁² + y₂²
/// s.t. 0 ≤ x ≤ 2, 2yᵢ − 2xᵢ + 2(yᵢ−1)lᵢ = 0, 0 ≤ 0.25 − (yᵢ−1)² ⊥ lᵢ ≥ 0. f* = −1
/// (x = y = 0.5).
pub fn desilva() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x1", "x2", "y1", "y2", "l1", "l2"]);
        pb.set_bounds(&v[..2], 0.0, 2.0).unwrap();
        pb.set_bounds(&v[4..], 0.0, f64::INFINITY).unwrap();
        pb.minimize(v[0].sq() - 2.0 * v[0] + v[1].sq() - 2.0 * v[1] + v[2].sq() + v[3].sq());
        for i in 0..2 {
            let (x, y, l) = (v[i], v[2 + i], v[4 + i]);
            pb.subject_to((2.0 * y - 2.0 * x + 2.0 * (y - 1.0) * l).eq(0.0))
                .unwrap();
            pb.complementarity(&format!("c{i}"), 0.25 - (y - 1.0).sq(), l)
                .unwrap();
        }
        pb
    }
    Case {
        name: "desilva",
        source: "MacMPEC desilva, f* = -1",
        build,
        f_star: -1.0,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC gauvin (Gauvin & Savard 1992, via MPECLIB): min x² + (y−10)², 0 ≤ x ≤ 15,
/// y, u ≥ 0, 0 ≤ 4(x + 2y − 30) + u ⊥ y ≥ 0, 0 ≤ 20 − x − y ⊥ u ≥ 0, from x = 7.5,
/// u = 1. MacMPEC f* = 20.
pub fn gauvin() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x", "y", "u"]);
        let (x, y, u) = (v[0], v[1], v[2]);
        pb.set_bounds(&v[..1], 0.0, 15.0).unwrap();
        pb.set_bounds(&v[1..], 0.0, f64::INFINITY).unwrap();
        pb.set_initial(&v, &[7.5, 0.0, 1.0]).unwrap();
        pb.minimize(x.sq() + (y - 10.0).sq());
        pb.complementarity("c1", 4.0 * (x + 2.0 * y - 30.0) + u, y)
            .unwrap();
        pb.complementarity("c2", 20.0 - x - y, u).unwrap();
        pb
    }
    Case {
        name: "gauvin",
        source: "MacMPEC gauvin, f* = 20",
        build,
        f_star: 20.0,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC qpec2 (Jiang & Ralph 1997), n = 10, m = 20: min Σ(xᵢ−1)² + Σ(yⱼ−2)², y ≥ 0,
/// yᵢ − xᵢ ≥ 0 ⊥ yᵢ (i ≤ n), yⱼ ⊥ yⱼ (j > n, i.e. yⱼ = 0), from x = y = 1. f* = 45
/// (by hand: 10 × 0.5 on the branch yᵢ = xᵢ = 1.5, plus 10 × 4).
pub fn qpec2() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let x: Vec<_> = pb.variable("x", 10).unwrap().iter().copied().collect();
        let y: Vec<_> = pb.variable("y", 20).unwrap().iter().copied().collect();
        pb.set_bounds(&y, 0.0, f64::INFINITY).unwrap();
        pb.set_initial(&x, &[1.0; 10]).unwrap();
        pb.set_initial(&y, &[1.0; 20]).unwrap();
        let mut f = symx::Expr::from(0.0);
        for xi in &x {
            f += (*xi - 1.0).sq();
        }
        for yj in &y {
            f += (*yj - 2.0).sq();
        }
        pb.minimize(f);
        for i in 0..10 {
            pb.complementarity(&format!("c{i}"), y[i] - x[i], y[i])
                .unwrap();
        }
        for (j, yj) in y.iter().enumerate().skip(10) {
            pb.complementarity(&format!("d{j}"), *yj, *yj).unwrap();
        }
        pb
    }
    Case {
        name: "qpec2",
        source: "MacMPEC qpec2, f* = 45",
        build,
        f_star: 45.0,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// MacMPEC scale1: min (100x₁ − 1)² + (x₂ − 1)², 0 ≤ x₁ ⊥ x₂ ≥ 0 (badly scaled). f* = 1
/// at (0.01, 0) or (0, 1).
pub fn scale1() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x1", "x2"]);
        pb.minimize((100.0 * v[0] - 1.0).sq() + (v[1] - 1.0).sq());
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "scale1",
        source: "MacMPEC scale1, f* = 1",
        build,
        f_star: 1.0,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// Fletcher & Leyffer (2002/2006), "Local convergence of SQP methods for MPECs", ex. (2.2):
/// min (z₁−1)² + z₂², z₂ ≥ 0, 0 ≤ z₂ − z₁ ⊥ z₂ ≥ 0. f* = 0.5 at (0.5, 0.5).
pub fn fl_ex1() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["z1", "z2"]);
        pb.minimize((v[0] - 1.0).sq() + v[1].sq());
        pb.complementarity("c", v[1] - v[0], v[1]).unwrap();
        pb
    }
    Case {
        name: "fl_ex1",
        source: "Fletcher et al., local SQP for MPECs, ex. 2.2, f* = 0.5",
        build,
        f_star: 0.5,
        f_tol: 1e-6,
        known_failures: &[],
    }
}

/// Fletcher et al., ex. (2.2) second problem: min z₁ + z₂, z ≥ 0, z₂² ≥ 1, 0 ≤ z₁ ⊥ z₂ ≥ 0.
/// f* = 1 at (0, 1).
pub fn fl_ex2() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["z1", "z2"]);
        pb.set_bounds(&v, 0.0, f64::INFINITY).unwrap();
        pb.minimize(v[0] + v[1]);
        pb.subject_to(v[1].sq().ge(1.0)).unwrap();
        pb.complementarity("c", v[0], v[1]).unwrap();
        pb
    }
    Case { name: "fl_ex2", source: "Fletcher et al., local SQP for MPECs, ex. 2.2, f* = 1", build, f_star: 1.0, f_tol: 1e-6,
        known_failures: &[(
            MpccBackend::Sqp,
            "from z = 0 the linearisation of z2^2 >= 1 has a zero gradient: the SQP stays at the infeasible origin (MaximumIterationsExceeded)",
        )],
    }
}

/// MacMPEC outrata31 (Outrata, SIAM J. Optim. 4(2), 1994; Scholtes 1997): min ½((x₁−3)² +
/// (x₂−4)²), x ≥ 0, 0 ≤ y ≤ 10, four nonlinear complementarity pairs Fᵢ(x, y) ≥ 0 ⊥ xᵢ ≥ 0
/// (see the .mod), from 0. MacMPEC f* = 3.2077, published to 5 digits: checked to 1e-4.
pub fn outrata31() -> Case {
    fn build() -> Problem {
        let mut pb = Problem::new();
        let v = scalars(&mut pb, &["x1", "x2", "x3", "x4", "y"]);
        let (x1, x2, x3, x4, y) = (v[0], v[1], v[2], v[3], v[4]);
        pb.set_bounds(&v[..4], 0.0, f64::INFINITY).unwrap();
        pb.set_bounds(&v[4..], 0.0, 10.0).unwrap();
        pb.minimize(0.5 * ((x1 - 3.0).sq() + (x2 - 4.0).sq()));
        let f1 = (1.0 + 0.2 * y) * x1 - (3.0 + 1.333 * y) - 0.333 * x3 + 2.0 * x1 * x4;
        let f2 = (1.0 + 0.1 * y) * x2 - y + x3 + 2.0 * x2 * x4;
        let f3 = 0.333 * x1 - x2 + 1.0 - 0.1 * y;
        let f4 = 9.0 + 0.1 * y - x1.sq() - x2.sq();
        pb.complementarity("nlcs1", f1, x1).unwrap();
        pb.complementarity("nlcs2", f2, x2).unwrap();
        pb.complementarity("nlcs3", f3, x3).unwrap();
        pb.complementarity("nlcs4", f4, x4).unwrap();
        pb
    }
    Case {
        name: "outrata31",
        source: "MacMPEC outrata31, f* = 3.2077",
        build,
        f_star: 3.2077,
        f_tol: 1e-4,
        known_failures: &[],
    }
}
