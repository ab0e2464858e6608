//! Transition points of affine loads, and the piece solutions of basis loads, in
//! double-double (mixed-precision refinement).
//!
//! On slender bodies the piece matrices are so ill-conditioned that a transition point
//! solved in double moves by up to ~1e-7 in α (cond · ε). When the problem carries its
//! data beyond double ([`crate::Problem::extended_precision`]: W as `W + W_lo`, q as
//! `q + q_lo`, or exact condensed data), the exit of a straight piece is recomputed from
//! the data in double-double: the piece's point at its entry α and its rate dλ/dα by
//! iterative refinement (residuals of the piece equations in double-double, corrections
//! with the piece's ordinary factorisation, which converges while cond · ε < 1), then
//! every decreasing guard's zero `α_e + s`, `s = −γ(α_e)/γ'`, in double-double, and the
//! first one wins. The double-precision ratio test still decides which guards decrease;
//! only where they cross, and which crosses first, comes from here. Under a basis load
//! the piece's basis solutions `y_j` (see [`super::advance`]) are refined the same way
//! and rounded ([`Path::refine_basis`]); the stepping and the roots then run in double on
//! their combinations, accurate to a few roundings of their terms. The start point is
//! refined under either load.

use faer::MatRef;

use super::*;
use crate::dd::{Dd, sym_gemv_dd};
use crate::dense::mat_mul;
use crate::piece::LinForm;

/// Most refinement rounds of one solve (a piece whose rounds contract by 1e-2 each
/// needed 11 from a first correction of 4.5e-4 of the solution). A round costs one solve
/// and one pass over W, and rounds that stop contracting end the refinement before
/// this: near a fold of the 1201 × 11 strip (F = 5, κ(W) 1.2e11) rates contracting by
/// 0.3–0.5 per round took up to 50 rounds (16 were allowed, and those pieces' exits
/// stayed in double, up to 5e-6 in α off).
const MAX_ROUNDS: usize = 64;
/// A correction this small relative to the solution's scale (max|x| or the data's force
/// scale, see [`Refiner::refine_all`]) ends the refinement, as does one whose successor
/// (predicted from the contraction) is. Where rounds cost anything, the pieces are
/// ill-conditioned (κ ≳ 1e10, each round contracting by κ ε): there the data carried in
/// double-double (W as `W + W_lo`, ~1e-32 of itself) determine the solution only to about
/// κ · 1e-32 ≳ 1e-22 of itself, and a rate that close moves a guard's root by 1e-17 of
/// the piece's length where the guard's slope cancels to 1e-5 of its terms (by 6e-13 of
/// it, 1.3e-16 in α, at the worst seen: a sliding node's tangential displacement on the
/// p = 1920 strip, slope 1.4e-9 against rates of d up to 8.8, on pieces 2e-4 long). It was
/// 1e-24: on the p = 1920 strip (rounds contracting by 5e-6, corrections 1e-7, 5e-13,
/// 4e-18, 2e-23 of the rate) that took a fourth round, a quarter of a transition.
const CONVERGED: f64 = 1e-22;
/// A refinement that stops contracting is kept when its last correction is this small
/// (relative to the solution's scale).
const STALLED: f64 = 1e-20;
/// A correction larger than this (relative to the solution's scale) ends the refinement
/// as failed: the guess, a double-precision solution, is then not within cond · ε of the
/// piece's (garbage from a nearly singular piece). On the p = 1920 strip, cond · ε
/// reaches 1e-4 of λ, and the refinement still contracts by that factor per round; near
/// a fold of the 1201 × 11 strip (F = 5) rates were 1–2.2e-2 off and refined (with 1e-2
/// those pieces' exits stayed in double). A refinement accepted has converged on
/// residuals in double-double, whatever its first step.
const ROUGH: f64 = 0.25;
/// See [`near`].
const NEAR: f64 = 1e-5;
/// A round whose correction is above this fraction of the last one (in the first round:
/// of the solution) makes the rest of the refinement use checked solves (see
/// [`SolveFn`]): plain solves of the updated factorisation contract by κ ε, and the
/// check's second solve then pays for itself only where that is slow, near folds. On the
/// 1201 × 11 strip (F = 5, κ(W) 6.4e10, through its folds) 235 of the first 1500
/// refinements of updated pieces turned to checked solves, and none failed (counted with a
/// scratch counter; no retry with checked solves, no fresh LU).
const SLOW: f64 = 1e-3;

/// A vector in double-double, as its high and low parts.
#[derive(Clone)]
struct DdVec {
    hi: Vec<f64>,
    lo: Vec<f64>,
}

impl DdVec {
    fn from(x: &[f64]) -> Self {
        Self {
            hi: x.to_vec(),
            lo: vec![0.0; x.len()],
        }
    }
    fn get(&self, k: usize) -> Dd {
        Dd {
            hi: self.hi[k],
            lo: self.lo[k],
        }
    }
    fn set(&mut self, k: usize, v: Dd) {
        self.hi[k] = v.hi;
        self.lo[k] = v.lo;
    }
    /// Each entry rounded to double.
    fn rounded(&self) -> Vec<f64> {
        (0..self.hi.len()).map(|k| self.get(k).to_f64()).collect()
    }
}

/// `d = W x + c` in double-double for each pair `(x, c)`: one pass over W for all of
/// them (`W_lo x` in double: it is ~ε of `W x`).
fn gaps_dd(
    w: MatRef<'_, f64>,
    w_lo: Option<MatRef<'_, f64>>,
    pairs: &[(&DdVec, &DdVec)],
) -> Vec<DdVec> {
    let xs: Vec<(&[f64], &[f64])> = pairs.iter().map(|(x, _)| (&x.hi[..], &x.lo[..])).collect();
    let wx = sym_gemv_dd(w, &xs);
    let his: Vec<&[f64]> = pairs.iter().map(|(x, _)| &x.hi[..]).collect();
    let lo = w_lo.map(|wl| mat_mul(wl, &his));
    pairs
        .iter()
        .zip(wx)
        .enumerate()
        .map(|(j, ((_, c), wx))| {
            let mut d = DdVec::from(&vec![0.0; wx.len()]);
            for (k, v) in wx.into_iter().enumerate() {
                let v = match &lo {
                    Some(l) => v.add_f64(l[j][k]),
                    None => v,
                };
                d.set(k, v + c.get(k));
            }
            d
        })
        .collect()
}

/// `form(λ, d)` in double-double.
fn eval_dd(f: &LinForm, lam: &DdVec, d: &DdVec) -> Dd {
    let mut v = Dd::ZERO;
    for t in &f.lam {
        if t.coef != 0.0 {
            v = v + lam.get(t.index).mul_f64(t.coef);
        }
    }
    if f.disp.coef != 0.0 {
        v = v + d.get(f.disp.index).mul_f64(f.disp.coef);
    }
    v
}

/// The piece's solves `b ↦ M_S⁻¹ b` for several columns at once (seed's row scaling),
/// with W times each solution where the solve computed it to check itself. With
/// `checked` (the updated factorisation's solves only), each solve is checked by its
/// residual and refined once in double where that is above rounding level (see
/// [`Refiner::refine_by`]).
type SolveFn<'a> = dyn Fn(&[Vec<f64>], bool) -> (Vec<Vec<f64>>, Option<Vec<Vec<f64>>>) + 'a;
type PieceSolve<'a> = Box<SolveFn<'a>>;

/// What a refinement on one piece needs: the constants, W (both parts), the load's
/// parts in double-double, and the piece's solves.
struct Refiner<'a> {
    c: PieceConstants<'a>,
    w: MatRef<'a, f64>,
    w_lo: Option<MatRef<'a, f64>>,
    classes: &'a [Class],
    solve: PieceSolve<'a>,
    /// Whether `solve` is the piece's updated factorisation (see [`Self::refine_all`]).
    updated: bool,
    /// The load's condensed vectors (high, low): q0 and q1 of an affine load, the q_j of
    /// a basis load.
    q: Vec<(Vec<f64>, Vec<f64>)>,
    gap: &'a [f64],
}

impl Refiner<'_> {
    /// The constant of d at α: `q0 + α q1 − (g, 0)` in double-double.
    fn point_constant(&self, alpha: f64) -> DdVec {
        let m = self.w.nrows();
        let ((q0, q0_lo), (q1, q1_lo)) = (&self.q[0], &self.q[1]);
        let mut out = DdVec::from(&vec![0.0; m]);
        for k in 0..m {
            let mut v = Dd::prod(alpha, q1[k]).add_f64(q0[k]);
            v = v.add_f64(q0_lo[k] + alpha * q1_lo[k]);
            if k < self.c.p {
                v = v.add_f64(-self.gap[k]);
            }
            out.set(k, v);
        }
        out
    }

    /// The constant of d at α under a basis load with weights `w` (at α):
    /// `Σ_j w_j q_j − (g, 0)` in double-double; with `gap` false, without the gap.
    fn basis_constant(&self, w: &[f64], gap: bool) -> DdVec {
        let m = self.w.nrows();
        let mut out = DdVec::from(&vec![0.0; m]);
        for k in 0..m {
            let mut v = if gap && k < self.c.p {
                Dd::new(-self.gap[k], 0.0)
            } else {
                Dd::ZERO
            };
            for (wj, (q, q_lo)) in w.iter().zip(&self.q) {
                if *wj != 0.0 {
                    v = v + Dd::prod(*wj, q[k]).add_f64(wj * q_lo[k]);
                }
            }
            out.set(k, v);
        }
        out
    }

    /// Each of a basis load's solutions `ys` (`y_1 … y_J, y_g`, see [`Path::refine_basis`])
    /// with the constant of its d: `q_j`, and the gap's `−(g, 0)` for `y_g`. None where
    /// `ys` is not one per basis vector and one for the gap.
    fn basis_pairs(&self, ys: &[Vec<f64>]) -> Option<Vec<(DdVec, DdVec)>> {
        let k = self.q.len();
        (ys.len() == k + 1).then(|| {
            ys.iter()
                .enumerate()
                .map(|(j, y)| {
                    let mut e = vec![0.0; k];
                    if j < k {
                        e[j] = 1.0;
                    }
                    (DdVec::from(y), self.basis_constant(&e, j == k))
                })
                .collect()
        })
    }

    /// The constant of d's rate: `q1` in double-double.
    fn rate_constant(&self) -> DdVec {
        let (q1, q1_lo) = &self.q[1];
        DdVec {
            hi: q1.clone(),
            lo: q1_lo.clone(),
        }
    }

    /// The force scale of the solutions of `W x + c = d` on the piece: `r0 ‖c‖∞`, the
    /// size the rounding of a double-precision solve is relative to (with max|x|, see
    /// [`Self::refine_all`]).
    fn floor(&self, c: &DdVec) -> f64 {
        self.c.r0 * inf_norm(&c.hi)
    }

    /// Refines each `(x, c)` pair from its double-precision guess to `(x, d = W x + c)`:
    /// residuals `H(x, d)` of the piece equations in double-double and corrections by the
    /// piece's solves, all pairs in lockstep (one pass over the factor and one over W per
    /// round for all of them); d is kept up to date by `W δ` in double (δ is small: its
    /// rounding is ~ε of δ, far below the target). None when one does not converge.
    ///
    /// The corrections are measured against max|x| or, where that is smaller, the force
    /// scale of the data ([`Self::floor`]): a double-precision solve is off by cond · ε of
    /// that scale, not of x. Near a point where every contact force vanishes (the last
    /// node of a body lifting off), x goes to zero while its double-precision guess keeps
    /// that error: measured against max|x|, the first correction (5.7e-8 against a guess
    /// of 5.7e-8, under a general load on a slender strip, F = 5) failed the refinement,
    /// the march kept the double-precision points, and the lift-off came 1.1e-8 in α
    /// early. Only the first round's test, whose correction stands for the contraction,
    /// stays relative to max|x| (a tiny x then takes more rounds).
    ///
    /// Where the piece's solves are its updated factorisation, the refinement starts with
    /// plain solves and turns to checked ones at the first slow round (see [`SLOW`]);
    /// where it fails, it is tried again with checked solves from the start, and then
    /// with a fresh LU of the piece matrix (O(m³), once): an updated solve is a poorer
    /// approximate inverse on a nearly singular piece (near a fold of the 1201 × 11 strip,
    /// F = 5, rate corrections of 2.0e-2 and then 2.7e-2 did not contract where a fresh
    /// LU's did, and the exit kept in double, 2e-5 in α off, made the path turn back at a
    /// fold it does not have).
    fn refine_all(&self, pairs: Vec<(DdVec, DdVec)>) -> Option<Vec<(DdVec, DdVec)>> {
        self.refine_all_known(pairs, &[])
    }

    /// [`Self::refine_all`], where `known[j]` (when given) is pair j's `d = W x + c`
    /// already, in double-double (see [`CarriedPoint`]): its product with W is skipped.
    fn refine_all_known(
        &self,
        pairs: Vec<(DdVec, DdVec)>,
        known: &[Option<DdVec>],
    ) -> Option<Vec<(DdVec, DdVec)>> {
        if !self.updated {
            return self.refine_by(&self.solve, pairs, known, true);
        }
        self.refine_by(&self.solve, pairs.clone(), known, false)
            .or_else(|| self.refine_by(&self.solve, pairs.clone(), known, true))
            .or_else(|| {
                let lu = DenseLu::new(self.c.piece_matrix(self.w, self.classes).as_ref());
                let fresh = |bs: &[Vec<f64>], _| (bs.iter().map(|b| lu.solve(b)).collect(), None);
                self.refine_by(&fresh, pairs, known, true)
            })
    }

    /// [`Self::refine_all_known`] with the piece's solves `solve`, checked ones from the
    /// first round with `checked`, else from the first round that contracts by less than
    /// [`SLOW`].
    fn refine_by(
        &self,
        solve: &SolveFn<'_>,
        pairs: Vec<(DdVec, DdVec)>,
        known: &[Option<DdVec>],
        mut checked: bool,
    ) -> Option<Vec<(DdVec, DdVec)>> {
        let floors: Vec<f64> = pairs.iter().map(|(_, c)| self.floor(c)).collect();
        let known_d = |j: usize| known.get(j).and_then(|d| d.as_ref());
        let refs: Vec<(&DdVec, &DdVec)> = (0..pairs.len())
            .filter(|&j| known_d(j).is_none())
            .map(|j| (&pairs[j].0, &pairs[j].1))
            .collect();
        let mut ds = gaps_dd(self.w, self.w_lo, &refs).into_iter();
        let mut xs: Vec<(DdVec, DdVec)> = Vec::with_capacity(pairs.len());
        for (j, (x, _)) in pairs.into_iter().enumerate() {
            let d = match known_d(j) {
                Some(d) => d.clone(),
                None => ds.next()?,
            };
            xs.push((x, d));
        }
        let (c, m) = (&self.c, self.w.nrows());
        let mut last = vec![f64::INFINITY; xs.len()];
        let mut done = vec![false; xs.len()];
        for _ in 0..MAX_ROUNDS {
            let active: Vec<usize> = (0..xs.len()).filter(|&j| !done[j]).collect();
            if active.is_empty() {
                return Some(xs);
            }
            let rs: Vec<Vec<f64>> = active
                .iter()
                .map(|&j| {
                    let (x, d) = &xs[j];
                    let mut r = vec![0.0; m];
                    for (i, &cls) in self.classes.iter().enumerate() {
                        let [nu, t] = c.equations(i, cls);
                        r[i] = -eval_dd(&nu, x, d).to_f64();
                        r[c.p + i] = -eval_dd(&t, x, d).to_f64();
                    }
                    r
                })
                .collect();
            // (W δ from the checked solve's own residual where it has it)
            let (dxs, wdxs) = solve(&rs, checked);
            let wdx = match wdxs {
                Some(w) if w.len() == dxs.len() => w,
                _ => mat_mul(self.w, &dxs.iter().map(|v| &v[..]).collect::<Vec<_>>()),
            };
            for ((&j, dx), wdx) in active.iter().zip(&dxs).zip(wdx) {
                let (x, d) = &mut xs[j];
                let size = inf_norm(&x.hi);
                let scale = size.max(floors[j]);
                let step = inf_norm(dx);
                // The guess is a double-precision solution: a correction beyond ROUGH of
                // it means a piece matrix too ill-conditioned for refinement in double
                // (its solves amplify rounding to that size), not a better point.
                if !step.is_finite() || step > ROUGH * scale {
                    return None;
                }
                for (k, v) in dx.iter().enumerate() {
                    let s = x.get(k).add_f64(*v);
                    x.set(k, s);
                }
                for (k, v) in wdx.into_iter().enumerate() {
                    let s = d.get(k).add_f64(v);
                    d.set(k, s);
                }
                // Converged when this correction, or the next one predicted from the
                // contraction so far (step² / last), is below the target. After the first
                // round the contraction is taken to be that round's correction relative to
                // the solution, step² / size (a double-precision solve is off by about
                // cond · ε of it, and each round contracts by about cond · ε), so a first
                // round ends the refinement only where the correction is within about
                // √CONVERGED (1e-11) of the solution. It used to end it where the
                // correction was within 1e-4: on two stacked blocks (p = 640, F = 0.3,
                // κ(W) = 2.3e7) a rate corrected by 5.7e-7 of itself in one round kept
                // enough error to move the slope of a guard that is a small difference of
                // large terms (a node's tangential displacement, 3.3e-6 per unit α against
                // displacements of 1.4), and the exit at the end of that piece lay up to
                // 3.1e-7 in α off where copies of the problem with rows scaled by other
                // factors put it (double alone: 5e-10). With a second round every copy
                // agrees to the last bit. (Before, taking every first round as enough, a
                // rate corrected by 4.5e-4 of itself on a slender strip kept 4.3e-6 of error
                // and its exit was 4.7e-9 in α off the independent reference.)
                let before = if last[j].is_finite() { last[j] } else { size };
                checked |= step > SLOW * before;
                let predicted = step * (step / before) <= CONVERGED * scale;
                if step <= CONVERGED * scale || predicted {
                    done[j] = true;
                } else if step > 0.5 * last[j] {
                    // Refinement that stopped contracting has reached what the residual
                    // in double-double can resolve (~cond · ε²): accepted where that is
                    // still far beyond double.
                    if step > STALLED * scale {
                        return None;
                    }
                    done[j] = true;
                }
                last[j] = step;
            }
        }
        done.iter().all(|&d| d).then_some(xs)
    }
}

/// A straight piece refined in double-double ([`Path::refine_piece`]): its point at the
/// entry α and its rate dλ/dα, each with its d, and the four rounded to double (in that
/// order).
#[derive(Clone)]
pub(super) struct RefinedPiece {
    lam_e: DdVec,
    d_e: DdVec,
    lam_1: DdVec,
    d_1: DdVec,
    pub(super) rounded: [Vec<f64>; 4],
    /// Pieces since `d_e` came from a product with W in double-double (0: this one's; see
    /// [`CarriedPoint`]).
    hops: usize,
}

/// The exit point of a refined straight piece on its line in double-double, `λ_e + s λ'`
/// with its `d_e + s d'` (`s = α − α_e` exact), at the exit's α rounded to double: d is
/// `W λ + q(α) − (g, 0)` there to the rounding of those sums, so the next piece's point is
/// refined from it without a product with W in double-double (of its two per piece, the
/// costlier part of a trace in extended precision). Every [`CARRY_REFRESH`]-th piece
/// computes that product afresh, so the carried sums' rounding (~1e-32 of their terms per
/// piece) cannot build up.
#[derive(Clone)]
pub(super) struct CarriedPoint {
    alpha: f64,
    lam: DdVec,
    d: DdVec,
    hops: usize,
}

/// See [`CarriedPoint`].
const CARRY_REFRESH: usize = 8;

impl CarriedPoint {
    /// λ and d of the point, rounded to double.
    pub(super) fn rounded(&self) -> (Vec<f64>, Vec<f64>) {
        (self.lam.rounded(), self.d.rounded())
    }
}

impl RefinedPiece {
    /// The point on the refined line at `alpha` (the piece entered at `alpha_e`), to be
    /// carried to the next piece (see [`CarriedPoint`]).
    pub(super) fn carried_at(&self, alpha_e: f64, alpha: f64) -> CarriedPoint {
        let s = along_from(alpha_e, alpha);
        CarriedPoint {
            alpha,
            lam: on_line(&self.lam_e, &self.lam_1, s),
            d: on_line(&self.d_e, &self.d_1, s),
            hops: self.hops + 1,
        }
    }

    /// λ on the refined line at `alpha` (the piece entered at `alpha_e`), rounded to
    /// double: `λ_e + (α − α_e) λ'` in double-double, the difference of the two α exact.
    pub(super) fn lam_at(&self, alpha_e: f64, alpha: f64) -> Vec<f64> {
        self.lam_along(along_from(alpha_e, alpha))
    }

    /// λ on the refined line `s` along α from its entry, `λ_e + s λ'` in double-double,
    /// rounded to double.
    fn lam_along(&self, s: Dd) -> Vec<f64> {
        let lam = on_line(&self.lam_e, &self.lam_1, s);
        (0..lam.hi.len()).map(|k| lam.get(k).to_f64()).collect()
    }
}

/// `α − α_e`, exact in double-double.
fn along_from(alpha_e: f64, alpha: f64) -> Dd {
    let (hi, lo) = crate::dd::two_sum(alpha, -alpha_e);
    Dd::new(hi, lo)
}

/// `x + s dx` in double-double.
fn on_line(x: &DdVec, dx: &DdVec, s: Dd) -> DdVec {
    let mut out = DdVec::from(&vec![0.0; x.hi.len()]);
    for k in 0..x.hi.len() {
        out.set(k, x.get(k) + dx.get(k) * s);
    }
    out
}

/// A double-double point `lam2` is taken for the double-precision one `lam` without
/// further checks only where the two lie within [`NEAR`] of each other (relative to
/// max|λ|, or to `floor` where that is larger: the force scale of the data, see
/// [`Refiner::refine_all`]): what double precision gets wrong on a slender body is ~1e-7
/// (in α, and so in λ along the piece) on most pieces, up to 5e-5 near the folds of the
/// 1201 × 11 strip (F = 5). A larger move may mean a piece whose point is ill-determined:
/// the double point, found with the tracer's own checks, is kept, except by
/// [`Path::polish_point`] and [`Path::refine_basis`] where the refined point solves the
/// piece from the data at least as well, or within a solve's check.
pub(super) fn near(lam2: &[f64], lam: &[f64], floor: f64) -> bool {
    let dl: Vec<f64> = lam2.iter().zip(lam).map(|(x, y)| x - y).collect();
    // (a NaN anywhere makes the norms NaN: not near)
    inf_norm(&dl) <= NEAR * inf_norm(lam).max(floor)
}

impl Path {
    /// The [`Refiner`] of the piece `classes`, solved by its updated factorisation
    /// `updated` where given, else by a fresh LU of its matrix; None when the problem is
    /// not carried beyond double (see the module doc).
    fn refiner<'a>(
        &mut self,
        problem: &'a Problem,
        classes: &'a [Class],
        updated: Option<&'a update::UpdatedLu>,
    ) -> Option<Refiner<'a>> {
        if !self.problem.extended_precision() {
            return None;
        }
        let m = 2 * problem.p();
        let c = PieceConstants::of(problem);
        let del = problem.delassus();
        let q: Vec<(Vec<f64>, Vec<f64>)> = if self.load.is_affine() {
            // q(α) = q0 + α q1 exactly from its parts (q(0) is q0 itself).
            let (q0, q1) = self.load.q(0.0, del).ok()?;
            let (q0_lo, q1_lo) = match self.load.affine_lo() {
                Some((a, b)) => (a.to_vec(), b.to_vec()),
                None => (vec![0.0; m], vec![0.0; m]),
            };
            vec![(q0, q0_lo), (q1, q1_lo)]
        } else if let Some(qs) = self.load.basis_vectors() {
            let lo = self.load.q_lo()?;
            qs.iter().cloned().zip(lo.iter().cloned()).collect()
        } else {
            // A general load: q at the α of its last evaluation, the one basis vector.
            let (q, lo) = self.load.general_q_lo()?;
            vec![(q.to_vec(), lo.to_vec())]
        };
        let w = del.w();
        let row_bound = self.row_bound();
        let solve: PieceSolve<'a> = match updated {
            // Checked solves (each refined once in double where its residual is above
            // rounding level) contract by about (κ ε)² per outer round, not κ ε, on
            // pieces near the limit of double precision; plain ones cost half as much
            // where the check would refine (a quarter of the columns on the p = 480
            // strip) and contract as fast elsewhere.
            Some(u) => Box::new(move |bs: &[Vec<f64>], checked: bool| {
                if !checked {
                    return (u.solve_many(&c, bs), None);
                }
                let cols: Vec<update::Rhs<'_>> =
                    bs.iter().map(|b| update::Rhs { b, guess: None }).collect();
                let (xs, wxs) = u
                    .solve_checked_many(&c, w, &cols, row_bound)
                    .into_iter()
                    .map(|k| (k.x, k.wx))
                    .unzip();
                (xs, Some(wxs))
            }),
            None => {
                let lu = DenseLu::new(c.piece_matrix(w, classes).as_ref());
                Box::new(move |bs: &[Vec<f64>], _| (bs.iter().map(|b| lu.solve(b)).collect(), None))
            }
        };
        Some(Refiner {
            c,
            w,
            w_lo: del.w_lo(),
            classes,
            solve,
            updated: updated.is_some(),
            q,
            gap: problem.gap_equilibrated(),
        })
    }

    /// The basis solutions `y_1 … y_J, y_g` of the piece `cur` under a basis load (see
    /// [`super::advance::BasisSolutions`]) refined in double-double from their
    /// double-precision solves `ys`, each rounded with `W y` (itself from `d = W y + c` in
    /// double-double). A combination of them is then accurate to a few roundings of its
    /// terms, where one of double-precision solves is off by cond · ε. None when the
    /// problem is not carried beyond double, the refinement does not converge, or it lands
    /// farther from a solve than [`near`] allows and its rounding does not solve the
    /// piece's equations from the data within a solve's check (relative residual 1e-12,
    /// one product with W for all such): the caller keeps the solves. (Near the folds of
    /// the 1201 × 11 strip, F = 5, refined solutions 2.8–5.2e-5 of max|y| from the solves
    /// were dropped, and under a basis load of the affine path's weights the strip with
    /// its rows scaled left that path at its 589th event.)
    pub(super) fn refine_basis(
        &mut self,
        cur: &CurrentPiece,
        ys: &[Vec<f64>],
    ) -> Option<Vec<(Vec<f64>, Vec<f64>)>> {
        let m = 2 * self.problem.p();
        let problem = self.problem.clone();
        let r = self.refiner(&problem, &cur.classes, cur.lu.updated())?;
        let k = r.q.len();
        let pairs = r.basis_pairs(ys)?;
        let consts: Vec<DdVec> = pairs.iter().map(|(_, c)| c.clone()).collect();
        let refined = r.refine_all(pairs)?;
        let mut out = Vec::with_capacity(k + 1);
        let mut far = Vec::new();
        for (j, ((x, d), (c, y))) in refined.iter().zip(consts.iter().zip(ys)).enumerate() {
            let yr: Vec<f64> = (0..m).map(|i| x.get(i).to_f64()).collect();
            let wy: Vec<f64> = (0..m).map(|i| (d.get(i) - c.get(i)).to_f64()).collect();
            if !yr.iter().chain(&wy).all(|v| v.is_finite()) {
                return None;
            }
            if !near(&yr, y, r.floor(c)) {
                far.push(j);
            }
            out.push((yr, wy));
        }
        if !far.is_empty() {
            let c = self.consts();
            let rhs = self.basis_rhs(&cur.classes)?;
            let cols: Vec<&[f64]> = far.iter().map(|&j| &out[j].0[..]).collect();
            let wys = mat_mul(problem.delassus().w(), &cols);
            let rb = self.row_bound();
            for (&j, wy) in far.iter().zip(&wys) {
                let (y, b) = (&out[j].0, &rhs[j]);
                let res = update::residual_rows(&c, &cur.classes, y, wy, b);
                let rel = update::relative_residual(&c, &cur.classes, &res, y, b, rb);
                if rel.is_nan() || rel > 1e-12 {
                    return None;
                }
            }
        }
        Some(out)
    }

    /// λ on the graph piece `classes` (solved by `lu`) at α, refined in double-double
    /// from the guess `lam` and rounded, with its `d = W λ + q(α) − (g, 0)` (from the
    /// double-double one): the start point, and each point of a general load's march.
    /// None as for [`Self::refiner`], when the refinement does not converge, or when it
    /// lands farther from `lam` than [`near`] allows and solves the piece's equations
    /// from the data (q(α) to double-double accuracy, rounded) less well than `lam`
    /// (relative residuals, one product with W each; a residual up to 1e-12 always
    /// passes).
    pub(super) fn polish_point(
        &mut self,
        classes: &[Class],
        lu: &PieceSolver,
        alpha: f64,
        lam: &[f64],
    ) -> Option<(Vec<f64>, Vec<f64>)> {
        self.polish_point_by(classes, lu.updated(), alpha, lam)
    }

    /// [`Self::polish_point`] with the piece solved by its updated factorisation
    /// `updated` where given, else by a fresh LU of its matrix.
    pub(super) fn polish_point_by(
        &mut self,
        classes: &[Class],
        updated: Option<&update::UpdatedLu>,
        alpha: f64,
        lam: &[f64],
    ) -> Option<(Vec<f64>, Vec<f64>)> {
        let problem = self.problem.clone();
        if !self.load.is_affine() {
            // A basis load's weights at α, a general load's q(α) (the refiner's).
            self.load.q(alpha, problem.delassus()).ok()?;
        }
        let r = self.refiner(&problem, classes, updated)?;
        let c = if self.load.is_affine() {
            r.point_constant(alpha)
        } else if self.load.basis_vectors().is_some() {
            r.basis_constant(self.load.weights_at(alpha)?.0, true)
        } else {
            r.basis_constant(&[1.0], true)
        };
        // The data the points are measured against: q(α) − (g, 0) to double-double
        // accuracy, rounded (the double q of a general load is a solve with A, off by
        // up to κ(A) ε).
        let qg: Vec<f64> = (0..c.hi.len()).map(|k| c.get(k).to_f64()).collect();
        let floor = r.floor(&c);
        let (x, d) = r.refine_all(vec![(DdVec::from(lam), c)])?.pop()?;
        let out: Vec<f64> = (0..x.hi.len()).map(|k| x.get(k).to_f64()).collect();
        let d: Vec<f64> = (0..d.hi.len()).map(|k| d.get(k).to_f64()).collect();
        if !out.iter().chain(&d).all(|v| v.is_finite()) {
            return None;
        }
        if near(&out, lam, floor) {
            return Some((out, d));
        }
        // Farther from the double-precision point than `near` allows: taken where it
        // solves the piece from the data at least as well as that point (their relative
        // residuals in double, one product with W each). The double point of a nearly
        // singular piece can be that far off (4e-5 of max|λ| on a slip piece of a
        // slender body entered 3e-5 in α before its next transition: its node then fit
        // no class at that transition, where the refined points trace through); a
        // refinement that "converged" to a non-solution (a garbage first step) leaves a
        // residual of order one. Against the double q of a general load, the double
        // point (solved from it) had the smaller residual near a fold of a slender body
        // (2e-11 against 6e-11), though 1e-5 of max|λ| off.
        let (rel, _, _) = self.point_residual(classes, &qg, &out);
        let (rel_double, _, _) = self.point_residual(classes, &qg, lam);
        (rel <= rel_double.max(1e-12)).then_some((out, d))
    }

    /// The straight piece `cur` (affine load, α moving) refined in double-double: its
    /// point at the entry α (from the piece's own point `cur.xp`, else the transition
    /// point) and its rate dλ/dα, each with its d. None when the problem is not carried
    /// beyond double, the piece is vertical, or the refinement does not converge (the
    /// piece is too ill-conditioned even for it): the caller then works in double.
    pub(super) fn refine_piece(&mut self, cur: &CurrentPiece) -> Option<RefinedPiece> {
        if !self.load.is_affine() || cur.scales.is_vertical(&cur.t) {
            return None;
        }
        let m = 2 * self.problem.p();
        let problem = self.problem.clone();
        let r = self.refiner(&problem, &cur.classes, cur.lu.updated())?;
        let start = match &cur.xp {
            Some(xp) => xp.to_vec(),
            None => cur.lam.clone(),
        };
        let ta = cur.t[m];
        let rate0: Vec<f64> = cur.t[..m].iter().map(|v| v / ta).collect();
        // The last piece's exit on its refined line where this piece starts there, with
        // its d (see CarriedPoint; every CARRY_REFRESH-th piece d afresh from W); else the
        // piece's own point in double.
        let carried = self
            .carried
            .as_ref()
            .filter(|cp| cp.alpha == cur.alpha)
            .cloned();
        let refine = |x0: DdVec, d0: Option<DdVec>| {
            r.refine_all_known(
                vec![
                    (x0, r.point_constant(cur.alpha)),
                    (DdVec::from(&rate0), r.rate_constant()),
                ],
                &[d0],
            )
        };
        // From the piece's own point in double where nothing is carried, or where the
        // refinement from the carried point fails.
        let from_start = || refine(DdVec::from(&start), None).map(|v| (v, 0));
        let refined = match carried {
            Some(cp) => {
                // The refresh recomputes d from the carried λ. (It used to start from the
                // piece's point in double, 1e-7 off on the p = 1920 strip, refined to the
                // target only, where the carried λ is within a rounding of the last line:
                // a guard that is a small difference of large terms, a sliding node's
                // tangential displacement of 2.9e-13 there with a slope of 1.4e-9 against
                // rates of d up to 8.8, takes its root from the point's last digits.)
                let (mut lam, mut d) = (cp.lam, (cp.hops < CARRY_REFRESH).then_some(cp.d));
                let hops = if d.is_some() { cp.hops } else { 0 };
                // A node open on this piece has λ = 0 exactly, as its solves give it: on
                // the last line a node that opens here is at its root, within rounding of
                // zero (a carried d then corrected by W times the change, O(m) per row).
                let p = self.problem.p();
                let open = (0..p).filter(|&i| cur.classes[i] == Class::Open);
                for row in open.flat_map(|i| [i, p + i]) {
                    let v = lam.get(row).to_f64();
                    if v != 0.0 || lam.lo[row] != 0.0 {
                        lam.set(row, Dd::ZERO);
                        if let Some(d) = d.as_mut() {
                            for (k, wk) in r.w.col(row).iter().enumerate() {
                                d.set(k, d.get(k).add_f64(-wk * v));
                            }
                        }
                    }
                }
                refine(lam, d).map(|v| (v, hops)).or_else(from_start)
            }
            None => from_start(),
        };
        let (refined, hops) = refined?;
        let mut refined = refined.into_iter();
        let (lam_e, d_e) = refined.next()?;
        let (lam_1, d_1) = refined.next()?;
        let rounded = [
            lam_e.rounded(),
            d_e.rounded(),
            lam_1.rounded(),
            d_1.rounded(),
        ];
        rounded
            .iter()
            .all(|v| v.iter().all(|x| x.is_finite()))
            .then_some(RefinedPiece {
                lam_e,
                d_e,
                lam_1,
                d_1,
                rounded,
                hops,
            })
    }

    /// In extended precision, the α where each of `forms` (guards of the straight piece
    /// `cur`) reaches zero on the piece's line refined in double-double (`λ_e + (α − α_e)
    /// λ'`, its d likewise), rounded to double: None for a form constant along the piece.
    /// None (for all) as for [`Self::refine_piece`]. The line is the one the piece's exit
    /// was refined on where that is kept (see `Path::refined`): at p = 1920 on the strips,
    /// half of the transition points have such forms, and refining their piece again
    /// (four solves and a product with W in double-double) was a third of a transition.
    pub(super) fn refined_roots(
        &mut self,
        cur: &CurrentPiece,
        forms: &[LinForm],
    ) -> Option<Vec<Option<f64>>> {
        let r = match self.refined.take() {
            Some((alpha, classes, r)) if alpha == cur.alpha && classes == cur.classes => r,
            _ => self.refine_piece(cur)?,
        };
        Some(
            forms
                .iter()
                .map(|f| {
                    let v = eval_dd(f, &r.lam_e, &r.d_e);
                    let slope = eval_dd(f, &r.lam_1, &r.d_1);
                    let alpha = (-v).div(slope).add_f64(cur.alpha).to_f64();
                    (slope.hi != 0.0 && alpha.is_finite()).then_some(alpha)
                })
                .collect(),
        )
    }

    /// [`Self::refined_roots`] under a basis load: each form's value and slope at `alpha`
    /// on the piece from its basis solutions refined in double-double (`Σ_j w_j G_j + G_g`
    /// and `Σ_j w'_j G_j`, G the form on each solution), and its root one Newton step
    /// from `alpha`, rounded to double. None (for all) where the solutions are not
    /// refined.
    pub(super) fn refined_basis_roots(
        &mut self,
        cur: &CurrentPiece,
        alpha: f64,
        forms: &[LinForm],
    ) -> Option<Vec<Option<f64>>> {
        let (ys, _) = self.basis_solves(cur)?;
        let problem = self.problem.clone();
        let r = self.refiner(&problem, &cur.classes, cur.lu.updated())?;
        let k = r.q.len();
        let refined = r.refine_all(r.basis_pairs(&ys)?)?;
        let (w, dw) = self.load.weights_at(alpha)?;
        Some(
            forms
                .iter()
                .map(|f| {
                    let (mut v, mut slope) = (Dd::ZERO, Dd::ZERO);
                    for (j, (x, d)) in refined.iter().enumerate() {
                        let g = eval_dd(f, x, d);
                        if j < k {
                            v = v + g.mul_f64(w[j]);
                            slope = slope + g.mul_f64(dw[j]);
                        } else {
                            v = v + g;
                        }
                    }
                    let root = alpha + (-v).div(slope).to_f64();
                    (slope.hi != 0.0 && root.is_finite()).then_some(root)
                })
                .collect(),
        )
    }

    /// The exit of the refined straight piece `r` of `cur` through the first of
    /// `decreasing` to reach zero, in double-double: `(λ, α, guard)` rounded to double.
    /// None when no guard of `decreasing` decreases in double-double or the exit lies
    /// outside the window: the caller then keeps its double-precision point.
    pub(super) fn polish_exit(
        &self,
        cur: &CurrentPiece,
        r: &RefinedPiece,
        decreasing: &[Guard],
    ) -> Option<(Vec<f64>, f64, Guard)> {
        let m = 2 * self.problem.p();
        let c = self.consts();
        let alpha_e = cur.alpha;
        let ta = cur.t[m];
        let dir = if ta > 0.0 { 1.0 } else { -1.0 };
        // Every decreasing guard's zero, s = −γ(α_e)/γ' (α − α_e = s, with the sign of
        // the direction of travel).
        let mut best: Option<(Dd, Guard)> = None;
        for &g in decreasing {
            let f = c.guard_form(g);
            let v = eval_dd(&f, &r.lam_e, &r.d_e);
            let slope = eval_dd(&f, &r.lam_1, &r.d_1);
            if dir * slope.hi >= 0.0 {
                continue;
            }
            let mut s = (-v).div(slope);
            if dir * s.hi < 0.0 {
                s = Dd::ZERO;
            }
            if best.is_none_or(|(b, _)| dir * (s - b).hi < 0.0) {
                best = Some((s, g));
            }
        }
        let (s, g) = best?;
        let alpha = s.add_f64(alpha_e).to_f64();
        let (lo, hi) = self.window();
        if !(lo..=hi).contains(&alpha) {
            return None;
        }
        let lam = r.lam_along(s);
        (alpha.is_finite() && lam.iter().all(|v| v.is_finite())).then_some((lam, alpha, g))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ProblemBuilder;
    use std::cell::Cell;

    type Counted = (Option<Vec<f64>>, Vec<f64>, usize, usize);

    /// A refiner of the sticking piece of a 3-node condensed problem (W symmetric positive
    /// definite, affine load), whose solves are `lu.solve(b)` times `plain` where the
    /// refinement asks for plain solves and exact ones where it asks for checked solves,
    /// counting both; the pair to refine is the point at α = 0.3, off by 1e-6 of itself.
    /// Returns the refined point (rounded), the point solved in double, and the numbers of
    /// plain and checked solves. With `start_plain`, as the path refines (plain solves
    /// first), else checked solves from the first round.
    fn refine_counting(plain: f64, start_plain: bool) -> Counted {
        let p = 3;
        let w = faer::Mat::<f64>::from_fn(2 * p, 2 * p, |i, j| {
            let (a, b) = (i.min(j) as f64, i.max(j) as f64);
            if i == j {
                4.0 + a
            } else {
                0.3 * (1.0 + a + 2.0 * b).sin()
            }
        });
        let problem = ProblemBuilder::condensed(w)
            .friction_uniform(0.5)
            .build()
            .expect("problem");
        let classes = vec![Class::Stick; p];
        let c = PieceConstants::of(&problem);
        let w = problem.delassus().w();
        let q0: Vec<f64> = (0..2 * p).map(|k| 0.1 * (k as f64 + 1.0).cos()).collect();
        let q1: Vec<f64> = (0..2 * p).map(|k| 0.2 * (k as f64 * 0.7).sin()).collect();
        let lu = DenseLu::new(c.piece_matrix(w, &classes).as_ref());
        let (plain_calls, checked_calls) = (Cell::new(0), Cell::new(0));
        let solve = |bs: &[Vec<f64>], checked: bool| {
            let (calls, f) = if checked {
                (&checked_calls, 1.0)
            } else {
                (&plain_calls, plain)
            };
            calls.set(calls.get() + 1);
            let xs = bs
                .iter()
                .map(|b| lu.solve(b).into_iter().map(|v| v * f).collect())
                .collect();
            (xs, None)
        };
        let r = Refiner {
            c,
            w,
            w_lo: None,
            classes: &classes,
            solve: Box::new(solve),
            updated: true,
            q: vec![(q0, vec![0.0; 2 * p]), (q1, vec![0.0; 2 * p])],
            gap: problem.gap_equilibrated(),
        };
        // Sticking: d = W λ + q(α) − (g, 0) = 0 (g = 0 here), so λ = −W⁻¹ q(α), solved
        // here in double with an LU of W itself.
        let cst = r.point_constant(0.3);
        let minus_q: Vec<f64> = (0..2 * p).map(|k| -cst.get(k).to_f64()).collect();
        let exact = DenseLu::new(w).solve(&minus_q);
        let guess: Vec<f64> = exact.iter().map(|v| v * (1.0 + 1e-6)).collect();
        let pairs = vec![(DdVec::from(&guess), cst)];
        let out = if start_plain {
            r.refine_all_known(pairs, &[])
        } else {
            r.refine_by(&r.solve, pairs, &[], true)
        };
        let x = out.map(|mut v| v.pop().expect("one pair").0.rounded());
        (x, exact, plain_calls.get(), checked_calls.get())
    }

    #[test]
    fn a_slowly_contracting_refinement_turns_to_checked_solves() {
        // Plain solves 10% too long contract by 0.1 per round: the first correction is
        // 1.1e-6 of the point, the second 1/10 of the first, slower than SLOW, and the
        // rest are checked (exact here). Without the turn, plain rounds would go on for
        // about 16 rounds.
        let (x, exact, plain, checked) = refine_counting(1.1, true);
        let x = x.expect("converges");
        let scale = inf_norm(&exact);
        for (a, b) in x.iter().zip(&exact) {
            assert!((a - b).abs() <= 1e-13 * scale, "{a} vs {b}");
        }
        assert!(plain <= 2, "{plain} plain solves");
        assert!(checked >= 1, "{checked} checked solves");
    }

    #[test]
    fn a_failed_plain_refinement_is_retried_with_checked_solves() {
        // Plain solves of the wrong sign double the guess's error: the second correction
        // is twice the first and the refinement fails (it stopped contracting). It is
        // retried with checked solves, before a fresh LU (which would leave the checked
        // count at 0).
        let (x, exact, plain, checked) = refine_counting(-1.0, true);
        let x = x.expect("converges");
        let scale = inf_norm(&exact);
        for (a, b) in x.iter().zip(&exact) {
            assert!((a - b).abs() <= 1e-13 * scale, "{a} vs {b}");
        }
        assert!(plain >= 1, "{plain} plain solves");
        assert!(checked >= 1, "{checked} checked solves");
        // And a refinement that asks for checked solves from the start uses no plain one.
        let (x, _, plain, _) = refine_counting(-1.0, false);
        assert!(x.is_some());
        assert_eq!(plain, 0);
    }
}
