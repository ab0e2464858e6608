//! `fricont._core`: the extension module behind the Python package `fricont`.
//!
//! The Python layer (`python/fricont/__init__.py`) converts scipy/numpy input to CSR
//! arrays with int64 indices and wraps the results; this module only converts between
//! numpy and the Rust API of `fricont`, releases the GIL while the library computes, and
//! maps the library's errors to Python exceptions. Node indices are 0-based here.

use std::ops::ControlFlow;
use std::sync::{Arc, Mutex, MutexGuard, TryLockError};
use std::thread::ThreadId;

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use fricont::load::LoadFailure;
use fricont::path::State;
use fricont::{Class, CsrMatrix, EndReason, Load, PathOptions, ProblemBuilder, Storage};
use fricont_exchange::io::CaseData;
use fricont_exchange::report::{PathReport, Timing};

create_exception!(_core, Error, PyException, "A numerical failure of fricont.");
create_exception!(
    _core,
    NotPositiveDefinite,
    Error,
    "A is not positive definite, or B = [N; T] is rank-deficient (W not positive definite)."
);
create_exception!(
    _core,
    SolveError,
    Error,
    "The fixed-alpha solve (the start point) did not converge."
);
create_exception!(
    _core,
    LoadError,
    Error,
    "The load callable failed or returned non-finite values."
);
create_exception!(
    _core,
    NumericalError,
    Error,
    "A numerical failure while tracing."
);
create_exception!(
    _core,
    UsageError,
    Error,
    "A call made in the wrong order (e.g. choosing a branch where there is none)."
);

/// Maps a library error to the documented Python exception.
fn to_py(e: fricont::Error) -> PyErr {
    use fricont::Error as E;
    let msg = e.to_string();
    match e {
        E::Dimension(_) | E::Csr(_) | E::NonFinite(_) | E::NotSymmetric(_) => {
            PyValueError::new_err(msg)
        }
        E::InvalidParameter(_) => PyValueError::new_err(msg),
        E::NotSpd { .. } | E::RankDeficient(_) => NotPositiveDefinite::new_err(msg),
        E::Load { .. } => LoadError::new_err(msg),
        E::SolveFailed { .. } => SolveError::new_err(msg),
        E::Usage(_) => UsageError::new_err(msg),
        _ => NumericalError::new_err(msg),
    }
}

fn exchange_err(e: fricont_exchange::Error) -> PyErr {
    match e {
        fricont_exchange::Error::Core(c) => to_py(c),
        fricont_exchange::Error::Io(m) => pyo3::exceptions::PyOSError::new_err(m),
    }
}

/// A CSR matrix from (indptr, indices, data) with int64 indices, 0-based.
fn csr(
    name: &str,
    shape: (usize, usize),
    indptr: PyReadonlyArray1<'_, i64>,
    indices: PyReadonlyArray1<'_, i64>,
    data: PyReadonlyArray1<'_, f64>,
) -> PyResult<CsrMatrix> {
    CsrMatrix::from_raw(
        name,
        shape.0,
        shape.1,
        indptr.as_slice()?,
        indices.as_slice()?,
        data.as_slice()?,
        0,
    )
    .map_err(to_py)
}

fn class_name(c: Class) -> &'static str {
    c.name()
}

fn classes_list(c: &[Class]) -> Vec<&'static str> {
    c.iter().map(|&c| class_name(c)).collect()
}

/// Branches as (classes, direction, orientation_preserving) tuples.
fn branch_tuples(b: &[fricont::path::Branch]) -> Vec<(Vec<&'static str>, i8, bool)> {
    b.iter()
        .map(|b| {
            (
                classes_list(&b.classes),
                b.direction,
                b.orientation_preserving,
            )
        })
        .collect()
}

fn state_dict<'py>(py: Python<'py>, s: &State, with_u: bool) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("alpha", s.alpha)?;
    if with_u {
        d.set_item("u", s.u.clone().into_pyarray(py))?;
    }
    d.set_item("lambda_n", s.lambda_n.clone().into_pyarray(py))?;
    d.set_item("lambda_t", s.lambda_t.clone().into_pyarray(py))?;
    d.set_item("classes", classes_list(&s.classes))?;
    d.set_item("residual", s.residual)?;
    Ok(d)
}

/// A problem: A, N, T, friction, gap, r, factorised once (Cholesky of A, W = B A⁻¹ Bᵀ).
#[pyclass(module = "fricont._core", frozen)]
struct Problem {
    inner: Arc<fricont::Problem>,
}

/// Arguments of one CSR matrix as the Python layer passes them.
type CsrArgs<'py> = (
    (usize, usize),
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, f64>,
);

#[pymethods]
impl Problem {
    /// Builds the problem (validation, Cholesky of A, Delassus operator) with the GIL
    /// released. `storage`: "full", "lower" or "upper". `threads`: those of the set-up
    /// and, where 2p ≥ 2048, of the trace's dense passes (private pools, see
    /// `ProblemBuilder::threads`). `extended_precision`: "auto", "on" or "off"
    /// (`ProblemBuilder::extended_precision`). Errors: ValueError for invalid data,
    /// threads outside 1..=1024 or another precision mode, NotPositiveDefinite when A is
    /// not SPD or B is rank-deficient.
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (a, n, t, friction, gap, r, storage, threads, extended_precision))]
    fn new(
        py: Python<'_>,
        a: CsrArgs<'_>,
        n: CsrArgs<'_>,
        t: CsrArgs<'_>,
        friction: Vec<f64>,
        gap: Option<Vec<f64>>,
        r: Option<f64>,
        storage: &str,
        threads: usize,
        extended_precision: &str,
    ) -> PyResult<Self> {
        let extended = match extended_precision {
            "auto" => fricont::ExtendedPrecision::Auto,
            "on" => fricont::ExtendedPrecision::On,
            "off" => fricont::ExtendedPrecision::Off,
            s => {
                return Err(PyValueError::new_err(format!(
                    "extended_precision = {s:?}: expected \"auto\", \"on\" or \"off\""
                )));
            }
        };
        let storage = match storage {
            "full" => Storage::Full,
            "lower" => Storage::Lower,
            "upper" => Storage::Upper,
            s => {
                return Err(PyValueError::new_err(format!(
                    "storage = {s:?}: expected \"full\", \"lower\" or \"upper\""
                )));
            }
        };
        let a = csr("A", a.0, a.1, a.2, a.3)?;
        let nm = csr("N", n.0, n.1, n.2, n.3)?;
        let tm = csr("T", t.0, t.1, t.2, t.3)?;
        let mut b = ProblemBuilder::new(a, storage, nm, tm)
            .threads(threads)
            .extended_precision(extended);
        b = if friction.len() == 1 {
            b.friction_uniform(friction[0])
        } else {
            b.friction(friction)
        };
        if let Some(g) = gap {
            b = b.gap(g);
        }
        if let Some(r) = r {
            b = b.r(r);
        }
        let inner = py.detach(move || b.build()).map_err(to_py)?;
        Ok(Problem {
            inner: Arc::new(inner),
        })
    }

    /// Number of dofs.
    #[getter]
    fn n(&self) -> usize {
        self.inner.n()
    }

    /// Number of contact nodes.
    #[getter]
    fn p(&self) -> usize {
        self.inner.p()
    }

    /// The augmentation parameter r in use (force per length).
    #[getter]
    fn r(&self) -> f64 {
        self.inner.r()
    }

    /// Whether W and the condensed loads are carried beyond double (`auto`: small problems,
    /// and ill-conditioned W where the refinement's cost is moderate; see
    /// `fricont.Problem.extended_precision`).
    #[getter]
    fn extended_precision(&self) -> bool {
        self.inner.extended_precision()
    }

    /// Estimate of the 2-norm condition number of the equilibrated W (dimensionless).
    #[getter]
    fn w_condition_estimate(&self) -> f64 {
        self.inner.w_condition_estimate()
    }

    /// Friction coefficients (p).
    #[getter]
    fn friction<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.friction().to_vec().into_pyarray(py)
    }

    /// Traces an affine load f0 + α f1 (see `fricont.Problem.trace`).
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (f0, f1, opts, monitor, guess, branch))]
    fn trace_affine(
        &self,
        py: Python<'_>,
        f0: PyReadonlyArray1<'_, f64>,
        f1: PyReadonlyArray1<'_, f64>,
        opts: OptionArgs,
        monitor: Option<Py<PyAny>>,
        guess: Option<PyReadonlyArray1<'_, f64>>,
        branch: Option<usize>,
    ) -> PyResult<Path> {
        let load = Load::affine(f0.as_slice()?.to_vec(), f1.as_slice()?.to_vec()).map_err(to_py)?;
        let opts = options(opts)?;
        self.trace(py, load, opts, monitor, None, guess, branch)
    }

    /// Traces a basis load `f(α) = Σ_j φ_j(α) f_j`: `vectors` the f_j (n values each),
    /// `weights(alpha)` returns `(phi, dphi)`, the k weights and their derivatives. Each
    /// vector is condensed once, so an evaluation costs O(k p), not a piece solve. An
    /// exception inside `weights` stops the path; it is kept on the path and re-raised by
    /// the Python layer.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (vectors, weights, opts, monitor, guess, branch))]
    fn trace_basis(
        &self,
        py: Python<'_>,
        vectors: Vec<PyReadonlyArray1<'_, f64>>,
        weights: Py<PyAny>,
        opts: OptionArgs,
        monitor: Option<Py<PyAny>>,
        guess: Option<PyReadonlyArray1<'_, f64>>,
        branch: Option<usize>,
    ) -> PyResult<Path> {
        let opts = options(opts)?;
        let vectors = vectors
            .iter()
            .map(|v| v.as_slice().map(<[f64]>::to_vec))
            .collect::<Result<Vec<_>, _>>()?;
        let slot: Arc<Mutex<Option<PyErr>>> = Arc::new(Mutex::new(None));
        let keep = slot.clone();
        let w = Box::new(move |alpha: f64, phi: &mut [f64], dphi: &mut [f64]| {
            Python::attach(|py| -> Result<(), LoadFailure> {
                let fail = |e: PyErr| keep_error(&keep, "weights", e);
                let v = weights.call1(py, (alpha,)).map_err(fail)?;
                let (p, d): (Bound<'_, PyAny>, Bound<'_, PyAny>) =
                    v.bind(py).extract().map_err(|e: PyErr| {
                        fail(PyValueError::new_err(format!(
                            "weights must return a pair (phi, dphi): {e}"
                        )))
                    })?;
                copy_floats(py, &p, phi, "weights (phi)", "k").map_err(fail)?;
                copy_floats(py, &d, dphi, "weights (dphi)", "k").map_err(fail)
            })
        }) as fricont::load::WeightsFn;
        let load = Load::basis(vectors, w).map_err(to_py)?;
        self.trace(py, load, opts, monitor, Some(slot), guess, branch)
    }

    /// Traces a general load: `load(alpha)` returns f (n values); `dload(alpha)` its
    /// derivative (central differences when None). An exception inside either stops the
    /// path; it is kept on the path and re-raised by the Python layer.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (load, dload, n, opts, monitor, guess, branch))]
    fn trace_general(
        &self,
        py: Python<'_>,
        load: Py<PyAny>,
        dload: Option<Py<PyAny>>,
        n: usize,
        opts: OptionArgs,
        monitor: Option<Py<PyAny>>,
        guess: Option<PyReadonlyArray1<'_, f64>>,
        branch: Option<usize>,
    ) -> PyResult<Path> {
        let opts = options(opts)?;
        let slot: Arc<Mutex<Option<PyErr>>> = Arc::new(Mutex::new(None));
        let wrap = |callable: Py<PyAny>, what: &'static str| {
            let slot = slot.clone();
            Box::new(move |alpha: f64, out: &mut [f64]| {
                Python::attach(|py| -> Result<(), LoadFailure> {
                    let fail = |e: PyErr| keep_error(&slot, what, e);
                    let v = callable.call1(py, (alpha,)).map_err(fail)?;
                    copy_floats(py, v.bind(py), out, what, "n").map_err(fail)
                })
            }) as fricont::load::VectorFn
        };
        let f = wrap(load, "load");
        let df = dload.map(|d| wrap(d, "dload"));
        let load = Load::general(n, f, df);
        self.trace(py, load, opts, monitor, Some(slot), guess, branch)
    }
}

/// A Python load callable (`what`) raised `e`: `e` is kept in `slot` (the first one, for
/// the Python layer to re-raise) and the library gets a failure that names it.
fn keep_error(slot: &Mutex<Option<PyErr>>, what: &str, e: PyErr) -> LoadFailure {
    let message = format!("{what} raised {e}");
    if let Ok(mut s) = slot.lock() {
        s.get_or_insert(e);
    }
    LoadFailure { code: 1, message }
}

/// Copies `v` (anything numpy reads as a 1-D float64 array) into `out`: ValueError when
/// it is not one, or when its length is not `out.len()` (`len_name` names that length).
fn copy_floats(
    py: Python<'_>,
    v: &Bound<'_, PyAny>,
    out: &mut [f64],
    what: &str,
    len_name: &str,
) -> PyResult<()> {
    let arr = py
        .import("numpy")?
        .call_method1("ascontiguousarray", (v, "float64"))?;
    let arr: PyReadonlyArray1<'_, f64> = arr.extract().map_err(|e: PyErr| {
        PyValueError::new_err(format!(
            "{what} must return a 1-D array of {len_name} floats: {e}"
        ))
    })?;
    let s = arr.as_slice()?;
    if s.len() != out.len() {
        return Err(PyValueError::new_err(format!(
            "{what} returned {} values, expected {len_name} = {}",
            s.len(),
            out.len()
        )));
    }
    out.copy_from_slice(s);
    Ok(())
}

/// The path options as `fricont.Problem.trace` passes them: the window, then
/// alpha_start, max_steps, max_alpha_step and zero_tol (None: the defaults).
type OptionArgs = (
    (f64, f64),
    Option<f64>,
    Option<usize>,
    Option<f64>,
    Option<f64>,
);

/// The path options of `trace`: ValueError for `max_steps` = 0 (the other values are
/// checked by `fricont::Path::new`).
fn options(
    (window, alpha_start, max_steps, max_alpha_step, zero_tol): OptionArgs,
) -> PyResult<PathOptions> {
    let mut opts = PathOptions::window(window.0, window.1);
    if let Some(z) = zero_tol {
        opts.zero_tol = z;
    }
    if let Some(a) = alpha_start {
        opts.alpha_start = a;
    }
    if let Some(k) = max_steps {
        if k == 0 {
            return Err(PyValueError::new_err("max_steps must be at least 1"));
        }
        opts.max_steps = k;
    }
    opts.max_alpha_step = max_alpha_step;
    Ok(opts)
}

impl Problem {
    /// Makes the path, starts it at `opts.alpha_start` (from `guess`, on start branch
    /// `branch`) and runs it (see [`Path::advance`]).
    #[allow(clippy::too_many_arguments)]
    fn trace(
        &self,
        py: Python<'_>,
        load: Load,
        opts: PathOptions,
        monitor: Option<Py<PyAny>>,
        load_error: Option<Arc<Mutex<Option<PyErr>>>>,
        guess: Option<PyReadonlyArray1<'_, f64>>,
        branch: Option<usize>,
    ) -> PyResult<Path> {
        let guess = guess
            .map(|g| g.as_slice().map(<[f64]>::to_vec))
            .transpose()?;
        let start = Begin::Start {
            alpha: opts.alpha_start,
            guess,
            branch,
        };
        let problem = self.inner.clone();
        let t0 = std::time::Instant::now();
        let path = fricont::Path::new(problem, load, opts).map_err(to_py)?;
        let setup_s = t0.elapsed().as_secs_f64();
        let path = Path {
            inner: Mutex::new(path),
            error: Mutex::new(None),
            load_error,
            timing: Mutex::new(Timing {
                setup_s,
                trace_s: 0.0,
            }),
            tracer: Mutex::new(None),
            start_branches: Mutex::new(Vec::new()),
        };
        path.advance(py, start, monitor)?;
        Ok(path)
    }
}

/// A traced path (see `fricont.Path`).
#[pyclass(module = "fricont._core", frozen)]
struct Path {
    inner: Mutex<fricont::Path>,
    /// The exception that ended the last run (a load's, the monitor's, the library's),
    /// until taken.
    error: Mutex<Option<PyErr>>,
    /// Where a Python load keeps its exception while the library unwinds (general loads).
    load_error: Option<Arc<Mutex<Option<PyErr>>>>,
    timing: Mutex<Timing>,
    /// The thread running the path while it holds `inner` (a call from its own monitor is
    /// refused instead of waiting for itself).
    tracer: Mutex<Option<ThreadId>>,
    /// The pieces that left the start point toward alpha_end when more than one did
    /// (`fricont::Path::branches` directly after the start), else empty.
    start_branches: Mutex<Vec<fricont::path::Branch>>,
}

/// How [`Path::advance`] begins before it runs the path on.
enum Begin {
    /// Start at `alpha` (from `guess`, 2p forces, when given), then take start branch
    /// `branch` when given.
    Start {
        alpha: f64,
        guess: Option<Vec<f64>>,
        branch: Option<usize>,
    },
    /// Continue along candidate `k` of the last bifurcation (`fricont::Path::choose_branch`).
    Branch(usize),
    /// Run on from where the path stopped.
    Resume,
}

fn poisoned<T>(_: T) -> PyErr {
    UsageError::new_err("the path is poisoned by an earlier panic")
}

impl Path {
    /// True when the calling thread is running this path (a call from its monitor).
    fn traced_here(&self) -> bool {
        self.tracer
            .lock()
            .is_ok_and(|t| *t == Some(std::thread::current().id()))
    }

    fn busy() -> PyErr {
        UsageError::new_err(
            "the path is being traced: it cannot be used from inside its own monitor (read it \
             after trace or resume returns)",
        )
    }

    /// The path, for a call without the GIL: waits while another thread runs it.
    fn lock_detached(&self) -> PyResult<MutexGuard<'_, fricont::Path>> {
        if self.traced_here() {
            return Err(Self::busy());
        }
        self.inner.lock().map_err(poisoned)
    }

    /// The path, for a call with the GIL: waits (without the GIL, so that a tracing thread
    /// can call its load or monitor) while another thread runs it.
    fn lock(&self, py: Python<'_>) -> PyResult<MutexGuard<'_, fricont::Path>> {
        loop {
            match self.inner.try_lock() {
                Ok(g) => return Ok(g),
                Err(TryLockError::Poisoned(e)) => return Err(poisoned(e)),
                Err(TryLockError::WouldBlock) if self.traced_here() => return Err(Self::busy()),
                Err(TryLockError::WouldBlock) => py.detach(|| drop(self.inner.lock())),
            }
        }
    }

    /// Begins as `begin` says (a start, a branch choice, or nothing) and runs the path
    /// until it ends, with the GIL
    /// released; the GIL is taken again only to call a Python load or the monitor. The
    /// monitor is called as `monitor(alpha, transitions, (first_event, end_event))` after
    /// each transition point: a true result, or an exception, stops the path
    /// (`EndReason::Stopped`; a later run continues from there). The exception that ended
    /// the run is kept for `take_error`. Errors: UsageError when called from the path's
    /// own monitor.
    fn advance(&self, py: Python<'_>, begin: Begin, monitor: Option<Py<PyAny>>) -> PyResult<()> {
        if self.traced_here() {
            return Err(Self::busy());
        }
        let t = std::time::Instant::now();
        let mut monitor_error: Option<PyErr> = None;
        let outcome = py.detach(|| -> PyResult<()> {
            let mut path = self.inner.lock().map_err(poisoned)?;
            *self.tracer.lock().map_err(poisoned)? = Some(std::thread::current().id());
            let mut run = || -> PyResult<()> {
                match &begin {
                    Begin::Start {
                        alpha,
                        guess,
                        branch,
                    } => {
                        path.start(*alpha, guess.as_deref()).map_err(to_py)?;
                        *self.start_branches.lock().map_err(poisoned)? = path.branches().to_vec();
                        // (branch 0 is the piece the start took, also when it is the only one)
                        if let Some(k) = *branch {
                            let offered = path.branches().len().max(1);
                            if k >= offered {
                                return Err(UsageError::new_err(format!(
                                    "branch = {k}: {offered} piece{} the start point toward alpha_end (branch counts from 0)",
                                    if offered > 1 { "s leave" } else { " leaves" }
                                )));
                            }
                            if k > 0 {
                                path.choose_branch(k).map_err(to_py)?;
                            }
                        }
                    }
                    Begin::Branch(k) => path.choose_branch(*k).map_err(to_py)?,
                    Begin::Resume => {}
                }
                path.run_monitored(|_, pr| {
                    let Some(m) = &monitor else {
                        return ControlFlow::Continue(());
                    };
                    let answer = Python::attach(|py| -> PyResult<bool> {
                        m.call1(
                            py,
                            (pr.alpha, pr.transitions, (pr.events.start, pr.events.end)),
                        )?
                        .bind(py)
                        .is_truthy()
                    });
                    match answer {
                        Ok(false) => ControlFlow::Continue(()),
                        Ok(true) => ControlFlow::Break(()),
                        Err(e) => {
                            monitor_error = Some(e);
                            ControlFlow::Break(())
                        }
                    }
                })
                .map_err(to_py)?;
                Ok(())
            };
            let result = run();
            *self.tracer.lock().map_err(poisoned)? = None;
            result
        });
        if let Ok(mut tm) = self.timing.lock() {
            tm.trace_s += t.elapsed().as_secs_f64();
        }
        // A Python load's own exception is what stopped the path, not the library's
        // LoadError that wraps it.
        let load_error = self
            .load_error
            .as_ref()
            .and_then(|s| s.lock().ok().and_then(|mut g| g.take()));
        let error = match outcome {
            Err(e) => Some(load_error.unwrap_or(e)),
            Ok(()) => monitor_error,
        };
        *self.error.lock().map_err(poisoned)? = error;
        Ok(())
    }
}

#[pymethods]
impl Path {
    /// The exception that stopped tracing, if any (taken: a second call gives None).
    fn take_error(&self) -> Option<PyErr> {
        self.error.lock().ok().and_then(|mut e| e.take())
    }

    /// Runs the path on from where it stopped (see `fricont.Path.resume`): nothing happens
    /// on a path that ended for another reason. The exception that ends the run is kept
    /// for `take_error`. Errors: UsageError when called from the path's own monitor.
    #[pyo3(signature = (monitor))]
    fn resume(&self, py: Python<'_>, monitor: Option<Py<PyAny>>) -> PyResult<()> {
        self.advance(py, Begin::Resume, monitor)
    }

    /// Continues along candidate `k` of the last bifurcation and runs the path on (see
    /// `fricont.Path.choose_branch`). The exception that ends the run (UsageError when no
    /// bifurcation is pending or `k` is out of range) is kept for `take_error`.
    #[pyo3(signature = (k, monitor))]
    fn choose_branch(&self, py: Python<'_>, k: usize, monitor: Option<Py<PyAny>>) -> PyResult<()> {
        self.advance(py, Begin::Branch(k), monitor)
    }

    /// Candidate continuations at the last transition point, as (classes, direction,
    /// orientation_preserving) tuples: empty unless it was a bifurcation and the path has
    /// not moved since (see `fricont::Path::branches`).
    fn branches(&self, py: Python<'_>) -> PyResult<Vec<(Vec<&'static str>, i8, bool)>> {
        Ok(branch_tuples(self.lock(py)?.branches()))
    }

    /// The pieces that left the start point toward alpha_end when more than one did, as
    /// `branches` (empty otherwise).
    fn start_branches(&self) -> PyResult<Vec<(Vec<&'static str>, i8, bool)>> {
        Ok(branch_tuples(
            &self.start_branches.lock().map_err(poisoned)?,
        ))
    }

    /// Events as tuples (alpha, node, from, to, fold, bifurcation, lambda_n, lambda_t,
    /// transition), node and transition 0-based.
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let path = self.lock(py)?;
        let out = PyList::empty(py);
        for e in path.events() {
            out.append((
                e.alpha,
                e.node,
                class_name(e.from),
                class_name(e.to),
                e.fold,
                e.bifurcation,
                e.lambda_n.clone().into_pyarray(py),
                e.lambda_t.clone().into_pyarray(py),
                e.transition,
            ))?;
        }
        Ok(out)
    }

    /// Pieces as dicts (alpha_from, alpha_to, classes, direction, orientation, det_sign,
    /// lambda_from, lambda_to).
    fn pieces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let path = self.lock(py)?;
        let out = PyList::empty(py);
        for r in path.pieces() {
            let d = PyDict::new(py);
            d.set_item("alpha_from", r.alpha_from)?;
            d.set_item("alpha_to", r.alpha_to)?;
            d.set_item("classes", classes_list(&r.classes))?;
            d.set_item("direction", r.direction)?;
            d.set_item("orientation", r.orientation)?;
            d.set_item("det_sign", r.det_sign)?;
            d.set_item("lambda_from", r.lambda_from.clone().into_pyarray(py))?;
            d.set_item("lambda_to", r.lambda_to.clone().into_pyarray(py))?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// Why the path ended ("window", "max_steps", "closed_loop", "bifurcation", "failed",
    /// "stopped") and the failure message, or (None, None) when it was never started (the
    /// start failed).
    fn end_reason(&self, py: Python<'_>) -> PyResult<(Option<&'static str>, Option<String>)> {
        let path = self.lock(py)?;
        Ok(match path.end_reason() {
            Some(EndReason::Failed(m)) => (Some("failed"), Some(m.clone())),
            Some(r) => (Some(r.name()), None),
            None => (None, None),
        })
    }

    /// How the start point was reached ("solved", "nearby", "zero_load", "open"; see
    /// `fricont::StartRoute`), or None when the path never started (the start failed).
    fn start_route(&self, py: Python<'_>) -> PyResult<Option<&'static str>> {
        Ok(self.lock(py)?.start_route().map(|r| r.name()))
    }

    /// The start state (alpha, lambda_n, lambda_t, classes, residual; no u), None before
    /// start(). The residual takes one back-solve (with the GIL released).
    fn start_state<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let st = py.detach(|| -> PyResult<Option<State>> {
            let path = self.lock_detached()?;
            if !path.is_started() {
                return Ok(None);
            }
            path.start_state().map(Some).map_err(to_py)
        })?;
        st.map(|s| state_dict(py, &s, false)).transpose()
    }

    /// The full state at event k (0-based): u by one back-solve, with the GIL released.
    fn event_state<'py>(&self, py: Python<'py>, k: usize) -> PyResult<Bound<'py, PyDict>> {
        let st = py.detach(|| -> PyResult<State> {
            self.lock_detached()?.event_state(k).map_err(to_py)
        })?;
        state_dict(py, &st, true)
    }

    /// Every traced solution at alpha: list of (piece, state dict, continuum).
    fn solutions_at<'py>(&self, py: Python<'py>, alpha: f64) -> PyResult<Bound<'py, PyList>> {
        let sols = py.detach(|| -> PyResult<Vec<fricont::Solution>> {
            self.lock_detached()?.solutions_at(alpha).map_err(to_py)
        })?;
        let out = PyList::empty(py);
        for s in &sols {
            out.append((s.piece, state_dict(py, &s.state, true)?, s.continuum))?;
        }
        Ok(out)
    }

    /// The JSON report of the CLI (SPEC §8), as text.
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        let timing = *self.timing.lock().map_err(poisoned)?;
        let mut path = self.lock(py)?;
        Ok(PathReport::from_path(&mut path, timing).to_json_string())
    }
}

/// Reads a problem directory in the exchange format: a dict with the CSR arrays of A
/// (full storage), N, T, the vectors f0, f1, gap (or None), friction, the window and the
/// metadata as JSON text. Errors: OSError naming the file and line; ValueError when the
/// files disagree.
#[pyfunction]
fn read_case<'py>(py: Python<'py>, directory: std::path::PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let case = py
        .detach(|| CaseData::read_dir(&directory))
        .map_err(exchange_err)?;
    let d = PyDict::new(py);
    let put_csr = |name: &str, m: &CsrMatrix| -> PyResult<()> {
        let rp: Vec<i64> = m.row_ptr().iter().map(|&x| x as i64).collect();
        let ci: Vec<i64> = m.col_idx().iter().map(|&x| x as i64).collect();
        d.set_item(
            name,
            (
                (m.nrows(), m.ncols()),
                rp.into_pyarray(py),
                ci.into_pyarray(py),
                m.values().to_vec().into_pyarray(py),
            ),
        )
    };
    put_csr("A", &case.a)?;
    put_csr("N", &case.n_mat)?;
    put_csr("T", &case.t_mat)?;
    d.set_item("f0", case.f0.clone().into_pyarray(py))?;
    d.set_item("f1", case.f1.clone().into_pyarray(py))?;
    d.set_item("gap", case.gap.clone().map(|g| g.into_pyarray(py)))?;
    d.set_item("friction", case.friction.clone().into_pyarray(py))?;
    d.set_item("alpha_start", case.alpha_start)?;
    d.set_item("alpha_end", case.alpha_end)?;
    d.set_item("meta", case.meta.to_string())?;
    Ok(d)
}

/// The library version.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<Problem>()?;
    m.add_class::<Path>()?;
    m.add_function(wrap_pyfunction!(read_case, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add("Error", py.get_type::<Error>())?;
    m.add("NotPositiveDefinite", py.get_type::<NotPositiveDefinite>())?;
    m.add("SolveError", py.get_type::<SolveError>())?;
    m.add("LoadError", py.get_type::<LoadError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    m.add("UsageError", py.get_type::<UsageError>())?;
    // (the condition estimate above which "auto" refines W where that is affordable)
    m.add("AUTO_CONDITION", fricont::problem::AUTO_CONDITION)?;
    Ok(())
}
