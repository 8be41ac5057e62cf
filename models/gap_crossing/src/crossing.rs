//! The crossing search: at which of its moves each foot first lands beyond each gap,
//! decided by comparing solved plans.
//!
//! In a solved plan of a schedule, each foot has a sequence of footholds (the start,
//! then one per move of its own), each in one allowed region of the terrain (the model
//! keeps it there, `model::build`). A *crossing* is a move whose foothold lies in
//! another region than the one before. The guess (`gait::footholds_for_schedule`)
//! crosses at the first move from which the far region is within one jump *of the
//! guess's footholds*; the solver then moves footholds, and a foot often ends pressed
//! against the near edge of the keep-out, where crossing one move earlier may be
//! possible and cheaper.
//!
//! [`earlier_crossings`] builds, for every foot and every crossing of it, the candidate
//! in which that foot crosses **one move earlier**: its footholds from the move before
//! the crossing on are shifted one move earlier (the crossing foothold moves to the
//! move before, and so on; its last foothold is kept), everything else of the plan kept,
//! CoMs and forces of the changed stances re-guessed. Each candidate's region
//! assignment is a different choice of the disjunction "x ≤ lo or x ≥ hi" for one
//! foothold. Candidates are solved (`crate::solve`) and the best plan by objective among
//! those that succeed and reach the goal is kept: a local search over crossing stances
//! scored by the NLP itself.
use crate::gait;
use crate::plan::Plan;
use crate::scenario::{Foot, Scenario};
use crate::terrain::{Region, Terrain};

/// A candidate is built only when the foothold that becomes the earlier crossing is
/// within this multiple of the step reach of the foothold before it.
pub const CANDIDATE_REACH: f64 = 1.15;

/// Index of the region holding `(x, y)` (tolerance `tol`), if any.
fn region_of(regions: &[Region], p: [f64; 3], tol: f64) -> Option<usize> {
    regions.iter().position(|r| r.contains(p[0], p[1], tol))
}

/// One candidate of the crossing search.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// The foot that crosses earlier.
    pub foot: Foot,
    /// Transition (0-based) of the move at which it now crosses.
    pub transition: usize,
    /// The candidate plan (a guess: it may violate (5) at the new crossing).
    pub plan: Plan,
}

/// The candidates described in the module docs, for plan `plan` of `schedule`.
pub fn earlier_crossings(
    s: &Scenario,
    terrain: &dyn Terrain,
    plan: &Plan,
    schedule: &[Foot],
) -> Vec<Candidate> {
    let regions = terrain.regions();
    let reach = s.step_radius_sq.sqrt();
    let mut out = Vec::new();
    for i in Foot::ALL {
        // Transitions at which foot i moves, and its footholds after each.
        let moves: Vec<usize> = (0..schedule.len()).filter(|&t| schedule[t] == i).collect();
        let holds: Vec<[f64; 3]> = std::iter::once(plan.stances[0].feet.get(i))
            .chain(moves.iter().map(|&t| plan.stances[t + 1].feet.get(i)))
            .collect();
        let zone: Vec<Option<usize>> = holds
            .iter()
            .map(|&p| region_of(&regions, p, crate::model::KEEP_OUT_SNAP))
            .collect();
        // Crossing at foothold m (m ≥ 2: foothold m − 1 is a variable, not the start).
        for m in 2..holds.len() {
            if zone[m] == zone[m - 1] {
                continue;
            }
            // The earlier crossing must be nearly within reach of the foothold before
            // it (the solve then moves both): a candidate farther off is infeasible in
            // practice and costs a full solve to find out.
            let d = (0..3)
                .map(|c| (holds[m][c] - holds[m - 2][c]).powi(2))
                .sum::<f64>()
                .sqrt();
            if d > CANDIDATE_REACH * reach {
                continue;
            }
            let mut new_holds = holds.clone();
            new_holds[m - 1..holds.len() - 1].copy_from_slice(&holds[m..]);
            let mut candidate = plan.clone();
            let first = moves[m - 2] + 1; // the stance after the earlier crossing move
            for (k, st) in candidate.stances.iter_mut().enumerate().skip(first) {
                let made = moves.iter().filter(|&&t| t < k).count();
                let p = new_holds[made];
                if st.feet.get(i) == p {
                    continue;
                }
                *st.feet.get_mut(i) = p;
                st.com = gait::coms_for(s, &st.feet);
                st.forces = gait::balance_forces(s, &st.com, &st.feet);
            }
            out.push(Candidate {
                foot: i,
                transition: moves[m - 2],
                plan: candidate,
            });
        }
    }
    out
}
