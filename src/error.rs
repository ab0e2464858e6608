//! Errors of the library. Every way the data or a computation can fail has a variant
//! with a specific message; nothing in the library panics on bad data.

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Everything that can go wrong. The `Display` text is a complete one-line message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A dimension does not fit (`what` names the object).
    #[error("dimension mismatch: {0}")]
    Dimension(String),
    /// A CSR matrix is malformed (row pointers, column indices, index base).
    #[error("{0}")]
    Csr(String),
    /// A NaN or infinite value in the input.
    #[error("non-finite value: {0}")]
    NonFinite(String),
    /// A matrix that must be symmetric is not: A in full storage, a condensed W, or the
    /// W formed by a host's solve. The message names the matrix and the entries.
    #[error("{0}")]
    NotSymmetric(String),
    /// The Cholesky factorisation of A met a non-positive pivot. The fields count from 0
    /// (as every index of the API); the message counts from 1, as every message does.
    #[error(
        "A is not positive definite: non-positive pivot in row {} of A (1-based; pivot {} of the fill-reducing ordering)",
        row + 1,
        pivot + 1
    )]
    NotSpd {
        /// Pivot position in the permuted order (0-based).
        pivot: usize,
        /// Row of A (0-based) that the pivot belongs to.
        row: usize,
    },
    /// A condensed operator W given by the caller is not positive definite (the message
    /// names the failing pivot's row and node).
    #[error("W is not positive definite: {0}")]
    WNotSpd(String),
    /// The host's solve callback failed: a fatal code (< 0), or a recoverable one (> 0)
    /// twice in a row (it is retried once), or NaN/Inf in what it returned (code 0).
    #[error("the host's solve callback failed (code {code}): {message}")]
    HostSolve {
        /// The callback's own nonzero return code (0 when it returned non-finite values).
        code: i32,
        /// What went wrong.
        message: String,
    },
    /// The displacement u was asked of a problem that cannot compute it (condensed input
    /// without a solve).
    #[error("{0}")]
    NoDisplacement(String),
    /// B = [N; T] does not have full row rank: W is not positive definite.
    #[error("B = [N; T] is rank-deficient (W = B A^-1 B^T not positive definite): {0}")]
    RankDeficient(String),
    /// A parameter is out of its range (friction < 0, r ≤ 0, empty window, …).
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// The load callback failed (returned a nonzero code) or returned NaN/Inf.
    #[error("load callback failed at alpha = {alpha:e} (code {code}): {message}")]
    Load {
        /// α at which the load was evaluated.
        alpha: f64,
        /// The callback's own nonzero return code (0 when it returned non-finite values).
        code: i32,
        /// What went wrong.
        message: String,
    },
    /// The fixed-α solver did not converge.
    #[error("fixed-alpha solve failed at alpha = {alpha:e}: {message}")]
    SolveFailed {
        /// α of the solve.
        alpha: f64,
        /// Why.
        message: String,
    },
    /// An allocation failed: the message says what and how many bytes were asked for.
    /// Nothing was changed; the handle stays usable.
    #[error("out of memory: {0}")]
    OutOfMemory(String),
    /// A numerical failure during tracing (singular piece where none may be, …).
    #[error("numerical failure: {0}")]
    Numerical(String),
    /// A call made in the wrong order (e.g. stepping a path that was not started).
    #[error("usage: {0}")]
    Usage(String),
}

/// A vector of `len` copies of `value`, or [`Error::OutOfMemory`] naming `what` and the
/// bytes asked for (instead of aborting the process).
pub(crate) fn try_vec<T: Clone>(len: usize, value: T, what: &str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len)
        .map_err(|_| oom(what, len, std::mem::size_of::<T>()))?;
    v.resize(len, value);
    Ok(v)
}

/// An empty vector with room for `len` elements, or [`Error::OutOfMemory`].
pub(crate) fn try_with_capacity<T>(len: usize, what: &str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len)
        .map_err(|_| oom(what, len, std::mem::size_of::<T>()))?;
    Ok(v)
}

/// A zero `rows × cols` matrix, or [`Error::OutOfMemory`].
pub(crate) fn try_zeros(rows: usize, cols: usize, what: &str) -> Result<faer::Mat<f64>> {
    let mut m = faer::Mat::<f64>::new();
    m.try_reserve(rows, cols)
        .map_err(|_| oom(what, rows.saturating_mul(cols), 8))?;
    m.resize_with(rows, cols, |_, _| 0.0);
    Ok(m)
}

/// The error for `count` elements of `size` bytes.
pub(crate) fn oom(what: &str, count: usize, size: usize) -> Error {
    let bytes = count as f64 * size as f64;
    Error::OutOfMemory(format!(
        "{what}: {count} values ({:.3} GiB) could not be allocated",
        bytes / (1u64 << 30) as f64
    ))
}
