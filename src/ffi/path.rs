//! The path handle: a load bound to a problem, stepping, events, states, queries.

use std::cell::RefCell;
use std::ffi::{c_char, c_void};
use std::sync::Arc;

use super::boundary::{
    ErrorSlot, Failure, FfiResult, HasSlot, ffi_boundary, handle_ref, len_of, put, slice_in,
    slice_out, write_message,
};
use super::problem::fricont_problem;
use super::status::{class_code, fricont_end_reason, fricont_start_route, fricont_status};
use crate::load::{Load, LoadFailure};
use crate::path::{Path, PathOptions, Solution, State, StepOutcome};
use crate::problem::Problem;

/// A general load callback: writes `f(α)` (or its derivative `f'(α)` when registered as
/// the derivative) into `f_out[0..n)`.
///
/// * `alpha`: the load parameter.
/// * `f_out`: n doubles owned by the library, valid only during the call (do not keep the
///   pointer). Force units are those of `A u`.
/// * `n`: the number of dofs.
/// * `user_data`: the pointer given to `fricont_path_new_general`.
///
/// Return 0 on success. Any other value aborts the current step: the calling function
/// returns `FRICONT_ERR_CALLBACK`, the path ends (`FRICONT_END_FAILED`) keeping what it
/// traced, and the value is kept for `fricont_path_callback_code`. A NaN or infinity in
/// `f_out` is treated the same way (`FRICONT_ERR_CALLBACK_VALUE`). Callbacks are called
/// synchronously, on the thread that called into the library, possibly several times per
/// step and at α slightly outside the window (finite differences). They must not throw
/// (C++), `longjmp` or call `mexErrMsgTxt`: return a code instead. A call into the same
/// path handle from inside the callback returns `FRICONT_ERR_ORDER` and changes nothing.
#[allow(non_camel_case_types)]
pub type fricont_load_fn = Option<
    unsafe extern "C" fn(alpha: f64, f_out: *mut f64, n: i64, user_data: *mut c_void) -> i32,
>;

/// A basis-weights callback for `f(α) = Σ_j φ_j(α) f_j`: writes `φ_j(α)` into `phi[0..k)`
/// and `φ_j'(α)` into `dphi[0..k)` (both arrays owned by the library, valid only during
/// the call). `user_data` is the pointer given to `fricont_path_new_basis`. Same return
/// contract as `fricont_load_fn`.
#[allow(non_camel_case_types)]
pub type fricont_weights_fn = Option<
    unsafe extern "C" fn(
        alpha: f64,
        phi: *mut f64,
        dphi: *mut f64,
        k: i64,
        user_data: *mut c_void,
    ) -> i32,
>;

/// A progress monitor, called by `fricont_path_run` after each transition point.
///
/// * `alpha`: α of the transition point just passed.
/// * `transitions`: transition points traced so far (events of one degenerate transition
///   count once).
/// * `first_event`, `end_event`: the new events are `first_event .. end_event − 1`
///   (0-based, for `fricont_path_event`; one per node that changed class).
/// * `user_data`: the pointer given to `fricont_path_set_monitor`.
///
/// Return 0 to go on; any other value stops the path cleanly: `fricont_path_run` returns
/// `FRICONT_END` with the end reason `FRICONT_END_STOPPED`, everything traced is kept, and
/// `fricont_path_step` / `fricont_path_run` continue from there. Called synchronously on
/// the thread that called `fricont_path_run`, with the path handle free: the monitor may
/// call the path's queries (`fricont_path_event`, `fricont_path_event_state`, …) but must
/// not free the path. It must not throw (C++), `longjmp` or call `mexErrMsgTxt`.
#[allow(non_camel_case_types)]
pub type fricont_monitor_fn = Option<
    unsafe extern "C" fn(
        alpha: f64,
        transitions: i64,
        first_event: i64,
        end_event: i64,
        user_data: *mut c_void,
    ) -> i32,
>;

/// A finalizer for a callback's `user_data`: called exactly once with `user_data` when
/// the library no longer needs it (see the `fricont_path_new_*` functions).
#[allow(non_camel_case_types)]
pub type fricont_free_fn = Option<unsafe extern "C" fn(user_data: *mut c_void)>;

/// One node changing class at a transition point (a plain value, copied out by
/// `fricont_path_event`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_camel_case_types)]
pub struct fricont_event {
    /// 0-based position in the path's event list.
    pub index: i64,
    /// 0-based number of the transition point; the events of one degenerate transition
    /// (several nodes switching at the same α) share it and come in node order.
    pub transition: i64,
    /// α at the transition point.
    pub alpha: f64,
    /// **0-based** contact node (row of N and T). Reports and the paper count from 1: print
    /// `node + 1`.
    pub node: i64,
    /// Class before the event (`fricont_class` code).
    pub from: i32,
    /// Class after the event (`fricont_class` code).
    pub to: i32,
    /// α turns back here (the sign of dα/ds after the transition is opposite to before).
    pub fold: bool,
    /// More than one neighbouring piece continues the path here.
    pub bifurcation: bool,
    /// ‖H‖∞ at the transition point over max(‖|A||u|‖∞, ‖f‖∞, ‖|Bᵀ||λ|‖∞, ‖λ‖∞,
    /// r‖|B||u|‖∞, r‖g‖∞, r‖W‖∞‖λ‖∞) (W = B A⁻¹ Bᵀ with unit contact rows): a normwise
    /// backward error (dimensionless).
    pub residual: f64,
}

/// A point of the solution curve, written into buffers that the caller owns. The caller
/// sets the four buffer pointers and lengths; the library writes `alpha`, `residual` and
/// the buffers. Each buffer pointer may be NULL (that part is not written, its length is
/// ignored); otherwise its length must be at least the size it receives (n for `u`, p for
/// the others), else the call fails with `FRICONT_ERR_LENGTH` and writes nothing.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
#[allow(non_camel_case_types)]
pub struct fricont_state {
    /// Output: the load parameter α.
    pub alpha: f64,
    /// Output: ‖H‖∞ over the scale of `fricont_event.residual` at this point (dimensionless).
    pub residual: f64,
    /// Displacements u (n values, length units), or NULL.
    pub u: *mut f64,
    /// Length of `u` (≥ n when `u` is not NULL).
    pub u_len: i64,
    /// Normal contact forces λν (p values, ≤ 0: compressive), or NULL.
    pub lambda_n: *mut f64,
    /// Length of `lambda_n` (≥ p when not NULL).
    pub lambda_n_len: i64,
    /// Tangential contact forces λt (p values), or NULL.
    pub lambda_t: *mut f64,
    /// Length of `lambda_t` (≥ p when not NULL).
    pub lambda_t_len: i64,
    /// Class of every node (p `fricont_class` codes) on the piece the point is reported
    /// for, or NULL. At an event: the classes of the piece after it.
    pub classes: *mut i32,
    /// Length of `classes` (≥ p when not NULL).
    pub classes_len: i64,
}

/// A traced smooth piece (copied out by `fricont_path_piece`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_camel_case_types)]
pub struct fricont_piece {
    /// α where the path entered the piece.
    pub alpha_from: f64,
    /// α where the path left it (so far, for the current piece); equal to `alpha_from`
    /// for a vertical piece.
    pub alpha_to: f64,
    /// Sign of dα/ds on the piece: +1, −1, or 0 for a vertical piece (a continuum of
    /// solutions at one α).
    pub direction: i32,
    /// The path's orientation sign, sign det [J; tᵀ] with J = ∂H/∂(λ, α) on the piece and t
    /// its tangent; constant along a path (folds show as a change of `direction`).
    pub orientation: i32,
    /// Sign of det ∂H/∂λ on the piece (0 if singular).
    pub det_sign: i32,
}

/// A candidate continuation at a bifurcation (copied out by `fricont_path_branch`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_camel_case_types)]
pub struct fricont_branch {
    /// Sign of dα/ds along the branch (0 for a vertical piece).
    pub direction: i32,
    /// True if it keeps the path's orientation.
    pub orientation_preserving: bool,
}

/// Where a solution from `fricont_path_solutions_at` comes from.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(non_camel_case_types)]
pub struct fricont_solution {
    /// 0-based index of the traced piece (`fricont_path_piece`) that gave it.
    pub piece: i64,
    /// True when that piece is vertical at this α: every point between the piece's ends
    /// is a solution too (a continuum).
    pub continuum: bool,
}

/// The caller's `user_data` with its finalizer, shared by the load closures.
pub(crate) struct UserData {
    pub(crate) ptr: *mut c_void,
    pub(crate) free: fricont_free_fn,
}

impl Drop for UserData {
    fn drop(&mut self) {
        if let Some(free) = self.free {
            // SAFETY: the caller's finalizer, called once with its own pointer.
            unsafe { free(self.ptr) }
        }
    }
}

// SAFETY: the library never dereferences `ptr`; it only hands it back to the caller's
// callbacks, which run synchronously on the thread that is using the path handle. A path
// handle is used by one thread at a time (documented), so `user_data` is never touched by
// two threads at once through the library. The load closures must be `Send` because the
// Rust `Path` is.
unsafe impl Send for UserData {}
// SAFETY: as above; shared references only let the closures read the pointer value.
unsafe impl Sync for UserData {}

/// A path: a load bound to a problem, traced step by step. Opaque.
///
/// Created by `fricont_path_new_affine`, `_basis` or `_general`, configured by the
/// `fricont_path_set_*` setters, started by `fricont_path_start`, advanced by
/// `fricont_path_step` / `fricont_path_run`, freed by `fricont_path_free`.
///
/// A path handle must not be used by two threads at the same time; different path handles
/// (on the same problem or not) may be used from different threads at once. Its load
/// callbacks run on the thread that calls into the path.
#[allow(non_camel_case_types)]
pub struct fricont_path {
    slot: ErrorSlot,
    /// Only shared references to the handle are ever formed (the slot is read by the
    /// boundary while the body runs); the mutable part sits in a `RefCell`. A load
    /// callback that re-enters the same handle finds it borrowed: `FRICONT_ERR_ORDER`.
    inner: RefCell<PathInner>,
}

/// The message of a call into a path from inside one of its own load callbacks.
const BUSY: &str = "the path is busy: it was called from inside one of its own load callbacks (a callback must not call back into its path)";

impl fricont_path {
    /// The path's state for reading; `FRICONT_ERR_ORDER` while a step is under way (a
    /// load callback calling back into its own path).
    fn read(&self) -> FfiResult<std::cell::Ref<'_, PathInner>> {
        self.inner.try_borrow().map_err(|_| Failure::order(BUSY))
    }

    /// The path's state for changing; `FRICONT_ERR_ORDER` as [`Self::read`].
    fn lock(&self) -> FfiResult<std::cell::RefMut<'_, PathInner>> {
        self.inner
            .try_borrow_mut()
            .map_err(|_| Failure::order(BUSY))
    }
}

/// A monitor with its user data (finalised when dropped).
struct Monitor {
    f: unsafe extern "C" fn(f64, i64, i64, i64, *mut c_void) -> i32,
    user: UserData,
}

struct PathInner {
    n: usize,
    p: usize,
    problem: Arc<Problem>,
    /// The load until the Rust path is created at the first start.
    load: Option<Load>,
    window: Option<(f64, f64)>,
    max_steps: usize,
    zero_tol: f64,
    max_alpha_step: Option<f64>,
    monitor: Option<Arc<Monitor>>,
    path: Option<Path>,
    solutions: Vec<Solution>,
}

impl HasSlot for fricont_path {
    fn slot(&self) -> &ErrorSlot {
        &self.slot
    }
}

const NOT_STARTED: &str = "the path has not been started: call fricont_path_start first";

impl PathInner {
    fn started(&self) -> FfiResult<&Path> {
        match &self.path {
            Some(p) if p.is_started() => Ok(p),
            _ => Err(Failure::order(NOT_STARTED)),
        }
    }

    fn started_mut(&mut self) -> FfiResult<&mut Path> {
        match &mut self.path {
            Some(p) if p.is_started() => Ok(p),
            _ => Err(Failure::order(NOT_STARTED)),
        }
    }

    fn configurable(&self, what: &str) -> FfiResult<()> {
        if self.path.is_some() {
            return Err(Failure::order(format!(
                "{what} can only be set before the first fricont_path_start"
            )));
        }
        Ok(())
    }

    /// Copies a state into the caller's buffers (all checked before anything is written).
    fn fill_state(&self, st: &State, out: *mut fricont_state) -> FfiResult<()> {
        // SAFETY: NULL or a caller-initialised struct, by the exported functions' contract.
        let Some(out) = (unsafe { out.as_mut() }) else {
            return Ok(());
        };
        let (n, p) = (self.n, self.p);
        if !out.u.is_null() && !self.problem.has_displacement() {
            return Err(Failure::new(
                fricont_status::FRICONT_ERR_UNAVAILABLE,
                "u is not available: the problem was made from condensed data (fricont_problem_new_condensed); pass u = NULL",
            ));
        }
        // SAFETY: the caller's buffers are valid for their stated lengths.
        let (u, ln, lt, cl) = unsafe {
            (
                slice_out(out.u, out.u_len, n, "u")?,
                slice_out(out.lambda_n, out.lambda_n_len, p, "lambda_n")?,
                slice_out(out.lambda_t, out.lambda_t_len, p, "lambda_t")?,
                slice_out(out.classes, out.classes_len, p, "classes")?,
            )
        };
        if let Some(u) = u {
            u.copy_from_slice(&st.u);
        }
        if let Some(l) = ln {
            l.copy_from_slice(&st.lambda_n);
        }
        if let Some(l) = lt {
            l.copy_from_slice(&st.lambda_t);
        }
        copy_classes(cl, &st.classes);
        out.alpha = st.alpha;
        out.residual = st.residual;
        Ok(())
    }
}

/// Writes class codes into a caller buffer when one was given.
fn copy_classes(dst: Option<&mut [i32]>, src: &[crate::Class]) {
    if let Some(d) = dst {
        for (c, k) in d.iter_mut().zip(src) {
            *c = class_code(*k);
        }
    }
}

fn index_in(k: i64, count: usize, what: &str) -> FfiResult<usize> {
    usize::try_from(k)
        .ok()
        .filter(|&k| k < count)
        .ok_or_else(|| Failure::range(format!("{what} index {k} is outside 0..{count}")))
}

/// Common part of the three constructors.
///
/// # Safety
/// `problem` is NULL or live; `out` is NULL or valid for one write.
unsafe fn new_path(
    problem: *mut fricont_problem,
    out: *mut *mut fricont_path,
    make_load: impl FnOnce(usize) -> FfiResult<Load>,
) -> FfiResult {
    if out.is_null() {
        return Err(Failure::null(
            "out (the fricont_path ** receiving the handle)",
        ));
    }
    // SAFETY: valid by contract; cleared before anything can fail.
    unsafe { out.write(std::ptr::null_mut()) };
    // SAFETY: NULL or live, by contract.
    let prob = unsafe { handle_ref(problem, "problem") }?;
    let (shared, n, p) = prob.shared()?;
    // n entries, or 2p condensed ones for a problem made from condensed data.
    let load_len = shared.load_len();
    let load = make_load(load_len)?;
    if load.n() != load_len {
        return Err(Failure::length(if shared.is_condensed() {
            format!(
                "the load has {} entries; a problem made from condensed data takes condensed loads of 2p = {load_len} entries",
                load.n()
            )
        } else {
            format!(
                "the load has {} entries, the problem has n = {n} dofs",
                load.n()
            )
        }));
    }
    let handle = Box::new(fricont_path {
        slot: ErrorSlot::default(),
        inner: RefCell::new(PathInner {
            n,
            p,
            problem: shared,
            load: Some(load),
            window: None,
            max_steps: 10_000,
            zero_tol: 1e-11,
            max_alpha_step: None,
            monitor: None,
            path: None,
            solutions: Vec::new(),
        }),
    });
    // SAFETY: valid by contract.
    unsafe { out.write(Box::into_raw(handle)) };
    Ok(fricont_status::FRICONT_OK)
}

/// Creates a path with the affine load `f(α) = f0 + α f1` on a problem (building the
/// problem first if its settings changed since the last build).
///
/// * `problem`: not NULL. The path keeps its own reference to the factorised problem; the
///   handle may be freed afterwards.
/// * `f0`, `f1`: n values each (force units of `A u`), read during the call and copied.
///   Not NULL (unless `n` = 0, which is an error anyway).
/// * `n`: their length; must equal the problem's n.
/// * `out`: receives the handle (NULL on failure). Not NULL.
///
/// The path must be given an α window (`fricont_path_set_window`) before it is started.
/// For an affine load every piece of the solution curve is a straight segment and every
/// transition point is found exactly.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_LENGTH` (`n` ≠ the problem's n),
/// `FRICONT_ERR_NONFINITE` (NaN or infinity in f0 or f1), `FRICONT_ERR_OUT_OF_MEMORY`
/// (the path's dense working set, about eight 2p × 2p matrices, cannot be allocated),
/// the errors of `fricont_problem_build`, `FRICONT_ERR_POISONED` (problem),
/// `FRICONT_ERR_PANIC`. Error
/// messages go to the problem handle and to `fricont_last_error_message`.
///
/// # Safety
/// `problem` is NULL or a live handle; `f0`, `f1` are NULL or valid for `n` reads; `out`
/// is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_new_affine(
    problem: *mut fricont_problem,
    f0: *const f64,
    f1: *const f64,
    n: i64,
    out: *mut *mut fricont_path,
) -> fricont_status {
    ffi_boundary!(problem => {
        let make = |_| {
            let len = len_of(n, "n")?;
            // SAFETY: NULL or valid for `n` reads, by contract.
            let (a, b) = unsafe { (slice_in(f0, len, "f0")?, slice_in(f1, len, "f1")?) };
            Ok(Load::affine(a.to_vec(), b.to_vec())?)
        };
        // SAFETY: by this function's contract.
        unsafe { new_path(problem, out, make) }
    })
}

/// Creates a path with the load `f(α) = Σ_j φ_j(α) f_j`, j = 0..k−1: k fixed vectors with
/// scalar weights from a callback. One solve per vector at creation; each α then costs
/// nothing but the callback. Along each piece the solution is solved for once per vector
/// (k + 1 solves with the piece matrix), and the many evaluations that locate the piece's
/// end combine those solutions (O(k p) each); a general load (`fricont_path_new_general`)
/// costs a solve with the piece matrix at every evaluation instead (and solves with A
/// until its evaluations have spanned its directions). Prefer this form whenever the load
/// is a combination of a few fixed vectors.
///
/// * `problem`: not NULL (see `fricont_path_new_affine`).
/// * `vectors`: the k vectors, each of n values, stored one after the other (column-major
///   n×k: vector j starts at `vectors + j*n`); read during the call and copied. Not NULL.
/// * `n`: must equal the problem's n. `k`: ≥ 1.
/// * `weights`: writes φ_j(α) and φ_j'(α) (see `fricont_weights_fn`). Not NULL.
/// * `user_data`: passed to `weights`; may be NULL. The library never dereferences it.
/// * `free_user_data`: may be NULL. If given, it is called exactly once with `user_data`:
///   by `fricont_path_free`, or before this function returns if it fails.
/// * `out`: receives the handle (NULL on failure). Not NULL.
///
/// Returns as `fricont_path_new_affine`, plus `FRICONT_ERR_LENGTH` for k < 1 and
/// `FRICONT_ERR_NULL` for a NULL `weights`.
///
/// # Safety
/// `problem` is NULL or a live handle; `vectors` is NULL or valid for `n*k` reads; `out`
/// is NULL or valid for one write; the callback and finalizer follow their contracts.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fricont_path_new_basis(
    problem: *mut fricont_problem,
    vectors: *const f64,
    n: i64,
    k: i64,
    weights: fricont_weights_fn,
    user_data: *mut c_void,
    free_user_data: fricont_free_fn,
    out: *mut *mut fricont_path,
) -> fricont_status {
    // Owned here so that the finalizer runs even if the boundary refuses the call.
    let ud = Arc::new(UserData {
        ptr: user_data,
        free: free_user_data,
    });
    ffi_boundary!(problem => {
        let ud = ud;
        let make = |_| {
                let len = len_of(n, "n")?;
                let k = len_of(k, "k")?;
                if k == 0 {
                    return Err(Failure::length("k = 0: a basis load needs at least one vector"));
                }
                let weights = weights.ok_or_else(|| Failure::null("weights (the callback)"))?;
                let total = len
                    .checked_mul(k)
                    .ok_or_else(|| Failure::length(format!("n * k = {len} * {k} overflows")))?;
                // SAFETY: NULL or valid for `n*k` reads, by contract.
                let all = unsafe { slice_in(vectors, total, "vectors") }?;
                let vecs: Vec<Vec<f64>> = all.chunks(len.max(1)).map(|c| c.to_vec()).collect();
                let ud = ud.clone();
                let f = move |alpha: f64, phi: &mut [f64], dphi: &mut [f64]| {
                    // SAFETY: the caller's callback with library-owned buffers of k values.
                    let code = unsafe {
                        weights(alpha, phi.as_mut_ptr(), dphi.as_mut_ptr(), phi.len() as i64, ud.ptr)
                    };
                    if code == 0 {
                        Ok(())
                    } else {
                        Err(LoadFailure {
                            code,
                            message: format!("the basis weights callback returned {code}"),
                        })
                    }
                };
                Ok(Load::basis(vecs, Box::new(f))?)
        };
        // SAFETY: by this function's contract.
        unsafe { new_path(problem, out, make) }
    })
}

/// Creates a path with a general load `f(α)` computed by a callback, with an optional
/// derivative callback. Without a derivative, f'(α) is approximated by central differences
/// (used only for step control and orientation: transition points are located on the
/// guards themselves).
///
/// Cost: each evaluation calls `f` (and `df`, or `f` twice more for the differences),
/// condenses f(α) and f'(α) to the contact rows, and solves with the current piece's
/// matrix (O(p²)). A vector within 64 ε (2-norm, relative) of the span of those condensed
/// before is condensed as their combination (O(k n)) instead of by a solve with A
/// (exactly, for the vector moved by at most that much; checked against a solve at the
/// 1st, 2nd, 4th, … such evaluation, and given up where they differ by more than 1e-6): a
/// load `Σ_j φ_j(α) f_j` of a few fixed vectors costs a few dozen solves with A in all
/// instead of one per evaluation. A load that spans more than 8 directions solves with A
/// at every evaluation (the span holds up to 8 vectors of n values), and so does every
/// load where W was refined (`fricont_problem_set_extended_precision`: auto refines small
/// and ill-conditioned problems) and for n ≤ 32. A basis load (`fricont_path_new_basis`)
/// is cheaper still.
///
/// Accuracy: fricont does not see the terms that make up f(α), so it cannot tell how far
/// rounding moves f where the load passes through (near) zero. It takes them as large as
/// the load's change along the current piece (from the last transition point, or the
/// start; or over the load's own α length ‖q‖/‖q'‖ where that is longer; never more than
/// over the window; and at least over 64 roundings of α over zero_tol, as f computed from
/// α is known to no better than one rounding of α, |f'| ε |α|), and a guard within their
/// rounding is at zero. Where the load at a transition is far smaller than that change,
/// transitions that lie closer together can be merged into one or moved, without an
/// error: f = 1e-8 f0 + φ(α) f1 (φ = α + 0.2 sin 2α) traced from α = ±1 through φ = 0
/// had a wrong first transition near φ = 0 in 2 of 80 traces on finite-element meshes
/// (none of 80 on random problems), and 1e-10 f0 + φ(α) f1 wrong events on 5 of 160
/// traces. A basis load (`fricont_path_new_basis`) has
/// exact terms and traced all of them: give the load so where it is a sum of fixed
/// vectors. On an ill-conditioned body the rounding of each entry of f(α) (ε |f|, fresh
/// at every α) moves the solution by up to the piece's conditioning times that, also
/// where the problem is carried in extended precision: transitions are located to that
/// noise (slender strips with F = 5 and κ(W) ~ 1e8: f0 + φ(α) f1 as a general load put
/// its events within 7.4e-13 in φ of the affine load's). A basis load has no such noise.
///
/// * `problem`: not NULL (see `fricont_path_new_affine`).
/// * `n`: the load's length; must equal the problem's n.
/// * `f`: writes f(α) (see `fricont_load_fn`). Not NULL.
/// * `df`: writes f'(α), or NULL.
/// * `user_data`: passed to both callbacks; may be NULL; never dereferenced.
/// * `free_user_data`: may be NULL. If given, it is called exactly once with `user_data`:
///   by `fricont_path_free`, or before this function returns if it fails.
/// * `out`: receives the handle (NULL on failure). Not NULL.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`problem`, `f`, `out`), `FRICONT_ERR_LENGTH`,
/// the errors of `fricont_problem_build`, `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
/// The callbacks are not called here.
///
/// # Safety
/// `problem` is NULL or a live handle; `out` is NULL or valid for one write; the callbacks
/// and finalizer follow their contracts.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_new_general(
    problem: *mut fricont_problem,
    n: i64,
    f: fricont_load_fn,
    df: fricont_load_fn,
    user_data: *mut c_void,
    free_user_data: fricont_free_fn,
    out: *mut *mut fricont_path,
) -> fricont_status {
    let ud = Arc::new(UserData {
        ptr: user_data,
        free: free_user_data,
    });
    ffi_boundary!(problem => {
        let ud = ud;
        let make = |_| {
                let len = len_of(n, "n")?;
                let f = f.ok_or_else(|| Failure::null("f (the load callback)"))?;
                let wrap = |cb: unsafe extern "C" fn(f64, *mut f64, i64, *mut c_void) -> i32,
                            what: &'static str| {
                    let ud = ud.clone();
                    Box::new(move |alpha: f64, out: &mut [f64]| {
                        // SAFETY: the caller's callback with a library-owned buffer of n values.
                        let code = unsafe { cb(alpha, out.as_mut_ptr(), out.len() as i64, ud.ptr) };
                        if code == 0 {
                            Ok(())
                        } else {
                            Err(LoadFailure {
                                code,
                                message: format!("the {what} callback returned {code}"),
                            })
                        }
                    }) as crate::load::VectorFn
                };
                let fv = wrap(f, "load");
                let dfv = df.map(|d| wrap(d, "load derivative"));
                Ok(Load::general(len, fv, dfv))
        };
        // SAFETY: by this function's contract.
        unsafe { new_path(problem, out, make) }
    })
}

/// Frees a path handle (and, through the finalizer, its callbacks' `user_data`). NULL is a
/// no-op. Never use the handle afterwards.
///
/// # Safety
/// `path` is NULL or a handle from `fricont_path_new_*` not freed before, not in use by
/// another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_free(path: *mut fricont_path) {
    super::boundary::run_value((), || {
        if !path.is_null() {
            // SAFETY: a live handle from `Box::into_raw`, by contract.
            drop(unsafe { Box::from_raw(path) });
        }
    })
}

/// Sets the α window: the path is traced from `alpha_start` toward `alpha_end` and ends
/// (`FRICONT_END_WINDOW`) when α leaves `[min, max]` of the two, on either side (after a
/// fold it may leave through the start). Required before the first `fricont_path_start`;
/// no default.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_RANGE` (not finite or equal),
/// `FRICONT_ERR_ORDER` (after the first start), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_set_window(
    path: *mut fricont_path,
    alpha_start: f64,
    alpha_end: f64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let mut h = h.lock()?;
        h.configurable("the alpha window")?;
        if !alpha_start.is_finite() || !alpha_end.is_finite() || alpha_start == alpha_end {
            return Err(Failure::range(format!(
                "alpha window [{alpha_start}, {alpha_end}] must be finite with distinct ends"
            )));
        }
        h.window = Some((alpha_start, alpha_end));
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Sets the step limit: the path ends (`FRICONT_END_MAX_STEPS`) after this many transition
/// points. Default 10000; must be ≥ 1. Only before the first start.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_RANGE` (< 1), `FRICONT_ERR_ORDER`
/// (after the first start), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_set_max_steps(
    path: *mut fricont_path,
    max_steps: i64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let mut h = h.lock()?;
        h.configurable("the step limit")?;
        if max_steps < 1 {
            return Err(Failure::range(format!("max_steps = {max_steps}, must be >= 1")));
        }
        h.max_steps = usize::try_from(max_steps).unwrap_or(usize::MAX);
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Sets the relative tolerance for "a guard is at zero" and "several nodes switch at
/// once" (dimensionless, relative to the force scale of the current point). Default 1e-11;
/// must be in (0, 1e-3]. Only before the first start. Friction below about `zero_tol`
/// times the forces is not resolved: where such a node's slip reverses while it is
/// pressed, the run fails with `FRICONT_ERR_NUMERICAL` ("without the stick phase"; F =
/// 1e-10 traces with 1e-12). Give frictionless nodes F = 0.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_RANGE`, `FRICONT_ERR_ORDER`
/// (after the first start), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_set_zero_tol(
    path: *mut fricont_path,
    zero_tol: f64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let mut h = h.lock()?;
        h.configurable("the zero tolerance")?;
        if !(zero_tol > 0.0 && zero_tol <= 1e-3) {
            return Err(Failure::range(format!("zero_tol = {zero_tol}, must be in (0, 1e-3]")));
        }
        h.zero_tol = zero_tol;
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Sets the largest α step of the step control of a nonlinear load (a path made by
/// `fricont_path_new_basis` or `fricont_path_new_general`), in α units. Default: 1/8 of
/// the window's length; must be finite and > 0. Only before the first start.
///
/// Each step is also shortened until the cubic Hermite model of every guard predicts a
/// fresh evaluation at the step's midpoint, value and slope. A load that varies faster
/// than that test can see (a guard that dips below zero and comes back within a stretch
/// narrower than the step at which the test passes) is caught only by a step no longer
/// than that stretch: for an oscillating load, set this to a fraction of its shortest
/// period. No effect on an affine load, whose pieces are followed exactly.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_RANGE` (not finite or ≤ 0),
/// `FRICONT_ERR_ORDER` (after the first start), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_set_max_alpha_step(
    path: *mut fricont_path,
    max_alpha_step: f64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let mut h = h.lock()?;
        h.configurable("the largest alpha step")?;
        if !(max_alpha_step.is_finite() && max_alpha_step > 0.0) {
            return Err(Failure::range(format!(
                "max_alpha_step = {max_alpha_step}, must be finite and > 0"
            )));
        }
        h.max_alpha_step = Some(max_alpha_step);
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Sets (or, with `monitor` = NULL, removes) the progress monitor that
/// `fricont_path_run` calls after each transition point (see `fricont_monitor_fn`). May be
/// called at any time, also from inside the monitor (the new one takes effect at the next
/// transition point).
///
/// * `user_data`: handed to every call of `monitor`; never dereferenced by the library.
/// * `free_user_data`: NULL, or called exactly once with `user_data` when the monitor is
///   replaced or removed, or the path is freed; also when this call fails with
///   `FRICONT_ERR_POISONED` or `FRICONT_ERR_PANIC`, so that ownership always passes.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`path`), `FRICONT_ERR_ORDER` (called from a
/// load callback of the same path), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `monitor` and `free_user_data` are NULL or valid
/// functions of their types.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_set_monitor(
    path: *mut fricont_path,
    monitor: fricont_monitor_fn,
    user_data: *mut c_void,
    free_user_data: fricont_free_fn,
) -> fricont_status {
    // Owned from here on: dropped (finalised) on every path out that does not keep it.
    let user = UserData {
        ptr: user_data,
        free: free_user_data,
    };
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let new = monitor.map(|f| Arc::new(Monitor { f, user }));
        let old = std::mem::replace(&mut h.lock()?.monitor, new);
        // The old monitor's user data is finalised after the handle is released.
        drop(old);
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Starts (or restarts) the path at `alpha` with the fixed-α solver (semi-smooth Newton
/// with a line search; where that stalls, projected block Gauss–Seidel and a continuation
/// in the friction coefficients), from the contact forces `guess` = (λν, λt) or, if
/// `guess` is NULL, from zero forces. A restart clears the events and pieces traced so
/// far. The load callbacks may be called. Where W is carried beyond double precision, a
/// stage that stalls has its last iterate solved again on its piece in double-double until
/// the classes settle (an exact solution to that precision). Where the solver fails at
/// `alpha` (every stage but its long runs: 20,000 Gauss–Seidel sweeps and restarts of
/// Newton), it traces the path of the load `τ f(alpha)` from zero load (τ = 0, zero
/// forces where every gap is ≥ 0) to τ = 1, through its folds, and its point at τ = 1 is
/// the start; where that path cannot leave τ = 0 (every gap zero: every node at the
/// vertex of its cone), the same ray from a load that holds every node open. Where
/// neither gets there, the solver's long runs follow, then it solves at a nearby α (1e-3,
/// 1e-2, then 1e-1 of the window's length away, or of a thousand times the load's own α
/// scale at `alpha` where that is shorter, the larger of `‖q‖∞ / ‖q'‖∞` and
/// `|alpha − alpha_start|`; toward `alpha_end` first, inside the window) and traces the
/// path from there back to `alpha`: the point it reaches is the start
/// (`FRICONT_ERR_SOLVE_FAILED` only where none leads there; the message says what each
/// attempt reached). A failed solve costs about as much at a nearby α as at `alpha` (a
/// minute at p = 1500 with F = 5, half of it in the long runs), hence the rays first.
/// `fricont_path_start_route` says which of these reached the start.
///
/// The problem at one α can have several solutions (large friction, a path that folds
/// back over `alpha`); the solver returns one of them, and which one can depend on
/// rounding. A `guess` that already solves the problem (to 1e-12 relative) is kept: the
/// path starts from that solution. Pass a known one (an event's or a
/// `fricont_path_solutions_at` state's forces) to trace from it.
///
/// * `alpha`: inside the window set by `fricont_path_set_window`.
/// * `guess`: NULL, or 2p values: λν of nodes 0..p−1 then λt of nodes 0..p−1; copied.
/// * `guess_len`: 2p when `guess` is not NULL (ignored otherwise).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`path`), `FRICONT_ERR_LENGTH` (`guess_len` ≠
/// 2p), `FRICONT_ERR_NONFINITE` (guess), `FRICONT_ERR_RANGE` (α not finite or outside the
/// window), `FRICONT_ERR_ORDER` (no window set), `FRICONT_ERR_SOLVE_FAILED`,
/// `FRICONT_ERR_CALLBACK`, `FRICONT_ERR_CALLBACK_VALUE`, `FRICONT_ERR_NUMERICAL`,
/// `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `guess` is NULL or valid for `guess_len` reads.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_start(
    path: *mut fricont_path,
    alpha: f64,
    guess: *const f64,
    guess_len: i64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let mut h = h.lock()?;
        let guess = if guess.is_null() {
            None
        } else {
            let len = len_of(guess_len, "guess_len")?;
            if len != 2 * h.p {
                return Err(Failure::length(format!(
                    "guess has {len} values, expected 2p = {} (lambda_n then lambda_t)",
                    2 * h.p
                )));
            }
            // SAFETY: non-NULL and valid for `len` reads by contract.
            let g = unsafe { slice_in(guess, len, "guess") }?;
            if let Some(i) = g.iter().position(|v| !v.is_finite()) {
                return Err(Failure::new(
                    fricont_status::FRICONT_ERR_NONFINITE,
                    format!("guess[{i}] is {}", g[i]),
                ));
            }
            Some(g.to_vec())
        };
        if !alpha.is_finite() {
            return Err(Failure::range(format!("alpha = {alpha} is not finite")));
        }
        if h.path.is_none() {
            let (a0, a1) = h.window.ok_or_else(|| {
                Failure::order("no alpha window: call fricont_path_set_window before fricont_path_start")
            })?;
            let load = h.load.take().ok_or_else(|| {
                Failure::order("this path failed to initialise earlier; free it and create a new one")
            })?;
            let mut opts = PathOptions::window(a0, a1);
            opts.max_steps = h.max_steps;
            opts.zero_tol = h.zero_tol;
            opts.max_alpha_step = h.max_alpha_step;
            h.path = Some(Path::new(h.problem.clone(), load, opts)?);
        }
        h.solutions.clear();
        let p = h.path.as_mut().expect("created above");
        p.start(alpha, guess.as_deref())?;
        Ok(fricont_status::FRICONT_OK)
    })
}

fn outcome_status(o: &StepOutcome) -> fricont_status {
    match o {
        StepOutcome::Transition {
            bifurcation: true, ..
        } => fricont_status::FRICONT_BIFURCATION,
        StepOutcome::Transition { fold: true, .. } => fricont_status::FRICONT_FOLD,
        StepOutcome::Transition { .. } => fricont_status::FRICONT_TRANSITION,
        StepOutcome::End(_) => fricont_status::FRICONT_END,
    }
}

/// Advances the path to the next transition point, or to its end. The new events (one per
/// node that changed class, in node order) are appended to the event list.
///
/// Returns a positive outcome: `FRICONT_TRANSITION`, `FRICONT_FOLD` (α turns back),
/// `FRICONT_BIFURCATION` (several pieces continue; the path took the unique
/// orientation-preserving one; candidates in `fricont_path_branch`), `FRICONT_END` (see
/// `fricont_path_end_reason`; stepping an ended path returns `FRICONT_END` again, except
/// after `FRICONT_END_BIFURCATION` and `fricont_path_choose_branch`). Errors:
/// `FRICONT_ERR_NULL`, `FRICONT_ERR_ORDER` (not started), `FRICONT_ERR_CALLBACK`,
/// `FRICONT_ERR_CALLBACK_VALUE` (the path then ends with `FRICONT_END_FAILED`),
/// `FRICONT_ERR_NUMERICAL`, `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`. A load callback
/// that fails ahead of the path is approached by shorter steps: the transitions before
/// the failure are returned first, and the error where the path reaches it (to within
/// 1e-12 of the window's length).
///
/// # Safety
/// `path` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_step(path: *mut fricont_path) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let mut h = h.lock()?;
        let outcome = h.started_mut()?.step()?;
        Ok(outcome_status(&outcome))
    })
}

/// Steps until the path ends, calling the monitor (`fricont_path_set_monitor`), if any,
/// after each transition point. Returns `FRICONT_END` (see `fricont_path_end_reason`:
/// `FRICONT_END_STOPPED` when the monitor stopped it) or the first error of
/// `fricont_path_step`.
///
/// # Safety
/// `path` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_run(path: *mut fricont_path) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        loop {
            // The handle is released while the monitor runs, so that it can read the path.
            let (progress, monitor) = {
                let mut inner = h.lock()?;
                if let StepOutcome::End(_) = inner.started_mut()?.step()? {
                    return Ok(fricont_status::FRICONT_END);
                }
                let progress = inner.started()?.progress();
                (progress, inner.monitor.clone())
            };
            if let (Some(pr), Some(m)) = (progress, monitor) {
                // SAFETY: the caller's monitor, called with its own user data.
                let rc = unsafe {
                    (m.f)(
                        pr.alpha,
                        pr.transitions as i64,
                        pr.events.start as i64,
                        pr.events.end as i64,
                        m.user.ptr,
                    )
                };
                if rc != 0 {
                    let mut inner = h.lock()?;
                    inner.started_mut()?.stop();
                    return Ok(fricont_status::FRICONT_END);
                }
            }
        }
    })
}

/// Why the path ended: `*reason` receives a `fricont_end_reason` code
/// (`FRICONT_END_NONE` while it has not ended). `reason` must not be NULL.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_ORDER` (not started),
/// `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `reason` is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_end_reason(
    path: *const fricont_path,
    reason: *mut i32,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let h = h.read()?;
        if reason.is_null() {
            return Err(Failure::null("reason"));
        }
        let code = fricont_end_reason::of(h.started()?.end_reason());
        // SAFETY: non-NULL and valid by contract.
        unsafe { reason.write(code as i32) };
        Ok(fricont_status::FRICONT_OK)
    })
}

/// How `fricont_path_start` reached the start point: `*route` receives a
/// `fricont_start_route` code (`FRICONT_START_SOLVED` where the fixed-α solver found it,
/// another code where one of its fallbacks did; see `fricont_path_start`). `route` must
/// not be NULL.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_ORDER` (not started),
/// `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `route` is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_start_route(
    path: *const fricont_path,
    route: *mut i32,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let h = h.read()?;
        if route.is_null() {
            return Err(Failure::null("route"));
        }
        let Some(started) = h.started()?.start_route() else {
            return Err(Failure::order(NOT_STARTED));
        };
        let code = fricont_start_route::of(started);
        // SAFETY: non-NULL and valid by contract.
        unsafe { route.write(code as i32) };
        Ok(fricont_status::FRICONT_OK)
    })
}

/// The nonzero code returned by the most recent failing load callback on this path
/// (`*code`; 0 if none failed, or if the callback wrote a NaN/infinity). Works before the
/// start. `code` must not be NULL.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `code` is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_callback_code(
    path: *const fricont_path,
    code: *mut i32,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let slot = &h.slot;
        if code.is_null() {
            return Err(Failure::null("code"));
        }
        // SAFETY: non-NULL and valid by contract.
        unsafe { code.write(slot.callback_code()) };
        Ok(fricont_status::FRICONT_OK)
    })
}

/// The body of the `*_count` queries: `*count = len(started path)`.
///
/// # Safety
/// `path` is NULL or a live handle; `count` is NULL or valid for one write.
unsafe fn write_count(
    path: *const fricont_path,
    count: *mut i64,
    len: impl FnOnce(&Path) -> usize,
) -> FfiResult<fricont_status> {
    // SAFETY: NULL or a live handle, by contract.
    let h = unsafe { handle_ref(path, "path") }?;
    let h = h.read()?;
    if count.is_null() {
        return Err(Failure::null("count"));
    }
    let c = len(h.started()?);
    // SAFETY: non-NULL and valid by contract.
    unsafe { count.write(c as i64) };
    Ok(fricont_status::FRICONT_OK)
}

/// The number of events so far (`*count`, not NULL).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_ORDER` (not started),
/// `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `count` is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_event_count(
    path: *const fricont_path,
    count: *mut i64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: the caller's contract, passed on.
        unsafe { write_count(path, count, |p| p.events().len()) }
    })
}

/// Copies event `k` (0-based, < the event count) into `*out` (not NULL). The event's
/// `residual` is computed here: one back-solve with the factor of A (the tracer itself
/// does no work proportional to n per event).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_RANGE` (k out of range),
/// `FRICONT_ERR_ORDER` (not started), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
/// No load callback is called: the load at the event was kept when it was found.
///
/// # Safety
/// `path` is NULL or a live handle; `out` is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_event(
    path: *const fricont_path,
    k: i64,
    out: *mut fricont_event,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let h = h.read()?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let path = h.started()?;
        let k = index_in(k, path.events().len(), "event")?;
        let residual = path.event_state(k)?.residual;
        let e = &path.events()[k];
        let v = fricont_event {
            index: e.index as i64,
            transition: e.transition as i64,
            alpha: e.alpha,
            node: e.node as i64,
            from: class_code(e.from),
            to: class_code(e.to),
            fold: e.fold,
            bifurcation: e.bifurcation,
            residual,
        };
        // SAFETY: non-NULL and valid by contract.
        unsafe { out.write(v) };
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Copies the full state at event `k` (u, λν, λt, the classes of the piece after the
/// event, residual) into the caller's buffers described by `*state` (see
/// `fricont_state`). `state` may be NULL (nothing written). Costs one back-solve with the
/// factor of A.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`path`), `FRICONT_ERR_RANGE` (k),
/// `FRICONT_ERR_LENGTH` (a buffer too short), `FRICONT_ERR_ORDER` (not started),
/// `FRICONT_ERR_NUMERICAL` (the state's numbers are not finite), `FRICONT_ERR_POISONED`,
/// `FRICONT_ERR_PANIC`. No load callback is called.
///
/// # Safety
/// `path` is NULL or a live handle; `state` is NULL or an initialised struct whose
/// non-NULL buffers are valid for their lengths.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_event_state(
    path: *const fricont_path,
    k: i64,
    state: *mut fricont_state,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let h = h.read()?;
        let path = h.started()?;
        let k = index_in(k, path.events().len(), "event")?;
        let st = path.event_state(k)?;
        h.fill_state(&st, state)?;
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Copies the start point (the fixed-α solution the path started from) into `*state`
/// (see `fricont_state`; may be NULL). Costs one back-solve with the factor of A, as
/// `fricont_path_event_state` (u is computed on request, not kept).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`path`), `FRICONT_ERR_LENGTH`,
/// `FRICONT_ERR_ORDER` (not started), `FRICONT_ERR_NUMERICAL` (the state's numbers are
/// not finite), `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`. No load callback is called.
///
/// # Safety
/// As `fricont_path_event_state`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_start_state(
    path: *const fricont_path,
    state: *mut fricont_state,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let h = h.read()?;
        let st = h.started()?.start_state()?;
        h.fill_state(&st, state)?;
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Copies the current point of the path (the end of the last step) into `*state` (see
/// `fricont_state`; may be NULL). Costs one back-solve for u; may call the load callback.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`path`), `FRICONT_ERR_LENGTH`,
/// `FRICONT_ERR_ORDER` (not started), `FRICONT_ERR_CALLBACK`, `FRICONT_ERR_CALLBACK_VALUE`,
/// `FRICONT_ERR_NUMERICAL` (the state's numbers are not finite), `FRICONT_ERR_POISONED`,
/// `FRICONT_ERR_PANIC`.
///
/// # Safety
/// As `fricont_path_event_state`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_current(
    path: *mut fricont_path,
    state: *mut fricont_state,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let mut h = h.lock()?;
        let st = h.started_mut()?.current()?;
        h.fill_state(&st, state)?;
        Ok(fricont_status::FRICONT_OK)
    })
}

/// The number of traced pieces (`*count`, not NULL); the last one is the current piece.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_ORDER` (not started),
/// `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `count` is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_piece_count(
    path: *const fricont_path,
    count: *mut i64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: the caller's contract, passed on.
        unsafe { write_count(path, count, |p| p.pieces().len()) }
    })
}

/// Copies piece `k` (0-based) into `*out` (may be NULL) and its class vector into
/// `classes` (p `fricont_class` codes; may be NULL, else `classes_len` ≥ p).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`path`), `FRICONT_ERR_RANGE` (k),
/// `FRICONT_ERR_LENGTH` (`classes_len` < p), `FRICONT_ERR_ORDER` (not started),
/// `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `out` is NULL or valid for one write; `classes` is
/// NULL or valid for `classes_len` writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_piece(
    path: *const fricont_path,
    k: i64,
    out: *mut fricont_piece,
    classes: *mut i32,
    classes_len: i64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let h = h.read()?;
        let pieces = h.started()?.pieces();
        let pc = &pieces[index_in(k, pieces.len(), "piece")?];
        // SAFETY: NULL or valid for `classes_len` writes, by contract.
        let cl = unsafe { slice_out(classes, classes_len, h.p, "classes") }?;
        copy_classes(cl, &pc.classes);
        let v = fricont_piece {
            alpha_from: pc.alpha_from,
            alpha_to: pc.alpha_to,
            direction: pc.direction as i32,
            orientation: pc.orientation as i32,
            det_sign: pc.det_sign as i32,
        };
        // SAFETY: NULL or valid by contract.
        unsafe { put(out, v) };
        Ok(fricont_status::FRICONT_OK)
    })
}

/// The number of candidate branches at the last transition point (`*count`, not NULL):
/// 0 unless it was a bifurcation. Directly after `fricont_path_start`: the number of
/// pieces leaving the start point toward alpha_end when more than one does (a
/// bifurcation at the start, e.g. at a zero-force vertex; the path follows branch 0).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_ORDER` (not started),
/// `FRICONT_ERR_POISONED`, `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `count` is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_branch_count(
    path: *const fricont_path,
    count: *mut i64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: the caller's contract, passed on.
        unsafe { write_count(path, count, |p| p.branches().len()) }
    })
}

/// Copies candidate branch `k` (0-based) at the last bifurcation into `*out` (may be NULL)
/// and its class vector into `classes` (may be NULL, else `classes_len` ≥ p).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`path`), `FRICONT_ERR_RANGE` (k),
/// `FRICONT_ERR_LENGTH`, `FRICONT_ERR_ORDER` (not started), `FRICONT_ERR_POISONED`,
/// `FRICONT_ERR_PANIC`.
///
/// # Safety
/// As `fricont_path_piece`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_branch(
    path: *const fricont_path,
    k: i64,
    out: *mut fricont_branch,
    classes: *mut i32,
    classes_len: i64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let h = h.read()?;
        let branches = h.started()?.branches();
        let b = &branches[index_in(k, branches.len(), "branch")?];
        // SAFETY: NULL or valid for `classes_len` writes, by contract.
        let cl = unsafe { slice_out(classes, classes_len, h.p, "classes") }?;
        copy_classes(cl, &b.classes);
        let v = fricont_branch {
            direction: b.direction as i32,
            orientation_preserving: b.orientation_preserving,
        };
        // SAFETY: NULL or valid by contract.
        unsafe { put(out, v) };
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Continues along candidate branch `k` of the last bifurcation instead of the branch the
/// path took (or after the path stopped with `FRICONT_END_BIFURCATION`); the next
/// `fricont_path_step` follows it. Only directly after the bifurcation step, or directly
/// after `fricont_path_start` when it offered branches (the path then starts again at
/// the same point on branch `k`).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_RANGE` (k out of range),
/// `FRICONT_ERR_ORDER` (not started, or no bifurcation pending), `FRICONT_ERR_POISONED`,
/// `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_choose_branch(
    path: *mut fricont_path,
    k: i64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let mut h = h.lock()?;
        let p = h.started_mut()?;
        let count = p.branches().len();
        if count == 0 {
            return Err(Failure::order(
                "no bifurcation pending: fricont_path_choose_branch is only allowed directly after a bifurcation",
            ));
        }
        let k = index_in(k, count, "branch")?;
        p.choose_branch(k)?;
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Computes every traced solution at `alpha` (one per traced piece whose α-range contains
/// it: several past a fold; a transition point shared by two pieces once) and keeps them
/// in the handle; `*count` (not NULL) receives their number (0 if the traced path never
/// reached `alpha`). Read them with `fricont_path_solution`. Each costs one small solve
/// on the stored piece (under a nonlinear load, refined in double-double where the
/// problem is carried in extended precision, as the traced points are) and one back-solve
/// for u; may call the load callback. Replaces the solutions of an earlier call.
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL`, `FRICONT_ERR_RANGE` (α not finite),
/// `FRICONT_ERR_ORDER` (not started), `FRICONT_ERR_CALLBACK`, `FRICONT_ERR_CALLBACK_VALUE`,
/// `FRICONT_ERR_NUMERICAL` (a piece's solve at α failed), `FRICONT_ERR_POISONED`,
/// `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `count` is NULL or valid for one write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_solutions_at(
    path: *mut fricont_path,
    alpha: f64,
    count: *mut i64,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let mut h = h.lock()?;
        if count.is_null() {
            return Err(Failure::null("count"));
        }
        h.solutions.clear();
        let sols = h.started_mut()?.solutions_at(alpha)?;
        h.solutions = sols;
        // SAFETY: non-NULL and valid by contract.
        unsafe { count.write(h.solutions.len() as i64) };
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Copies solution `k` (0-based, < the count of the last `fricont_path_solutions_at`):
/// its origin into `*info` (may be NULL) and its state into `*state` (see
/// `fricont_state`; may be NULL).
///
/// Returns `FRICONT_OK`, `FRICONT_ERR_NULL` (`path`), `FRICONT_ERR_RANGE` (k),
/// `FRICONT_ERR_LENGTH`, `FRICONT_ERR_ORDER` (not started), `FRICONT_ERR_POISONED`,
/// `FRICONT_ERR_PANIC`.
///
/// # Safety
/// `path` is NULL or a live handle; `info` is NULL or valid for one write; `state` as in
/// `fricont_path_event_state`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_solution(
    path: *const fricont_path,
    k: i64,
    info: *mut fricont_solution,
    state: *mut fricont_state,
) -> fricont_status {
    ffi_boundary!(path => {
        // SAFETY: NULL or a live handle, by contract.
        let h = unsafe { handle_ref(path, "path") }?;
        let h = h.read()?;
        h.started()?;
        let s = &h.solutions[index_in(k, h.solutions.len(), "solution")?];
        h.fill_state(&s.state, state)?;
        // SAFETY: NULL or valid by contract.
        unsafe {
            put(
                info,
                fricont_solution {
                    piece: s.piece as i64,
                    continuum: s.continuum,
                },
            )
        };
        Ok(fricont_status::FRICONT_OK)
    })
}

/// Copies the message of the most recent failing call on this path handle into `buf`
/// with `snprintf` semantics (see `fricont_problem_error_message`). Returns the full
/// length in bytes without the NUL (0 for none or a NULL handle). Works on a poisoned
/// handle.
///
/// # Safety
/// `path` is NULL or a live handle; `buf` is NULL or valid for `len` bytes of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_path_error_message(
    path: *const fricont_path,
    buf: *mut c_char,
    len: usize,
) -> usize {
    super::boundary::run_value(0, || {
        // SAFETY: NULL or a live handle, by contract.
        let Some(h) = (unsafe { path.as_ref() }) else {
            return 0;
        };
        // SAFETY: by contract.
        unsafe { write_message(&h.slot.message(), buf, len) }
    })
}
