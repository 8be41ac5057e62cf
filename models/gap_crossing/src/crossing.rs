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
//! CoMs and forces of the changed stances re-guessed. It is built when the new jump
//! (from the foothold two moves before the old crossing) is within
//! [`CANDIDATE_REACH`] × the reach, or when the approach could be stretched to make
//! it so (`approach_can_stretch`: a foot that walked up to the near edge and jumps
//! one move later, as the back feet do on the default gap); never when the far region
//! is farther from the foot's start than the moves left before it allow (no plan could
//! cross there). Each candidate's region
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

/// The jump of a stretched approach (`approach_can_stretch`) is this fraction of the
/// step reach: a little room on (5) for the solver.
pub const STRETCH_JUMP: f64 = 0.999;

/// Whether the approach of a foot whose crossing foothold `m` is to move one move
/// earlier, but lies farther than [`CANDIDATE_REACH`] × reach from foothold `m − 2`,
/// can be stretched to close the distance: each approach foothold `j` (1 ≤ j ≤ m − 2)
/// shifted toward the crossing by `j / (m − 2)` of the shortfall (foothold `m − 2` then
/// ends [`STRETCH_JUMP`] × reach from the crossing foothold in x–y, every earlier step
/// grows by the same small amount) stays in its region, and every step of it, the jump
/// included, is within [`CANDIDATE_REACH`] × reach.
///
/// The candidate's guess keeps the unstretched approach (a jump longer than the reach
/// that the solver closes): on the default scenario and the 12 scenarios of
/// `tests/gap_crossing.rs` it reaches the same objectives as the stretched guess in
/// fewer iterations (default: 66 + 89 + 96 against 106 + 114 + 113).
fn approach_can_stretch(
    terrain: &dyn Terrain,
    regions: &[Region],
    holds: &[[f64; 3]],
    zone: &[Option<usize>],
    m: usize,
    reach: f64,
) -> bool {
    let (from, to) = (holds[m - 2], holds[m]);
    let e = [to[0] - from[0], to[1] - from[1]];
    let len = e[0].hypot(e[1]);
    let shortfall = len - STRETCH_JUMP * reach;
    if m < 3 || shortfall <= 0.0 {
        return false;
    }
    let limit = CANDIDATE_REACH * reach;
    let mut prev = holds[0];
    for j in 1..=m - 2 {
        let a = shortfall * j as f64 / (m - 2) as f64 / len;
        let (x, y) = (holds[j][0] + a * e[0], holds[j][1] + a * e[1]);
        let p = [x, y, terrain.height_at(x, y)];
        if region_of(regions, p, 0.0) != zone[j] || dist(p, prev) > limit {
            return false;
        }
        prev = p;
    }
    dist(to, prev) <= limit
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt()
}

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
            // The earlier crossing should be nearly within reach of the foothold before
            // it (the solve then moves both), or reachable by stretching the approach
            // (below): a candidate farther off is infeasible in practice and costs a
            // full solve to find out.
            let d = (0..3)
                .map(|c| (holds[m][c] - holds[m - 2][c]).powi(2))
                .sum::<f64>()
                .sqrt();
            // Necessary for any plan: the crossing's region within m − 1 moves of the
            // start (2-D distance; a 3-D step is at least as long).
            if let Some(z) = zone[m] {
                if regions[z].distance_to(holds[0][0], holds[0][1]) > (m - 1) as f64 * reach {
                    continue;
                }
            }
            // Too far for a plain shift: built only when stretching the approach could
            // close the distance (the guess keeps the approach; the solver moves it).
            if d > CANDIDATE_REACH * reach
                && !approach_can_stretch(terrain, &regions, &holds, &zone, m, reach)
            {
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
