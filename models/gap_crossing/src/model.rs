//! Equations (1)–(11) of the gap-crossing planner, declared in the symx/nlp DSL.
//!
//! Each constraint group is named after its equation and stance (e.g. `(11) leg BR,
//! stance 3`), so solver messages speak the specification's language. Stances are
//! numbered from 1 as in the specification; stance 1 is the start configuration (its CoMs
//! and feet are constants, its forces are variables).
//!
//! Two design choices make the problem well posed for a Newton-type solver:
//! - **Keep-out as bounds.** The disjunction "no foot in the keep-out" is resolved by a
//!   region assignment: foot `i` at stance `k` stays in the allowed region of the terrain
//!   (a box, [`crate::terrain::Region`]) where the initial guess has it, as simple bounds
//!   on its x and y. Which stance first lands beyond a gap is decided before the solve,
//!   by the guess's crossing search ([`crate::gait`]). Interior-point iterates
//!   never leave their bounds, so they never see the steep edges of the terrain (`k = 1e6`),
//!   which is where off-the-shelf IPOPT walks feet into the gap.
//! - **Shared foot variables** ([`Formulation::Scheduled`]). When only a scheduled foot may
//!   move at a transition, the other feet keep the *same* variables in both stances, so
//!   equation (10) holds exactly by construction (not to a tolerance), and (3), (5) are
//!   declared once per foothold instead of once per stance.
//!
//! [`Formulation::Complementarity`] states (10) in lifted form for the free gait: step
//! lengths `s_i^k ≥ ‖r_i^{k+1} − r_i^k‖²`, `0 ≤ s_i^k ≤ 0.09` (which is (5)), and at most one
//! non-zero `s_i^k` per transition, enforced by the exact penalty `π Σ_{i<j} s_i^k s_j^k`
//! (Leyffer, López-Calva & Nocedal 2006) with `π` a parameter of the compiled problem.
use crate::plan::{foot_offset, STANCE_LEN};
use crate::scenario::{Biped, Foot, Scenario};
use crate::terrain::{Region, Terrain};
use nlp::{BuildError, Problem, Relation};
use symx::{Expr, Matrix};

/// How equation (10), "one foot moves per step", enters the problem.
#[derive(Clone, Debug, PartialEq)]
pub enum Formulation {
    /// `schedule[k]` is the only foot allowed to move from stance `k+1` to `k+2`
    /// (`n_step − 1` entries); the others share variables between the two stances.
    Scheduled(Vec<Foot>),
    /// Free gait: lifted step lengths with the exact complementarity penalty.
    Complementarity,
}

/// A built model: the problem and the expressions needed to read a plan back.
pub struct Model {
    /// The nonlinear program.
    pub problem: Problem,
    /// The 30 expressions of every stance, in the flat layout of [`crate::plan`]
    /// (constants for stance 1's CoMs and feet).
    pub layout: Vec<Expr>,
    /// Lifted step lengths `s_i^k` per transition, in [`Foot::ALL`] order (free gait only).
    pub step_lengths: Vec<[Expr; 4]>,
    /// Whether the cost holds the complementarity penalty, a parameter named [`PENALTY`]
    /// (free gait only).
    pub has_penalty: bool,
}

/// ε of the smoothed friction cone `√(‖F_t‖² + ε²) ≤ μ F·n` (N): it makes the cone
/// differentiable at `F_t = 0` and only shrinks it (by at most ε), so a plan that satisfies
/// the smoothed cone satisfies (4).
pub const CONE_SMOOTHING: f64 = 1.0;

/// Distance (m) within which a guessed foot x on a keep-out edge counts as on that edge's side.
pub const KEEP_OUT_SNAP: f64 = 1e-6;

/// Name of the complementarity penalty parameter `π` in the compiled problem.
pub const PENALTY: &str = "complementarity penalty";

/// Errors building the model.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The guess has the wrong length.
    #[error("initial guess has {got} numbers, expected {expected} (30 per stance)")]
    GuessLength { expected: usize, got: usize },
    /// A schedule of the wrong length.
    #[error("schedule has {got} entries, expected n_step − 1 = {expected}")]
    ScheduleLength { expected: usize, got: usize },
    /// The guess puts a foot in the keep-out (outside every allowed region of the
    /// terrain), so no region can be assigned.
    #[error(
        "initial guess puts foot {foot} at stance {stance} in the keep-out, at (x, y) = ({x}, {y})"
    )]
    GuessInKeepOut {
        foot: &'static str,
        stance: usize,
        x: f64,
        y: f64,
    },
    /// A problem-definition error from nlp.
    #[error(transparent)]
    Build(#[from] BuildError),
}

fn vec3(e: &[Expr]) -> Matrix {
    Matrix::from_vec(e.to_vec())
}

fn constant3(v: [f64; 3]) -> Matrix {
    Matrix::from_f64(&v)
}

/// The variables of every stance (stance 1's CoMs and feet are constants).
struct Vars {
    coms: Vec<[Matrix; 2]>,
    feet: Vec<[Matrix; 4]>,
    forces: Vec<[Matrix; 4]>,
    /// Whether foot i got new variables at stance k (never at stance 1).
    moved: Vec<[bool; 4]>,
}

/// Refuses a guess or a schedule of the wrong length.
fn check_sizes(n: usize, formulation: &Formulation, guess: &[f64]) -> Result<(), ModelError> {
    if guess.len() != n * STANCE_LEN {
        return Err(ModelError::GuessLength {
            expected: n * STANCE_LEN,
            got: guess.len(),
        });
    }
    if let Formulation::Scheduled(schedule) = formulation {
        if schedule.len() != n - 1 {
            return Err(ModelError::ScheduleLength {
                expected: n - 1,
                got: schedule.len(),
            });
        }
    }
    Ok(())
}

/// The variables r_i^k of foot `i` at stance `k` (0-based), initialised from the guess
/// and kept in the allowed region holding the guess (the keep-out as bounds on x, y).
fn foot_variable(
    pb: &mut Problem,
    regions: &[Region],
    guess: &[f64],
    k: usize,
    i: Foot,
) -> Result<Matrix, ModelError> {
    let label = k + 1;
    let r = pb.variable(&format!("r_{}^{label}", i.name()), 3)?;
    let off = foot_offset(k, i);
    let g = &guess[off..off + 3];
    pb.set_initial(&r, g)?;
    // The region holding the guess (a guess on a region's edge, e.g. a previous solution
    // at its bound up to the solver's bound relaxation, belongs to it): the foot stays
    // in it, as bounds on its x and y.
    let Some(region) = regions
        .iter()
        .find(|q| q.contains(g[0], g[1], KEEP_OUT_SNAP))
    else {
        return Err(ModelError::GuessInKeepOut {
            foot: i.name(),
            stance: label,
            x: g[0],
            y: g[1],
        });
    };
    for (c, [lo, hi]) in [(0, region.x), (1, region.y)] {
        if lo.is_finite() || hi.is_finite() {
            pb.set_bounds(&r[c..c + 1], lo, hi)?;
        }
    }
    Ok(r)
}

/// Declares the variables stance by stance — CoMs, the feet that may move (the others
/// share the previous stance's), forces — initialised from `guess`.
fn variables(
    pb: &mut Problem,
    s: &Scenario,
    terrain: &dyn Terrain,
    formulation: &Formulation,
    guess: &[f64],
) -> Result<Vars, ModelError> {
    let n = s.n_step;
    let regions = terrain.regions();
    let mut v = Vars {
        coms: Vec::with_capacity(n),
        feet: Vec::with_capacity(n),
        forces: Vec::with_capacity(n),
        moved: Vec::with_capacity(n),
    };
    for k in 0..n {
        let label = k + 1;
        let at = |offset: usize| &guess[offset..offset + 3];
        if k == 0 {
            v.coms
                .push([constant3(s.start.com.b), constant3(s.start.com.f)]);
            v.feet
                .push(Foot::ALL.map(|i| constant3(s.start.feet.get(i))));
            v.moved.push([false; 4]);
        } else {
            let c = Biped::ALL.map(|j| {
                let r = pb.variable(&format!("r_{}^{label}", j.name()), 3)?;
                let off = k * STANCE_LEN + if j == Biped::B { 0 } else { 3 };
                pb.set_initial(&r, at(off)).map(|_| r)
            });
            let [cb, cf] = c;
            v.coms.push([cb?, cf?]);
            let mut fk: Vec<Matrix> = Vec::with_capacity(4);
            let mut mk = [false; 4];
            for i in Foot::ALL {
                let may_move = match formulation {
                    Formulation::Scheduled(schedule) => schedule[k - 1] == i,
                    Formulation::Complementarity => true,
                };
                if may_move {
                    mk[i.index()] = true;
                    fk.push(foot_variable(pb, &regions, guess, k, i)?);
                } else {
                    fk.push(v.feet[k - 1][i.index()].clone());
                }
            }
            v.feet
                .push([fk[0].clone(), fk[1].clone(), fk[2].clone(), fk[3].clone()]);
            v.moved.push(mk);
        }
        let f = Foot::ALL.map(|i| {
            let r = pb.variable(&format!("F_{}^{label}", i.name()), 3)?;
            pb.set_initial(&r, at(k * STANCE_LEN + 18 + 3 * i.index()))
                .map(|_| r)
        });
        let [f0, f1, f2, f3] = f;
        v.forces.push([f0?, f1?, f2?, f3?]);
    }
    Ok(v)
}

/// (6)–(9) distances between the feet of one stance, skipped for a pair both still at
/// the start (which the scenario validated).
fn foot_distances(
    pb: &mut Problem,
    s: &Scenario,
    label: usize,
    feet: &[Matrix; 4],
) -> Result<(), BuildError> {
    let foot = |i: Foot| &feet[i.index()];
    let pairs = [
        ("(6) same side BR-FR", Foot::BR, Foot::FR, s.same_side_sq),
        ("(7) same side BL-FL", Foot::BL, Foot::FL, s.same_side_sq),
        ("(8) same biped BR-BL", Foot::BR, Foot::BL, s.same_biped_sq),
        ("(9) same biped FR-FL", Foot::FR, Foot::FL, s.same_biped_sq),
    ];
    for (name, a, b, bounds) in pairs {
        let d2 = (foot(a) - foot(b)).sumsqr();
        if d2.value().is_some() {
            continue;
        }
        pb.subject_to_named(
            &format!("{name}, stance {label}"),
            nlp::bounded(bounds.min, d2, bounds.max),
        )?;
    }
    Ok(())
}

/// The constraints of every stance: (2), (4) for every foot, (3) and (5) for a foot
/// that moved, (6)–(9) and (11) from stance 2 on.
fn stance_constraints(
    pb: &mut Problem,
    s: &Scenario,
    terrain: &dyn Terrain,
    formulation: &Formulation,
    v: &Vars,
) -> Result<(), BuildError> {
    for k in 0..s.n_step {
        let label = k + 1;
        force_balance(pb, s, label, &v.coms[k], &v.feet[k], &v.forces[k])?;
        for i in Foot::ALL {
            let r = &v.feet[k][i.index()];
            friction_cone(pb, s, terrain, label, i, r, &v.forces[k][i.index()])?;
            if k == 0 || !v.moved[k][i.index()] {
                continue;
            }
            // (3) the foot is on the terrain: f_env = h(x, y) − z = 0.
            pb.subject_to_named(
                &format!("(3) foot {} on terrain, stance {label}", i.name()),
                (terrain.height(r[0], r[1]) - r[2]).eq(0.0),
            )?;
            // (5) step length, for a foot that may move (the free gait states it through
            // the bounds of its lifted step length instead).
            if let Formulation::Scheduled(_) = formulation {
                let step = (r - &v.feet[k - 1][i.index()]).sumsqr();
                pb.subject_to_named(
                    &format!("(5) step {}, stance {label}", i.name()),
                    step.le(s.step_radius_sq),
                )?;
            }
        }
        if k == 0 {
            continue;
        }
        foot_distances(pb, s, label, &v.feet[k])?;
        rigid_legs(pb, s, label, &v.coms[k], &v.feet[k])?;
        motion_limits(pb, s, terrain, label, &v.coms[k - 1], &v.coms[k])?;
    }
    Ok(())
}

/// The scenario's optional [`crate::scenario::MotionLimits`] at stance `label` (≥ 2):
/// each CoM's height above the ground under it, and its travel from the previous stance.
/// Nothing when no limit is set.
fn motion_limits(
    pb: &mut Problem,
    s: &Scenario,
    terrain: &dyn Terrain,
    label: usize,
    previous: &[Matrix; 2],
    coms: &[Matrix; 2],
) -> Result<(), BuildError> {
    let m = &s.motion;
    body_height(pb, s, terrain, label, coms)?;
    for (j, (c, before)) in Biped::ALL.iter().zip(coms.iter().zip(previous)) {
        if let Some(t) = m.com_travel_max {
            pb.subject_to_named(
                &format!("motion CoM travel {}, stance {label}", j.name()),
                (c - before).sumsqr().le(t * t),
            )?;
        }
    }
    Ok(())
}

/// The scenario's optional body-height limits ([`crate::scenario::MotionLimits`]) on
/// both CoMs of stance `label`: `min ≤ z − h(x, y) ≤ max`. Nothing when neither is set.
fn body_height(
    pb: &mut Problem,
    s: &Scenario,
    terrain: &dyn Terrain,
    label: usize,
    coms: &[Matrix; 2],
) -> Result<(), BuildError> {
    let m = &s.motion;
    if m.body_height_min.is_none() && m.body_height_max.is_none() {
        return Ok(());
    }
    for (j, c) in Biped::ALL.iter().zip(coms) {
        let above = c[2] - terrain.height(c[0], c[1]);
        pb.subject_to_named(
            &format!("motion body height {}, stance {label}", j.name()),
            nlp::bounded(
                m.body_height_min.unwrap_or(f64::NEG_INFINITY),
                above,
                m.body_height_max.unwrap_or(f64::INFINITY),
            ),
        )?;
    }
    Ok(())
}

/// (10) in lifted form (free gait): per transition, step lengths
/// `s_i^k ≥ ‖r_i^{k+1} − r_i^k‖²` bounded by (5), initialised from `guess`. Returns the
/// step lengths and the products `s_i^k s_j^k` (i < j) for the penalty.
fn complementarity(
    pb: &mut Problem,
    s: &Scenario,
    feet: &[[Matrix; 4]],
    guess: &[f64],
) -> Result<(Vec<[Expr; 4]>, Vec<Expr>), BuildError> {
    let mut step_lengths = Vec::new();
    let mut products = Vec::new();
    for k in 1..s.n_step {
        let label = k + 1;
        let sk = pb.variable(&format!("s^{label}"), 4)?;
        pb.set_bounds(&sk, 0.0, s.step_radius_sq)?;
        let mut init = [0.0; 4];
        for i in Foot::ALL {
            let step = (&feet[k][i.index()] - &feet[k - 1][i.index()]).sumsqr();
            pb.subject_to_named(
                &format!("(10) lifted step length {}, stance {label}", i.name()),
                (sk[i.index()] - step).ge(0.0),
            )?;
            let (a, b) = (foot_offset(k - 1, i), foot_offset(k, i));
            init[i.index()] = (0..3)
                .map(|d| (guess[b + d] - guess[a + d]).powi(2))
                .sum::<f64>();
        }
        pb.set_initial(&sk, &init)?;
        for a in 0..4 {
            for b in a + 1..4 {
                products.push(sk[a] * sk[b]);
            }
        }
        step_lengths.push([sk[0], sk[1], sk[2], sk[3]]);
    }
    Ok((step_lengths, products))
}

/// (1) the cost, plus the penalty `π Σ products` when there are products (free gait);
/// returns whether the penalty parameter [`PENALTY`] was declared.
fn objective(
    pb: &mut Problem,
    s: &Scenario,
    v: &Vars,
    products: Vec<Expr>,
) -> Result<bool, BuildError> {
    let mut terms = Vec::new();
    for k in 0..s.n_step {
        stance_cost(s, &v.coms[k], &v.forces[k], &mut terms);
    }
    let mut cost: Expr = terms.into_iter().sum();
    let has_penalty = !products.is_empty();
    if has_penalty {
        let penalty = pb.scalar_parameter(PENALTY)?;
        pb.set_value(penalty, &[1.0])?;
        cost += penalty * products.into_iter().sum::<Expr>();
    }
    pb.minimize(cost);
    Ok(has_penalty)
}

/// The 30 expressions of every stance in the flat layout of [`crate::plan`].
fn flat_layout(v: &Vars) -> Vec<Expr> {
    let mut layout = Vec::with_capacity(v.coms.len() * STANCE_LEN);
    for k in 0..v.coms.len() {
        for c in &v.coms[k] {
            layout.extend_from_slice(c);
        }
        for r in &v.feet[k] {
            layout.extend_from_slice(r);
        }
        for f in &v.forces[k] {
            layout.extend_from_slice(f);
        }
    }
    layout
}

/// Builds the planner for scenario `s` on `terrain`, with the variables initialised (and
/// keep-out sides assigned) from `guess` (flat layout, 30 numbers per stance).
pub fn build(
    s: &Scenario,
    terrain: &dyn Terrain,
    formulation: &Formulation,
    guess: &[f64],
) -> Result<Model, ModelError> {
    check_sizes(s.n_step, formulation, guess)?;
    let mut pb = Problem::new();
    let vars = variables(&mut pb, s, terrain, formulation, guess)?;
    stance_constraints(&mut pb, s, terrain, formulation, &vars)?;
    let (step_lengths, products) = if *formulation == Formulation::Complementarity {
        complementarity(&mut pb, s, &vars.feet, guess)?
    } else {
        (Vec::new(), Vec::new())
    };
    let has_penalty = objective(&mut pb, s, &vars, products)?;
    Ok(Model {
        layout: flat_layout(&vars),
        problem: pb,
        step_lengths,
        has_penalty,
    })
}

/// The terms of cost (1) for one stance: w_CoM Σ_j ‖r_j − goal_j‖² + w_F Σ_i ‖F_i‖².
fn stance_cost(s: &Scenario, coms: &[Matrix; 2], forces: &[Matrix; 4], terms: &mut Vec<Expr>) {
    for (j, goal) in [(0, s.goal.b), (1, s.goal.f)] {
        terms.push(s.weights.com * (&coms[j] - &constant3(goal)).sumsqr());
    }
    for f in forces {
        terms.push(s.weights.force * f.sumsqr());
    }
}

/// (2) static centroidal balance of one stance: forces and moments about the whole-body
/// CoM.
fn force_balance(
    pb: &mut Problem,
    s: &Scenario,
    label: usize,
    coms: &[Matrix; 2],
    feet: &[Matrix; 4],
    forces: &[Matrix; 4],
) -> Result<(), BuildError> {
    let m_total = s.masses.total();
    let gravity = constant3([0.0, 0.0, -s.gravity]);
    let [rb, rf] = coms;
    let total_force = forces.iter().fold(&gravity * m_total, |acc, f| acc + f);
    pb.subject_to_named(
        &format!("(2) force balance, stance {label}"),
        total_force.eq(0.0),
    )?;
    let r_w = (rb * s.masses.b + rf * s.masses.f) * (1.0 / m_total);
    let mut moment = Matrix::zeros(3, 1);
    for i in Foot::ALL {
        let arm = &feet[i.index()] - &r_w;
        moment = moment + arm.cross(&forces[i.index()]).expect("3-vectors");
    }
    pb.subject_to_named(
        &format!("(2) moment balance, stance {label}"),
        moment.eq(0.0),
    )
}

/// (4) friction cone of foot `i` at `r` with force `f`, with n = (−h_x, −h_y, 1)/‖·‖:
/// F·n ≥ F_thr and ‖F_t‖ ≤ μ F·n with F_t = F − (F·n)n, written in the convex smoothed
/// form √(‖F‖² − (F·n)² + ε²) ≤ μ F·n (conservative by at most ε, see CONE_SMOOTHING).
fn friction_cone(
    pb: &mut Problem,
    s: &Scenario,
    terrain: &dyn Terrain,
    label: usize,
    i: Foot,
    r: &Matrix,
    f: &Matrix,
) -> Result<(), BuildError> {
    let [hx, hy] = terrain.gradient(r[0], r[1]);
    let n_raw = vec3(&[-hx, -hy, Expr::one()]);
    let n_norm = n_raw.sumsqr().sqrt();
    let f_n = f.dot(&n_raw).expect("3-vectors") / n_norm;
    pb.subject_to_named(
        &format!("(4) normal force {}, stance {label}", i.name()),
        f_n.ge(s.friction.f_thr),
    )?;
    let tangential = (f.sumsqr() - f_n.sq() + CONE_SMOOTHING * CONE_SMOOTHING).sqrt();
    pb.subject_to_named(
        &format!("(4) friction cone {}, stance {label}", i.name()),
        (tangential - s.friction.mu * f_n).le(0.0),
    )
}

/// (11) rigid legs of one stance.
fn rigid_legs(
    pb: &mut Problem,
    s: &Scenario,
    label: usize,
    coms: &[Matrix; 2],
    feet: &[Matrix; 4],
) -> Result<(), BuildError> {
    for i in Foot::ALL {
        let com = if i.biped() == Biped::B {
            &coms[0]
        } else {
            &coms[1]
        };
        let d2 = (com - &feet[i.index()]).sumsqr();
        pb.subject_to_named(
            &format!("(11) leg {}, stance {label}", i.name()),
            d2.eq(s.leg_length_sq),
        )?;
    }
    Ok(())
}

/// Name of the parameter holding the feet of the [`build_stance`] problem: 12 numbers,
/// BR, BL, FR, FL (x, y, z each).
pub const STANCE_FEET: &str = "stance feet";

/// One stance with its feet given: the CoMs and forces that minimise the stance's terms
/// of (1) subject to (2), (4), (11) and the scenario's body-height limits (`motion`, when
/// set), with the four footholds a parameter named [`STANCE_FEET`]. Variables: r_B, r_F,
/// then F_BR, F_BL, F_FR, F_FL (18). The feet's own equations ((3), (5)–(9), the
/// keep-out) are not in it: they involve only the footholds; nor is the CoM travel limit,
/// which links two stances (the schedule search checks it on the plan it proposes).
pub fn build_stance(s: &Scenario, terrain: &dyn Terrain) -> Result<Problem, BuildError> {
    let mut pb = Problem::new();
    let label = 0;
    let p = pb.parameter(STANCE_FEET, 12)?;
    pb.set_value(&p, &[0.0; 12])?;
    let feet: [Matrix; 4] = std::array::from_fn(|c| vec3(&p[3 * c..3 * c + 3]));
    let [rb, rf] = Biped::ALL.map(|j| pb.variable(&format!("r_{}", j.name()), 3));
    let coms = [rb?, rf?];
    let [f0, f1, f2, f3] = Foot::ALL.map(|i| pb.variable(&format!("F_{}", i.name()), 3));
    let forces = [f0?, f1?, f2?, f3?];
    force_balance(&mut pb, s, label, &coms, &feet, &forces)?;
    for i in Foot::ALL {
        friction_cone(
            &mut pb,
            s,
            terrain,
            label,
            i,
            &feet[i.index()],
            &forces[i.index()],
        )?;
    }
    rigid_legs(&mut pb, s, label, &coms, &feet)?;
    body_height(&mut pb, s, terrain, label, &coms)?;
    let mut terms = Vec::new();
    stance_cost(s, &coms, &forces, &mut terms);
    pb.minimize(terms.into_iter().sum());
    Ok(pb)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gait;
    use crate::plan::Plan;
    use crate::terrain::GapTerrain;
    use nlp::NumericNlp;

    fn crawl_model(s: &Scenario) -> (Model, Vec<f64>) {
        let guess = gait::crawl(s);
        let f = Formulation::Scheduled(gait::crawl_schedule(s.n_step));
        (
            build(s, &GapTerrain { gap: s.gap }, &f, &guess).unwrap(),
            guess,
        )
    }

    /// The symbolic cost (1) at the crawl guess equals the plan's cost computed with plain
    /// numbers (independent code), to rounding (relative 1e-12 on a sum of ~10⁵).
    #[test]
    fn objective_matches_plain_cost() {
        let s = Scenario::default();
        let (m, guess) = crawl_model(&s);
        let mut c = m.problem.compile().unwrap();
        let x = m
            .problem
            .variables()
            .iter()
            .map(|_| 0.0)
            .collect::<Vec<_>>();
        let mut x0 = x.clone();
        c.initial_point(&mut x0);
        let expected = Plan::from_flat(&s, &guess).unwrap().cost(&s);
        let f = c.eval_f(&x0);
        assert!(
            (f - expected).abs() <= 1e-12 * expected,
            "{f} vs {expected}"
        );
        // The layout read back at the initial point reproduces the guess.
        let flat = m.problem.evaluate(&m.layout, &x0).unwrap();
        assert!(flat.iter().zip(&guess).all(|(a, b)| (a - b).abs() < 1e-12));
    }

    /// The crawl heuristic satisfies the geometric equations by construction, so every
    /// row named (3), (5)–(9) or (11) holds at the initial point (1e-9: the heuristic's
    /// CoM placement solves (11) in closed form, up to rounding).
    #[test]
    fn crawl_guess_satisfies_geometric_rows() {
        let s = Scenario::default();
        let (m, _) = crawl_model(&s);
        let mut c = m.problem.compile().unwrap();
        let (n, mm) = (c.n(), c.m());
        let mut x0 = vec![0.0; n];
        c.initial_point(&mut x0);
        let mut g = vec![0.0; mm];
        c.eval_g(&x0, &mut g);
        let (mut xl, mut xu, mut gl, mut gu) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; mm], vec![0.0; mm]);
        c.bounds(&mut xl, &mut xu, &mut gl, &mut gu);
        let geometric = ["(3)", "(5)", "(6)", "(7)", "(8)", "(9)", "(11)"];
        let mut checked = 0;
        for i in 0..mm {
            let name = c.constraint_name(i);
            if geometric.iter().any(|p| name.starts_with(p)) {
                checked += 1;
                assert!(
                    g[i] >= gl[i] - 1e-9 && g[i] <= gu[i] + 1e-9,
                    "{name}: {} not in [{}, {}]",
                    g[i],
                    gl[i],
                    gu[i]
                );
            }
        }
        assert!(checked > 500, "only {checked} geometric rows");
        // Keep-out bounds hold at the guess.
        assert!(x0
            .iter()
            .zip(xl.iter().zip(&xu))
            .all(|(x, (l, u))| x >= l && x <= u));
    }

    /// In the scheduled formulation only the scheduled foot gets new variables: 3 per
    /// transition, plus 6 CoM and 12 force variables per stance.
    #[test]
    fn scheduled_feet_share_variables() {
        let s = Scenario {
            n_step: 9,
            ..Scenario::default()
        };
        let (m, _) = crawl_model(&s);
        assert_eq!(m.problem.n_variables(), 8 * (6 + 3) + 9 * 12);
    }
}
