//! [`Solution`]s saved to and loaded from a versioned JSON file.
//!
//! The file is one JSON object:
//! `{"format": "symnlp.solution", "version": 1, "solution": {...}}`, where `solution`
//! holds the fields of [`Solution`] under their Rust names (`status` as its variant name,
//! `stats.records` the iteration log). Numbers are written in the shortest form that reads
//! back to the same `f64` bit for bit. JSON has no NaN or infinity: a solution holding
//! one is refused on saving ([`SolutionFileError::NonFinite`]).
//!
//! A file of another format version is refused with an error naming both versions
//! ([`SolutionFileError::Version`]); [`SOLUTION_FILE_VERSION`] is the version written.
use crate::solution::Solution;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The `format` field of a solution file.
pub const SOLUTION_FILE_FORMAT: &str = "symnlp.solution";
/// The format version this build writes and reads.
pub const SOLUTION_FILE_VERSION: u32 = 1;

/// Why a solution could not be saved or loaded.
#[derive(Debug, Error)]
pub enum SolutionFileError {
    /// Reading or writing the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The system's error.
        source: std::io::Error,
    },
    /// The text is not a solution file (not JSON, another `format`, missing fields).
    #[error("not a symnlp solution file: {why}")]
    Format {
        /// What is wrong.
        why: String,
    },
    /// The file was written in another format version.
    #[error("solution file format version {found} cannot be read by this build, which reads version {expected}")]
    Version {
        /// The file's version.
        found: u64,
        /// The version this build reads.
        expected: u32,
    },
    /// The solution holds NaN or ±∞, which JSON cannot represent.
    #[error("the solution holds a NaN or infinite number, which a JSON file cannot represent")]
    NonFinite,
}

#[derive(Serialize)]
struct Envelope<'a> {
    format: &'a str,
    version: u32,
    solution: &'a Solution,
}

#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u64>,
}

#[derive(Deserialize)]
struct Body {
    solution: Solution,
}

impl Solution {
    /// This solution as the text of a solution file (see the module notes).
    ///
    /// ```
    /// use nlp::{Problem, Ipm, IpmOptions, Solution};
    /// let mut pb = Problem::new();
    /// let x = pb.variable("x", 1).unwrap();
    /// pb.minimize((x[0] - 2.0).sq());
    /// let sol = Ipm::new(IpmOptions::default()).solve(&mut pb.compile().unwrap()).unwrap();
    /// let text = sol.to_json().unwrap();
    /// let back = Solution::from_json(&text).unwrap();
    /// assert_eq!(back.x[0].to_bits(), sol.x[0].to_bits());
    /// ```
    pub fn to_json(&self) -> Result<String, SolutionFileError> {
        let text = serde_json::to_string_pretty(&Envelope {
            format: SOLUTION_FILE_FORMAT,
            version: SOLUTION_FILE_VERSION,
            solution: self,
        })
        .map_err(|e| SolutionFileError::Format { why: e.to_string() })?;
        // serde_json writes NaN and ±∞ as `null`, which does not read back as a number.
        if serde_json::from_str::<Body>(&text).is_err() {
            return Err(SolutionFileError::NonFinite);
        }
        Ok(text)
    }

    /// A solution from the text of a solution file; `Err` for another format or version.
    pub fn from_json(text: &str) -> Result<Solution, SolutionFileError> {
        let format = |why: String| SolutionFileError::Format { why };
        let header: Header = serde_json::from_str(text).map_err(|e| format(e.to_string()))?;
        match header.format.as_deref() {
            Some(SOLUTION_FILE_FORMAT) => {}
            Some(other) => {
                return Err(format(format!(
                    "format is '{other}', expected '{SOLUTION_FILE_FORMAT}'"
                )))
            }
            None => return Err(format("no 'format' field".into())),
        }
        match header.version {
            Some(v) if v == u64::from(SOLUTION_FILE_VERSION) => {}
            Some(found) => {
                return Err(SolutionFileError::Version {
                    found,
                    expected: SOLUTION_FILE_VERSION,
                })
            }
            None => return Err(format("no 'version' field".into())),
        }
        let body: Body = serde_json::from_str(text).map_err(|e| format(e.to_string()))?;
        Ok(body.solution)
    }

    /// Writes this solution to the file `path` ([`Solution::to_json`]).
    pub fn save(&self, path: impl AsRef<std::path::Path>) -> Result<(), SolutionFileError> {
        let path = path.as_ref();
        std::fs::write(path, self.to_json()?).map_err(|source| SolutionFileError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// Reads a solution from the file `path` ([`Solution::from_json`]).
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<Solution, SolutionFileError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| SolutionFileError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Solution::from_json(&text)
    }
}
