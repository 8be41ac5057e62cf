//! The IPM's termination part: IPOPT's scaled optimality error E_μ (Wächter & Biegler
//! 2006, eq. (5)) from the error's parts, and [`StopTest`], which owns the convergence
//! test's state (the acceptable-level counter of [`Termination`]) and the limits, and
//! says when and why a run ends. The core measures the parts (`core/measures.rs`) and
//! calls [`StopTest::check`] before each iteration.

use crate::frontend::{KktResiduals, Termination};
use crate::options::IpmOptions;
use crate::solution::Status;

/// E_μ = max(‖∇L‖/s_d, ‖c‖, ‖complementarity‖/s_c) with the multiplier scalings
/// s_d = max(s_max, (‖y‖₁ + ‖z‖₁)/(m + n_z))/s_max and s_c = max(s_max, ‖z‖₁/n_z)/s_max
/// (eq. (5)); `parts` are the max-norms (dual, primal, complementarity), `zl`/`zu`
/// count where `has_l`/`has_u`.
pub(crate) fn scaled_error(
    parts: [f64; 3],
    y: &[f64],
    (zl, has_l): (&[f64], &[bool]),
    (zu, has_u): (&[f64], &[bool]),
    s_max: f64,
) -> f64 {
    let mut nz = 0usize;
    let mut zsum = 0.0;
    for j in 0..has_l.len() {
        if has_l[j] {
            nz += 1;
            zsum += zl[j].abs();
        }
        if has_u[j] {
            nz += 1;
            zsum += zu[j].abs();
        }
    }
    let ysum: f64 = y.iter().map(|x| x.abs()).sum();
    let m = y.len();
    let sd = if m + nz > 0 {
        (s_max.max((ysum + zsum) / (m + nz) as f64)) / s_max
    } else {
        1.0
    };
    let sc = if nz > 0 {
        (s_max.max(zsum / nz as f64)) / s_max
    } else {
        1.0
    };
    (parts[0] / sd).max(parts[1]).max(parts[2] / sc)
}

/// Why a run stops ([`StopTest::check`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Stop {
    pub(crate) status: Status,
    pub(crate) message: &'static str,
    /// A restoration run's problem converged (rather than being stopped).
    pub(crate) resto_converged: bool,
}

/// The termination test of one run: convergence (or, in restoration, the restoration
/// problem's own convergence to `tol`) and the limits on iterations, restoration
/// iterations, wall time and the iterate's size.
#[derive(Clone, Debug)]
pub(crate) struct StopTest {
    test: Termination,
    in_resto: bool,
    tol: f64,
    max_iter: usize,
    max_resto_iter: usize,
    /// The iteration at which a restoration run stops (set by [`StopTest::start`]).
    resto_iter_end: usize,
    max_wall_time: f64,
    diverging_iterates_tol: f64,
}

impl StopTest {
    /// The test for a run with `opts` (`in_resto` for a restoration run).
    pub(crate) fn new(opts: &IpmOptions, in_resto: bool) -> StopTest {
        StopTest {
            test: Termination::default(),
            in_resto,
            tol: opts.tol,
            max_iter: opts.max_iter,
            max_resto_iter: opts.max_resto_iter,
            resto_iter_end: usize::MAX,
            max_wall_time: opts.max_wall_time,
            diverging_iterates_tol: opts.diverging_iterates_tol,
        }
    }

    /// The run starts at iteration `iter` (a restoration run may take `max_resto_iter`
    /// iterations from there).
    pub(crate) fn start(&mut self, iter: usize) {
        self.resto_iter_end = iter.saturating_add(self.max_resto_iter);
    }

    /// The test before an iteration at `iter` with residuals `e`, scaled objective `f`,
    /// `elapsed` seconds and max-norm `w_norm` of the primal iterate; `None` to go on.
    pub(crate) fn check(
        &mut self,
        e: &KktResiduals,
        f: f64,
        opts: &IpmOptions,
        (iter, elapsed, w_norm): (usize, f64, f64),
    ) -> Option<Stop> {
        let stop = |status, message| {
            Some(Stop {
                status,
                message,
                resto_converged: false,
            })
        };
        if !self.in_resto {
            if let Some(status) = self.test.check(e, f, &opts.common) {
                return stop(status, "");
            }
        } else if e.overall <= self.tol {
            return Some(Stop {
                status: Status::SolveSucceeded,
                message: "restoration problem converged",
                resto_converged: true,
            });
        } else {
            self.test.set_last_objective(f);
        }
        if iter >= self.max_iter {
            return stop(Status::MaximumIterationsExceeded, "");
        }
        if self.in_resto && iter >= self.resto_iter_end {
            return stop(Status::MaximumIterationsExceeded, "max_resto_iter");
        }
        if elapsed > self.max_wall_time {
            return stop(Status::MaximumWallTimeExceeded, "");
        }
        if w_norm > self.diverging_iterates_tol {
            return stop(Status::DivergingIterates, "");
        }
        None
    }

    /// The last tested iterate was acceptable (see [`Termination::last_was_acceptable`]).
    pub(crate) fn last_was_acceptable(&self) -> bool {
        self.test.last_was_acceptable()
    }
}

#[cfg(test)]
mod tests {
    use super::{scaled_error, Stop, StopTest};
    use crate::frontend::KktResiduals;
    use crate::options::IpmOptions;
    use crate::solution::Status;

    /// eq. (5) on a hand-made iterate: y = (3), z_L = (1, ·), z_U = (·, 5) (bounds
    /// x₀ ≥ l, x₁ ≤ u). With s_max = 1: s_d = max(1, 9/3) = 3, s_c = max(1, 6/2) = 3;
    /// with IPOPT's s_max = 100 both are 1.
    #[test]
    fn scaled_error_follows_eq_5() {
        let y = [3.0];
        let (zl, has_l) = ([1.0, 7.0], [true, false]);
        let (zu, has_u) = ([9.0, 5.0], [false, true]);
        let parts = [6.0, 1.0, 9.0];
        let e = scaled_error(parts, &y, (&zl, &has_l), (&zu, &has_u), 1.0);
        assert_eq!(e, 3.0, "max(6/3, 1, 9/3)");
        let e = scaled_error(parts, &y, (&zl, &has_l), (&zu, &has_u), 100.0);
        assert_eq!(e, 9.0);
        // No multipliers at all: no scaling.
        assert_eq!(scaled_error(parts, &[], (&[], &[]), (&[], &[]), 1.0), 9.0);
    }

    fn res(overall: f64) -> KktResiduals {
        KktResiduals {
            overall,
            dual: overall,
            primal: overall,
            compl: overall,
        }
    }

    #[test]
    fn limits_in_order() {
        let o = IpmOptions {
            common: crate::CommonOptions {
                max_iter: 10,
                max_wall_time: 5.0,
                diverging_iterates_tol: 1e6,
                ..Default::default()
            },
            max_resto_iter: 3,
            ..IpmOptions::default()
        };
        let mut t = StopTest::new(&o, false);
        t.start(0);
        assert_eq!(t.check(&res(1.0), 0.0, &o, (9, 1.0, 1.0)), None);
        let st = |s: Option<Stop>| s.map(|s| (s.status, s.message));
        assert_eq!(
            st(t.check(&res(1e-9), 0.0, &o, (10, 9.0, 1e9))),
            Some((Status::SolveSucceeded, "")),
            "convergence before the limits"
        );
        assert_eq!(
            st(t.check(&res(1.0), 0.0, &o, (10, 9.0, 1e9))),
            Some((Status::MaximumIterationsExceeded, ""))
        );
        assert_eq!(
            st(t.check(&res(1.0), 0.0, &o, (3, 9.0, 1e9))),
            Some((Status::MaximumWallTimeExceeded, ""))
        );
        assert_eq!(
            st(t.check(&res(1.0), 0.0, &o, (3, 1.0, 1e9))),
            Some((Status::DivergingIterates, ""))
        );
        // A restoration run started at iteration 5: converged to tol, or at 5 + 3.
        let mut r = StopTest::new(&o, true);
        r.start(5);
        let conv = r.check(&res(1e-9), 0.0, &o, (6, 1.0, 1.0)).unwrap();
        assert!(conv.resto_converged && conv.status == Status::SolveSucceeded);
        assert_eq!(r.check(&res(1.0), 0.0, &o, (7, 1.0, 1.0)), None);
        assert_eq!(
            st(r.check(&res(1.0), 0.0, &o, (8, 1.0, 1.0))),
            Some((Status::MaximumIterationsExceeded, "max_resto_iter"))
        );
    }
}
