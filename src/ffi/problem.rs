//! The problem handle: A, N, T in CSR, friction, gap, r; factorised once and shared.

use std::ffi::{c_char, c_int, c_void};
use std::sync::{Arc, Mutex};

use super::boundary::{
    ErrorSlot, Failure, FfiResult, HasSlot, ffi_boundary, handle_ref, len_of, put, slice_in,
    write_message,
};
use super::path::{UserData, fricont_free_fn};
use super::status::{fricont_status, fricont_storage};
use crate::condense::{HostSolve, SolveFailure};
use crate::problem::{CsrMatrix, Problem, ProblemBuilder, Storage};

/// A sparse matrix in compressed sparse row (CSR) form with `int64_t` indices, as the
/// caller stores it. The library only reads it during the call that receives it and
/// copies what it needs. For `int32_t` indices (PETSc's default `PetscInt`, Eigen, the
/// int API of CHOLMOD, scipy) use `fricont_csr_i32` with the `_i32` constructors.
///
/// Row `i` (0-based position) holds the entries `row_ptr[i] - index_base ..
/// row_ptr[i+1] - index_base` (0-based positions in `col_idx` and `values`); the column
/// numbers in `col_idx` count from `index_base` too. Within a row the columns may come in
/// any order and may repeat: **duplicate entries are summed** (in the order given), as
/// scipy, MATLAB's `sparse`, Eigen's `setFromTriplets` and PETSc's `ADD_VALUES` do; the
/// checks of A (symmetry in full storage, positive definiteness) apply to the summed
/// matrix.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
#[allow(non_camel_case_types)]
pub struct fricont_csr {
    /// Number of rows, ≥ 0.
    pub nrows: i64,
    /// Number of columns, ≥ 0.
    pub ncols: i64,
    /// Number of stored entries: the length of `col_idx` and `values`, and
    /// `row_ptr[nrows] - index_base`.
    pub nnz: i64,
    /// `nrows + 1` row pointers, `row_ptr[0] == index_base`, non-decreasing.
    pub row_ptr: *const i64,
    /// `nnz` column indices (NULL allowed when `nnz == 0`).
    pub col_idx: *const i64,
    /// `nnz` values (NULL allowed when `nnz == 0`), finite.
    pub values: *const f64,
    /// 0 (C) or 1 (Fortran, MATLAB).
    pub index_base: i64,
}

/// A sparse matrix in CSR form with `int32_t` row pointers and column indices: the same
/// layout and rules as `fricont_csr` (index base, unsorted columns, duplicates summed),
/// for callers whose matrices hold 32-bit indices, passed to `fricont_problem_new_i32`
/// and `fricont_problem_new_solve_i32` without a copy on the caller's side (the library
/// copies during the call, as for `fricont_csr`). The sizes stay `int64_t`; `nnz` and
/// every row pointer must fit in `int32_t` (they do when the arrays are `int32_t`).
/// A negative row pointer or column index is `FRICONT_ERR_CSR`, as with 64-bit indices.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
#[allow(non_camel_case_types)]
pub struct fricont_csr_i32 {
    /// Number of rows, ≥ 0.
    pub nrows: i64,
    /// Number of columns, ≥ 0.
    pub ncols: i64,
    /// Number of stored entries: the length of `col_idx` and `values`, and
    /// `row_ptr[nrows] - index_base`.
    pub nnz: i64,
    /// `nrows + 1` row pointers, `row_ptr[0] == index_base`, non-decreasing.
    pub row_ptr: *const i32,
    /// `nnz` column indices (NULL allowed when `nnz == 0`).
    pub col_idx: *const i32,
    /// `nnz` values (NULL allowed when `nnz == 0`), finite.
    pub values: *const f64,
    /// 0 (C) or 1 (Fortran, MATLAB).
    pub index_base: i64,
}

/// A contact problem: the stiffness A, the contact matrices N and T, friction, gap and
/// the augmentation parameter r. Opaque.
///
/// Created by `fricont_problem_new`, configured by the `fricont_problem_set_*` setters,
/// factorised by `fricont_problem_build` (or implicitly by the first `fricont_path_new_*`
/// after a change), freed by `fricont_problem_free`. Every path created from it keeps its
/// own reference to the factorised data as it was at the path's creation, so the problem
/// handle may be changed or freed while paths are alive, and any number of paths may use
/// one problem, from any threads. The problem handle itself is internally locked: its
/// functions may be called from several threads at once.
#[allow(non_camel_case_types)]
pub struct fricont_problem {
    slot: ErrorSlot,
    inner: Mutex<ProblemInner>,
}

struct ProblemInner {
    /// Number of dofs (0 for a problem made from condensed data).
    n: usize,
    p: usize,
    /// The recorded data and settings (taken out and put back by the setters).
    builder: Option<ProblemBuilder>,
    /// The factorised problem for the current settings, if built.
    built: Option<Arc<Problem>>,
}

impl HasSlot for fricont_problem {
    fn slot(&self) -> &ErrorSlot {
        &self.slot
    }
}

impl fricont_problem {
    fn lock(&self) -> std::sync::MutexGuard<'_, ProblemInner> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The factorised problem for the current settings (building it if needed).
    pub(crate) fn shared(&self) -> FfiResult<(Arc<Problem>, usize, usize)> {
        let mut inner = self.lock();
        let problem = inner.build()?;
        Ok((problem, inner.n, inner.p))
    }
}

impl ProblemInner {
    fn update(&mut self, f: impl FnOnce(ProblemBuilder) -> ProblemBuilder) {
        let b = self
            .builder
            .take()
            .expect("builder present outside a setter");
        self.builder = Some(f(b));
        self.built = None;
    }

    fn build(&mut self) -> FfiResult<Arc<Problem>> {
        if let Some(p) = &self.built {
            return Ok(p.clone());
        }
        let b = self
            .builder
            .clone()
            .expect("builder present outside a setter");
        let p = Arc::new(b.build()?);
        self.built = Some(p.clone());
        Ok(p)
    }
}

/// A caller's CSR struct of either index width (the two C structs differ only there).
trait CsrIn {
    /// The index type of `row_ptr` and `col_idx`.
    type Index: Copy + Into<i64>;
    /// `(nrows, ncols, nnz, row_ptr, col_idx, values, index_base)`.
    #[allow(clippy::type_complexity)]
    fn parts(
        &self,
    ) -> (
        i64,
        i64,
        i64,
        *const Self::Index,
        *const Self::Index,
        *const f64,
        i64,
    );
}

impl CsrIn for fricont_csr {
    type Index = i64;
    fn parts(&self) -> (i64, i64, i64, *const i64, *const i64, *const f64, i64) {
        let m = self;
        (
            m.nrows,
            m.ncols,
            m.nnz,
            m.row_ptr,
            m.col_idx,
            m.values,
            m.index_base,
        )
    }
}

impl CsrIn for fricont_csr_i32 {
    type Index = i32;
    fn parts(&self) -> (i64, i64, i64, *const i32, *const i32, *const f64, i64) {
        let m = self;
        (
            m.nrows,
            m.ncols,
            m.nnz,
            m.row_ptr,
            m.col_idx,
            m.values,
            m.index_base,
        )
    }
}

/// Reads a caller's CSR matrix of either index width (`name` for messages).
///
/// # Safety
/// `m` is NULL or points to a CSR struct whose arrays are valid for their lengths.
unsafe fn read_csr<M: CsrIn>(m: *const M, name: &str) -> FfiResult<CsrMatrix> {
    // SAFETY: by this function's contract.
    let m = unsafe { handle_ref(m, name) }?;
    let (nrows, ncols, nnz, rp, ci, vals, base) = m.parts();
    let nrows = len_of(nrows, &format!("{name}.nrows"))?;
    let ncols = len_of(ncols, &format!("{name}.ncols"))?;
    let nnz = len_of(nnz, &format!("{name}.nnz"))?;
    // SAFETY: the struct's arrays have the lengths it states (the caller's contract).
    let (row_ptr, col_idx, values) = unsafe {
        (
            slice_in(rp, nrows + 1, &format!("{name}.row_ptr"))?,
            slice_in(ci, nnz, &format!("{name}.col_idx"))?,
            slice_in(vals, nnz, &format!("{name}.values"))?,
        )
    };
    Ok(CsrMatrix::from_raw(
        name, nrows, ncols, row_ptr, col_idx, values, base,
    )?)
}

fn storage_of(code: i32) -> FfiResult<Storage> {
    match code {
        c if c == fricont_storage::FRICONT_STORAGE_FULL as i32 => Ok(Storage::Full),
        c if c == fricont_storage::FRICONT_STORAGE_LOWER as i32 => Ok(Storage::Lower),
        c if c == fricont_storage::FRICONT_STORAGE_UPPER as i32 => Ok(Storage::Upper),
        c => Err(Failure::range(format!(
            "a_storage = {c} is not a storage code (FRICONT_STORAGE_FULL = 0, _LOWER = 1, _UPPER = 2)"
        ))),
    }
}

/// Creates a problem from the stiffness matrix A and the contact matrices N and T.
///
/// * `a`: A (n×n), symmetric positive definite with the Dirichlet dofs eliminated, in
///   the storage given by `a_storage`. Not NULL.
/// * `a_storage`: `FRICONT_STORAGE_FULL`, `_LOWER` or `_UPPER` (`fricont_storage`).
/// * `n`, `t`: N and T (p×n, p ≥ 1, 2p ≤ n): row i gives the outward normal and the
///   tangential displacement of contact node i, so that `(N u)_i ≤ g_i` is
///   non-penetration. Not NULL.
/// * `out`: receives the new handle (NULL on failure). Not NULL.
///
/// All arrays are read during the call and copied; the caller keeps ownership. The CSR
/// structure, the dimensions and finiteness are checked here; symmetry, positive
/// definiteness of A and the rank of B = [N; T] when the problem is built. Defaults of
/// the settings: F = 0 (frictionless), gap g = 0, r = 2p / trace(W) (see
/// `fricont_problem_r`).
///
/// Returns `FRICONT_OK`; `FRICONT_ERR_NULL` (a NULL argument or array);
/// `FRICONT_ERR_LENGTH` (negative sizes, A not square, N or T not p×n, p = 0);
/// `FRICONT_ERR_RANGE` (unknown `a_storage`); `FRICONT_ERR_CSR` (malformed CSR, index base
/// not 0/1); `FRICONT_ERR_NONFINITE` (NaN or infinity in a value); `FRICONT_ERR_PANIC`.
/// The message is in `fricont_last_error_message`.
///
/// # Safety
/// Each pointer is NULL or valid as described; arrays have the lengths the CSR structs
/// state.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_new(
    a: *const fricont_csr,
    a_storage: i32,
    n: *const fricont_csr,
    t: *const fricont_csr,
    out: *mut *mut fricont_problem,
) -> fricont_status {
    // SAFETY: by this function's contract.
    ffi_boundary!(unsafe { problem_new(a, a_storage, n, t, out) })
}

/// `fricont_problem_new` for CSR matrices with `int32_t` indices (`fricont_csr_i32`):
/// the same arguments, checks, defaults, ownership (the arrays are read during the call
/// and copied) and statuses. A, N and T all use 32-bit indices.
///
/// Returns `FRICONT_OK`; `FRICONT_ERR_NULL`; `FRICONT_ERR_LENGTH`; `FRICONT_ERR_RANGE`;
/// `FRICONT_ERR_CSR` (malformed CSR: a negative or decreasing row pointer, a column index
/// out of range or negative, index base not 0/1); `FRICONT_ERR_NONFINITE`;
/// `FRICONT_ERR_PANIC`, as `fricont_problem_new`.
///
/// # Safety
/// As for `fricont_problem_new`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_new_i32(
    a: *const fricont_csr_i32,
    a_storage: i32,
    n: *const fricont_csr_i32,
    t: *const fricont_csr_i32,
    out: *mut *mut fricont_problem,
) -> fricont_status {
    // SAFETY: by this function's contract.
    ffi_boundary!(unsafe { problem_new(a, a_storage, n, t, out) })
}

/// The body of `fricont_problem_new` and `fricont_problem_new_i32`.
///
/// # Safety
/// As for `fricont_problem_new`.
unsafe fn problem_new<M: CsrIn>(
    a: *const M,
    a_storage: i32,
    n: *const M,
    t: *const M,
    out: *mut *mut fricont_problem,
) -> FfiResult {
    if out.is_null() {
        return Err(Failure::null(
            "out (the fricont_problem ** receiving the handle)",
        ));
    }
    // SAFETY: `out` is a valid pointer by contract; clear it before any failure.
    unsafe { out.write(std::ptr::null_mut()) };
    // SAFETY: by this function's contract.
    let (am, nm, tm) = unsafe { (read_csr(a, "A")?, read_csr(n, "N")?, read_csr(t, "T")?) };
    let storage = storage_of(a_storage)?;
    let nd = am.nrows();
    if am.ncols() != nd {
        return Err(Failure::length(format!(
            "A is {}x{}, must be square",
            nd,
            am.ncols()
        )));
    }
    let p = nm.nrows();
    if p == 0 {
        return Err(Failure::length(
            "N has 0 rows: there must be at least one contact node",
        ));
    }
    for (name, m) in [("N", &nm), ("T", &tm)] {
        if m.nrows() != p || m.ncols() != nd {
            return Err(Failure::length(format!(
                "{name} is {}x{}, expected p x n = {p}x{nd} (p from the rows of N, n from A)",
                m.nrows(),
                m.ncols()
            )));
        }
    }
    // SAFETY: `out` is valid (checked above).
    unsafe { new_handle(out, nd, p, ProblemBuilder::new(am, storage, nm, tm)) }
}

/// Writes a new handle for `builder` into `out` (valid, by the callers' contract).
///
/// # Safety
/// `out` is valid for one write.
unsafe fn new_handle(
    out: *mut *mut fricont_problem,
    n: usize,
    p: usize,
    builder: ProblemBuilder,
) -> FfiResult {
    let handle = Box::new(fricont_problem {
        slot: ErrorSlot::default(),
        inner: Mutex::new(ProblemInner {
            n,
            p,
            builder: Some(builder),
            built: None,
        }),
    });
    // SAFETY: by this function's contract.
    unsafe { out.write(Box::into_raw(handle)) };
    Ok(fricont_status::FRICONT_OK)
}

/// Creates a problem from condensed data: the Delassus operator W = B A⁻¹ Bᵀ of the
/// caller's stiffness A and contact matrices B = [N; T] (for example the Schur complement
/// a distributed direct solver computes, see the README's "Distributed hosts"). fricont
/// never sees A, N or T.
///
/// * `p`: the number of contact nodes, ≥ 1.
/// * `w`: W, 2p × 2p, column-major with leading dimension `ldw` ≥ 2p (entry (i, j) at
///   `w[i + j * ldw]`, 0-based): rows and columns 0..p are the normal rows of B (N),
///   p..2p the tangential ones (T), in the caller's units (length per force). Symmetric
///   (relative tolerance 1e-10; the mean of both triangles is used) and positive
///   definite. Read during the call and copied; not NULL.
/// * `out`: receives the new handle (NULL on failure). Not NULL.
///
/// Loads are then given condensed: every load vector (`fricont_path_new_affine`'s f0, f1,
/// the basis vectors, what a general callback writes) has 2p entries, q = B A⁻¹ f, in the
/// same row order as W. The gap, friction and r setters work as for
/// `fricont_problem_new` (the gap in the length units of N u). States carry no
/// displacement: pass `u = NULL` in `fricont_state` (a non-NULL u gives
/// `FRICONT_ERR_UNAVAILABLE`), and `fricont_problem_dims` reports n = 0. The residual of a
/// state then checks the contact law against d = q + W λ only.
///
/// Symmetry and positive definiteness are checked when the problem is built (first
/// `fricont_problem_build`, `fricont_problem_r` or `fricont_path_new_*`): a non-symmetric
/// W gives `FRICONT_ERR_NOT_SYMMETRIC`, an indefinite one `FRICONT_ERR_NOT_SPD` with the
/// failing row and node in the message, a NaN or infinity `FRICONT_ERR_NONFINITE`.
///
/// Returns `FRICONT_OK`; `FRICONT_ERR_NULL` (`w` or `out`); `FRICONT_ERR_LENGTH` (p < 1,
/// ldw < 2p, or 2p × ldw beyond the address space); `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `w` is NULL or valid for reading `ldw * (2p - 1) + 2p` doubles; `out` is NULL or
/// valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_new_condensed(
    p: i64,
    w: *const f64,
    ldw: i64,
    out: *mut *mut fricont_problem,
) -> fricont_status {
    ffi_boundary!({
        if out.is_null() {
            return Err(Failure::null(
                "out (the fricont_problem ** receiving the handle)",
            ));
        }
        // SAFETY: `out` is a valid pointer by contract; clear it before any failure.
        unsafe { out.write(std::ptr::null_mut()) };
        let pn = len_of(p, "p")?;
        if pn == 0 {
            return Err(Failure::length(
                "p = 0: there must be at least one contact node",
            ));
        }
        let m = 2 * pn;
        let ld = len_of(ldw, "ldw")?;
        if ld < m {
            return Err(Failure::length(format!(
                "ldw = {ld} is smaller than 2p = {m}"
            )));
        }
        let total = ld
            .checked_mul(m - 1)
            .and_then(|v| v.checked_add(m))
            .filter(|&v| v <= isize::MAX as usize / 8)
            .ok_or_else(|| {
                Failure::length(format!(
                    "W of 2p = {m} columns with ldw = {ld} does not fit in memory"
                ))
            })?;
        // SAFETY: valid for `total` reads by contract.
        let wv = unsafe { slice_in(w, total, "w") }?;
        let mut wm = crate::error::try_zeros(m, m, "a copy of W")?;
        for j in 0..m {
            for i in 0..m {
                wm[(i, j)] = wv[i + j * ld];
            }
        }
        // SAFETY: `out` is valid (checked above).
        unsafe { new_handle(out, 0, pn, ProblemBuilder::condensed(wm)) }
    })
}

/// The host's solve with its stiffness A (see `fricont_problem_new_solve`): overwrite
/// each of the `ncols` columns of `x` (n rows, column-major, leading dimension
/// `ldx` ≥ n: entry (i, j) at `x[i + j * ldx]`) with A⁻¹ times it. `user` is the pointer
/// given to `fricont_problem_new_solve`. Return 0 on success, a positive code for a
/// recoverable failure (fricont restores the right-hand sides and calls once more), a
/// negative code for a fatal one (SUNDIALS' convention). Called only from inside
/// fricont's functions, on the thread that called them (never from a thread of
/// fricont's own), one call at a time per problem; it must not call fricont functions
/// that use the same problem.
#[allow(non_camel_case_types)]
pub type fricont_solve_fn = Option<
    unsafe extern "C" fn(user: *mut c_void, n: i64, ncols: i64, x: *mut f64, ldx: i64) -> c_int,
>;

/// The C solve as a Rust closure (user data carried across threads: the host answers for
/// it, as documented on `fricont_solve_fn`); the finalizer runs when the last problem or
/// path that uses it is freed.
struct CSolve {
    f: unsafe extern "C" fn(*mut c_void, i64, i64, *mut f64, i64) -> c_int,
    user: UserData,
}
// SAFETY: fricont calls the host's solve only from threads that called into fricont with
// this problem, one call at a time (a mutex); the host's contract for `user` covers this.
unsafe impl Send for CSolve {}

impl CSolve {
    fn call(&self, mut x: faer::MatMut<'_, f64>) -> Result<(), SolveFailure> {
        let (n, k) = (x.nrows(), x.ncols());
        let contiguous = x.row_stride() == 1 && x.col_stride() >= n as isize;
        let code = if contiguous {
            // SAFETY: `x` addresses k columns of n values with stride `col_stride`; the
            // host's function is valid by the contract of `fricont_problem_new_solve`.
            unsafe {
                (self.f)(
                    self.user.ptr,
                    n as i64,
                    k as i64,
                    x.as_ptr_mut(),
                    (x.col_stride() as i64).max(1),
                )
            }
        } else {
            let mut tmp = x.to_owned();
            let ld = (tmp.col_stride() as i64).max(1);
            // SAFETY: as above, for the contiguous copy.
            let c = unsafe {
                (self.f)(
                    self.user.ptr,
                    n as i64,
                    k as i64,
                    tmp.as_mut().as_ptr_mut(),
                    ld,
                )
            };
            x.copy_from(&tmp);
            c
        };
        match code {
            0 => Ok(()),
            c => Err(SolveFailure {
                code: c,
                message: format!(
                    "the solve returned {c} ({}) for a block of {k} column(s)",
                    if c > 0 {
                        "recoverable, retried once"
                    } else {
                        "fatal"
                    }
                ),
            }),
        }
    }
}

/// Creates a problem from the contact matrices N and T and the host's own solve with its
/// stiffness A (n × n, symmetric positive definite; for an FEM code that has A factorised
/// already). fricont never sees A.
///
/// * `n`: the number of dofs, ≥ 2p.
/// * `solve`: the host's solve (see `fricont_solve_fn`); not NULL. `user` is passed to
///   it unchanged (may be NULL) and must stay valid until `free_user` is called.
/// * `free_user`: NULL, or called exactly once with `user` when the problem and every
///   path made from it have been freed (or at once when this function fails).
/// * `max_block`: the largest number of columns fricont passes in one call (≥ 1; fricont
///   uses at most 256).
/// * `nmat`, `tmat`: N and T (p × n, p ≥ 1), as for `fricont_problem_new`. Not NULL.
/// * `out`: receives the new handle (NULL on failure). Not NULL.
///
/// Cost: the build forms W = B A⁻¹ Bᵀ by 2p solves (in blocks of `max_block` columns);
/// each basis load vector costs one solve when a path is made, a general load one solve
/// per evaluation (two without a derivative), u at a point one solve. Loads are ordinary
/// (n entries). The residual of a state checks the contact law with d = B u and omits
/// A u − f − Bᵀ λ (A is unknown). At the build, a W that is not symmetric to 1e-8
/// relative (a solve that is not that of a symmetric matrix) gives
/// `FRICONT_ERR_NOT_SYMMETRIC`; a failing solve `FRICONT_ERR_SOLVE_CALLBACK`.
///
/// Returns `FRICONT_OK`; `FRICONT_ERR_NULL` (`solve`, `nmat`, `tmat`, `out`, an array);
/// `FRICONT_ERR_LENGTH` (n < 2p, N or T not p × n, p = 0, max_block < 1);
/// `FRICONT_ERR_CSR`; `FRICONT_ERR_NONFINITE`; `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `solve` is NULL or a function as documented; `nmat`, `tmat` as for
/// `fricont_problem_new`; `out` is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_new_solve(
    n: i64,
    solve: fricont_solve_fn,
    user: *mut c_void,
    free_user: fricont_free_fn,
    max_block: i64,
    nmat: *const fricont_csr,
    tmat: *const fricont_csr,
    out: *mut *mut fricont_problem,
) -> fricont_status {
    // Owned here so that the finalizer runs even if the call fails.
    let user = UserData {
        ptr: user,
        free: free_user,
    };
    // SAFETY: by this function's contract.
    ffi_boundary!(unsafe { problem_new_solve(n, solve, user, max_block, nmat, tmat, out) })
}

/// `fricont_problem_new_solve` for N and T with `int32_t` indices (`fricont_csr_i32`):
/// the same arguments, solve contract, finalizer rule (`free_user` is called exactly once,
/// at once if this function fails), ownership and statuses.
///
/// Returns `FRICONT_OK`; `FRICONT_ERR_NULL`; `FRICONT_ERR_LENGTH`; `FRICONT_ERR_CSR`;
/// `FRICONT_ERR_NONFINITE`; `FRICONT_ERR_PANIC`, as `fricont_problem_new_solve`.
///
/// # Safety
/// As for `fricont_problem_new_solve`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_new_solve_i32(
    n: i64,
    solve: fricont_solve_fn,
    user: *mut c_void,
    free_user: fricont_free_fn,
    max_block: i64,
    nmat: *const fricont_csr_i32,
    tmat: *const fricont_csr_i32,
    out: *mut *mut fricont_problem,
) -> fricont_status {
    // Owned here so that the finalizer runs even if the call fails.
    let user = UserData {
        ptr: user,
        free: free_user,
    };
    // SAFETY: by this function's contract.
    ffi_boundary!(unsafe { problem_new_solve(n, solve, user, max_block, nmat, tmat, out) })
}

/// The body of `fricont_problem_new_solve` and `fricont_problem_new_solve_i32`.
///
/// # Safety
/// As for `fricont_problem_new_solve`.
unsafe fn problem_new_solve<M: CsrIn>(
    n: i64,
    solve: fricont_solve_fn,
    user: UserData,
    max_block: i64,
    nmat: *const M,
    tmat: *const M,
    out: *mut *mut fricont_problem,
) -> FfiResult {
    if out.is_null() {
        return Err(Failure::null(
            "out (the fricont_problem ** receiving the handle)",
        ));
    }
    // SAFETY: `out` is a valid pointer by contract; clear it before any failure.
    unsafe { out.write(std::ptr::null_mut()) };
    let Some(f) = solve else {
        return Err(Failure::null("solve (the host's solve function)"));
    };
    let nd = len_of(n, "n")?;
    if max_block < 1 {
        return Err(Failure::length(format!(
            "max_block = {max_block}, must be ≥ 1"
        )));
    }
    // SAFETY: by this function's contract.
    let (nm, tm) = unsafe { (read_csr(nmat, "N")?, read_csr(tmat, "T")?) };
    let p = nm.nrows();
    if p == 0 {
        return Err(Failure::length(
            "N has 0 rows: there must be at least one contact node",
        ));
    }
    for (name, m) in [("N", &nm), ("T", &tm)] {
        if m.nrows() != p || m.ncols() != nd {
            return Err(Failure::length(format!(
                "{name} is {}x{}, expected p x n = {p}x{nd} (p from the rows of N, n as given)",
                m.nrows(),
                m.ncols()
            )));
        }
    }
    if 2 * p > nd {
        return Err(Failure::length(format!(
            "2p = {} exceeds n = {nd}, so B = [N; T] cannot have full row rank",
            2 * p
        )));
    }
    let cs = CSolve { f, user };
    let host = HostSolve::new(
        Box::new(move |x| cs.call(x)),
        usize::try_from(max_block).unwrap_or(usize::MAX),
    );
    // SAFETY: `out` is valid (checked above).
    unsafe { new_handle(out, nd, p, ProblemBuilder::with_solve(nd, host, nm, tm)) }
}

/// Frees a problem handle. NULL is a no-op. Paths created from it stay valid (they hold
/// their own reference to the factorised data). Never use the handle afterwards.
///
/// # Safety
/// `problem` is NULL or a handle from `fricont_problem_new` not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_free(problem: *mut fricont_problem) {
    super::boundary::run_value((), || {
        if !problem.is_null() {
            // SAFETY: a live handle from `Box::into_raw`, by contract.
            drop(unsafe { Box::from_raw(problem) });
        }
    })
}

/// Sets the same friction coefficient F (dimensionless, finite, ≥ 0) at every node.
/// Default 0 (frictionless). A change drops the factorisation: the next build (explicit or
/// by `fricont_path_new_*`) factorises A again; existing paths are not affected.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`), `FRICONT_ERR_RANGE` (F < 0 or not
/// finite; the setting is then unchanged), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `problem` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_set_friction(
    problem: *mut fricont_problem,
    friction: f64,
) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        if !friction.is_finite() || friction < 0.0 {
            return Err(Failure::range(format!(
                "friction coefficient F = {friction}, must be finite and >= 0"
            )));
        }
        h.lock().update(|b| b.friction_uniform(friction));
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Sets one friction coefficient per contact node: `friction[i]` (finite, ≥ 0) for node i
/// (0-based), `len` must equal p. The array is copied. Default: 0 at every node. A change
/// drops the factorisation as for `fricont_problem_set_friction`.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`, or `friction` with `len > 0`),
/// `FRICONT_ERR_LENGTH` (`len ≠ p`), `FRICONT_ERR_RANGE` (a value < 0 or not finite; the
/// message names the node), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `problem` is NULL or a live handle; `friction` is NULL or valid for `len` reads.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_set_friction_nodes(
    problem: *mut fricont_problem,
    friction: *const f64,
    len: i64,
) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        let len = len_of(len, "len")?;
        // SAFETY: by this function's contract.
        let f = unsafe { slice_in(friction, len, "friction") }?;
        let mut inner = h.lock();
        if len != inner.p {
            return Err(Failure::length(format!(
                "friction has {len} values, expected p = {}",
                inner.p
            )));
        }
        if let Some(i) = f.iter().position(|v| !v.is_finite() || *v < 0.0) {
            return Err(Failure::range(format!(
                "friction[{i}] (node {}) = {}, must be finite and >= 0",
                i + 1,
                f[i]
            )));
        }
        let f = f.to_vec();
        inner.update(|b| b.friction(f));
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Sets the initial normal gap g (p values, length units of u): node i is in contact when
/// `(N u)_i = g_i`. `gap` NULL (with any `len`) restores the default g = 0; otherwise
/// `len` must equal p. The array is copied. A change drops the factorisation as for
/// `fricont_problem_set_friction`.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`), `FRICONT_ERR_LENGTH` (`len ≠ p`),
/// `FRICONT_ERR_NONFINITE` (a NaN or infinity; the message names the node),
/// `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `problem` is NULL or a live handle; `gap` is NULL or valid for `len` reads.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_set_gap(
    problem: *mut fricont_problem,
    gap: *const f64,
    len: i64,
) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        let mut inner = h.lock();
        let p = inner.p;
        if gap.is_null() {
            inner.update(|b| b.gap(vec![0.0; p]));
            return Ok(fricont_status::FRICONT_OK);
        }
        let len = len_of(len, "len")?;
        if len != p {
            return Err(Failure::length(format!("gap has {len} values, expected p = {p}")));
        }
        // SAFETY: non-NULL and valid for `len` reads by contract.
        let g = unsafe { slice_in(gap, len, "gap") }?;
        if let Some(i) = g.iter().position(|v| !v.is_finite()) {
            return Err(Failure::new(
                fricont_status::FRICONT_ERR_NONFINITE,
                format!("gap[{i}] (node {}) is {}", i + 1, g[i]),
            ));
        }
        let g = g.to_vec();
        inner.update(|b| b.gap(g));
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Sets the augmentation parameter r > 0 (force per length) of the equations H = 0
/// H1 = A u − f − Nᵀλν − Tᵀλt, H2 = λν − min(λν − r (N u − g), 0),
/// H3 = λt − P_[−b,b](λt − r T u) with b = max(−F λν, 0).
/// Solutions, classes and transition points do not depend on r; it scales the
/// rows H2, H3 and so the reported residuals. Default: r = 2p / trace(W), the reciprocal
/// of the mean diagonal of the Delassus operator W = B A⁻¹ Bᵀ of the equilibrated rows
/// (each row of N and of T scaled to about unit norm by a power of two, and by another
/// for an A whose largest entry lies outside [2^-64, 2^64]; the README's "Conventions").
/// Changing r keeps the factorisation (no new Cholesky of A).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`), `FRICONT_ERR_RANGE` (r ≤ 0 or not
/// finite; or, once the problem is built, r outside [1e-6, 1e6] × the default — the
/// setting is then unchanged; before the build that range is checked by
/// `fricont_problem_build`), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `problem` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_set_r(
    problem: *mut fricont_problem,
    r: f64,
) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        if !r.is_finite() || r <= 0.0 {
            return Err(Failure::range(format!("r = {r}, must be finite and > 0")));
        }
        let mut inner = h.lock();
        // Built already: the range check (r relative to the default) happens first, so
        // that a refused r leaves the handle as it was.
        let rebuilt = match inner.built.as_ref() {
            Some(p) => Some(Arc::new(p.with_r(r)?)),
            None => None,
        };
        if rebuilt.is_some() {
            inner.built = rebuilt;
        }
        let b = inner.builder.take().expect("builder present outside a setter");
        inner.builder = Some(b.r(r));
        Ok(fricont_status::FRICONT_OK)
    })
}

/// The order m = 2p from which a path's dense passes (LU factorisations, triangular
/// solves, products with W) use the problem's threads (`fricont_problem_set_threads`);
/// below it they run on the calling thread, as fast.
pub const FRICONT_PARALLEL_MIN_ORDER: i64 = 2048;
const _: () = assert!(FRICONT_PARALLEL_MIN_ORDER as usize == crate::dense::PARALLEL_MIN_ORDER);

/// Sets the number of threads of the set-up and of the trace's dense passes. The numeric
/// Cholesky factorisation of A and forming W run on a private pool of `threads` threads,
/// started by the build and stopped when it ends. Where m = 2p ≥ 2048
/// (`FRICONT_PARALLEL_MIN_ORDER`: below it one thread is as fast), each call into a path
/// of the problem (`fricont_path_start`, `_step`, `_run`, `_solutions_at`,
/// `_choose_branch`) starts such a pool for its LU factorisations, triangular solves and
/// products with W, and stops it before returning; the path's logic and every callback
/// (load, host's solve, monitor) stay on the calling thread. Default 1: no thread is ever
/// started, and fricont never uses a global thread pool of the host. Results agree with
/// one thread to rounding (1e-14 relative in W, 1e-12 in the events' α). Takes effect at
/// the next build (an already built problem is kept as it is). A library built without
/// its `threads` feature accepts the setting and runs on the calling thread.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`), `FRICONT_ERR_RANGE` (threads
/// outside 1..=1024), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `problem` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_set_threads(
    problem: *mut fricont_problem,
    threads: i64,
) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        let max = crate::problem::MAX_THREADS;
        let t = usize::try_from(threads)
            .ok()
            .filter(|t| (1..=max).contains(t))
            .ok_or_else(|| Failure::range(format!("threads = {threads}, must be in 1..={max}")))?;
        let mut inner = h.lock();
        let b = inner.builder.take().expect("builder present outside a setter");
        inner.builder = Some(b.threads(t));
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Sets whether W and the condensed loads are carried beyond double precision
/// (`ProblemBuilder::extended_precision` of the Rust API): `mode` 0 = auto (the default),
/// 1 = on, 2 = off. On slender bodies (thin strips, beams) W = B A⁻¹ Bᵀ is so
/// ill-conditioned that W rounded to double moves transition points by up to ~1e-7 in α;
/// with extended precision fricont also computes the low parts of W and of the condensed
/// load vectors by mixed-precision iterative refinement with its Cholesky factor of A
/// (residuals in double-double, about four solves with the factor per column of Bᵀ at
/// the build, and 2p × 2p more doubles of memory). Auto refines where the refinement is
/// cheap (at most 6e9 floating-point operations, about 0.3 s: small problems, whose
/// events then carry about 1e-14 instead of 1e-12 to 1e-9 relative error), and where an
/// estimate of the 2-norm condition number of the equilibrated W exceeds 1e6 and the
/// refinement's estimated cost is at most max(20 × the factorisation's, 1e11
/// floating-point operations), or whatever it costs where that estimate exceeds 1e8
/// (there double's rounding moved a transition of a slender strip by 4.3e-3 in α); off
/// never. A problem made from condensed data (`fricont_problem_new_condensed`) is never
/// refined (its W is the caller's data); with on (or auto and an ill-conditioned W) it is
/// traced in extended precision all the same. Like the friction, a change drops the
/// factorisation: the next build (explicit or by `fricont_path_new_*`) factorises A
/// again; existing paths are not affected. Query the outcome with
/// `fricont_problem_extended_precision`. Under a general load
/// (`fricont_path_new_general`) each evaluation is refined too, at about twice its cost:
/// in double alone the solutions at neighbouring α of a slender body disagree by more
/// than the transition thresholds, and the trace stops with `FRICONT_ERR_NUMERICAL`.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`), `FRICONT_ERR_RANGE` (`mode` not
/// 0, 1 or 2; the setting is then unchanged), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
/// With mode 1 on a problem made with a host's solve (`fricont_problem_new_solve`), the
/// build fails with `FRICONT_ERR_RANGE`: without A there is nothing to refine with.
///
/// # Safety
/// `problem` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_set_extended_precision(
    problem: *mut fricont_problem,
    mode: i32,
) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        let m = match mode {
            0 => crate::ExtendedPrecision::Auto,
            1 => crate::ExtendedPrecision::On,
            2 => crate::ExtendedPrecision::Off,
            _ => {
                return Err(Failure::range(format!(
                    "extended precision mode = {mode}, must be 0 (auto), 1 (on) or 2 (off)"
                )));
            }
        };
        h.lock().update(|b| b.extended_precision(m));
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Whether the problem is traced in extended precision (`*extended` = 1, else 0: W was
/// refined beyond double, or condensed data with mode on or auto and an ill-conditioned W;
/// see `fricont_problem_set_extended_precision`) and the estimate of the 2-norm condition
/// number of the equilibrated W (`*w_condition`, dimensionless; a lower bound usually
/// within a few percent, from 20 power and 20 inverse iterations). Builds the problem if
/// needed (so it returns the build's errors too). Each output pointer may be NULL.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`), the errors of
/// `fricont_problem_build`, `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `problem` is NULL or a live handle; `extended`, `w_condition` are NULL or valid for
/// one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_extended_precision(
    problem: *mut fricont_problem,
    extended: *mut i32,
    w_condition: *mut f64,
) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        let (pr, _, _) = h.shared()?;
        // SAFETY: NULL or valid, by contract.
        unsafe {
            put(extended, i32::from(pr.extended_precision()));
            put(w_condition, pr.w_condition_estimate());
        }
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Validates and factorises the problem now: checks the symmetry of A (full storage),
/// computes a sparse Cholesky factorisation of A and the Delassus operator W = B A⁻¹ Bᵀ:
/// from the trailing block of the factor (the dofs B touches ordered last) where that is
/// cheaper, by 2p solves with an AMD-ordered factor where they are (slender bodies, wide
/// rows of B), or with the host's solve; a condensed W is checked instead;
/// and checks that W is positive definite (B = [N; T] of full row rank). Extreme but
/// valid scales of A work (entries of 1e300 or 1e-310, with loads of the same size): an
/// A whose largest entry lies outside [2^-64, 2^64] is factorised as 2^k A (exact, k
/// bringing it into [1, 4)) and results are reported in the caller's units; a load that
/// makes u overflow a double gives `FRICONT_ERR_NUMERICAL` where u is computed (the start
/// of a path). Optional: `fricont_path_new_*` builds when
/// needed; call it to see data errors early or to time the set-up. A no-op when nothing
/// changed since the last build.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_NOT_SYMMETRIC`,
/// `FRICONT_ERR_NOT_SPD`, `FRICONT_ERR_RANK_DEFICIENT`, `FRICONT_ERR_CSR` (an entry of A in
/// the wrong triangle for the storage), `FRICONT_ERR_LENGTH` (2p > n), `FRICONT_ERR_RANGE`
/// (an r set outside [1e-6, 1e6] × the default 2p / trace(W); or A's largest entry a
/// subnormal number below 2^-1034 ≈ 5.4e-312, fewer than 40 significant bits: multiply A
/// and the loads by one power of two; or a friction coefficient F that, times the ratio of
/// its node's tangential and normal row norms, leaves the range of normal doubles: rows
/// whose lengths differ by a factor near 1e308, or a tangential row near 1e-308 of its
/// normal one), `FRICONT_ERR_NUMERICAL` (W = B A⁻¹ Bᵀ beyond the
/// range of a double: A numerically singular),
/// `FRICONT_ERR_OUT_OF_MEMORY` (the factor, W or a copy of the data cannot be allocated:
/// the message says how much was asked; the handle stays usable),
/// `FRICONT_ERR_SOLVE_CALLBACK` (the host's solve failed), `FRICONT_ERR_POISONED`,
/// `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `problem` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_build(problem: *mut fricont_problem) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        h.shared()?;
        Ok(fricont_status::FRICONT_OK)
    })
}

/// The dimensions: `*n` receives the number of dofs n (0 for a problem made by
/// `fricont_problem_new_condensed`), `*p` the number of contact nodes p. Each output pointer may be NULL (not written). Does not build.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`), `FRICONT_ERR_POISONED`,
/// `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `problem` is NULL or a live handle; `n`, `p` are NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_dims(
    problem: *const fricont_problem,
    n: *mut i64,
    p: *mut i64,
) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        let inner = h.lock();
        // SAFETY: NULL or valid, by contract.
        unsafe {
            put(n, inner.n as i64);
            put(p, inner.p as i64);
        }
        Ok(fricont_status::FRICONT_OK)
    })
}

/// The augmentation parameter in use (`*r`) and its data-derived default 2p / trace(W)
/// (`*default_r`), both force per length. Builds the problem if needed (so it returns the
/// build's errors too). Each output pointer may be NULL.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`), the errors of
/// `fricont_problem_build`, `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `problem` is NULL or a live handle; `r`, `default_r` are NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_r(
    problem: *mut fricont_problem,
    r: *mut f64,
    default_r: *mut f64,
) -> fricont_status {
    ffi_boundary!(problem => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(problem, "problem") }?;
        let (pr, _, _) = h.shared()?;
        // SAFETY: NULL or valid, by contract.
        unsafe {
            put(r, pr.r());
            put(default_r, pr.default_r());
        }
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Copies the message of the most recent failing call on this problem handle into `buf`
/// with `snprintf` semantics (at most `len - 1` bytes and a NUL, cut at a UTF-8 character
/// boundary; nothing written when `buf` is NULL or `len` is 0). Returns the full message
/// length in bytes without the NUL (0 if no call on the handle has failed; also 0 for a
/// NULL handle). Works on a poisoned handle.
///
/// # Safety
/// `problem` is NULL or a live handle; `buf` is NULL or valid for `len` bytes of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_problem_error_message(
    problem: *const fricont_problem,
    buf: *mut c_char,
    len: usize,
) -> usize {
    super::boundary::run_value(0, || {
        // SAFETY: NULL or a live handle, by contract.
        let Some(h) = (unsafe { problem.as_ref() }) else {
            return 0;
        };
        // SAFETY: by contract.
        unsafe { write_message(&h.slot.message(), buf, len) }
    })
}
