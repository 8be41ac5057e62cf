//! Per-iteration callbacks: IPOPT's `intermediate_callback`, CasADi's `iteration_callback`.
//!
//! [`Ipm`](crate::Ipm) and [`Sqp`](crate::Sqp) (and [`solve_mpcc`](crate::solve_mpcc),
//! phase by phase) call a user closure once per iteration, iteration 0 (the starting
//! point) included, right after the iteration's row of the log is recorded and before
//! the convergence test, exactly as IPOPT does:
//!
//! ```
//! use std::ops::ControlFlow;
//! use nlp::{Ipm, IterationView, Problem, Status};
//!
//! let mut pb = Problem::new();
//! let x = pb.variable("x", 2).unwrap();
//! pb.minimize((x[0] - 1.0).sq() + (x[1] - 2.0).sq());
//! let mut compiled = pb.compile().unwrap();
//! let mut objectives = Vec::new();
//! let sol = Ipm::default()
//!     .solve_with_callback(&mut compiled, |v: &IterationView<'_>| {
//!         objectives.push(v.record().objective);
//!         if v.iter() == 1 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
//!     })
//!     .unwrap();
//! assert_eq!(sol.status, Status::UserRequestedStop);
//! assert_eq!(objectives.len(), 2); // iterations 0 and 1
//! ```
//!
//! The closure sees an [`IterationView`]: the iteration's [`IterationRecord`] (the same
//! value that ends up in [`Stats::records`](crate::Stats::records)), the primal point in
//! the user's variable space and the constraint multipliers. Returning
//! [`ControlFlow::Break`] ends the solve with [`Status::UserRequestedStop`](crate::Status)
//! and the current point as the solution (IPOPT's `User_Requested_Stop`).
//!
//! Cost: without a callback, one `Option` test per iteration. With one, a copy of x and λ
//! into buffers allocated once per solve (no allocation per iteration).

use std::ops::ControlFlow;

use crate::frontend::scaled::ScaledNlp;
use crate::numeric::AffineCone;
use crate::solution::IterationRecord;

/// The per-iteration callback: return [`ControlFlow::Break`] to stop the solve.
pub type IterationCallback<'c> = dyn FnMut(&IterationView<'_>) -> ControlFlow<()> + 'c;

/// Which solve of a multi-solve driver ([`solve_mpcc`](crate::solve_mpcc)) an iteration
/// belongs to; the same words as [`MpccPhase`](crate::MpccPhase).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseLabel {
    /// 0-based position of the solve in [`MpccSolution::phases`](crate::MpccSolution).
    pub index: usize,
    /// "sqp" (products as constraints), "penalty" (IPM, π·Σab) or "final" (branches fixed).
    pub kind: &'static str,
    /// π of a penalty phase (0 otherwise).
    pub penalty: f64,
}

/// A read-only view of the current iterate, passed to an [`IterationCallback`].
#[derive(Debug, Clone, Copy)]
pub struct IterationView<'a> {
    pub(crate) record: &'a IterationRecord,
    pub(crate) x: &'a [f64],
    pub(crate) lambda: &'a [f64],
    pub(crate) phase: Option<PhaseLabel>,
}

impl<'a> IterationView<'a> {
    /// The iteration's row of the log (also pushed to `Solution::stats.records`):
    /// unscaled objective, inf_pr, inf_du, μ, ‖d‖, regularisation, step sizes, ...
    pub fn record(&self) -> &'a IterationRecord {
        self.record
    }

    /// Iteration number (`record().iter`).
    pub fn iter(&self) -> usize {
        self.record.iter
    }

    /// True in the interior point's feasibility restoration phase; for the SQP, true in
    /// elastic mode (the step minimised the linearised ℓ1 infeasibility). Same as
    /// `record().restoration` (the 'r' of the log).
    pub fn in_restoration(&self) -> bool {
        self.record.restoration
    }

    /// The primal point in the user's variables (length n of the problem given to the
    /// solver): unscaled, fixed variables included, and for the interior point with
    /// `honor_original_bounds` clamped into the bounds as the returned solution would
    /// be. During restoration, the x part of the restoration problem's iterate. If the
    /// solve stops here, `Solution::x` equals this.
    pub fn x(&self) -> &'a [f64] {
        self.x
    }

    /// Constraint multipliers λ (length m, unscaled, IPOPT's sign convention as in
    /// [`Solution::lambda`](crate::Solution)); rows without bounds report 0. During
    /// interior-point restoration these are the restoration problem's multipliers of the
    /// same rows (IPOPT's convention), not estimates for the original problem.
    pub fn lambda(&self) -> &'a [f64] {
        self.lambda
    }

    /// Which phase of a [`solve_mpcc`](crate::solve_mpcc) run this is; `None` for a
    /// plain solve.
    pub fn phase(&self) -> Option<PhaseLabel> {
        self.phase
    }
}

/// The callback with the buffers of the user-space point, owned by one solve.
pub(crate) struct Observer<'c> {
    callback: &'c mut IterationCallback<'c>,
    x: Vec<f64>,
    lambda: Vec<f64>,
    /// User bounds to clamp x into (the interior point's `honor_original_bounds`).
    clamp: Option<(Vec<f64>, Vec<f64>)>,
    stopped: bool,
}

impl<'c> Observer<'c> {
    pub fn new(
        callback: &'c mut IterationCallback<'c>,
        n: usize,
        m: usize,
        clamp: Option<(&[f64], &[f64])>,
    ) -> Self {
        Observer {
            callback,
            x: vec![0.0; n],
            lambda: vec![0.0; m],
            clamp: clamp.map(|(l, u)| (l.to_vec(), u.to_vec())),
            stopped: false,
        }
    }

    /// True once the callback has asked to stop.
    pub fn stopped(&self) -> bool {
        self.stopped
    }

    /// Buffers for x and λ, to be filled by the solver before [`Observer::call`].
    pub fn buffers(&mut self) -> (&mut [f64], &mut [f64]) {
        (&mut self.x, &mut self.lambda)
    }

    /// Calls the callback with the buffers' point; returns (and remembers) a stop request.
    pub fn call(&mut self, record: &IterationRecord) -> bool {
        if let Some((l, u)) = &self.clamp {
            for ((x, l), u) in self.x.iter_mut().zip(l).zip(u) {
                *x = x.clamp(*l, *u);
            }
        }
        let view = IterationView {
            record,
            x: &self.x,
            lambda: &self.lambda,
            phase: None,
        };
        if (self.callback)(&view).is_break() {
            self.stopped = true;
        }
        self.stopped
    }

    /// The SQP's iterate (x already in user space, no fixed-variable reduction) with the
    /// multipliers of the scaled problem, unscaled by `sc`; cone rows report the cone
    /// multiplier (as `Solution` does).
    pub fn call_scaled(
        &mut self,
        record: &IterationRecord,
        x: &[f64],
        sc: &ScaledNlp<'_>,
        lambda_scaled: &[f64],
        cones: &[AffineCone],
        z_cone: &[f64],
    ) -> bool {
        self.x.copy_from_slice(x);
        sc.scaling.lambdas_to_user(lambda_scaled, &mut self.lambda);
        for c in cones {
            self.lambda[c.row] = sc.scaling.z_to_user(z_cone[c.offset]);
        }
        self.call(record)
    }
}
