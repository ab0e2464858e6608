//! An independent reference tracer for affine loads, written from scratch for the tests.
//!
//! Nothing here calls fricont's condensation, solver, tracer or tolerances (the only type
//! it shares is the [`Class`] label). It is deliberately plain and slow:
//!
//! * **Condensation** ([`Condensed::from_sparse`]): the stiffness, symmetrised as fricont
//!   does (`(A + Aᵀ)/2`), is ordered by reverse
//!   Cuthill–McKee and factorised by an envelope (skyline) Cholesky; every solve with `A`
//!   is refined to double-double accuracy with residuals from compensated dot products
//!   ([`dot_dd`]), and `W = B A⁻¹ Bᵀ`, `q_k = B A⁻¹ f_k` are kept in double-double. (On
//!   slender meshes a displacement guard is a difference of terms ~10⁶ times larger than
//!   itself; W merely rounded to double moves some transition points of the p = 480
//!   strip by 2e-8.)
//! * **Pieces** ([`Condensed::piece`]): for a class vector, the piece equations of SPEC §3
//!   with the open nodes (λ = 0) and the slip rows (λt = ±F λν) eliminated, a square system
//!   `K x = −(q0 − g)_R − α q1_R` over the contact nodes' unknowns, solved for
//!   `x(α) = x0 + α x1` by a fresh partial-pivoting LU (nalgebra) of K in double, refined
//!   twice in double-double against the piece equations written with the full λ.
//!   The sign of `det K` (from the pivots and the permutation's parity) equals the sign of
//!   the determinant of the full square piece Jacobian with the seed's rows (the
//!   eliminated rows are unit rows after a column operation that keeps the determinant).
//! * **Guards** are affine functions `g0 + α g1`, each coefficient rounded once from its
//!   double-double value (force guards from λ, displacement guards from
//!   `d = q + W λ − (g, 0)`).
//! * **Tracing** ([`Condensed::trace`]): from a start piece, the nearest guard crossing
//!   `α* = −g0/g1` in the path's direction; crossings within 1e-9 (relative α) of the
//!   nearest are one (degenerate) transition. The crossing nodes switch by the generic rules
//!   (open → slip± by the sign of dt, stick → slip± by the cone side reached, slip → stick,
//!   slip → open); the new piece must contain the point (its λ at α* equals the old one)
//!   and enter its region (every guard of a switched node that is at zero there increases
//!   along the new direction, every other guard non-negative). When several nodes switch
//!   at once, or the generic choice does not fit, every class combination of the switched
//!   nodes is tried; if not exactly one fits, tracing stops and says why. The direction of α on a piece follows the
//!   orientation rule of SPEC §4: `sign(dα/ds) = orientation · sign det K`, the orientation
//!   fixed at the start; a sign change is a fold. A singular piece (vertical) stops the
//!   trace. The trace ends when α leaves the window.
#![allow(dead_code)]

use fricont::Class;
use nalgebra::{DMatrix, DVector};

// ---------------------------------------------------------------------------------------
// Error-free transformations and double-double sums.
// ---------------------------------------------------------------------------------------

/// `a + b = s + e` exactly.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `a + b = s + e` exactly, for `|a| ≥ |b|` (or a = 0).
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// Veltkamp's splitting `a = h + l` into halves of 26 bits.
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a;
    let h = c - (c - a);
    (h, a - h)
}

/// `a b = p + e` exactly (Dekker's product; no fused multiply-add, which is a library
/// call on the default x86-64 target; |a|, |b| < 1e300).
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// `(hi + lo) + d` renormalised to double-double.
fn dd_add(hi: f64, lo: f64, d: f64) -> (f64, f64) {
    let (s, e) = two_sum(hi, d);
    fast_two_sum(s, e + lo)
}

/// `Σ a_k b_k` as if computed in twice the working precision (the Dot2 algorithm of
/// Ogita, Rump and Oishi), returned unrounded as `(hi, lo)` with `hi = fl(hi + lo)`.
pub fn dot_dd(terms: impl Iterator<Item = (f64, f64)>) -> (f64, f64) {
    let (mut hi, mut lo) = (0.0f64, 0.0f64);
    for (a, b) in terms {
        let (p, pe) = two_prod(a, b);
        let (s, se) = two_sum(hi, p);
        hi = s;
        lo += se + pe;
    }
    two_sum(hi, lo)
}

// ---------------------------------------------------------------------------------------
// Sparse input and the envelope Cholesky factor of A.
// ---------------------------------------------------------------------------------------

/// A sparse matrix as lists of `(column, value)` per row.
#[derive(Clone, Debug)]
pub struct SparseRows {
    pub ncols: usize,
    pub rows: Vec<Vec<(usize, f64)>>,
}

impl SparseRows {
    /// The nonzeros of a dense matrix.
    pub fn from_dense(m: &DMatrix<f64>) -> SparseRows {
        SparseRows {
            ncols: m.ncols(),
            rows: (0..m.nrows())
                .map(|i| {
                    (0..m.ncols())
                        .filter(|&j| m[(i, j)] != 0.0)
                        .map(|j| (j, m[(i, j)]))
                        .collect()
                })
                .collect(),
        }
    }

    /// `(A + Aᵀ)/2` computed as fricont does for full storage (`0.5 (a_ij + a_ji)` in
    /// double): assembled stiffness matrices are often symmetric only to a unit in the last
    /// place, and on slender meshes that last place moves W by 1e-12 and transition points
    /// by up to 1e-7, so both tracers must see the same matrix.
    pub fn symmetrised(&self) -> SparseRows {
        let mut t: Vec<Vec<(usize, f64)>> = vec![Vec::new(); self.ncols];
        for (i, r) in self.rows.iter().enumerate() {
            for &(j, v) in r {
                t[j].push((i, v));
            }
        }
        let rows = self
            .rows
            .iter()
            .zip(&t)
            .map(|(r, tr)| {
                let mut m: std::collections::BTreeMap<usize, (f64, f64)> = Default::default();
                for &(j, v) in r {
                    m.entry(j).or_default().0 += v;
                }
                for &(j, v) in tr {
                    m.entry(j).or_default().1 += v;
                }
                m.into_iter()
                    .map(|(j, (a, b))| (j, 0.5 * (a + b)))
                    .collect()
            })
            .collect();
        SparseRows {
            ncols: self.ncols,
            rows,
        }
    }

    /// Row `i` times `x`, compensated.
    pub fn row_dot(&self, i: usize, x: &[f64]) -> f64 {
        dot_dd(self.rows[i].iter().map(|&(j, v)| (v, x[j]))).0
    }
}

/// Reverse Cuthill–McKee ordering of the graph of a symmetric sparse matrix: `perm[new] =
/// old`. Each connected component starts from a pseudo-peripheral node.
fn rcm(a: &SparseRows) -> Vec<usize> {
    let n = a.rows.len();
    let adj: Vec<Vec<usize>> = a
        .rows
        .iter()
        .enumerate()
        .map(|(i, r)| r.iter().map(|&(j, _)| j).filter(|&j| j != i).collect())
        .collect();
    let deg: Vec<usize> = adj.iter().map(Vec::len).collect();
    let mut placed = vec![false; n];
    let mut order = Vec::with_capacity(n);
    // BFS levels from `s` over unplaced nodes: (last level, depth).
    let bfs = |s: usize, placed: &[bool]| -> (Vec<usize>, usize) {
        let mut seen = vec![false; n];
        seen[s] = true;
        let mut level = vec![s];
        let mut depth = 0;
        loop {
            let mut next = Vec::new();
            for &v in &level {
                for &w in &adj[v] {
                    if !seen[w] && !placed[w] {
                        seen[w] = true;
                        next.push(w);
                    }
                }
            }
            if next.is_empty() {
                return (level, depth);
            }
            level = next;
            depth += 1;
        }
    };
    while order.len() < n {
        let first = (0..n)
            .filter(|&i| !placed[i])
            .min_by_key(|&i| deg[i])
            .unwrap();
        // Pseudo-peripheral start: move to a node of least degree in the last BFS level
        // while the depth grows.
        let mut s = first;
        let (mut last, mut depth) = bfs(s, &placed);
        for _ in 0..8 {
            let c = *last.iter().min_by_key(|&&v| deg[v]).unwrap();
            let (l2, d2) = bfs(c, &placed);
            if d2 <= depth {
                break;
            }
            s = c;
            last = l2;
            depth = d2;
        }
        let _ = last;
        placed[s] = true;
        let start = order.len();
        order.push(s);
        let mut head = start;
        while head < order.len() {
            let v = order[head];
            head += 1;
            let mut nb: Vec<usize> = adj[v].iter().copied().filter(|&w| !placed[w]).collect();
            nb.sort_by_key(|&w| deg[w]);
            for w in nb {
                if !placed[w] {
                    placed[w] = true;
                    order.push(w);
                }
            }
        }
    }
    order.reverse();
    order
}

/// `P A Pᵀ = L Lᵀ` with `L` stored by rows inside the envelope of `P A Pᵀ`.
pub struct Skyline {
    /// `perm[new] = old`.
    perm: Vec<usize>,
    /// First column of the envelope of each (new) row.
    first: Vec<usize>,
    /// Row `i` of `L`, columns `first[i]..=i`.
    rows: Vec<Vec<f64>>,
}

impl Skyline {
    /// Factorises the symmetric positive definite `a` (both triangles stored). Panics if
    /// `a` is not positive definite.
    pub fn factor(a: &SparseRows) -> Skyline {
        let n = a.rows.len();
        let perm = rcm(a);
        let mut inv = vec![0; n];
        for (new, &old) in perm.iter().enumerate() {
            inv[old] = new;
        }
        let mut first: Vec<usize> = (0..n).collect();
        for (old, r) in a.rows.iter().enumerate() {
            let i = inv[old];
            for &(j, _) in r {
                let jn = inv[j];
                if jn < i {
                    first[i] = first[i].min(jn);
                }
            }
        }
        let mut rows: Vec<Vec<f64>> = (0..n).map(|i| vec![0.0; i - first[i] + 1]).collect();
        for (old, r) in a.rows.iter().enumerate() {
            let i = inv[old];
            for &(j, v) in r {
                let jn = inv[j];
                if jn <= i {
                    rows[i][jn - first[i]] = v;
                }
            }
        }
        for i in 0..n {
            let fi = first[i];
            for j in fi..i {
                let fj = first[j];
                let k0 = fi.max(fj);
                let (ri, rj) = (&rows[i], &rows[j]);
                let mut s = ri[j - fi];
                for k in k0..j {
                    s -= ri[k - fi] * rj[k - fj];
                }
                let v = s / rj[j - fj];
                rows[i][j - fi] = v;
            }
            let ri = &rows[i];
            let mut s = ri[i - fi];
            for k in fi..i {
                s -= ri[k - fi] * ri[k - fi];
            }
            assert!(
                s > 0.0,
                "A is not positive definite (pivot {s:e} at row {i})"
            );
            rows[i][i - fi] = s.sqrt();
        }
        Skyline { perm, first, rows }
    }

    /// Stored entries of L.
    pub fn envelope(&self) -> usize {
        self.rows.iter().map(Vec::len).sum()
    }

    /// `A⁻¹ b` (one forward and one backward substitution, no refinement).
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.perm.len();
        let mut y: Vec<f64> = (0..n).map(|i| b[self.perm[i]]).collect();
        for i in 0..n {
            let fi = self.first[i];
            let r = &self.rows[i];
            let mut s = y[i];
            for k in fi..i {
                s -= r[k - fi] * y[k];
            }
            y[i] = s / r[i - fi];
        }
        for i in (0..n).rev() {
            let fi = self.first[i];
            let r = &self.rows[i];
            y[i] /= r[i - fi];
            let xi = y[i];
            for k in fi..i {
                y[k] -= r[k - fi] * xi;
            }
        }
        let mut x = vec![0.0; n];
        for i in 0..n {
            x[self.perm[i]] = y[i];
        }
        x
    }

    /// `A⁻¹ b` in double-double: `x_hi + x_lo`, refined with residuals `b − A x` from
    /// compensated dot products until the correction is below 1e-27 of `x` or stops
    /// shrinking (at most 8 steps; each gains the digits that κ(A) leaves of double
    /// precision).
    pub fn solve_dd(&self, a: &SparseRows, b: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let n = b.len();
        let mut hi = self.solve(b);
        let mut lo = vec![0.0; n];
        let mut last = f64::INFINITY;
        for _ in 0..8 {
            let r: Vec<f64> = (0..n)
                .map(|i| {
                    dot_dd(
                        std::iter::once((1.0, b[i])).chain(
                            a.rows[i]
                                .iter()
                                .flat_map(|&(j, v)| [(-v, hi[j]), (-v, lo[j])]),
                        ),
                    )
                    .0
                })
                .collect();
            let dx = self.solve(&r);
            let mut big = 0.0f64;
            let mut corr = 0.0f64;
            for i in 0..n {
                (hi[i], lo[i]) = dd_add(hi[i], lo[i], dx[i]);
                big = big.max(hi[i].abs());
                corr = corr.max(dx[i].abs());
            }
            // Converged, or at the floor the compensated residual allows.
            if corr <= big * 1e-27 || corr > last / 16.0 {
                break;
            }
            last = corr;
        }
        (hi, lo)
    }
}

// ---------------------------------------------------------------------------------------
// The condensed problem.
// ---------------------------------------------------------------------------------------

/// The condensed problem `d = q0 + α q1 + W λ − (g, 0)` with friction and gap. `W`, `q0`
/// and `q1` are kept in double-double (`x + x_lo`): on slender meshes a displacement guard
/// is the small difference of terms ~10⁶ times larger, and W rounded to double moves some
/// transition points by more than 1e-8 (measured on the p = 480 strip).
#[derive(Clone, Debug)]
pub struct Condensed {
    pub p: usize,
    pub w: DMatrix<f64>,
    pub w_lo: DMatrix<f64>,
    pub q0: DVector<f64>,
    pub q0_lo: DVector<f64>,
    pub q1: DVector<f64>,
    pub q1_lo: DVector<f64>,
    pub gap: Vec<f64>,
    pub friction: Vec<f64>,
}

impl Condensed {
    /// Condenses sparse data (A symmetric positive definite with both triangles stored,
    /// N and T p × n) with the envelope Cholesky and double-double solves: `W_kl` for
    /// `k ≥ l` from column `l` (mirrored above the diagonal), `q_k = B_k A⁻¹ f_k`.
    pub fn from_sparse(
        a: &SparseRows,
        nm: &SparseRows,
        tm: &SparseRows,
        f0: &[f64],
        f1: &[f64],
        gap: Vec<f64>,
        friction: Vec<f64>,
    ) -> Condensed {
        let n = a.rows.len();
        let p = nm.rows.len();
        let a = &a.symmetrised();
        let chol = Skyline::factor(a);
        let brow = |k: usize| if k < p { &nm.rows[k] } else { &tm.rows[k - p] };
        let bdot = |k: usize, x: &(Vec<f64>, Vec<f64>)| {
            dot_dd(
                brow(k)
                    .iter()
                    .flat_map(|&(j, v)| [(v, x.0[j]), (v, x.1[j])]),
            )
        };
        let mut w = DMatrix::zeros(2 * p, 2 * p);
        let mut w_lo = DMatrix::zeros(2 * p, 2 * p);
        let mut e = vec![0.0; n];
        for l in 0..2 * p {
            for &(j, v) in brow(l) {
                e[j] = v;
            }
            let x = chol.solve_dd(a, &e);
            for &(j, _) in brow(l) {
                e[j] = 0.0;
            }
            for k in l..2 * p {
                let (h, lo) = bdot(k, &x);
                w[(k, l)] = h;
                w[(l, k)] = h;
                w_lo[(k, l)] = lo;
                w_lo[(l, k)] = lo;
            }
        }
        let x0 = chol.solve_dd(a, f0);
        let x1 = chol.solve_dd(a, f1);
        let q = |x: &(Vec<f64>, Vec<f64>)| {
            let v: Vec<(f64, f64)> = (0..2 * p).map(|k| bdot(k, x)).collect();
            (
                DVector::from_fn(2 * p, |k, _| v[k].0),
                DVector::from_fn(2 * p, |k, _| v[k].1),
            )
        };
        let (q0, q0_lo) = q(&x0);
        let (q1, q1_lo) = q(&x1);
        Condensed {
            p,
            w,
            w_lo,
            q0,
            q0_lo,
            q1,
            q1_lo,
            gap,
            friction,
        }
    }

    /// Condensed data in double precision only (the low parts zero): W and q as another
    /// code computed them.
    pub fn from_double(
        w: DMatrix<f64>,
        q0: DVector<f64>,
        q1: DVector<f64>,
        gap: Vec<f64>,
        friction: Vec<f64>,
    ) -> Condensed {
        let m = w.nrows();
        Condensed {
            p: m / 2,
            w,
            w_lo: DMatrix::zeros(m, m),
            q0,
            q0_lo: DVector::zeros(m),
            q1,
            q1_lo: DVector::zeros(m),
            gap,
            friction,
        }
    }

    /// The condensed problem of dense data.
    pub fn from_data(d: &super::Data) -> Condensed {
        Condensed::from_sparse(
            &SparseRows::from_dense(&d.a),
            &SparseRows::from_dense(&d.nm),
            &SparseRows::from_dense(&d.tm),
            d.f0.as_slice(),
            d.f1.as_slice(),
            d.gap.clone(),
            d.friction.clone(),
        )
    }

    /// `sign · (W λ)_k + Σ head` for `λ = hi + lo` (nonzero entries `nz`), as if computed
    /// in twice the working precision (one exact product per entry: `W_hi λ_hi`; the
    /// products with a low part are ε times smaller and need no correction).
    /// Also returns the sum of the magnitudes of the terms.
    fn w_dot(&self, k: usize, nz: &[usize], l: &Dd, sign: f64, head: &[(f64, f64)]) -> (f64, f64) {
        // W is symmetric: row k read as column k (contiguous).
        let (w, w_lo) = (self.w.column(k), self.w_lo.column(k));
        let (mut hi, mut lo, mut mag) = (0.0f64, 0.0f64, 0.0f64);
        for &(a, b) in head {
            let (p, pe) = two_prod(a, b);
            let (s, se) = two_sum(hi, p);
            hi = s;
            lo += se + pe;
            mag += p.abs();
        }
        // Four independent compensated sums (the chain of two_sum is latency-bound),
        // added at the end with their errors.
        let mut acc = [(0.0f64, 0.0f64); 4];
        for chunk in nz.chunks(4) {
            for (a, &j) in acc.iter_mut().zip(chunk) {
                let (wj, lj) = (sign * w[j], l.hi[j]);
                let (p, pe) = two_prod(wj, lj);
                let (s, se) = two_sum(a.0, p);
                a.0 = s;
                a.1 += se + pe + wj * l.lo[j] + sign * w_lo[j] * lj;
                mag += p.abs();
            }
        }
        for (h, e) in acc {
            let (s, se) = two_sum(hi, h);
            hi = s;
            lo += se + e;
        }
        (hi + lo, mag)
    }

    /// `d_k(λ) = q0_k + α q1_k + (W λ)_k − g_k` split as `(d0, d1)` for `λ = l0 + α l1`
    /// (each rounded once from double-double), with the largest magnitude of the terms of
    /// `d0 + α d1` at `alpha` (the row's scale).
    fn gap_row(&self, k: usize, l0: &Dd, l1: &Dd, alpha: f64) -> (f64, f64, f64) {
        let g = if k < self.p { self.gap[k] } else { 0.0 };
        let m = 2 * self.p;
        let nz: Vec<usize> = (0..m)
            .filter(|&j| l0.hi[j] != 0.0 || l1.hi[j] != 0.0)
            .collect();
        let (d0, _) = self.w_dot(
            k,
            &nz,
            l0,
            1.0,
            &[(1.0, self.q0[k]), (1.0, self.q0_lo[k]), (-1.0, g)],
        );
        let (d1, _) = self.w_dot(k, &nz, l1, 1.0, &[(1.0, self.q1[k]), (1.0, self.q1_lo[k])]);
        let mut s = (self.q0[k] + alpha * self.q1[k]).abs().max(g.abs());
        let wk = self.w.column(k);
        for &j in &nz {
            s = s.max((wk[j] * (l0.hi[j] + alpha * l1.hi[j])).abs());
        }
        (d0, d1, s)
    }
}

// ---------------------------------------------------------------------------------------
// Pieces and guards.
// ---------------------------------------------------------------------------------------

/// The guards of SPEC §3, each "value > 0" inside the piece.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuardKind {
    /// Open: `−dν`.
    Gap,
    /// Contact: `−λν`.
    Compress,
    /// Stick: `λt − F λν` (reaching 0: slip+).
    ConeUpper,
    /// Stick: `−F λν − λt` (reaching 0: slip−).
    ConeLower,
    /// Slip+: `dt`.
    SlipPos,
    /// Slip−: `−dt`.
    SlipNeg,
}

fn kinds(c: Class) -> &'static [GuardKind] {
    use GuardKind::*;
    match c {
        Class::Open => &[Gap],
        Class::Stick => &[Compress, ConeUpper, ConeLower],
        Class::SlipPlus => &[Compress, SlipPos],
        Class::SlipMinus => &[Compress, SlipNeg],
    }
}

/// One guard of a piece: `g0 + α g1 > 0` inside; `scale` is the magnitude it is rounded
/// relative to (the largest term of its formula at the point where it was made).
#[derive(Clone, Copy, Debug)]
pub struct RefGuard {
    pub node: usize,
    pub kind: GuardKind,
    pub g0: f64,
    pub g1: f64,
    pub scale: f64,
}

impl RefGuard {
    pub fn at(&self, alpha: f64) -> f64 {
        self.g0 + alpha * self.g1
    }
}

/// A vector in double-double: `hi + lo`, `|lo| ≤ ulp(hi)/2`.
#[derive(Clone, Debug)]
pub struct Dd {
    pub hi: DVector<f64>,
    pub lo: DVector<f64>,
}

impl Dd {
    fn zeros(m: usize) -> Dd {
        Dd {
            hi: DVector::zeros(m),
            lo: DVector::zeros(m),
        }
    }
}

/// A solved piece: `λ(α) = l0 + α l1` (double-double) and its guards.
#[derive(Clone, Debug)]
pub struct RefPiece {
    pub classes: Vec<Class>,
    pub l0: Dd,
    pub l1: Dd,
    /// Sign of the determinant of the piece matrix.
    pub det_sign: i8,
    /// min |U_ii| / max |U_ii| of the LU.
    pub pivot_ratio: f64,
    /// Largest relative residual of the piece equations after refinement,
    /// `|M λ − b| / (|M| |λ| + |b|)` row by row, with `λ` in double-double.
    pub residual: f64,
    pub guards: Vec<RefGuard>,
}

impl RefPiece {
    /// `λ(α)` rounded to double.
    pub fn lambda(&self, alpha: f64) -> DVector<f64> {
        DVector::from_fn(self.l0.hi.len(), |j, _| {
            dot_dd(
                [
                    (1.0, self.l0.hi[j]),
                    (1.0, self.l0.lo[j]),
                    (alpha, self.l1.hi[j]),
                    (alpha, self.l1.lo[j]),
                ]
                .into_iter(),
            )
            .0
        })
    }
}

impl Condensed {
    /// Solves the piece of `classes`; guards made with rounding scales at `alpha`. `Err`
    /// when the piece matrix is numerically singular (a vertical piece).
    ///
    /// The unknowns are λν of every contact node and λt of every stick node (λ = 0 at
    /// open nodes, λt = ±F λν at slip nodes), the rows `dν_i = 0` of the contact nodes and
    /// `dt_i = 0` of the stick nodes, both in the full system's order, so `det K` has the
    /// sign of the full piece matrix's determinant. `K` is factorised in double (nalgebra,
    /// partial pivoting); the solution is refined in double-double against the piece
    /// equations written with the full λ and W in double-double.
    pub fn piece(&self, classes: &[Class], alpha: f64) -> Result<RefPiece, String> {
        let p = self.p;
        let m = 2 * p;
        let mut vars: Vec<usize> = (0..p).filter(|&i| classes[i] != Class::Open).collect();
        vars.extend(
            (0..p)
                .filter(|&i| classes[i] == Class::Stick)
                .map(|i| p + i),
        );
        let k = vars.len();
        let slip_sign = |i: usize| match classes[i] {
            Class::SlipPlus => 1.0,
            Class::SlipMinus => -1.0,
            _ => 0.0,
        };
        let mut l0 = Dd::zeros(m);
        let mut l1 = Dd::zeros(m);
        let mut det_sign = 1i8;
        let mut pivot_ratio = 1.0;
        let mut residual = 0.0f64;
        if k > 0 {
            let kmat = DMatrix::from_fn(k, k, |r, c| {
                let (row, var) = (vars[r], vars[c]);
                let s = if var < p { slip_sign(var) } else { 0.0 };
                if s != 0.0 {
                    self.w[(row, var)] + s * self.friction[var] * self.w[(row, p + var)]
                } else {
                    self.w[(row, var)]
                }
            });
            let lu = kmat.lu();
            let u = lu.u();
            let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
            for i in 0..k {
                let d = u[(i, i)];
                lo = lo.min(d.abs());
                hi = hi.max(d.abs());
                if d < 0.0 {
                    det_sign = -det_sign;
                }
            }
            pivot_ratio = lo / hi;
            if pivot_ratio.is_nan() || pivot_ratio <= 1e-13 {
                return Err(format!(
                    "singular piece matrix (pivot ratio {pivot_ratio:e}, {k} unknowns)"
                ));
            }
            if lu.p().determinant::<f64>() < 0.0 {
                det_sign = -det_sign;
            }
            // λ (double-double) from the unknowns x (double-double).
            let expand = |x: &Dd| -> Dd {
                let mut l = Dd::zeros(m);
                for (c, &var) in vars.iter().enumerate() {
                    l.hi[var] = x.hi[c];
                    l.lo[var] = x.lo[c];
                }
                for i in 0..p {
                    let s = slip_sign(i);
                    if s != 0.0 {
                        let sf = s * self.friction[i];
                        let (h, e) = two_prod(sf, l.hi[i]);
                        (l.hi[p + i], l.lo[p + i]) = fast_two_sum(h, e + sf * l.lo[i]);
                    }
                }
                l
            };
            // Solves rows `b_r = −(c_hi + c_lo − g)_r − (W λ)_r` for one right-hand side
            // (c = q0 with the gap, or q1 without).
            let solve = |c: &DVector<f64>, c_lo: &DVector<f64>, gap: bool| -> (Dd, f64) {
                let g = |row: usize| if gap && row < p { self.gap[row] } else { 0.0 };
                let b = DVector::from_fn(k, |r, _| {
                    let row = vars[r];
                    dot_dd([(-1.0, c[row]), (-1.0, c_lo[row]), (1.0, g(row))].into_iter()).0
                });
                let mut x = Dd {
                    hi: lu.solve(&b).expect("nonsingular"),
                    lo: DVector::zeros(k),
                };
                // Two corrections; the residual reported is the one before the second (an
                // upper bound of the final one, up to the floor of the compensated sums).
                let mut rel = 0.0f64;
                for it in 0..2 {
                    let l = expand(&x);
                    let nz: Vec<usize> = (0..m).filter(|&j| l.hi[j] != 0.0).collect();
                    let mut res = DVector::zeros(k);
                    for r in 0..k {
                        let row = vars[r];
                        let head = [(-1.0, c[row]), (-1.0, c_lo[row]), (1.0, g(row))];
                        let (v, mag) = self.w_dot(row, &nz, &l, -1.0, &head);
                        res[r] = v;
                        if it == 1 && mag > 0.0 {
                            rel = rel.max(v.abs() / mag);
                        }
                    }
                    let dx = lu.solve(&res).expect("nonsingular");
                    for r in 0..k {
                        (x.hi[r], x.lo[r]) = dd_add(x.hi[r], x.lo[r], dx[r]);
                    }
                }
                (x, rel)
            };
            let (x0, r0) = solve(&self.q0, &self.q0_lo, true);
            let (x1, r1) = solve(&self.q1, &self.q1_lo, false);
            residual = r0.max(r1);
            l0 = expand(&x0);
            l1 = expand(&x1);
        }
        let mut guards = Vec::new();
        for (i, &c) in classes.iter().enumerate() {
            let f = self.friction[i];
            let (n0, n1, t0, t1) = (l0.hi[i], l1.hi[i], l0.hi[p + i], l1.hi[p + i]);
            let fscale = (n0 + alpha * n1).abs().max((t0 + alpha * t1).abs());
            // Σ c_j λ_j over (coefficient, index) in double-double, rounded once.
            let lin = |l: &Dd, terms: &[(f64, usize)]| {
                dot_dd(
                    terms
                        .iter()
                        .flat_map(|&(c, j)| [(c, l.hi[j]), (c, l.lo[j])]),
                )
                .0
            };
            for &kind in kinds(c) {
                let (g0, g1, scale) = match kind {
                    GuardKind::Gap => {
                        let (d0, d1, s) = self.gap_row(i, &l0, &l1, alpha);
                        (-d0, -d1, s)
                    }
                    GuardKind::SlipPos | GuardKind::SlipNeg => {
                        let (d0, d1, s) = self.gap_row(p + i, &l0, &l1, alpha);
                        let sg = if kind == GuardKind::SlipPos {
                            1.0
                        } else {
                            -1.0
                        };
                        (sg * d0, sg * d1, s)
                    }
                    GuardKind::Compress => {
                        let t = [(-1.0, i)];
                        (lin(&l0, &t), lin(&l1, &t), fscale)
                    }
                    GuardKind::ConeUpper => {
                        let t = [(1.0, p + i), (-f, i)];
                        (lin(&l0, &t), lin(&l1, &t), fscale)
                    }
                    GuardKind::ConeLower => {
                        let t = [(-1.0, p + i), (-f, i)];
                        (lin(&l0, &t), lin(&l1, &t), fscale)
                    }
                };
                guards.push(RefGuard {
                    node: i,
                    kind,
                    g0,
                    g1,
                    scale,
                });
            }
        }
        Ok(RefPiece {
            classes: classes.to_vec(),
            l0,
            l1,
            det_sign,
            pivot_ratio,
            residual,
            guards,
        })
    }
}

// ---------------------------------------------------------------------------------------
// The tracer.
// ---------------------------------------------------------------------------------------

/// One node changing class.
#[derive(Clone, Debug, PartialEq)]
pub struct RefEvent {
    pub alpha: f64,
    pub node: usize,
    pub from: Class,
    pub to: Class,
    pub fold: bool,
}

/// What [`Condensed::trace`] found.
#[derive(Clone, Debug)]
pub struct RefTrace {
    pub events: Vec<RefEvent>,
    /// `(classes, α from, α to)` of every traversed piece.
    pub pieces: Vec<(Vec<Class>, f64, f64)>,
    /// Where the trace ended.
    pub end_alpha: f64,
    /// `Ok` when α left the window; `Err(why)` when the trace stopped.
    pub end: Result<(), String>,
    /// Largest relative residual of any piece solve.
    pub max_residual: f64,
    /// Smallest pivot ratio of any piece matrix.
    pub min_pivot_ratio: f64,
    /// The smallest relative distance in α between the transition taken and the next
    /// crossing not grouped with it (how close the nearest separate crossings came).
    pub min_separation: f64,
    /// The largest relative distance in α between crossings grouped into one transition
    /// (0 when every transition had one crossing or exactly simultaneous ones).
    pub max_group_spread: f64,
}

/// Crossings within this relative α of the nearest are one transition.
pub const GROUP_TOL: f64 = 1e-9;

/// The class a node enters when guard `kind` of its class reaches zero (generic rule);
/// `dt` is the tangential displacement gap at the point (for open → slip±).
fn generic_next(kind: GuardKind, dt: f64) -> Class {
    match kind {
        GuardKind::Gap => {
            if dt > 0.0 {
                Class::SlipPlus
            } else if dt < 0.0 {
                Class::SlipMinus
            } else {
                Class::Stick
            }
        }
        GuardKind::Compress => Class::Open,
        GuardKind::ConeUpper => Class::SlipPlus,
        GuardKind::ConeLower => Class::SlipMinus,
        GuardKind::SlipPos | GuardKind::SlipNeg => Class::Stick,
    }
}

/// True when guard `kind` of class `to` is zero at a point where a node switches from
/// `from` to `to` (the equations of both classes hold there).
fn structural_zero(from: Class, to: Class, kind: GuardKind) -> bool {
    use GuardKind::*;
    match (from, to) {
        (_, Class::Open) => kind == Gap,
        (Class::Open, _) => matches!(kind, Compress | ConeUpper | ConeLower),
        (Class::SlipPlus, Class::Stick) => kind == ConeUpper,
        (Class::SlipMinus, Class::Stick) => kind == ConeLower,
        (Class::Stick, Class::SlipPlus) => kind == SlipPos,
        (Class::Stick, Class::SlipMinus) => kind == SlipNeg,
        (Class::SlipMinus, Class::SlipPlus) | (Class::SlipPlus, Class::SlipMinus) => {
            kind == Compress
        }
        _ => false,
    }
}

impl Condensed {
    /// Direction of α on `piece` for the path orientation `orient`.
    fn direction(orient: i8, piece: &RefPiece) -> i8 {
        orient * piece.det_sign
    }

    /// Checks that `cand` continues the path at `alpha` from the piece `old` after the
    /// nodes in `group` switched: it contains the point and enters its region
    /// with direction `dir`. A guard of a switched node that is zero by construction
    /// ([`structural_zero`]) or within 1e-12 of the magnitude of `g0` and `α g1` must
    /// increase along `dir`; every guard must be non-negative to that accuracy.
    fn enters(
        &self,
        cand: &RefPiece,
        old: &RefPiece,
        alpha: f64,
        group: &[usize],
        dir: f64,
    ) -> Result<(), String> {
        let lc = cand.lambda(alpha);
        // The rounding scale of λ(α) = l0 + α l1 on either piece.
        let rounding = |pc: &RefPiece| {
            pc.l0
                .hi
                .iter()
                .zip(pc.l1.hi.iter())
                .map(|(a, b)| a.abs() + (alpha * b).abs())
                .fold(0.0, f64::max)
        };
        let scale = rounding(cand).max(rounding(old));
        let diff = (&lc - old.lambda(alpha)).amax();
        if diff > 1e-8 * scale {
            return Err(format!(
                "does not contain the point (|Δλ| = {diff:e}, scale {scale:e})"
            ));
        }
        for g in &cand.guards {
            let v = g.at(alpha);
            // v is rounded from g0 + α g1 (coefficients accurate to a unit in the last
            // place); the scale of the terms λ or d are made of enters only through λ,
            // accurate to double-double.
            let thr = 1e-12 * g.g0.abs().max((alpha * g.g1).abs()) + 1e-20 * g.scale;
            if v < -thr {
                return Err(format!("node {} guard {:?} = {v:e} < 0", g.node, g.kind));
            }
            let i = g.node;
            let at_zero = structural_zero(old.classes[i], cand.classes[i], g.kind) || v <= thr;
            if group.contains(&i) && at_zero && dir * g.g1 <= 0.0 {
                return Err(format!(
                    "node {i} guard {:?} at zero does not increase (slope {:e})",
                    g.kind,
                    dir * g.g1
                ));
            }
        }
        Ok(())
    }

    /// Traces from the piece of `classes0` at `a0` toward `a_end` until α leaves the
    /// window `[min(a0, a_end), max(a0, a_end)]` (or `max_steps` transitions, or a stop).
    /// `progress(transitions, α)` is called after each transition.
    pub fn trace(
        &self,
        classes0: &[Class],
        a0: f64,
        a_end: f64,
        max_steps: usize,
        progress: &mut dyn FnMut(usize, f64),
    ) -> RefTrace {
        let (lo, hi) = (a0.min(a_end), a0.max(a_end));
        let mut out = RefTrace {
            events: Vec::new(),
            pieces: Vec::new(),
            end_alpha: a0,
            end: Ok(()),
            max_residual: 0.0,
            min_pivot_ratio: 1.0,
            min_separation: f64::INFINITY,
            max_group_spread: 0.0,
        };
        let mut piece = match self.piece(classes0, a0) {
            Ok(pc) => pc,
            Err(e) => {
                out.end = Err(format!("start piece: {e}"));
                return out;
            }
        };
        let mut dir: f64 = if a_end > a0 { 1.0 } else { -1.0 };
        let orient = (dir as i8) * piece.det_sign;
        for g in &piece.guards {
            if g.at(a0) <= 0.0 {
                out.end = Err(format!(
                    "start: node {} guard {:?} = {:e} is not positive",
                    g.node,
                    g.kind,
                    g.at(a0)
                ));
                return out;
            }
        }
        let mut alpha = a0;
        let mut transitions = 0;
        // Class vectors entered at the current α (a cycle of zero-length pieces stops).
        let mut here: Vec<Vec<Class>> = vec![piece.classes.clone()];
        loop {
            out.max_residual = out.max_residual.max(piece.residual);
            out.min_pivot_ratio = out.min_pivot_ratio.min(piece.pivot_ratio);
            let tol = GROUP_TOL * 1f64.max(alpha.abs());
            // Crossings ahead: (distance, α*, guard).
            let mut cross: Vec<(f64, f64, usize)> = piece
                .guards
                .iter()
                .enumerate()
                .filter(|(_, g)| dir * g.g1 < 0.0)
                .map(|(k, g)| {
                    let a = -g.g0 / g.g1;
                    ((a - alpha) * dir, a, k)
                })
                .filter(|&(t, _, _)| t >= -tol)
                .collect();
            cross.sort_by(|a, b| a.0.total_cmp(&b.0));
            let edge = if dir > 0.0 { hi } else { lo };
            let t_edge = (edge - alpha) * dir;
            if cross.is_empty() || cross[0].0 > t_edge {
                out.pieces.push((piece.classes.clone(), alpha, edge));
                out.end_alpha = edge;
                return out;
            }
            if transitions >= max_steps {
                out.end = Err(format!("{max_steps} transitions"));
                out.end_alpha = alpha;
                return out;
            }
            let (t0, a_e, _) = cross[0];
            let gtol = GROUP_TOL * 1f64.max(a_e.abs());
            let group_guards: Vec<usize> = cross
                .iter()
                .take_while(|c| c.0 <= t0.max(0.0) + gtol)
                .map(|c| c.2)
                .collect();
            if let Some(last) = cross.get(group_guards.len() - 1) {
                out.max_group_spread = out
                    .max_group_spread
                    .max((last.0 - t0) / 1f64.max(a_e.abs()));
            }
            if let Some(next) = cross.get(group_guards.len()) {
                out.min_separation = out.min_separation.min((next.0 - t0) / 1f64.max(a_e.abs()));
            }
            let a_e = if t0 < 0.0 { alpha } else { a_e };
            let mut nodes: Vec<usize> =
                group_guards.iter().map(|&k| piece.guards[k].node).collect();
            nodes.sort_unstable();
            nodes.dedup();
            if nodes.len() > 6 {
                out.end = Err(format!(
                    "α = {a_e}: {} nodes switch at once, not enumerated",
                    nodes.len()
                ));
                out.end_alpha = a_e;
                return out;
            }
            // The generic choice: per node, the class its crossing guard leads to (a node
            // with several guards at zero takes the first; the enumeration covers the rest).
            let mut generic = piece.classes.clone();
            for &i in &nodes {
                let k = *group_guards
                    .iter()
                    .find(|&&k| piece.guards[k].node == i)
                    .unwrap();
                let dt = {
                    let (d0, d1, _) = self.gap_row(self.p + i, &piece.l0, &piece.l1, a_e);
                    d0 + a_e * d1
                };
                generic[i] = generic_next(piece.guards[k].kind, dt);
            }
            let try_piece = |classes: &[Class]| -> Result<(RefPiece, f64), String> {
                let pc = self.piece(classes, a_e)?;
                let d = Self::direction(orient, &pc) as f64;
                self.enters(&pc, &piece, a_e, &nodes, d)?;
                Ok((pc, d))
            };
            // One node: the generic rule, if its piece fits. Several nodes at once (a
            // degenerate transition), or a generic piece that does not fit: every
            // combination, and exactly one must fit.
            let first = if nodes.len() == 1 {
                try_piece(&generic)
            } else {
                Err("several nodes".to_string())
            };
            let chosen = match first {
                Ok(x) => Ok(x),
                Err(why_generic) => {
                    // Every other combination of classes of the switched nodes.
                    let mut ok = Vec::new();
                    let mut whys = vec![format!("generic {generic:?}: {why_generic}")];
                    let total = 4usize.pow(nodes.len() as u32);
                    for code in 0..total {
                        let mut cl = piece.classes.clone();
                        for (b, &i) in nodes.iter().enumerate() {
                            cl[i] = Class::ALL[(code >> (2 * b)) & 3];
                        }
                        if cl == piece.classes || (nodes.len() == 1 && cl == generic) {
                            continue;
                        }
                        match try_piece(&cl) {
                            Ok(x) => ok.push(x),
                            Err(e) => {
                                if whys.len() < 6 {
                                    whys.push(format!(
                                        "{:?}: {e}",
                                        nodes.iter().map(|&i| cl[i]).collect::<Vec<_>>()
                                    ));
                                }
                            }
                        }
                    }
                    if ok.len() == 1 {
                        Ok(ok.pop().unwrap())
                    } else {
                        Err(format!(
                            "α = {a_e}: nodes {:?} (0-based) switch; {} continuations fit ({})",
                            nodes,
                            ok.len(),
                            whys.join("; ")
                        ))
                    }
                }
            };
            let (next, ndir) = match chosen {
                Ok(x) => x,
                Err(e) => {
                    out.pieces.push((piece.classes.clone(), alpha, a_e));
                    out.end = Err(e);
                    out.end_alpha = a_e;
                    return out;
                }
            };
            out.pieces.push((piece.classes.clone(), alpha, a_e));
            if a_e != alpha {
                here.clear();
            }
            if here.contains(&next.classes) {
                out.end = Err(format!("α = {a_e}: the class vectors at this point cycle"));
                out.end_alpha = a_e;
                return out;
            }
            here.push(next.classes.clone());
            let fold = ndir != dir;
            for &i in &nodes {
                if next.classes[i] != piece.classes[i] {
                    out.events.push(RefEvent {
                        alpha: a_e,
                        node: i,
                        from: piece.classes[i],
                        to: next.classes[i],
                        fold,
                    });
                }
            }
            transitions += 1;
            progress(transitions, a_e);
            piece = next;
            dir = ndir;
            alpha = a_e;
        }
    }
}

// ---------------------------------------------------------------------------------------
// Comparison of two event lists.
// ---------------------------------------------------------------------------------------

/// An event as `(α, node, from, to)`.
pub type Ev = (f64, usize, Class, Class);

/// fricont's events of `path` as [`Ev`].
pub fn path_events(path: &fricont::Path) -> Vec<Ev> {
    path.events()
        .iter()
        .map(|e| (e.alpha, e.node, e.from, e.to))
        .collect()
}

impl RefTrace {
    /// The reference's events as [`Ev`].
    pub fn evs(&self) -> Vec<Ev> {
        self.events
            .iter()
            .map(|e| (e.alpha, e.node, e.from, e.to))
            .collect()
    }
}

/// Compares traced events `got` with the reference `want`: events are grouped into
/// clusters of consecutive events whose α agree within `tol` (relative to max(1, |α|)),
/// clusters must pair up with equal multisets of `(node, from, to)` and α within `tol`.
/// Returns the largest |Δα| / max(1, |α|), or the first difference.
pub fn compare_events(got: &[Ev], want: &[Ev], tol: f64) -> Result<f64, String> {
    fn clusters(e: &[Ev], tol: f64) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        let mut s = 0;
        while s < e.len() {
            let mut t = s + 1;
            while t < e.len() && (e[t].0 - e[s].0).abs() <= tol * 1f64.max(e[s].0.abs()) {
                t += 1;
            }
            out.push((s, t));
            s = t;
        }
        out
    }
    let show = |e: &Ev| format!("α = {:.14e} node {} {} -> {}", e.0, e.1 + 1, e.2, e.3);
    let (cg, cw) = (clusters(got, tol), clusters(want, tol));
    let mut worst = 0.0f64;
    for (k, (&(gs, ge), &(ws, we))) in cg.iter().zip(&cw).enumerate() {
        let key = |e: &[Ev]| {
            let mut v: Vec<(usize, Class, Class)> = e.iter().map(|x| (x.1, x.2, x.3)).collect();
            v.sort();
            v
        };
        let (g, w) = (&got[gs..ge], &want[ws..we]);
        let d = g
            .iter()
            .chain(w)
            .map(|x| (x.0 - w[0].0).abs() / 1f64.max(w[0].0.abs()))
            .fold(0.0, f64::max);
        if key(g) != key(w) || d > tol {
            return Err(format!(
                "transition {} (events {}.. of fricont, {}.. of the reference) differs:\n  fricont:   {}\n  reference: {}",
                k + 1,
                gs + 1,
                ws + 1,
                g.iter().map(show).collect::<Vec<_>>().join("; "),
                w.iter().map(show).collect::<Vec<_>>().join("; ")
            ));
        }
        worst = worst.max(d);
    }
    if cg.len() != cw.len() {
        let k = cg.len().min(cw.len());
        let next = |c: &[(usize, usize)], e: &[Ev]| {
            c.get(k).map_or("none".to_string(), |&(s, t)| {
                e[s..t].iter().map(show).collect::<Vec<_>>().join("; ")
            })
        };
        return Err(format!(
            "{} transitions in fricont, {} in the reference; first extra: fricont {}, reference {}",
            cg.len(),
            cw.len(),
            next(&cg, got),
            next(&cw, want)
        ));
    }
    Ok(worst)
}

/// Every reference event (`want`) matched to the traced event (`got`) of the same node and kind nearest
/// in α: those further apart than `tol` (relative to max(1, |α|); infinite when there is
/// none within 1e-3), largest first, as (reference index, difference, event).
pub fn differences(got: &[Ev], want: &[Ev], tol: f64) -> Vec<(usize, f64, Ev)> {
    let mut out = Vec::new();
    for (k, e) in want.iter().enumerate() {
        let d = got
            .iter()
            .filter(|f| (f.1, f.2, f.3) == (e.1, e.2, e.3))
            .map(|f| (f.0 - e.0).abs() / 1f64.max(e.0.abs()))
            .fold(f64::INFINITY, f64::min);
        let d = if d > 1e-3 { f64::INFINITY } else { d };
        if d > tol {
            out.push((k, d, *e));
        }
    }
    out.sort_by(|a, b| b.1.total_cmp(&a.1));
    out
}

// ---------------------------------------------------------------------------------------
// Running fricont and the reference on the same data.
// ---------------------------------------------------------------------------------------

impl SparseRows {
    /// The rows of a CSR matrix (a data container only).
    pub fn from_csr(m: &fricont::CsrMatrix) -> SparseRows {
        SparseRows {
            ncols: m.ncols(),
            rows: (0..m.nrows()).map(|i| m.row(i).collect()).collect(),
        }
    }
}

/// fricont's path and the reference trace of the same problem, compared.
pub struct Comparison {
    /// fricont's events.
    pub fricont: Vec<Ev>,
    /// fricont's end: (α at the end of its last piece, reason).
    pub fricont_end: (f64, String),
    /// How fricont's start was reached (`Path::start_route`).
    pub fricont_route: fricont::StartRoute,
    /// The reference trace.
    pub reference: RefTrace,
    /// max |λ_fricont − λ_ref| / max |λ| at the start.
    pub start_diff: f64,
    /// max |λ_fricont − λ_ref| / max |λ| at the window's end, on the last pieces of both
    /// (0 when either did not reach it).
    pub end_diff: f64,
    /// The comparison of the events: the largest relative α difference, or the first
    /// difference.
    pub events: Result<f64, String>,
    /// Seconds: fricont (set-up + trace), reference (trace).
    pub seconds: (f64, f64),
    /// Folds: fricont's events with the flag, the reference's.
    pub folds: (usize, usize),
}

impl Comparison {
    /// Everything agrees: the reference reached the window's end, fricont ended with
    /// reason `window` at the same α, the start states agree to `tol` (relative to the
    /// largest force; in double alone fricont's condensation was only accurate to 1e-7 on
    /// the p = 480 strip, with extended precision its start agrees to ~1e-14), and so do
    /// the λ at the window's end on the last pieces of both, the events
    /// agree ([`compare_events`] to `tol`) and neither path folds
    /// where the other does not. The message lists the first differing transition and the
    /// largest differences of single events ([`differences`]).
    pub fn check(&self, tol: f64) -> Result<(), String> {
        self.reference.end.as_ref().map_err(|e| {
            format!(
                "the reference stopped at α = {}: {e}",
                self.reference.end_alpha
            )
        })?;
        let mut errs = Vec::new();
        if self.start_diff > tol {
            errs.push(format!("start λ differ by {:e}", self.start_diff));
        }
        if self.end_diff > tol {
            errs.push(format!(
                "λ at the window's end differ by {:e}",
                self.end_diff
            ));
        }
        if let Err(e) = &self.events {
            errs.push(e.clone());
            let want = self.reference.evs();
            let d = differences(&self.fricont, &want, tol);
            errs.push(format!(
                "{} of {} reference events differ from fricont's nearest event of the same node and kind by more than {tol:e}; the largest:\n{}",
                d.len(),
                want.len(),
                d.iter()
                    .take(5)
                    .map(|(k, d, e)| format!(
                        "  reference event {}: α = {:.14e} node {} {} -> {}: {}",
                        k + 1,
                        e.0,
                        e.1 + 1,
                        e.2,
                        e.3,
                        if d.is_finite() {
                            format!("fricont's differs by {d:.1e}")
                        } else {
                            "no such event in fricont within 1e-3".to_string()
                        }
                    ))
                    .collect::<Vec<_>>()
                    .join("\n")
            ));
        }
        if self.folds.0 != self.folds.1 {
            errs.push(format!(
                "fricont reports {} folds, the reference {}",
                self.folds.0, self.folds.1
            ));
        }
        if self.fricont_end.1 != "window" || self.fricont_end.0 != self.reference.end_alpha {
            errs.push(format!(
                "fricont ended at α = {} ({}), the reference at {} (window)",
                self.fricont_end.0, self.fricont_end.1, self.reference.end_alpha
            ));
        }
        if errs.is_empty() {
            Ok(())
        } else {
            Err(errs.join("\n"))
        }
    }
}

/// The tracers alone on identical data: `cond`'s W, q0, q1 rounded to double, given to
/// fricont as condensed input (extended precision `mode`) and to the reference as they are
/// ([`Condensed::from_double`]), compared as [`compare_with_fricont`] does.
pub fn compare_on_rounded(
    cond: &Condensed,
    mode: fricont::ExtendedPrecision,
    a0: f64,
    a1: f64,
    tol: f64,
) -> Comparison {
    let m = 2 * cond.p;
    let problem = fricont::ProblemBuilder::condensed(fricont::faer::Mat::from_fn(m, m, |i, j| {
        cond.w[(i, j)]
    }))
    .friction(cond.friction.clone())
    .gap(cond.gap.clone())
    .extended_precision(mode)
    .build()
    .expect("condensed problem");
    if mode == fricont::ExtendedPrecision::On {
        assert!(problem.extended_precision());
    }
    let rounded = Condensed::from_double(
        cond.w.clone(),
        cond.q0.clone(),
        cond.q1.clone(),
        cond.gap.clone(),
        cond.friction.clone(),
    );
    let q0: Vec<f64> = cond.q0.iter().copied().collect();
    let q1: Vec<f64> = cond.q1.iter().copied().collect();
    compare_with_fricont(
        &rounded,
        std::sync::Arc::new(problem),
        &q0,
        &q1,
        a0,
        a1,
        tol,
        &mut |_, _| {},
    )
}

/// [`compare_with_fricont`] on a test case: `problem` (built from `case`'s data) traced
/// under its affine load on its window, the reference condensing the same data itself.
pub fn compare_case(
    case: &super::Case,
    problem: std::sync::Arc<fricont::Problem>,
    tol: f64,
) -> Comparison {
    let d = &case.data;
    compare_with_fricont(
        &Condensed::from_data(d),
        problem,
        d.f0.as_slice(),
        d.f1.as_slice(),
        case.a0,
        case.a1,
        tol,
        &mut |_, _| {},
    )
}

/// Traces `problem` with the affine load `(f0, f1)` on `[a0 → a1]` with fricont (default
/// options) and with the reference tracer on `cond` (the same data condensed
/// independently), starting the reference from fricont's start classes after checking
/// that the reference piece of those classes reproduces fricont's start λ and has all its
/// guards positive at `a0`.
#[allow(clippy::too_many_arguments)]
pub fn compare_with_fricont(
    cond: &Condensed,
    problem: std::sync::Arc<fricont::Problem>,
    f0: &[f64],
    f1: &[f64],
    a0: f64,
    a1: f64,
    tol: f64,
    progress: &mut dyn FnMut(usize, f64),
) -> Comparison {
    let t = std::time::Instant::now();
    let load = fricont::Load::affine(f0.to_vec(), f1.to_vec()).expect("affine load");
    let mut path =
        fricont::Path::new(problem, load, fricont::PathOptions::window(a0, a1)).expect("Path::new");
    path.start(a0, None).expect("fricont start");
    let route = path.start_route().expect("started");
    let run = path.run();
    let fr_secs = t.elapsed().as_secs_f64();
    let fricont = path_events(&path);
    let end_alpha = path.pieces().last().map_or(a0, |p| p.alpha_to);
    let reason = match (&run, path.end_reason()) {
        (Err(e), _) => format!("error: {e}"),
        (Ok(_), Some(fricont::EndReason::Failed(m))) => format!("failed: {m}"),
        (Ok(_), Some(r)) => r.name().to_string(),
        (Ok(_), None) => "none".to_string(),
    };
    let start = path.start_state().expect("start state").clone();
    let t = std::time::Instant::now();
    let p = cond.p;
    let lam_fr =
        DVector::from_iterator(2 * p, start.lambda_n.iter().chain(&start.lambda_t).copied());
    let (start_diff, reference) = match cond.piece(&start.classes, a0) {
        Ok(pc) => {
            let l = pc.lambda(a0);
            let d = (&l - &lam_fr).amax() / l.amax().max(lam_fr.amax()).max(1e-300);
            (d, cond.trace(&start.classes, a0, a1, 100_000, progress))
        }
        Err(e) => (
            f64::INFINITY,
            RefTrace {
                events: Vec::new(),
                pieces: Vec::new(),
                end_alpha: a0,
                end: Err(format!("start piece: {e}")),
                max_residual: 0.0,
                min_pivot_ratio: 0.0,
                min_separation: f64::INFINITY,
                max_group_spread: 0.0,
            },
        ),
    };
    let ref_secs = t.elapsed().as_secs_f64();
    // The end point: fricont's last piece's end against the reference's last piece solved
    // at the same α (nothing checks it as a transition point).
    let end_diff = match (
        path.pieces().last(),
        reference.pieces.last(),
        &reference.end,
    ) {
        (Some(pc), Some((classes, _, _)), Ok(())) if reason == "window" => {
            let l_fr = DVector::from_column_slice(&pc.lambda_to);
            match cond.piece(classes, pc.alpha_to) {
                Ok(rp) => {
                    let l = rp.lambda(pc.alpha_to);
                    (&l - &l_fr).amax() / l.amax().max(l_fr.amax()).max(1e-300)
                }
                Err(_) => f64::INFINITY,
            }
        }
        _ => 0.0,
    };
    let want = reference.evs();
    let events = compare_events(&fricont, &want, tol);
    let folds = (
        path.events().iter().filter(|e| e.fold).count(),
        reference.events.iter().filter(|e| e.fold).count(),
    );
    Comparison {
        folds,
        fricont,
        fricont_end: (end_alpha, reason),
        fricont_route: route,
        reference,
        start_diff,
        end_diff,
        events,
        seconds: (fr_secs, ref_secs),
    }
}
