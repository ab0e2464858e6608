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
//! that it never touches a host program's thread pool) and the dense `W`, formed by one
//! multi-right-hand-side solve in blocks of columns.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltError as DenseLltError;
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymbolicCholeskyRaw, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};

use crate::error::{Error, Result};
use crate::problem::CsrMatrix;

/// Columns of `Bᵀ` solved at once when forming `W` (bounds the dense workspace to
/// `n × BLOCK` numbers).
const BLOCK: usize = 32;

/// The Cholesky factor of `A` and the Delassus operator `W = B A⁻¹ Bᵀ`.
#[derive(Debug)]
pub struct Delassus {
    n: usize,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    b: CsrMatrix,
    w: Mat<f64>,
}

impl Delassus {
    /// Factorises `A` given by its lower triangle (CSR, row ≥ col; as CSC this is the upper
    /// triangle of the symmetric matrix) and forms `W` for `B` (2p×n).
    ///
    /// Errors: [`Error::NotSpd`] with the failing pivot, [`Error::RankDeficient`] when `W`
    /// is not numerically positive definite (a pivot of its Cholesky factor below 1e-12
    /// of the corresponding diagonal entry), [`Error::Numerical`] when faer runs out of
    /// memory.
    pub fn new(a_lower: &CsrMatrix, b: &CsrMatrix) -> Result<Self> {
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
        let symbolic = factorize_symbolic_cholesky(symb, Side::Upper, Default::default(), params)
            .map_err(|e| Error::Numerical(format!("symbolic Cholesky of A: {e:?}")))?;
        let mut l_values = vec![0.0f64; symbolic.len_val()];
        let par = Par::Seq;
        {
            let mut mem = MemBuffer::try_new(
                symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
            )
            .map_err(|_| Error::Numerical("out of memory for the Cholesky of A".into()))?;
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
            symbolic,
            l_values,
            b: b.clone(),
            w: Mat::zeros(0, 0),
        };
        this.w = this.form_w()?;
        this.check_w()?;
        Ok(this)
    }

    fn form_w(&self) -> Result<Mat<f64>> {
        let m = self.b.nrows();
        let mut w = Mat::<f64>::zeros(m, m);
        let mut x = Mat::<f64>::zeros(self.n, BLOCK.min(m));
        let mut col0 = 0;
        while col0 < m {
            let k = BLOCK.min(m - col0);
            let mut xb = x.as_mut().subcols_mut(0, k);
            xb.fill(0.0);
            for c in 0..k {
                for (j, v) in self.b.row(col0 + c) {
                    xb[(j, c)] = v;
                }
            }
            self.solve_mat_in_place(xb.as_mut());
            for i in 0..m {
                for c in 0..k {
                    w[(i, col0 + c)] = self.b.row(i).map(|(j, v)| v * xb[(j, c)]).sum();
                }
            }
            col0 += k;
        }
        // symmetrise the rounding
        for i in 0..m {
            for j in 0..i {
                let s = 0.5 * (w[(i, j)] + w[(j, i)]);
                w[(i, j)] = s;
                w[(j, i)] = s;
            }
        }
        Ok(w)
    }

    fn check_w(&self) -> Result<()> {
        let m = self.w.nrows();
        let p = m / 2;
        let name = |i: usize| {
            if i < p {
                format!("row {} of N (node {})", i + 1, i + 1)
            } else {
                format!("row {} of T (node {})", i - p + 1, i - p + 1)
            }
        };
        // Plain Cholesky with a relative pivot test: pivot² ≤ 1e-12 W_ii means the row of
        // B is (numerically) a combination of the previous ones.
        let mut l = self.w.clone();
        for j in 0..m {
            let wjj = self.w[(j, j)];
            if wjj <= 0.0 {
                return Err(Error::RankDeficient(format!("{} is zero", name(j))));
            }
            let mut d = l[(j, j)];
            for k in 0..j {
                d -= l[(j, k)] * l[(j, k)];
            }
            if d <= 1e-12 * wjj {
                return Err(Error::RankDeficient(format!(
                    "{} depends linearly on the rows before it (relative pivot {:e})",
                    name(j),
                    d / wjj
                )));
            }
            let djj = d.sqrt();
            l[(j, j)] = djj;
            for i in j + 1..m {
                let mut s = l[(i, j)];
                for k in 0..j {
                    s -= l[(i, k)] * l[(j, k)];
                }
                l[(i, j)] = s / djj;
            }
        }
        Ok(())
    }

    /// Number of dofs `n`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// `W = B A⁻¹ Bᵀ` (2p×2p; rows/cols `0..p` normal, `p..2p` tangential).
    pub fn w(&self) -> MatRef<'_, f64> {
        self.w.as_ref()
    }

    /// `B = [N; T]`.
    pub fn b(&self) -> &CsrMatrix {
        &self.b
    }

    /// The default augmentation parameter `2p / trace(W)` (force per length).
    pub fn default_r(&self) -> f64 {
        let m = self.w.nrows();
        let tr: f64 = (0..m).map(|i| self.w[(i, i)]).sum();
        m as f64 / tr
    }

    /// Solves `A X = X` in place for every column of `x` (n rows).
    pub fn solve_mat_in_place(&self, x: MatMut<'_, f64>) {
        let par = Par::Seq;
        let k = x.ncols();
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(k, par));
        LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            x,
            par,
            MemStack::new(&mut mem),
        );
    }

    /// Solves `A x = x` in place (x has n entries).
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let n = x.len();
        let mat = faer::MatMut::from_column_major_slice_mut(x, n, 1);
        self.solve_mat_in_place(mat);
    }

    /// `q = B A⁻¹ f` (2p entries) for a load vector `f` (n entries).
    pub fn condense(&self, f: &[f64]) -> Vec<f64> {
        let mut x = f.to_vec();
        self.solve_in_place(&mut x);
        let mut q = vec![0.0; self.b.nrows()];
        self.b.mul_vec(&x, &mut q);
        q
    }

    /// The displacement `u = A⁻¹ (f + Bᵀ λ)` (one back-solve).
    pub fn displacement(&self, f: &[f64], lambda: &[f64]) -> Vec<f64> {
        let mut x = f.to_vec();
        self.b.mul_t_vec_add(lambda, &mut x);
        self.solve_in_place(&mut x);
        x
    }
}
