//! CUTEst-style problems (none from Hock–Schittkowski).
use crate::Family;

/// The CUTEst-style families.
pub static FAMILIES: &[Family] = &[];
