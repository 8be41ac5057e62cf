//! The barrier function φ_μ of the barrier problem (Wächter & Biegler 2006, eq. (3)) with
//! IPOPT's damping of one-sided bounds (κ_d), used by the line search, the filter and the
//! restoration phase.

/// φ_μ(w) = f − μ Σ ln(slack) + κ_d μ Σ slack (one-sided bounds only).
#[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
pub(crate) fn barrier_value(
    w: &[f64],
    f: f64,
    mu: f64,
    kappa_d: f64,
    wl: &[f64],
    wu: &[f64],
    has_l: &[bool],
    has_u: &[bool],
) -> f64 {
    let kd = kappa_d * mu;
    let mut phi = f;
    for j in 0..w.len() {
        if has_l[j] {
            let s = w[j] - wl[j];
            phi -= mu * s.ln();
            if !has_u[j] {
                phi += kd * s;
            }
        }
        if has_u[j] {
            let s = wu[j] - w[j];
            phi -= mu * s.ln();
            if !has_l[j] {
                phi += kd * s;
            }
        }
    }
    phi
}
