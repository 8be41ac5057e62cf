//! The planner's frame: every scenario is planned translated so that its start foot BR
//! stands at x = y = 0, and the plan is translated back.
//!
//! The model's lengths are translation-invariant, but floating point, the solver's bound
//! relaxation (relative to each bound's magnitude) and every decision taken on numbers
//! are not: the default scenario shifted by +100 m in x used to fail ("initial guess puts
//! foot FR in the keep-out", a foot at a region bound relaxed by 1e-8·102 m) and shifted
//! by +50 m it solved to a different objective. Planning in the start's frame makes the
//! outcome independent of where the world origin is, up to the round-off of the shift
//! itself (a scenario whose start foot BR is already at the origin is planned unchanged).
use crate::plan::Plan;
use crate::scenario::{Foot, Scenario, TerrainSpec, Vec3};

/// The horizontal translation that moves `s`'s start foot BR to the origin.
pub fn offset(s: &Scenario) -> [f64; 2] {
    let p = s.start.feet.get(Foot::BR);
    [-p[0], -p[1]]
}

fn shift(p: &mut Vec3, d: [f64; 2]) {
    p[0] += d[0];
    p[1] += d[1];
}

/// `s` translated horizontally by `d` (m): start, goal and terrain.
pub fn translated(s: &Scenario, d: [f64; 2]) -> Scenario {
    let mut t = s.clone();
    for p in [
        &mut t.start.com.b,
        &mut t.start.com.f,
        &mut t.start.feet.br,
        &mut t.start.feet.bl,
        &mut t.start.feet.fr,
        &mut t.start.feet.fl,
        &mut t.goal.b,
        &mut t.goal.f,
    ] {
        shift(p, d);
    }
    t.gap.min += d[0];
    t.gap.max += d[0];
    match &mut t.terrain {
        TerrainSpec::Gap => {}
        TerrainSpec::Step { edge, .. } => *edge += d[0],
        TerrainSpec::Gaps { gaps } => {
            for g in gaps {
                g.min += d[0];
                g.max += d[0];
            }
        }
        TerrainSpec::Stones { stones } => {
            for b in stones {
                b[0] += d[0];
                b[1] += d[0];
                b[2] += d[1];
                b[3] += d[1];
            }
        }
        TerrainSpec::HeightMap { origin, .. } => {
            origin[0] += d[0];
            origin[1] += d[1];
        }
    }
    t
}

/// `plan` translated horizontally by `d` (m): CoMs and feet (forces are vectors).
pub fn translate_plan(plan: &mut Plan, d: [f64; 2]) {
    for st in &mut plan.stances {
        for p in [
            &mut st.com.b,
            &mut st.com.f,
            &mut st.feet.br,
            &mut st.feet.bl,
            &mut st.feet.fr,
            &mut st.feet.fl,
        ] {
            shift(p, d);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Translating there and back returns the scenario up to the round-off of the
    /// shift (1e-13 m for 100 m), and the default is its own frame.
    #[test]
    fn there_and_back() {
        let s = Scenario::default();
        assert_eq!(offset(&s), [0.0, 0.0]);
        let mut stones = s.clone();
        stones
            .apply_overrides(&["terrain={kind=\"stones\", stones=[[-1.0, 2.0, -1.0, 2.0]]}"])
            .unwrap();
        for s in [s, stones] {
            let t = translated(&s, [100.0, -4.0]);
            assert_eq!(offset(&t), [-100.0, 4.0]);
            assert_ne!(t, s);
            let back = translated(&t, offset(&t));
            for ((name, a), (_, b)) in back.numbers().into_iter().zip(s.numbers()) {
                assert!((a - b).abs() < 1e-13, "{name}: {a} against {b}");
            }
            assert_eq!(back.terrain.kind(), s.terrain.kind());
        }
    }
}
