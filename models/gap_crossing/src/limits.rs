//! The largest problem the planner will build: `n_step` against the memory it needs.
//!
//! The model, its compiled derivative tapes and the KKT factorisation all grow linearly
//! in `n_step`. Without a limit a too-long horizon (`n_step = 100000`) ran for minutes
//! and aborted on an allocation failure deep in `symx::ad::hessian`. [`check`] refuses
//! such a scenario before anything is built, with the estimate in its message.
//!
//! The estimate is [`BASE_BYTES`] + [`BYTES_PER_STANCE`] · `n_step`, fitted to the peak
//! resident memory of the release CLI (free gait, the default scenario otherwise;
//! `/usr/bin/time -f %M`; figures at [`BYTES_PER_STANCE`] and in docs/gap-crossing.md,
//! "Size limit"), rounded up. It is compared
//! with the memory the system reports available (`MemAvailable` of `/proc/meminfo`; when
//! that cannot be read, [`FALLBACK_AVAILABLE_BYTES`]).
use crate::scenario::{Scenario, TerrainSpec};

/// Fixed part of the memory estimate (bytes).
pub const BASE_BYTES: u64 = 64 << 20;

/// Memory per stance (bytes), 0.75 MiB. Peak resident memory of the release CLI, free
/// gait, default scenario (`/usr/bin/time -f %M`, 2026-11-25, branch s6-gait): 41.5 MiB
/// at n_step 60, 135 at 250, 260 at 500, 513–621 at 1000 (two binaries; the peak
/// depends on which solves overlap on the threads), 915 at 2000. This estimate is
/// 1.3–2.6× those peaks (1.31–1.59× at 1000, 1.71× at 2000), never below; the
/// previous 200 MiB + 1 MiB per stance was 1.9–6.3×.
pub const BYTES_PER_STANCE: u64 = 3 << 18;

/// Memory assumed available when the system does not say (bytes).
pub const FALLBACK_AVAILABLE_BYTES: u64 = 4 << 30;

/// Memory per height-map node (bytes), 6 KiB, independent of `n_step`: the model looks a
/// height map up in tables of one bicubic polynomial per cell (16 coefficients, 128 bytes
/// per node), the table of `h` and the derivative tables (to third order) the model's
/// derivatives use, which each thread's expression graph builds for itself. Peak resident
/// memory of the release CLI, free gait, n_step 60, 2026-11-27 (machine loaded;
/// `/usr/bin/time -f %M`): 49 MiB on a 0.1 m grid over 10 m × 3 m (3131 nodes), 316 MiB
/// on a 0.02 m grid (75651 nodes), against 34 MiB for the default scenario: 3.8–4.8 KiB
/// per node; the estimate (127 MiB and 552 MiB) is 1.7–2.6× those peaks.
pub const BYTES_PER_GRID_NODE: u64 = 6 << 10;

/// A problem too large for the memory available.
#[derive(Debug, thiserror::Error)]
#[error(
    "n_step = {n_step}{} is too large: building and solving it needs about {} of memory \
     (estimate {}{} + {} per stance), but {} is available; {}",
    grid_text(*nodes), gib(*estimate), gib(BASE_BYTES), node_text(*nodes),
    mib(BYTES_PER_STANCE), gib(*available), fits_text(*max_n_step, *nodes)
)]
pub struct TooLarge {
    /// The scenario's `n_step`.
    pub n_step: usize,
    /// Nodes of the scenario's height map (0 for other terrains).
    pub nodes: usize,
    /// Estimated peak memory (bytes).
    pub estimate: u64,
    /// Memory available (bytes).
    pub available: u64,
    /// The largest `n_step` whose estimate fits.
    pub max_n_step: usize,
}

fn grid_text(nodes: usize) -> String {
    if nodes == 0 {
        String::new()
    } else {
        format!(" on a height map of {nodes} nodes")
    }
}

fn node_text(nodes: usize) -> String {
    if nodes == 0 {
        String::new()
    } else {
        format!(" + {} per grid node", kib(BYTES_PER_GRID_NODE))
    }
}

fn fits_text(max_n_step: usize, nodes: usize) -> String {
    if max_n_step >= 2 {
        format!("at most n_step = {max_n_step} fits")
    } else if nodes > 0 {
        "the height map alone does not fit: use a coarser grid".into()
    } else {
        "no n_step fits".into()
    }
}

fn gib(b: u64) -> String {
    format!("{:.1} GiB", b as f64 / (1u64 << 30) as f64)
}

fn mib(b: u64) -> String {
    format!("{:.2} MiB", b as f64 / (1u64 << 20) as f64)
}

fn kib(b: u64) -> String {
    format!("{:.0} KiB", b as f64 / 1024.0)
}

/// Estimated peak memory of planning `n_step` stances on flat or analytic terrain (bytes).
pub fn memory_estimate(n_step: usize) -> u64 {
    memory_estimate_on_grid(n_step, 0)
}

/// Estimated peak memory of planning `n_step` stances on a height map of `nodes` nodes
/// (0: another terrain), bytes.
pub fn memory_estimate_on_grid(n_step: usize, nodes: usize) -> u64 {
    fixed(nodes).saturating_add(BYTES_PER_STANCE.saturating_mul(n_step as u64))
}

/// The part of the estimate that does not grow with `n_step`.
fn fixed(nodes: usize) -> u64 {
    BASE_BYTES.saturating_add(BYTES_PER_GRID_NODE.saturating_mul(nodes as u64))
}

/// The number of nodes of `s`'s height map (0 for other terrains).
pub fn grid_nodes(s: &Scenario) -> usize {
    match &s.terrain {
        TerrainSpec::HeightMap { heights, .. } => heights.iter().map(Vec::len).sum(),
        _ => 0,
    }
}

/// The memory available, from `/proc/meminfo` (`MemAvailable`), if readable.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Refuses `s` when its estimate exceeds `available` bytes.
pub fn check_with(s: &Scenario, available: u64) -> Result<(), TooLarge> {
    let nodes = grid_nodes(s);
    let estimate = memory_estimate_on_grid(s.n_step, nodes);
    if estimate <= available {
        return Ok(());
    }
    Err(TooLarge {
        n_step: s.n_step,
        nodes,
        estimate,
        available,
        max_n_step: (available.saturating_sub(fixed(nodes)) / BYTES_PER_STANCE) as usize,
    })
}

/// Refuses `s` when its estimate exceeds the memory available now.
pub fn check(s: &Scenario) -> Result<(), TooLarge> {
    check_with(s, available_memory().unwrap_or(FALLBACK_AVAILABLE_BYTES))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_past_the_available_memory() {
        let s = |n_step| Scenario {
            n_step,
            ..Scenario::default()
        };
        let avail = 2u64 << 30;
        assert!(check_with(&s(60), avail).is_ok());
        let e = check_with(&s(100_000), avail).unwrap_err();
        assert_eq!(e.estimate, memory_estimate(100_000));
        assert!(e.max_n_step < 100_000 && memory_estimate(e.max_n_step) <= avail);
        assert!(memory_estimate(e.max_n_step + 1) > avail);
        let msg = e.to_string();
        assert!(
            msg.contains("n_step = 100000") && msg.contains("GiB"),
            "{msg}"
        );
    }

    /// A height map's grid counts once (not per stance): 2000 × 2000 nodes need 15 GiB
    /// and are refused with the grid in the message; a 0.02 m grid over 10 m × 3 m
    /// (501 × 151 nodes) fits at n_step 60.
    #[test]
    fn counts_the_height_map_grid() {
        let grid = |nx: usize, ny: usize| Scenario {
            terrain: TerrainSpec::HeightMap {
                file: "x.csv".into(),
                origin: [0.0, 0.0],
                spacing: [0.1, 0.1],
                heights: vec![vec![0.0; nx]; ny],
            },
            ..Scenario::default()
        };
        let avail = 8u64 << 30;
        assert!(check_with(&grid(16, 5), avail).is_ok());
        assert!(check_with(&grid(501, 151), avail).is_ok());
        let e = check_with(&grid(2000, 2000), avail).unwrap_err();
        assert_eq!(e.nodes, 4_000_000);
        assert_eq!(e.max_n_step, 0);
        let msg = e.to_string();
        assert!(
            msg.contains("height map of 4000000 nodes")
                && msg.contains("per grid node")
                && msg.contains("use a coarser grid"),
            "{msg}"
        );
    }
}
