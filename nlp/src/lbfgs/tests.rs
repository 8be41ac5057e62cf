//! Checks of the compact forms against the textbook recursions, and of the low-rank KKT
//! solve and inertia against a dense matrix.

use super::{dot, norm2, LimitedMemory, Settings, UpdateKind};
use crate::kkt::LowRankKkt;
use crate::kkt::{Kkt, LowRankTerm};
use crate::options::{LimitedMemoryInit, LimitedMemoryUpdate};
use crate::test_support::{pattern, Rng};
use faer::linalg::solvers::Solve;
use faer::sparse::SymbolicSparseColMat;
use faer::Mat;
use faer::Side;

fn settings(update: LimitedMemoryUpdate, max_history: usize) -> Settings {
    Settings {
        max_history,
        update,
        init: LimitedMemoryInit::Scalar1,
        init_val: 1.0,
        init_val_min: 1e-8,
        init_val_max: 1e8,
        max_skipping: 2,
    }
}

impl LimitedMemory {
    /// Feeds one pair directly (as `update` does after forming s and y).
    fn push_pair(&mut self, s: Vec<f64>, y: Vec<f64>) -> bool {
        let ok = self.accept(&s, &y);
        if ok {
            self.add_pair(s, y);
        }
        ok
    }
}

/// B as a dense matrix, column by column from `apply`.
fn dense_of(term: &LowRankTerm, n: usize) -> Mat<f64> {
    let mut b = Mat::<f64>::zeros(n, n);
    let mut e = vec![0.0; n];
    let mut col = vec![0.0; n];
    for j in 0..n {
        e.iter_mut().for_each(|v| *v = 0.0);
        e[j] = 1.0;
        term.apply(&e, &mut col);
        for i in 0..n {
            b[(i, j)] = col[i];
        }
    }
    b
}

fn matvec(a: &Mat<f64>, x: &[f64]) -> Vec<f64> {
    (0..a.nrows())
        .map(|i| (0..a.ncols()).map(|j| a[(i, j)] * x[j]).sum())
        .collect()
}

/// Textbook recursion from B₀ = σI over the pairs (BFGS: Nocedal & Wright eq. 6.19;
/// SR1: eq. 6.24).
fn recursion(sigma: f64, pairs: &[(Vec<f64>, Vec<f64>)], sr1: bool, n: usize) -> Mat<f64> {
    let mut b = Mat::<f64>::zeros(n, n);
    for i in 0..n {
        b[(i, i)] = sigma;
    }
    for (s, y) in pairs {
        let bs = matvec(&b, s);
        if sr1 {
            let r: Vec<f64> = y.iter().zip(&bs).map(|(a, c)| a - c).collect();
            let den = dot(&r, s);
            for i in 0..n {
                for j in 0..n {
                    b[(i, j)] += r[i] * r[j] / den;
                }
            }
        } else {
            let sbs = dot(s, &bs);
            let sty = dot(s, y);
            for i in 0..n {
                for j in 0..n {
                    b[(i, j)] += -bs[i] * bs[j] / sbs + y[i] * y[j] / sty;
                }
            }
        }
    }
    b
}

fn rel_diff(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    let mut num: f64 = 0.0;
    let mut den: f64 = 0.0;
    for i in 0..a.nrows() {
        for j in 0..a.ncols() {
            num = num.max((a[(i, j)] - b[(i, j)]).abs());
            den = den.max(b[(i, j)].abs());
        }
    }
    num / den
}

/// A random pair with sᵀy > 0 (y = A s + small noise, A symmetric positive definite).
fn spd_pair(rng: &mut Rng, a: &Mat<f64>, n: usize) -> (Vec<f64>, Vec<f64>) {
    loop {
        let s = rng.vec(n);
        let mut y = matvec(a, &s);
        for v in y.iter_mut() {
            *v += 0.1 * rng.sym();
        }
        if dot(&s, &y) > 0.1 * norm2(&s) * norm2(&y) {
            return (s, y);
        }
    }
}

fn random_spd(rng: &mut Rng, n: usize) -> Mat<f64> {
    let g = Mat::<f64>::from_fn(n, n, |_, _| rng.sym());
    let mut a = Mat::<f64>::zeros(n, n);
    for i in 0..n {
        for j in 0..n {
            a[(i, j)] = (0..n).map(|k| g[(k, i)] * g[(k, j)]).sum::<f64>() / n as f64;
        }
        a[(i, i)] += 0.5;
    }
    a
}

#[test]
fn compact_bfgs_equals_textbook_recursion() {
    // Tolerance 1e-10 relative (max-norm): both sides are O(κ·ε) accurate and the
    // matrices here are well conditioned (κ ≲ 1e3).
    let mut rng = Rng(2024);
    for &(n, hist, npairs) in &[(5, 6, 3), (8, 6, 6), (12, 4, 9), (20, 6, 15)] {
        let a = random_spd(&mut rng, n);
        let mut mem = LimitedMemory::new(n, settings(LimitedMemoryUpdate::Bfgs, hist));
        let mut pairs = Vec::new();
        for _ in 0..npairs {
            let (s, y) = spd_pair(&mut rng, &a, n);
            assert!(mem.push_pair(s.clone(), y.clone()));
            pairs.push((s, y));
        }
        let kept = &pairs[pairs.len().saturating_sub(hist)..];
        assert_eq!(mem.len(), kept.len());
        let (s_new, y_new) = kept.last().unwrap();
        let sigma = dot(s_new, y_new) / dot(s_new, s_new);
        assert_eq!(mem.term().sigma(), sigma);
        let compact = dense_of(mem.term(), n);
        let reference = recursion(sigma, kept, false, n);
        let d = rel_diff(&compact, &reference);
        assert!(d < 1e-10, "n={n}: relative difference {d:e}");
        // The BFGS matrix is positive definite.
        let eig = compact.self_adjoint_eigenvalues(Side::Lower).unwrap();
        assert!(eig[0] > 0.0, "{eig:?}");
    }
}

#[test]
fn compact_sr1_equals_textbook_recursion() {
    let mut rng = Rng(99);
    for &(n, npairs) in &[(6, 3), (10, 5)] {
        // An indefinite "true Hessian" so SR1 is not BFGS in disguise.
        let mut a = random_spd(&mut rng, n);
        a[(0, 0)] -= 3.0;
        let mut mem = LimitedMemory::new(n, settings(LimitedMemoryUpdate::Sr1, 6));
        let mut pairs = Vec::new();
        for _ in 0..npairs {
            let s = rng.vec(n);
            let y = matvec(&a, &s);
            if mem.push_pair(s.clone(), y.clone()) {
                pairs.push((s, y));
            }
        }
        assert!(pairs.len() >= 2 && mem.len() >= 2, "{} pairs", mem.len());
        let kept: Vec<(Vec<f64>, Vec<f64>)> =
            mem.s.iter().cloned().zip(mem.y.iter().cloned()).collect();
        let sigma = mem.term().sigma();
        let compact = dense_of(mem.term(), n);
        let reference = recursion(sigma, &kept, true, n);
        let d = rel_diff(&compact, &reference);
        assert!(d < 1e-9, "n={n}: relative difference {d:e}");
    }
}

#[test]
fn curvature_test_skips_and_repeated_skips_reset() {
    let n = 3;
    let pat = SymbolicSparseColMat::new_checked(0, n, vec![0; n + 1], None, Vec::new());
    let mut mem = LimitedMemory::new(n, settings(LimitedMemoryUpdate::Bfgs, 6));
    // f = ½ xᵀx: y = s.
    let g = |x: &[f64]| x.to_vec();
    let x0 = [1.0, 2.0, 3.0];
    assert_eq!(mem.update(&x0, &g(&x0), &[], &pat, &[]), UpdateKind::Reset);
    let x1 = [0.5, 1.0, 2.0];
    assert_eq!(
        mem.update(&x1, &g(&x1), &[], &pat, &[]),
        UpdateKind::Updated
    );
    assert_eq!(mem.len(), 1);
    assert_eq!(mem.term().sigma(), 1.0);
    // Negative curvature: gradient moves against the step.
    let x2 = [0.0, 0.0, 0.0];
    assert_eq!(
        mem.update(&x2, &[5.0, 5.0, 5.0], &[], &pat, &[]),
        UpdateKind::Skipped
    );
    // The same point again: no pair, and not a skip.
    assert_eq!(
        mem.update(&x2, &[5.0, 5.0, 5.0], &[], &pat, &[]),
        UpdateKind::Unchanged
    );
    // A step below 100ε.
    let x3 = [1e-15, 0.0, 0.0];
    assert_eq!(
        mem.update(&x3, &[5.0, 5.0, 5.0], &[], &pat, &[]),
        UpdateKind::Skipped
    );
    assert_eq!(mem.len(), 1);
    // Two skips in a row (limited_memory_max_skipping = 2): reset.
    assert_eq!(mem.update(&x1, &g(&x1), &[], &pat, &[]), UpdateKind::Reset);
    assert_eq!(mem.len(), 0);
}

#[test]
fn secant_pair_uses_the_new_multipliers_on_both_sides() {
    // L = x₀² + λ (x₀ x₁): ∇ₓL = (2x₀ + λx₁, λx₀); J = [x₁, x₀].
    let n = 2;
    let pat = SymbolicSparseColMat::new_checked(1, n, vec![0, 1, 2], None, vec![0, 0]);
    let mut mem = LimitedMemory::new(n, settings(LimitedMemoryUpdate::Bfgs, 6));
    let x0 = [1.0, 1.0];
    mem.update(&x0, &[2.0, 0.0], &[1.0, 1.0], &pat, &[0.3]);
    let x1 = [1.5, 1.2];
    let lam = [2.0];
    assert_eq!(
        mem.update(&x1, &[3.0, 0.0], &[1.2, 1.5], &pat, &lam),
        UpdateKind::Updated
    );
    // Exact: y = ∇²L s with ∇²L = [[2, λ], [λ, 0]], s = (0.5, 0.2).
    let y = [2.0 * 0.5 + 2.0 * 0.2, 2.0 * 0.5];
    assert!((dot(&mem.s[0], &mem.y[0]) - dot(&[0.5, 0.2], &y)).abs() < 1e-14);
    assert!((mem.y[0][0] - y[0]).abs() < 1e-14 && (mem.y[0][1] - y[1]).abs() < 1e-14);
}

/// Dense K = [B + diag(dx), Jᵀ; J, −diag(dc)].
fn dense_kkt(b: &Mat<f64>, dx: &[f64], j: &[(usize, usize, f64)], dc: &[f64]) -> Mat<f64> {
    let (n, m) = (dx.len(), dc.len());
    let mut k = Mat::<f64>::zeros(n + m, n + m);
    for r in 0..n {
        for c in 0..n {
            k[(r, c)] = b[(r, c)];
        }
        k[(r, r)] += dx[r];
    }
    for &(r, c, v) in j {
        k[(n + r, c)] += v;
        k[(c, n + r)] += v;
    }
    for i in 0..m {
        k[(n + i, n + i)] -= dc[i];
    }
    k
}

/// Builds a memory of the given kind and history on random pairs.
fn memory(rng: &mut Rng, n: usize, update: LimitedMemoryUpdate, npairs: usize) -> LimitedMemory {
    let mut a = random_spd(rng, n);
    if update == LimitedMemoryUpdate::Sr1 {
        for i in 0..n / 2 {
            a[(i, i)] -= 4.0;
        }
    }
    let mut mem = LimitedMemory::new(n, settings(update, 6));
    for _ in 0..npairs {
        let s = rng.vec(n);
        let mut y = matvec(&a, &s);
        y.iter_mut().for_each(|v| *v += 0.05 * rng.sym());
        mem.push_pair(s, y);
    }
    mem
}

#[test]
fn low_rank_kkt_solve_and_inertia_match_the_dense_matrix() {
    let mut rng = Rng(7);
    let mut cases = 0;
    let mut not_quasi_definite = 0;
    for trial in 0..24 {
        let n = 6 + trial % 7;
        let m = 1 + trial % 4;
        let update = if trial % 3 == 2 {
            LimitedMemoryUpdate::Sr1
        } else {
            LimitedMemoryUpdate::Bfgs
        };
        let mem = memory(&mut rng, n, update, 2 + trial % 6);
        // Jacobian: one guaranteed entry per row plus random ones.
        let mut entries = Vec::new();
        for r in 0..m {
            entries.push((r, (3 * r) % n, 1.0 + rng.next()));
            for c in 0..n {
                if rng.next() < 0.3 {
                    entries.push((r, c, rng.sym()));
                }
            }
        }
        entries.sort_by_key(|e| (e.1, e.0));
        entries.dedup_by_key(|e| (e.1, e.0));
        let jp = pattern(
            m,
            n,
            &entries.iter().map(|e| (e.0, e.1)).collect::<Vec<_>>(),
        );
        let jv: Vec<f64> = entries.iter().map(|e| e.2).collect();
        // Empty Hessian pattern (pure quasi-Newton Hessian).
        let hp = pattern(n, n, &[]);
        let mut kkt = Kkt::new(n, m, &hp, &jp).unwrap();
        // Σ: some variables at bounds (large), and in half the cases a negative shift so
        // that B + Σ is indefinite and the inertia is not the quasi-definite one.
        let dx: Vec<f64> = (0..n)
            .map(|i| {
                if trial % 2 == 1 && i == 0 {
                    -2.5
                } else {
                    rng.next() * if i % 3 == 0 { 10.0 } else { 0.1 }
                }
            })
            .collect();
        let dc: Vec<f64> = (0..m).map(|_| 1e-8 + 1e-3 * rng.next()).collect();
        let mut lr = LowRankKkt::default();
        let inertia = lr
            .factorize(&mut kkt, mem.term(), &[], &dx, &jv, &dc)
            .unwrap();
        let b = dense_of(mem.term(), n);
        let trip: Vec<(usize, usize, f64)> = entries.clone();
        let kd = dense_kkt(&b, &dx, &trip, &dc);
        let eig = kd.self_adjoint_eigenvalues(Side::Lower).unwrap();
        let pos = eig.iter().filter(|&&e| e > 0.0).count();
        let neg = eig.iter().filter(|&&e| e < 0.0).count();
        assert_eq!(
            (inertia.positive, inertia.negative, inertia.zero),
            (pos, neg, 0),
            "trial {trial}: eigenvalues {eig:?}"
        );
        if neg > m {
            not_quasi_definite += 1;
        }
        // Solve against a dense LU solve of the same matrix; 1e-9 relative: K's
        // condition number here is ≲ 1e5 (dc ≥ 1e-8 only on rows with J entries O(1)).
        let rhs: Vec<f64> = rng.vec(n + m);
        let mut x = rhs.clone();
        let ratio = lr.solve_shifted(&mut kkt, &mut x, None).unwrap();
        assert!(ratio < 1e-12, "trial {trial}: residual ratio {ratio:e}");
        let xd = kd
            .partial_piv_lu()
            .solve(Mat::<f64>::from_fn(n + m, 1, |i, _| rhs[i]));
        let scale = (0..n + m).fold(0.0f64, |a, i| a.max(xd[(i, 0)].abs()));
        for i in 0..n + m {
            assert!(
                (x[i] - xd[(i, 0)]).abs() <= 1e-9 * scale,
                "trial {trial}, entry {i}: {} vs {}",
                x[i],
                xd[(i, 0)]
            );
        }
        cases += 1;
    }
    assert_eq!(cases, 24);
    // The inertia formula is exercised beyond the quasi-definite case.
    assert!(not_quasi_definite >= 4, "{not_quasi_definite}");
}

#[test]
fn low_rank_solve_removes_a_shift_by_refinement() {
    // Factor with dc + 1e-6 on the constraint rows, solve the system with dc.
    let mut rng = Rng(5);
    let (n, m) = (8, 3);
    let mem = memory(&mut rng, n, LimitedMemoryUpdate::Bfgs, 4);
    let entries: Vec<(usize, usize, f64)> = vec![
        (0, 0, 1.0),
        (1, 3, 2.0),
        (2, 5, -1.0),
        (0, 6, 0.5),
        (2, 7, 0.3),
    ];
    let mut sorted = entries.clone();
    sorted.sort_by_key(|e| (e.1, e.0));
    let jp = pattern(m, n, &sorted.iter().map(|e| (e.0, e.1)).collect::<Vec<_>>());
    let jv: Vec<f64> = sorted.iter().map(|e| e.2).collect();
    let hp = pattern(n, n, &[]);
    let mut kkt = Kkt::new(n, m, &hp, &jp).unwrap();
    let dx = vec![0.5; n];
    let dc = vec![1e-8; m];
    let dc_reg: Vec<f64> = dc.iter().map(|d| d + 1e-6).collect();
    let mut lr = LowRankKkt::default();
    lr.factorize(&mut kkt, mem.term(), &[], &dx, &jv, &dc_reg)
        .unwrap();
    let mut shift = vec![0.0; n + m];
    shift[n..].iter_mut().for_each(|s| *s = 1e-6);
    let rhs = rng.vec(n + m);
    let mut x = rhs.clone();
    lr.solve_shifted(&mut kkt, &mut x, Some(&shift)).unwrap();
    let kd = dense_kkt(&dense_of(mem.term(), n), &dx, &sorted, &dc);
    let r: f64 = (0..n + m)
        .map(|i| ((0..n + m).map(|j| kd[(i, j)] * x[j]).sum::<f64>() - rhs[i]).abs())
        .fold(0.0, f64::max);
    assert!(r < 1e-10, "residual {r:e}");
}
