//! # fricont-exchange — files and reports around the fricont core
//!
//! What a program around the embeddable library needs, kept out of it so that
//! `libfricont` links no serde and does no file I/O:
//!
//! | module | what |
//! |---|---|
//! | [`io`] | the exchange format of a problem directory (`docs/exchange-format.md`): reading, writing |
//! | [`report`] | the JSON report of a traced path (`docs/json-report.md`), the α format, the transition table |
//! | [`generator`] | the rectangle problems (Q1 plane strain on a rigid foundation) |

pub mod generator;
pub mod io;
pub mod report;

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, Error>;

/// What can go wrong around the core: a file, or the core itself.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// Reading or writing a file failed, or a file is malformed. The message names the
    /// file (and the 1-based line where there is one).
    #[error("{0}")]
    Io(String),
    /// The core rejected the data or failed (dimensions, validation, numerics).
    #[error(transparent)]
    Core(#[from] fricont::Error),
}
