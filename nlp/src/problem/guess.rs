//! Helpers for initial guesses and parameter sweeps.

/// `count` evenly spaced numbers from `start` to `end`, both included (numpy's and
/// CasADi's `linspace`): `[start]` for `count = 1`, empty for `count = 0`.
///
/// ```
/// assert_eq!(nlp::linspace(0.0, 1.0, 5), [0.0, 0.25, 0.5, 0.75, 1.0]);
/// assert_eq!(nlp::linspace(1.0, 0.5, 3), [1.0, 0.75, 0.5]);
/// assert_eq!(nlp::linspace(2.0, 3.0, 1), [2.0]);
/// assert!(nlp::linspace(2.0, 3.0, 0).is_empty());
/// assert_eq!(*nlp::linspace(0.0, 0.3, 7).last().unwrap(), 0.3); // the end exactly
/// ```
pub fn linspace(start: f64, end: f64, count: usize) -> Vec<f64> {
    match count {
        0 => Vec::new(),
        1 => vec![start],
        _ => {
            let step = (end - start) / (count - 1) as f64;
            let mut v: Vec<f64> = (0..count).map(|i| start + step * i as f64).collect();
            v[count - 1] = end; // exactly, whatever the rounding of the steps
            v
        }
    }
}
