//! Smooth pieces (SPEC §3–4): piece equations, guards, tangents and orientation.
//!
//! Everything here works in the condensed variables `λ = (λν, λt) ∈ R^{2p}` and α, with
//! `d = q(α) + W λ − (g, 0)`. Both the piece equations and the guards of a node are
//! *linear forms* in `(λ, d)`: `Σ a_j λ_j + Σ b_j d_j`. Substituting `d` gives rows over
//! `(λ, α)`:
//!
//! ```text
//! row_λ = a + bᵀ W,   row_α = bᵀ q'(α),   constant = bᵀ (q(α) − (g, 0)) − row_α α
//! ```
//!
//! so a piece `S` is the solution set of `J_S (λ, α) = const`, `J_S ∈ R^{2p×(2p+1)}`, with
//! the seed's rows: `r dν` for a contact node and `λν` for an open one; `r dt` for stick,
//! `λt ∓ F λν` for slip±, `λt` for open. Guards are scaled to force units: displacement
//! guards are multiplied by the problem's default `r` (which depends on the data only), so
//! that tolerances and the reported geometry never depend on the user's `r`.

use faer::{Mat, MatRef};

use crate::class::Class;
use crate::problem::Problem;

/// One term `coef · x[index]` of a linear form (a zero `coef` is an absent term).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Term {
    pub index: usize,
    pub coef: f64,
}

impl Term {
    const NONE: Term = Term {
        index: 0,
        coef: 0.0,
    };
}

/// A linear form `Σ a_j λ_j + b d_k` with at most two λ terms and one d term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LinForm {
    /// The λ terms.
    pub lam: [Term; 2],
    /// The displacement-gap term (d = q + Wλ − (g, 0)).
    pub disp: Term,
}

impl LinForm {
    fn lam(i: usize, c: f64) -> Self {
        Self {
            lam: [Term { index: i, coef: c }, Term::NONE],
            disp: Term::NONE,
        }
    }
    fn lam2(i: usize, c: f64, j: usize, e: f64) -> Self {
        Self {
            lam: [Term { index: i, coef: c }, Term { index: j, coef: e }],
            disp: Term::NONE,
        }
    }
    fn disp(i: usize, c: f64) -> Self {
        Self {
            lam: [Term::NONE, Term::NONE],
            disp: Term { index: i, coef: c },
        }
    }
    /// Value at `(λ, d)`; also the derivative along `(λ̇, ḋ)` (the forms are homogeneous).
    pub fn eval(&self, lam: &[f64], d: &[f64]) -> f64 {
        let [a0, a1] = self.lam;
        a0.coef * lam[a0.index] + a1.coef * lam[a1.index] + self.disp.coef * d[self.disp.index]
    }
    /// Row over `(λ, α)` (length m + 1) given W and `q'`.
    pub fn row(&self, w: MatRef<'_, f64>, dq: &[f64], out: &mut [f64]) {
        let m = w.nrows();
        out.iter_mut().for_each(|x| *x = 0.0);
        for t in &self.lam {
            out[t.index] += t.coef;
        }
        let Term { index: j, coef: c } = self.disp;
        if c != 0.0 {
            // Row j of the symmetric W, read as its (contiguous) column j.
            let col = w.col(j);
            for k in 0..m {
                out[k] += c * col[k];
            }
            out[m] = c * dq[j];
        }
    }
}

/// The inequalities that hold strictly inside a piece, as "value > 0".
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum GuardKind {
    /// Open: `−dν > 0`.
    Gap,
    /// Contact: `−λν > 0`.
    Compress,
    /// Stick: `λt − F λν > 0` (reaching 0: slip+).
    ConeUpper,
    /// Stick: `−F λν − λt > 0` (reaching 0: slip−).
    ConeLower,
    /// Slip+: `dt > 0`.
    SlipPos,
    /// Slip−: `−dt > 0`.
    SlipNeg,
}

/// A guard of one node.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct Guard {
    pub node: usize,
    pub kind: GuardKind,
}

/// The guards of a class.
pub(crate) fn guard_kinds(c: Class) -> &'static [GuardKind] {
    use GuardKind::*;
    match c {
        Class::Open => &[Gap],
        Class::Stick => &[Compress, ConeUpper, ConeLower],
        Class::SlipPlus => &[Compress, SlipPos],
        Class::SlipMinus => &[Compress, SlipNeg],
    }
}

/// Problem constants the forms need.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PieceConstants<'a> {
    pub p: usize,
    pub friction: &'a [f64],
    /// The user's r (equation rows).
    pub r: f64,
    /// The default r (guard scaling).
    pub r0: f64,
}

impl<'a> PieceConstants<'a> {
    pub fn of(problem: &'a Problem) -> Self {
        Self {
            p: problem.p(),
            friction: problem.friction_equilibrated(),
            r: problem.r(),
            r0: problem.default_r(),
        }
    }

    /// Whether node `i` is frictionless (F = 0): its stick region is empty, and its S+ and
    /// S− have the same equations (dν = 0, λt = 0).
    pub fn frictionless(&self, i: usize) -> bool {
        self.friction[i] == 0.0
    }

    /// Whether `g` is the slip guard (dt's sign) of a [frictionless](Self::frictionless)
    /// node: the guard's side names the class and constrains nothing.
    pub fn label_only(&self, g: Guard) -> bool {
        matches!(g.kind, GuardKind::SlipPos | GuardKind::SlipNeg) && self.frictionless(g.node)
    }

    /// The guard as a linear form in force units.
    pub fn guard_form(&self, g: Guard) -> LinForm {
        let (i, p, f, r0) = (g.node, self.p, self.friction[g.node], self.r0);
        match g.kind {
            GuardKind::Gap => LinForm::disp(i, -r0),
            GuardKind::Compress => LinForm::lam(i, -1.0),
            GuardKind::ConeUpper => LinForm::lam2(p + i, 1.0, i, -f),
            GuardKind::ConeLower => LinForm::lam2(p + i, -1.0, i, -f),
            GuardKind::SlipPos => LinForm::disp(p + i, r0),
            GuardKind::SlipNeg => LinForm::disp(p + i, -r0),
        }
    }

    /// The two piece equations of node `i` in class `c`: (ν-row, t-row), the seed's rows.
    pub fn equations(&self, i: usize, c: Class) -> [LinForm; 2] {
        let (p, f, r) = (self.p, self.friction[i], self.r);
        let nu = match c {
            Class::Open => LinForm::lam(i, 1.0),
            _ => LinForm::disp(i, r),
        };
        let t = match c {
            Class::Open => LinForm::lam(p + i, 1.0),
            Class::Stick => LinForm::disp(p + i, r),
            Class::SlipPlus => LinForm::lam2(p + i, 1.0, i, -f),
            Class::SlipMinus => LinForm::lam2(p + i, 1.0, i, f),
        };
        [nu, t]
    }

    /// The rows of `M_S` for `classes` as linear forms: the ν-rows of nodes 0..p, then
    /// their t-rows (the order of λ).
    pub fn rows(&self, classes: &[Class]) -> Vec<LinForm> {
        let eqs: Vec<_> = (0..self.p).map(|i| self.equations(i, classes[i])).collect();
        eqs.iter()
            .map(|e| e[0])
            .chain(eqs.iter().map(|e| e[1]))
            .collect()
    }

    /// Makes `lam` satisfy exactly the local equations of node classes `a` and `b` (a
    /// point on both pieces, e.g. a transition point): `λ = 0` where either class is
    /// open, `λt = ±F λν` where a class slips (the guard that a stick–slip transition
    /// crosses). Those equations involve no W, so a solve meets them only to rounding;
    /// at a point where every force vanishes, that rounding is the whole force. Nodes
    /// slipping one way in `a` and the other in `b` are left as they are.
    pub fn satisfy_local(&self, a: &[Class], b: &[Class], lam: &mut [f64]) {
        let p = self.p;
        for i in 0..p {
            let slip = |c: Class| match c {
                Class::SlipPlus => Some(self.friction[i]),
                Class::SlipMinus => Some(-self.friction[i]),
                _ => None,
            };
            if a[i] == Class::Open || b[i] == Class::Open {
                lam[i] = 0.0;
                lam[p + i] = 0.0;
            } else if let Some(s) = slip(a[i]).or(slip(b[i]))
                && slip(a[i]).unwrap_or(s) == slip(b[i]).unwrap_or(s)
            {
                lam[p + i] = s * lam[i];
            }
        }
    }

    /// The constant part of the piece equations at fixed α: `M_S λ = rhs` with
    /// `rhs = −bᵀ (q − g)` row by row (also gives `M_S λ' = −bᵀ q'` when passed `q'`).
    pub fn piece_rhs(&self, classes: &[Class], qg: &[f64]) -> Vec<f64> {
        let mut rhs = vec![0.0; 2 * self.p];
        for (i, &c) in classes.iter().enumerate() {
            let [nu, t] = self.equations(i, c);
            rhs[i] = -nu.disp.coef * qg[nu.disp.index];
            rhs[self.p + i] = -t.disp.coef * qg[t.disp.index];
        }
        rhs
    }

    /// The square part `M_S = ∂H/∂λ` of the piece Jacobian.
    pub fn piece_matrix(&self, w: MatRef<'_, f64>, classes: &[Class]) -> Mat<f64> {
        let m = 2 * self.p;
        let zeros = vec![0.0; m];
        let (j, _) = self.jacobian(w, classes, &zeros, &zeros, 0.0);
        j.as_ref().subcols(0, m).to_owned()
    }

    /// All guards of a class vector.
    pub fn guards(&self, classes: &[Class]) -> Vec<Guard> {
        classes
            .iter()
            .enumerate()
            .flat_map(|(node, &c)| guard_kinds(c).iter().map(move |&kind| Guard { node, kind }))
            .collect()
    }

    /// The right-hand side of [`Self::jacobian`] alone (O(m), no W needed).
    pub fn jacobian_rhs(
        &self,
        classes: &[Class],
        q_minus_g: &[f64],
        dq: &[f64],
        alpha: f64,
    ) -> Vec<f64> {
        let mut rhs = vec![0.0; 2 * self.p];
        for (i, &c) in classes.iter().enumerate() {
            for (k, form) in self.equations(i, c).iter().enumerate() {
                let Term {
                    index: bj,
                    coef: bc,
                } = form.disp;
                rhs[if k == 0 { i } else { self.p + i }] =
                    -(bc * q_minus_g[bj]) + bc * dq[bj] * alpha;
            }
        }
        rhs
    }

    /// The piece Jacobian `J_S` (m × (m+1)) at `q'` and the constant so that the piece is
    /// `J_S (λ, α) = rhs` at the current α (rhs computed from `q(α)` and α).
    pub fn jacobian(
        &self,
        w: MatRef<'_, f64>,
        classes: &[Class],
        q_minus_g: &[f64],
        dq: &[f64],
        alpha: f64,
    ) -> (Mat<f64>, Vec<f64>) {
        let m = 2 * self.p;
        let mut j = Mat::<f64>::zeros(m, m + 1);
        let mut rhs = vec![0.0; m];
        let mut row = vec![0.0; m + 1];
        for (i, &c) in classes.iter().enumerate() {
            let eqs = self.equations(i, c);
            for (k, form) in eqs.iter().enumerate() {
                let r_idx = if k == 0 { i } else { self.p + i };
                form.row(w, dq, &mut row);
                for (col, &v) in row.iter().enumerate() {
                    j[(r_idx, col)] = v;
                }
                // J (λ, α) + bᵀ(q − g) − row_α α = 0
                let Term {
                    index: bj,
                    coef: bc,
                } = form.disp;
                rhs[r_idx] = -(bc * q_minus_g[bj]) + row[m] * alpha;
            }
        }
        (j, rhs)
    }
}

/// `d = q − (g, 0) + W λ` (one product with the symmetric W, [`crate::dense::mat_mul`]).
pub(crate) fn displacement_gaps(w: MatRef<'_, f64>, q_minus_g: &[f64], lam: &[f64]) -> Vec<f64> {
    let mut d = crate::dense::mat_mul(w, &[lam]).pop().expect("one column");
    for (di, qi) in d.iter_mut().zip(q_minus_g) {
        *di += qi;
    }
    d
}

/// `q(α) − (g, 0)`.
pub(crate) fn shift_gap(q: &[f64], gap: &[f64]) -> Vec<f64> {
    let mut v = q.to_vec();
    for (vi, gi) in v.iter_mut().zip(gap) {
        *vi -= gi;
    }
    v
}

/// Result of an LU with partial pivoting: solves and the sign of the determinant.
///
/// [`Self::reduced`] first eliminates the matrix's *local* rows (a piece matrix's rows of
/// open nodes, `λ = 0`, and the t-rows of slipping nodes, `λt ∓ F λν = 0`: a nonzero
/// diagonal and nonzeros only in the columns of kept rows), so only the Schur complement
/// on the other rows is factorised: O(m_r³) with m_r = 2·stick + slip instead of O(m³),
/// and a solve reads m_r·m numbers instead of m².
pub(crate) struct DenseLu {
    /// LU of the matrix, or of its Schur complement on the kept rows.
    lu: crate::dense::PartialLu,
    red: Option<Reduction>,
    /// Sign of the determinant (0 when a pivot is exactly 0).
    pub det_sign: i8,
    /// min |pivot| / max |pivot| over the LU's `U_ii` (and the eliminated rows'
    /// diagonals): a cheap singularity indicator.
    pub pivot_ratio: f64,
}

/// The local rows L eliminated ahead of the LU: with D the other (kept) rows, and the
/// rows and columns of one matrix split alike, `M_LL` is diagonal, so
/// `S = M_DD − M_DL M_LL⁻¹ M_LD`, `det M = det S · Π M_ll` (a symmetric permutation
/// keeps the determinant), and `M x = b` is solved by
/// `S x_D = b_D − M_DL M_LL⁻¹ b_L`, `x_L = M_LL⁻¹ (b_L − M_LD x_D)`.
struct Reduction {
    /// The kept rows D, increasing.
    kept: Vec<usize>,
    /// The local rows L, increasing, with their diagonal entries.
    local: Vec<usize>,
    diag: Vec<f64>,
    /// `M_DL`, |D| × |L|.
    dl: Mat<f64>,
    /// The nonzeros of `M_LL⁻¹ M_LD`: (position in `local`, position in `kept`, value).
    ld: Vec<(usize, usize, f64)>,
}

impl DenseLu {
    pub fn new(a: MatRef<'_, f64>) -> Self {
        Self::from_lu(crate::dense::partial_piv_lu(a.to_owned()), None)
    }

    /// The LU of the matrix whose row `r` is the linear form `rows[r]` over λ (W
    /// symmetric, m × m), eliminating first its local rows: those without a
    /// displacement term, with a nonzero diagonal, and whose other terms lie in columns
    /// of rows not eliminated (the other rows are kept). The solutions are those of the
    /// same matrix; the pivots differ from a plain LU's, so [`Self::pivot_ratio`] is an
    /// indicator of the same kind. The matrix itself is never formed: O(m_r m) reads of W.
    pub fn reduced(w: MatRef<'_, f64>, rows: &[LinForm]) -> Self {
        let m = rows.len();
        let diag_of = |r: usize| -> f64 {
            let f = &rows[r];
            f.lam.iter().filter(|t| t.index == r).map(|t| t.coef).sum()
        };
        let cand: Vec<bool> = (0..m)
            .map(|r| rows[r].disp.coef == 0.0 && diag_of(r) != 0.0 && diag_of(r).is_finite())
            .collect();
        // Candidates whose other terms all lie in non-candidate columns. Dropping a
        // candidate that fails keeps the others valid (their columns only leave L).
        let is_local: Vec<bool> = (0..m)
            .map(|r| {
                cand[r]
                    && rows[r]
                        .lam
                        .iter()
                        .all(|t| t.coef == 0.0 || t.index == r || !cand[t.index])
            })
            .collect();
        let local: Vec<usize> = (0..m).filter(|&r| is_local[r]).collect();
        let kept: Vec<usize> = (0..m).filter(|&r| !is_local[r]).collect();
        // Position of each row in `kept` or in `local`.
        let mut pos = vec![0usize; m];
        for (k, &r) in kept.iter().enumerate() {
            pos[r] = k;
        }
        for (k, &r) in local.iter().enumerate() {
            pos[r] = k;
        }
        // Kept rows' displacement terms, W read by (contiguous, W symmetric) columns: a
        // gather per column over slices (indexing the matrices entry by entry cost as
        // much as the LU of the reduced matrix on a 960-row piece).
        let disp: Vec<(usize, f64)> = kept
            .iter()
            .map(|&r| (rows[r].disp.index, rows[r].disp.coef))
            .collect();
        let block = |cols: &[usize]| -> Mat<f64> {
            let mut out = Mat::<f64>::zeros(kept.len(), cols.len());
            for (j, &c) in cols.iter().enumerate() {
                let dst = out
                    .col_mut(j)
                    .try_as_col_major_mut()
                    .expect("an owned matrix's column is contiguous")
                    .as_slice_mut();
                // (W's columns are contiguous, as `dense::mat_mul` takes them)
                let col = w.col(c).try_as_col_major().expect("contiguous column");
                let col = col.as_slice();
                for (o, &(k, a)) in dst.iter_mut().zip(&disp).filter(|(_, t)| t.1 != 0.0) {
                    *o = a * col[k];
                }
            }
            out
        };
        let mut s = block(&kept);
        let mut dl = block(&local);
        for (i, &r) in kept.iter().enumerate() {
            for t in rows[r].lam.iter().filter(|t| t.coef != 0.0) {
                if is_local[t.index] {
                    dl[(i, pos[t.index])] += t.coef;
                } else {
                    s[(i, pos[t.index])] += t.coef;
                }
            }
        }
        let diag: Vec<f64> = local.iter().map(|&r| diag_of(r)).collect();
        let mut ld = Vec::new();
        for (l, &r) in local.iter().enumerate() {
            for t in rows[r].lam.iter().filter(|t| t.coef != 0.0 && t.index != r) {
                ld.push((l, pos[t.index], t.coef / diag[l]));
            }
        }
        for &(l, d, v) in &ld {
            let x = dl.col(l).try_as_col_major().expect("contiguous column");
            let y = s
                .col_mut(d)
                .try_as_col_major_mut()
                .expect("contiguous column");
            crate::dense::axpy(y.as_slice_mut(), -v, x.as_slice());
        }
        let red = Reduction {
            kept,
            local,
            diag,
            dl,
            ld,
        };
        Self::from_lu(crate::dense::partial_piv_lu(s), Some(red))
    }

    /// Sign and pivot ratio from the LU's pivots and permutation with the eliminated
    /// rows' diagonals.
    fn from_lu(lu: crate::dense::PartialLu, red: Option<Reduction>) -> Self {
        let diag = red.iter().flat_map(|r| r.diag.iter().copied());
        let u = &lu.lu;
        let n = u.nrows();
        let mut sign: i8 = perm_parity(&lu.row_fwd);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for v in (0..n).map(|i| u[(i, i)]).chain(diag) {
            if v < 0.0 {
                sign = -sign;
            } else if v == 0.0 || v.is_nan() {
                sign = 0;
            }
            lo = lo.min(v.abs());
            hi = hi.max(v.abs());
        }
        let pivot_ratio = if hi == 0.0 { 0.0 } else { lo / hi };
        Self {
            lu,
            red,
            det_sign: sign,
            pivot_ratio,
        }
    }

    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = b.len();
        let mut x = b.to_vec();
        let xm = faer::MatMut::from_column_major_slice_mut(&mut x, n, 1);
        self.solve_mat(xm);
        x
    }

    /// Solves for every column of `b` in place.
    pub fn solve_mat(&self, mut b: faer::MatMut<'_, f64>) {
        let Some(r) = &self.red else {
            self.lu.solve_in_place(b);
            return;
        };
        let k = b.ncols();
        let zl = Mat::from_fn(r.local.len(), k, |l, j| b[(r.local[l], j)] / r.diag[l]);
        let mut xd = Mat::from_fn(r.kept.len(), k, |i, j| b[(r.kept[i], j)]);
        // A piece's right-hand sides are zero in the local rows (λ = 0, λt ∓ F λν = 0),
        // and a node's unit columns nonzero in one: only the columns of M_DL that meet a
        // nonzero are read.
        let nz: Vec<usize> = (0..r.local.len())
            .filter(|&l| (0..k).any(|j| zl[(l, j)] != 0.0))
            .collect();
        if 4 * nz.len() >= r.local.len() {
            crate::dense::mat_mul_sub(xd.as_mut(), r.dl.as_ref(), zl.as_ref());
        } else {
            for &l in &nz {
                let col = r.dl.col(l).try_as_col_major().expect("contiguous");
                for j in 0..k {
                    let f = zl[(l, j)];
                    if f != 0.0 {
                        let out = xd.col_mut(j).try_as_col_major_mut().expect("contiguous");
                        crate::dense::axpy(out.as_slice_mut(), -f, col.as_slice());
                    }
                }
            }
        }
        self.lu.solve_in_place(xd.as_mut());
        for j in 0..k {
            for (l, &row) in r.local.iter().enumerate() {
                b[(row, j)] = zl[(l, j)];
            }
            for &(l, d, v) in &r.ld {
                b[(r.local[l], j)] -= v * xd[(d, j)];
            }
            for (i, &row) in r.kept.iter().enumerate() {
                b[(row, j)] = xd[(i, j)];
            }
        }
    }

    /// The order of the matrix.
    pub fn n(&self) -> usize {
        self.lu.lu.nrows() + self.red.as_ref().map_or(0, |r| r.local.len())
    }
}

fn perm_parity(fwd: &[usize]) -> i8 {
    let n = fwd.len();
    let mut seen = vec![false; n];
    let mut sign = 1i8;
    for s in 0..n {
        if seen[s] {
            continue;
        }
        let mut len = 0;
        let mut k = s;
        while !seen[k] {
            seen[k] = true;
            k = fwd[k];
            len += 1;
        }
        if len % 2 == 0 {
            sign = -sign;
        }
    }
    sign
}

/// The full-pivoting LU of a piece Jacobian `J ∈ R^{m×(m+1)}` (`P J Qᵀ = L U`), with the
/// tangent and its orientation. One factorisation gives all three:
///
/// * `t`: the kernel vector, from `U y = 0` with the free (last pivoted) variable 1;
/// * `orientation = sign det [J; tᵀ] = sign(P) sign(Q) Π sign(U_ii)`, because
///   `det [U; (Q t)ᵀ] = det U₁ (1 + ‖y₁‖²)/‖y‖` for `Q t = y/‖y‖` (SPEC §4: the sign is
///   taken from the pivots and permutation parities, never from the determinant's value);
/// * particular solutions of `J x = b` (free variable 0) for the exact event points.
pub(crate) struct PieceLu {
    l: Mat<f64>,
    u: Mat<f64>,
    p_fwd: Vec<usize>,
    q_fwd: Vec<usize>,
    /// Unit kernel vector.
    pub t: Vec<f64>,
    /// `sign det [J; tᵀ]` for this `t`.
    pub orientation: i8,
}

impl PieceLu {
    /// Factorises `J` (m × (m+1)). `None` when its rank is below m (the last pivot is below
    /// `1e-13` of the first): the piece is not a curve there.
    pub fn new(j: MatRef<'_, f64>) -> Option<Self> {
        let m = j.nrows();
        let crate::dense::Lu {
            l,
            u,
            row_fwd: p_fwd,
            col_fwd: q_fwd,
        } = crate::dense::full_piv_lu(j);
        let u00 = if m > 0 { u[(0, 0)].abs() } else { 1.0 };
        if m > 0 && u[(m - 1, m - 1)].abs() <= 1e-13 * u00 {
            return None;
        }
        let mut y = vec![0.0; m + 1];
        y[m] = 1.0;
        back_substitute(u.as_ref(), &mut y);
        let mut t = vec![0.0; m + 1];
        for (i, &f) in q_fwd.iter().enumerate() {
            t[f] = y[i];
        }
        let norm = t.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return None;
        }
        t.iter_mut().for_each(|v| *v /= norm);
        let mut orientation = perm_parity(&p_fwd) * perm_parity(&q_fwd);
        for i in 0..m {
            if u[(i, i)] < 0.0 {
                orientation = -orientation;
            }
        }
        Some(Self {
            l,
            u,
            p_fwd,
            q_fwd,
            t,
            orientation,
        })
    }

    /// A solution of `J x = b` (the one whose free pivoted variable is 0).
    pub fn particular(&self, b: &[f64]) -> Vec<f64> {
        let m = self.u.nrows();
        // L z = P b (unit lower triangular)
        let mut z: Vec<f64> = self.p_fwd.iter().map(|&k| b[k]).collect();
        for i in 0..m {
            let mut s = z[i];
            for k in 0..i {
                s -= self.l[(i, k)] * z[k];
            }
            z[i] = s;
        }
        let mut y = z;
        y.push(0.0);
        // U₁ y₁ = z − u₂ y_m with y_m = 0
        for i in (0..m).rev() {
            let mut s = y[i];
            for k in i + 1..m {
                s -= self.u[(i, k)] * y[k];
            }
            y[i] = s / self.u[(i, i)];
        }
        let mut x = vec![0.0; m + 1];
        for (i, &f) in self.q_fwd.iter().enumerate() {
            x[f] = y[i];
        }
        x
    }
}

/// `U y = 0` for the first m entries of y given `y[m]` (U is m × (m+1), upper trapezoidal).
fn back_substitute(u: MatRef<'_, f64>, y: &mut [f64]) {
    let m = u.nrows();
    for i in (0..m).rev() {
        let mut s = u[(i, m)] * y[m];
        for k in i + 1..m {
            s += u[(i, k)] * y[k];
        }
        y[i] = -s / u[(i, i)];
    }
}

/// A unit vector spanning `ker J` (see [`PieceLu`]).
#[cfg(test)]
pub(crate) fn kernel_vector(j: MatRef<'_, f64>) -> Option<Vec<f64>> {
    PieceLu::new(j).map(|p| p.t)
}

/// `sign det [J; tᵀ]` by an LU of the bordered matrix (a cross-check of [`PieceLu`]).
#[cfg(test)]
pub(crate) fn orientation(j: MatRef<'_, f64>, t: &[f64]) -> i8 {
    let m = j.nrows();
    let mut b = Mat::<f64>::zeros(m + 1, m + 1);
    for r in 0..m {
        for c in 0..=m {
            b[(r, c)] = j[(r, c)];
        }
    }
    for c in 0..=m {
        b[(m, c)] = t[c];
    }
    DenseLu::new(b.as_ref()).det_sign
}

/// The relative residual of the seed's H at `(u, λ, α)`:
///
/// ```text
/// H1 = A u − f(α) − Nᵀ λν − Tᵀ λt
/// H2 = λν − min(λν − r (N u − g), 0)
/// H3 = λt − P_[−b, b](λt − r T u),   b = max(−F λν, 0)
/// residual = max( ‖H1‖∞ / max(‖|A||u|‖∞, ‖f‖∞, ‖|Bᵀ||λ|‖∞),
///                 max_i max(|H2_i|, |H3_i|) / max(s_i, 1e-3 S) )
/// s_i = max(|λν_i|, |λt_i|, r (|B||u|)_i, r (|B||u|)_{p+i}, r |g_i|,
///           r (|W| 1)_i ‖λ‖∞, r (|W| 1)_{p+i} ‖λ‖∞)
/// S   = the largest of every term above (and of H1's scale)
/// ```
///
/// Each equation is measured against the magnitude of its own terms, taken entry by
/// entry (`|A||u|` rather than `A u`), as in a backward error: what rounding errors are
/// proportional to, independent of the units of u and f. H2, H3 are measured node by
/// node, so that a node far from the foundation (a large gap) or with large forces does
/// not hide another node's error; a node whose terms are all tiny is measured against a
/// thousandth of the point's scale S. The `(|W| 1) ‖λ‖∞` terms bound the terms that
/// `B u = q + W λ` is made of: at a contact node `B u` vanishes by cancellation inside u
/// (`|B||u|` is 0 there), while its rounding is that of `W λ`, which H2 and H3 multiply
/// by r.
///
/// Without A (a host's solve, or condensed input) H1 is not evaluated. With a host's
/// solve `B u` comes from its u; for condensed input (u empty, `f` the condensed load q)
/// `B u = q + W λ`, with `|q| + |W||λ|` as its terms' magnitude.
pub fn residual(problem: &Problem, u: &[f64], lam: &[f64], f: &[f64]) -> f64 {
    residuals(problem, &[(u, lam, f)], &mut Vec::new())[0]
}

/// [`residual`] of several points `(u, λ, f)` at once (all with u, or all without): one
/// pass over A for all of them, which on large meshes costs little more than one.
/// `scratch` is working memory (n × the number of points), kept by the caller between
/// calls.
pub fn residuals(
    problem: &Problem,
    points: &[(&[f64], &[f64], &[f64])],
    scratch: &mut Vec<f64>,
) -> Vec<f64> {
    let n = problem.n();
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    let inf = crate::dense::inf_norm;
    // Terms near the end of the range of doubles (a load of 1e308, u of 1e308) would
    // overflow in the sums below: u, f, λ and g of each point are multiplied by a power of
    // two σ first, which does not change H / scale (H is homogeneous of degree one in
    // them).
    let sigmas: Vec<i32> = points
        .iter()
        .map(|(u, lam, f)| {
            let big = inf(u)
                .max(inf(f))
                .max(inf(lam))
                .max(inf(problem.gap_equilibrated()));
            if big > 0.0 && !(2f64.powi(-500)..=2f64.powi(500)).contains(&big) {
                -(big.log2().ceil() as i32)
            } else {
                0
            }
        })
        .collect();
    let scaled = |v: &[f64], k: i32| -> Vec<f64> {
        v.iter().map(|&x| crate::problem::mul_pow2(x, k)).collect()
    };
    let ok: Vec<bool> = points
        .iter()
        .map(|(u, lam, f)| finite(u) && finite(lam) && finite(f))
        .collect();
    // H1 of every point with one pass over A: (|H1|∞, scale) per point.
    let mut h1 = vec![(0.0f64, 1e-300f64); points.len()];
    if let Some(a) = problem.a()
        && points.iter().all(|(u, _, _)| u.len() == n)
    {
        // H1 of the problem as factorised, 2^(k/2) (A u − f − Bᵀ λ) with A scaled by 2^k
        // (k = a_scale_log2, 0 for ordinary data): every product below is between
        // numbers of the range that was factorised (exact scalings by powers of two).
        let hs = crate::problem::mul_pow2(1.0, problem.a_scale_log2() / 2);
        let k = points.len();
        // u of all points interleaved (row j holds u_c[j] for every point c), so that the
        // pass over A reads each point's entries next to each other; this copy and the
        // pass go by tiles of rows, so that the point-by-point reads and writes stay in
        // cache.
        const TILE: usize = 64;
        scratch.resize(n * k, 0.0);
        let ut = &mut scratch[..n * k];
        for jb in (0..n).step_by(TILE) {
            let je = (jb + TILE).min(n);
            for (c, &(u, _, _)) in points.iter().enumerate() {
                for j in jb..je {
                    ut[j * k + c] = crate::problem::mul_pow2(u[j], sigmas[c]) / hs;
                }
            }
        }
        let lams: Vec<Vec<f64>> = points
            .iter()
            .zip(&sigmas)
            .map(|((_, lam, _), &sg)| scaled(lam, sg))
            .collect();
        let bt = problem.b().transpose();
        let mut au = vec![0.0; TILE * k];
        let mut au_abs = vec![0.0; TILE * k];
        for ib in (0..n).step_by(TILE) {
            let ie = (ib + TILE).min(n);
            faer::traits::pulp::Arch::new().dispatch(TileProducts {
                a,
                rows: ib..ie,
                ut,
                k,
                au: &mut au,
                au_abs: &mut au_abs,
            });
            for (c, &(_, _, f)) in points.iter().enumerate() {
                let (h, sc) = &mut h1[c];
                for i in ib..ie {
                    let (mut btl, mut btl_abs) = (0.0, 0.0);
                    for (l, v) in bt.row(i) {
                        let x = hs * v * lams[c][l];
                        btl += x;
                        btl_abs += x.abs();
                    }
                    let fi = hs * crate::problem::mul_pow2(f[i], sigmas[c]);
                    let t = (i - ib) * k + c;
                    *h = h.max((au[t] - fi - btl).abs());
                    *sc = sc.max(au_abs[t]).max(fi.abs()).max(btl_abs);
                }
            }
        }
    }
    points
        .iter()
        .enumerate()
        .map(|(c, &(u, lam, f))| {
            if !ok[c] {
                return f64::INFINITY;
            }
            let sg = sigmas[c];
            let scaled_copies;
            let (u, lam, f) = if sg == 0 {
                (u, lam, f)
            } else {
                scaled_copies = [scaled(u, sg), scaled(lam, sg), scaled(f, sg)];
                let [u, lam, f] = &scaled_copies;
                (&u[..], &lam[..], &f[..])
            };
            let gap = scaled(problem.gap_equilibrated(), sg);
            node_residual(problem, u, lam, f, &gap, h1[c])
        })
        .collect()
}

/// `A u` and `|A||u|` of rows `rows` for k interleaved points (`ut`, row j holding the
/// points' u_j), into `au`, `au_abs` (k per row, from the first row of `rows`): the hot
/// loop of [`residuals`], compiled for the machine's vector instructions by the dispatch.
struct TileProducts<'a> {
    a: &'a crate::problem::CsrMatrix,
    rows: std::ops::Range<usize>,
    ut: &'a [f64],
    k: usize,
    au: &'a mut [f64],
    au_abs: &'a mut [f64],
}

impl faer::traits::pulp::WithSimd for TileProducts<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: faer::traits::pulp::Simd>(self, _: S) {
        let k = self.k;
        self.au.fill(0.0);
        self.au_abs.fill(0.0);
        let first = self.rows.start;
        for i in self.rows {
            let t = (i - first) * k;
            let (s, sa) = (&mut self.au[t..t + k], &mut self.au_abs[t..t + k]);
            for (j, v) in self.a.row(i) {
                let row = &self.ut[j * k..(j + 1) * k];
                for ((s, sa), &x) in s.iter_mut().zip(sa.iter_mut()).zip(row) {
                    let x = v * x;
                    *s += x;
                    *sa += x.abs();
                }
            }
        }
    }
}

/// The residual of one point (scaled by its σ) from its H1 part `(|H1|∞, scale)`: H2, H3
/// node by node (see [`residual`]).
fn node_residual(
    problem: &Problem,
    u: &[f64],
    lam: &[f64],
    f: &[f64],
    gap: &[f64],
    (h, scale): (f64, f64),
) -> f64 {
    let (p, r) = (problem.p(), problem.r());
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    let mut bu = vec![0.0; 2 * p];
    let mut bu_abs = vec![0.0; 2 * p];
    if u.is_empty() {
        // Condensed: B u = q + W λ.
        let w = problem.delassus().w();
        let q = problem
            .delassus()
            .condense(f)
            .unwrap_or_else(|_| vec![f64::NAN; 2 * p]);
        for i in 0..2 * p {
            // (condense is linear: q of the scaled load)
            bu[i] = q[i];
            bu_abs[i] = q[i].abs();
            for (j, &l) in lam.iter().enumerate() {
                bu[i] += w[(i, j)] * l;
                bu_abs[i] += (w[(i, j)] * l).abs();
            }
        }
    } else {
        for i in 0..2 * p {
            for (j, v) in problem.b().row(i) {
                bu[i] += v * u[j];
                bu_abs[i] += (v * u[j]).abs();
            }
        }
    }
    // H1 relative to its own terms; H2, H3 node by node, relative to the node's terms,
    // not below a thousandth of the point's force scale (a node far from the foundation
    // does not set the scale of the others, see the doc above).
    let h1 = if h > 0.0 { h / scale } else { 0.0 };
    let lam_max = lam.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let wrow = problem.w_row_sums();
    let mut global = scale.max(lam_max);
    for k in 0..2 * p {
        global = global.max(r * bu_abs[k]).max(r * wrow[k] * lam_max);
    }
    let mut hn = 0.0f64;
    for i in 0..p {
        let g = gap[i];
        let (ln, lt) = (lam[i], lam[p + i]);
        let h2 = ln - (ln - r * (bu[i] - g)).min(0.0);
        let b = (-problem.friction_equilibrated()[i] * ln).max(0.0);
        let h3 = lt - (lt - r * bu[p + i]).clamp(-b, b);
        let own = ln
            .abs()
            .max(lt.abs())
            .max(r * bu_abs[i])
            .max(r * bu_abs[p + i])
            .max(r * g.abs())
            .max(r * wrow[i] * lam_max)
            .max(r * wrow[p + i] * lam_max);
        let hi = h2.abs().max(h3.abs());
        if !(h2.is_finite() && h3.is_finite()) {
            return f64::INFINITY;
        }
        if hi > 0.0 {
            hn = hn.max(hi / own.max(1e-3 * global));
        }
    }
    let res = h1.max(hn);
    // (f64::max drops NaN: a NaN term shows in the sums, h or the scale)
    if res.is_finite() && scale.is_finite() && global.is_finite() && finite(&bu) {
        res
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [−1, 1) on a grid of `1/half` (xorshift64 from `seed`).
    fn uniform(seed: u64, half: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s % (2 * half)) as f64 / half as f64 - 1.0
        }
    }

    #[test]
    fn kernel_of_random_wide_matrix_is_annihilated() {
        let mut rnd = uniform(12345, 1000);
        for m in [1, 2, 5, 9] {
            let j = Mat::<f64>::from_fn(m, m + 1, |_, _| rnd());
            let plu = PieceLu::new(j.as_ref()).unwrap();
            let t = kernel_vector(j.as_ref()).unwrap();
            for r in 0..m {
                let s: f64 = (0..=m).map(|c| j[(r, c)] * t[c]).sum();
                assert!(s.abs() < 1e-13, "row {r}: {s}");
            }
            // the orientation from the pivots equals the bordered determinant's sign
            assert_eq!(plu.orientation, orientation(j.as_ref(), &t));
            let flipped: Vec<f64> = t.iter().map(|v| -v).collect();
            assert_eq!(-plu.orientation, orientation(j.as_ref(), &flipped));
            // a particular solution solves J x = b
            let b: Vec<f64> = (0..m).map(|_| rnd()).collect();
            let x = plu.particular(&b);
            for r in 0..m {
                let s: f64 = (0..=m).map(|c| j[(r, c)] * x[c]).sum();
                assert!((s - b[r]).abs() < 1e-12, "row {r}: {s} vs {}", b[r]);
            }
        }
    }

    #[test]
    fn transition_points_meet_the_local_equations_of_both_classes() {
        use Class::*;
        let friction = [0.5, 2.0, 1.0, 3.0, 0.25];
        let c = PieceConstants {
            p: 5,
            friction: &friction,
            r: 1.0,
            r0: 1.0,
        };
        // Slip+ -> open; stick -> slip+ (λt = F λν); slip- -> stick (λt = −F λν);
        // stick -> stick (untouched); slip+ -> slip− (untouched).
        let a = [SlipPlus, Stick, SlipMinus, Stick, SlipPlus];
        let b = [Open, SlipPlus, Stick, Stick, SlipMinus];
        let mut lam = vec![
            1e-17,
            -2.0,
            -1.0,
            -4.0,
            -1.0,
            3e-17,
            -4.0 + 1e-15,
            1.0,
            0.3,
            0.1,
        ];
        c.satisfy_local(&a, &b, &mut lam);
        assert_eq!(
            lam,
            vec![0.0, -2.0, -1.0, -4.0, -1.0, 0.0, -4.0, 1.0, 0.3, 0.1]
        );
    }

    #[test]
    fn determinant_sign_matches_hand_values() {
        // det [[0, 1], [1, 0]] = -1 (a swap), det [[2, 1], [1, 3]] = 5, det diag(-1, 2, 3) < 0
        let a = Mat::<f64>::from_fn(2, 2, |i, j| if i != j { 1.0 } else { 0.0 });
        assert_eq!(DenseLu::new(a.as_ref()).det_sign, -1);
        let b = Mat::<f64>::from_fn(2, 2, |i, j| [[2.0, 1.0], [1.0, 3.0]][i][j]);
        assert_eq!(DenseLu::new(b.as_ref()).det_sign, 1);
        let c = Mat::<f64>::from_fn(3, 3, |i, j| if i == j { [-1.0, 2.0, 3.0][i] } else { 0.0 });
        assert_eq!(DenseLu::new(c.as_ref()).det_sign, -1);
        // a 3-cycle permutation matrix has det +1
        let d = Mat::<f64>::from_fn(3, 3, |i, j| if j == (i + 1) % 3 { 1.0 } else { 0.0 });
        assert_eq!(DenseLu::new(d.as_ref()).det_sign, 1);
    }

    /// `det` by the permutation expansion (small orders only).
    fn leibniz_det(a: MatRef<'_, f64>) -> f64 {
        fn perms(rest: &mut Vec<usize>, cur: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
            if rest.is_empty() {
                out.push(cur.clone());
            }
            for k in 0..rest.len() {
                let v = rest.remove(k);
                cur.push(v);
                perms(rest, cur, out);
                cur.pop();
                rest.insert(k, v);
            }
        }
        let n = a.nrows();
        let mut all = Vec::new();
        perms(&mut (0..n).collect(), &mut Vec::new(), &mut all);
        all.iter()
            .map(|pm| {
                let inversions = (0..n)
                    .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
                    .filter(|&(i, j)| pm[i] > pm[j])
                    .count();
                let sign = if inversions % 2 == 0 { 1.0 } else { -1.0 };
                sign * (0..n).map(|i| a[(i, pm[i])]).product::<f64>()
            })
            .sum()
    }

    #[test]
    fn reduced_lu_solves_the_piece_matrix_and_keeps_its_determinant_sign() {
        let mut rnd = uniform(987654321, 50_000);
        let classes_all = [Class::Open, Class::Stick, Class::SlipPlus, Class::SlipMinus];
        let mut checked_det = 0;
        for trial in 0..400 {
            let p = 1 + trial % 7;
            let m = 2 * p;
            // W symmetric positive definite: G Gᵀ + shift.
            let g = Mat::<f64>::from_fn(m, m, |_, _| rnd());
            let w = Mat::<f64>::from_fn(m, m, |i, j| {
                (0..m).map(|k| g[(i, k)] * g[(j, k)]).sum::<f64>() + if i == j { 0.1 } else { 0.0 }
            });
            let friction: Vec<f64> = (0..p).map(|_| 2.5 * (rnd() + 1.0)).collect();
            let r = 10f64.powf(2.0 * rnd());
            let c = PieceConstants {
                p,
                friction: &friction,
                r,
                r0: 1.0,
            };
            let classes: Vec<Class> = (0..p)
                .map(|_| classes_all[((rnd() + 1.0) * 2.0).min(3.0) as usize])
                .collect();
            let rows = c.rows(&classes);
            let full = c.piece_matrix(w.as_ref(), &classes);
            let red = DenseLu::reduced(w.as_ref(), &rows);
            assert_eq!(red.n(), m);
            let plain = DenseLu::new(full.as_ref());
            // A dense right-hand side; then, in one solve, one zero in the rows without W
            // (a piece's) and a unit column (a node's): the sparse path of `solve_mat`.
            let b: Vec<f64> = (0..m).map(|_| rnd()).collect();
            let b_piece: Vec<f64> = (0..m)
                .map(|r| if rows[r].disp.coef == 0.0 { 0.0 } else { b[r] })
                .collect();
            let unit: Vec<f64> = (0..m)
                .map(|r| if r == trial % m { 1.0 } else { 0.0 })
                .collect();
            let mut xs = Mat::from_fn(m, 2, |i, j| [&b_piece, &unit][j][i]);
            red.solve_mat(xs.as_mut());
            let solved = [
                (&b, red.solve(&b)),
                (&b_piece, xs.col(0).iter().copied().collect()),
                (&unit, xs.col(1).iter().copied().collect()),
            ];
            for (j, (b, x)) in solved.into_iter().enumerate() {
                let scale: f64 = (0..m)
                    .map(|i| (0..m).map(|k| (full[(i, k)] * x[k]).abs()).sum::<f64>() + b[i].abs())
                    .fold(0.0, f64::max);
                for i in 0..m {
                    let res: f64 = (0..m).map(|k| full[(i, k)] * x[k]).sum::<f64>() - b[i];
                    assert!(
                        res.abs() <= 1e-11 * scale,
                        "trial {trial} col {j} row {i}: {res:e}"
                    );
                }
            }
            // The determinant's sign: the plain LU's, and the expansion's where it is
            // clearly away from zero.
            assert_eq!(red.det_sign, plain.det_sign, "trial {trial}");
            if m <= 6 {
                let det = leibniz_det(full.as_ref());
                let bound: f64 = (0..m)
                    .map(|i| (0..m).map(|j| full[(i, j)].abs()).sum::<f64>())
                    .product();
                if det.abs() > 1e-8 * bound {
                    assert_eq!(red.det_sign as f64, det.signum(), "trial {trial}");
                    checked_det += 1;
                }
            }
        }
        assert!(checked_det > 100, "{checked_det} determinants checked");
    }

    #[test]
    fn reduced_lu_keeps_coupled_or_singular_local_rows() {
        // Rows 0 and 1 are local candidates coupled to each other (both kept); row 2 has
        // no displacement term but a zero diagonal (kept); row 3 is a W row; row 4 is
        // local (eliminated), with a term in the kept column 3.
        let w = Mat::<f64>::from_fn(5, 5, |i, j| if i == j { 2.0 } else { 0.5 });
        let rows = [
            LinForm::lam2(0, 2.0, 1, 1.0),
            LinForm::lam2(1, 1.0, 0, -3.0),
            LinForm::lam2(0, 1.0, 3, 1.0),
            LinForm::disp(3, 1.5),
            LinForm::lam2(4, -1.0, 3, 2.0),
        ];
        let full = Mat::<f64>::from_fn(5, 5, |i, j| {
            let mut row = vec![0.0; 6];
            rows[i].row(w.as_ref(), &[0.0; 5], &mut row);
            row[j]
        });
        let red = DenseLu::reduced(w.as_ref(), &rows);
        assert_eq!(red.red.as_ref().map(|r| r.local.clone()), Some(vec![4]));
        let b = [1.0, -2.0, 0.5, 3.0, -1.0];
        let x = red.solve(&b);
        for i in 0..5 {
            let res: f64 = (0..5).map(|j| full[(i, j)] * x[j]).sum::<f64>() - b[i];
            assert!(res.abs() < 1e-13, "row {i}: {res:e}");
        }
        let det = leibniz_det(full.as_ref());
        assert!(det.abs() > 0.1, "{det}");
        assert_eq!(red.det_sign as f64, det.signum());
    }
}
