//! The user's f, g, ∇f and J (unscaled) at the last point they were evaluated at, as
//! IPOPT's cached results (`IpOrigIpoptNLP`): a value asked for again at the same point
//! (bit for bit) is not evaluated again. This is how the end of a solve reports f, g and
//! the KKT measures at the final point without evaluating there a second time, and how
//! the start of an IPM solve shares the evaluations of its scaling and its initial point.
//! The values are those the evaluation returned, so reusing them changes no result.

/// Which value of the problem.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Value {
    /// The objective f.
    F,
    /// The rows g.
    G,
    /// The gradient ∇f.
    Grad,
    /// The Jacobian's values, in the user's pattern order.
    Jac,
}

impl Value {
    fn index(self) -> usize {
        self as usize
    }
}

/// The values known at one point (see the module doc); empty at the start of a solve.
#[derive(Default)]
pub(crate) struct PointValues {
    /// The point of the values marked known.
    x: Vec<f64>,
    /// Which of f, g, ∇f, J (in [`Value`]'s order) are known at `x`.
    known: [bool; 4],
    f: f64,
    g: Vec<f64>,
    grad: Vec<f64>,
    jac: Vec<f64>,
}

impl PointValues {
    /// Nothing known, vectors sized for `n` variables, `m` rows and `nnz_jac` Jacobian
    /// entries (keeping their capacity).
    pub(crate) fn reset(&mut self, n: usize, m: usize, nnz_jac: usize) {
        self.known = [false; 4];
        self.x.clear();
        self.f = f64::NAN;
        for (v, len) in [
            (&mut self.g, m),
            (&mut self.grad, n),
            (&mut self.jac, nnz_jac),
        ] {
            v.clear();
            v.resize(len, 0.0);
        }
    }

    /// Whether `value` is known at `x` (same bits).
    pub(crate) fn has(&self, value: Value, x: &[f64]) -> bool {
        self.known[value.index()] && same_bits(&self.x, x)
    }

    /// Makes `x` the point of the values: when it is another point, everything known at
    /// the old one is forgotten.
    fn move_to(&mut self, x: &[f64]) {
        if !same_bits(&self.x, x) {
            self.known = [false; 4];
            self.x.clear();
            self.x.extend_from_slice(x);
        }
    }

    /// Stores f(x).
    pub(crate) fn store_f(&mut self, x: &[f64], f: f64) {
        self.move_to(x);
        self.f = f;
        self.known[Value::F.index()] = true;
    }

    /// The vector of `value` (not `F`) at `x`, to be written by its evaluation and
    /// marked known: everything known at another point is forgotten first.
    pub(crate) fn store(&mut self, value: Value, x: &[f64]) -> &mut [f64] {
        self.move_to(x);
        self.known[value.index()] = true;
        match value {
            Value::G => &mut self.g,
            Value::Grad => &mut self.grad,
            Value::Jac => &mut self.jac,
            Value::F => unreachable!("f is stored by store_f"),
        }
    }

    /// The vectors of ∇f and J at `x`, to be written by one evaluation and both marked
    /// known (as [`PointValues::store`]).
    pub(crate) fn store_grad_jac(&mut self, x: &[f64]) -> (&mut [f64], &mut [f64]) {
        self.move_to(x);
        self.known[Value::Grad.index()] = true;
        self.known[Value::Jac.index()] = true;
        (&mut self.grad, &mut self.jac)
    }

    /// f at the point (meaningful when [`PointValues::has`] says so).
    pub(crate) fn f(&self) -> f64 {
        self.f
    }

    /// g at the point.
    pub(crate) fn g(&self) -> &[f64] {
        &self.g
    }

    /// ∇f at the point.
    pub(crate) fn grad(&self) -> &[f64] {
        &self.grad
    }

    /// J's values at the point.
    pub(crate) fn jac(&self) -> &[f64] {
        &self.jac
    }
}

/// Whether `a` and `b` hold the same numbers bit for bit.
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[cfg(test)]
mod tests {
    use super::{PointValues, Value};

    #[test]
    fn values_are_known_at_their_point_only_and_forgotten_when_it_moves() {
        let mut pv = PointValues::default();
        pv.reset(2, 1, 2);
        let (x, y) = ([1.0, 2.0], [1.0, 2.0 + f64::EPSILON * 2.0]);
        assert!(!pv.has(Value::F, &x), "nothing known after a reset");
        pv.store_f(&x, 5.0);
        pv.store(Value::G, &x)[0] = 3.0;
        assert!(pv.has(Value::F, &x) && pv.has(Value::G, &x));
        assert!(!pv.has(Value::Grad, &x) && !pv.has(Value::F, &y));
        assert_eq!((pv.f(), pv.g()), (5.0, &[3.0][..]));
        pv.store(Value::Jac, &y).copy_from_slice(&[7.0, 8.0]);
        assert!(pv.has(Value::Jac, &y) && !pv.has(Value::F, &x) && !pv.has(Value::G, &y));
        assert_eq!(pv.jac(), &[7.0, 8.0]);
        // −0.0 and 0.0 compare equal but are other bits: another point for the cache.
        pv.store_f(&[0.0, 1.0], 1.0);
        assert!(!pv.has(Value::F, &[-0.0, 1.0]));
        pv.reset(2, 1, 2);
        assert!(!pv.has(Value::Jac, &y));
    }
}
