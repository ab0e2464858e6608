//! Problem data (SPEC §1): the stiffness `A`, the contact matrices `N`, `T`, friction `F`,
//! gap `g` and the augmentation parameter `r`, validated once and immutable afterwards.
//!
//! A [`Problem`] owns the Cholesky factor of `A` and the Delassus operator `W` (see
//! [`crate::condense`]); it is `Send + Sync` and is meant to be shared (`Arc<Problem>`) by
//! any number of [`crate::path::Path`]s.

use crate::condense::{Delassus, HostSolve};
use crate::error::{Error, Result, try_with_capacity, try_zeros};
use faer::Mat;

/// A sparse matrix in compressed sparse row form, 0-based, validated: row pointers start
/// at 0 and do not decrease, column indices are in range, sorted and unique within each
/// row (the constructors sum duplicate entries), values are finite.
#[derive(Debug, Clone, PartialEq)]
pub struct CsrMatrix {
    nrows: usize,
    ncols: usize,
    row_ptr: Vec<usize>,
    col_idx: Vec<usize>,
    values: Vec<f64>,
}

impl CsrMatrix {
    /// Validates and copies a CSR matrix given with signed indices (`i64` or `i32`, as the
    /// caller stores them: no conversion on the caller's side) and an index base of 0 (C)
    /// or 1 (Fortran, MATLAB).
    ///
    /// `row_ptr` has `nrows + 1` entries with `row_ptr[0] == index_base`; the entries of row
    /// `i` are `row_ptr[i] - base .. row_ptr[i+1] - base`. Within a row, columns may come in
    /// any order (they are sorted here) and may repeat: **duplicate entries are summed**, in
    /// the order they are given (the assembly convention of scipy, MATLAB's `sparse`,
    /// Eigen's `setFromTriplets` and PETSc's `ADD_VALUES`, and of Matrix Market files).
    /// Every later check (symmetry of A in full storage, positive definiteness) sees the
    /// summed matrix. `name` is used in error messages ("A", "N", "T").
    ///
    /// Errors: [`Error::Csr`] for a bad index base, row pointer (length, start, decrease,
    /// end ≠ number of values), column index out of range; [`Error::NonFinite`] for a NaN or
    /// infinite value, or duplicates whose sum overflows to infinity.
    pub fn from_raw<I: Copy + Into<i64>>(
        name: &str,
        nrows: usize,
        ncols: usize,
        row_ptr: &[I],
        col_idx: &[I],
        values: &[f64],
        index_base: i64,
    ) -> Result<Self> {
        if index_base != 0 && index_base != 1 {
            return Err(Error::Csr(format!(
                "{name} (CSR): index_base is {index_base}, must be 0 or 1"
            )));
        }
        if nrows.checked_add(1) != Some(row_ptr.len()) {
            return Err(Error::Csr(format!(
                "{name} (CSR): row_ptr has {} entries, expected nrows + 1 = {nrows} + 1",
                row_ptr.len(),
            )));
        }
        if col_idx.len() != values.len() {
            return Err(Error::Csr(format!(
                "{name} (CSR): {} column indices but {} values",
                col_idx.len(),
                values.len()
            )));
        }
        let first: i64 = row_ptr[0].into();
        if first != index_base {
            return Err(Error::Csr(format!(
                "{name} (CSR): row_ptr[0] = {first}, expected the index base {index_base}"
            )));
        }
        let nnz = values.len();
        let mut rp = try_with_capacity(row_ptr.len(), &format!("{name}: row pointers"))?;
        let mut prev = first;
        for (i, r) in row_ptr.iter().enumerate() {
            let r: i64 = (*r).into();
            // saturating: i64::MIN - 1 must be "out of range", not an overflow
            let r0 = r.saturating_sub(index_base);
            if i > 0 && r < prev {
                return Err(Error::Csr(format!(
                    "{name} (CSR): row pointer decreases at row {} ({} after {})",
                    i - 1 + index_base as usize,
                    r,
                    prev
                )));
            }
            if r0 < 0 || r0 as u64 > nnz as u64 {
                return Err(Error::Csr(format!(
                    "{name} (CSR): row_ptr[{i}] = {r} is outside 0..={nnz} (+ index base)"
                )));
            }
            rp.push(r0 as usize);
            prev = r;
        }
        if rp[nrows] != nnz {
            return Err(Error::Csr(format!(
                "{name} (CSR): row_ptr[nrows] - base = {} but there are {nnz} values",
                rp[nrows]
            )));
        }
        let mut ci = try_with_capacity(nnz, &format!("{name}: column indices"))?;
        let mut vals: Vec<f64> = try_with_capacity(nnz, &format!("{name}: values"))?;
        let mut row: Vec<(usize, f64)> = Vec::new();
        // `rp` is rewritten row by row to the summed structure; `lo` keeps the caller's
        // start of the next row.
        let mut lo = rp[0];
        for i in 0..nrows {
            let hi = rp[i + 1];
            row.clear();
            for k in lo..hi {
                let given: i64 = col_idx[k].into();
                let c = given.saturating_sub(index_base);
                if c < 0 || c as u64 >= ncols as u64 {
                    return Err(Error::Csr(format!(
                        "{name} (CSR): row {} has column index {} outside {}..{} (ncols {ncols}, index base {index_base})",
                        i as i64 + index_base,
                        given,
                        index_base,
                        (ncols as i64).saturating_add(index_base)
                    )));
                }
                if !values[k].is_finite() {
                    return Err(Error::NonFinite(format!(
                        "{name}: entry ({}, {}) is {}",
                        i as i64 + index_base,
                        given,
                        values[k]
                    )));
                }
                row.push((c as usize, values[k]));
            }
            // Stable: duplicates are summed in the order the caller gave them.
            row.sort_by_key(|e| e.0);
            let row_start = ci.len();
            for &(c, v) in &row {
                if ci.len() > row_start && ci.last() == Some(&c) {
                    let s = vals.last_mut().expect("a value per column index");
                    *s += v;
                    if !s.is_finite() {
                        return Err(Error::NonFinite(format!(
                            "{name}: the duplicate entries ({}, {}) sum to {}",
                            i as i64 + index_base,
                            c as i64 + index_base,
                            *s
                        )));
                    }
                } else {
                    ci.push(c);
                    vals.push(v);
                }
            }
            rp[i + 1] = ci.len();
            lo = hi;
        }
        Ok(Self {
            nrows,
            ncols,
            row_ptr: rp,
            col_idx: ci,
            values: vals,
        })
    }

    /// Builds a CSR matrix from 0-based triplets `(row, col, value)`; duplicates are
    /// **summed** (in the order given), as by [`CsrMatrix::from_raw`] and in Matrix Market
    /// files. Errors: [`Error::Csr`] for indices out of range, [`Error::NonFinite`] for
    /// non-finite values or duplicates whose sum overflows.
    pub fn from_triplets(
        name: &str,
        nrows: usize,
        ncols: usize,
        triplets: &[(usize, usize, f64)],
    ) -> Result<Self> {
        let mut t: Vec<(usize, usize, f64)> =
            try_with_capacity(triplets.len(), &format!("{name}: entries"))?;
        t.extend_from_slice(triplets);
        for &(i, j, v) in &t {
            if i >= nrows || j >= ncols {
                return Err(Error::Csr(format!(
                    "{name}: entry ({}, {}) (1-based) outside a {nrows}x{ncols} matrix",
                    i + 1,
                    j + 1
                )));
            }
            if !v.is_finite() {
                return Err(Error::NonFinite(format!(
                    "{name}: entry ({}, {}) (1-based) is {v}",
                    i + 1,
                    j + 1
                )));
            }
        }
        t.sort_by_key(|e| (e.0, e.1));
        let len = nrows
            .checked_add(1)
            .ok_or_else(|| Error::Dimension(format!("{name}: {nrows} rows is too many")))?;
        let mut row_ptr = crate::error::try_vec(len, 0usize, name)?;
        let mut col_idx = try_with_capacity(t.len(), &format!("{name}: column indices"))?;
        let mut values: Vec<f64> = try_with_capacity(t.len(), &format!("{name}: values"))?;
        let mut last: Option<(usize, usize)> = None;
        for (i, j, v) in t {
            if last == Some((i, j)) {
                let s = values.last_mut().expect("a value per entry");
                *s += v;
                if !s.is_finite() {
                    return Err(Error::NonFinite(format!(
                        "{name}: the duplicate entries ({}, {}) (1-based) sum to {}",
                        i + 1,
                        j + 1,
                        *s
                    )));
                }
            } else {
                col_idx.push(j);
                values.push(v);
                row_ptr[i + 1] += 1;
                last = Some((i, j));
            }
        }
        for i in 0..nrows {
            row_ptr[i + 1] += row_ptr[i];
        }
        Ok(Self {
            nrows,
            ncols,
            row_ptr,
            col_idx,
            values,
        })
    }

    /// Builds a CSR matrix from a dense row-major array, dropping exact zeros
    /// (convenient for tests and tiny problems).
    pub fn from_dense(nrows: usize, ncols: usize, row_major: &[f64]) -> Result<Self> {
        if nrows.checked_mul(ncols) != Some(row_major.len()) {
            return Err(Error::Dimension(format!(
                "dense array has {} entries, expected {nrows}x{ncols}",
                row_major.len()
            )));
        }
        let mut t = Vec::new();
        for i in 0..nrows {
            for j in 0..ncols {
                let v = row_major[i * ncols + j];
                if v != 0.0 {
                    t.push((i, j, v));
                }
            }
        }
        Self::from_triplets("matrix", nrows, ncols, &t)
    }

    /// Number of rows.
    pub fn nrows(&self) -> usize {
        self.nrows
    }
    /// Number of columns.
    pub fn ncols(&self) -> usize {
        self.ncols
    }
    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }
    /// Row pointers (0-based, `nrows + 1` entries).
    pub fn row_ptr(&self) -> &[usize] {
        &self.row_ptr
    }
    /// Column indices (0-based, sorted within each row).
    pub fn col_idx(&self) -> &[usize] {
        &self.col_idx
    }
    /// Values.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
    /// The entries of row `i` as `(column, value)` pairs.
    pub fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.row_ptr[i]..self.row_ptr[i + 1];
        self.col_idx[r.clone()]
            .iter()
            .copied()
            .zip(self.values[r].iter().copied())
    }
    /// `y = M x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        for (i, yi) in y.iter_mut().enumerate().take(self.nrows) {
            *yi = self.row(i).map(|(j, v)| v * x[j]).sum();
        }
    }
    /// `y += Mᵀ x`.
    pub fn mul_t_vec_add(&self, x: &[f64], y: &mut [f64]) {
        for (i, &xi) in x.iter().enumerate().take(self.nrows) {
            if xi != 0.0 {
                for (j, v) in self.row(i) {
                    y[j] += v * xi;
                }
            }
        }
    }
    /// The transpose (counting sort: linear in the number of entries; rows stay sorted).
    pub fn transpose(&self) -> CsrMatrix {
        let mut rp = vec![0usize; self.ncols + 1];
        for &j in &self.col_idx {
            rp[j + 1] += 1;
        }
        for j in 0..self.ncols {
            rp[j + 1] += rp[j];
        }
        let mut next = rp.clone();
        let mut ci = vec![0usize; self.nnz()];
        let mut vals = vec![0.0; self.nnz()];
        for i in 0..self.nrows {
            for (j, v) in self.row(i) {
                ci[next[j]] = i;
                vals[next[j]] = v;
                next[j] += 1;
            }
        }
        CsrMatrix {
            nrows: self.ncols,
            ncols: self.nrows,
            row_ptr: rp,
            col_idx: ci,
            values: vals,
        }
    }

    /// Largest absolute entry (0 for an empty matrix).
    pub fn max_abs(&self) -> f64 {
        self.values.iter().fold(0.0, |m, v| m.max(v.abs()))
    }

    /// Multiplies every value by `2^e` (exact unless a value leaves the normal range).
    pub(crate) fn scale_pow2(&mut self, e: i32) {
        if e != 0 {
            self.values.iter_mut().for_each(|v| *v = mul_pow2(*v, e));
        }
    }
}

/// Which part of the symmetric matrix `A` the caller stores.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Storage {
    /// Both triangles; symmetry is checked to a relative tolerance of 1e-10, and the
    /// matrix used is `(A + Aᵀ)/2`.
    Full,
    /// Only entries with `row ≥ col` (entries above the diagonal are an error).
    Lower,
    /// Only entries with `row ≤ col` (entries below the diagonal are an error).
    Upper,
}

/// Whether W and the condensed loads are carried beyond double precision
/// ([`ProblemBuilder::extended_precision`]).
///
/// On slender bodies (thin strips, beams) the Delassus operator W is so ill-conditioned
/// that W merely rounded to double moves transition points by up to ~1e-7 in α (the
/// p = 480 strip of `cli/benches/strips.rs`). With extended precision fricont computes
/// the low parts `W_lo` and `q_lo` of `W = W_hi + W_lo` and `q = q_hi + q_lo` by
/// mixed-precision iterative refinement with its Cholesky factor of A (residuals in
/// double-double, corrections in double), and the tracer locates transition points in
/// double-double. `W_hi` and `q_hi` are then W and q correctly rounded to double. Under
/// a basis load each piece's basis solutions are refined so; under a general load each
/// evaluation at an α is (`q(α)`'s low part by one more refinement with the factor of A,
/// then the point), which about doubles its cost: in double alone the solutions at
/// neighbouring α of a slender body disagree by more than the guards' thresholds, and
/// the trace stops with [`crate::Error::Numerical`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExtendedPrecision {
    /// Refine when it is cheap, or when W is ill-conditioned and refining is affordable:
    /// the refinement's estimated floating-point operations (about `2p · (16 nnz(L) + 36
    /// nnz(A))`) are at most [`AUTO_SMALL_FLOPS`] (6e9, about 0.3 s on one core), or the
    /// estimate [`Problem::w_condition_estimate`] exceeds [`AUTO_CONDITION`] (1e6) and
    /// they are at most `max(20 × the factorisation's, 1e11)` ([`AUTO_COST_FLOPS`]: about
    /// 10 s on one core), or, whatever they cost, where the estimate exceeds
    /// [`AUTO_CONDITION_ALWAYS`] (1e8: there double's rounding can move transition points
    /// by 1e-3 and more). A host's solve is never refined; condensed input counts as
    /// extended when its W is ill-conditioned (the tracer then works in double-double
    /// with the caller's W).
    #[default]
    Auto,
    /// Always refine (condensed input: always trace in double-double). A host's solve is
    /// an error ([`Error::InvalidParameter`]): without A there is no residual to refine
    /// with.
    On,
    /// Never: W and q as rounded to double.
    Off,
}

/// [`ExtendedPrecision::Auto`] refines W when the estimate of its 2-norm condition number
/// exceeds this (equilibrated rows): there, W's rounding to double (relative 1e-16 entry by
/// entry) moves the solutions of the piece equations by more than about 1e-9. Measured on
/// slender rectangles traced in double against an independent double-double reference:
/// at κ ≈ 1.6e6 (74 × 4 nodes on 7.1 × 0.29, F = 3.5) events were off by up to 8.6e-9 in
/// α, at κ ≈ 1.4e6 the start by 1.2e-9 relative; at κ ≈ 4e5 and 9.7e5 they were within
/// 1e-10. (It was 1e7, which left those two in double.)
pub const AUTO_CONDITION: f64 = 1e6;

/// [`ExtendedPrecision::Auto`] refines W whatever the refinement costs where the estimate of
/// its condition number exceeds this. Double's rounding of W moves the solutions by about
/// κ ε relative (1e-8 here), and a transition point by that divided by how steeply its
/// guard crosses zero, which is not bounded: on a 2001 × 21-node strip on 200 × 0.6
/// (F = 0.1, p = 2000, n = 84,000, estimate 6.4e10; its refinement 4.7e11 flops, over the
/// budget below) the first transition in double lay 4.3e-3 in α (610 κ ε) from the
/// refined one, whose path holds from the data to 3.5e-8 (SuperLU with long-double
/// residuals); refined, that strip sets up in 71 s instead of 8 s and traces its window
/// in 228 s instead of 38 s. On a 1001 × 21-node strip on 100 × 0.3 (estimate 3.0e10,
/// 1.17e11 flops) the first transition in double was 1.1e-3 off the independent
/// reference, refined 1.1e-9 (`cli/tests/slender.rs`). Below 1e8 the measured worst was
/// 5 κ ε (a 2001 × 76-node strip, estimate 5.8e7: 3.1e-8 in α, refining it would cost
/// 398 s of set-up instead of 11 s).
pub const AUTO_CONDITION_ALWAYS: f64 = 1e8;

/// [`ExtendedPrecision::Auto`] refines only when the refinement's estimated floating-point
/// operations are at most `max(AUTO_COST_RATIO × the factorisation's, AUTO_COST_FLOPS)`.
pub const AUTO_COST_RATIO: f64 = 20.0;

/// The absolute budget of [`ExtendedPrecision::Auto`] in floating-point operations (1e11,
/// about 10 s on one core), see [`AUTO_COST_RATIO`]. Slender strips factorise in almost no
/// time, so the ratio alone would refuse them, while their refinement stays well within
/// the time of tracing them: the p = 1920 strip of `cli/benches/strips.rs` (κ(W) ≈ 4e11,
/// estimate 5.6e10) refines in about 6.5 s and traces in about 10 min; in double its
/// pieces' points would be off by up to κ ε ≈ 4e-5 relative. A 308,160-dof mesh with p = 480
/// would need 8e11 (44 × its factorisation).
pub const AUTO_COST_FLOPS: f64 = 1e11;

/// [`ExtendedPrecision::Auto`] refines whatever W's condition where the refinement's
/// estimated floating-point operations are at most this (6e9: up to about 0.3 s on this
/// project's machine for rectangles of 20–200 × 2–12 nodes, where the estimate ran at
/// 1.3e10–5e10 per second; the repository's sample, n = 1320 and p = 30, is below it; a
/// 121 × 81 rectangle with p = 120 is not). Even a
/// well-conditioned W, condensed in double, carries errors of κ(A) ε in its entries, and
/// transitions where a guard crosses zero at a shallow angle amplify them and the
/// trace's own rounding: on finite-element meshes of 12 to 37 × 1 to 3 elements with
/// κ(W) ≈ 1e3–1e4, events in double were off by up to 5.5e-12 relative (against a
/// double-double reference), and by at most 8.6e-13 refined and traced in double-double;
/// on 400 random rectangles (20–200 × 2–12 nodes) against the independent reference of
/// `tests/common/reference.rs`, 55 of the 150 that 2e8 left in double (κ(W) 3e3–1e6) were
/// off by more than 1e-11 in α, up to 1.3e-9; refined, all agree to 2.7e-16. This budget
/// refines all 400 (the costliest 5.7e9 flops); 2e9 left 39 of them in double (κ(W)
/// 1.3e4–9.9e5), 15 of those off by more than 1e-11 (up to 1.3e-9), and their refinement
/// takes 0.12 s on average, 0.21 s at most. (It was 2e8, "about 0.05 s", which ran in
/// 0.01 s, then 2e9.)
pub const AUTO_SMALL_FLOPS: f64 = 6e9;

/// Where the operator `A⁻¹` and `W` come from.
#[derive(Debug, Clone)]
enum Source {
    /// A, N, T: fricont factorises A.
    Matrix {
        a: CsrMatrix,
        storage: Storage,
        n: CsrMatrix,
        t: CsrMatrix,
    },
    /// N, T and the host's solve with A.
    Solve {
        n_dofs: usize,
        solve: HostSolve,
        n: CsrMatrix,
        t: CsrMatrix,
    },
    /// The caller's W; loads are given condensed.
    Condensed { w: Mat<f64> },
}

/// Builder for a [`Problem`]. Every setter only records; [`ProblemBuilder::build`]
/// validates everything and factorises.
///
/// Three sources, from the most to the least that fricont does itself:
/// [`ProblemBuilder::new`] (A, N, T: fricont factorises A), [`ProblemBuilder::with_solve`]
/// (N, T and the host's own solve with A) and [`ProblemBuilder::condensed`] (the host's
/// W; no displacement).
#[derive(Debug, Clone)]
pub struct ProblemBuilder {
    source: Source,
    friction: Vec<f64>,
    gap: Option<Vec<f64>>,
    r: Option<f64>,
    threads: usize,
    extended: ExtendedPrecision,
}

impl ProblemBuilder {
    /// Starts a problem from the stiffness `A` (n×n, symmetric positive definite, Dirichlet
    /// dofs eliminated, stored as `storage` says) and the contact matrices `N`, `T` (p×n:
    /// row i gives the outward normal and the tangential displacement of contact node i).
    /// Friction defaults to 0 (frictionless), the gap to 0, `r` to the default of
    /// [`Problem::default_r`].
    pub fn new(a: CsrMatrix, storage: Storage, n: CsrMatrix, t: CsrMatrix) -> Self {
        Self::from_source(Source::Matrix { a, storage, n, t })
    }

    /// Starts a problem from the contact matrices `N`, `T` (p×n) and the host's own solve
    /// with A (n×n symmetric positive definite, which fricont never sees): `solve`
    /// overwrites a block of right-hand sides with `A⁻¹` times them. At the build, W is
    /// formed by 2p solves (in blocks of the solve's `max_block` columns); each load
    /// vector costs one solve (a general load one or two per evaluation) and u at a point
    /// one solve. The residual of reported states then omits `A u − f − Bᵀλ` (A is not
    /// known). Loads are ordinary (n entries).
    pub fn with_solve(n_dofs: usize, solve: HostSolve, n: CsrMatrix, t: CsrMatrix) -> Self {
        Self::from_source(Source::Solve {
            n_dofs,
            solve,
            n,
            t,
        })
    }

    /// Starts a problem from condensed data: `w` is the Delassus operator
    /// `W = B A⁻¹ Bᵀ` (2p×2p, symmetric positive definite; rows and columns `0..p` normal,
    /// `p..2p` tangential, in the units of the caller's N and T). Loads are then given
    /// condensed, `q = B A⁻¹ f` (2p entries, the same row order), and the gap in the
    /// units of `N u`. No displacement is available: states carry an empty u.
    pub fn condensed(w: Mat<f64>) -> Self {
        Self::from_source(Source::Condensed { w })
    }

    fn from_source(source: Source) -> Self {
        Self {
            source,
            friction: vec![0.0],
            gap: None,
            r: None,
            threads: 1,
            extended: ExtendedPrecision::Auto,
        }
    }

    /// Whether W and the condensed loads are carried beyond double precision (see
    /// [`ExtendedPrecision`]); default [`ExtendedPrecision::Auto`]. Refining costs about
    /// four solves with the factor of A per column of Bᵀ (2p columns) at the build, and
    /// 2p × 2p more numbers of memory (W_lo); the time is [`crate::condense::SetupTimes::w_lo_s`].
    /// With [`ExtendedPrecision::On`], [`ProblemBuilder::build`] fails with
    /// [`Error::InvalidParameter`] for a problem made with a host's solve.
    pub fn extended_precision(mut self, mode: ExtendedPrecision) -> Self {
        self.extended = mode;
        self
    }

    /// The number of threads of the set-up (the numeric Cholesky factorisation of A and
    /// forming W) and of the tracer's dense passes, 1 ..= [`MAX_THREADS`]; default 1.
    /// With more than one, the build runs faer's parallel kernels inside a private rayon
    /// pool of that many threads, started for the build and stopped after it; and where
    /// m = 2p ≥ [`crate::PARALLEL_MIN_ORDER`] (2048), each call into a path
    /// (start, step, run, `solutions_at`, `choose_branch`) starts such a pool for its
    /// LU factorisations, triangular solves and products with W, and stops it before
    /// returning. The path's own logic and every callback (load, host's solve, monitor)
    /// stay on the calling thread. fricont never uses a global pool, and starts no thread
    /// at all with 1. Results agree with the single-threaded ones to rounding (1e-14
    /// relative for W; events to 1e-12). Without the crate's `threads` feature the option
    /// is accepted and ignored.
    pub fn threads(mut self, threads: usize) -> Self {
        self.threads = threads;
        self
    }

    /// Friction coefficient `F ≥ 0` (dimensionless), the same at every node.
    pub fn friction_uniform(mut self, f: f64) -> Self {
        self.friction = vec![f];
        self
    }
    /// Friction coefficients per node (`p` values, each `≥ 0`).
    pub fn friction(mut self, f: Vec<f64>) -> Self {
        self.friction = f;
        self
    }
    /// Initial normal gap `g` (p values, length units of `u`): contact means `(N u)_i = g_i`.
    pub fn gap(mut self, g: Vec<f64>) -> Self {
        self.gap = Some(g);
        self
    }
    /// Augmentation parameter `r > 0` (force per length). Solutions and transition points
    /// do not depend on it; it only scales the rows of `H` and so the residuals.
    pub fn r(mut self, r: f64) -> Self {
        self.r = Some(r);
        self
    }

    /// Validates the data, factorises `A` (sparse Cholesky, fill-reducing ordering) and
    /// forms `W = B A⁻¹ Bᵀ` (with a host's solve: W by 2p solves; condensed: W checked
    /// and used as given).
    ///
    /// Errors: [`Error::Dimension`] (A not square, N/T not p×n, 2p > n, W not 2p×2p, F or
    /// g of wrong length),
    /// [`Error::NotSymmetric`] (A in full storage, the caller's W, or the W of a host's
    /// solve), [`Error::Csr`] (entries in the wrong triangle),
    /// [`Error::NonFinite`], [`Error::NotSpd`] (A, with the pivot), [`Error::WNotSpd`] (the
    /// caller's W, with the pivot), [`Error::RankDeficient`]
    /// (B = [N; T] without full row rank 2p), [`Error::HostSolve`] (the host's solve
    /// failed), [`Error::InvalidParameter`] (F < 0 or not
    /// finite, r ≤ 0 or not finite or `r / r0` outside [`R_RANGE`], p = 0, A's largest
    /// entry a subnormal number below 2^-1034 ≈ 5.4e-312, i.e. with fewer than 40
    /// significant bits).
    ///
    /// Extreme but valid scales of A work: A is factorised as `2^k A` with k from its
    /// largest entry (see [`Problem::a_scale_log2`]), so A × 4e307 or A × 1e-310 with the
    /// loads scaled alike give the transition points of A.
    pub fn build(self) -> Result<Problem> {
        let p = match &self.source {
            Source::Matrix { n, .. } | Source::Solve { n, .. } => n.nrows(),
            Source::Condensed { w } => {
                if w.nrows() != w.ncols() || w.nrows() % 2 != 0 {
                    return Err(Error::Dimension(format!(
                        "W is {}x{}, must be 2p x 2p",
                        w.nrows(),
                        w.ncols()
                    )));
                }
                w.nrows() / 2
            }
        };
        if p == 0 {
            return Err(Error::InvalidParameter(
                "no contact nodes: p must be ≥ 1 (N has 0 rows, or W is empty)".into(),
            ));
        }
        let n_dofs = match &self.source {
            Source::Matrix { a, .. } => {
                if a.ncols() != a.nrows() {
                    return Err(Error::Dimension(format!(
                        "A is {}x{}, must be square",
                        a.nrows(),
                        a.ncols()
                    )));
                }
                a.nrows()
            }
            Source::Solve { n_dofs, .. } => *n_dofs,
            Source::Condensed { .. } => 0,
        };
        if let Source::Matrix { n, t, .. } | Source::Solve { n, t, .. } = &self.source {
            for (name, m) in [("N", n), ("T", t)] {
                if m.nrows() != p || m.ncols() != n_dofs {
                    return Err(Error::Dimension(format!(
                        "{name} is {}x{}, expected p x n = {p}x{n_dofs} (p from the rows of N, n from A)",
                        m.nrows(),
                        m.ncols()
                    )));
                }
            }
            if 2 * p > n_dofs {
                return Err(Error::Dimension(format!(
                    "2p = {} exceeds n = {n_dofs}, so B = [N; T] cannot have full row rank",
                    2 * p
                )));
            }
        }
        let friction = match self.friction.len() {
            1 => vec![self.friction[0]; p],
            l if l == p => self.friction,
            l => {
                return Err(Error::Dimension(format!(
                    "friction has {l} values, expected 1 or p = {p}"
                )));
            }
        };
        for (i, &f) in friction.iter().enumerate() {
            if !f.is_finite() || f < 0.0 {
                return Err(Error::InvalidParameter(format!(
                    "friction coefficient F at node {} is {f}, must be finite and ≥ 0",
                    i + 1
                )));
            }
        }
        let gap = match self.gap {
            None => vec![0.0; p],
            Some(g) if g.len() == p => g,
            Some(g) => {
                return Err(Error::Dimension(format!(
                    "gap has {} values, expected p = {p}",
                    g.len()
                )));
            }
        };
        if let Some(i) = gap.iter().position(|g| !g.is_finite()) {
            return Err(Error::NonFinite(format!(
                "gap at node {} is {}",
                i + 1,
                gap[i]
            )));
        }
        if !(1..=MAX_THREADS).contains(&self.threads) {
            return Err(Error::InvalidParameter(format!(
                "threads = {}, must be in 1..={MAX_THREADS}",
                self.threads
            )));
        }
        if let Some(r) = self.r
            && (!r.is_finite() || r <= 0.0)
        {
            return Err(Error::InvalidParameter(format!(
                "r = {r}, must be finite and > 0"
            )));
        }
        if self.extended == ExtendedPrecision::On && matches!(self.source, Source::Solve { .. }) {
            return Err(crate::condense::host_cannot_refine());
        }
        let mode = self.extended;
        let (a, b, row_scale, delassus, a_scale_log2) = match self.source {
            Source::Matrix {
                mut a,
                storage,
                n,
                t,
            } => {
                // The copies of A made below (both triangles, the lower one, a transpose)
                // and the per-dof arrays of the ordering, asked for at once so that a
                // problem too large for the memory fails here cleanly instead of aborting
                // in an allocation further on.
                preflight(
                    4 * a.nnz() * 16 + 8 * n_dofs * 8,
                    "the copies of A and the ordering",
                )?;
                check_a_precision(a.max_abs())?;
                let (b_unit, unit_scale) = equilibrated_b(&n, &t, n_dofs)?;
                // A far from 1 in size (4e307, or subnormal entries) is scaled by an
                // exact power of four before anything else is computed from it; the
                // square root of that power goes into the row scales (see
                // `stiffness_exponent`).
                let k = stiffness_exponent(a.max_abs(), &unit_scale);
                a.scale_pow2(k);
                let (lower, full_a) = lower_and_full(&a, storage, k)?;
                let full_a = std::sync::Arc::new(full_a);
                let h = mul_pow2(1.0, k / 2);
                let mut del =
                    with_threads(self.threads, |par| Delassus::new(&lower, &b_unit, h, par))?;
                let refine = match mode {
                    ExtendedPrecision::On => true,
                    ExtendedPrecision::Off => false,
                    ExtendedPrecision::Auto => {
                        let flops = del.refine_flops(full_a.nnz());
                        let kappa = del.w_condition_estimate();
                        flops <= AUTO_SMALL_FLOPS
                            || kappa > AUTO_CONDITION_ALWAYS
                            || (kappa > AUTO_CONDITION
                                && flops
                                    <= (AUTO_COST_RATIO * del.factor_flops()).max(AUTO_COST_FLOPS))
                    }
                };
                if refine {
                    del.refine_w(full_a.clone())?;
                } else {
                    del.keep_matrix(full_a.clone());
                }
                let mut b = b_unit;
                b.scale_pow2(-k / 2);
                let row_scale = unit_scale.iter().map(|s| s * h).collect();
                (Some(full_a), b, row_scale, del, k)
            }
            Source::Solve { solve, n, t, .. } => {
                let (b, row_scale) = equilibrated_b(&n, &t, n_dofs)?;
                let del = Delassus::from_host_solve(n_dofs, solve, &b)?;
                (None, b, row_scale, del, 0)
            }
            Source::Condensed { w } => {
                let (w_int, row_scale, l) = equilibrated_w(w)?;
                let del = Delassus::from_condensed(w_int, row_scale.clone(), l.as_ref());
                (None, del.b().clone(), row_scale, del, 0)
            }
        };
        let gap_eq: Vec<f64> = gap.iter().zip(&row_scale).map(|(g, s)| g / s).collect();
        let friction_eq = equilibrated_friction(&friction, &row_scale)?;
        let extended = delassus.w_lo().is_some()
            || (delassus.is_condensed()
                && match mode {
                    ExtendedPrecision::On => true,
                    ExtendedPrecision::Off => false,
                    ExtendedPrecision::Auto => delassus.w_condition_estimate() > AUTO_CONDITION,
                });
        let delassus = std::sync::Arc::new(delassus);
        let r_default = delassus.default_r();
        let r = self.r.unwrap_or(r_default);
        check_r(r, r_default)?;
        let w = delassus.w();
        // (W is symmetric: row k's absolute sum read as its contiguous column k)
        let w_row_sums: std::sync::Arc<Vec<f64>> = std::sync::Arc::new(
            (0..w.nrows())
                .map(|k| w.col(k).iter().map(|v| v.abs()).sum::<f64>())
                .collect(),
        );
        Ok(Problem {
            n: n_dofs,
            p,
            a,
            b,
            friction,
            gap,
            gap_eq,
            friction_eq,
            row_scale,
            a_scale_log2,
            r,
            r_default,
            w_row_sums,
            delassus,
            extended,
            threads: self.threads,
        })
    }
}

/// The largest entries of A outside `[2^-A_BAND, 2^A_BAND]` are scaled into `[1, 4)`.
const A_BAND: i32 = 64;

/// The exponent k (even) of the exact scaling `2^k A` under which fricont factorises A:
/// 0 when the largest entry `max_abs` lies within `[2^-64, 2^64]` (nothing changes for
/// ordinary data), otherwise the one that brings it into `[1, 4)`. A stiffness of 4e307
/// would otherwise give a W with subnormal entries (and a trace that overflows), and one
/// with subnormal entries (1e-310) a meaningless factorisation.
///
/// The problem `(A, f, λ, u, g)` is the same as
/// `(2^k A, 2^(k/2) f, 2^(k/2) λ, 2^(-k/2) u, 2^(-k/2) g)` with `B` unchanged; fricont
/// factorises the latter, and traces with the rows of B divided by `2^(k/2)` on top of
/// the row's own scale (forces `2^(k/2) λ` then pair with the caller's u and g), so W,
/// q and the forces the path works with stay in the range of ordinary numbers, and
/// reports the former. The row scales
/// `unit_scale[k] · 2^(k/2)` must stay within `[2^-1000, 2^1000]`: k is moved toward 0
/// as far as they require (only for rows of N, T of absurd size).
fn stiffness_exponent(max_abs: f64, unit_scale: &[f64]) -> i32 {
    let band = mul_pow2(1.0, -A_BAND)..=mul_pow2(1.0, A_BAND);
    if max_abs.is_nan() || max_abs <= 0.0 || band.contains(&max_abs) {
        return 0;
    }
    // 2^e ≤ max_abs < 2^(e + 1) (up to the rounding of log2), so 4^half max_abs ∈ [1, 4).
    let e = max_abs.log2().floor() as i32;
    let half = -e.div_euclid(2);
    let smax = unit_scale.iter().fold(1.0f64, |m, &s| m.max(s));
    let smin = unit_scale.iter().fold(1.0f64, |m, &s| m.min(s));
    let hi = (1000.0 - smax.log2()).floor() as i32;
    let lo = (-1000.0 - smin.log2()).ceil() as i32;
    2 * half.min(hi).max(lo)
}

/// The smallest largest entry of A accepted: below it A is subnormal with fewer than 40
/// significant bits (a normwise rounding of the data itself above 2^-40 ≈ 1e-12).
const A_MIN_MAX_ABS_LOG2: i32 = -1034;

/// A whose largest entry is a subnormal number of fewer than 40 significant bits cannot
/// be represented to the accuracy fricont reports ([`Error::InvalidParameter`], saying
/// how to rescale). Larger subnormal scales (1e-310: 44 bits) are accepted.
fn check_a_precision(max_abs: f64) -> Result<()> {
    if max_abs > 0.0 && max_abs < mul_pow2(1.0, A_MIN_MAX_ABS_LOG2) {
        let bits = (max_abs / f64::from_bits(1)).log2().floor() + 1.0;
        return Err(Error::InvalidParameter(format!(
            "the largest entry of A is {max_abs:e}, a subnormal number with {bits} significant bits: A cannot be represented at this scale (fricont needs at least 40 bits, |A| ≥ 2^{A_MIN_MAX_ABS_LOG2} ≈ {:e}); multiply A and the loads by the same power of two 2^k (transition points do not change, λ scales by 2^k)",
            mul_pow2(1.0, A_MIN_MAX_ABS_LOG2)
        )));
    }
    Ok(())
}

/// `x · 2^e`, exact whenever the result is a normal number (in up to three steps, since
/// `2^e` itself may not be representable).
pub(crate) fn mul_pow2(mut x: f64, mut e: i32) -> f64 {
    while e != 0 {
        let s = e.clamp(-1000, 1000);
        x *= f64::from_bits(((1023 + s) as u64) << 52);
        e -= s;
    }
    x
}

/// The largest power of two ≤ `s > 0` (up to the rounding of log2): a scale by which
/// every division is exact, so that equilibrating changes no digit of the data.
fn pow2_below(s: f64) -> f64 {
    mul_pow2(1.0, (s.log2().floor() as i32).clamp(-1074, 1023))
}

/// Equilibration: each row of `B = [N; T]` divided by its scale `s_k`, the power of two at
/// or below its 2-norm (the rows are then of size 1 … 2, and the scaled data are the
/// caller's digits exactly). The problem is invariant under such a scaling: λ_k scales by
/// `s_k`, the gap `g_i` by `1/s_i`, and node i's friction coefficient becomes
/// `F_i s_{p+i} / s_i` ([`equilibrated_friction`]). With unit rows no force is measured
/// on another's scale, not even a node's normal force on the scale of its own tangential
/// row. Returns `B / s` (2p×n) and the 2p scales.
fn equilibrated_b(n: &CsrMatrix, t: &CsrMatrix, n_dofs: usize) -> Result<(CsrMatrix, Vec<f64>)> {
    let p = n.nrows();
    // ‖row‖₂, scaled by the row's largest entry where the sum of squares would overflow or
    // lose accuracy to underflow.
    let row_norm = |m: &CsrMatrix, i: usize| {
        let s2 = m.row(i).map(|(_, v)| v * v).sum::<f64>();
        if s2.is_normal() && s2 < f64::MAX {
            return s2.sqrt();
        }
        let big = m.row(i).fold(0.0f64, |a, (_, v)| a.max(v.abs()));
        if big == 0.0 {
            return 0.0;
        }
        big * m
            .row(i)
            .map(|(_, v)| (v / big) * (v / big))
            .sum::<f64>()
            .sqrt()
    };
    let scale = |s: f64| {
        if s.is_finite() && s > 0.0 {
            pow2_below(s)
        } else {
            1.0
        }
    };
    let row_scale: Vec<f64> = (0..2 * p)
        .map(|k| {
            if k < p {
                scale(row_norm(n, k))
            } else {
                scale(row_norm(t, k - p))
            }
        })
        .collect();
    let mut trip = Vec::with_capacity(n.nnz() + t.nnz());
    for i in 0..p {
        let (sn, st) = (row_scale[i], row_scale[p + i]);
        trip.extend(n.row(i).map(|(j, v)| (i, j, v / sn)));
        trip.extend(t.row(i).map(|(j, v)| (p + i, j, v / st)));
    }
    Ok((
        CsrMatrix::from_triplets("B", 2 * p, n_dofs, &trip)?,
        row_scale,
    ))
}

/// Checks a caller's W (finite, symmetric to 1e-10 relative, positive definite with a
/// relative pivot above 1e-12) and equilibrates it as [`equilibrated_b`] would the rows of
/// B: `s_i` the power of two at or below `sqrt(max(W_ii, W_{p+i,p+i}))` (node i's rows of
/// B in the A⁻¹ norm), so the internal W has node diagonals < 4 and keeps the caller's
/// digits. Returns `S⁻¹ W S⁻¹`, the scales and the Cholesky factor of `S⁻¹ W S⁻¹`.
fn equilibrated_w(w: Mat<f64>) -> Result<(Mat<f64>, Vec<f64>, Mat<f64>)> {
    let m = w.nrows();
    let p = m / 2;
    let name = |i: usize| {
        if i < p {
            format!("row {} (normal, node {})", i + 1, i + 1)
        } else {
            format!("row {} (tangential, node {})", i + 1, i - p + 1)
        }
    };
    let mut big = 0.0f64;
    for j in 0..m {
        for i in 0..m {
            let v = w[(i, j)];
            if !v.is_finite() {
                return Err(Error::NonFinite(format!(
                    "W({}, {}) (1-based) is {v}",
                    i + 1,
                    j + 1
                )));
            }
            big = big.max(v.abs());
        }
    }
    for j in 0..m {
        for i in j + 1..m {
            let d = (w[(i, j)] - w[(j, i)]).abs();
            if d > 1e-10 * big {
                return Err(Error::NotSymmetric(format!(
                    "W is not symmetric: W({}, {}) and W({}, {}) differ by {d:e} (tolerance 1e-10 * max|W| = {:e})",
                    i + 1,
                    j + 1,
                    j + 1,
                    i + 1,
                    1e-10 * big
                )));
            }
        }
    }
    if let Some(i) = (0..m).find(|&i| w[(i, i)] <= 0.0) {
        return Err(Error::WNotSpd(format!(
            "{} has the diagonal entry W({}, {}) = {:e} ≤ 0",
            name(i),
            i + 1,
            i + 1,
            w[(i, i)]
        )));
    }
    let row_scale: Vec<f64> = (0..m).map(|k| pow2_below(w[(k, k)].sqrt())).collect();
    let sc = |k: usize| row_scale[k];
    let mut w_int = try_zeros(m, m, "the equilibrated W")?;
    for j in 0..m {
        for i in 0..m {
            // (no overflow for entries near f64::MAX)
            // (no overflow of the product of two scales near 2^512 either)
            w_int[(i, j)] = (0.5 * w[(i, j)] + 0.5 * w[(j, i)]) / sc(i) / sc(j);
        }
    }
    let pivot_err = |j: usize, d: f64| {
        Error::WNotSpd(format!(
            "the Cholesky factorisation of W fails at {} (relative pivot {d:e}; W must be symmetric positive definite: is B = [N; T] of full row rank?)",
            name(j)
        ))
    };
    let l = match crate::dense::llt_lower(w_int.as_ref()) {
        Ok(l) => l,
        Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) => {
            return Err(pivot_err(index.min(m - 1), 0.0));
        }
    };
    for j in 0..m {
        let d = l[(j, j)] * l[(j, j)] / w_int[(j, j)];
        if d <= 1e-12 {
            return Err(pivot_err(j, d));
        }
    }
    Ok((w_int, row_scale, l))
}

/// Node i's friction coefficient for the equilibrated rows: `F_i s_{p+i} / s_i` (exact:
/// the scales are powers of two), so that `|λt| ≤ F λν` in the caller's units is the same
/// cone for the internal forces `s λ`. Error where it leaves the range of normal doubles (a
/// node whose tangential and normal rows differ in length by a factor near 1e308, or a
/// friction coefficient near the largest double): a subnormal coefficient keeps only some
/// of F's digits (a tangential row of one entry 1e-320 gave slipping nodes |λt| = 1.15 F
/// |λν| in the caller's units).
fn equilibrated_friction(friction: &[f64], row_scale: &[f64]) -> Result<Vec<f64>> {
    let p = friction.len();
    (0..p)
        .map(|i| {
            // the scales are powers of two: their log2 are exact integers
            let e = row_scale[p + i].log2() as i32 - row_scale[i].log2() as i32;
            let f = mul_pow2(friction[i], e);
            if f.is_finite() && (f >= f64::MIN_POSITIVE || friction[i] == 0.0) {
                Ok(f)
            } else {
                Err(Error::InvalidParameter(format!(
                    "friction coefficient F = {:e} at node {}: F times the ratio 2^{e} of the node's tangential and normal row norms is out of the range of normal doubles",
                    friction[i],
                    i + 1
                )))
            }
        })
        .collect()
}

/// Lower triangle (row ≥ col) and full storage of A, checking the storage convention and,
/// for full storage, symmetry. Linear in the number of entries (no sorting). `a` is the
/// caller's A times `2^scale_log2` (see [`stiffness_exponent`]): messages report the caller's
/// numbers.
fn lower_and_full(
    a: &CsrMatrix,
    storage: Storage,
    scale_log2: i32,
) -> Result<(CsrMatrix, CsrMatrix)> {
    let n = a.nrows();
    let keep = |m: &CsrMatrix, lower: bool| {
        let mut rp = vec![0usize; n + 1];
        let (mut ci, mut vals) = (Vec::new(), Vec::new());
        for i in 0..n {
            for (j, v) in m.row(i) {
                if (lower && j <= i) || (!lower && j >= i) {
                    ci.push(j);
                    vals.push(v);
                }
            }
            rp[i + 1] = ci.len();
        }
        CsrMatrix {
            nrows: n,
            ncols: n,
            row_ptr: rp,
            col_idx: ci,
            values: vals,
        }
    };
    match storage {
        Storage::Full => {
            let at = a.transpose();
            let tol = 1e-10 * a.max_abs();
            for i in 0..n {
                let (mut x, mut y) = (a.row(i).peekable(), at.row(i).peekable());
                loop {
                    let (c, d) = match (x.peek().copied(), y.peek().copied()) {
                        (None, None) => break,
                        (Some((j, v)), None) => {
                            x.next();
                            (j, v)
                        }
                        (None, Some((j, w))) => {
                            y.next();
                            (j, -w)
                        }
                        (Some((j, v)), Some((k, w))) => match j.cmp(&k) {
                            std::cmp::Ordering::Equal => {
                                x.next();
                                y.next();
                                (j, v - w)
                            }
                            std::cmp::Ordering::Less => {
                                x.next();
                                (j, v)
                            }
                            std::cmp::Ordering::Greater => {
                                y.next();
                                (k, -w)
                            }
                        },
                    };
                    if d.abs() > tol {
                        return Err(Error::NotSymmetric(format!(
                            "A is not symmetric: A({}, {}) and A({}, {}) differ by {:e} (tolerance 1e-10 * max|A| = {:e}); pass lower or upper storage if only one triangle is meant",
                            i + 1,
                            c + 1,
                            c + 1,
                            i + 1,
                            mul_pow2(d.abs(), -scale_log2),
                            mul_pow2(tol, -scale_log2)
                        )));
                    }
                }
            }
            // (A + Aᵀ)/2: uses both triangles the caller gave, and A and Aᵀ give
            // bit-identical results (a row-major and a column-major caller agree).
            let mut sym = a.clone();
            for i in 0..n {
                let (r0, r1) = (sym.row_ptr[i], sym.row_ptr[i + 1]);
                let mut t = at.row(i).peekable();
                for k in r0..r1 {
                    let j = sym.col_idx[k];
                    while t.peek().is_some_and(|&(c, _)| c < j) {
                        t.next();
                    }
                    let w = match t.peek() {
                        Some(&(c, w)) if c == j => w,
                        _ => 0.0,
                    };
                    // (no overflow for entries near f64::MAX)
                    sym.values[k] = 0.5 * sym.values[k] + 0.5 * w;
                }
            }
            Ok((keep(&sym, true), sym))
        }
        Storage::Lower | Storage::Upper => {
            let lower = storage == Storage::Lower;
            for i in 0..n {
                for (j, _) in a.row(i) {
                    if (lower && j > i) || (!lower && j < i) {
                        return Err(Error::Csr(format!(
                            "A (CSR, {storage:?} storage): entry ({}, {}) (1-based) lies in the other triangle",
                            i + 1,
                            j + 1
                        )));
                    }
                }
            }
            let lo = if lower { a.clone() } else { a.transpose() };
            // full = lower + strict upper (the transpose of lower without its diagonal)
            let up = lo.transpose();
            let mut rp = vec![0usize; n + 1];
            let (mut ci, mut vals) = (Vec::new(), Vec::new());
            for i in 0..n {
                for (j, v) in lo.row(i) {
                    ci.push(j);
                    vals.push(v);
                }
                for (j, v) in up.row(i) {
                    if j > i {
                        ci.push(j);
                        vals.push(v);
                    }
                }
                rp[i + 1] = ci.len();
            }
            let full = CsrMatrix {
                nrows: n,
                ncols: n,
                row_ptr: rp,
                col_idx: ci,
                values: vals,
            };
            Ok((lo, full))
        }
    }
}

/// The largest accepted [`ProblemBuilder::threads`].
pub const MAX_THREADS: usize = 1024;

/// Runs `f` with the parallelism for `threads`: sequential on the calling thread for 1,
/// else inside a private rayon pool of `threads` threads that ends with the call.
fn with_threads<T: Send>(
    threads: usize,
    f: impl FnOnce(faer::Par) -> Result<T> + Send,
) -> Result<T> {
    #[cfg(feature = "threads")]
    if threads > 1 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("fricont-{i}"))
            .build()
            .map_err(|e| Error::Numerical(format!("cannot start {threads} threads: {e}")))?;
        return pool.install(|| f(faer::Par::rayon(threads)));
    }
    #[cfg(not(feature = "threads"))]
    let _ = threads;
    f(faer::Par::Seq)
}

/// Asks for `bytes` at once and gives them back: [`Error::OutOfMemory`] naming `what` when
/// the allocation fails (the process keeps running).
pub(crate) fn preflight(bytes: usize, what: &str) -> Result<()> {
    let mut v: Vec<u8> = Vec::new();
    v.try_reserve_exact(bytes)
        .map_err(|_| crate::error::oom(what, bytes, 1))
}

/// The accepted range of `r / r0` (r0 = [`Problem::default_r`]). Solutions do not
/// depend on r, but the fixed-α solver's equations mix `λ` and `r (N u − g)`: far outside
/// this range one of them drowns in the other's rounding (the sample fails to start at
/// 1e-8 · r0 and at 1e10 · r0, and works from 1e-6 to 1e8).
pub const R_RANGE: (f64, f64) = (1e-6, 1e6);

fn check_r(r: f64, r_default: f64) -> Result<()> {
    if !r.is_finite() || r <= 0.0 {
        return Err(Error::InvalidParameter(format!(
            "r = {r}, must be finite and > 0"
        )));
    }
    let rel = r / r_default;
    if !(R_RANGE.0..=R_RANGE.1).contains(&rel) {
        return Err(Error::InvalidParameter(format!(
            "r = {r:e} is outside [{:e}, {:e}] × the default r0 = 2p / trace(W) = {r_default:e} (r does not change the solutions; leave it at its default)",
            R_RANGE.0, R_RANGE.1
        )));
    }
    Ok(())
}

/// A validated, factorised contact problem. Immutable; share it with `Arc`.
#[derive(Debug)]
pub struct Problem {
    n: usize,
    p: usize,
    a: Option<std::sync::Arc<CsrMatrix>>,
    b: CsrMatrix,
    friction: Vec<f64>,
    /// The gap as given.
    gap: Vec<f64>,
    /// Equilibrated gap `g_i / s_i`.
    gap_eq: Vec<f64>,
    /// Equilibrated friction `F_i s_{p+i} / s_i`.
    friction_eq: Vec<f64>,
    row_scale: Vec<f64>,
    a_scale_log2: i32,
    r: f64,
    r_default: f64,
    /// The absolute row sums of W (equilibrated rows).
    w_row_sums: std::sync::Arc<Vec<f64>>,
    delassus: std::sync::Arc<Delassus>,
    /// See [`Problem::extended_precision`].
    extended: bool,
    /// See [`Problem::threads`].
    threads: usize,
}

impl Problem {
    /// Number of displacement dofs `n` (0 for a problem made from condensed data).
    pub fn n(&self) -> usize {
        self.n
    }
    /// True when u can be computed (fricont's factor of A or a host's solve); false for a
    /// problem made from condensed data.
    pub fn has_displacement(&self) -> bool {
        self.delassus.has_solve()
    }
    /// True for a problem made from condensed data ([`ProblemBuilder::condensed`]): loads
    /// are condensed vectors of 2p entries.
    pub fn is_condensed(&self) -> bool {
        self.delassus.is_condensed()
    }
    /// Length of the load vectors: n, or 2p for a problem made from condensed data.
    pub fn load_len(&self) -> usize {
        self.delassus.load_len()
    }
    /// Number of contact nodes `p`.
    pub fn p(&self) -> usize {
        self.p
    }
    /// The stiffness matrix, full storage, as fricont uses it: the caller's A (for full
    /// storage `(A + Aᵀ)/2`) times `2^`[`Problem::a_scale_log2`] (exactly the caller's
    /// numbers unless A's largest entry lies outside `[2^-64, 2^64]`); None when the
    /// problem was made from a host's solve or from condensed data.
    pub fn a(&self) -> Option<&CsrMatrix> {
        self.a.as_deref()
    }
    /// The exponent k of the exact internal scaling `2^k A` (even; 0 unless A's largest
    /// entry lies outside `[2^-64, 2^64]`, then the k that brings it into `[1, 4)`).
    /// Extreme but valid scales (A × 4e307, subnormal entries) are factorised as
    /// ordinary numbers this way; results are reported in the caller's units. The problem
    /// `(A, f, λ, u, g)` is factorised as `(2^k A, 2^(k/2) f, 2^(k/2) λ, 2^(-k/2) u,
    /// 2^(-k/2) g)`: `2^(k/2)` is part of [`Problem::row_scale`], and the residual of a
    /// state is that of the scaled equations. 0 for a host's solve and condensed data.
    pub fn a_scale_log2(&self) -> i32 {
        self.a_scale_log2
    }
    /// The equilibrated `B = [N; T]` (2p×n; 2p×0 for condensed data): rows `0..p` are N,
    /// rows `p..2p` are T, row k divided by [`Problem::row_scale`]`[k]`. W, the condensed
    /// loads and every internal λ refer to these rows; the path reports λ in the caller's
    /// units.
    pub fn b(&self) -> &CsrMatrix {
        &self.b
    }
    /// The scale `s_k` of each row of B (2p values: N's rows, then T's): the power of two
    /// at or below `‖B_k‖₂ · 2^(k/2)` (1 for an empty row; k = [`Problem::a_scale_log2`],
    /// 0 for ordinary A); for condensed data at or below `sqrt(W_kk)`. Internal forces are
    /// `s_k λ_k` for the caller's `λ_k`; node i's internal gap is `g_i / s_i` and its
    /// internal friction coefficient `F_i s_{p+i} / s_i`
    /// ([`Problem::friction_equilibrated`]).
    pub fn row_scale(&self) -> &[f64] {
        &self.row_scale
    }
    /// Friction coefficients, one per node.
    pub fn friction(&self) -> &[f64] {
        &self.friction
    }
    /// Gap, one per node, as given (length units of `N u`).
    pub fn gap(&self) -> &[f64] {
        &self.gap
    }
    /// The equilibrated gap `g_i / s_i` (see [`Problem::b`]).
    pub fn gap_equilibrated(&self) -> &[f64] {
        &self.gap_eq
    }
    /// The friction coefficients of the equilibrated rows, `F_i s_{p+i} / s_i` (see
    /// [`Problem::row_scale`]): the cone of the internal forces.
    pub fn friction_equilibrated(&self) -> &[f64] {
        &self.friction_eq
    }
    /// The augmentation parameter in use (force per length).
    pub fn r(&self) -> f64 {
        self.r
    }
    /// The data-derived default `r = 2p / trace(W)`, the reciprocal of the mean diagonal of
    /// the Delassus operator (a contact stiffness). Also the scale by which displacement
    /// guards are compared with force guards, so tolerances never depend on the chosen r.
    pub fn default_r(&self) -> f64 {
        self.r_default
    }
    /// The absolute row sums of W, `|W| 1` (2p values, equilibrated rows; length per
    /// force): `(|W| |λ|)_k ≤ (|W| 1)_k ‖λ‖∞` bounds the terms of row k of `W λ`.
    pub fn w_row_sums(&self) -> &[f64] {
        &self.w_row_sums
    }
    /// The condensation (Cholesky of A, W).
    pub fn delassus(&self) -> &Delassus {
        &self.delassus
    }
    /// The threads it was built with ([`ProblemBuilder::threads`], 1 by default): those of
    /// the set-up, and of the tracer's dense passes where m = 2p ≥
    /// [`crate::PARALLEL_MIN_ORDER`].
    pub fn threads(&self) -> usize {
        self.threads
    }
    /// True when W is carried beyond double precision (see [`ExtendedPrecision`]): W was
    /// refined (`W_hi + W_lo`, [`Delassus::w_lo`]; the loads' condensed vectors are then
    /// refined too), or the problem was made from condensed data with
    /// [`ExtendedPrecision::On`], or with `Auto` and an ill-conditioned W (the caller's W
    /// and q are exact data). The tracer then locates transition points in double-double.
    pub fn extended_precision(&self) -> bool {
        self.extended
    }
    /// An estimate of the 2-norm condition number of the equilibrated W (dimensionless, a
    /// lower bound that is usually within a few percent; see
    /// [`Delassus::w_condition_estimate`]). Computed at every build (O(p²) on top of the
    /// Cholesky factorisation of W that checks it).
    pub fn w_condition_estimate(&self) -> f64 {
        self.delassus.w_condition_estimate()
    }
    /// A copy of this problem with another `r`; the factor of A and W are shared, not
    /// recomputed. Errors: r ≤ 0 or not finite, `r / default_r()` outside [`R_RANGE`].
    pub fn with_r(&self, r: f64) -> Result<Problem> {
        check_r(r, self.r_default)?;
        Ok(Problem {
            n: self.n,
            p: self.p,
            a: self.a.clone(),
            b: self.b.clone(),
            friction: self.friction.clone(),
            gap: self.gap.clone(),
            gap_eq: self.gap_eq.clone(),
            friction_eq: self.friction_eq.clone(),
            row_scale: self.row_scale.clone(),
            a_scale_log2: self.a_scale_log2,
            r,
            r_default: self.r_default,
            w_row_sums: self.w_row_sums.clone(),
            delassus: self.delassus.clone(),
            extended: self.extended,
            threads: self.threads,
        })
    }
}
