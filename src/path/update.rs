//! Piece matrices by updates of one factorised base (Sherman–Morrison–Woodbury).
//!
//! Consecutive pieces differ in the classes of a few nodes, and the piece matrix
//! `M_S = ∂H/∂λ` of a node's class touches only that node's two rows (ν-row `i`, t-row
//! `p + i`). So, with one base `M_0` factorised by LU (its rows of open nodes and t-rows of
//! slipping nodes eliminated first, see [`DenseLu::reduced`]: O(m_r³) with
//! m_r = 2·stick + slip ≤ m = 2p), every nearby piece
//! is `M_S = M_0 + U V` with `U = [E_1 … E_k]` (`E_j` = the two unit columns of the rows
//! that changed at the j-th update) and `V` the stacked row differences (2k × m). Then
//!
//! ```text
//! M_S⁻¹ b = x0 − Z C⁻¹ V x0,   x0 = M_0⁻¹ b,   Z = M_0⁻¹ U,   C = I + V Z   (2k × 2k)
//! det M_S = det M_0 · det C
//! ```
//!
//! Appending one update costs two solves with the base (O(m_r m)), at most 8km
//! dot-product flops for the new border of C (a row change that is sparse costs next to
//! nothing, see [`RowChange`]), and O(k²) for the bordered inverse of C; a solve costs
//! O(m_r m + km).
//! The sign of `det C` is carried exactly as the product of the signs of the 2 × 2 Schur
//! complements (the matrix determinant lemma), so orientations never come from a
//! determinant's value. When more than [`max_updates`] updates have accumulated, or when
//! a solve fails its residual check, the caller factorises a new base at the current
//! piece.
//!
//! Everything here works with the displacement rows multiplied by `r0 / r` (the rows
//! `r0 d` instead of the seed's `r d`, r0 = [`crate::problem::Problem::default_r`]): a
//! positive row scaling that changes neither solutions nor determinant signs, and keeps
//! the rows of W and the unit rows of open and slipping nodes of one size whatever r the
//! user chose.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use faer::MatRef;

use crate::class::Class;
use crate::dense::{axpy, dot, inf_norm};
use crate::piece::{DenseLu, PieceConstants};

/// Most updates kept on one base before a refactorisation: m/16 (at least 8). With k
/// updates a transition pays O(k m) for the border of C and the capacitance corrections,
/// besides its O(m²) solves, and a refactorisation (O(m³)) is paid once per K updates,
/// so the cost per transition is about R/K + c K/2, least at K = √(2R/c) ∝ m. Measured
/// on this project's machine: K ≈ m/12 at m = 960 and m/17 at m = 4000 (where the
/// updates' columns no longer stay in cache); the total is flat near the least, and m/16
/// also keeps the SMW sums short, so fewer solves need refining (half as many at
/// m = 4000 as with m/8). (Measured with the LU of the whole M_S; the reduced LU costs
/// about (m_r/m)³ of it, which moves the least to smaller K, but on the 308,160-dof mesh
/// (m = 960) m/32 and m/24 traced no faster than m/16 within this machine's noise.)
pub(crate) fn max_updates(m: usize) -> usize {
    (m / 16).max(8)
}

/// A factorised base piece matrix, shared by every update derived from it.
pub(super) struct Base {
    lu: DenseLu,
    /// `M_0⁻¹ [e_i, e_{p+i}]` for node i, computed on first use.
    z: Mutex<HashMap<usize, Arc<NodeCols>>>,
}

/// The base's solution columns of one node: `M_0⁻¹ [e_i, e_{p+i}]` (in `r0` units, see
/// the module doc).
type NodeCols = [Vec<f64>; 2];

impl Base {
    fn z_of(&self, node: usize, p: usize) -> Arc<NodeCols> {
        if let Some(z) = self.cache().get(&node) {
            return z.clone();
        }
        self.solve_nodes(&[node], p, &[]);
        self.cache()[&node].clone()
    }

    fn cache(&self) -> std::sync::MutexGuard<'_, HashMap<usize, Arc<NodeCols>>> {
        self.z.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Solves with the base for the columns of every node of `nodes` not cached yet (kept)
    /// and for each column of `extra` (returned): one pass over the factor for all.
    fn solve_nodes(&self, nodes: &[usize], p: usize, extra: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let todo: Vec<usize> = {
            let cache = self.cache();
            let mut t: Vec<usize> = nodes
                .iter()
                .copied()
                .filter(|i| !cache.contains_key(i))
                .collect();
            t.sort_unstable();
            t.dedup();
            t
        };
        if todo.is_empty() && extra.is_empty() {
            return Vec::new();
        }
        let m = 2 * p;
        let k = 2 * todo.len();
        let mut e = faer::Mat::<f64>::zeros(m, k + extra.len());
        for (j, &i) in todo.iter().enumerate() {
            e[(i, 2 * j)] = 1.0;
            e[(p + i, 2 * j + 1)] = 1.0;
        }
        for (j, b) in extra.iter().enumerate() {
            for (r, v) in b.iter().enumerate() {
                e[(r, k + j)] = *v;
            }
        }
        self.lu.solve_mat(e.as_mut());
        let col = |j: usize| -> Vec<f64> { e.col(j).iter().copied().collect() };
        let mut cache = self.cache();
        for (j, &i) in todo.iter().enumerate() {
            cache.insert(i, Arc::new([col(2 * j), col(2 * j + 1)]));
        }
        (0..extra.len()).map(|j| col(k + j)).collect()
    }
}

/// One rank-2 update: node `node`'s two rows changed by `v` (rows over λ).
struct Update {
    node: usize,
    v: [RowChange; 2],
    z: Arc<NodeCols>,
}

/// The change of one row. Many are sparse: between stick and slip the ν-row (a row of W)
/// does not change, between slip and open the t-row changes by `±F` at `λν` only, so
/// their products cost nothing instead of a pass over m numbers.
enum RowChange {
    /// The nonzeros (index, value), at most [`SPARSE_MAX`].
    Sparse(Vec<(usize, f64)>),
    Dense(Vec<f64>),
}

/// Most nonzeros of a [`RowChange::Sparse`].
const SPARSE_MAX: usize = 4;

impl RowChange {
    fn new(new: &[f64], old: &[f64]) -> Self {
        let v: Vec<f64> = new.iter().zip(old).map(|(a, b)| a - b).collect();
        if v.iter().filter(|x| **x != 0.0).count() <= SPARSE_MAX {
            Self::Sparse(
                v.into_iter()
                    .enumerate()
                    .filter(|(_, x)| *x != 0.0)
                    .collect(),
            )
        } else {
            Self::Dense(v)
        }
    }

    /// The row times `x`.
    fn dot(&self, x: &[f64]) -> f64 {
        match self {
            Self::Sparse(nz) => nz.iter().map(|&(j, v)| v * x[j]).sum(),
            Self::Dense(v) => dot(v, x),
        }
    }
}

/// The base's solutions `x0 = (D M_0)⁻¹ b` of right-hand sides b carried from piece to
/// piece: when the class of node i changes, each `b` changes in rows i, p+i only (the α
/// column of an affine load, whose q' is constant; the columns `rhs_S(q_j)` of a basis
/// load's vectors and of the gap), so `x0` changes by the base's columns of node i times
/// that change (O(m), no pass over the base's factor), and the piece's solution is
/// `x0 − Z C⁻¹ V x0` (O(km)): what a fresh solve with the updated factorisation gives, up
/// to the rounding of those sums. The caller checks them by their residuals from the data.
#[derive(Clone)]
pub(crate) struct Carried {
    /// The right-hand sides, in `r0` units.
    b: Vec<Vec<f64>>,
    /// The base's solutions of them (λ units).
    x0: Vec<Vec<f64>>,
    /// The piece's solutions, where they were computed ([`UpdatedLu::extend`]).
    y: Option<Vec<Vec<f64>>>,
    /// The piece's solutions as the caller checked them from the data (or solved them
    /// again), with W times each ([`UpdatedLu::set_checked`]).
    checked: Option<Arc<CheckedCols>>,
}

/// Solutions of the carried right-hand sides on one piece, checked from the data: the
/// solutions, and W times each.
pub(crate) type CheckedCols = (Vec<Vec<f64>>, Vec<Vec<f64>>);

/// `M_S` for one class vector, as a base plus updates. Cheap to clone (the big arrays are
/// shared).
#[derive(Clone)]
pub(crate) struct UpdatedLu {
    base: Arc<Base>,
    classes: Vec<Class>,
    updates: Vec<Arc<Update>>,
    /// `C⁻¹`, 2k × 2k, column-major.
    cinv: Arc<Vec<f64>>,
    det_sign: i8,
    /// A solution carried along the updates (see [`Carried`]).
    carry: Option<Arc<Carried>>,
}

/// The constants with the displacement rows in `r0` units (see the module doc).
fn equilibrated<'a>(c: &PieceConstants<'a>) -> PieceConstants<'a> {
    PieceConstants { r: c.r0, ..*c }
}

/// `D_S b`: the right-hand side of the piece equations in `r0` units.
fn scale_rhs(c: &PieceConstants<'_>, classes: &[Class], b: &[f64]) -> Vec<f64> {
    let s = c.r0 / c.r;
    let mut out = b.to_vec();
    for (i, &cl) in classes.iter().enumerate() {
        if cl != Class::Open {
            out[i] *= s;
        }
        if cl == Class::Stick {
            out[c.p + i] *= s;
        }
    }
    out
}

/// The two rows (over λ, length m) of node `i` in class `c`.
fn node_rows(c: &PieceConstants<'_>, w: MatRef<'_, f64>, i: usize, cls: Class) -> [Vec<f64>; 2] {
    let m = 2 * c.p;
    let zeros = vec![0.0; m];
    let mut out = vec![0.0; m + 1];
    let eqs = c.equations(i, cls);
    let mut rows = [Vec::new(), Vec::new()];
    for (k, form) in eqs.iter().enumerate() {
        form.row(w, &zeros, &mut out);
        rows[k] = out[..m].to_vec();
    }
    rows
}

impl UpdatedLu {
    /// Factorises `M_S` afresh (O(m_r³), see the module doc). `None` if it is exactly
    /// singular.
    pub fn factor(c: &PieceConstants<'_>, w: MatRef<'_, f64>, classes: &[Class]) -> Option<Self> {
        let c = &equilibrated(c);
        // The rows `λ = 0` of open nodes and the t-rows of slipping nodes are eliminated
        // ahead of the LU (see [`DenseLu::reduced`]).
        let lu = DenseLu::reduced(w, &c.rows(classes));
        if lu.det_sign == 0 || lu.pivot_ratio.is_nan() || lu.pivot_ratio <= 0.0 {
            return None;
        }
        let det_sign = lu.det_sign;
        Some(Self {
            base: Arc::new(Base {
                lu,
                z: Mutex::new(HashMap::new()),
            }),
            classes: classes.to_vec(),
            updates: Vec::new(),
            cinv: Arc::new(Vec::new()),
            det_sign,
            carry: None,
        })
    }

    /// `min |U_ii| / max |U_ii|` of the base's LU (in `r0` units): a cheap singularity
    /// indicator of the base piece matrix.
    pub fn pivot_ratio(&self) -> f64 {
        self.base.lu.pivot_ratio
    }

    /// Number of updates on the base.
    pub fn updates(&self) -> usize {
        self.updates.len()
    }

    /// True when `classes` can be reached by updates of this base: the updates so far and
    /// the nodes whose class differs stay within [`max_updates`] (else a fresh base is
    /// factorised).
    pub fn reaches(&self, classes: &[Class]) -> bool {
        self.updates() + self.differences(classes) <= max_updates(2 * self.classes.len())
    }

    /// Nodes whose class differs from `classes`.
    pub fn differences(&self, classes: &[Class]) -> usize {
        self.classes
            .iter()
            .zip(classes)
            .filter(|(a, b)| a != b)
            .count()
    }

    /// Sign of `det M_S`.
    pub fn det_sign(&self) -> i8 {
        self.det_sign
    }

    /// The factorisation for `classes`, by one rank-2 update per node whose class differs.
    /// `None` when an update makes C singular (then `M_S` is singular). With `carry_to`
    /// (the right-hand sides b of `M_S y = b` for `classes`, the seed's row scaling), the
    /// solutions carried by `self` are carried along (see [`Carried`]); they are dropped
    /// when they do not end up solving for exactly those b. Each column of `extra` (the
    /// seed's row scaling for `classes`) is solved for with the new piece matrix, without
    /// a check, its pass over the base's factor shared with the new nodes' columns.
    pub fn extend(
        &self,
        c: &PieceConstants<'_>,
        w: MatRef<'_, f64>,
        classes: &[Class],
        carry_to: Option<&[Vec<f64>]>,
        extra: &[Vec<f64>],
    ) -> Option<(Self, Vec<Vec<f64>>)> {
        let mut out = self.clone();
        let target: Option<Vec<Vec<f64>>> =
            carry_to.map(|bs| bs.iter().map(|b| scale_rhs(c, classes, b)).collect());
        if target.is_none() {
            out.carry = None;
        }
        let nodes: Vec<usize> = (0..classes.len())
            .filter(|&i| out.classes[i] != classes[i])
            .collect();
        let scaled: Vec<Vec<f64>> = extra.iter().map(|b| scale_rhs(c, classes, b)).collect();
        let x0 = self.base.solve_nodes(&nodes, c.p, &scaled);
        for &i in &nodes {
            out.append(c, w, i, classes[i], target.as_deref())?;
        }
        if let (Some(cr), Some(t)) = (&out.carry, &target)
            && cr.b != *t
        {
            out.carry = None;
        }
        // The extras and the carried solutions, corrected together.
        let mut cols = x0;
        let n_extra = cols.len();
        if let Some(cr) = &out.carry {
            cols.extend(cr.x0.iter().cloned());
        }
        let mut xs = out.correct_many(cols);
        if xs.len() > n_extra
            && let Some(cr) = out.carry.take()
        {
            let y = xs.split_off(n_extra);
            out.carry = Some(Arc::new(Carried {
                y: Some(y),
                checked: None,
                ..Arc::unwrap_or_clone(cr)
            }));
        }
        Some((out, xs))
    }

    /// Keeps the right-hand sides `bs` (the seed's row scaling) of `M_S y = b`, solved by
    /// `ys`, to be carried to the next pieces (see [`Carried`]).
    pub fn set_carry(&mut self, c: &PieceConstants<'_>, bs: &[Vec<f64>], ys: &[Vec<f64>]) {
        // On the base itself x0 is y; on an update, one pass over the base's factor.
        let b: Vec<Vec<f64>> = bs.iter().map(|b| scale_rhs(c, &self.classes, b)).collect();
        let x0 = if self.updates.is_empty() {
            ys.to_vec()
        } else {
            self.base_solve(&b)
        };
        self.carry = Some(Arc::new(Carried {
            b,
            x0,
            y: None,
            checked: None,
        }));
    }

    /// Keeps the carried right-hand sides' solutions on this piece as the caller checked
    /// them from the data, with W times each (see [`Self::checked`]). No-op without a
    /// carry or with a different number of columns.
    pub fn set_checked(&mut self, cols: CheckedCols) {
        if let Some(cr) = self.carry.take() {
            let n = cr.b.len();
            let mut cr = Arc::unwrap_or_clone(cr);
            cr.checked = (cols.0.len() == n && cols.1.len() == n).then(|| Arc::new(cols));
            self.carry = Some(Arc::new(cr));
        }
    }

    /// `M_S⁻¹ b` with W times it for every column `b` of `bs` (see
    /// [`Self::solve_checked_many`]); None unless every one is finite with a relative
    /// residual ≤ 1e-12.
    pub fn solve_cols(
        &self,
        c: &PieceConstants<'_>,
        w: MatRef<'_, f64>,
        bs: &[Vec<f64>],
        row_bound: f64,
    ) -> Option<CheckedCols> {
        let cols: Vec<Rhs<'_>> = bs.iter().map(|b| Rhs { b, guess: None }).collect();
        let ks = self.solve_checked_many(c, w, &cols, row_bound);
        ks.iter()
            .all(|k| k.rel <= 1e-12 && k.x.iter().all(|v| v.is_finite()))
            .then(|| ks.into_iter().map(|k| (k.x, k.wx)).unzip())
    }

    /// The carried right-hand sides' solutions kept by [`Self::set_checked`] on this very
    /// piece (an update drops them).
    pub fn checked(&self) -> Option<Arc<CheckedCols>> {
        self.carry.as_ref()?.checked.clone()
    }

    fn append(
        &mut self,
        c: &PieceConstants<'_>,
        w: MatRef<'_, f64>,
        i: usize,
        cls: Class,
        target: Option<&[Vec<f64>]>,
    ) -> Option<()> {
        let c = &equilibrated(c);
        let new = node_rows(c, w, i, cls);
        let old = node_rows(c, w, i, self.classes[i]);
        let v = [0, 1].map(|a| RowChange::new(&new[a], &old[a]));
        let z = self.base.z_of(i, c.p);
        let upd = Update { node: i, v, z };
        let k2 = 2 * self.updates.len();
        // Border of C: b = V_old z_new (k2 × 2), cb = v_new Z_old (2 × k2), d = I + v z.
        let mut bcol = vec![0.0; k2 * 2];
        let mut crow = [vec![0.0; k2], vec![0.0; k2]];
        for (j, u) in self.updates.iter().enumerate() {
            for a in 0..2 {
                for b in 0..2 {
                    bcol[(2 * j + a) + k2 * b] = u.v[a].dot(&upd.z[b]);
                    crow[a][2 * j + b] = upd.v[a].dot(&u.z[b]);
                }
            }
        }
        let mut d = [[0.0; 2]; 2];
        for (a, row) in d.iter_mut().enumerate() {
            for (b, x) in row.iter_mut().enumerate() {
                *x = upd.v[a].dot(&upd.z[b]) + if a == b { 1.0 } else { 0.0 };
            }
        }
        // Schur complement s = d − cb C⁻¹ b, with y = C⁻¹ b (k2 × 2), x = cb C⁻¹ (2 × k2);
        // C⁻¹ is read by columns (contiguous).
        let col_of = |col: usize| &self.cinv[k2 * col..k2 * (col + 1)];
        let mut y = vec![0.0; k2 * 2];
        for b in 0..2 {
            let yb = &mut y[k2 * b..k2 * (b + 1)];
            for col in 0..k2 {
                let f = bcol[col + k2 * b];
                if f != 0.0 {
                    axpy(yb, f, col_of(col));
                }
            }
        }
        let x: [Vec<f64>; 2] =
            [0, 1].map(|a| (0..k2).map(|col| dot(&crow[a], col_of(col))).collect());
        let mut s = d;
        for (a, row) in s.iter_mut().enumerate() {
            for (b, e) in row.iter_mut().enumerate() {
                *e -= dot(&crow[a], &y[k2 * b..k2 * (b + 1)]);
            }
        }
        let det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
        if !det.is_finite() || det == 0.0 {
            return None;
        }
        let si = [
            [s[1][1] / det, -s[0][1] / det],
            [-s[1][0] / det, s[0][0] / det],
        ];
        // C_new⁻¹ = [[C⁻¹ + y s⁻¹ x, −y s⁻¹], [−s⁻¹ x, s⁻¹]]
        let n2 = k2 + 2;
        let mut cinv = vec![0.0; n2 * n2];
        // y s⁻¹ (k2 × 2)
        let ys: [Vec<f64>; 2] = [0, 1].map(|b| {
            (0..k2)
                .map(|r| y[r] * si[0][b] + y[r + k2] * si[1][b])
                .collect()
        });
        for col in 0..k2 {
            let out = &mut cinv[n2 * col..n2 * (col + 1)];
            out[..k2].copy_from_slice(col_of(col));
            axpy(&mut out[..k2], x[0][col], &ys[0]);
            axpy(&mut out[..k2], x[1][col], &ys[1]);
            for a in 0..2 {
                out[k2 + a] = -(si[a][0] * x[0][col] + si[a][1] * x[1][col]);
            }
        }
        for b in 0..2 {
            let out = &mut cinv[n2 * (k2 + b)..n2 * (k2 + b + 1)];
            for r in 0..k2 {
                out[r] = -ys[b][r];
            }
            for a in 0..2 {
                out[k2 + a] = si[a][b];
            }
        }
        if cinv.iter().any(|v| !v.is_finite()) {
            return None;
        }
        // The carried right-hand sides and their base solutions: each b changes in node
        // i's rows.
        self.carry = match (self.carry.take(), target) {
            (Some(cr), Some(ts)) if ts.len() == cr.b.len() => {
                let mut cr = Arc::unwrap_or_clone(cr);
                for ((b, x0), t) in cr.b.iter_mut().zip(cr.x0.iter_mut()).zip(ts) {
                    for (a, row) in [i, c.p + i].into_iter().enumerate() {
                        let delta = t[row] - b[row];
                        if delta != 0.0 {
                            axpy(x0, delta, &upd.z[a]);
                        }
                        b[row] = t[row];
                    }
                }
                cr.y = None;
                cr.checked = None;
                cr.x0
                    .iter()
                    .all(|x0| x0.iter().all(|v| v.is_finite()))
                    .then(|| Arc::new(cr))
            }
            _ => None,
        };
        self.cinv = Arc::new(cinv);
        if det < 0.0 {
            self.det_sign = -self.det_sign;
        }
        self.classes[upd.node] = cls;
        self.updates.push(Arc::new(upd));
        Some(())
    }

    /// `(D_S M_S)⁻¹ b` for every column `b` (already in `r0` units): one pass over the
    /// base's factor for all of them, then the capacitance correction column by column.
    fn solve(&self, bs: &[Vec<f64>]) -> Vec<Vec<f64>> {
        self.correct_many(self.base_solve(bs))
    }

    /// `x0 − Z C⁻¹ V x0` for every x0 of `xs`: base solutions made the piece's (O(km)),
    /// all in one pass over the updates' rows and columns.
    fn correct_many(&self, mut xs: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
        let k2 = 2 * self.updates.len();
        if k2 == 0 {
            return xs;
        }
        let mut vx = vec![vec![0.0; k2]; xs.len()];
        for (j, u) in self.updates.iter().enumerate() {
            for a in 0..2 {
                for (t, x) in xs.iter().enumerate() {
                    vx[t][2 * j + a] = u.v[a].dot(x);
                }
            }
        }
        let wv: Vec<Vec<f64>> = vx
            .iter()
            .map(|vx| {
                let mut wv = vec![0.0; k2];
                for (col, &v) in vx.iter().enumerate() {
                    if v != 0.0 {
                        axpy(&mut wv, v, &self.cinv[k2 * col..k2 * (col + 1)]);
                    }
                }
                wv
            })
            .collect();
        for (j, u) in self.updates.iter().enumerate() {
            for a in 0..2 {
                for (x, wv) in xs.iter_mut().zip(&wv) {
                    let c = wv[2 * j + a];
                    if c != 0.0 {
                        axpy(x, -c, &u.z[a]);
                    }
                }
            }
        }
        xs
    }

    /// `M_S⁻¹ b` for every column `b` (the seed's row scaling), without a check: one
    /// pass over the base's factor for all of them. For callers that check by themselves
    /// (the refinement in double-double).
    pub fn solve_many(&self, c: &PieceConstants<'_>, bs: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let scaled: Vec<Vec<f64>> = bs.iter().map(|b| scale_rhs(c, &self.classes, b)).collect();
        self.solve(&scaled)
    }

    /// The solutions `y` of the carried right-hand sides (see [`Carried`]), if any
    /// (O(km) each): unchecked (the caller checks them by their residuals from the data,
    /// [`residual_rows`]).
    pub fn carried(&self) -> Option<Vec<Vec<f64>>> {
        let cr = self.carry.as_deref()?;
        Some(match &cr.y {
            Some(y) => y.clone(),
            None => self.correct_many(cr.x0.clone()),
        })
    }

    /// `(D M_0)⁻¹ b` for each b (in `r0` units): one pass over the base's factor.
    fn base_solve(&self, bs: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let m = self.base.lu.n();
        let mut xm = faer::Mat::<f64>::from_fn(m, bs.len(), |i, c| bs[c][i]);
        self.base.lu.solve_mat(xm.as_mut());
        (0..bs.len())
            .map(|c| xm.col(c).iter().copied().collect())
            .collect()
    }

    /// `M_S⁻¹ b` with its check (see [`Self::solve_checked_many`]).
    pub fn solve_checked(
        &self,
        c: &PieceConstants<'_>,
        w: MatRef<'_, f64>,
        b: &[f64],
        row_bound: f64,
    ) -> Checked {
        self.solve_checked_many(c, w, &[Rhs { b, guess: None }], row_bound)
            .pop()
            .expect("one column")
    }

    /// `M_S⁻¹ b` for every column, each with its relative residual
    /// `‖D(b − M_S x)‖∞ / (‖|D M_S||x|‖∞ + ‖D b‖∞)` (D: the row scaling to `r0` units;
    /// `|D M_S|` bounded row-wise by `row_bound`, see [`row_bound`]) and the product with
    /// W that the residual needs (which callers reuse). A column with a guess solves for
    /// the correction only, from the guess's residual: its rounding is then relative to
    /// that residual, not to b (an SMW solve of b itself can lose digits to cancellation
    /// between the base's solution and the capacitance correction). A column is refined
    /// once only when its first residual is above [`REFINE_ABOVE`]: the columns together
    /// then cost one pass over the base's factor and one over W.
    pub fn solve_checked_many(
        &self,
        c: &PieceConstants<'_>,
        w: MatRef<'_, f64>,
        cols: &[Rhs<'_>],
        row_bound: f64,
    ) -> Vec<Checked> {
        let full: Vec<Vec<f64>> = cols
            .iter()
            .map(|col| scale_rhs(c, &self.classes, col.b))
            .collect();
        let bs: Vec<Vec<f64>> = cols
            .iter()
            .zip(&full)
            .map(|(col, f)| match col.guess {
                Some((_, r)) => scale_rhs(c, &self.classes, r),
                None => f.clone(),
            })
            .collect();
        let c = &equilibrated(c);
        let finish = |k: usize, solved: Vec<f64>, r: Vec<f64>, wx: Vec<f64>| {
            let x: Vec<f64> = match cols[k].guess {
                Some((x0, _)) => x0.iter().zip(&solved).map(|(a, b)| a + b).collect(),
                None => solved.clone(),
            };
            Checked {
                rel: scaled_relative_residual(&r, &x, &full[k], row_bound),
                x,
                wx,
                solved,
                r,
            }
        };
        let xs = self.solve(&bs);
        let checks = residuals(c, w, &self.classes, &xs, &bs);
        let mut out: Vec<Checked> = xs
            .into_iter()
            .zip(checks)
            .enumerate()
            .map(|(k, (x, (r, wx)))| finish(k, x, r, wx))
            .collect();
        let again: Vec<usize> = (0..out.len())
            .filter(|&k| out[k].rel > REFINE_ABOVE)
            .collect();
        if !again.is_empty() {
            let rs: Vec<Vec<f64>> = again.iter().map(|&k| out[k].r.clone()).collect();
            let dxs = self.solve(&rs);
            let xs: Vec<Vec<f64>> = again
                .iter()
                .zip(dxs)
                .map(|(&k, dx)| out[k].solved.iter().zip(&dx).map(|(a, d)| a + d).collect())
                .collect();
            let b2: Vec<Vec<f64>> = again.iter().map(|&k| bs[k].clone()).collect();
            let checks = residuals(c, w, &self.classes, &xs, &b2);
            for ((&k, x), (r, wx)) in again.iter().zip(xs).zip(checks) {
                out[k] = finish(k, x, r, wx);
            }
        }
        out
    }
}

/// A right-hand side of [`UpdatedLu::solve_checked_many`].
pub(crate) struct Rhs<'a> {
    /// b (the seed's row scaling, as [`PieceConstants::piece_rhs`] gives it).
    pub b: &'a [f64],
    /// A guess `x0` with its residual `b − M_S x0` (same scaling as b).
    pub guess: Option<(&'a [f64], &'a [f64])>,
}

/// A solve with its check: see [`UpdatedLu::solve_checked`].
pub(crate) struct Checked {
    /// The solution (λ units).
    pub x: Vec<f64>,
    /// Its relative residual.
    pub rel: f64,
    /// `W` times the solved part: `W x`, or for a column with a guess `W (x − x0)`.
    pub wx: Vec<f64>,
    /// The solved part (x, or x − x0).
    solved: Vec<f64>,
    /// The residual `D (b − M_S x)`.
    r: Vec<f64>,
}

/// `b − M_S x` (the seed's row scaling) for the piece `classes` from x and `d = W x + k`:
/// with k = 0 the residual of `M_S x = b`; with k = q − (g, 0) and b = 0 that of the piece
/// equations at a point.
pub(crate) fn residual_rows(
    c: &PieceConstants<'_>,
    classes: &[Class],
    x: &[f64],
    d: &[f64],
    b: &[f64],
) -> Vec<f64> {
    let mut r = b.to_vec();
    for (i, &cls) in classes.iter().enumerate() {
        let [nu, t] = c.equations(i, cls);
        r[i] -= nu.eval(x, d);
        r[c.p + i] -= t.eval(x, d);
    }
    r
}

/// The relative residual of `x` on the equations of `classes` whose residual is `r`
/// (`b − M_S x`, the seed's row scaling), as [`UpdatedLu::solve_checked_many`] measures
/// it: `‖D r‖∞ / (row_bound ‖x‖∞ + ‖D b‖∞)`, D the row scaling to `r0` units.
pub(crate) fn relative_residual(
    c: &PieceConstants<'_>,
    classes: &[Class],
    r: &[f64],
    x: &[f64],
    b: &[f64],
    row_bound: f64,
) -> f64 {
    scaled_relative_residual(
        &scale_rhs(c, classes, r),
        x,
        &scale_rhs(c, classes, b),
        row_bound,
    )
}

/// `‖r‖∞ / (row_bound ‖x‖∞ + ‖b‖∞)` for r and b already in `r0` units (‖r‖∞ where the
/// denominator is 0); ∞ where that is not finite, a NaN in r, x or b included (the norms
/// are NaN then, see [`inf_norm`]).
fn scaled_relative_residual(r: &[f64], x: &[f64], b: &[f64], row_bound: f64) -> f64 {
    let denom = row_bound * inf_norm(x) + inf_norm(b);
    let num = inf_norm(r);
    let rel = if denom > 0.0 || denom.is_nan() {
        num / denom
    } else {
        num
    };
    if rel.is_finite() { rel } else { f64::INFINITY }
}

/// Relative residual above which a solve is refined once (a few units of rounding: a
/// backward-stable solve of a well-conditioned piece lands below it).
pub(crate) const REFINE_ABOVE: f64 = 1e-15;

/// `b − M_S x` and `W x` for every column (one product of W with all columns).
fn residuals(
    c: &PieceConstants<'_>,
    w: MatRef<'_, f64>,
    classes: &[Class],
    xs: &[Vec<f64>],
    bs: &[Vec<f64>],
) -> Vec<(Vec<f64>, Vec<f64>)> {
    let cols: Vec<&[f64]> = xs.iter().map(|x| &x[..]).collect();
    crate::dense::mat_mul(w, &cols)
        .into_iter()
        .zip(xs.iter().zip(bs))
        .map(|(d, (x, b))| (residual_rows(c, classes, x, &d, b), d))
        .collect()
}

/// The largest absolute row sum of any piece matrix in `r0` units:
/// `max(r0 ‖W‖∞, 1 + max F)`, from W's absolute row sums
/// ([`crate::problem::Problem::w_row_sums`]; O(m)).
pub(crate) fn row_bound(c: &PieceConstants<'_>, w_row_sums: &[f64]) -> f64 {
    let c = &equilibrated(c);
    (c.r * inf_norm(w_row_sums)).max(1.0 + inf_norm(c.friction))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_residual_with_a_nan_is_never_small() {
        // f64::max skips a NaN: a residual (or solution) with a NaN among small entries
        // measured that way passed the 1e-12 checks.
        assert!(inf_norm(&[1.0, f64::NAN, -3.0]).is_nan());
        assert!(inf_norm(&[f64::NAN, 1.0]).is_nan());
        assert_eq!(inf_norm(&[1.0, -3.0, 2.0]), 3.0);
        assert_eq!(inf_norm(&[]), 0.0);
        let friction = [0.5, 0.5];
        let c = PieceConstants {
            p: 2,
            friction: &friction,
            r: 1.0,
            r0: 1.0,
        };
        let classes = [Class::Stick, Class::Open];
        let (x, b) = ([1.0, 2.0, 0.5, 0.0], [1.0, 1.0, 1.0, 1.0]);
        let small = relative_residual(&c, &classes, &[1e-17, 0.0, 0.0, 0.0], &x, &b, 4.0);
        assert!(small > 0.0 && small < 1e-16, "{small:e}");
        for r in [[f64::NAN, 0.0, 0.0, 0.0], [0.0, 1e-17, 0.0, f64::NAN]] {
            assert_eq!(
                relative_residual(&c, &classes, &r, &x, &b, 4.0),
                f64::INFINITY
            );
        }
        let x_nan = [1.0, f64::NAN, 0.5, 0.0];
        assert_eq!(
            relative_residual(&c, &classes, &[0.0; 4], &x_nan, &b, 4.0),
            f64::INFINITY
        );
    }

    #[test]
    fn row_changes_between_neighbouring_classes_are_sparse_where_the_forms_say() {
        // W = 2 I + 1 (dense), p = 3, F = 0.7 at node 1, r = r0 = 1.
        let w = faer::Mat::<f64>::from_fn(6, 6, |i, j| if i == j { 3.0 } else { 1.0 });
        let friction = [0.2, 0.7, 0.4];
        let c = PieceConstants {
            p: 3,
            friction: &friction,
            r: 1.0,
            r0: 1.0,
        };
        let change = |from: Class, to: Class, row: usize| {
            let (a, b) = (
                node_rows(&c, w.as_ref(), 1, to),
                node_rows(&c, w.as_ref(), 1, from),
            );
            RowChange::new(&a[row], &b[row])
        };
        let sparse = |r: RowChange| match r {
            RowChange::Sparse(nz) => Some(nz),
            RowChange::Dense(_) => None,
        };
        // Stick -> slip+: the ν-row (W's row 1) is kept; the t-row changes densely.
        assert_eq!(
            sparse(change(Class::Stick, Class::SlipPlus, 0)),
            Some(vec![])
        );
        assert_eq!(sparse(change(Class::Stick, Class::SlipPlus, 1)), None);
        // Slip+ -> open: λt − F λν = 0 becomes λt = 0, a change of +F at λν (index 1).
        assert_eq!(
            sparse(change(Class::SlipPlus, Class::Open, 1)),
            Some(vec![(1, 0.7)])
        );
        assert_eq!(sparse(change(Class::SlipPlus, Class::Open, 0)), None);
        // Slip+ -> slip−: −F λν becomes +F λν.
        assert_eq!(
            sparse(change(Class::SlipPlus, Class::SlipMinus, 1)),
            Some(vec![(1, 1.4)])
        );
        // The products agree with the dense row's.
        let x: Vec<f64> = (0..6).map(|k| 1.0 + k as f64).collect();
        let dense = change(Class::Stick, Class::Open, 1);
        let (a, b) = (
            node_rows(&c, w.as_ref(), 1, Class::Open),
            node_rows(&c, w.as_ref(), 1, Class::Stick),
        );
        let expect: f64 = (0..6).map(|k| (a[1][k] - b[1][k]) * x[k]).sum();
        assert!((dense.dot(&x) - expect).abs() < 1e-13);
        assert_eq!(change(Class::SlipPlus, Class::Open, 1).dot(&x), 0.7 * 2.0);
    }
}
