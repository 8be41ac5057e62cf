//! The Hock–Schittkowski suite: the problems ([`problems`]) and what the suites of both
//! back ends share ([`harness`]: one timed solve, the success criteria, the report).
pub mod harness;
pub mod problems;

pub use harness::SUITE;
