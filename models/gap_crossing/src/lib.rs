//! Quadruped gap crossing: the flagship model of symnlp.
//!
//! A quadruped, modelled as two compass bipeds joined by a massless prismatic link, must
//! walk from a start to a goal configuration across a gap in the ground, in `n_step`
//! quasi-static four-contact stances (specification: `docs/gap-crossing.md`, equations
//! (1)–(11) of Roscia & Sodano). This crate holds:
//!
//! - [`scenario`]: the problem's numbers (serde, defaults, validation, `--set` overrides);
//! - [`plan`]: the solution file (JSON) and the flat variable layout, 30 numbers per stance;
//! - [`gait`]: initial guesses (standing still, the crawl-gait heuristic) and the crawl
//!   schedule;
//! - [`terrain`], [`terrain_spec`]: the ground (gap, step, several gaps, stepping stones,
//!   height map) as expressions and numbers, its allowed regions, and its scenario table;
//! - [`crossing`]: the crossing search's candidates (which move of each foot first lands
//!   beyond a gap), [`crossing_search`]: solving them, on the plan's walking horizon
//!   (`early_start`: the free gait's later solves started as soon as they are known to be
//!   needed, or speculatively, while the crawl plan is still being solved);
//! - [`frame`]: the translation to the start's frame every plan is solved in;
//! - [`reach`]: geometric certificates that a goal is unreachable; [`footing`]: on a
//!   height map, the cells no foot can stand on and whether the rest joins start and goal;
//! - [`replan`]: re-planning the rest of a plan from a measured (perturbed) stance;
//! - [`status`]: the typed outcome of planning (solved, gap not crossable, goal not
//!   reached, solver failed, check failed) and its exit code;
//! - [`check`]: the independent checker, recomputing every residual from a solution file
//!   with plain `f64` arithmetic (no symbolic or solver code);
//! - [`convergence`]: the per-iteration history of the solver runs (objective,
//!   constraint violation, residual of (10)), recorded by the solvers' iteration callback;
//! - [`render`]: hand-written SVG plots of a plan, of solver convergence and of a sweep,
//!   and the animated plan page (`plan.html`);
//! - [`schedule_search`]: the free gait's search over foot schedules (shortest path over
//!   foothold counts);
//! - [`shard`]: a sweep split into shards run anywhere, and their results merged;
//! - [`output`]: writing a run's files all or nothing;
//! - [`limits`]: the largest `n_step` the memory allows, checked before building;
//! - [`strict_json`]: JSON parsing that rejects duplicate keys.

pub mod check;
pub mod console;
pub mod convergence;
pub mod crossing;
pub mod crossing_search;
mod early_start;
pub mod export;
pub mod footing;
pub mod frame;
pub mod gait;
pub mod limits;
pub mod model;
pub mod output;
pub mod plan;
pub mod reach;
pub mod render;
pub mod replan;
pub mod scenario;
pub mod schedule_search;
pub mod shard;
pub mod solve;
pub mod status;
pub mod strict_json;
pub mod sweep;
pub mod terrain;
pub mod terrain_spec;
