//! What the MPC examples share: a closed loop of an OCP whose initial state is the
//! parameter `x0`, on the nominal plant (the transcription's RK4 step), with its cost
//! `dt Σ_s l(x_s, u_s)` and a command line `[ipm|sqp|rti] [--jit] [--json]`.
use std::time::Instant;

use symnlp::nlp::mpc::{ClosedLoop, Mpc, MpcError};
use symnlp::nlp::ocp::{ButcherTableau, Method, Ocp, Simulator, Transcription};
use symnlp::nlp::{Ipm, Solver, Sqp, SqpOptions};
use symnlp::symx::{Evaluator, Expr, Function, Matrix};

/// One MPC example: the OCP (initial state the parameter `x0`), its grid and loop.
pub struct MpcExample {
    /// Name printed in the summary.
    pub name: &'static str,
    /// Intervals of the horizon.
    pub intervals: usize,
    /// Sampling period = one interval (s).
    pub dt: f64,
    /// Closed-loop steps.
    pub steps: usize,
    /// The plant's initial state.
    pub x_init: Vec<f64>,
    /// The stage cost `l(x, u)` (also in the OCP), for the closed-loop cost.
    pub stage_cost: fn(&Matrix, &Matrix) -> Expr,
    /// The OCP.
    pub ocp: fn() -> Result<Ocp, Box<dyn std::error::Error>>,
}

impl MpcExample {
    /// The transcription (RK4 multiple shooting, one step per interval) and the plant.
    pub fn setup(&self) -> Result<(Transcription, Simulator), Box<dyn std::error::Error>> {
        let ocp = (self.ocp)()?;
        let tr = ocp.transcribe(
            &Method::multiple_shooting(ButcherTableau::rk4(), 1),
            self.intervals,
        )?;
        Ok((tr, Simulator::new(&ocp, ButcherTableau::rk4(), 1)?))
    }

    /// The closed loop with `solver`.
    pub fn closed_loop(
        &self,
        solver: Box<dyn Solver>,
    ) -> Result<ClosedLoop, Box<dyn std::error::Error>> {
        self.closed_loop_with(|tr| Mpc::new(tr, solver))
    }

    /// The closed loop with real-time iterations (SQP defaults), the first step solved to
    /// convergence by the interior point, as CasADi's RTI loop in
    /// `benches/reference/mpc_casadi.py` does with its sqpmethod.
    pub fn closed_loop_rti(&self) -> Result<ClosedLoop, Box<dyn std::error::Error>> {
        self.closed_loop_with(|tr| Ok(self.controller(tr, "rti", false)?.0))
    }

    /// The closed loop with the controller `make` builds for the transcription.
    pub fn closed_loop_with(
        &self,
        make: impl FnOnce(&Transcription) -> Result<Mpc, MpcError>,
    ) -> Result<ClosedLoop, Box<dyn std::error::Error>> {
        let (tr, mut plant) = self.setup()?;
        let mut mpc = make(&tr)?;
        let dt = self.dt;
        Ok(mpc.run(&self.x_init, self.steps, |x, u, next| {
            plant.step_into(x, u, dt, next)
        })?)
    }

    /// The closed loop's cost `dt Σ_s l(x_s, u_s)`.
    pub fn cost(&self, run: &ClosedLoop) -> Result<f64, Box<dyn std::error::Error>> {
        let nx = self.x_init.len();
        let nu = run.controls.first().map_or(0, |u| u.len());
        let (x, u) = (Matrix::sym_vec("x", nx), Matrix::sym_vec("u", nu));
        let l = Function::new(&[&x, &u], &[&[(self.stage_cost)(&x, &u)]])?;
        let mut total = 0.0;
        for (x, u) in run.states.iter().zip(&run.controls) {
            total += l.call(&[x, u])?[0][0];
        }
        Ok(self.dt * total)
    }

    /// The controller `solver` (`"ipm"`, `"sqp"` or `"rti"`, as in [`MpcExample::main`])
    /// for `tr`, its functions compiled to machine code when `jit`
    /// ([`Mpc::with_evaluator`]); also returns the wall seconds of that compilation (0
    /// without `jit`).
    pub fn controller(
        &self,
        tr: &Transcription,
        solver: &str,
        jit: bool,
    ) -> Result<(Mpc, f64), MpcError> {
        let mpc = match solver {
            "rti" => Mpc::with_rti(tr, SqpOptions::default(), Box::new(Ipm::default()))?,
            "sqp" => Mpc::new(tr, Box::new(Sqp::default()))?,
            _ => Mpc::new(tr, Box::new(Ipm::default()))?,
        };
        if !jit {
            return Ok((mpc, 0.0));
        }
        let start = Instant::now();
        let mpc = mpc.with_evaluator(Evaluator::Jit)?;
        Ok((mpc, start.elapsed().as_secs_f64()))
    }

    /// `[ipm|sqp|rti] [--jit] [--json]`: runs the loop (with `--jit` on native
    /// evaluators, [`Mpc::with_evaluator`]); prints the steps as CSV (or one JSON summary
    /// line with `--json`, its `jit_compile_ms` the native compilation's wall time, not
    /// part of any step) on stdout and a summary on stderr.
    pub fn main(&self) -> Result<(), Box<dyn std::error::Error>> {
        let args: Vec<String> = std::env::args().skip(1).collect();
        let solver = ["rti", "sqp"]
            .into_iter()
            .find(|s| args.iter().any(|a| a == s))
            .unwrap_or("ipm");
        let jit = args.iter().any(|a| a == "--jit");
        let name = if jit {
            format!("{solver}_jit")
        } else {
            solver.to_string()
        };
        let mut jit_seconds = 0.0;
        let run = self.closed_loop_with(|tr| {
            let (mpc, seconds) = self.controller(tr, solver, jit)?;
            jit_seconds = seconds;
            Ok(mpc)
        })?;
        let (median, max) = run.latency();
        let (warm_median, warm_max) = run.warm_latency();
        // The steps after the first (RTI's first step is a converged solve).
        let later = ClosedLoop {
            steps: run.steps[1.min(run.steps.len())..].to_vec(),
            ..ClosedLoop::default()
        };
        let (feedback_median, feedback_max) = later.feedback_latency();
        let (later_median, _) = later.latency();
        let (mean_it, max_it) = run.iterations();
        let cost = self.cost(&run)?;
        if args.iter().any(|a| a == "--json") {
            let failed: Vec<usize> = (0..run.steps.len())
                .filter(|&s| !run.steps[s].succeeded())
                .collect();
            let summary = serde_json::json!({
                "problem": self.name, "solver": name, "closed_loop_cost": cost,
                "all_succeeded": run.all_succeeded(), "failed_steps": failed,
                "median_ms": 1e3 * median, "max_ms": 1e3 * max,
                "warm_median_ms": 1e3 * warm_median, "warm_max_ms": 1e3 * warm_max,
                "later_median_ms": 1e3 * later_median,
                "feedback_median_ms": 1e3 * feedback_median,
                "feedback_max_ms": 1e3 * feedback_max,
                "iterations_mean": mean_it, "iterations_max": max_it,
                "final_state": run.states.last(),
                "jit_compile_ms": 1e3 * jit_seconds,
            });
            println!("{summary}");
        } else {
            println!("step,status,iterations,ms,feedback ms,state...,control...");
            for (s, r) in run.steps.iter().enumerate() {
                let v: Vec<String> = run.states[s]
                    .iter()
                    .chain(&run.controls[s])
                    .map(|v| format!("{v:.6}"))
                    .collect();
                println!(
                    "{s},{},{},{:.3},{:.3},{}",
                    r.status,
                    r.iterations,
                    1e3 * r.seconds,
                    1e3 * r.feedback_seconds,
                    v.join(",")
                );
            }
        }
        eprintln!(
            "{} {name}: all succeeded {}, closed-loop cost {cost:.10}, latency median {:.3} ms max {:.3} ms (feedback median {:.3} ms after the first step), iterations mean {mean_it:.2} max {max_it}, jit compile {:.0} ms",
            self.name,
            run.all_succeeded(),
            1e3 * median,
            1e3 * max,
            1e3 * feedback_median,
            1e3 * jit_seconds,
        );
        Ok(())
    }
}
