//! [`MultiPhaseOcp`]: several optimal control problems in sequence — each phase with its
//! own dynamics, horizon (fixed or free), grid and transcription — joined by linkage
//! constraints between one phase's end and another's start (state continuity, or a user
//! function such as an impact map), written as one [`Problem`]. A contact sequence (stance,
//! flight, stance) is such a problem.
use super::phase::Phase;
use super::transcription::ParameterTable;
use super::{Grid, Method, Ocp, OcpError, Trajectory};
use crate::compiled::Compiled;
use crate::constraint::{Constraint, Relation};
use crate::problem::Problem;
use crate::solution::Solution;
use symx::{Expr, Matrix};

/// A phase of a [`MultiPhaseOcp`], as returned by [`MultiPhaseOcp::add_phase`]; phases
/// are numbered in the order they were added (and run in that order in time).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PhaseId(pub usize);

/// A linkage `c(x_from(T_from), x_to(0), p)`.
type LinkFn = Box<dyn Fn(&Matrix, &Matrix, &Matrix) -> Constraint>;

struct PhaseSpec {
    name: String,
    ocp: Ocp,
    method: Method,
    grid: Grid,
}

struct Link {
    name: String,
    from: PhaseId,
    to: PhaseId,
    c: LinkFn,
}

/// Phases run one after the other: phase `k` starts when phase `k − 1` ends, each with its
/// own [`Ocp`] (dynamics, costs, bounds, path and boundary constraints, horizon as its
/// duration), [`Method`] and [`Grid`]. The objective is the sum of the phases' costs.
/// Phases meet only through linkage constraints ([`MultiPhaseOcp::link_states`],
/// [`MultiPhaseOcp::add_linkage`]): without one, a phase's start is free.
///
/// Parameters are shared by name: phases that declare a parameter of the same name use one
/// problem parameter (declared with the same values, else an error), and a linkage receives
/// every parameter stacked in the order of first declaration.
///
/// ```
/// use nlp::ocp::{ControlInterpolation, Grid, Horizon, Method, MultiPhaseOcp, Ocp};
/// use nlp::{Ipm, Relation};
/// use symx::Matrix;
/// // ẍ = u, min ½∫u² over two phases of 1 s: from (0, 0) to a wall at x = 1, where an
/// // impact reverses and halves the velocity, then back to (0, 0). Closed form: J* = 3.9.
/// let phase = || {
///     let mut ocp = Ocp::new(&["x", "v"], &["u"]);
///     ocp.set_dynamics(|x, u, _p| Matrix::from_vec(vec![x[1], u[0]]));
///     ocp.set_stage_cost(|_x, u, _p| 0.5 * u[0].sq());
///     ocp.set_horizon(Horizon::Fixed(1.0)).unwrap();
///     ocp.set_control_interpolation(ControlInterpolation::PiecewiseLinear);
///     ocp
/// };
/// let (mut approach, mut back) = (phase(), phase());
/// approach.set_initial_state(&[0.0, 0.0])?;
/// approach.add_boundary_constraint("wall", |_x0, xt, _p, _t| xt[0].eq(1.0));
/// back.set_final_state(&[0.0, 0.0])?;
/// let mut mp = MultiPhaseOcp::new();
/// let a = mp.add_phase("approach", approach, Method::hermite_simpson(), Grid::uniform(4)?)?;
/// let b = mp.add_phase("back", back, Method::hermite_simpson(), Grid::uniform(4)?)?;
/// mp.add_linkage("impact", a, b, |end, start, _p| {
///     Matrix::from_vec(vec![start[0] - end[0], start[1] + 0.5 * end[1]]).eq(0.0)
/// })?;
/// let tr = mp.transcribe()?;
/// let sol = Ipm::default().solve(&mut tr.compile()?)?;
/// assert!((sol.objective - 3.9).abs() < 1e-6); // exact: the optimal x(t) are cubics
/// let trajs = tr.trajectories(&sol)?;
/// assert_eq!(trajs[1].time[0], 1.0); // absolute time: phase 2 starts at 1 s
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Default)]
pub struct MultiPhaseOcp {
    phases: Vec<PhaseSpec>,
    links: Vec<Link>,
}

impl MultiPhaseOcp {
    /// A problem without phases.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends a phase named `name` (non-empty, unique, without `.`; its variables are
    /// named `"{name}.X"`, `"{name}.U"`, `"{name}.T"`... and its constraint groups
    /// `"{name}.continuity"`...), transcribed by `method` on `grid`.
    pub fn add_phase(
        &mut self,
        name: &str,
        ocp: Ocp,
        method: Method,
        grid: Grid,
    ) -> Result<PhaseId, OcpError> {
        if name.is_empty() || name.contains('.') {
            return Err(OcpError::Invalid {
                what: format!("phase name '{name}'"),
                why: "must be non-empty and contain no '.'".into(),
            });
        }
        if self.phases.iter().any(|p| p.name == name) {
            return Err(OcpError::Invalid {
                what: format!("phase name '{name}'"),
                why: "already used by another phase".into(),
            });
        }
        self.phases.push(PhaseSpec {
            name: name.to_string(),
            ocp,
            method,
            grid,
        });
        Ok(PhaseId(self.phases.len() - 1))
    }

    /// The state is continuous from the end of `from` to the start of `to`:
    /// `x_to(0) = x_from(T_from)` (the phases must have as many states), as the group
    /// `"link {from}→{to}"`.
    pub fn link_states(&mut self, from: PhaseId, to: PhaseId) -> Result<(), OcpError> {
        let (a, b) = (self.spec(from)?, self.spec(to)?);
        if a.ocp.nx() != b.ocp.nx() {
            return Err(OcpError::Size {
                what: format!("states of phase '{}' linked to phase '{}'", b.name, a.name),
                expected: a.ocp.nx(),
                got: b.ocp.nx(),
            });
        }
        let name = format!("link {}→{}", a.name, b.name);
        self.add_linkage(&name, from, to, |end, start, _p| start.eq(end))
    }

    /// A linkage constraint `c(x_from(T_from), x_to(0), p)` (a relation: `.eq`, `.le`...),
    /// e.g. an impact map `x_to(0) = Δ(x_from(T_from))`; `p` stacks every parameter of the
    /// problem in the order of first declaration.
    pub fn add_linkage(
        &mut self,
        name: &str,
        from: PhaseId,
        to: PhaseId,
        c: impl Fn(&Matrix, &Matrix, &Matrix) -> Constraint + 'static,
    ) -> Result<(), OcpError> {
        self.spec(from)?;
        self.spec(to)?;
        if from == to {
            return Err(OcpError::Invalid {
                what: format!("linkage '{name}'"),
                why: format!("links phase {} to itself", from.0),
            });
        }
        self.links.push(Link {
            name: name.to_string(),
            from,
            to,
            c: Box::new(c),
        });
        Ok(())
    }

    fn spec(&self, id: PhaseId) -> Result<&PhaseSpec, OcpError> {
        self.phases.get(id.0).ok_or_else(|| OcpError::Invalid {
            what: format!("phase {}", id.0),
            why: format!("the problem has {} phases", self.phases.len()),
        })
    }

    /// Writes every phase into one [`Problem`] (in the order added), then the linkages;
    /// the objective is the sum of the phases' costs. Errors: no phase, and what
    /// [`Ocp::transcribe_on`] reports for a phase.
    pub fn transcribe(&self) -> Result<MultiPhaseTranscription, OcpError> {
        if self.phases.is_empty() {
            return Err(OcpError::Invalid {
                what: "multi-phase problem".into(),
                why: "has no phase: call add_phase".into(),
            });
        }
        let mut problem = Problem::new();
        let mut parameters = ParameterTable::default();
        let mut cost = Expr::zero();
        let mut phases = Vec::with_capacity(self.phases.len());
        for spec in &self.phases {
            let prefix = format!("{}.", spec.name);
            let (phase, c) = spec.ocp.write_phase(
                &mut problem,
                &prefix,
                &spec.method,
                &spec.grid,
                &mut parameters,
            )?;
            cost += c;
            phases.push(phase);
        }
        let p = parameters.stacked();
        for link in &self.links {
            let end = &phases[link.from.0].states;
            let end = end.column(end.ncols() - 1)?;
            let start = phases[link.to.0].states.column(0)?;
            problem.subject_to_named(&link.name, (link.c)(&end, &start, &p))?;
        }
        problem.minimize(cost);
        let names = self.phases.iter().map(|p| p.name.clone()).collect();
        Ok(MultiPhaseTranscription {
            problem,
            phases,
            names,
        })
    }
}

/// A [`MultiPhaseOcp`] written as one [`Problem`], with what is needed to read a solution
/// back phase by phase.
pub struct MultiPhaseTranscription {
    problem: Problem,
    phases: Vec<Phase>,
    names: Vec<String>,
}

impl MultiPhaseTranscription {
    /// The transcribed problem.
    pub fn problem(&self) -> &Problem {
        &self.problem
    }

    /// The transcribed problem, to add costs, constraints or guesses before compiling.
    pub fn problem_mut(&mut self) -> &mut Problem {
        &mut self.problem
    }

    /// Compiles the problem (see [`Problem::compile`]).
    pub fn compile(&self) -> Result<Compiled, OcpError> {
        Ok(self.problem.compile()?)
    }

    /// Number of phases.
    pub fn n_phases(&self) -> usize {
        self.phases.len()
    }

    /// The phase named `name`.
    pub fn phase_id(&self, name: &str) -> Option<PhaseId> {
        self.names.iter().position(|n| n == name).map(PhaseId)
    }

    fn phase(&self, id: PhaseId) -> Result<&Phase, OcpError> {
        self.phases.get(id.0).ok_or_else(|| OcpError::Invalid {
            what: format!("phase {}", id.0),
            why: format!("the problem has {} phases", self.phases.len()),
        })
    }

    /// The grid states `X` of a phase (`nx × (N+1)`).
    pub fn states(&self, id: PhaseId) -> Result<&Matrix, OcpError> {
        Ok(&self.phase(id)?.states)
    }

    /// The controls `U` of a phase (`nu × N`, or `nu × (N+1)` at the nodes).
    pub fn controls(&self, id: PhaseId) -> Result<&Matrix, OcpError> {
        Ok(&self.phase(id)?.controls)
    }

    /// The duration of a phase: its variable `T` or the fixed value as a constant.
    pub fn duration(&self, id: PhaseId) -> Result<Expr, OcpError> {
        Ok(self.phase(id)?.final_time)
    }

    /// The time at which a phase starts: the sum of the durations of the phases before it
    /// (an expression, e.g. to constrain or minimise the total time).
    pub fn start_time(&self, id: PhaseId) -> Result<Expr, OcpError> {
        self.phase(id)?;
        let mut t = Expr::zero();
        for phase in &self.phases[..id.0] {
            t += phase.final_time;
        }
        Ok(t)
    }

    /// The solution as one trajectory per phase, in **absolute** time: phase `k`'s times
    /// run from the end of phase `k − 1` (its `final_time` is its end time); every
    /// trajectory carries the total objective and the status.
    pub fn trajectories(&self, sol: &Solution) -> Result<Vec<Trajectory>, OcpError> {
        let mut start = 0.0;
        let mut out = Vec::with_capacity(self.phases.len());
        for phase in &self.phases {
            let traj = phase.trajectory(&self.problem, sol, start)?;
            start = traj.final_time;
            out.push(traj);
        }
        Ok(out)
    }
}
