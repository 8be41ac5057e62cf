//! The user's problem as the SQP sees it: objective and rows scaled, evaluations counted
//! and timed.

use std::time::Instant;

use crate::numeric::NumericNlp;

/// Evaluation counters.
#[derive(Default, Clone)]
pub(super) struct Counters {
    pub f: usize,
    pub grad_f: usize,
    pub g: usize,
    pub jac_g: usize,
    pub hess_l: usize,
    pub seconds: f64,
}

/// The user's problem with scaling, counters and timing.
pub(super) struct Scaled<'a> {
    pub nlp: &'a mut dyn NumericNlp,
    pub obj_scale: f64,
    pub g_scale: Vec<f64>,
    pub counters: Counters,
}

impl Scaled<'_> {
    pub fn f(&mut self, x: &[f64]) -> f64 {
        let t = Instant::now();
        let v = self.nlp.eval_f(x) * self.obj_scale;
        self.counters.f += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
        v
    }
    pub fn grad(&mut self, x: &[f64], out: &mut [f64]) {
        let t = Instant::now();
        self.nlp.eval_grad_f(x, out);
        out.iter_mut().for_each(|v| *v *= self.obj_scale);
        self.counters.grad_f += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
    }
    pub fn g(&mut self, x: &[f64], out: &mut [f64], cone: &mut [f64]) {
        let t = Instant::now();
        self.nlp.eval_g(x, out);
        for (v, s) in out.iter_mut().zip(&self.g_scale) {
            *v *= s;
        }
        if !cone.is_empty() {
            self.nlp.eval_cone_entries(x, cone);
        }
        self.counters.g += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
    }
    pub fn jac(&mut self, x: &[f64], out: &mut [f64], cone_jac: &mut [f64]) {
        let t = Instant::now();
        self.nlp.eval_jac_g(x, out);
        let p = self.nlp.jac_g_sparsity();
        let rows = p.row_idx();
        for (v, &r) in out.iter_mut().zip(rows) {
            *v *= self.g_scale[r];
        }
        if !cone_jac.is_empty() {
            self.nlp.eval_cone_jac(x, cone_jac);
        }
        self.counters.jac_g += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
    }
    /// Hessian of the scaled Lagrangian f̃ + λ̃ᵀg̃.
    pub fn hess(&mut self, x: &[f64], lambda: &[f64], out: &mut [f64]) {
        let t = Instant::now();
        let l: Vec<f64> = lambda
            .iter()
            .zip(&self.g_scale)
            .map(|(l, s)| l * s)
            .collect();
        self.nlp.eval_hess_l(x, self.obj_scale, &l, out);
        self.counters.hess_l += 1;
        self.counters.seconds += t.elapsed().as_secs_f64();
    }
}
