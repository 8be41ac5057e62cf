//! A plant model for closed-loop simulation: the OCP's dynamics integrated numerically
//! over one sampling period with an explicit Runge–Kutta method.
use super::{ButcherTableau, Ocp, OcpError};
use symx::{Expr, Function, Matrix};

/// `x(t + dt)` from `x(t)` under a constant control: `steps` steps of an explicit
/// Runge–Kutta `tableau` on the OCP's dynamics (the same expressions as the multiple
/// shooting transcription with that tableau, compiled once as `F(x, u, p, dt)`). The
/// nominal plant of an MPC loop ([`crate::mpc::Mpc::run`]); a user's own plant (a
/// higher-fidelity model, a disturbance) plugs in the same place.
///
/// ```
/// use nlp::ocp::{ButcherTableau, Ocp, Simulator};
/// use symx::Matrix;
/// let mut ocp = Ocp::new(&["x"], &["u"]);
/// ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![u[0] - x[0]]));
/// let mut plant = Simulator::new(&ocp, ButcherTableau::rk4(), 10).unwrap();
/// let x1 = plant.step(&[1.0], &[0.0], 1.0).unwrap();
/// // ẋ = −x: x(1) = e⁻¹, to RK4's global error O(h⁴) with h = 0.1 (about 3e-7).
/// assert!((x1[0] - (-1.0f64).exp()).abs() < 1e-6);
/// ```
pub struct Simulator {
    step: Function,
    work: Vec<f64>,
    nx: usize,
    nu: usize,
    parameters: Vec<f64>,
}

impl Simulator {
    /// Compiles the integrator of `ocp`'s dynamics (its parameters at their declared
    /// values, changeable with [`Simulator::set_parameters`]). `steps ≥ 1`.
    pub fn new(ocp: &Ocp, tableau: ButcherTableau, steps: usize) -> Result<Simulator, OcpError> {
        if steps == 0 {
            return Err(OcpError::Invalid {
                what: "simulator".into(),
                why: "steps per period must be ≥ 1".into(),
            });
        }
        let dynamics = ocp.dynamics.as_ref().ok_or(OcpError::NoDynamics)?;
        let x = Matrix::sym_vec("x", ocp.nx());
        let u = Matrix::sym_vec("u", ocp.nu());
        let p = Matrix::sym_vec("p", ocp.np());
        let dt = Expr::sym("dt");
        let failure = std::cell::RefCell::new(None);
        let rhs = |z: &Matrix| match dynamics.eval(z, &u, &p) {
            Ok(f) => f,
            Err(e) => {
                failure.borrow_mut().get_or_insert(e);
                Matrix::zeros(ocp.nx(), 1)
            }
        };
        let x_end = tableau.integrate(&rhs, &x, dt, steps);
        if let Some(e) = failure.into_inner() {
            return Err(e);
        }
        if x_end.len() != ocp.nx() {
            return Err(OcpError::Size {
                what: "dynamics output".into(),
                expected: ocp.nx(),
                got: x_end.len(),
            });
        }
        let inputs: [(&str, &[Expr]); 4] = [("x", &x), ("u", &u), ("p", &p), ("dt", &[dt])];
        let step = Function::named("plant", &inputs, &[("x_next", &x_end)])?;
        let parameters = ocp.parameters.iter().flat_map(|(_, v)| v.clone()).collect();
        Ok(Simulator {
            work: vec![0.0; step.work_size()],
            step,
            nx: ocp.nx(),
            nu: ocp.nu(),
            parameters,
        })
    }

    /// Sets all parameter entries (stacked in declaration order, as the OCP's `p`).
    pub fn set_parameters(&mut self, p: &[f64]) -> Result<(), OcpError> {
        if p.len() != self.parameters.len() {
            return Err(OcpError::Size {
                what: "simulator parameters".into(),
                expected: self.parameters.len(),
                got: p.len(),
            });
        }
        self.parameters.copy_from_slice(p);
        Ok(())
    }

    /// Writes `x(t + dt)` into `next` from `x` under the control `u`; allocates nothing.
    pub fn step_into(
        &mut self,
        x: &[f64],
        u: &[f64],
        dt: f64,
        next: &mut [f64],
    ) -> Result<(), OcpError> {
        for (what, len, expected) in [
            ("plant state", x.len(), self.nx),
            ("plant control", u.len(), self.nu),
            ("plant next state", next.len(), self.nx),
        ] {
            if len != expected {
                return Err(OcpError::Size {
                    what: what.into(),
                    expected,
                    got: len,
                });
            }
        }
        if !(dt.is_finite() && dt > 0.0) {
            return Err(OcpError::Invalid {
                what: "plant step dt".into(),
                why: format!("{dt} is not finite and > 0"),
            });
        }
        let inputs: [&[f64]; 4] = [x, u, &self.parameters, &[dt]];
        self.step.eval(&inputs, &mut [next], &mut self.work)?;
        Ok(())
    }

    /// `x(t + dt)` from `x` under the control `u` (see [`Simulator::step_into`]).
    pub fn step(&mut self, x: &[f64], u: &[f64], dt: f64) -> Result<Vec<f64>, OcpError> {
        let mut next = vec![0.0; self.nx];
        self.step_into(x, u, dt, &mut next)?;
        Ok(next)
    }
}
