//! The free gait's first phase without an idle thread: each of the two threads goes on,
//! as soon as its own solve ends, with the later work that is already known to be needed.
//!
//! The crawl and biped-pair schedules are solved on two threads; the free gait then runs
//! the crossing search and the schedule search from the better of the two plans, the
//! schedule search from the other, and the reference without (10) from the better
//! (`solve::chains`). All of it used to wait for both solves, though on the default
//! scenario the pair solve (117 iterations) ends well before the crawl solve (156), and
//! its thread stood idle. Now ([`first_phase`]):
//!
//! - the pair thread, once its plan is solved, starts the crossing search from it
//!   *speculatively* (the pair plan is the better one on the default and on most
//!   scenarios of `models/gap_crossing/scripts/scenario_table.py`), and after it the
//!   schedule search from its result if the pair plan is by then known to be the better;
//! - the crawl thread, once its plan is solved and the pair plan is known to be the
//!   better, runs the schedule search from the crawl plan and the reference (the other
//!   chain of `solve::chains`); when the pair solve is still running, it starts the
//!   schedule search from the crawl plan *speculatively* (needed when the pair plan wins)
//!   and the reference after it if the pair plan has won by then. Without this, a crawl
//!   solve ending first left its thread idle until the pair thread's whole chain had run
//!   (since the crawl and pair solves start from the least-cost stances, 101 and 87
//!   iterations, either may end first: one default run in three took 1.03 s instead of
//!   0.77 s).
//!
//! [`Race`] keeps the two verdicts: as soon as both are known and the crawl plan is the
//! better one, the speculative searches are cancelled (their solves stop at their next
//! iteration) and discarded, and everything then runs after the first phase as before.
//! Whatever was not started early runs there too.
//!
//! Determinism: each early result is the same computation, with the same inputs, as the
//! one `solve::chains` would run, and it is used only when the pair plan is the better
//! one, when it is never cancelled (the flag is set only when the crawl plan wins). The
//! plan, every phase's record and the order of the log do not depend on which solve ends
//! first or on the number of threads.
use crate::crossing_search::{self, Searched};
use crate::gait;
use crate::scenario::Scenario;
use crate::solve::{
    objective_without_10, search_from, solve_from_footholds, PlanningError, Settings, Solved,
};
use crate::terrain::Terrain;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard};

/// What a finished solve of the first phase says for the choice of the better plan:
/// its objective when it succeeded, `None` when it failed (or could not run).
pub(crate) type Verdict = Option<f64>;

/// Whether the pair plan is the better one: the same rule as `solve::Run::beats`
/// (it succeeded, and the crawl plan failed or costs more).
pub(crate) fn pair_better(pair: Verdict, crawl: Verdict) -> bool {
    match (pair, crawl) {
        (None, _) => false,
        (Some(_), None) => true,
        (Some(p), Some(c)) => p < c,
    }
}

/// What the two threads share: the verdicts so far, the pair plan (the reference's
/// start) and the cancel flag of the speculative search.
#[derive(Default)]
pub(crate) struct Race {
    state: Mutex<Shared>,
    /// Set when the crawl plan turned out the better: the speculation is not wanted.
    pub(crate) cancel: AtomicBool,
}

#[derive(Default)]
struct Shared {
    crawl: Option<Verdict>,
    pair: Option<Verdict>,
    pair_plan: Option<Vec<f64>>,
}

impl Race {
    /// Records the crawl solve's verdict; cancels the speculation if the pair solve has
    /// ended and lost. Says what the crawl thread may start.
    pub(crate) fn crawl_finished(&self, crawl: Verdict) -> AfterCrawl {
        let mut v = self.lock();
        v.crawl = Some(crawl);
        let Some(pair) = v.pair else {
            return AfterCrawl::PairPending;
        };
        match v.pair_plan.clone() {
            Some(plan) if self.settle(pair, crawl) => AfterCrawl::PairBetter(plan),
            _ => AfterCrawl::Nothing,
        }
    }

    /// The pair plan (flat) if both solves have ended and it is the better one.
    pub(crate) fn pair_plan_if_better(&self) -> Option<Vec<f64>> {
        let v = self.lock();
        match (v.pair, v.crawl) {
            (Some(p), Some(c)) if pair_better(p, c) => v.pair_plan.clone(),
            _ => None,
        }
    }

    /// Records the pair solve's verdict and plan; whether the speculative crossing
    /// search from the pair plan is (still) wanted: the pair solve succeeded, and the
    /// crawl solve has not ended yet or lost.
    pub(crate) fn pair_finished(&self, pair: Verdict, plan: Vec<f64>) -> bool {
        let mut v = self.lock();
        v.pair = Some(pair);
        v.pair_plan = Some(plan);
        match v.crawl {
            Some(crawl) => self.settle(pair, crawl),
            None => pair.is_some(),
        }
    }

    /// Whether both verdicts are known and the pair plan is the better one.
    pub(crate) fn pair_known_better(&self) -> bool {
        let v = self.lock();
        matches!((v.pair, v.crawl), (Some(p), Some(c)) if pair_better(p, c))
    }

    /// Whether the speculation has been cancelled.
    pub(crate) fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::SeqCst)
    }

    /// Both verdicts known: sets the cancel flag unless the pair plan is the better one;
    /// returns whether it is.
    fn settle(&self, pair: Verdict, crawl: Verdict) -> bool {
        let wanted = pair_better(pair, crawl);
        if !wanted {
            self.cancel.store(true, Ordering::SeqCst);
        }
        wanted
    }

    fn lock(&self) -> MutexGuard<'_, Shared> {
        // A panic while holding the lock leaves plain data: still usable.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// What the crawl thread may start once its solve has ended ([`Race::crawl_finished`]).
#[derive(Debug, PartialEq)]
pub(crate) enum AfterCrawl {
    /// The pair plan is known to be the better one: its plan (flat), the reference's
    /// start.
    PairBetter(Vec<f64>),
    /// The pair solve is still running: the crawl thread speculates that its plan will
    /// be the better one.
    PairPending,
    /// The crawl plan is the better one, or the pair solve failed: nothing.
    Nothing,
}

/// The later work done early, all of it for the case that the pair plan is the better
/// one (empty otherwise): what `solve::chains` then does not run again.
#[derive(Default)]
pub(crate) struct Early {
    /// The crossing search from the pair plan.
    pub(crate) crossed: Option<Searched>,
    /// The schedule search from the crossing search's result.
    pub(crate) from_better: Option<Vec<Solved>>,
    /// The schedule search from the crawl plan.
    pub(crate) from_worse: Option<Vec<Solved>>,
    /// The reference without (10).
    pub(crate) reference: Option<Option<f64>>,
}

/// The crawl thread's early work: the schedule search from the crawl plan, the
/// reference without (10).
#[derive(Default)]
struct ByCrawl {
    searched: Option<Result<Vec<Solved>, PlanningError>>,
    reference: Option<Result<Option<f64>, PlanningError>>,
}
type ByPair = (
    Option<Result<Searched, PlanningError>>,
    Option<Result<Vec<Solved>, PlanningError>>,
);

/// The crawl and pair solves on two threads, each followed by what it can start early
/// (module docs): the crawl schedule's solve, the pair schedule's solve, and the early
/// work when the pair plan is the better one.
pub(crate) fn first_phase(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    settings: &Settings,
    candidate: &Settings,
) -> Result<(Solved, Solved, Early), PlanningError> {
    let race = Race::default();
    let ((crawl, by_crawl), (pair, by_pair)) = rayon::join(
        || crawl_thread(s, terrain, settings, candidate, &race),
        || pair_thread(s, terrain, candidate, &race),
    );
    let (crawl, pair) = (crawl?, pair?);
    if !pair.run.beats(&crawl.run) {
        // Whatever ran early is discarded: it was for the pair plan.
        return Ok((crawl, pair, Early::default()));
    }
    let (crossed, from_better) = by_pair;
    let early = Early {
        crossed: crossed.transpose()?,
        from_better: from_better.transpose()?,
        from_worse: by_crawl.searched.transpose()?,
        reference: by_crawl.reference.transpose()?,
    };
    Ok((crawl, pair, early))
}

/// The crawl schedule's solve, then (pair plan known better) the schedule search from
/// the crawl plan ‖ the reference from the pair plan, or (pair solve still running) the
/// speculative schedule search from the crawl plan, then the reference if the pair plan
/// has won by then.
fn crawl_thread(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    settings: &Settings,
    candidate: &Settings,
    race: &Race,
) -> (Result<Solved, PlanningError>, ByCrawl) {
    let schedule = gait::crawl_schedule(s.n_step);
    let name = "free gait: crawl schedule";
    let solved = solve_from_footholds(s, terrain, &schedule, gait::crawl_plan(s), settings, name);
    let verdict = solved.as_ref().ok().and_then(|r| r.run.verdict());
    let next = race.crawl_finished(verdict);
    let Ok(crawl) = &solved else {
        return (solved, ByCrawl::default());
    };
    if !crawl.run.solution.status.is_success() {
        return (solved, ByCrawl::default());
    }
    let by_crawl = match next {
        AfterCrawl::PairBetter(start) => {
            let (searched, reference) = rayon::join(
                || search_from(s, terrain, candidate, &crawl.run, "crawl", None),
                || objective_without_10(s, terrain, &start, candidate),
            );
            ByCrawl {
                searched: Some(searched),
                reference: Some(reference),
            }
        }
        AfterCrawl::PairPending => {
            let cancel = Some(&race.cancel);
            let searched = search_from(s, terrain, candidate, &crawl.run, "crawl", cancel);
            let reference = race
                .pair_plan_if_better()
                .map(|start| objective_without_10(s, terrain, &start, candidate));
            ByCrawl {
                searched: Some(searched),
                reference,
            }
        }
        AfterCrawl::Nothing => ByCrawl::default(),
    };
    (solved, by_crawl)
}

/// The pair schedule's solve, then the speculative crossing search from its plan, then
/// (pair plan known better by then) the schedule search from the crossing search's
/// result.
fn pair_thread(
    s: &Scenario,
    terrain: &(dyn Terrain + Sync),
    candidate: &Settings,
    race: &Race,
) -> (Result<Solved, PlanningError>, ByPair) {
    let schedule = gait::pair_schedule(s.n_step);
    let footholds = gait::footholds_for_schedule(s, &schedule);
    let name = "free gait: biped-pair schedule";
    let plan = gait::plan_for_footholds(s, &footholds);
    let solved = solve_from_footholds(s, terrain, &schedule, plan, candidate, name);
    let Ok(pair) = &solved else {
        race.pair_finished(None, Vec::new());
        return (solved, (None, None));
    };
    if !race.pair_finished(pair.run.verdict(), pair.run.plan.to_flat()) {
        return (solved, (None, None));
    }
    let crossed = crossing_search::run(s, terrain, candidate, &pair.run, Some(&race.cancel));
    let from_better = match &crossed {
        Ok(c) if !race.cancelled() && race.pair_known_better() => {
            let from = c.best_run().unwrap_or(&pair.run);
            Some(search_from(s, terrain, candidate, from, "biped-pair", None))
        }
        _ => None,
    };
    (solved, (Some(crossed), from_better))
}

#[cfg(test)]
mod tests {
    use super::{pair_better, AfterCrawl, Race};

    #[test]
    fn pair_better_follows_the_rule_of_beats() {
        assert!(pair_better(Some(1.0), Some(2.0)));
        assert!(
            !pair_better(Some(2.0), Some(2.0)),
            "a tie goes to the crawl plan"
        );
        assert!(!pair_better(Some(3.0), Some(2.0)));
        assert!(pair_better(Some(3.0), None));
        assert!(!pair_better(None, Some(2.0)));
        assert!(!pair_better(None, None));
    }

    #[test]
    fn the_speculation_is_cancelled_only_when_the_crawl_plan_wins() {
        let plan = || vec![1.0, 2.0];
        // Pair first, then a worse crawl plan: kept, and the crawl thread goes on.
        let r = Race::default();
        assert!(r.pair_finished(Some(1.0), plan()));
        assert!(!r.pair_known_better());
        assert_eq!(r.crawl_finished(Some(2.0)), AfterCrawl::PairBetter(plan()));
        assert!(!r.cancelled());
        assert!(r.pair_known_better());
        // Pair first, then a better crawl plan: cancelled, the crawl thread stops.
        let r = Race::default();
        assert!(r.pair_finished(Some(2.0), plan()));
        assert_eq!(r.crawl_finished(Some(1.0)), AfterCrawl::Nothing);
        assert!(r.cancelled());
        assert!(!r.pair_known_better());
        // Crawl first and better: the crawl thread speculates, the pair thread's
        // speculation does not start, and the crawl thread's is cancelled when the pair
        // plan loses.
        let r = Race::default();
        assert_eq!(r.crawl_finished(Some(1.0)), AfterCrawl::PairPending);
        assert_eq!(r.pair_plan_if_better(), None);
        assert!(!r.pair_finished(Some(2.0), plan()));
        assert!(r.cancelled());
        assert_eq!(r.pair_plan_if_better(), None);
        // Crawl first and worse: the crawl thread speculates, the pair thread's search
        // starts, nothing is cancelled and the reference may then start from the pair plan.
        let r = Race::default();
        assert_eq!(r.crawl_finished(Some(3.0)), AfterCrawl::PairPending);
        assert!(r.pair_finished(Some(2.0), plan()));
        assert!(!r.cancelled());
        assert!(r.pair_known_better());
        assert_eq!(r.pair_plan_if_better(), Some(plan()));
        // The pair solve failed: nothing starts.
        let r = Race::default();
        assert!(!r.pair_finished(None, Vec::new()));
        assert_eq!(r.crawl_finished(Some(1.0)), AfterCrawl::Nothing);
    }
}
