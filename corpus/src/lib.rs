//! An open corpus of nonlinear programs for symnlp's solvers, written with the project's
//! own builder ([`nlp::Problem`]).
//!
//! Two kinds of problems ([`Kind`]):
//! - **optimal control** ([`ocp`]): direct transcriptions of COPS 3.0's control problems,
//!   CasADi's examples and classic robotics problems, each a [`Family`] at three sizes (the
//!   largest above 20 000 variables), in several transcriptions (trapezoidal, RK4 multiple
//!   shooting, Gauss collocation);
//! - **CUTEst-style** ([`cute`]): problems of the CUTE/CUTEst collections (none of them
//!   Hock–Schittkowski), each at one size.
//!
//! Every family names its source, and its published optimum where one exists
//! ([`Reference`]). [`export`] writes an instance as text (symx's printed expressions) so
//! that `benches/reference/corpus_ipopt.py` solves the identical formulation with IPOPT;
//! [`run`] solves instances with symnlp's interior-point method; [`profile`] turns both
//! result sets into a table and Dolan–Moré performance profiles. See `docs/corpus.md`.

pub mod cute;
pub mod diagnose;
pub mod export;
pub mod ocp;
pub mod profile;
pub mod run;

use nlp::{BuildError, Problem};

/// The two halves of the corpus.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Kind {
    /// A transcribed optimal-control problem.
    Ocp,
    /// A CUTEst-style problem.
    Cute,
}

/// A published optimal objective of one instance, in the corpus's minimisation convention
/// (a maximisation is written as the minimisation of the negated objective, and so is its
/// value).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Reference {
    /// The size parameter of the instance the value is published for.
    pub size: usize,
    /// The optimal objective value.
    pub value: f64,
    /// Where it is published (or why it is known exactly).
    pub source: &'static str,
}

/// A builder of one problem at size parameter `size` (number of intervals for OCPs, of
/// variables for scalable CUTEst problems).
pub type Builder = fn(usize) -> Result<Problem, BuildError>;

/// One problem family: a formulation, its sizes and its sources.
#[derive(Clone, Copy, Debug)]
pub struct Family {
    /// Short unique name, e.g. `rocket_trap`.
    pub name: &'static str,
    /// Optimal control or CUTEst-style.
    pub kind: Kind,
    /// The discretisation (`trapezoidal`, `rk4-shooting`, `collocation`) or `-`.
    pub transcription: &'static str,
    /// Where the statement comes from.
    pub source: &'static str,
    /// The size parameters of its instances, smallest first.
    pub sizes: &'static [usize],
    /// Builds the problem at a size.
    pub build: Builder,
    /// Published optima (possibly at sizes other than `sizes`).
    pub references: &'static [Reference],
}

/// One instance: a family at one size.
#[derive(Clone, Copy, Debug)]
pub struct Instance {
    /// Its family.
    pub family: &'static Family,
    /// Its size parameter.
    pub size: usize,
}

impl Instance {
    /// `family_size`, e.g. `rocket_trap_400`.
    pub fn name(&self) -> String {
        format!("{}_{}", self.family.name, self.size)
    }

    /// Builds the problem.
    pub fn build(&self) -> Result<Problem, BuildError> {
        (self.family.build)(self.size)
    }

    /// The published optimum of this very instance, if any.
    pub fn reference(&self) -> Option<Reference> {
        self.family
            .references
            .iter()
            .copied()
            .find(|r| r.size == self.size)
    }
}

/// Every family of the corpus: the optimal-control families first.
pub fn families() -> Vec<&'static Family> {
    ocp::FAMILIES.iter().chain(cute::FAMILIES).collect()
}

/// Every instance of the corpus, family by family, smallest size first.
pub fn instances() -> Vec<Instance> {
    families()
        .into_iter()
        .flat_map(|family| {
            family
                .sizes
                .iter()
                .map(move |&size| Instance { family, size })
        })
        .collect()
}

/// The instance called `name` (`family_size`).
pub fn instance(name: &str) -> Option<Instance> {
    instances().into_iter().find(|i| i.name() == name)
}

/// The instance `family_size` at any size of a known family, listed or not (e.g.
/// `noncvxu2_100`, to compare a problem at sizes the corpus does not run). A size of 0 is
/// refused.
pub fn instance_at_any_size(name: &str) -> Option<Instance> {
    let (family, size) = name.rsplit_once('_')?;
    let size: usize = size.parse().ok().filter(|&s| s > 0)?;
    let family = families().into_iter().find(|f| f.name == family)?;
    Some(Instance { family, size })
}

/// What can go wrong while building, exporting or solving an instance.
#[derive(Debug, thiserror::Error)]
pub enum CorpusError {
    /// The problem could not be built or compiled.
    #[error("building the problem: {0}")]
    Build(#[from] BuildError),
    /// The solver rejected the problem.
    #[error("solving: {0}")]
    Solve(#[from] nlp::SolveError),
    /// A variable name the reference side cannot read.
    #[error("instance {instance}: variable name '{name}' is not `name` or `name[i]`")]
    VariableName {
        /// The instance.
        instance: String,
        /// The offending name.
        name: String,
    },
    /// A printed expression did not parse back.
    #[error("parsing the printed {what}: {message}")]
    Parse {
        /// Which expression.
        what: String,
        /// The parser's message.
        message: String,
    },
    /// No instance has this name.
    #[error("no instance named '{0}' (see `corpus list`)")]
    UnknownInstance(String),
    /// An IPM option given by name was refused.
    #[error("options: {0}")]
    Options(String),
    /// A results file could not be read.
    #[error("results file: {0}")]
    Results(String),
}
