//! Condensation onto the contact unknowns (SPEC §2).
//!
//! With `λ = (λν, λt) ∈ R^{2p}` and `B = [N; T]`,
//!
//! ```text
//! u(λ, α) = A⁻¹ (f(α) + Bᵀ λ),     d(λ, α) = B u − (g, 0) = q(α) + W λ − (g, 0),
//! q(α) = B A⁻¹ f(α),               W = B A⁻¹ Bᵀ  (2p×2p, SPD: the Delassus operator).
//! ```
//!
//! [`Delassus`] holds one fill-reducing sparse Cholesky factor of `A` (faer, sequential so
//! that it never touches a host program's thread pool) and the dense `W`.
//!
//! **W by the trailing block** (SPEC §6). B touches only the s dofs of the contact nodes
//! (the union S of the column supports of N and T). They are ordered *last* (after an AMD
//! ordering of the others, then among themselves in AMD order), so that with
//! `P A Pᵀ = L Lᵀ` the trailing s × s block `L_SS` of the factor gives
//! `(A⁻¹)_SS = (L_SS L_SSᵀ)⁻¹` and `W = Zᵀ Z` with `Z = L_SS⁻¹ B_Sᵀ`: one dense triangular
//! solve of size s with 2p columns instead of 2p sparse solves with A. It is used when
//! `s ≤ TRAILING_MAX_RATIO · 2p` (nodal contact has s ≤ 2p) and its dense work is less
//! than the solves' (on a slender strip the factor is a thin band and the solves are
//! cheaper, see `trailing_is_cheaper`); otherwise W comes from the solves, one
//! multi-right-hand-side solve in blocks of columns. Both give the same W up to rounding
//! ([`Delassus::w_by_solves`] recomputes it the second way).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltError as DenseLltError;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Accum, Conj, Mat, MatMut, MatRef, Par, Side};

use crate::dd::{Dd, two_prod, two_sum};
use crate::dense::inf_norm;
use crate::error::{Error, Result, try_vec, try_zeros};
use crate::problem::CsrMatrix;

/// Columns of `Bᵀ` solved at once when forming `W` by solves (bounds the dense workspace
/// to `n × BLOCK` numbers).
const BLOCK: usize = 32;

/// W is formed from the trailing block of the factor when the number s of dofs that B
/// touches is at most this multiple of 2p (the dense `L_SS` then holds at most
/// `(2 · 2p)²` numbers) and its dense work is less than the solves' (see
/// `trailing_is_cheaper`); otherwise by 2p solves.
pub const TRAILING_MAX_RATIO: usize = 2;

/// True when forming W from the trailing block (s contact dofs, m = 2p rows of B) costs
/// fewer floating-point operations than 2p solves with the AMD-ordered factor of
/// `nnz_l` values: the dense trailing block's factorisation, its triangular solve with
/// m columns and `Zᵀ Z` (`s³/3 + s² m + s m²`) against a forward and a backward
/// substitution per column (`4 m nnz(L)`). On a mesh the contact dofs are a small
/// separator of a large factor (the 308,160-dof mesh, s = 2p = 960: 2e9 against 1e11);
/// on a slender strip the factor is a thin band and the dense block of all contact dofs
/// is the expensive part (p = 1920: 1.3e11 against 4e9).
fn trailing_is_cheaper(s: usize, m: usize, nnz_l: usize) -> bool {
    let (s, m) = (s as f64, m as f64);
    s * s * s / 3.0 + s * s * m + s * m * m <= 4.0 * m * nnz_l as f64
}

/// Wall-clock times of the set-up phases, in seconds, and the size of the factor.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SetupTimes {
    /// Symbolic analysis: the fill-reducing ordering (with the contact dofs last when W
    /// comes from the trailing block) and the structure of the factor.
    pub analyse_s: f64,
    /// Numeric Cholesky factorisation of A.
    pub factorise_s: f64,
    /// Forming W (trailing block or solves) and checking that it is positive definite
    /// (with the estimate of its condition number, [`Delassus::w_condition_estimate`]).
    pub w_s: f64,
    /// The low part of W by mixed-precision refinement ([`Delassus::w_lo`]); 0 when W
    /// was not refined ([`crate::ExtendedPrecision`]).
    pub w_lo_s: f64,
    /// Number of stored values of the factor L.
    pub nnz_l: usize,
}

/// Why a host's solve failed: its own code and a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SolveFailure {
    /// The callback's nonzero code: > 0 recoverable (the call is retried once), < 0 fatal.
    pub code: i32,
    /// A human-readable reason.
    pub message: String,
}

/// The host's solve: overwrites every column of `x` (n rows, column-major) with
/// `A⁻¹ x`. It is called only from inside fricont's functions, on the thread that called
/// them, never from a thread of fricont's own; calls are serialised.
pub type SolveFn = Box<dyn FnMut(MatMut<'_, f64>) -> std::result::Result<(), SolveFailure> + Send>;

/// A host's solve with its block size: fricont never passes more than `max_block`
/// columns at once. Cloning shares the one callback.
#[derive(Clone)]
pub struct HostSolve {
    f: std::sync::Arc<std::sync::Mutex<SolveFn>>,
    max_block: usize,
}

impl std::fmt::Debug for HostSolve {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "HostSolve(max_block = {})", self.max_block)
    }
}

impl HostSolve {
    /// Wraps a solve closure; `max_block` (≥ 1; 0 is taken as 1) bounds the number of
    /// columns per call.
    pub fn new(f: SolveFn, max_block: usize) -> Self {
        Self {
            f: std::sync::Arc::new(std::sync::Mutex::new(f)),
            max_block: max_block.max(1),
        }
    }

    /// Solves in place, in blocks of at most `max_block` columns; a recoverable failure
    /// (code > 0) is retried once (on a copy of the right-hand sides), a fatal one (< 0)
    /// or NaN/Inf in the result is an error.
    fn solve(&self, mut x: MatMut<'_, f64>) -> Result<()> {
        thread_local! {
            /// The solves this thread is inside of (addresses of their callbacks).
            static ACTIVE: std::cell::RefCell<Vec<usize>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let key = std::sync::Arc::as_ptr(&self.f) as *const () as usize;
        if ACTIVE.with(|a| a.borrow().contains(&key)) {
            return Err(Error::HostSolve {
                code: -1,
                message: "the solve callback called fricont with its own problem (re-entrant use is not allowed)".into(),
            });
        }
        ACTIVE.with(|a| a.borrow_mut().push(key));
        let res = self.solve_blocks(x.as_mut());
        ACTIVE.with(|a| a.borrow_mut().retain(|&k| k != key));
        res
    }

    fn solve_blocks(&self, mut x: MatMut<'_, f64>) -> Result<()> {
        let mut f = self.f.lock().unwrap_or_else(|e| e.into_inner());
        let k = x.ncols();
        let mut c0 = 0;
        while c0 < k {
            let kb = self.max_block.min(k - c0);
            let mut xb = x.as_mut().subcols_mut(c0, kb);
            let mut rhs = try_zeros(xb.nrows(), kb, "a copy of the right-hand sides")?;
            rhs.copy_from(&xb);
            let mut res = f(xb.as_mut());
            if let Err(e) = &res
                && e.code > 0
            {
                xb.copy_from(&rhs);
                res = f(xb.as_mut());
            }
            if let Err(e) = res {
                return Err(Error::HostSolve {
                    code: if e.code == 0 { -1 } else { e.code },
                    message: e.message,
                });
            }
            for c in 0..kb {
                for i in 0..xb.nrows() {
                    if !xb[(i, c)].is_finite() {
                        return Err(Error::HostSolve {
                            code: 0,
                            message: format!(
                                "the solve returned {} in entry {} of column {}",
                                xb[(i, c)],
                                i + 1,
                                c0 + c + 1
                            ),
                        });
                    }
                }
            }
            c0 += kb;
        }
        Ok(())
    }
}

/// How `A⁻¹` is applied.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)] // one per problem
enum Operator {
    /// fricont's own sparse Cholesky factor of A.
    Cholesky {
        symbolic: SymbolicCholesky<usize>,
        l_values: Vec<f64>,
    },
    /// The host's solve.
    Host(HostSolve),
    /// Condensed input: no A⁻¹ at all. Loads are given condensed (2p entries); row k is
    /// divided by `row_scale[k]` (the node's equilibration).
    Condensed { row_scale: Vec<f64> },
}

/// The Delassus operator `W = B A⁻¹ Bᵀ` and the means to apply `A⁻¹`: fricont's own
/// Cholesky factor of `A`, a host's solve, or nothing (condensed input).
#[derive(Debug)]
pub struct Delassus {
    n: usize,
    op: Operator,
    /// `h = 2^(k/2)` of the exact scaling of A ([`crate::Problem::a_scale_log2`]; 1 for
    /// ordinary A): the factor is that of `h² A`, and loads enter as `h f`.
    h: f64,
    b: CsrMatrix,
    w: Mat<f64>,
    /// `Z = L_SS⁻¹ B_Sᵀ` (s × 2p, rows in the factor's order) when W came from the trailing
    /// block: it also turns a back-solve for u into a half solve ([`Self::displacements`]).
    z: Option<Mat<f64>>,
    times: SetupTimes,
    /// `W_lo`: `W_hi + W_lo` is `B A⁻¹ Bᵀ` to double-double accuracy, `W_hi` = `w` (None:
    /// not refined, see [`Self::refine_w`]).
    w_lo: Option<Mat<f64>>,
    /// The factorised matrix (`h² A`, full storage, shared with the problem) kept for
    /// refining load vectors ([`Self::keep_matrix`], [`Self::refine_w`]).
    a_full: Option<std::sync::Arc<CsrMatrix>>,
    /// Estimate of the 2-norm condition number of W ([`Self::w_condition_estimate`]).
    cond: f64,
}

/// Condensed load vectors and, where they came from half solves, the half-solved
/// vectors (see [`Delassus::condense_many_keep_half`]).
pub(crate) type CondensedWithHalf = (Vec<Vec<f64>>, Option<Mat<f64>>);

impl Delassus {
    /// Factorises `A` given by its lower triangle (CSR, row ≥ col; as CSC this is the upper
    /// triangle of the symmetric matrix) and forms `W` for `B` (2p×n).
    ///
    /// `h` (a power of two; 1 for ordinary data) says that `a_lower` is the caller's A
    /// times `h²` (see [`crate::Problem::a_scale_log2`]): `W = B (h² A)⁻¹ Bᵀ` is then W for
    /// the rows `B / h`, and the functions taking a load `f` and giving `u` work with the
    /// caller's f and u (`A⁻¹ f = h (h² A)⁻¹ (h f)`).
    ///
    /// Errors: [`Error::NotSpd`] with the failing pivot, [`Error::RankDeficient`] when `W`
    /// is not numerically positive definite (a pivot of its Cholesky factor below 1e-12
    /// of the corresponding diagonal entry), [`Error::Numerical`] when faer runs out of
    /// memory.
    ///
    /// `par`: the parallelism of the numeric factorisation and of forming W
    /// (`Par::Seq`, or `Par::rayon(n)` inside a private rayon pool, see
    /// [`crate::ProblemBuilder::threads`]).
    pub fn new(a_lower: &CsrMatrix, b: &CsrMatrix, h: f64, par: Par) -> Result<Self> {
        let n = a_lower.nrows();
        // CSR of the lower triangle == CSC of the upper triangle.
        let symb =
            SymbolicSparseColMatRef::new_checked(n, n, a_lower.row_ptr(), None, a_lower.col_idx());
        let a_csc = SparseColMatRef::new(symb, a_lower.values());
        // Supernodal always: its dense kernels halve the set-up and the back-solves even
        // where faer's heuristic would pick the simplicial code (measured on the sample,
        // n = 1320: 57M -> 31M instructions for the set-up).
        let params = faer::sparse::linalg::cholesky::CholeskySymbolicParams {
            supernodal_flop_ratio_threshold:
                faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let t_analyse = std::time::Instant::now();
        let symbolic_err = |e: faer::sparse::FaerError| match e {
            faer::sparse::FaerError::OutOfMemory => Error::OutOfMemory(
                "the symbolic Cholesky factorisation of A (ordering and structure of L)".into(),
            ),
            e => Error::Numerical(format!("symbolic Cholesky of A: {e:?}")),
        };
        let amd = factorize_symbolic_cholesky(symb, Side::Upper, SymmetricOrdering::Amd, params)
            .map_err(symbolic_err)?;
        // The dofs B touches, and whether W comes from the trailing block of the factor.
        let mut touched = vec![false; n];
        for &j in b.col_idx() {
            touched[j] = true;
        }
        let s = touched.iter().filter(|&&t| t).count();
        let trailing = s > 0
            && s <= TRAILING_MAX_RATIO * b.nrows().max(1)
            && trailing_is_cheaper(s, b.nrows(), amd.len_val());
        let symbolic = if trailing {
            // AMD order of the others, then the touched dofs (in AMD order) last.
            let amd_fwd: Vec<usize> = match amd.perm() {
                Some(p) => p.arrays().0.to_vec(),
                None => (0..n).collect(),
            };
            let mut fwd: Vec<usize> = amd_fwd.iter().copied().filter(|&j| !touched[j]).collect();
            fwd.extend(amd_fwd.iter().copied().filter(|&j| touched[j]));
            let mut inv = vec![0usize; n];
            for (k, &j) in fwd.iter().enumerate() {
                inv[j] = k;
            }
            let perm = PermRef::new_checked(&fwd, &inv, n);
            factorize_symbolic_cholesky(symb, Side::Upper, SymmetricOrdering::Custom(perm), params)
                .map_err(symbolic_err)?
        } else {
            amd
        };
        let analyse_s = t_analyse.elapsed().as_secs_f64();
        let t_factorise = std::time::Instant::now();
        let mut l_values = try_vec(symbolic.len_val(), 0.0f64, "the Cholesky factor L of A")?;
        {
            let mut mem = MemBuffer::try_new(
                symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
            )
            .map_err(|_| {
                Error::OutOfMemory(
                    "the workspace of the numeric Cholesky factorisation of A".into(),
                )
            })?;
            let res = symbolic.factorize_numeric_llt::<f64>(
                &mut l_values,
                a_csc,
                Side::Upper,
                Default::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            );
            if let Err(e) = res {
                return Err(match e {
                    DenseLltError::NonPositivePivot { index } => {
                        // faer's simplicial factorisation reports the pivot 1-based, the
                        // supernodal one 0-based.
                        let k = match symbolic.raw() {
                            SymbolicCholeskyRaw::Simplicial(_) => index.saturating_sub(1),
                            SymbolicCholeskyRaw::Supernodal(_) => index,
                        }
                        .min(n.saturating_sub(1));
                        let row = symbolic.perm().map(|p| p.arrays().0[k]).unwrap_or(k);
                        Error::NotSpd { pivot: k, row }
                    }
                });
            }
        }
        let mut this = Self {
            n,
            op: Operator::Cholesky { symbolic, l_values },
            h,
            b: b.clone(),
            w: Mat::zeros(0, 0),
            z: None,
            times: SetupTimes::default(),
            w_lo: None,
            a_full: None,
            cond: f64::NAN,
        };
        this.times.analyse_s = analyse_s;
        this.times.factorise_s = t_factorise.elapsed().as_secs_f64();
        this.times.nnz_l = match &this.op {
            Operator::Cholesky { l_values, .. } => l_values.len(),
            _ => 0,
        };
        let t_w = std::time::Instant::now();
        this.w = match trailing
            .then(|| this.w_by_trailing_block(s, par))
            .transpose()?
            .flatten()
        {
            Some((w, z)) => {
                this.z = Some(z);
                w
            }
            None => this.w_by_solves()?,
        };
        this.cond = this.check_w()?;
        this.times.w_s = t_w.elapsed().as_secs_f64();
        Ok(this)
    }

    /// `W = Zᵀ Z`, `Z = L_SS⁻¹ B_Sᵀ`, from the trailing s × s block of a supernodal factor
    /// whose ordering puts the s dofs that B touches last. None when the factor does not
    /// have that form (then W is formed by solves).
    fn w_by_trailing_block(&self, s: usize, par: Par) -> Result<Option<(Mat<f64>, Mat<f64>)>> {
        let n = self.n;
        let m = self.b.nrows();
        let Operator::Cholesky { symbolic, l_values } = &self.op else {
            return Ok(None);
        };
        let SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw() else {
            return Ok(None);
        };
        let Some(perm) = symbolic.perm() else {
            return Ok(None);
        };
        let inv = perm.arrays().1;
        let first = n - s;
        // Every dof B touches must sit in the trailing block.
        if self.b.col_idx().iter().any(|&j| inv[j] < first) {
            return Ok(None);
        }
        let llt = SupernodalLltRef::<'_, usize, f64>::new(sym, l_values);
        let mut lss = try_zeros(s, s, "the trailing block L_SS of the factor")?;
        for k in 0..sym.n_supernodes() {
            let node = llt.supernode(k);
            let start = node.start();
            let val = node.val();
            let ncols = val.ncols();
            if start + ncols <= first {
                continue;
            }
            let pattern = node.pattern();
            for c in start.max(first)..start + ncols {
                let cl = c - start;
                for r in c..start + ncols {
                    lss[(r - first, c - first)] = val[(r - start, cl)];
                }
                for (t, &r) in pattern.iter().enumerate() {
                    lss[(r - first, c - first)] = val[(ncols + t, cl)];
                }
            }
        }
        let mut z = try_zeros(s, m, "Z = L_SS^-1 B_S^T")?;
        for i in 0..m {
            for (j, v) in self.b.row(i) {
                z[(inv[j] - first, i)] = v;
            }
        }
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(
            lss.as_ref(),
            z.as_mut(),
            par,
        );
        let mut w = try_zeros(m, m, "W")?;
        faer::linalg::matmul::matmul(
            w.as_mut(),
            Accum::Replace,
            z.transpose(),
            z.as_ref(),
            1.0,
            par,
        );
        symmetrise(&mut w);
        Ok(Some((w, z)))
    }

    /// `W = B A⁻¹ Bᵀ` by 2p solves with the factor of A, in blocks of columns: how W is
    /// formed when B's rows are wide or the solves cost less than the trailing block's
    /// dense work (slender bodies), and an independent check of the trailing-block W
    /// (the two agree to rounding: ~1e-13 relative). Errors: a host's solve failed;
    /// [`Error::NoDisplacement`] for condensed input (no A⁻¹).
    pub fn w_by_solves(&self) -> Result<Mat<f64>> {
        let mut w = self.w_by_solves_raw(BLOCK)?;
        symmetrise(&mut w);
        Ok(w)
    }

    /// `B A⁻¹ Bᵀ` by solves with `block` columns at a time, not symmetrised.
    fn w_by_solves_raw(&self, block: usize) -> Result<Mat<f64>> {
        let m = self.b.nrows();
        let mut w = try_zeros(m, m, "W")?;
        let mut x = try_zeros(self.n, block.min(m), "a block of solves for W")?;
        let mut col0 = 0;
        while col0 < m {
            let k = block.min(m - col0);
            let mut xb = x.as_mut().subcols_mut(0, k);
            xb.fill(0.0);
            for c in 0..k {
                for (j, v) in self.b.row(col0 + c) {
                    xb[(j, c)] = v;
                }
            }
            self.solve_scaled(xb.as_mut())?;
            for i in 0..m {
                for c in 0..k {
                    w[(i, col0 + c)] = self.b.row(i).map(|(j, v)| v * xb[(j, c)]).sum();
                }
            }
            col0 += k;
        }
        Ok(w)
    }

    /// Checks W (finite, positive definite with relative pivots above 1e-12) and returns
    /// the estimate of its condition number from the Cholesky factor it computes.
    fn check_w(&self) -> Result<f64> {
        let m = self.w.nrows();
        let p = m / 2;
        let name = |i: usize| {
            if i < p {
                format!("row {} of N (node {})", i + 1, i + 1)
            } else {
                format!("row {} of T (node {})", i - p + 1, i - p + 1)
            }
        };
        // Cholesky of W (faer, blocked) with a relative pivot test: a pivot d_j = L_jj²
        // ≤ 1e-12 W_jj means that row j of B is (numerically) a combination of the rows
        // before it.
        for j in 0..m {
            if self.w[(j, j)] <= 0.0 {
                return Err(Error::RankDeficient(format!("{} is zero", name(j))));
            }
        }
        for j in 0..m {
            if let Some(i) = (0..m).find(|&i| !self.w[(i, j)].is_finite()) {
                return Err(Error::Numerical(format!(
                    "W = B A^-1 B^T has the entry W({}, {}) = {} (1-based): A^-1 is beyond the range of a double (A numerically singular?)",
                    i + 1,
                    j + 1,
                    self.w[(i, j)]
                )));
            }
        }
        let dependent = |j: usize, d: f64| {
            Error::RankDeficient(format!(
                "{} depends linearly on the rows before it (relative pivot {:e})",
                name(j),
                d / self.w[(j, j)]
            ))
        };
        crate::problem::preflight(m * m * 8, "the Cholesky factor of W")?;
        let l = match crate::dense::llt_lower(self.w.as_ref()) {
            Ok(l) => l,
            Err(DenseLltError::NonPositivePivot { index }) => {
                return Err(dependent(index.min(m.saturating_sub(1)), 0.0));
            }
        };
        for j in 0..m {
            let d = l[(j, j)] * l[(j, j)];
            if d <= 1e-12 * self.w[(j, j)] {
                return Err(dependent(j, d));
            }
        }
        Ok(condition_estimate(self.w.as_ref(), l.as_ref()))
    }

    /// Number of dofs `n` (0 for condensed input).
    pub fn n(&self) -> usize {
        self.n
    }

    /// `W = B A⁻¹ Bᵀ` (2p×2p; rows/cols `0..p` normal, `p..2p` tangential).
    pub fn w(&self) -> MatRef<'_, f64> {
        self.w.as_ref()
    }

    /// Times of the set-up phases and nnz(L) (see [`SetupTimes`]).
    pub fn setup_times(&self) -> SetupTimes {
        self.times
    }

    /// True when W was formed from the trailing block of the factor (the dofs that B
    /// touches ordered last), false when by 2p solves (wide rows of B, or a factor so thin
    /// that the solves cost less).
    pub fn w_from_trailing_block(&self) -> bool {
        self.z.is_some()
    }

    /// True when [`Self::half_solve`] and [`Self::displacements`] are available (fricont's
    /// own factor, W from its trailing block).
    pub(crate) fn has_half_solve(&self) -> bool {
        self.z.is_some()
    }

    /// The forward half of a solve with A: `Y = L⁻¹ Pᵀ (h X)` in place for every column of
    /// `x` (n rows, the caller's loads; `h` as in [`Self::new`]), in the factor's order.
    /// Errors: [`Error::Usage`] without
    /// [`Self::has_half_solve`].
    pub(crate) fn half_solve(&self, mut x: MatMut<'_, f64>) -> Result<()> {
        let (llt, fwd) = self.supernodal()?;
        let k = x.ncols();
        let mut col = vec![0.0; self.n];
        for c in 0..k {
            for (i, &j) in fwd.iter().enumerate() {
                col[i] = self.h * x[(j, c)];
            }
            for (i, v) in col.iter().enumerate() {
                x[(i, c)] = *v;
            }
        }
        let mut mem = self.solve_scratch(k)?;
        llt.l_solve_with_conj(Conj::No, x, Par::Seq, MemStack::new(&mut mem));
        Ok(())
    }

    /// `q = B A⁻¹ v` from `y = L⁻¹ Pᵀ v` ([`Self::half_solve`]): `q = Zᵀ y_S`, because
    /// the last s entries of `L⁻ᵀ y` depend on the last s entries of `y` only.
    pub(crate) fn condense_half(&self, y: &[f64]) -> Vec<f64> {
        let z = self
            .z
            .as_ref()
            .expect("condense_half needs the trailing block");
        let ys = &y[self.n - z.nrows()..];
        (0..z.ncols())
            .map(|i| {
                let col = z.col(i).try_as_col_major().expect("contiguous");
                crate::dense::dot(col.as_slice(), ys)
            })
            .collect()
    }

    /// `u = A⁻¹ (f + (B / h)ᵀ λ)` for every column, from the half-solved loads
    /// `y = L⁻¹ Pᵀ h f` (n × k, overwritten) and the contact forces `lam` (2p × k,
    /// equilibrated rows): `L⁻¹ Pᵀ Bᵀ λ = (0, Z λ)`, and u is h times the solution of the
    /// factorised `h² A`, so only the backward half `P L⁻ᵀ (y + (0, Z λ))` touches
    /// the whole factor. Errors: [`Error::Usage`] without [`Self::has_half_solve`]; out of
    /// memory.
    pub(crate) fn displacements(
        &self,
        mut y: MatMut<'_, f64>,
        lam: MatRef<'_, f64>,
        mut u: MatMut<'_, f64>,
    ) -> Result<()> {
        let (llt, fwd) = self.supernodal()?;
        let z = self.z.as_ref().expect("supernodal() checked z");
        let (n, k) = (self.n, y.ncols());
        let first = n - z.nrows();
        faer::linalg::matmul::matmul(
            y.as_mut().subrows_mut(first, z.nrows()),
            Accum::Add,
            z.as_ref(),
            lam,
            1.0,
            Par::Seq,
        );
        let mut mem = self.solve_scratch(k)?;
        llt.l_transpose_solve_with_conj(Conj::No, y.as_mut(), Par::Seq, MemStack::new(&mut mem));
        for c in 0..k {
            let yc = y.as_ref().col(c);
            let mut uc = u.as_mut().col_mut(c);
            for (i, &j) in fwd.iter().enumerate() {
                uc[j] = self.h * yc[i];
            }
            check_u(uc.as_ref().iter().copied())?;
        }
        Ok(())
    }

    fn supernodal(&self) -> Result<(SupernodalLltRef<'_, usize, f64>, &[usize])> {
        if let (Operator::Cholesky { symbolic, l_values }, Some(_)) = (&self.op, &self.z)
            && let SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw()
            && let Some(perm) = symbolic.perm()
        {
            return Ok((
                SupernodalLltRef::<'_, usize, f64>::new(sym, l_values),
                perm.arrays().0,
            ));
        }
        Err(Error::Usage(
            "half solves need fricont's own factor with W from its trailing block".into(),
        ))
    }

    fn solve_scratch(&self, k: usize) -> Result<MemBuffer> {
        let Operator::Cholesky { symbolic, .. } = &self.op else {
            unreachable!("checked by supernodal()")
        };
        MemBuffer::try_new(symbolic.solve_in_place_scratch::<f64>(k, Par::Seq)).map_err(|_| {
            Error::OutOfMemory(format!(
                "the workspace of a solve with {k} right-hand sides"
            ))
        })
    }

    /// `B = [N; T]` with the equilibrated rows the factor is used with: `h` times
    /// [`crate::Problem::b`] (`h` as in [`Self::new`], 1 for ordinary data).
    pub fn b(&self) -> &CsrMatrix {
        &self.b
    }

    /// The default augmentation parameter `2p / trace(W)` (force per length).
    pub fn default_r(&self) -> f64 {
        let m = self.w.nrows();
        let tr: f64 = (0..m).map(|i| self.w[(i, i)]).sum();
        m as f64 / tr
    }

    /// True when `A⁻¹` can be applied (fricont's factor or a host's solve): u is then
    /// available; false for condensed input.
    pub fn has_solve(&self) -> bool {
        !matches!(self.op, Operator::Condensed { .. })
    }

    /// True for condensed input (W given, loads given condensed).
    pub fn is_condensed(&self) -> bool {
        matches!(self.op, Operator::Condensed { .. })
    }

    /// Length of a load vector: n, or 2p for condensed input.
    pub fn load_len(&self) -> usize {
        if self.is_condensed() {
            self.w.nrows()
        } else {
            self.n
        }
    }

    /// Solves `A X = X` in place for every column of `x` (n rows), with the caller's A.
    /// Errors: the host's solve failed ([`Error::HostSolve`]); condensed input
    /// ([`Error::NoDisplacement`]).
    pub fn solve_mat_in_place(&self, mut x: MatMut<'_, f64>) -> Result<()> {
        // A⁻¹ x = h (h² A)⁻¹ (h x): both products by h are exact, and every intermediate
        // stays in the range of the data.
        if self.h != 1.0 {
            x *= faer::Scale(self.h);
        }
        self.solve_scaled(x.as_mut())?;
        if self.h != 1.0 {
            x *= faer::Scale(self.h);
        }
        for c in 0..x.ncols() {
            check_u(x.as_ref().col(c).iter().copied())?;
        }
        Ok(())
    }

    /// Solves with the matrix that was factorised (`h² A`, see [`Self::new`]).
    fn solve_scaled(&self, x: MatMut<'_, f64>) -> Result<()> {
        match &self.op {
            Operator::Cholesky { symbolic, l_values } => {
                let par = Par::Seq;
                let k = x.ncols();
                let mut mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(k, par));
                LltRef::new(symbolic, l_values).solve_in_place_with_conj(
                    Conj::No,
                    x,
                    par,
                    MemStack::new(&mut mem),
                );
                Ok(())
            }
            Operator::Host(h) => h.solve(x),
            Operator::Condensed { .. } => Err(no_displacement()),
        }
    }

    /// Solves `A x = x` in place (x has n entries). Errors as [`Self::solve_mat_in_place`].
    pub fn solve_in_place(&self, x: &mut [f64]) -> Result<()> {
        let n = x.len();
        let mat = faer::MatMut::from_column_major_slice_mut(x, n, 1);
        self.solve_mat_in_place(mat)
    }

    /// `q = (B / h) A⁻¹ f` (2p entries, the rows of [`crate::Problem::b`]) for a load
    /// vector `f` (n entries, the caller's units; `h` as in [`Self::new`]);
    /// for condensed input `f` is already `q` in the caller's rows, and only the
    /// equilibration is applied. Errors: the host's solve failed.
    pub fn condense(&self, f: &[f64]) -> Result<Vec<f64>> {
        Ok(self.condense_many(&[f])?.pop().expect("one column"))
    }

    /// [`Self::condense`] for every vector of `fs`, in one pass over the factor for all
    /// of them: the forward half only where W came from the factor's trailing block
    /// ([`Self::condense_half`]). Errors as [`Self::condense`].
    pub(crate) fn condense_many(&self, fs: &[&[f64]]) -> Result<Vec<Vec<f64>>> {
        Ok(self.condense_many_keep_half(fs)?.0)
    }

    /// [`Self::condense_many`], also returning the half-solved vectors
    /// `Y = L⁻¹ Pᵀ (h F)` (n × k, see [`Self::half_solve`]) where they were the way to q
    /// ([`Self::has_half_solve`]), for the displacements at later forces.
    pub(crate) fn condense_many_keep_half(&self, fs: &[&[f64]]) -> Result<CondensedWithHalf> {
        if fs.is_empty() {
            return Ok((Vec::new(), None));
        }
        if let Operator::Condensed { row_scale } = &self.op {
            let qs = fs
                .iter()
                .map(|f| f.iter().zip(row_scale).map(|(v, s)| v / s).collect())
                .collect();
            return Ok((qs, None));
        }
        let n = self.n;
        if let Some(f) = fs.iter().find(|f| f.len() != n) {
            return Err(Error::Dimension(format!(
                "a load vector has {} entries, A has n = {n}",
                f.len()
            )));
        }
        let mut x = crate::error::try_zeros(n, fs.len(), "the condensed load vectors")?;
        for (c, f) in fs.iter().enumerate() {
            for (i, v) in f.iter().enumerate() {
                x[(i, c)] = *v;
            }
        }
        let half = self.has_half_solve();
        let qs: Vec<Vec<f64>> = if half {
            self.half_solve(x.as_mut())?;
            (0..fs.len())
                .map(|c| {
                    let y = x.col(c).try_as_col_major().expect("contiguous");
                    self.condense_half(y.as_slice())
                })
                .collect()
        } else {
            // B (h² A)⁻¹ (h f) = (B / h) A⁻¹ f
            x *= faer::Scale(self.h);
            self.solve_scaled(x.as_mut())?;
            (0..fs.len())
                .map(|c| {
                    let xc = x.col(c).try_as_col_major().expect("contiguous");
                    let mut q = vec![0.0; self.b.nrows()];
                    self.b.mul_vec(xc.as_slice(), &mut q);
                    q
                })
                .collect()
        };
        for q in &qs {
            if let Some(i) = q.iter().position(|v| !v.is_finite()) {
                return Err(Error::Numerical(format!(
                    "the condensed load q = B A^-1 f overflows (row {} is {}): the load is too large for this A",
                    i + 1,
                    q[i]
                )));
            }
        }
        Ok((qs, half.then_some(x)))
    }

    /// The displacement `u = A⁻¹ (f + (B / h)ᵀ λ)` (one back-solve; `h` as in
    /// [`Self::new`], 1 for ordinary data), for the caller's f and u. Errors as
    /// [`Self::solve_mat_in_place`].
    pub fn displacement(&self, f: &[f64], lambda: &[f64]) -> Result<Vec<f64>> {
        // h (h² A)⁻¹ (h f + Bᵀ λ)
        let mut x: Vec<f64> = f.iter().map(|v| self.h * v).collect();
        self.b.mul_t_vec_add(lambda, &mut x);
        let n = x.len();
        self.solve_scaled(faer::MatMut::from_column_major_slice_mut(&mut x, n, 1))?;
        x.iter_mut().for_each(|v| *v *= self.h);
        check_u(x.iter().copied())?;
        Ok(x)
    }

    /// Forms W from a host's solve: `W = B X`, `X = A⁻¹ Bᵀ` by 2p solves in blocks of the
    /// host's `max_block` columns. `b` is the equilibrated `B` (2p×n). Errors: the solve
    /// failed; W not symmetric (relative 1e-8: the solve is not that of a symmetric A);
    /// B rank-deficient.
    pub fn from_host_solve(n: usize, solve: HostSolve, b: &CsrMatrix) -> Result<Self> {
        let t_w = std::time::Instant::now();
        let mut this = Self {
            n,
            op: Operator::Host(solve),
            h: 1.0,
            b: b.clone(),
            w: Mat::zeros(0, 0),
            z: None,
            times: SetupTimes::default(),
            w_lo: None,
            a_full: None,
            cond: f64::NAN,
        };
        let m = b.nrows();
        let block = match &this.op {
            Operator::Host(h) => h.max_block.clamp(1, 256),
            _ => BLOCK,
        };
        let mut w = this.w_by_solves_raw(block)?;
        let big = (0..m).fold(0.0f64, |a, i| a.max(w[(i, i)].abs()));
        for i in 0..m {
            for j in 0..i {
                let d = (w[(i, j)] - w[(j, i)]).abs();
                if d > 1e-8 * big {
                    return Err(Error::NotSymmetric(format!(
                        "W = B A^-1 B^T formed with the host's solve is not symmetric: W({}, {}) and W({}, {}) differ by {d:e} (max |W_ii| = {big:e}); is the solve that of a symmetric A?",
                        i + 1,
                        j + 1,
                        j + 1,
                        i + 1
                    )));
                }
            }
        }
        symmetrise(&mut w);
        this.w = w;
        this.cond = this.check_w()?;
        this.times.w_s = t_w.elapsed().as_secs_f64();
        Ok(this)
    }

    /// Condensed input: `w` is the caller's W (2p×2p) already divided symmetrically by
    /// the row scales (`row_scale`, 2p entries, see [`crate::Problem::row_scale`]), and
    /// checked to be symmetric and positive definite by the caller, who also gives its
    /// Cholesky factor `l` (for the condition estimate).
    pub(crate) fn from_condensed(w: Mat<f64>, row_scale: Vec<f64>, l: MatRef<'_, f64>) -> Self {
        let cond = condition_estimate(w.as_ref(), l);
        Self {
            n: 0,
            op: Operator::Condensed { row_scale },
            h: 1.0,
            b: CsrMatrix::from_triplets("B", w.nrows(), 0, &[]).expect("an empty matrix"),
            w,
            z: None,
            times: SetupTimes::default(),
            w_lo: None,
            a_full: None,
            cond,
        }
    }
}

/// A displacement that is not finite: the caller's u does not fit in a double (a tiny A
/// and a large load): [`Error::Numerical`] instead of an infinite u.
fn check_u(u: impl Iterator<Item = f64>) -> Result<()> {
    match u.enumerate().find(|(_, v)| !v.is_finite()) {
        None => Ok(()),
        Some((i, v)) => Err(Error::Numerical(format!(
            "the displacement u overflows (entry {} is {v}): u = A^-1 (f + B^T lambda) is beyond the range of a double for this A and load (A tiny compared with f? scale A and the loads alike)",
            i + 1,
        ))),
    }
}

fn no_displacement() -> Error {
    Error::NoDisplacement(
        "u is not available: the problem was made from condensed data (W) without a solve with A"
            .into(),
    )
}

/// Replaces `w` by `(w + wᵀ) / 2` (the rounding of a product is not symmetric).
fn symmetrise(w: &mut Mat<f64>) {
    for i in 0..w.nrows() {
        for j in 0..i {
            let s = 0.5 * w[(i, j)] + 0.5 * w[(j, i)];
            w[(i, j)] = s;
            w[(j, i)] = s;
        }
    }
}

/// Rounds of mixed-precision refinement at most (each gains the digits that κ(A) leaves
/// of double precision; two or three suffice on the slender meshes of the tests).
const REFINE_ROUNDS: usize = 5;

/// A correction below this fraction of the solution (∞-norms, column by column) ends the
/// refinement: the double-double solution is then as accurate as its residuals allow.
const REFINE_TOL: f64 = 1e-30;

/// Iterations of the power method (λ_max of W) and of inverse iteration (λ_min) in
/// [`condition_estimate`].
const COND_ITERS: usize = 20;

impl Delassus {
    /// The low part of W: `W_hi + W_lo` (with `W_hi` = [`Self::w`], then W correctly
    /// rounded) is `B A⁻¹ Bᵀ` of the
    /// equilibrated rows to double-double accuracy (about 1e-30 relative to max|W| when A
    /// is well enough conditioned for refinement in double to converge, κ(A) < 1e15).
    /// None when W is exact as stored: not refined ([`crate::ExtendedPrecision::Off`], or
    /// `Auto` on a well-conditioned W, or a host's solve), or condensed input (the caller's
    /// W is the data).
    pub fn w_lo(&self) -> Option<MatRef<'_, f64>> {
        self.w_lo.as_ref().map(|m| m.as_ref())
    }

    /// An estimate of the 2-norm condition number `λ_max / λ_min` of W (equilibrated
    /// rows), from 20 steps of the power method for λ_max and 20 steps of inverse
    /// iteration with the Cholesky factor of W (computed anyway to check that W is
    /// positive definite) for λ_min: each a lower bound of its eigenvalue's size, so the
    /// estimate is at most κ₂(W) and usually within a few percent of it. Costs 40 products
    /// with a 2p × 2p matrix, O(p²) each, at the build. Dimensionless.
    pub fn w_condition_estimate(&self) -> f64 {
        self.cond
    }

    /// Floating-point operations of the numeric Cholesky factorisation of A, estimated as
    /// `Σ_j c_j²` over the column counts `c_j` of L (0 without fricont's factor).
    pub(crate) fn factor_flops(&self) -> f64 {
        let Operator::Cholesky { symbolic, .. } = &self.op else {
            return 0.0;
        };
        match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sym) => {
                let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
                let ptr = sym.col_ptr_for_row_idx();
                (0..sym.n_supernodes())
                    .map(|s| {
                        let k = end[s] - begin[s];
                        let r = (ptr[s + 1] - ptr[s]) as f64;
                        (0..k).map(|t| ((k - t) as f64 + r).powi(2)).sum::<f64>()
                    })
                    .sum()
            }
            SymbolicCholeskyRaw::Simplicial(sym) => sym
                .col_ptr()
                .windows(2)
                .map(|w| ((w[1] - w[0]) as f64).powi(2))
                .sum(),
        }
    }

    /// Floating-point operations of [`Self::refine_w`], estimated for three rounds: per
    /// column of Bᵀ four solves with the factor (4 nnz(L) each) and three residuals in
    /// double-double (about 12 operations per entry of A).
    pub(crate) fn refine_flops(&self, nnz_a: usize) -> f64 {
        let m = self.w.nrows() as f64;
        let nnz_l = self.times.nnz_l as f64;
        m * (4.0 * 4.0 * nnz_l + 3.0 * 12.0 * nnz_a as f64)
    }

    /// Computes [`Self::w_lo`] by mixed-precision iterative refinement with the Cholesky
    /// factor of A, in blocks of 32 columns of Bᵀ: `X = A⁻¹ Bᵀ_blk` in double, then
    /// rounds of `R = Bᵀ_blk − A (X + X_lo)` (double-double, rounded to double),
    /// `D = A⁻¹ R`, `X + X_lo += D` (double-double) until, in every column, `‖D‖∞ ≤
    /// 1e-30 ‖X‖∞`, or a round no longer halves the correction, or the next correction
    /// (the contraction ρ ≈ κ(A) ε of the last round times ‖D‖) falls below the floor
    /// `ρ ε ‖X‖` that residuals in double-double allow (at most 5 rounds; 3 on the slender
    /// strips, where ρ ≈ 1e-7); then `W_exact = B (X + X_lo)` in double-double,
    /// symmetrised; W becomes `W_exact` rounded to double (the W of the trailing block or
    /// of the solves is accurate only to ~κ(A) ε) and `W_lo` the rest. `a_full` is the
    /// factorised matrix (`h² A`, both triangles; [`crate::Problem::a`], shared with the
    /// problem, not copied); it is kept for [`Self::condense_lo`].
    /// Memory: O(n · 32) besides W_lo (2p × 2p). Time: about 2p × 4 solves with the
    /// factor ([`SetupTimes::w_lo_s`]).
    ///
    /// Errors: [`Error::InvalidParameter`] for a host's solve (no A to compute residuals
    /// with); out of memory. A no-op for condensed input.
    pub(crate) fn refine_w(&mut self, a_full: std::sync::Arc<CsrMatrix>) -> Result<()> {
        match &self.op {
            Operator::Condensed { .. } => return Ok(()),
            Operator::Host(_) => return Err(host_cannot_refine()),
            Operator::Cholesky { .. } => {}
        }
        let t = std::time::Instant::now();
        let (n, m) = (self.n, self.b.nrows());
        let kb = BLOCK.min(m);
        let mut w_lo = try_zeros(m, m, "the low part of W")?;
        let mut w_hi = try_zeros(m, m, "W rounded from double-double")?;
        let mut buf = RefineBuffers::new(n, kb)?;
        let mut col0 = 0;
        while col0 < m {
            let k = kb.min(m - col0);
            buf.rhs[..n * k].fill(0.0);
            for c in 0..k {
                for (j, v) in self.b.row(col0 + c) {
                    buf.rhs[c * n + j] = v;
                }
            }
            self.refine_solve(&a_full, &mut buf, k)?;
            for c in 0..k {
                let (x, xl) = (&buf.x[c * n..(c + 1) * n], &buf.x_lo[c * n..(c + 1) * n]);
                for i in 0..m {
                    let exact = sparse_dot_dd(self.b.row(i), x, xl);
                    (w_hi[(i, col0 + c)], w_lo[(i, col0 + c)]) = (exact.hi, exact.lo);
                }
            }
            col0 += k;
        }
        // The exact W is symmetric; its two computed halves differ in the last digits of
        // double-double. Their mean, rounded: W_hi (W correctly rounded, which every
        // double-precision computation of the tracer then uses) and W_lo.
        for j in 0..m {
            for i in j..m {
                let mean = (Dd::new(w_hi[(i, j)], w_lo[(i, j)])
                    + Dd::new(w_hi[(j, i)], w_lo[(j, i)]))
                .mul_f64(0.5);
                (w_hi[(i, j)], w_lo[(i, j)]) = (mean.hi, mean.lo);
                (w_hi[(j, i)], w_lo[(j, i)]) = (mean.hi, mean.lo);
            }
        }
        self.w = w_hi;
        self.w_lo = Some(w_lo);
        self.a_full = Some(a_full);
        self.times.w_lo_s = t.elapsed().as_secs_f64();
        Ok(())
    }

    /// Keeps the factorised matrix (`h² A`, both triangles; [`crate::Problem::a`], shared,
    /// not copied) for [`Self::condense_error`] where W is not refined. A no-op for a
    /// host's solve and condensed input.
    pub(crate) fn keep_matrix(&mut self, a_full: std::sync::Arc<CsrMatrix>) {
        if matches!(self.op, Operator::Cholesky { .. }) {
            self.a_full = Some(a_full);
        }
    }

    /// The low parts of condensed load vectors: for each load vector `f_j` (n entries, the
    /// caller's units) and its condensed image `q_j` as fricont stores it (2p entries),
    /// `exact((B / h) A⁻¹ f_j) − q_j` rounded to double, by the refinement that gave W's
    /// low part (mixed-precision solves with the factor of A, a few per vector). None when
    /// W was not refined ([`Self::w_lo`] is None): then q is used as stored.
    /// Errors: lengths that do not match; out of memory.
    pub fn condense_lo(&self, f: &[&[f64]], q: &[&[f64]]) -> Result<Option<Vec<Vec<f64>>>> {
        if self.w_lo.is_none() {
            return Ok(None);
        }
        self.condense_error(f, q)
    }

    /// What [`Self::condense_lo`] computes, `exact((B / h) A⁻¹ f_j) − q_j` rounded to
    /// double, wherever the factorised matrix is kept ([`Self::keep_matrix`]), whether W
    /// was refined or not: the error of each condensed vector as the solve left it (about
    /// κ(A) ε of the whole vector, in every row, also where the exact row is 0). None for
    /// a host's solve and condensed input. Errors: as [`Self::condense_lo`]; the
    /// refinement diverged ([`Error::Numerical`], A too ill-conditioned for double).
    pub(crate) fn condense_error(
        &self,
        f: &[&[f64]],
        q: &[&[f64]],
    ) -> Result<Option<Vec<Vec<f64>>>> {
        let Some(a_full) = self.a_full.as_ref() else {
            return Ok(None);
        };
        let (n, m) = (self.n, self.b.nrows());
        if f.len() != q.len() || f.iter().any(|v| v.len() != n) || q.iter().any(|v| v.len() != m) {
            return Err(Error::Dimension(format!(
                "condense_lo: {} load vectors of n = {n} entries and {} condensed ones of 2p = {m} entries expected",
                f.len(),
                q.len()
            )));
        }
        let mut out = Vec::with_capacity(f.len());
        let kb = BLOCK.min(f.len().max(1));
        let mut buf = RefineBuffers::new(n, kb)?;
        for (fs, qs) in f.chunks(kb).zip(q.chunks(kb)) {
            let k = fs.len();
            for (c, v) in fs.iter().enumerate() {
                // (h² A)⁻¹ (h f): the product by the power of two h is exact.
                for (r, x) in buf.rhs[c * n..(c + 1) * n].iter_mut().zip(v.iter()) {
                    *r = self.h * x;
                }
            }
            self.refine_solve(a_full, &mut buf, k)?;
            for (c, qc) in qs.iter().enumerate() {
                let (x, xl) = (&buf.x[c * n..(c + 1) * n], &buf.x_lo[c * n..(c + 1) * n]);
                out.push(
                    (0..m)
                        .map(|i| sparse_dot_dd(self.b.row(i), x, xl).add_f64(-qc[i]).to_f64())
                        .collect(),
                );
            }
        }
        Ok(Some(out))
    }

    /// `X + X_lo = A⁻¹ rhs` to double-double accuracy for the first `k` columns of
    /// `buf.rhs` (n × k, column-major): a solve in double, then rounds of residuals in
    /// double-double and corrections with the factor (see [`Self::refine_w`]).
    fn refine_solve(&self, a: &CsrMatrix, buf: &mut RefineBuffers, k: usize) -> Result<()> {
        let n = self.n;
        let RefineBuffers { rhs, x, x_lo, r } = buf;
        let (rhs, x, x_lo, r) = (
            &rhs[..n * k],
            &mut x[..n * k],
            &mut x_lo[..n * k],
            &mut r[..n * k],
        );
        x.copy_from_slice(rhs);
        self.solve_scaled(MatMut::from_column_major_slice_mut(x, n, k))?;
        x_lo.fill(0.0);
        let mut last = vec![f64::INFINITY; k];
        for _ in 0..REFINE_ROUNDS {
            residual_dd(a, rhs, x, x_lo, r, n);
            self.solve_scaled(MatMut::from_column_major_slice_mut(r, n, k))?;
            let mut more = false;
            for c in 0..k {
                for i in c * n..(c + 1) * n {
                    let s = Dd {
                        hi: x[i],
                        lo: x_lo[i],
                    }
                    .add_f64(r[i]);
                    (x[i], x_lo[i]) = (s.hi, s.lo);
                }
                // (NaN-sticky norms: a NaN correction is a divergence too)
                let dn = inf_norm(&r[c * n..(c + 1) * n]);
                let xn = inf_norm(&x[c * n..(c + 1) * n]);
                if !dn.is_finite() {
                    return Err(Error::Numerical(
                        "the refinement of A^-1 B^T diverged (A too ill-conditioned for refinement in double)".into(),
                    ));
                }
                // The contraction ρ ≈ κ(A) ε of a round (the first correction is ρ times
                // x). The residuals, exact to ~ε² |A| |x|, leave a floor of ~ρ ε ‖x‖
                // that no round passes: once the next correction, ρ ‖D‖, is below it (or
                // below the tolerance), or a round no longer halves the correction, the
                // column is done.
                let rho = if last[c].is_finite() {
                    dn / last[c]
                } else {
                    dn / xn
                };
                if dn > REFINE_TOL * xn
                    && dn <= 0.5 * last[c]
                    && rho * dn > (REFINE_TOL).max(rho * f64::EPSILON / 2.0) * xn
                {
                    more = true;
                }
                last[c] = dn;
            }
            if !more {
                break;
            }
        }
        Ok(())
    }
}

/// The work arrays of [`Delassus::refine_solve`]: right-hand sides, the solution's high and
/// low parts and the residual, n × block each (column-major).
struct RefineBuffers {
    rhs: Vec<f64>,
    x: Vec<f64>,
    x_lo: Vec<f64>,
    r: Vec<f64>,
}

impl RefineBuffers {
    fn new(n: usize, k: usize) -> Result<Self> {
        let what = "the work arrays of the refinement of W";
        Ok(Self {
            rhs: try_vec(n * k, 0.0, what)?,
            x: try_vec(n * k, 0.0, what)?,
            x_lo: try_vec(n * k, 0.0, what)?,
            r: try_vec(n * k, 0.0, what)?,
        })
    }
}

/// `r = rhs − A (x + x_lo)` for the n-long columns of `rhs`, `x`, `x_lo` and `r`
/// (column-major), compensated in double-double and rounded to double. Four columns
/// share each pass over a row of A (independent chains); compiled for the machine's
/// fused multiply-adds by faer's dispatch (elsewhere `mul_add` is a library call).
fn residual_dd(a: &CsrMatrix, rhs: &[f64], x: &[f64], x_lo: &[f64], r: &mut [f64], n: usize) {
    struct Residual<'a> {
        a: &'a CsrMatrix,
        rhs: &'a [f64],
        x: &'a [f64],
        x_lo: &'a [f64],
        r: &'a mut [f64],
        n: usize,
    }
    impl<'a> faer::traits::pulp::WithSimd for Residual<'a> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: faer::traits::pulp::Simd>(self, _: S) {
            const L: usize = 4;
            let Residual {
                a,
                rhs,
                x,
                x_lo,
                r,
                n,
            } = self;
            let (ptr, idx, val) = (a.row_ptr(), a.col_idx(), a.values());
            let k = rhs.len() / n;
            let mut c0 = 0;
            while c0 < k {
                let lanes = L.min(k - c0);
                let col = |v: &'a [f64], l: usize| &v[(c0 + l.min(lanes - 1)) * n..][..n];
                let xs: [&[f64]; L] = std::array::from_fn(|l| col(x, l));
                let ls: [&[f64]; L] = std::array::from_fn(|l| col(x_lo, l));
                for i in 0..n {
                    // rhs_i − Σ_j a_ij (x_j + x_lo,j), compensated, in L columns at once
                    let mut s: [f64; L] = std::array::from_fn(|l| col(rhs, l)[i]);
                    let mut e = [0.0f64; L];
                    for q in ptr[i]..ptr[i + 1] {
                        let (j, v) = (idx[q], val[q]);
                        for l in 0..L {
                            let (p, pe) = two_prod(-v, xs[l][j]);
                            let (s2, se) = two_sum(s[l], p);
                            s[l] = s2;
                            e[l] += pe + se - v * ls[l][j];
                        }
                    }
                    for l in 0..lanes {
                        r[(c0 + l) * n + i] = s[l] + e[l];
                    }
                }
                c0 += lanes;
            }
        }
    }
    faer::traits::pulp::Arch::new().dispatch(Residual {
        a,
        rhs,
        x,
        x_lo,
        r,
        n,
    })
}

/// `Σ v_j (x_j + x_lo,j)` over a sparse row, in double-double (compensated: the products'
/// and the sums' errors kept; the `v x_lo` terms, already ε times smaller, in double).
fn sparse_dot_dd(row: impl Iterator<Item = (usize, f64)>, x: &[f64], x_lo: &[f64]) -> Dd {
    let (mut s, mut e) = (0.0f64, 0.0f64);
    for (j, v) in row {
        let (p, pe) = two_prod(v, x[j]);
        let (s2, se) = two_sum(s, p);
        s = s2;
        e += pe + se + v * x_lo[j];
    }
    Dd::new(s, e)
}

pub(crate) fn host_cannot_refine() -> Error {
    Error::InvalidParameter(
        "extended precision (W beyond double by mixed-precision refinement) needs A: a problem made with the host's solve cannot be refined (use ProblemBuilder::new with A, or condensed data computed in extended precision)".into(),
    )
}

/// An estimate of `κ₂(W) = λ_max / λ_min` for W symmetric positive definite with Cholesky
/// factor `l` (lower): [`COND_ITERS`] steps of the power method with W and of inverse
/// iteration with `L Lᵀ`, from a fixed start vector, Rayleigh quotients at the end.
pub(crate) fn condition_estimate(w: MatRef<'_, f64>, l: MatRef<'_, f64>) -> f64 {
    let m = w.nrows();
    if m == 0 {
        return 1.0;
    }
    // (Explicit sequential kernels: faer's operators would use its global parallelism,
    // a thread pool in the host's process.)
    let dot = |a: &Mat<f64>, b: &Mat<f64>| (0..m).map(|i| a[(i, 0)] * b[(i, 0)]).sum::<f64>();
    let normalise = |x: &mut Mat<f64>| {
        let nrm = dot(x, x).sqrt();
        if nrm > 0.0 && nrm.is_finite() {
            for i in 0..m {
                x[(i, 0)] /= nrm;
            }
        }
    };
    // A fixed start with no symmetry (a symmetric mesh's extremal eigenvectors may be
    // orthogonal to a constant vector).
    let mut start = Mat::from_fn(m, 1, |i, _| 1.0 + ((i * 7919) % 97) as f64 / 97.0);
    normalise(&mut start);
    let mut x = start.clone();
    let mut y = Mat::<f64>::zeros(m, 1);
    let mut lmax = 0.0;
    for _ in 0..COND_ITERS {
        faer::linalg::matmul::matmul(y.as_mut(), Accum::Replace, w, x.as_ref(), 1.0, Par::Seq);
        lmax = dot(&x, &y);
        std::mem::swap(&mut x, &mut y);
        normalise(&mut x);
    }
    let mut x = start;
    let mut inv_lmin = 0.0;
    for _ in 0..COND_ITERS {
        y.copy_from(&x);
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, y.as_mut(), Par::Seq);
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(
            l.transpose(),
            y.as_mut(),
            Par::Seq,
        );
        inv_lmin = dot(&x, &y);
        std::mem::swap(&mut x, &mut y);
        normalise(&mut x);
    }
    if inv_lmin > 0.0 && lmax > 0.0 {
        lmax * inv_lmin
    } else {
        f64::INFINITY
    }
}
