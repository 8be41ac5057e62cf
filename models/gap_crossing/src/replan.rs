//! Re-planning from a measured stance: the robot followed a plan up to stance K, but its
//! CoM or a foot is not where the plan put it. [`replan`] keeps stances 1..K−1 as they
//! were, takes stance K as measured (the plan's stance K with the perturbation applied)
//! and re-solves stance K's forces and every later stance, warm from the old plan, on the
//! old plan's foot schedule.
//!
//! The re-plan is the planner's own problem with a new start: the scenario's start
//! becomes the measured stance and n_step becomes n_step − K + 1 ([`measured_scenario`]).
//! As for stance 1 of any plan, the measured stance's CoMs and feet are constants, its
//! forces are variables held to (2) and (4), and the rigid legs (11) and the foot
//! distances (6)–(9) are not imposed on it: a measured CoM 2 cm off its legs' spheres is
//! a fact to re-plan from, not something a plan can change. The result is judged as any
//! plan ([`crate::solve::decide`] on the whole file, with its
//! [`crate::plan::Replanned`] block telling the checker which stance was measured): the
//! goal-not-reached and gap-not-crossable certificates apply to the re-plan's own
//! scenario, so a perturbation that leaves too few stances says so with a bound.
//!
//! ```no_run
//! use gap_crossing::plan::SolutionFile;
//! use gap_crossing::replan::{replan, Perturbation};
//! use gap_crossing::scenario::Foot;
//! use gap_crossing::solve::Settings;
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let old = SolutionFile::read(std::path::Path::new("out/solution.json"))?;
//! let perturbation = Perturbation {
//!     com_offset: [0.02, 0.0, 0.0],
//!     feet: vec![],
//! };
//! let outcome = replan(&old, 20, &perturbation, &Settings::default())?;
//! assert!(outcome.status.is_solved());
//! // Stances 1..19 are the old plan's, bit for bit.
//! assert_eq!(outcome.file.stances[..19], old.stances[..19]);
//! # Ok(())
//! # }
//! ```
use crate::check::MOVE_TOL;
use crate::frame;
use crate::plan::{Plan, Replanned, SolutionFile, SolverInfo, Stance};
use crate::scenario::{dist2, Foot, Scenario, Vec3, START_TERRAIN_TOL, START_TOL};
use crate::solve::{self, Outcome, PlanningError, Settings};
use crate::terrain;
use std::time::Instant;

/// What was measured at the re-planned stance, relative to the plan.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Perturbation {
    /// Added to both CoMs (so the whole-body CoM moves by it), m.
    pub com_offset: Vec3,
    /// Feet measured elsewhere than planned: the foot and its measured position (m).
    pub feet: Vec<(Foot, Vec3)>,
}

/// Why a re-plan cannot start (bad input: exit code 2 in the CLI).
#[derive(Debug, thiserror::Error)]
pub enum ReplanError {
    /// The stance to re-plan from is not one the plan can continue from.
    #[error("--stance {stance}: the plan has {n_step} stances; a re-plan starts at a stance from 2 to {} (stance 1 is the start, and at least one stance must follow)", n_step - 1)]
    Stance {
        /// The stance asked for (1-based).
        stance: usize,
        /// The plan's stance count.
        n_step: usize,
    },
    /// The plan's stance count differs from its scenario's n_step.
    #[error("the plan has {stances} stances but its scenario's n_step is {n_step}")]
    Length {
        /// Stances in the file.
        stances: usize,
        /// The scenario's n_step.
        n_step: usize,
    },
    /// A number of the perturbation or of the plan is not finite.
    #[error("{0} is not finite")]
    NotFinite(String),
    /// A foot is given twice.
    #[error("foot {0} is given twice")]
    FootTwice(Foot),
    /// A measured foot is not on the terrain or is in the keep-out: no stance has it there.
    #[error("measured foot {foot} at ({x}, {y}, {z}) cannot bear weight: {why}")]
    FootNotOnGround {
        /// The foot.
        foot: Foot,
        /// Its measured position.
        x: f64,
        /// y.
        y: f64,
        /// z.
        z: f64,
        /// What is wrong, in numbers.
        why: String,
    },
    /// Planning stopped with an error.
    #[error(transparent)]
    Planning(#[from] PlanningError),
}

/// The foot that moves at each transition of `stances` (`stances.len() − 1` entries): the
/// foot displaced most, when one moves by more than [`MOVE_TOL`]; at a transition where
/// none moves, the next transition's mover (the last one's at the end, BR when no foot
/// ever moves), so that the re-solve may use that step early.
pub fn schedule_of(stances: &[Stance]) -> Vec<Foot> {
    let movers: Vec<Option<Foot>> = stances
        .windows(2)
        .map(|w| {
            let d = Foot::ALL.map(|i| dist2(w[0].feet.get(i), w[1].feet.get(i)));
            let i = (0..4).fold(0, |b, i| if d[i] > d[b] { i } else { b });
            (d[i].sqrt() > MOVE_TOL).then_some(Foot::ALL[i])
        })
        .collect();
    let mut out = vec![Foot::BR; movers.len()];
    let mut next = movers.iter().rev().flatten().next().copied();
    for t in (0..movers.len()).rev() {
        if let Some(f) = movers[t] {
            next = Some(f);
        }
        out[t] = next.unwrap_or(Foot::BR);
    }
    out
}

/// The plan's stance `stance` (1-based) with the perturbation applied: what was measured.
fn measured_stance(old: &Stance, p: &Perturbation) -> Stance {
    let mut m = *old;
    for c in [&mut m.com.b, &mut m.com.f] {
        for (v, d) in c.iter_mut().zip(p.com_offset) {
            *v += d;
        }
    }
    for &(i, r) in &p.feet {
        *m.feet.get_mut(i) = r;
    }
    m
}

/// The scenario of the re-plan from `measured` (stance `stance`, 1-based, of a plan of
/// `s`): `s` with that stance as its start and n_step − stance + 1 stances.
pub fn measured_scenario(s: &Scenario, stance: usize, measured: &Stance) -> Scenario {
    let mut sub = s.clone();
    sub.start.com = measured.com;
    sub.start.feet = measured.feet;
    sub.n_step = s.n_step + 1 - stance;
    sub
}

/// Refuses what cannot be re-planned from: a stance out of range, non-finite numbers, a
/// foot given twice, a measured foot off the terrain or in the keep-out.
fn validate(
    file: &SolutionFile,
    stance: usize,
    p: &Perturbation,
    measured: Option<&Stance>,
) -> Result<(), ReplanError> {
    let s = &file.scenario;
    if file.stances.len() != s.n_step {
        return Err(ReplanError::Length {
            stances: file.stances.len(),
            n_step: s.n_step,
        });
    }
    if stance < 2 || stance >= s.n_step {
        return Err(ReplanError::Stance {
            stance,
            n_step: s.n_step,
        });
    }
    if !file.stances.iter().all(|st| {
        st.com.b.iter().chain(&st.com.f).all(|v| v.is_finite())
            && st.feet.to_array().iter().flatten().all(|v| v.is_finite())
            && st.forces.to_array().iter().flatten().all(|v| v.is_finite())
    }) {
        return Err(ReplanError::NotFinite("a number of the plan".into()));
    }
    if !p.com_offset.iter().all(|v| v.is_finite()) {
        return Err(ReplanError::NotFinite("the CoM offset".into()));
    }
    for (n, &(i, r)) in p.feet.iter().enumerate() {
        if !r.iter().all(|v| v.is_finite()) {
            return Err(ReplanError::NotFinite(format!("foot {i}'s position")));
        }
        if p.feet[..n].iter().any(|&(j, _)| j == i) {
            return Err(ReplanError::FootTwice(i));
        }
    }
    let Some(m) = measured else {
        return Ok(());
    };
    let terrain = terrain::of(s);
    for &(i, _) in &p.feet {
        let r = m.feet.get(i);
        let bad = |why: String| ReplanError::FootNotOnGround {
            foot: i,
            x: r[0],
            y: r[1],
            z: r[2],
            why,
        };
        let h = terrain.height_at(r[0], r[1]);
        if (h - r[2]).abs() > START_TERRAIN_TOL {
            return Err(bad(format!(
                "the terrain's height there is {h}, {:.3e} m from z (tolerance {START_TERRAIN_TOL} m)",
                (h - r[2]).abs()
            )));
        }
        let depth = terrain.keep_out_depth(r[0], r[1]);
        if depth > START_TOL {
            return Err(bad(format!(
                "it is {depth:.3e} m inside the keep-out (outside every region where the {} terrain allows feet)",
                s.terrain.kind()
            )));
        }
    }
    Ok(())
}

/// Re-plans `file` (a plan of its own scenario) from its stance `stance` (1-based, from
/// 2 to n_step − 1) measured with perturbation `p` (see the module docs): stances before
/// `stance` are kept bit for bit, the measured stance's forces and every later stance
/// are re-solved by one warm solve from the old plan on the old plan's foot schedule
/// ([`schedule_of`]). The outcome's file is the whole plan (n_step stances) with a
/// [`Replanned`] block; its status is decided as for any plan
/// ([`crate::solve::decide`]), with the certificates of the re-plan's own scenario
/// ([`measured_scenario`]): a perturbation that leaves the goal out of reach in the
/// stances left is `goal_not_reached` with the bound, before any solve.
pub fn replan(
    file: &SolutionFile,
    stance: usize,
    p: &Perturbation,
    settings: &Settings,
) -> Result<Outcome, ReplanError> {
    replan_with(file, stance, p, settings, false)
}

/// [`replan`], then, with `improve`, the free gait's schedule search from the re-plan
/// (the foot schedule of stances K.. may change; [`crate::solve::plan_warm`]); the best
/// plan is kept, so it costs no more than [`replan`]'s. A scenario with a prescribed
/// gait (`gait = "crawl"`) keeps its schedule: `improve` does nothing there.
pub fn replan_with(
    file: &SolutionFile,
    stance: usize,
    p: &Perturbation,
    settings: &Settings,
    improve: bool,
) -> Result<Outcome, ReplanError> {
    validate(file, stance, p, None)?;
    let s = &file.scenario;
    let k0 = stance - 1;
    let measured = measured_stance(&file.stances[k0], p);
    validate(file, stance, p, Some(&measured))?;
    let sub = measured_scenario(s, stance, &measured);
    // The schedule search changes the schedule, which a prescribed gait forbids.
    let improve = improve && s.gait == crate::scenario::Gait::Free;
    let schedule = schedule_of(&file.stances[k0..]);
    let mut guess = Plan {
        stances: file.stances[k0..].to_vec(),
    };
    guess.stances[0] = measured;
    // A foot measured elsewhere stays there until its next move (the guess's later
    // stances follow it, so that the guess keeps the feet where the schedule says).
    for &(i, r) in &p.feet {
        for (t, &mover) in schedule.iter().enumerate() {
            if mover == i {
                break;
            }
            *guess.stances[t + 1].feet.get_mut(i) = r;
        }
    }
    let replanned = Replanned {
        stance,
        com_offset: p.com_offset,
        feet: p.feet.iter().map(|&(i, r)| (i.name().into(), r)).collect(),
    };
    // Solved in the old plan's frame (the frame `solve::plan` planned it in).
    let d = frame::offset(s);
    let local = frame::translated(&sub, d);
    frame::translate_plan(&mut guess, d);
    let started = Instant::now();
    let sub_out = solve::plan_warm(
        &local,
        &*terrain::of(&local),
        &schedule,
        &guess,
        settings,
        improve,
    )?;
    let mut tail = sub_out.file.plan();
    frame::translate_plan(&mut tail, [-d[0], -d[1]]);
    // The measured stance is what was measured, exactly (its forces are re-planned).
    tail.stances[0].com = measured.com;
    tail.stances[0].feet = measured.feet;
    let mut stances = file.stances[..k0].to_vec();
    stances.extend(tail.stances);
    let whole = Plan { stances };
    let solver = SolverInfo {
        objective: whole.cost(s),
        solve_seconds: started.elapsed().as_secs_f64(),
        ..sub_out.file.solver.clone()
    };
    let mut out_file = SolutionFile::new(s.clone(), solver, whole);
    out_file.replanned = Some(replanned);
    let status = match sub_out.phases.is_empty() {
        // A certificate of the re-plan's scenario decided before solving.
        true => sub_out.status,
        false => solve::decide(&sub, sub_out.phases[sub_out.chosen].status, &out_file),
    };
    out_file.solver.status = status.kind().word().into();
    out_file.solver.reason = (!status.is_solved()).then(|| {
        format!(
            "re-planning from stance {stance} (stances {stance}..{}: n_step {} below): {status}",
            s.n_step, sub.n_step
        )
    });
    Ok(Outcome {
        status,
        file: out_file,
        phases: sub_out.phases,
        chosen: sub_out.chosen,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Feet;

    fn stance(feet: [Vec3; 4]) -> Stance {
        Stance {
            com: crate::scenario::Coms {
                b: [0.0; 3],
                f: [0.0; 3],
            },
            feet: Feet::from_array(feet),
            forces: Feet::from_array([[0.0; 3]; 4]),
        }
    }

    /// The mover of each transition is the foot displaced; a transition where no foot
    /// moves takes the next mover, and trailing ones the last mover.
    #[test]
    fn schedule_follows_the_moves() {
        let z = [0.0; 3];
        let a = stance([z, z, z, z]);
        let mut b = a;
        b.feet.fr = [0.1, 0.0, 0.0];
        let c = b;
        let mut d = c;
        d.feet.bl = [0.0, 0.2, 0.0];
        let e = d;
        assert_eq!(
            schedule_of(&[a, b, c, d, e]),
            vec![Foot::FR, Foot::BL, Foot::BL, Foot::BL]
        );
        assert_eq!(schedule_of(&[a, a]), vec![Foot::BR]);
    }
}
