//! Solves with the factor of K and residual-checked iterative refinement, also of the
//! shifted system K + diag(shift) (to remove a static regularisation from a step).

use super::error::KktError;
use super::system::Kkt;

/// Residual ratio below which refinement stops even while it still improves (the
/// default of [`Kkt::residual_ratio_floor`]).
pub(super) const REFINEMENT_FLOOR: f64 = 1e-14;

/// Max-norm of `v`.
pub(super) fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, &b| a.max(b.abs()))
}

/// The work vectors of one refined solve, in the factor's space: right-hand side `b`,
/// solution `x`, residual `r` and correction `d`.
struct Work {
    b: Vec<f64>,
    x: Vec<f64>,
    r: Vec<f64>,
    d: Vec<f64>,
}

impl Kkt {
    /// Solves K x = rhs in place with residual-checked iterative refinement.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<f64, KktError> {
        self.solve_shifted(rhs, None)
    }

    /// Solves (K + diag(shift)) x = rhs in place, using the factor of K as preconditioner
    /// of iterative refinement (e.g. to remove a static regularisation from the step).
    /// Returns the final relative residual.
    pub fn solve_shifted(
        &mut self,
        rhs: &mut [f64],
        shift: Option<&[f64]>,
    ) -> Result<f64, KktError> {
        if !self.factored {
            return Err(KktError::NotFactorized);
        }
        let dim = self.dim();
        if rhs.len() != dim {
            return Err(KktError::Length {
                what: "rhs",
                expected: dim,
                got: rhs.len(),
            });
        }
        if let Some(s) = shift {
            if s.len() != dim {
                return Err(KktError::Length {
                    what: "shift",
                    expected: dim,
                    got: s.len(),
                });
            }
        }
        let mut w = Work {
            b: std::mem::take(&mut self.wb),
            x: std::mem::take(&mut self.wx),
            r: std::mem::take(&mut self.wr),
            d: std::mem::take(&mut self.wd),
        };
        // The simplicial factor works in the AMD-permuted space: permute in (and out at
        // the end); refinement runs there too, on the permuted K.
        let mut pshift = Vec::new();
        let shift = match self.simplicial.as_mut() {
            Some(simp) => {
                for (w, &o) in w.b.iter_mut().zip(&simp.fwd) {
                    *w = rhs[o];
                }
                match shift {
                    Some(s) => {
                        pshift = std::mem::take(&mut simp.pshift);
                        for (w, &o) in pshift.iter_mut().zip(&simp.fwd) {
                            *w = s[o];
                        }
                        Some(&pshift[..])
                    }
                    None => None,
                }
            }
            None => {
                w.b.copy_from_slice(rhs);
                shift
            }
        };
        let ratio = self.refine(&mut w, shift);
        match self.simplicial.as_mut() {
            Some(simp) => {
                for (&v, &o) in w.x.iter().zip(&simp.fwd) {
                    rhs[o] = v;
                }
                if !pshift.is_empty() {
                    simp.pshift = pshift;
                }
            }
            None => rhs.copy_from_slice(&w.x),
        }
        self.wb = w.b;
        self.wx = w.x;
        self.wr = w.r;
        self.wd = w.d;
        self.last_residual_ratio = ratio;
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(KktError::NonFinite);
        }
        Ok(ratio)
    }

    /// x = K⁻¹b refined against K + diag(shift) (see [`refine`]); returns the ratio.
    fn refine(&mut self, w: &mut Work, shift: Option<&[f64]>) -> f64 {
        let limits = RefineLimits::of(self);
        let Work { b, x, r, d } = w;
        match refine(&mut Plain { kkt: self, shift }, limits, b, x, r, d) {
            Ok(ratio) => ratio,
            Err(never) => match never {},
        }
    }
}

/// The operator iterative refinement works on: K (+ shift) and an approximate solve
/// with it (the factorisation of K, or of K plus a low-rank term).
pub(super) trait Refinable {
    /// Why an application can fail.
    type Error;
    /// r = K x.
    fn apply(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Self::Error>;
    /// v ← an approximate K⁻¹ v.
    fn approx_solve(&mut self, v: &mut [f64]) -> Result<(), Self::Error>;
}

/// The factorised K with an optional diagonal shift, as [`Refinable`].
struct Plain<'a> {
    kkt: &'a mut Kkt,
    shift: Option<&'a [f64]>,
}

impl Refinable for Plain<'_> {
    type Error = std::convert::Infallible;
    fn apply(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Self::Error> {
        self.kkt.matvec(x, self.shift, r);
        Ok(())
    }
    fn approx_solve(&mut self, v: &mut [f64]) -> Result<(), Self::Error> {
        self.kkt.raw_solve(v);
        Ok(())
    }
}

/// The refinement settings of a [`Kkt`].
#[derive(Clone, Copy)]
pub(super) struct RefineLimits {
    residual_ratio_max: f64,
    residual_ratio_floor: f64,
    min_steps: usize,
    max_steps: usize,
}

impl RefineLimits {
    pub(super) fn of(kkt: &Kkt) -> RefineLimits {
        RefineLimits {
            residual_ratio_max: kkt.residual_ratio_max,
            residual_ratio_floor: kkt.residual_ratio_floor,
            min_steps: kkt.min_refinement_steps,
            max_steps: kkt.max_refinement_steps,
        }
    }
}

/// x = K⁻¹b by `op`'s approximate solve, refined against `op`'s K until the residual ratio
/// meets the target (see below) or stops improving; returns the ratio. `r` and `d` are
/// work vectors of K's dimension.
pub(super) fn refine<R: Refinable>(
    op: &mut R,
    limits: RefineLimits,
    b: &[f64],
    x: &mut [f64],
    r: &mut [f64],
    d: &mut [f64],
) -> Result<f64, R::Error> {
    let b_norm = inf_norm(b);
    x.copy_from_slice(b);
    op.approx_solve(x)?;
    let mut ratio = f64::INFINITY;
    let mut steps = 0;
    loop {
        op.apply(x, r)?;
        for (r, b) in r.iter_mut().zip(b.iter()) {
            *r = b - *r;
        }
        // IPOPT's residual ratio ‖r‖ / (min(‖x‖, 10⁶‖b‖) + ‖b‖): the cap on ‖x‖ keeps
        // a huge solution of a (nearly) singular system from looking accurate.
        let r_norm = inf_norm(r);
        let denom = inf_norm(x).min(1e6 * b_norm) + b_norm;
        let new_ratio = if denom > 0.0 { r_norm / denom } else { r_norm };
        if !new_ratio.is_finite() {
            break;
        }
        if steps > 0 && new_ratio >= ratio {
            // Refinement stopped improving: undo the last correction.
            for (x, d) in x.iter_mut().zip(d.iter()) {
                *x -= d;
            }
            break;
        }
        // The ratio is a backward error dominated by the largest entries of x: on an
        // ill-conditioned K (huge multipliers) it can pass the target while the small
        // entries are still far off. So keep refining past the target while a step
        // still gains a lot (at most ½ of the previous ratio) and the ratio is above
        // the floor (round-off by default); a well-conditioned system reaches round-off
        // in one step.
        let fast = new_ratio <= 0.5 * ratio;
        ratio = new_ratio;
        let converged = ratio <= limits.residual_ratio_max
            && (ratio <= limits.residual_ratio_floor || (steps > 0 && !fast));
        if (steps >= limits.min_steps && converged) || steps >= limits.max_steps {
            break;
        }
        d.copy_from_slice(r);
        op.approx_solve(d)?;
        for (x, d) in x.iter_mut().zip(d.iter()) {
            *x += d;
        }
        steps += 1;
    }
    Ok(ratio)
}
