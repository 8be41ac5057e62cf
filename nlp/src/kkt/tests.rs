//! Unit tests of the KKT system against dense eigenvalues and residuals.

#![allow(clippy::needless_range_loop)]

use super::{Kkt, KktError, KktFactorization};
use crate::test_support::{pattern, Rng};
use faer::sparse::SymbolicSparseColMat;
use faer::{Mat, Side};

struct Case {
    n: usize,
    m: usize,
    h: SymbolicSparseColMat<usize>,
    j: SymbolicSparseColMat<usize>,
    hv: Vec<f64>,
    jv: Vec<f64>,
    dx: Vec<f64>,
    dc: Vec<f64>,
}

fn random_case(rng: &mut Rng, n: usize, m: usize, density: f64, indefinite: bool) -> Case {
    let mut he = Vec::new();
    for c in 0..n {
        for r in c..n {
            if r == c || rng.next() < density {
                he.push((r, c));
            }
        }
    }
    let mut je = Vec::new();
    for r in 0..m {
        je.push((r, (r * 7) % n));
        for c in 0..n {
            if rng.next() < density {
                je.push((r, c));
            }
        }
    }
    let h = pattern(n, n, &he);
    let j = pattern(m, n, &je);
    let hv = (0..h.row_idx().len())
        .map(|_| {
            if indefinite {
                3.0 * rng.sym()
            } else {
                rng.sym()
            }
        })
        .collect();
    let jv = (0..j.row_idx().len()).map(|_| rng.sym()).collect();
    let dx = (0..n)
        .map(|_| if indefinite { 0.0 } else { 10.0 + rng.next() })
        .collect();
    let dc = (0..m).map(|_| 1e-3 + rng.next() * 1e-2).collect();
    Case {
        n,
        m,
        h,
        j,
        hv,
        jv,
        dx,
        dc,
    }
}

fn dense(c: &Case) -> Mat<f64> {
    let dim = c.n + c.m;
    let mut k = Mat::<f64>::zeros(dim, dim);
    for col in 0..c.n {
        for p in c.h.col_range(col) {
            let r = c.h.row_idx()[p];
            k[(r, col)] += c.hv[p];
            if r != col {
                k[(col, r)] += c.hv[p];
            }
        }
        for p in c.j.col_range(col) {
            let r = c.j.row_idx()[p];
            k[(c.n + r, col)] += c.jv[p];
            k[(col, c.n + r)] += c.jv[p];
        }
    }
    for i in 0..c.n {
        k[(i, i)] += c.dx[i];
    }
    for i in 0..c.m {
        k[(c.n + i, c.n + i)] -= c.dc[i];
    }
    k
}

fn check_case(c: &Case) {
    for kind in [
        KktFactorization::Supernodal,
        KktFactorization::Simplicial,
        KktFactorization::Auto,
    ] {
        check_case_kind(c, kind);
    }
}

fn check_case_kind(c: &Case, kind: KktFactorization) {
    let mut kkt = Kkt::with_factorization(c.n, c.m, &c.h, &c.j, kind).unwrap();
    assert_eq!(
        kkt.is_supernodal(),
        kind == KktFactorization::Supernodal
            || (kind == KktFactorization::Auto && kkt.is_supernodal())
    );
    // Simplicial analyses run on our own factorisation of the permuted K.
    assert_eq!(kkt.simplicial.is_some(), !kkt.is_supernodal());
    let inertia = kkt.factorize(&c.hv, &c.dx, &c.jv, &c.dc).unwrap();
    let kd = dense(c);
    let eig = kd.self_adjoint_eigenvalues(Side::Lower).unwrap();
    let pos = eig.iter().filter(|&&e| e > 0.0).count();
    let neg = eig.iter().filter(|&&e| e < 0.0).count();
    assert_eq!(
        (inertia.positive, inertia.negative),
        (pos, neg),
        "eig {eig:?}"
    );
    let dim = c.n + c.m;
    let mut rng = Rng(99);
    let b: Vec<f64> = (0..dim).map(|_| rng.sym()).collect();
    let mut x = b.clone();
    let ratio = kkt.solve(&mut x).unwrap();
    assert!(ratio < 1e-12, "residual ratio {ratio}");
    // Dense residual check.
    let mut maxr: f64 = 0.0;
    for i in 0..dim {
        let mut s = 0.0;
        for j in 0..dim {
            s += kd[(i, j)] * x[j];
        }
        maxr = maxr.max((s - b[i]).abs());
    }
    assert!(maxr < 1e-9, "dense residual {maxr}");
}

#[test]
fn quasi_definite_inertia_and_solve() {
    let mut rng = Rng(12345);
    for &(n, m) in &[(5, 2), (10, 4), (30, 12), (60, 25)] {
        let c = random_case(&mut rng, n, m, 0.2, false);
        check_case(&c);
        let mut kkt = Kkt::new(c.n, c.m, &c.h, &c.j).unwrap();
        let i = kkt.factorize(&c.hv, &c.dx, &c.jv, &c.dc).unwrap();
        assert_eq!((i.positive, i.negative, i.zero), (n, m, 0));
    }
}

#[test]
fn indefinite_inertia_matches_dense() {
    let mut rng = Rng(777);
    for k in 0..20 {
        let n = 4 + k;
        let m = k / 2 + 1;
        let c = random_case(&mut rng, n, m, 0.3, true);
        check_case(&c);
    }
}

#[test]
fn refactorization_reuses_symbolic() {
    let mut rng = Rng(4242);
    let c = random_case(&mut rng, 20, 8, 0.25, true);
    let mut kkt = Kkt::new(c.n, c.m, &c.h, &c.j).unwrap();
    let mut dx = c.dx.clone();
    // Increasing δ_w eventually yields the quasi-definite inertia (n, m, 0).
    let mut delta = 1e-4;
    loop {
        dx.iter_mut().for_each(|d| *d = delta);
        let i = kkt.factorize(&c.hv, &dx, &c.jv, &c.dc).unwrap();
        if i.negative == c.m {
            assert_eq!(i.positive, c.n);
            break;
        }
        delta *= 8.0;
        assert!(delta < 1e6);
    }
}

#[test]
fn shifted_solve_removes_regularisation() {
    let mut rng = Rng(31337);
    let c = random_case(&mut rng, 15, 6, 0.3, false);
    let mut kkt = Kkt::new(c.n, c.m, &c.h, &c.j).unwrap();
    // Factor with dc + 1e-8, solve the system with dc.
    let dc_reg: Vec<f64> = c.dc.iter().map(|d| d + 1e-8).collect();
    kkt.factorize(&c.hv, &c.dx, &c.jv, &dc_reg).unwrap();
    let mut shift = vec![0.0; c.n + c.m];
    shift[c.n..].iter_mut().for_each(|s| *s = 1e-8);
    let b: Vec<f64> = (0..c.n + c.m).map(|_| rng.sym()).collect();
    let mut x = b.clone();
    let ratio = kkt.solve_shifted(&mut x, Some(&shift)).unwrap();
    assert!(ratio < 1e-13, "{ratio}");
}

#[test]
fn zero_block_without_regularisation_is_an_error_not_a_panic() {
    let h = pattern(2, 2, &[(0, 0), (1, 1)]);
    let j = pattern(1, 2, &[(0, 0)]);
    let mut kkt = Kkt::new(2, 1, &h, &j).unwrap();
    // H = 0, J = 0, dc = 0: K is singular.
    let r = kkt.factorize(&[0.0, 0.0], &[0.0, 0.0], &[0.0], &[0.0]);
    assert!(r.is_err() || r.unwrap().zero > 0);
    let r = kkt.factorize(&[f64::NAN, 0.0], &[1.0, 1.0], &[1.0], &[1.0]);
    assert_eq!(r, Err(KktError::NonFinite));
    let mut b = vec![1.0; 3];
    assert_eq!(kkt.solve(&mut b), Err(KktError::NotFactorized));
}

#[test]
fn rejects_upper_hessian_pattern() {
    let h = pattern(2, 2, &[(0, 1)]);
    let j = pattern(0, 2, &[]);
    assert!(matches!(Kkt::new(2, 0, &h, &j), Err(KktError::Pattern(_))));
    let h = pattern(3, 3, &[]);
    assert!(matches!(Kkt::new(2, 0, &h, &j), Err(KktError::Pattern(_))));
}

/// hs061, iteration 2: multipliers ~1e8 make the Schur complement tiny, so the static
/// regularisation slows refinement down (factor ≈ 0.28 per step). The backward error
/// passes 1e-10 after two steps while x[0] is still 12 % off (2.68 instead of 2.4);
/// refinement must continue while it gains.
#[test]
fn refinement_continues_while_it_gains_on_ill_conditioned_systems() {
    let h = pattern(3, 3, &[(0, 0), (1, 1), (2, 2)]);
    let j = pattern(2, 3, &[(0, 0), (1, 0), (0, 1), (1, 2)]);
    let (x1, x2, x3) = (2.600000002744226f64, -4.0f64, 6.000000000000001f64);
    let (y1, y2) = (142262354.26711383f64, -106696762.65033539f64);
    let hv = [8.0, 4.0 - 4.0 * y1, 4.0 - 2.0 * y2];
    let jv = [3.0, 4.0, -4.0 * x2, -2.0 * x3];
    let g = [8.0 * x1 - 33.0, 4.0 * x2 + 16.0, 4.0 * x3 - 24.0];
    let c = [3.0 * x1 - 2.0 * x2 * x2 - 7.0, 4.0 * x1 - x3 * x3 - 11.0];
    let mut x = vec![
        -(g[0] + 3.0 * y1 + 4.0 * y2),
        -(g[1] - 4.0 * x2 * y1),
        -(g[2] - 2.0 * x3 * y2),
        -c[0],
        -c[1],
    ];
    let mut kkt = Kkt::new(3, 2, &h, &j).unwrap();
    kkt.residual_ratio_max = 1e-10;
    let i = kkt.factorize(&hv, &[1e-8; 3], &jv, &[1e-8; 2]).unwrap();
    assert_eq!((i.positive, i.negative), (3, 2));
    let shift = [-1e-8, -1e-8, -1e-8, 1e-8, 1e-8];
    kkt.solve_shifted(&mut x, Some(&shift)).unwrap();
    // Exact step (50-digit arithmetic): (2.39999799, 1.50000038, −2.25000067, …).
    assert!((x[0] - 2.4).abs() < 1e-3, "{x:?}");
    assert!((x[1] - 1.5).abs() < 1e-3, "{x:?}");
    assert!((x[2] + 2.25).abs() < 1e-3, "{x:?}");
}

/// `residual_ratio_floor`: refinement that removes a regularisation of 1e-4 gains a
/// factor of roughly 1e-4 per step; with the floor at the target it stops at the first
/// ratio below the target, with the default floor it goes on to round-off. The ratios
/// are the solver's own, checked against a dense residual.
#[test]
fn refinement_floor_decides_how_far_past_the_target_refinement_goes() {
    let mut rng = Rng(8080);
    let c = random_case(&mut rng, 30, 12, 0.2, false);
    let reg = 1e-4;
    let dc_reg: Vec<f64> = c.dc.iter().map(|d| d + reg).collect();
    let mut shift = vec![0.0; c.n + c.m];
    shift[c.n..].iter_mut().for_each(|s| *s = reg);
    let b: Vec<f64> = (0..c.n + c.m).map(|_| rng.sym()).collect();
    let kd = dense(&c);
    let dense_ratio = |x: &[f64]| {
        let dim = c.n + c.m;
        let r = (0..dim)
            .map(|i| ((0..dim).map(|j| kd[(i, j)] * x[j]).sum::<f64>() - b[i]).abs())
            .fold(0.0, f64::max);
        let xn = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let bn = b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        r / (xn + bn)
    };
    let mut ratios = Vec::new();
    for floor in [1e-10, 1e-14] {
        let mut kkt = Kkt::new(c.n, c.m, &c.h, &c.j).unwrap();
        kkt.residual_ratio_max = 1e-10;
        kkt.residual_ratio_floor = floor;
        kkt.factorize(&c.hv, &c.dx, &c.jv, &dc_reg).unwrap();
        let mut x = b.clone();
        let ratio = kkt.solve_shifted(&mut x, Some(&shift)).unwrap();
        assert!(ratio <= 1e-10, "floor {floor}: {ratio}");
        // The solver's ratio is the dense one (to rounding of the residual itself).
        assert!(dense_ratio(&x) <= ratio.max(1e-15) * 10.0, "floor {floor}");
        ratios.push(ratio);
    }
    assert!(ratios[0] > 1e-14, "stopped at the target: {}", ratios[0]);
    assert!(ratios[1] <= 1e-14 && ratios[1] < ratios[0], "{ratios:?}");
}
