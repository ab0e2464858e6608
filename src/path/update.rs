//! Piece matrices by updates of one factorised base (Sherman–Morrison–Woodbury).
//!
//! Consecutive pieces differ in the classes of a few nodes, and the piece matrix
//! `M_S = ∂H/∂λ` of a node's class touches only that node's two rows (ν-row `i`, t-row
//! `p + i`). So, with one base `M_0` factorised by LU (O(m³), m = 2p), every nearby piece
//! is `M_S = M_0 + U V` with `U = [E_1 … E_k]` (`E_j` = the two unit columns of the rows
//! that changed at the j-th update) and `V` the stacked row differences (2k × m). Then
//!
//! ```text
//! M_S⁻¹ b = x0 − Z C⁻¹ V x0,   x0 = M_0⁻¹ b,   Z = M_0⁻¹ U,   C = I + V Z   (2k × 2k)
//! det M_S = det M_0 · det C
//! ```
//!
//! Appending one update costs two solves with the base (O(m²)), 8km dot-product flops for
//! the new border of C, and O(k²) for the bordered inverse of C; a solve costs O(m² + km).
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
use crate::piece::{DenseLu, PieceConstants};

/// Most updates kept on one base before a refactorisation: m/8 (at least 8). The
/// border of C then costs O(m²) per update, like a solve, and a refactorisation
/// (O(m³)) is paid once per ~m/8 transitions.
pub(crate) fn max_updates(m: usize) -> usize {
    (m / 8).max(8)
}

/// A factorised base piece matrix, shared by every update derived from it.
pub(super) struct Base {
    lu: DenseLu,
    /// `M_0⁻¹ [e_i, e_{p+i}]` for node i, computed on first use.
    z: Mutex<HashMap<usize, Arc<[Vec<f64>; 2]>>>,
}

impl Base {
    fn z_of(&self, node: usize, p: usize) -> Arc<[Vec<f64>; 2]> {
        let mut cache = self.z.lock().unwrap_or_else(|e| e.into_inner());
        cache
            .entry(node)
            .or_insert_with(|| {
                // Both columns in one solve: the factor is read once.
                let m = 2 * p;
                let mut e = faer::Mat::<f64>::zeros(m, 2);
                e[(node, 0)] = 1.0;
                e[(p + node, 1)] = 1.0;
                self.lu.solve_mat(e.as_mut());
                Arc::new([
                    e.col(0).iter().copied().collect(),
                    e.col(1).iter().copied().collect(),
                ])
            })
            .clone()
    }
}

/// One rank-2 update: node `node`'s two rows changed by `v` (rows over λ).
struct Update {
    node: usize,
    v: [Vec<f64>; 2],
    z: Arc<[Vec<f64>; 2]>,
}

/// `M_S` for one class vector, as a base plus updates. Cheap to clone (the big arrays are
/// shared).
#[derive(Clone)]
pub(crate) struct UpdatedLu {
    base: Arc<Base>,
    classes: Vec<Class>,
    updates: Vec<Arc<Update>>,
    /// `C⁻¹`, 2k × 2k, column-major.
    cinv: Vec<f64>,
    det_sign: i8,
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

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
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
    /// Factorises `M_S` afresh (O(m³)). `None` if it is exactly singular.
    pub fn factor(c: &PieceConstants<'_>, w: MatRef<'_, f64>, classes: &[Class]) -> Option<Self> {
        let c = &equilibrated(c);
        let lu = DenseLu::new(c.piece_matrix(w, classes).as_ref());
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
            cinv: Vec::new(),
            det_sign,
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
    /// `None` when an update makes C singular (then `M_S` is singular).
    pub fn extend(
        &self,
        c: &PieceConstants<'_>,
        w: MatRef<'_, f64>,
        classes: &[Class],
    ) -> Option<Self> {
        let mut out = self.clone();
        for i in 0..classes.len() {
            if out.classes[i] != classes[i] {
                out.append(c, w, i, classes[i])?;
            }
        }
        Some(out)
    }

    fn append(
        &mut self,
        c: &PieceConstants<'_>,
        w: MatRef<'_, f64>,
        i: usize,
        cls: Class,
    ) -> Option<()> {
        let c = &equilibrated(c);
        let new = node_rows(c, w, i, cls);
        let old = node_rows(c, w, i, self.classes[i]);
        let v = [
            new[0].iter().zip(&old[0]).map(|(a, b)| a - b).collect(),
            new[1].iter().zip(&old[1]).map(|(a, b)| a - b).collect(),
        ];
        let z = self.base.z_of(i, c.p);
        let upd = Update { node: i, v, z };
        let k2 = 2 * self.updates.len();
        // Border of C: b = V_old z_new (k2 × 2), cb = v_new Z_old (2 × k2), d = I + v z.
        let mut bcol = vec![0.0; k2 * 2];
        let mut crow = vec![0.0; 2 * k2];
        for (j, u) in self.updates.iter().enumerate() {
            for a in 0..2 {
                for b in 0..2 {
                    bcol[(2 * j + a) + k2 * b] = dot(&u.v[a], &upd.z[b]);
                    crow[a + 2 * (2 * j + b)] = dot(&upd.v[a], &u.z[b]);
                }
            }
        }
        let mut d = [[0.0; 2]; 2];
        for (a, row) in d.iter_mut().enumerate() {
            for (b, x) in row.iter_mut().enumerate() {
                *x = dot(&upd.v[a], &upd.z[b]) + if a == b { 1.0 } else { 0.0 };
            }
        }
        // Schur complement s = d − cb C⁻¹ b, with y = C⁻¹ b (k2 × 2), x = cb C⁻¹ (2 × k2).
        let ci = |r: usize, col: usize| self.cinv[r + k2 * col];
        let mut y = vec![0.0; k2 * 2];
        let mut x = vec![0.0; 2 * k2];
        for b in 0..2 {
            for r in 0..k2 {
                y[r + k2 * b] = (0..k2).map(|s| ci(r, s) * bcol[s + k2 * b]).sum();
            }
        }
        for a in 0..2 {
            for col in 0..k2 {
                x[a + 2 * col] = (0..k2).map(|s| crow[a + 2 * s] * ci(s, col)).sum();
            }
        }
        let mut s = d;
        for (a, row) in s.iter_mut().enumerate() {
            for (b, e) in row.iter_mut().enumerate() {
                *e -= (0..k2)
                    .map(|r| crow[a + 2 * r] * y[r + k2 * b])
                    .sum::<f64>();
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
        let mut ys = vec![0.0; k2 * 2];
        for r in 0..k2 {
            for b in 0..2 {
                ys[r + k2 * b] = y[r] * si[0][b] + y[r + k2] * si[1][b];
            }
        }
        for col in 0..k2 {
            for r in 0..k2 {
                cinv[r + n2 * col] = ci(r, col) + ys[r] * x[2 * col] + ys[r + k2] * x[1 + 2 * col];
            }
            for a in 0..2 {
                cinv[k2 + a + n2 * col] = -(si[a][0] * x[2 * col] + si[a][1] * x[1 + 2 * col]);
            }
        }
        for b in 0..2 {
            for r in 0..k2 {
                cinv[r + n2 * (k2 + b)] = -ys[r + k2 * b];
            }
            for a in 0..2 {
                cinv[k2 + a + n2 * (k2 + b)] = si[a][b];
            }
        }
        if cinv.iter().any(|v| !v.is_finite()) {
            return None;
        }
        self.cinv = cinv;
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
        let m = self.base.lu.n();
        let mut xm = faer::Mat::<f64>::from_fn(m, bs.len(), |i, c| bs[c][i]);
        self.base.lu.solve_mat(xm.as_mut());
        let k2 = 2 * self.updates.len();
        (0..bs.len())
            .map(|c| {
                let mut x: Vec<f64> = xm.col(c).iter().copied().collect();
                if k2 == 0 {
                    return x;
                }
                let mut vx = vec![0.0; k2];
                for (j, u) in self.updates.iter().enumerate() {
                    vx[2 * j] = dot(&u.v[0], &x);
                    vx[2 * j + 1] = dot(&u.v[1], &x);
                }
                let mut wv = vec![0.0; k2];
                for (col, &v) in vx.iter().enumerate() {
                    if v != 0.0 {
                        for (r, o) in wv.iter_mut().enumerate() {
                            *o += self.cinv[r + k2 * col] * v;
                        }
                    }
                }
                for (j, u) in self.updates.iter().enumerate() {
                    for a in 0..2 {
                        let c = wv[2 * j + a];
                        if c != 0.0 {
                            for (xi, zi) in x.iter_mut().zip(&u.z[a]) {
                                *xi -= c * zi;
                            }
                        }
                    }
                }
                x
            })
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
        let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let finish = |k: usize, solved: Vec<f64>, r: Vec<f64>, wx: Vec<f64>| {
            let x: Vec<f64> = match cols[k].guess {
                Some((x0, _)) => x0.iter().zip(&solved).map(|(a, b)| a + b).collect(),
                None => solved.clone(),
            };
            let denom = row_bound * inf(&x) + inf(&full[k]);
            let rel = if denom > 0.0 {
                inf(&r) / denom
            } else {
                inf(&r)
            };
            Checked {
                rel: if rel.is_finite() { rel } else { f64::INFINITY },
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
    let m = w.nrows();
    let xm = faer::Mat::<f64>::from_fn(m, xs.len(), |i, k| xs[k][i]);
    let mut dm = faer::Mat::<f64>::zeros(m, xs.len());
    faer::linalg::matmul::matmul(
        dm.as_mut(),
        faer::Accum::Replace,
        w,
        xm.as_ref(),
        1.0,
        faer::Par::Seq,
    );
    xs.iter()
        .zip(bs)
        .enumerate()
        .map(|(k, (x, b))| {
            let d: Vec<f64> = dm.col(k).iter().copied().collect();
            let mut r = b.clone();
            for (i, &cls) in classes.iter().enumerate() {
                let [nu, t] = c.equations(i, cls);
                r[i] -= nu.eval(x, &d);
                r[c.p + i] -= t.eval(x, &d);
            }
            (r, d)
        })
        .collect()
}

/// The largest absolute row sum of any piece matrix in `r0` units:
/// `max(r0 ‖W‖∞, 1 + max F)`.
pub(crate) fn row_bound(c: &PieceConstants<'_>, w: MatRef<'_, f64>) -> f64 {
    let c = &equilibrated(c);
    let m = w.nrows();
    let mut wn = 0.0f64;
    for i in 0..m {
        wn = wn.max((0..m).map(|j| w[(i, j)].abs()).sum());
    }
    let fmax = c.friction.iter().fold(0.0f64, |a, &b| a.max(b));
    (c.r * wn).max(1.0 + fmax)
}
