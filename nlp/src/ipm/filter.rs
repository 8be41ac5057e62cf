//! The (θ, φ) filter of the line search (Wächter & Biegler 2006, §2.3).

/// A set of forbidden (θ, φ) corners: a trial is rejected if θ ≥ θ_j and φ ≥ φ_j for
/// some entry j.
#[derive(Debug, Clone, Default)]
pub struct Filter {
    entries: Vec<(f64, f64)>,
}

impl Filter {
    /// Removes all entries (done whenever μ changes).
    pub fn reset(&mut self) {
        self.entries.clear();
    }

    /// Number of entries.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True if empty.
    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// True if (θ, φ) is not dominated by any entry.
    pub fn acceptable(&self, theta: f64, phi: f64) -> bool {
        self.entries.iter().all(|&(t, p)| theta < t || phi < p)
    }

    /// Adds the corner (θ, φ), dropping entries it dominates.
    pub fn add(&mut self, theta: f64, phi: f64) {
        self.entries.retain(|&(t, p)| !(t >= theta && p >= phi));
        self.entries.push((theta, phi));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filter_dominance() {
        let mut f = Filter::default();
        assert!(f.acceptable(1.0, 1.0));
        f.add(1.0, 1.0);
        assert!(!f.acceptable(1.0, 1.0));
        assert!(!f.acceptable(2.0, 2.0));
        assert!(f.acceptable(0.5, 2.0));
        assert!(f.acceptable(2.0, 0.5));
        f.add(0.5, 0.5);
        assert_eq!(f.len(), 1);
        f.reset();
        assert!(f.is_empty());
    }
}
