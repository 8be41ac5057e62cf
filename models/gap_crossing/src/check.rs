//! The independent checker.
//!
//! Recomputes, from a [`SolutionFile`] alone, every requirement of the spec's section
//! "What a solved plan must satisfy", with plain `f64` / `nalgebra` arithmetic: no
//! symbolic expressions and no solver code are involved, so a bug in the model or the
//! solver cannot hide itself here.
//!
//! Labels: `(2)`…`(11)` are the source's equations; `gap` is the terrain's keep-out (the
//! widened gap; for other terrains, outside every allowed region); `start` is stance 1 = the scenario's start; `goal` is the final CoMs within 0.05 m
//! of their goals; `crawl` (crawl gait mode only) is a foot moving out of its turn;
//! `n_step` is a stance count that differs from the scenario's; `replanned` is a re-planned
//! file whose measured stance is not one of its stances. A re-planned file's measured
//! stance ([`crate::plan::Replanned`]) is checked for (2), (3), (4) and the keep-out only,
//! and the transition into it is not checked: it is the perturbation.

use crate::gait;
use crate::plan::{SolutionFile, Stance};
use crate::reach;
use crate::scenario::{dist2, Biped, Foot, Gait, Scenario, Vec3, START_TERRAIN_TOL};
use crate::terrain::{self, Terrain};
use nalgebra::Vector3;
use serde::Serialize;
use std::fmt;

/// Absolute tolerance of every residual, in the units of its equation (spec).
pub const TOL: f64 = 1e-6;

/// A foot displaced by more than this between consecutive stances has moved (m), for (10).
pub const MOVE_TOL: f64 = 1e-6;

/// Final CoMs must be within this distance of their goals (m).
pub const GOAL_TOL: f64 = 0.05;

/// Whether the goal requirement applies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GoalCheck {
    /// Required unless the geometry proves the goal unreachable ([`crate::reach`]): a
    /// keep-out zone on the way at least as wide as the step reach, or n_step below the
    /// lower bound on the stances any plan needs. A plan that stops before a crossable
    /// gap with enough stances is therefore rejected.
    #[default]
    Auto,
    /// Always required.
    Required,
    /// The goal distance is not checked (for inspecting the other equations of a partial
    /// plan: a guess, a plan of a too-short horizon; the summary says "goal NOT
    /// checked"), but a plan that stops before a crossable keep-out zone is still
    /// rejected (label `cross`, [`reach::stopped_before_crossable`]).
    Skip,
}

/// Checker settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Residual tolerance (default [`TOL`]).
    pub tol: f64,
    /// Goal requirement (default [`GoalCheck::Auto`]).
    pub goal: GoalCheck,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            tol: TOL,
            goal: GoalCheck::Auto,
        }
    }
}

/// One requirement not met.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Violation {
    /// Label: `(2)`…`(11)`, `gap`, `start`, `goal`, `crawl` or `n_step`.
    pub equation: String,
    /// What was checked, in words, with the unit of `amount`.
    pub name: String,
    /// Stance, 1-based; for (5), (10) and `crawl`, the first of the two stances compared.
    pub stance: usize,
    /// The foot (or feet, or CoM) concerned, when there is one.
    pub foot: Option<String>,
    /// By how much the requirement is missed (beyond the tolerance's reference value).
    pub amount: f64,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}: stance {}", self.equation, self.name, self.stance)?;
        if let Some(foot) = &self.foot {
            write!(f, ", {foot}")?;
        }
        write!(f, ": violated by {:.3e}", self.amount)
    }
}

/// The checker's findings.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// Every requirement not met, in stance order within each check.
    pub violations: Vec<Violation>,
    /// Number of stances checked.
    pub stances: usize,
    /// Number of foot moves (a foot displaced by more than [`MOVE_TOL`] between stances).
    pub moves: usize,
    /// Largest residual of the (2)–(11) checks, whether or not within tolerance
    /// (mixed units: N, N·m, m, m²).
    pub max_residual: f64,
    /// (10) in the source's product form: the largest over transitions of
    /// `Σ_{i<j} ‖Δr_i‖²‖Δr_j‖²` (m⁴); 0 when at most one foot moves at each transition.
    /// Informative only: (10) itself is checked by [`MOVE_TOL`] on each displacement.
    pub residual_10: f64,
    /// Whether the goal requirement was checked.
    pub goal_checked: bool,
}

impl Report {
    /// True when nothing is violated.
    pub fn ok(&self) -> bool {
        self.violations.is_empty()
    }

    /// The distinct labels of the violations, sorted.
    pub fn equations(&self) -> Vec<String> {
        let mut e: Vec<String> = self.violations.iter().map(|v| v.equation.clone()).collect();
        e.sort();
        e.dedup();
        e
    }

    /// One-line summary.
    pub fn summary(&self) -> String {
        let goal = if self.goal_checked {
            "goals reached"
        } else {
            "goal NOT checked"
        };
        if self.ok() {
            format!(
                "OK: {} stances, {} foot moves, {goal}, largest residual {:.2e} (tolerance {TOL:.0e})",
                self.stances, self.moves, self.max_residual
            )
        } else {
            format!(
                "FAILED: {} violations ({}) in {} stances",
                self.violations.len(),
                self.equations().join(", "),
                self.stances
            )
        }
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for v in &self.violations {
            writeln!(f, "{v}")?;
        }
        write!(f, "{}", self.summary())
    }
}

fn v3(a: Vec3) -> Vector3<f64> {
    Vector3::from(a)
}

fn inf_norm(v: Vector3<f64>) -> f64 {
    v.iter().fold(
        0.0f64,
        |m, x| if x.is_nan() { f64::NAN } else { m.max(x.abs()) },
    )
}

struct Checker<'a> {
    s: &'a Scenario,
    terrain: Box<dyn Terrain>,
    tol: f64,
    out: Vec<Violation>,
    max_residual: f64,
    residual_10: f64,
}

impl Checker<'_> {
    /// Records `amount` (how far past its bound a residual is); a violation when it
    /// exceeds the tolerance or is NaN.
    fn test(&mut self, eq: &str, name: &str, stance: usize, foot: Option<String>, amount: f64) {
        self.test_with(self.tol, eq, name, stance, foot, amount);
    }

    /// [`Checker::test`] with tolerance `tol`.
    fn test_with(
        &mut self,
        tol: f64,
        eq: &str,
        name: &str,
        stance: usize,
        foot: Option<String>,
        amount: f64,
    ) {
        if amount.is_nan() || amount > self.max_residual {
            self.max_residual = amount;
        }
        if amount.is_nan() || amount > tol {
            self.out.push(Violation {
                equation: eq.to_string(),
                name: name.to_string(),
                stance,
                foot,
                amount,
            });
        }
    }

    /// The checks of stance `k`; a `measured` stance (the state a re-plan started from,
    /// [`crate::plan::Replanned`]) is not held to (6)–(9) and (11).
    fn stance(&mut self, k: usize, st: &Stance, measured: bool) {
        let s = self.s;
        let m = s.masses.total();
        let w = (v3(st.com.b) * s.masses.b + v3(st.com.f) * s.masses.f) / m;
        // (2) static balance.
        let mut force = v3(s.gravity_vector()) * m;
        let mut moment = Vector3::zeros();
        for i in Foot::ALL {
            let f = v3(st.forces.get(i));
            force += f;
            moment += (v3(st.feet.get(i)) - w).cross(&f);
        }
        self.test("(2)", "force balance (N)", k, None, inf_norm(force));
        self.test("(2)", "moment balance (N·m)", k, None, inf_norm(moment));
        for i in Foot::ALL {
            let p = st.feet.get(i);
            let name = Some(i.name().to_string());
            // (3) on the terrain: f_env = h(x) − z = 0.
            let f_env = self.terrain.height_at(p[0], p[1]) - p[2];
            // A foot still at its start may sit up to START_TERRAIN_TOL off the terrain
            // (the spec: a deep gap's atan tail lowers the ground near its edges).
            let tol = if p == s.start.feet.get(i) {
                START_TERRAIN_TOL.max(self.tol)
            } else {
                self.tol
            };
            self.test_with(
                tol,
                "(3)",
                "foot on terrain |h(x) − z| (m)",
                k,
                name.clone(),
                f_env.abs(),
            );
            // (4) friction cone about the terrain normal.
            let n = v3(self.terrain.normal_at(p[0], p[1]));
            let f = v3(st.forces.get(i));
            let fn_ = f.dot(&n);
            let ft = (f - n * fn_).norm();
            self.test(
                "(4)",
                "normal force below F_thr (N)",
                k,
                name.clone(),
                s.friction.f_thr - fn_,
            );
            self.test(
                "(4)",
                "tangential force above μ·normal (N)",
                k,
                name.clone(),
                ft - s.friction.mu * fn_,
            );
            // (11) rigid legs.
            let j = i.biped();
            let l2 = dist2(st.com.get(j), p);
            if !measured {
                self.test(
                    "(11)",
                    &format!("leg length ‖r_{j} − r_foot‖² − {} (m²)", s.leg_length_sq),
                    k,
                    name.clone(),
                    (l2 - s.leg_length_sq).abs(),
                );
            }
            // Keep-out: distance from the nearest region where feet may stand.
            let inside = self.terrain.keep_out_depth(p[0], p[1]);
            if p[0].is_nan() || p[1].is_nan() || inside > 0.0 {
                self.test(
                    "gap",
                    "foot in the keep-out, distance from the nearest allowed region (m)",
                    k,
                    name,
                    inside,
                );
            }
        }
        if measured {
            return;
        }
        if k >= 2 {
            self.body_height(k, st);
        }
        // (6)–(9) foot distances.
        let pairs = [
            ("(6)", Foot::BR, Foot::FR, s.same_side_sq),
            ("(7)", Foot::BL, Foot::FL, s.same_side_sq),
            ("(8)", Foot::BR, Foot::BL, s.same_biped_sq),
            ("(9)", Foot::FR, Foot::FL, s.same_biped_sq),
        ];
        for (eq, a, b, bounds) in pairs {
            let d2 = dist2(st.feet.get(a), st.feet.get(b));
            let what = Some(format!("{a}–{b}"));
            self.test(
                eq,
                &format!("squared distance below {} (m²)", bounds.min),
                k,
                what.clone(),
                bounds.min - d2,
            );
            self.test(
                eq,
                &format!("squared distance above {} (m²)", bounds.max),
                k,
                what,
                d2 - bounds.max,
            );
        }
    }

    /// The optional body-height limits (`motion.body_height_min`/`max`) at stance `k`.
    fn body_height(&mut self, k: usize, st: &Stance) {
        let m = self.s.motion;
        for j in Biped::ALL {
            let c = st.com.get(j);
            let above = c[2] - self.terrain.height_at(c[0], c[1]);
            let who = Some(j.name().to_string());
            if let Some(lo) = m.body_height_min {
                let name =
                    format!("body height above the ground below motion.body_height_min = {lo} (m)");
                self.test("motion", &name, k, who.clone(), lo - above);
            }
            if let Some(hi) = m.body_height_max {
                let name =
                    format!("body height above the ground above motion.body_height_max = {hi} (m)");
                self.test("motion", &name, k, who.clone(), above - hi);
            }
        }
    }

    /// The optional CoM travel limit (`motion.com_travel_max`) between stances k and k+1.
    fn com_travel(&mut self, k: usize, a: &Stance, b: &Stance) {
        let Some(t) = self.s.motion.com_travel_max else {
            return;
        };
        for j in Biped::ALL {
            let d = dist2(a.com.get(j), b.com.get(j)).sqrt();
            let name = format!("CoM travel above motion.com_travel_max = {t} (m)");
            self.test("motion", &name, k, Some(j.name().to_string()), d - t);
        }
    }

    /// (5), (10) and the crawl schedule between stances k and k+1 (1-based k).
    fn transition(&mut self, k: usize, a: &Stance, b: &Stance, scheduled: Option<Foot>) -> usize {
        let s = self.s;
        let mut moved = Vec::new();
        let d2s = Foot::ALL.map(|i| dist2(a.feet.get(i), b.feet.get(i)));
        let mut products = 0.0;
        for p in 0..4 {
            for q in p + 1..4 {
                products += d2s[p] * d2s[q];
            }
        }
        self.residual_10 = self.residual_10.max(products);
        for (i, d2) in Foot::ALL.into_iter().zip(d2s) {
            self.test(
                "(5)",
                &format!("step length ‖Δr‖² above {} (m²)", s.step_radius_sq),
                k,
                Some(i.name().to_string()),
                d2 - s.step_radius_sq,
            );
            let d = d2.sqrt();
            if d.is_nan() || d > MOVE_TOL {
                moved.push((i, d));
            }
        }
        if moved.len() > 1 {
            let mut ds: Vec<f64> = moved.iter().map(|m| m.1).collect();
            ds.sort_by(|x, y| y.total_cmp(x));
            let feet: Vec<&str> = moved.iter().map(|m| m.0.name()).collect();
            self.out.push(Violation {
                equation: "(10)".into(),
                name: format!("{} feet move at once; second-largest move (m)", moved.len()),
                stance: k,
                foot: Some(feet.join("+")),
                amount: ds[1],
            });
        }
        if let Some(turn) = scheduled {
            for &(i, d) in &moved {
                if i != turn {
                    self.out.push(Violation {
                        equation: "crawl".into(),
                        name: format!("foot moves out of turn ({turn}'s turn) by (m)"),
                        stance: k,
                        foot: Some(i.name().to_string()),
                        amount: d,
                    });
                }
            }
        }
        moved.len()
    }
}

/// Checks a solution file with the default [`Options`].
pub fn check(file: &SolutionFile) -> Report {
    check_with(file, &Options::default())
}

/// Checks a solution file: every requirement of the spec's list, each stance, each foot.
pub fn check_with(file: &SolutionFile, opts: &Options) -> Report {
    let s = &file.scenario;
    let st = &file.stances;
    let mut c = Checker {
        s,
        terrain: terrain::of(s),
        tol: opts.tol,
        out: Vec::new(),
        max_residual: 0.0,
        residual_10: 0.0,
    };
    if st.len() != s.n_step {
        c.out.push(Violation {
            equation: "n_step".into(),
            name: format!(
                "stance count differs from the scenario's n_step {}",
                s.n_step
            ),
            stance: st.len(),
            foot: None,
            amount: (st.len() as f64 - s.n_step as f64).abs(),
        });
    }
    // A re-planned file's measured stance (1-based), see [`crate::plan::Replanned`].
    let measured = file.replanned.as_ref().map(|r| r.stance);
    if let Some(m) = measured.filter(|&m| m < 2 || m > st.len()) {
        c.out.push(Violation {
            equation: "replanned".into(),
            name: format!(
                "measured stance outside 2..={} (the stances of the plan)",
                st.len()
            ),
            stance: m,
            foot: None,
            amount: f64::NAN,
        });
    }
    for (k, stance) in st.iter().enumerate() {
        c.stance(k + 1, stance, measured == Some(k + 1));
    }
    let schedule = gait::crawl_schedule(st.len());
    let mut moves = 0;
    for k in 0..st.len().saturating_sub(1) {
        // The way into a measured stance is the perturbation, not a planned step.
        if measured == Some(k + 2) {
            continue;
        }
        let turn = (s.gait == Gait::Crawl).then(|| schedule[k]);
        c.com_travel(k + 1, &st[k], &st[k + 1]);
        moves += c.transition(k + 1, &st[k], &st[k + 1], turn);
    }
    let max_residual = c.max_residual;
    let residual_10 = c.residual_10;
    let mut out = c.out;
    let tol = opts.tol;
    if let Some(first) = st.first() {
        let mut start = |what: String, got: Vec3, want: Vec3| {
            let d = inf_norm(v3(got) - v3(want));
            if d.is_nan() || d > tol {
                out.push(Violation {
                    equation: "start".into(),
                    name: "stance 1 differs from the scenario's start by (m)".into(),
                    stance: 1,
                    foot: Some(what),
                    amount: d,
                });
            }
        };
        for j in Biped::ALL {
            start(format!("CoM {j}"), first.com.get(j), s.start.com.get(j));
        }
        for i in Foot::ALL {
            start(i.name().to_string(), first.feet.get(i), s.start.feet.get(i));
        }
    }
    let goal_checked = match opts.goal {
        GoalCheck::Required => true,
        GoalCheck::Skip => false,
        GoalCheck::Auto => {
            reach::uncrossable(s).is_none() && s.n_step >= reach::stances_needed(s).needed
        }
    };
    if goal_checked {
        if let Some(last) = st.last() {
            for j in Biped::ALL {
                let d = dist2(last.com.get(j), s.goal.get(j)).sqrt();
                if d.is_nan() || d > GOAL_TOL {
                    out.push(Violation {
                        equation: "goal".into(),
                        name: format!("final CoM farther than {GOAL_TOL} m from its goal by (m)"),
                        stance: st.len(),
                        foot: Some(format!("CoM {j}")),
                        amount: d - GOAL_TOL,
                    });
                }
            }
        }
    }
    if opts.goal == GoalCheck::Skip {
        // Skipping the goal never forgives a plan that stops before a crossable gap.
        if let Some(last) = st.last() {
            for (i, d) in reach::stopped_before_crossable(s, &last.feet) {
                out.push(Violation {
                    equation: "cross".into(),
                    name: "foot stops before a crossable keep-out zone its goal lies beyond; distance from the goal's region (m)".into(),
                    stance: st.len(),
                    foot: Some(i.name().to_string()),
                    amount: d,
                });
            }
        }
    }
    Report {
        violations: out,
        stances: st.len(),
        moves,
        max_residual,
        residual_10,
        goal_checked,
    }
}
