//! Convexification of the SQP Hessian: B = ∇²L + δI + ρ_a·(J_AᵀJ_A + I_b) positive
//! definite over the strongly active rows and bounds A, certified by inertia.

use super::geometry::Geometry;
use super::iterate::Mult;
use super::options::SqpOptions;
use super::shape::Shape;
use crate::frontend::scaled::refill;
use crate::kkt::Kkt;

/// The Hessian term B of the QP and how it was convexified.
pub(super) struct Curvature {
    /// Lower-triangular ∇²L values.
    pub hv: Vec<f64>,
    /// Dense B, column-major (BFGS only; empty otherwise).
    pub bfgs: Vec<f64>,
    /// ρ_a on the active rows, 0 elsewhere.
    pub row_weight: Vec<f64>,
    /// ρ_a on the active bounds, 0 elsewhere.
    pub bound_weight: Vec<f64>,
    pub rho_a_last: f64,
    pub delta_last: f64,
    /// Proximal shift added after rejected or heavily cut steps.
    pub extra_shift: f64,
}

impl Curvature {
    /// No curvature yet: B = I for BFGS, no weights, no shifts.
    pub(super) fn new(shape: &Shape) -> Curvature {
        let mut c = Curvature {
            hv: Vec::new(),
            bfgs: Vec::new(),
            row_weight: Vec::new(),
            bound_weight: Vec::new(),
            rho_a_last: 0.0,
            delta_last: 0.0,
            extra_shift: 0.0,
        };
        c.reset(shape);
        c
    }

    /// Back to [`Curvature::new`]'s state for `shape`, in these vectors.
    pub(super) fn reset(&mut self, shape: &Shape) {
        let n = shape.n;
        refill(&mut self.hv, shape.hp.row_idx().len(), 0.0);
        self.bfgs.clear();
        if shape.dense {
            self.bfgs
                .extend((0..n * n).map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 }));
        }
        refill(&mut self.row_weight, shape.m, 0.0);
        refill(&mut self.bound_weight, n, 0.0);
        self.rho_a_last = 0.0;
        self.delta_last = 0.0;
        self.extra_shift = 0.0;
    }
}

/// Which rows of g and which variable bounds count as active for the
/// augmented-Lagrangian convexification: equality rows, and inequality rows and bounds
/// whose multiplier is nonzero with the sign of an active side (strongly active).
///
/// A row or bound merely at its bound, or with a multiplier of the wrong sign, is left
/// out: the term ½ρ_a(J_i d)² penalises leaving the constraint in both directions, so on
/// a constraint the step should leave it acts as a proximal term of weight ρ_a and the
/// iterates creep (the gap-crossing planner crawled at ‖d‖ ≈ 1e-4 for 3000 iterations
/// with complementarity error 5e3 when "at the bound" counted as active).
/// Written into `(rows, bounds)` (resized; no allocation once grown to m and n).
pub(super) fn active_sets_into(
    geo: &Geometry,
    x: &[f64],
    g: &[f64],
    mult: &Mult,
    (rows, bounds): &mut (Vec<bool>, Vec<bool>),
) {
    const TOL: f64 = 1e-6;
    // "Nearly at the bound": a multiplier left on a row the iterate has moved away from
    // (e.g. the share ρ_a·J_i d of the last step) must not keep the row active.
    let near = |a: f64, b: f64| (a - b).abs() <= 1e-3 * (1.0 + b.abs());
    rows.clear();
    rows.extend((0..g.len()).map(|i| {
        !geo.cone_row[i]
            && (geo.g_l[i] == geo.g_u[i]
                || (geo.g_u[i].is_finite() && mult.lambda[i] > TOL && near(g[i], geo.g_u[i]))
                || (geo.g_l[i].is_finite() && mult.lambda[i] < -TOL && near(g[i], geo.g_l[i])))
    }));
    bounds.clear();
    bounds.extend((0..x.len()).map(|j| {
        (geo.x_l[j].is_finite() && mult.z_l[j] > TOL && near(x[j], geo.x_l[j]))
            || (geo.x_u[j].is_finite() && mult.z_u[j] > TOL && near(x[j], geo.x_u[j]))
    }));
}

/// The diagonals of the inertia tests, kept between tests (no allocation once grown).
#[derive(Default)]
pub(super) struct ConvexifyScratch {
    dx: Vec<f64>,
    dc: Vec<f64>,
}

/// Finds B = H + δI + ρ_a·(J_Aᵀ J_A + I_bounds) positive definite, where A are the active
/// rows and bounds. By the Schur complement, B is positive definite iff
/// `[H + δI + ρ_a·I_b, J_Aᵀ; J_A, −I/ρ_a]` (inactive rows with a negligible −1e20 pivot)
/// has inertia (n, m, 0) — the test IPOPT applies to its KKT matrix, counted from a faer
/// LDLᵀ ([`Kkt`]). Order: (0, 0) unless the last iteration needed ρ_a > 0; (0, ρ₀) with
/// ρ₀ = max(1, ρ_last/10); then δ by IPOPT's sequence with the test at ρ_a =
/// `max_augmented_weight` (positive definite on the null space of the active
/// constraints, so the QP keeps the Newton step there: for d with J_A d = −c_A the
/// augmented term is constant); then the smallest ρ_a = ρ₀·10^k passing at that δ.
pub(super) struct Convexify<'a> {
    pub kkt: &'a mut Kkt,
    pub hv: &'a [f64],
    pub jv: &'a [f64],
    pub active_r: &'a [bool],
    pub active_b: &'a [bool],
}

/// The smallest shift δ for which `test(δ)` holds, by IPOPT's sequence: 0 (when
/// `allow_zero`), then `first_hessian_shift` or δ_last/3, ×100 at first, ×8 after, up to
/// `max_hessian_shift`.
fn shift_search(
    o: &SqpOptions,
    delta_last: f64,
    test: &mut dyn FnMut(f64) -> bool,
    allow_zero: bool,
) -> Option<f64> {
    if allow_zero && test(0.0) {
        return Some(0.0);
    }
    let mut delta = if delta_last == 0.0 {
        o.first_hessian_shift
    } else {
        (delta_last / 3.0).max(o.min_hessian_shift)
    };
    let grow = if delta_last == 0.0 { 100.0 } else { 8.0 };
    while delta <= o.max_hessian_shift {
        if test(delta) {
            return Some(delta);
        }
        delta *= grow;
    }
    None
}

impl Convexify<'_> {
    /// Whether B = H + δI + ρ·(J_AᵀJ_A + I_b) is positive definite: the inertia of
    /// `[H + δI + ρ·I_b, J_Aᵀ; J_A, −I/ρ]` is (n, m) (inactive rows decoupled by a huge
    /// diagonal). Counts the factorisation in `n_fact`.
    fn positive_definite(
        &mut self,
        delta: f64,
        rho: f64,
        n_fact: &mut usize,
        scratch: &mut ConvexifyScratch,
    ) -> bool {
        let (n, m) = (self.kkt.n(), self.kkt.m());
        *n_fact += 1;
        let active_b = self.active_b;
        let active_r = self.active_r;
        let ConvexifyScratch { dx, dc } = scratch;
        dx.clear();
        dx.extend((0..n).map(|j| delta + if active_b[j] { rho } else { 0.0 }));
        dc.clear();
        dc.extend((0..m).map(|i| {
            if rho > 0.0 && active_r[i] {
                1.0 / rho
            } else {
                1e20
            }
        }));
        matches!(self.kkt.factorize(self.hv, dx, self.jv, dc),
            Ok(i) if i.positive == n && i.negative == m)
    }

    /// The (δ, ρ_a) found, or `None` when no shift up to `max_hessian_shift` works;
    /// counts the factorisations in `n_fact`. δ is the shift the inertia asks for, no
    /// more: the step control's proximal shift is the caller's, applied on top (mixing it
    /// into `delta_last` made one cut step damp the next iterations through the δ/3
    /// memory, see `SqpState::convexify`).
    /// `(delta_last, rho_last)`: the last iteration's; the diagonals of the tests are in
    /// `scratch`'s vectors.
    pub fn run_in(
        mut self,
        o: &SqpOptions,
        (delta_last, rho_last): (f64, f64),
        n_fact: &mut usize,
        sc: &mut ConvexifyScratch,
    ) -> Option<(f64, f64)> {
        if rho_last == 0.0 && self.positive_definite(0.0, 0.0, n_fact, sc) {
            return Some((0.0, 0.0));
        }
        let any_active = self.active_r.iter().chain(self.active_b).any(|&a| a);
        if !any_active {
            let mut test = |d| self.positive_definite(d, 0.0, n_fact, sc);
            return shift_search(o, delta_last, &mut test, true).map(|d| (d, 0.0));
        }
        // The cheapest guess first: the last iteration's weight (or a tenth of it).
        let rho0 = if rho_last > 0.0 {
            (rho_last / 10.0).max(1.0)
        } else {
            1.0
        };
        if self.positive_definite(0.0, rho0, n_fact, sc) {
            return Some((0.0, rho0));
        }
        // δ for the reduced Hessian: the test in the limit ρ_a = rho_max is IPOPT's
        // inertia test of [H + δI, J_Aᵀ; J_A, −I/rho_max] (active bounds nearly fixed),
        // i.e. positive definiteness on the null space of the active constraints. A
        // shift of the full-space Hessian (ρ_a = 0) would also pay for curvature across
        // the constraints, which the augmented term supplies for free.
        let rho_max = o.max_augmented_weight;
        let mut test = |d| self.positive_definite(d, rho_max, n_fact, sc);
        let delta = shift_search(o, delta_last, &mut test, true)?;
        // Then the smallest weight ρ_a (×10 from rho0) that makes B itself positive
        // definite; rho_max passed above.
        let mut rho = if delta == 0.0 { rho0 * 10.0 } else { rho0 };
        while rho < rho_max {
            if self.positive_definite(delta, rho, n_fact, sc) {
                return Some((delta, rho));
            }
            rho *= 10.0;
        }
        Some((delta, rho_max))
    }
}
