//! The exchange format (SPEC §7): a problem directory with `A.mtx`, `N.mtx`, `T.mtx`
//! (Matrix Market coordinate real, `general` or `symmetric`), `f0.txt`, `f1.txt`,
//! optional `gap.txt`, and `meta.json`.

use crate::error::Result;
use crate::problem::CsrMatrix;

/// A problem in the exchange format, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseData {
    /// Stiffness, full storage (a `symmetric` Matrix Market file is expanded).
    pub a: CsrMatrix,
    /// Normal contact matrix (p×n).
    pub n_mat: CsrMatrix,
    /// Tangential contact matrix (p×n).
    pub t_mat: CsrMatrix,
    /// Load at α = 0 (n).
    pub f0: Vec<f64>,
    /// Load per unit α (n).
    pub f1: Vec<f64>,
    /// Gap (p), if given.
    pub gap: Option<Vec<f64>>,
    /// Friction: one value or p values.
    pub friction: Vec<f64>,
    /// Start of the α window.
    pub alpha_start: f64,
    /// End of the α window.
    pub alpha_end: f64,
    /// The whole `meta.json` object (descriptive keys kept).
    pub meta: serde_json::Value,
}

impl CaseData {
    /// Reads a problem directory. Errors: [`crate::Error::Io`] with the file name and the
    /// line of the first problem.
    pub fn read_dir(dir: &std::path::Path) -> Result<CaseData> {
        let _ = dir;
        todo!()
    }

    /// Writes a problem directory (creating it). A is written as `general`.
    pub fn write_dir(&self, dir: &std::path::Path) -> Result<()> {
        let _ = dir;
        todo!()
    }
}
