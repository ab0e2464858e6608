//! Advancing inside a piece: the exact ratio test of an affine load
//! ([`Path::exit_linear`]) and the certified steps of a nonlinear load
//! ([`Path::exit_graph`]), both on the table of guard values and derivatives.

use super::roots::{brent_fallible, hermite_min, newton_bracketed};
use super::*;
use crate::dense::axpy;

/// True where a guard `k` not `skip`ped dips below its threshold `−tol[k]` on a stretch
/// of α of length `len` (signed) whose ends have the rows `a` and `b`: in the cubic
/// Hermite model of its values and slopes there, the ends included.
fn dips(
    a: &[GuardRow],
    b: &[GuardRow],
    len: f64,
    tol: &Thresholds,
    skip: impl Fn(usize) -> bool,
) -> bool {
    (0..b.len()).any(|k| {
        let (m0, m1) = (a[k].slope * len, b[k].slope * len);
        let sc = overflow_guard(&[a[k].value, b[k].value, m0, m1]);
        !skip(k)
            && tol.below(
                k,
                hermite_min(a[k].value * sc, b[k].value * sc, m0 * sc, m1 * sc),
                sc,
            )
    })
}

/// The zero thresholds ([`Tol::of`]) of the guards of a table at one point, each computed
/// on first use: a displacement guard's reads a column of W (O(m)), so computing all of
/// them at every step of a march cost O(m p) a step (half of a basis load's trace at
/// p = 2000). Most comparisons are decided by the O(1) upper bound ([`Tol::upper`]);
/// every comparison gives what it gives with all thresholds computed.
struct Thresholds {
    tol: Tol,
    forms: Vec<crate::piece::LinForm>,
    /// [`Tol::upper`], raised by 1e-10 of itself (the bound and the threshold are sums in
    /// different orders: their roundings must not put the threshold above it).
    upper: Vec<f64>,
    exact: Vec<std::cell::OnceCell<f64>>,
}

impl Thresholds {
    /// `labels[k]`: row k is a frictionless node's slip guard, its threshold
    /// [`Tol::label_of`].
    fn new(tol: Tol, forms: Vec<crate::piece::LinForm>, labels: &[bool]) -> Self {
        let upper = forms.iter().map(|f| tol.upper(f) * (1.0 + 1e-10)).collect();
        let exact = forms
            .iter()
            .zip(labels)
            .map(|(f, &label)| {
                let cell = std::cell::OnceCell::new();
                if label {
                    let _ = cell.set(tol.label_of(f));
                }
                cell
            })
            .collect();
        Self {
            tol,
            forms,
            upper,
            exact,
        }
    }

    /// `v < −tol[k] sc` (`sc`: a power of two that scales v and the threshold alike).
    fn below(&self, k: usize, v: f64, sc: f64) -> bool {
        if v >= 0.0 {
            return false;
        }
        v < -self.upper[k] * sc || v < -self[k] * sc
    }

    /// True where every one of `vs` is farther from zero than the threshold's bound: then
    /// no comparison of them with ±`tol[k] sc` depends on the threshold's value.
    fn clear_of(&self, k: usize, vs: &[f64], sc: f64) -> bool {
        vs.iter().all(|v| v.abs() > self.upper[k] * sc)
    }
}

impl std::ops::Index<usize> for Thresholds {
    type Output = f64;
    fn index(&self, k: usize) -> &f64 {
        self.exact[k].get_or_init(|| self.tol.of(&self.forms[k]))
    }
}

/// 2^-8 where a number of `v` exceeds [`NEAR_OVERFLOW`] (guards near the largest double,
/// whose Hermite models' sums would overflow), else 1: a scale for all of them (exact, and
/// the models' tests are homogeneous in it).
fn overflow_guard(v: &[f64]) -> f64 {
    if v.iter().any(|x| x.abs() > NEAR_OVERFLOW) {
        2f64.powi(-8)
    } else {
        1.0
    }
}

/// A guard with its value and its derivative along the tangent.
#[derive(Clone)]
pub(super) struct GuardRow {
    pub(super) guard: Guard,
    /// The guard's value at the point (force units; ≥ 0 inside the piece).
    pub(super) value: f64,
    /// Its derivative along the tangent (0 when no tangent is given).
    pub(super) slope: f64,
}

/// Most consecutive steps of at most `hmin` (1e-12 of the window, or of the load's own α
/// length where the window is far longer, see `Path::load_span`; at least [`ALPHA_ULPS`]
/// ulps of α) that a march along one piece of a nonlinear load takes before it stops with
/// an error: such steps skip the step control, and a march that takes nothing longer has
/// stalled.
const MAX_FORCED_STEPS: usize = 1000;

/// The least step of a march, in ulps of α (`hmin` in `Path::exit_graph`): a shorter one
/// may not move α at all.
const ALPHA_ULPS: f64 = 8.0;

/// An error unless every guard of `rows` at `pt` is finite: past the range of a double
/// (forces near 1e308) every comparison with a NaN is false, so no guard would cross and
/// a march in α would neither advance nor stop.
fn finite_guards(rows: &[GuardRow], pt: &Point) -> Result<()> {
    if pt.alpha.is_finite()
        && rows
            .iter()
            .all(|r| r.value.is_finite() && r.slope.is_finite())
    {
        return Ok(());
    }
    Err(Error::Numerical(format!(
        "the guards at alpha = {:e} are not finite numbers{}",
        pt.alpha,
        near_overflow(pt)
    )))
}

/// Where advancing on the current piece stops: the window's end, or a point where guards
/// reach zero (a transition point, with the guards that cross there).
pub(super) enum Exit {
    Window(Point),
    Guards(Point, Vec<Guard>),
}

/// Every this many transitions the exit point's d is computed from W afresh instead of
/// from the piece's point along its line (see [`Path::exit_linear`]).
const GAPS_REFRESH: usize = 8;

/// A piece's solutions under a basis load `q(α) = Σ_j w_j(α) q_j`. The piece's right-hand
/// side is linear in `q − (g, 0)`, so with `y_j = M_S⁻¹ rhs_S(q_j)` and
/// `y_g = M_S⁻¹ rhs_S(−(g, 0))`: `λ(α) = Σ_j w_j y_j + y_g`, `dλ/dα = Σ_j w'_j y_j`, and
/// `d = W λ + q − (g, 0)` follows from the products `W y_j`, `W y_g`. J + 1 checked solves
/// and their products with W once per piece; each evaluation along the piece then costs
/// O(J m) instead of two solves with `M_S` and two products with W.
pub(super) struct BasisSolutions {
    /// `y_1 … y_J`, then `y_g`.
    y: Vec<Vec<f64>>,
    /// W times each.
    wy: Vec<Vec<f64>>,
    /// Refined in double-double ([`Path::refine_basis`]): their combinations are then
    /// accurate to a few roundings of their terms, and a point is not corrected from its
    /// residual in double (which would move it by up to cond · that residual).
    refined: bool,
}

impl BasisSolutions {
    /// `(λ, d, dλ/dα, rate of d along (dλ/dα, 1))` for the weights `w`, `w'` at α, with
    /// `qg = q(α) − (g, 0)` and `dq = q'(α)`.
    fn at(&self, w: &[f64], dw: &[f64], qg: &[f64], dq: &[f64]) -> [Vec<f64>; 4] {
        let k = w.len();
        let d: Vec<f64> = qg.iter().zip(&self.wy[k]).map(|(a, b)| a + b).collect();
        self.combine(self.y[k].clone(), d, w, dw, dq)
    }

    /// `(λ0 + Σ_j c_j y_j, d0 + Σ_j c_j W y_j, Σ_j w'_j y_j, q' + Σ_j w'_j W y_j)`: the
    /// point, its d, dλ/dα and the rate of d, from a point `(λ0, d0)` of the piece and
    /// the weights' changes `c` since it ([`Self::at`]: from y_g).
    fn combine(
        &self,
        mut lam: Vec<f64>,
        mut d: Vec<f64>,
        c: &[f64],
        dw: &[f64],
        dq: &[f64],
    ) -> [Vec<f64>; 4] {
        let mut dl = vec![0.0; lam.len()];
        let mut rate = dq.to_vec();
        for j in 0..c.len() {
            axpy(&mut lam, c[j], &self.y[j]);
            axpy(&mut d, c[j], &self.wy[j]);
            axpy(&mut dl, dw[j], &self.y[j]);
            axpy(&mut rate, dw[j], &self.wy[j]);
        }
        [lam, d, dl, rate]
    }

    /// [`Self::combine`] from the piece's point `from` (its q, λ, d), whose weights were
    /// `w_from`: the point at `q = q(α)` and the weights `w`, `w'` there, `dq = q'(α)`.
    fn starting_at(
        &self,
        (from, w_from): (&Entry, &[f64]),
        q: &[f64],
        (w, dw): (&[f64], &[f64]),
        dq: &[f64],
    ) -> [Vec<f64>; 4] {
        let d = from
            .d
            .iter()
            .zip(q.iter().zip(&from.q))
            .map(|(v, (a, b))| v + (a - b))
            .collect();
        let c: Vec<f64> = w.iter().zip(w_from).map(|(a, b)| a - b).collect();
        self.combine(from.lam.clone(), d, &c, dw, dq)
    }
}

/// A point of a graph piece, its `q(α)`, λ and `d = W λ + q − (g, 0)`: a general load's
/// at the piece's entry (see [`Path::exit_graph`]), or where a basis load's combinations
/// start from ([`BasisSolutions::starting_at`]).
#[derive(Clone)]
struct Entry {
    q: Vec<f64>,
    lam: Vec<f64>,
    d: Vec<f64>,
}

type EntryCell = std::cell::RefCell<Option<Entry>>;

impl Path {
    /// The [`BasisSolutions`] of the current piece under a basis load, solved by updates of
    /// the path's factorisation. None for other loads, for the fresh-factorisation tracer
    /// (which keeps solving at every α, the reference), or when a solve fails its check.
    fn basis_solutions(&mut self, cur: &CurrentPiece) -> Option<BasisSolutions> {
        let (y, wy) = self.basis_solves(cur)?;
        Some(match self.refine_basis(cur, &y) {
            Some(r) => {
                let (y, wy) = r.into_iter().unzip();
                BasisSolutions {
                    y,
                    wy,
                    refined: true,
                }
            }
            None => BasisSolutions {
                y,
                wy,
                refined: false,
            },
        })
    }

    /// The basis solutions `y_j` of the current piece (see [`BasisSolutions`]) in double,
    /// with `W y_j`: carried by the updates to this piece and checked from the data when
    /// its tangent was computed (`Path::tangent_updated`), else solved for. None for a
    /// piece not solved by updates, or when a solve fails its check.
    pub(super) fn basis_solves(&self, cur: &CurrentPiece) -> Option<update::CheckedCols> {
        let PieceSolver::Updated(u) = &*cur.lu else {
            return None;
        };
        let rhs = self.basis_rhs(&cur.classes)?;
        match u.checked().filter(|k| k.0.len() == rhs.len()) {
            Some(k) => Some(Arc::unwrap_or_clone(k)),
            None => u.solve_cols(
                &self.consts(),
                self.problem.delassus().w(),
                &rhs,
                self.row_bound(),
            ),
        }
    }

    /// The point `(λ, d)` of the current piece at α from the guess `lam` (the basis
    /// solutions' combination, `refined` when they were refined in double-double),
    /// `qg = q(α) − (g, 0)`: d by one product with W, kept when its residual on the piece
    /// equations from the data is at rounding level (refined: within a solve's check),
    /// else corrected by a checked solve from that residual. None when the correction
    /// fails its check (or for a piece not solved by updates).
    fn checked_point(
        &self,
        cur: &CurrentPiece,
        qg: &[f64],
        lam: Vec<f64>,
        refined: bool,
    ) -> Option<(Vec<f64>, Vec<f64>)> {
        let PieceSolver::Updated(u) = &*cur.lu else {
            return None;
        };
        let (rel, d, r) = self.point_residual(&cur.classes, qg, &lam);
        if rel <= update::REFINE_ABOVE || (refined && rel <= 1e-12) {
            return Some((lam, d));
        }
        let c = self.consts();
        let rhs = c.piece_rhs(&cur.classes, qg);
        let col = update::Rhs {
            b: &rhs,
            guess: Some((&lam, &r)),
        };
        let w = self.problem.delassus().w();
        let k = u
            .solve_checked_many(&c, w, &[col], self.row_bound())
            .pop()?;
        (k.rel <= 1e-12).then(|| {
            let d = d.iter().zip(&k.wx).map(|(a, b)| a + b).collect();
            (k.x, d)
        })
    }

    /// The relative residual of `lam` on the equations of the piece `classes` from the
    /// data (`qg = q(α) − (g, 0)`; one product with W), with its d and the residual rows.
    pub(super) fn point_residual(
        &self,
        classes: &[Class],
        qg: &[f64],
        lam: &[f64],
    ) -> (f64, Vec<f64>, Vec<f64>) {
        let c = self.consts();
        let d = displacement_gaps(self.problem.delassus().w(), qg, lam);
        let zeros = vec![0.0; 2 * c.p];
        let r = update::residual_rows(&c, classes, lam, &d, &zeros);
        let rhs = c.piece_rhs(classes, qg);
        let rel = update::relative_residual(&c, classes, &r, lam, &rhs, self.row_bound());
        (rel, d, r)
    }

    /// In extended precision, the root of guard `g` (row `k` of the piece's guard table,
    /// slope `slope` per unit α) of the piece `cur` under a basis load corrected on the
    /// point refined in double-double. A point rounded to double carries the rounding of
    /// its terms in each d (ε |W||λ|), and more where it was accepted at a residual above
    /// rounding level (up to a solve's check, 1e-12), which the piece's conditioning
    /// amplifies in λ and again in d. Where the guard crosses at a shallow angle against
    /// its terms, that moves the root by that error over the slope, while the refined d is
    /// accurate to the data. So `pt` is refined, and the root moved by one Newton step on
    /// the refined guard, the point with it along the piece's tangent (`bs` at α: a step
    /// of that error's size, whose own error is its square). The error is measured, not
    /// estimated: an estimate from the point's residual and the guard's terms (without
    /// the conditioning) judged a root well determined in double that was 4.2e-9 in α
    /// (2.8e-8 in φ) off on a slender strip (κ(W) = 1.5e8, F = 5) under a sine load. Steps
    /// of any size are taken: where a node opens and closes again at one point, steps of
    /// 1.6e-14 in α put its two events together, as they are on the affine path.
    /// `within`: the stretch of α the root was found on; a step beyond it means a
    /// refinement that did not land near this root. None when the problem is carried in
    /// double, the refinement fails, the step is zero or leaves `within`.
    fn polish_root(
        &mut self,
        cur: &CurrentPiece,
        bs: &BasisSolutions,
        (k, slope): (usize, f64),
        within: (f64, f64),
        pt: &Point,
    ) -> Result<Option<Point>> {
        if !self.problem.extended_precision() {
            return Ok(None);
        }
        let Some((lam, d)) = self.polish_point(&cur.classes, &cur.lu, pt.alpha, &pt.lam) else {
            return Ok(None);
        };
        let v = self.guard_rows(&cur.classes, &lam, &d, None)[k].value;
        let step = -v / slope;
        let (lo, hi) = within;
        if !(step != 0.0 && (lo..=hi).contains(&(pt.alpha + step))) {
            return Ok(None);
        }
        let Some((w, dw)) = self.load.weights_at(pt.alpha) else {
            return Ok(None);
        };
        let qg = shift_gap(&pt.q, self.problem.gap_equilibrated());
        let [_, _, t, rate] = bs.at(w, dw, &qg, &pt.dq);
        Ok(Some(self.step_along(
            pt.alpha,
            (&lam, &d),
            (&t, &rate),
            step,
        )?))
    }

    /// The point `(λ, d)` at `alpha` moved along its piece's tangent `(t, rate)` (per
    /// unit α: dλ/dα and the rate of d, as [`BasisSolutions::at`] gives them) by `step`
    /// in α, its d kept for [`Self::gaps`]. Errors: the load's at the new α.
    fn step_along(
        &mut self,
        alpha: f64,
        (lam, d): (&[f64], &[f64]),
        (t, rate): (&[f64], &[f64]),
        step: f64,
    ) -> Result<Point> {
        let lam: Vec<f64> = lam.iter().zip(t).map(|(l, t)| l + step * t).collect();
        let d: Vec<f64> = d.iter().zip(rate).map(|(x, r)| x + step * r).collect();
        let alpha = alpha + step;
        self.prime_gaps(alpha, &lam, d);
        self.point_at(lam, alpha)
    }

    /// How near zero guard `g` must be at `pt` for a root the piece ends at: a quarter of
    /// its threshold; for a normal force, that over F (from slip, λt = ±F λν follows it,
    /// and the classes the node may take bound λt by the same threshold: with F = 5, λν
    /// at 0.65 of it left λt beyond the open class's, and no piece continued the path).
    fn root_accept(&self, pt: &Point, g: Guard) -> f64 {
        let c = self.consts();
        let amplified = match g.kind {
            crate::piece::GuardKind::Compress => c.friction[g.node].max(1.0),
            _ => 1.0,
        };
        0.25 * self.tol_at(pt).of(&c.guard_form(g)) / amplified
    }

    /// The point `pt` where a piece ends at the zero of guard `g`, moved along the piece's
    /// tangent to that zero where the root's search in α could not reach it (α cannot
    /// resolve it, or the load's solutions are noisier than the guard's threshold, see the
    /// general-load arm of [`Self::exit_graph`]'s root): λ and d by the Newton step, α by
    /// it rounded. `tangent`: dλ/dα and dd/dα at `pt` (computed only where the point
    /// moves; None: it stays); `within`: the stretch of α the root was found on (a step
    /// beyond it is not taken). Near a fold the guard's slope per unit α was 1e4 (basis
    /// load): neighbouring doubles of α straddled its zero at ±2.5e-14; on a piece with
    /// dα/ds = 3.9e-5 (general load, slender strip, F = 5) the normal force of the node
    /// lifting off was −4.5e-12 at the root's double, 1.7 times its threshold, and no piece
    /// continued the path. Moved where the guard is beyond [`Self::root_accept`].
    fn onto_guard_zero(
        &mut self,
        pt: Point,
        g: Guard,
        tangent: impl FnOnce(&Self, &Point) -> Option<[Vec<f64>; 2]>,
        (lo, hi): (f64, f64),
    ) -> Result<Point> {
        let form = self.consts().guard_form(g);
        let d = self.gaps(&pt);
        let v = form.eval(&pt.lam, &d);
        if v.abs() <= self.root_accept(&pt, g) {
            return Ok(pt);
        }
        let Some([t, rate]) = tangent(self, &pt) else {
            return Ok(pt);
        };
        let step = -v / form.eval(&t, &rate);
        if !(step.is_finite() && (lo..=hi).contains(&(pt.alpha + step))) {
            return Ok(pt);
        }
        self.step_along(pt.alpha, (&pt.lam, &d), (&t, &rate), step)
    }

    /// Values and derivatives along `t` of all guards of `classes` at `pt`; `t` comes
    /// with the rate of d along it (`W t_λ + q' t_α`, see [`Path::rate_along`]).
    pub(super) fn guard_table(
        &self,
        classes: &[Class],
        pt: &Point,
        t: Option<(&[f64], &[f64])>,
    ) -> Vec<GuardRow> {
        let d = self.gaps(pt);
        self.guard_rows(classes, &pt.lam, &d, t)
    }

    /// As [`Self::guard_table`], at the point `(λ, d)`.
    fn guard_rows(
        &self,
        classes: &[Class],
        lam: &[f64],
        d: &[f64],
        t: Option<(&[f64], &[f64])>,
    ) -> Vec<GuardRow> {
        let c = self.consts();
        let m = 2 * c.p;
        let zeros;
        let (lt, dt) = match t {
            Some((t, rate)) => (&t[..m], rate),
            None => {
                zeros = vec![0.0; m];
                (&zeros[..], &zeros[..])
            }
        };
        c.guards(classes)
            .into_iter()
            .map(|g| {
                let f = c.guard_form(g);
                GuardRow {
                    guard: g,
                    value: f.eval(lam, d),
                    slope: f.eval(lt, dt),
                }
            })
            .collect()
    }

    /// Exit of a straight piece (affine load, or a vertical piece): ratio test on the
    /// guards and the window, then the exact point by one bordered solve.
    pub(super) fn exit_linear(&mut self, cur: &CurrentPiece) -> Result<Exit> {
        let m = 2 * self.problem.p();
        // The piece's own point at the entry α where it was solved for (it may differ from
        // the transition point by cond · ε on an ill-conditioned piece): the guards are
        // measured there, on the line the exit point is then taken from. In extended
        // precision, that point and the piece's direction refined in double-double
        // (rounded): on a piece so ill-conditioned that cond · ε is visible in its guards
        // (1e-4 of λ on the p = 1920 strip), the double-precision point made a guard
        // crossed at the piece's entry and the exit went backwards.
        let refined = self.refine_piece(cur);
        self.refined = refined.clone().map(|r| (cur.alpha, cur.classes.clone(), r));
        // Set again below where this piece's exit is taken on its refined line.
        self.carried = None;
        let (lam0, t, rate) = match &refined {
            Some(r) => {
                let [lam_e, d_e, lam_1, d_1] = &r.rounded;
                let ta = cur.t[m];
                self.prime_gaps(cur.alpha, lam_e, d_e.clone());
                let mut t: Vec<f64> = lam_1.iter().map(|v| v * ta).collect();
                t.push(ta);
                let rate: Vec<f64> = d_1.iter().map(|v| v * ta).collect();
                (lam_e.clone(), t, rate)
            }
            None => (
                cur.xp
                    .as_deref()
                    .cloned()
                    .unwrap_or_else(|| cur.lam.clone()),
                cur.t.clone(),
                cur.rate.to_vec(),
            ),
        };
        let pt = self.point_at(lam0, cur.alpha)?;
        // The thresholds are those of the transition point (computed, row by row, when
        // the path joined the piece there; the two points differ by rounding only).
        let tol = self.tol_at(&Point {
            lam: cur.lam.clone(),
            ..pt.clone()
        });
        let table = self.guard_table(&cur.classes, &pt, Some((&t, &rate)));
        finite_guards(&table, &pt)?;
        let mut best: Option<(f64, Guard)> = None;
        let mut decreasing = Vec::new();
        let c = self.consts();
        for &GuardRow {
            guard: g,
            value: v,
            slope: vd,
        } in &table
        {
            // A decreasing guard leaves the piece where it reaches zero. Only a guard at
            // zero whose slope is within the slope threshold counts as not decreasing (it
            // was let in on that slope); one inside the piece that decreases however
            // slowly does cross, and where it crosses first it is the exit.
            //
            // A frictionless node's dt (its slip guard) decreases only beyond the slope
            // threshold: where it stays at zero (the node on a symmetric body's axis, alone
            // in contact), its value is the rounding of W's entries that vanish by symmetry
            // (2e-17 against a threshold of a hundredth of that, the row's terms being
            // that rounding too), and its root along a slope of that size was the exit:
            // 1.0 in α behind the entry. Its side only names its class (S+ or S−, the same
            // equations), so it need not be resolved below the slope threshold.
            let label_only = c.label_only(g);
            if vd < -tol.slope()
                || (!label_only && vd < 0.0 && !tol.at_zero(&c.guard_form(g), v, vd))
            {
                let s = (v / -vd).max(0.0);
                decreasing.push(g);
                if best.is_none_or(|b| s < b.0) {
                    best = Some((s, g));
                }
            }
        }
        let (lo, hi) = self.window();
        let ta = cur.t[m];
        // A vertical piece stays at its α, inside the window (also on its edge): it leaves
        // through its guards only.
        let s_win = if cur.scales.is_vertical(&cur.t) {
            None
        } else if ta > 0.0 {
            Some((hi - cur.alpha) / ta)
        } else if ta < 0.0 {
            Some((lo - cur.alpha) / ta)
        } else {
            None
        };
        let problem = self.problem.clone();
        let c = PieceConstants::of(&problem);
        let w = problem.delassus().w();
        match (best, s_win) {
            (None, None) => Err(Error::Numerical(format!(
                "vertical piece at alpha = {:e} with no exit: the continuum is unbounded",
                cur.alpha
            ))),
            // A guard that reaches zero where α reaches the window's edge (within zero_tol
            // along the unit tangent) is a transition point on the edge: the path goes
            // through it (onto a vertical piece there, or out of the window at once on the
            // next step).
            (b, Some(sw)) if b.is_none_or(|b| sw < b.0 - self.opts.zero_tol) => {
                let alpha = if ta > 0.0 { hi } else { lo };
                let pt = self.point_at(vec![0.0; m], alpha)?;
                let qg = shift_gap(&pt.q, self.problem.gap_equilibrated());
                let rhs = c.piece_rhs(&cur.classes, &qg);
                // The window's edge ends the path without a transition point's checks, so
                // it is solved from the data: on the refined line where the piece was
                // refined, else by the updated factorisation where its residual passes
                // (1e-12), else by one LU of M_S. The updated solve was once kept
                // unchecked: on a slender strip (F = 3, p = 400) its residual was 1.3e-10
                // and an open node's λ 2e-6 of max|λ| off zero at the window's end.
                let lam = match &refined {
                    Some(r) => r.lam_at(cur.alpha, alpha),
                    None => self.piece_solve(&cur.classes, cur.lu.updated(), &rhs).0,
                };
                Ok(Exit::Window(Point { lam, ..pt }))
            }
            (Some((s, g)), _) => {
                // The exit's distance τ along t from the piece's point `pt` where the
                // exit lies on that line: its d is then `d(pt) + τ · rate` (O(m)).
                let mut on_line: Option<f64> = None;
                // Whether the line starts at `pt` itself (the piece's solved or refined
                // point), not at a particular solution elsewhere on it.
                let from_pt = refined.is_some() || cur.xp.is_some();
                let (lam, alpha) = if self.load.is_affine() {
                    // Exact point from the data: x = x_p + τ t with J x_p = rhs (from the
                    // piece's factorisation) and τ from the guard's equation; no drift
                    // from earlier points enters.
                    let qg = shift_gap(&pt.q, self.problem.gap_equilibrated());
                    let rhs = c.jacobian_rhs(&cur.classes, &qg, &pt.dq, pt.alpha);
                    let form = c.guard_form(g);
                    let mut row = vec![0.0; m + 1];
                    form.row(w, &pt.dq, &mut row);
                    let v0 = table
                        .iter()
                        .find(|e| e.guard == g)
                        .map(|e| e.value)
                        .unwrap_or(0.0);
                    let c0 = v0
                        - row[..m]
                            .iter()
                            .zip(&pt.lam)
                            .map(|(a, b)| a * b)
                            .sum::<f64>()
                        - row[m] * cur.alpha;
                    // The piece's point at the entry α was solved from the data with the
                    // tangent (updated factorisations) or refined; else one particular
                    // solve.
                    let xp = if from_pt {
                        let mut x = pt.lam.clone();
                        x.push(cur.alpha);
                        x
                    } else {
                        let dq_col = self.alpha_column(&cur.classes, &pt.dq);
                        cur.lu.particular_raw(
                            &c,
                            w,
                            &rhs,
                            cur.alpha,
                            &dq_col,
                            cur.scales,
                            self.row_bound(),
                        )
                    };
                    let dot = |x: &[f64]| row.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
                    let tau = (-c0 - dot(&xp)) / dot(&t);
                    let x: Vec<f64> = xp.iter().zip(&t).map(|(a, b)| a + tau * b).collect();
                    if x.iter().all(|v| v.is_finite()) {
                        if from_pt {
                            on_line = Some(tau);
                        }
                        (x[..m].to_vec(), x[m])
                    } else {
                        on_line = Some(s);
                        let lam = pt.lam.iter().zip(&t).map(|(l, t)| l + s * t).collect();
                        (lam, cur.alpha + s * t[m])
                    }
                } else {
                    let lam = pt.lam.iter().zip(&t).map(|(l, t)| l + s * t).collect();
                    (lam, cur.alpha)
                };
                // In extended precision, the same exit in double-double where it lies
                // near this one (a piece too ill-conditioned for the refinement keeps
                // the double-precision point).
                let polished = refined
                    .as_ref()
                    .and_then(|r| self.polish_exit(cur, r, &decreasing).map(|exit| (r, exit)));
                // The exit is then the refined line's point at that α rounded to double,
                // with its d there: the transition point's gaps without a product with W
                // (one pass over W, 6 % of a transition at p = 1920). d is that of the
                // point in double-double, within a rounding of |W||λ| of the rounded λ's,
                // as a product's own rounding is.
                let mut primed = None;
                let (lam, alpha, g) = match polished {
                    Some((r, (l2, a2, g2)))
                        if super::polish::near(&l2, &lam, self.force_scale(&pt)) =>
                    {
                        on_line = None;
                        let cp = r.carried_at(cur.alpha, a2);
                        let (l, d) = cp.rounded();
                        primed = Some(d);
                        self.carried = Some(cp);
                        (l, a2, g2)
                    }
                    _ => (lam, alpha, g),
                };
                // The exit's d from the piece's point along the line instead of a product
                // with W (at p = 1920 that pass was 45 % of a transition). Each such d
                // carries the rounding of the one before it, so every GAPS_REFRESH-th
                // transition computes it afresh from W: the drift stays within a few
                // roundings of |W||λ|, far below the thresholds.
                let exit = self.point_at(lam, alpha)?;
                if let Some(d) = primed.filter(|d| d.iter().all(|v| v.is_finite())) {
                    self.prime_gaps(exit.alpha, &exit.lam, d);
                }
                let transitions = self.trace.as_ref().map_or(0, |tr| tr.transitions);
                if let Some(tau) = on_line
                    && !transitions.is_multiple_of(GAPS_REFRESH)
                {
                    // Row k is kept where its rounding, ε (|d_k(pt)| + |τ rate_k|), is within
                    // a few of the product's own, ε (|W||λ|)_k ≥ ε |(W λ)_k|; elsewhere
                    // (cancellation along a long piece) it is the row of the product (O(m)).
                    let d0 = self.gaps(&pt);
                    let qg = shift_gap(&exit.q, self.problem.gap_equilibrated());
                    let w = self.problem.delassus().w();
                    let d: Vec<f64> = (0..m)
                        .map(|k| {
                            let v = d0[k] + tau * rate[k];
                            let step = d0[k].abs() + (tau * rate[k]).abs();
                            if step <= 4.0 * ((v - qg[k]).abs() + qg[k].abs()) {
                                v
                            } else {
                                // row k of the symmetric W, read as its column k
                                qg[k]
                                    + w.col(k)
                                        .iter()
                                        .zip(&exit.lam)
                                        .map(|(a, b)| a * b)
                                        .sum::<f64>()
                            }
                        })
                        .collect();
                    if d.iter().all(|v| v.is_finite()) {
                        self.prime_gaps(exit.alpha, &exit.lam, d);
                    }
                }
                Ok(Exit::Guards(exit, vec![g]))
            }
            (None, Some(_)) => unreachable!("handled by the window arm"),
        }
    }

    /// Exit of a graph piece under a nonlinear load: march in α with steps that the
    /// guards' Hermite interpolants certify free of double crossings, then Brent.
    ///
    /// A general load in double precision is evaluated relative to the piece's entry
    /// point: `q(α) = q(α_e) + (condensed f(α) − f(α_e))` ([`BoundLoad::anchor_at`]) and
    /// `λ(α) = λ(α_e) + M_S⁻¹ (b(q(α)) − b(q(α_e)))`, d likewise. Solved afresh at each α,
    /// λ and d carry rounding of `cond · ε` of the whole load, different at each α: on a
    /// slender body that noise exceeded the guards' thresholds, so that the march stopped
    /// (the guards at α and α + 1e-14 disagreed) or roots moved by 1e-9. Relative to the
    /// entry, the rounding is proportional to the change of the load since the entry:
    /// smooth in α, and small near the roots that matter. (Under extended precision each
    /// point is refined in double-double instead.)
    pub(super) fn exit_graph(&mut self, cur: &CurrentPiece) -> Result<Exit> {
        let anchored = self.load.basis_vectors().is_none()
            && !self.load.is_affine()
            && !self.problem.extended_precision();
        if !anchored {
            return self.exit_graph_on(cur, None);
        }
        let problem = self.problem.clone();
        self.load.anchor_at(cur.alpha, problem.delassus())?;
        let entry = std::cell::RefCell::new(None);
        let out = self.exit_graph_on(cur, Some(&entry));
        self.load.drop_anchor();
        out
    }

    /// [`Self::exit_graph`], with `entry` for a general load evaluated relative to the
    /// entry point (set by the first evaluation, at the entry).
    fn exit_graph_on(&mut self, cur: &CurrentPiece, entry: Option<&EntryCell>) -> Result<Exit> {
        let m = 2 * self.problem.p();
        let dir = if cur.t[m] > 0.0 { 1.0 } else { -1.0 };
        let (lo, hi) = self.window();
        let bound = if dir > 0.0 { hi } else { lo };
        // M_S solves: by the piece's updated factorisation, or one LU of M_S. Where an
        // updated solve fails its check from the data (a relative residual above 1e-12),
        // the march goes on with one LU of M_S instead, from that evaluation on (its
        // solves at neighbouring α then share one factorisation). On a slender strip
        // (F = 5) a piece entered after ten updates (pivot ratio 2e-6) was solved to a
        // residual of 1.9e-9 at its entry: λ was wrong by more than its size, its
        // refinement in double-double failed, and the march stopped with an error.
        let piece_lu = |this: &Self| {
            let c = this.consts();
            DenseLu::new(
                c.piece_matrix(this.problem.delassus().w(), &cur.classes)
                    .as_ref(),
            )
        };
        let dense = std::cell::OnceCell::new();
        if let PieceSolver::Full(_) = &*cur.lu {
            let _ = dense.set(piece_lu(self));
        }
        let add =
            |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| x + y).collect() };
        // λ, d, dλ/dα and the rate of d along (dλ/dα, 1) from solves with M_S: both
        // columns in one pass over the factor and one product with W.
        let solve = |this: &Self, qg: &[f64], dq: &[f64]| -> [Vec<f64>; 4] {
            let c = this.consts();
            let w = this.problem.delassus().w();
            let rhs = [c.piece_rhs(&cur.classes, qg), c.piece_rhs(&cur.classes, dq)];
            let by_lu = |lu: &DenseLu| {
                let xs: Vec<Vec<f64>> = rhs.iter().map(|b| lu.solve(b)).collect();
                let wxs = crate::dense::mat_mul(w, &[&xs[0], &xs[1]]);
                (xs, wxs)
            };
            let (xs, wxs) = match (dense.get(), &*cur.lu) {
                (Some(lu), _) => by_lu(lu),
                (None, PieceSolver::Updated(u)) => {
                    let cols = rhs.each_ref().map(|b| update::Rhs { b, guess: None });
                    let ks = u.solve_checked_many(&c, w, &cols, this.row_bound());
                    if ks.iter().all(|k| k.rel <= 1e-12) {
                        ks.into_iter().map(|k| (k.x, k.wx)).unzip()
                    } else {
                        by_lu(dense.get_or_init(|| piece_lu(this)))
                    }
                }
                (None, PieceSolver::Full(_)) => unreachable!("a full solver has its dense LU"),
            };
            let [lam, dl]: [Vec<f64>; 2] = xs.try_into().expect("two columns");
            [lam, add(qg, &wxs[0]), dl, add(dq, &wxs[1])]
        };
        let classes = cur.classes.clone();
        let basis = self.basis_solutions(cur);
        // A basis load's points along the piece from its entry, the transition point
        // (λ_e, d_e at α_e): `λ(α) = λ_e + Σ_j (w_j(α) − w_j(α_e)) y_j`, d likewise. The
        // combination `Σ_j w_j y_j + y_g` itself cancels where the piece is nearly
        // singular (its y_j large, λ small): on a slender strip (F = 5, κ(W) = 1e10) it
        // put the entry of a steep piece 1e-4 of λ off the transition point, four guards
        // negative there, and the path turned back onto the piece it came from.
        // Relative to the entry the error is that of the weights' change since it. Only
        // in extended precision where the basis solutions could not be refined: refined,
        // their combination is accurate, and the entry carries the rounding of its α (in
        // a window far out on the α axis, α_e's ulp times the piece's slope: events
        // drifted by 1.6e-8); in double the entry carries the rounding of the transition
        // point's own solve, and a mirror-symmetric pair of strips (κ(W) = 1.6e5) stopped
        // with a node fitting no class where the combination traces its window.
        let anchor = match &basis {
            Some(bs) if !bs.refined && self.problem.extended_precision() => {
                let at = self.point_at(cur.lam.clone(), cur.alpha)?;
                let d = self.gaps(&at).to_vec();
                self.load.weights_at(cur.alpha).map(|(w, _)| {
                    let entry = Entry {
                        q: at.q,
                        lam: at.lam,
                        d,
                    };
                    (entry, w.to_vec())
                })
            }
            _ => None,
        };
        // The guards at α: from the piece's basis solutions where there are some (O(J m)),
        // else from solves with M_S. `exact`: the point that ends the piece, checked
        // against the data (its combination kept where its residual is at rounding level,
        // else solved for), and its d kept for the join.
        let eval = |this: &mut Self, alpha: f64, exact: bool| -> Result<(Point, Vec<GuardRow>)> {
            let at = this.point_at(Vec::new(), alpha)?;
            let (qg, dq) = (shift_gap(&at.q, this.problem.gap_equilibrated()), &at.dq);
            let [lam, d, mut t, rate] = match (&basis, this.load.weights_at(alpha)) {
                (Some(bs), Some((w, dw))) => {
                    let [lam, d, t, rate] = match &anchor {
                        Some((entry, w_e)) => bs.starting_at((entry, w_e), &at.q, (w, dw), dq),
                        None => bs.at(w, dw, &qg, dq),
                    };
                    if !exact {
                        [lam, d, t, rate]
                    } else if let Some((lam, d)) = this.checked_point(cur, &qg, lam, bs.refined) {
                        [lam, d, t, rate]
                    } else {
                        solve(this, &qg, dq)
                    }
                }
                _ if let Some(cell) = entry => {
                    let known = cell.borrow().clone();
                    match known {
                        // λ and d at the entry plus the solution for the change of q.
                        Some(e) => {
                            let change: Vec<f64> =
                                at.q.iter().zip(&e.q).map(|(a, b)| a - b).collect();
                            let [dl, dd, t, rate] = solve(this, &change, dq);
                            [add(&e.lam, &dl), add(&e.d, &dd), t, rate]
                        }
                        None => {
                            let out = solve(this, &qg, dq);
                            *cell.borrow_mut() = Some(Entry {
                                q: at.q.clone(),
                                lam: out[0].clone(),
                                d: out[1].clone(),
                            });
                            out
                        }
                    }
                }
                _ => {
                    let [mut lam, mut d, t, rate] = solve(this, &qg, dq);
                    // A general load on a problem carried beyond double: the point refined
                    // in double-double (the solves at neighbouring α otherwise differ by
                    // cond · ε, more than the guards' thresholds on a slender body), its d
                    // from it; the rates stay in double. Refined by solves as the point
                    // was: the updated factorisation, or a fresh LU where its check failed
                    // (with the failing update, the refinement did not converge and the
                    // double point was kept).
                    let by = match dense.get() {
                        Some(_) => None,
                        None => cur.lu.updated(),
                    };
                    if basis.is_none()
                        && let Some(refined) = this.polish_point_by(&classes, by, alpha, &lam)
                    {
                        (lam, d) = refined;
                    }
                    [lam, d, t, rate]
                }
            };
            t.push(1.0);
            let table = this.guard_rows(&classes, &lam, &d, Some((&t, &rate)));
            if exact {
                this.prime_gaps(alpha, &lam, d);
            }
            let pt = Point { lam, ..at };
            finite_guards(&table, &pt)?;
            Ok((pt, table))
        };
        let (mut pa, mut ga) = eval(self, cur.alpha, false)?;
        let span = self.load_span(&pa, FAR_WINDOW, self.opts.alpha_start);
        // The start of the step before `pa` and its guards (None on the first step).
        let mut behind: Option<(f64, Vec<GuardRow>)> = None;
        // (the default largest step is 1/8 of the window itself, as documented: a step
        // reached by doubling trusted ones)
        let hmax = self.opts.max_alpha_step.unwrap_or(self.alpha_scale() / 8.0);
        // The first piece's march starts short and doubles its way up: a step trusted by
        // its midpoint can alias the load's period only when it spans whole periods, and
        // one reached by doubling a trusted step cannot (its half was trusted). A first
        // step of span/32 spanned two periods of a load with 64 periods on the window,
        // and its excursions there were skipped.
        let floor = span / 1024.0;
        let first = self
            .graph_step
            .get()
            .map_or(floor, |h| (2.0 * h).max(floor));
        let mut h = first
            .min(span / 32.0)
            .min(hmax)
            .min((bound - cur.alpha).abs());
        let hmin_span = span * 1e-12;
        // Guards below their threshold at the piece's own point at its entry, and rising:
        // the guards the piece was entered through, measured on its own solution, which
        // differs from the transition point by cond · ε (more than the thresholds on the
        // ill-conditioned pieces of a slender body). As on a straight piece, where only a
        // decreasing guard leaves, such a guard is no exit while it rises: it counts
        // again once it is back above its threshold, or where it turns down below it.
        let mut below: Option<Vec<bool>> = None;
        let mut ahead: Option<(Point, Vec<GuardRow>)> = None;
        // Consecutive steps taken at h ≤ hmin, where the step control is skipped: a march
        // that can take no longer step crawls at 1e-12 of the span and never ends.
        let mut forced = 0usize;
        loop {
            // No step below α's own resolution (a few of its ulps): a step that does not
            // move α, or a root one ulp away whose stretch is halved again and again, never
            // ends (α near 1e6 on a window of length 7: the march halved a 1.2e-10 stretch
            // to 5.8e-11 forever).
            let hmin = hmin_span.max(ALPHA_ULPS * f64::EPSILON * pa.alpha.abs());
            let tol = {
                let c = self.consts();
                let forms = ga.iter().map(|row| c.guard_form(row.guard)).collect();
                let labels: Vec<bool> = ga.iter().map(|row| c.label_only(row.guard)).collect();
                Thresholds::new(self.tol_at(&pa), forms, &labels)
            };
            let below = below.get_or_insert_with(|| {
                (0..ga.len())
                    .map(|k| dir * ga[k].slope > 0.0 && tol.below(k, ga[k].value, 1.0))
                    .collect()
            });
            let at_bound = (bound - pa.alpha).abs() <= h;
            let b_alpha = if at_bound {
                bound
            } else {
                pa.alpha + dir * h.max(hmin)
            };
            // The midpoint of an untrusted step is the end of the step that follows.
            // Where the load cannot be evaluated (its callback failed), the step is
            // shortened, so that the transitions before that point are still reported; the
            // error ends the path only once the step can be shortened no more (within hmin
            // of the failure).
            let (mut pb, mut gb) = match ahead.take() {
                Some(m) if m.0.alpha == b_alpha => m,
                _ => match eval(self, b_alpha, false) {
                    Ok(v) => v,
                    Err(Error::Load { .. }) if h > hmin => {
                        h *= 0.5;
                        continue;
                    }
                    Err(e) => return Err(e),
                },
            };
            // A guard the piece just entered (zero at a, increasing) that is negative at b:
            // the step overshoots the piece's first stretch; shorten it.
            let premature = (0..gb.len()).any(|k| {
                !below[k]
                    && dir * ga[k].slope > 0.0
                    && tol.below(k, gb[k].value, 1.0)
                    && ga[k].value <= tol[k]
            });
            if premature && h > hmin {
                h *= 0.5;
                continue;
            }
            // A guard positive at both ends with a minimum inside (its derivative changes
            // sign) may dip below zero and come back: locate the minimum (Brent on the
            // derivative) and look at the guard there. A double crossing inside one step
            // is never skipped, however close to tangent. Not where both slopes would
            // change the guard by less than 1e-9 of its smaller end value over the step
            // (slopes at rounding level, as on the open nodes of a slender body, where
            // each such search cost tens of evaluations): a dip to zero would then need a
            // load stationary at both ends and varying a billion times faster inside,
            // which the midpoint test below looks for as for every guard.
            // Every evaluation gives all guards' slopes, so the searches share them: each
            // starts from the tightest bracket of its slope's sign change among the step's
            // ends and the last search's final bracket. Under a load `f0 + φ(α) f1` every
            // guard turns where φ does, and after the first search the others' brackets
            // are already at machine precision: one search instead of one per guard, each
            // of tens of evaluations (a general sine load on a mesh with p = 140: 11× less
            // time for the whole trace).
            let mut cut: Option<f64> = None;
            let delta_b = pb.alpha - pa.alpha;
            // (α, guards) at the step's ends and around the last minimum found, in the
            // order of travel (at most five tables kept between searches).
            let mut seen: Vec<(f64, Vec<GuardRow>)> = Vec::new();
            let order = |x: &(f64, Vec<GuardRow>), y: &(f64, Vec<GuardRow>)| {
                (dir * x.0).total_cmp(&(dir * y.0))
            };
            for k in 0..gb.len() {
                let flat = 1e-9 * ga[k].value.min(gb[k].value);
                if dir * ga[k].slope < 0.0
                    && dir * gb[k].slope > 0.0
                    && ga[k].value > -tol[k]
                    && gb[k].value >= -tol[k]
                    && (ga[k].slope * delta_b)
                        .abs()
                        .max((gb[k].slope * delta_b).abs())
                        >= flat
                {
                    if seen.is_empty() {
                        seen.push((pa.alpha, ga.clone()));
                        seen.push((pb.alpha, gb.clone()));
                    }
                    // The first sign change of the slope (− to + along the step): there is
                    // one, as the step's ends are first and last, with finite slopes
                    // (`finite_guards`) negative at the start and positive at the end.
                    let i = (0..seen.len() - 1)
                        .find(|&i| {
                            dir * seen[i].1[k].slope < 0.0 && dir * seen[i + 1].1[k].slope >= 0.0
                        })
                        .expect("the slope changes sign on the step");
                    let (a, b) = (seen[i].0, seen[i + 1].0);
                    let (fa, fb) = (dir * seen[i].1[k].slope, dir * seen[i + 1].1[k].slope);
                    let smin = brent_fallible(a, b, fa, fb, |x| {
                        let rows = eval(self, x, false)?.1;
                        let slope = dir * rows[k].slope;
                        seen.push((x, rows));
                        Ok(slope)
                    })?;
                    // Brent ends at a point it evaluated or at an end of its bracket.
                    if !seen.iter().any(|e| e.0 == smin) {
                        let rows = eval(self, smin, false)?.1;
                        seen.push((smin, rows));
                    }
                    seen.sort_by(order);
                    let j = seen.iter().position(|e| e.0 == smin).expect("kept");
                    // (below zero from above it: a dip through zero, see `through` below)
                    let dip = seen[j].1[k].value;
                    if (dip < -tol[k] || (dip < 0.0 && ga[k].value > 0.0))
                        && cut.is_none_or(|c| dir * (smin - c) < 0.0)
                    {
                        cut = Some(smin);
                    }
                    // Kept: the ends, the minimum and its neighbours.
                    let keep = [0, j.saturating_sub(1), j, j + 1, seen.len() - 1];
                    let mut i = 0;
                    seen.retain(|_| {
                        i += 1;
                        keep.contains(&(i - 1))
                    });
                }
            }
            if let Some(smin) = cut {
                (pb, gb) = eval(self, smin, false)?;
            }
            let at_bound = at_bound && cut.is_none();
            let delta = pb.alpha - pa.alpha;
            // The step is trusted only where the cubic Hermite model of every guard (from
            // the values and slopes at both ends) predicts a fresh evaluation at the
            // midpoint to within a quarter of the guard's smallest margin on the step (of
            // its values at both ends for a guard that changes sign, whose root is then
            // found on the guard itself): a load that changes faster than the step
            // resolves (an excursion of a guard below zero and back inside one step)
            // fails this test and shortens the step to its first half. A guard already
            // negative at the midpoint is a crossing inside the first half.
            if h > hmin {
                let pm = match eval(self, pa.alpha + 0.5 * delta, false) {
                    Ok(v) => v,
                    Err(Error::Load { .. }) => {
                        h = 0.5 * delta.abs();
                        continue;
                    }
                    Err(e) => return Err(e),
                };
                let gm = &pm.1;
                let untrusted = (0..gb.len()).any(|k| {
                    let (v0, v1, vm) = (ga[k].value, gb[k].value, gm[k].value);
                    let (m0, m1) = (ga[k].slope * delta, gb[k].slope * delta);
                    // Guards near the largest double: the model's sums below overflow, and
                    // an infinite model fails every step. All scaled by one power of two
                    // (exact; the test is homogeneous in them).
                    let sc = overflow_guard(&[v0, v1, vm, m0, m1]);
                    let (v0, v1, vm, m0, m1) = (v0 * sc, v1 * sc, vm * sc, m0 * sc, m1 * sc);
                    // (where v0, v1, vm are all beyond the threshold's bound, v0 above it,
                    // and vm above it or v1 below it, nothing below depends on tol_k: 0
                    // stands for it)
                    let clear =
                        tol.clear_of(k, &[v0, v1, vm], sc) && v0 > 0.0 && (v1 < 0.0 || vm > 0.0);
                    let tol_k = if clear { 0.0 } else { tol[k] * sc };
                    let slope_m = gm[k].slope * delta * sc;
                    let model = 0.5 * (v0 + v1) + 0.125 * (m0 - m1);
                    let margin = if v0 > tol_k && v1 < -tol_k {
                        v0.min(-v1)
                    } else {
                        v0.min(v1).min(vm).max(tol_k)
                    };
                    // the model's slope at the midpoint, against the guard's there (an
                    // error symmetric about the midpoint leaves it, an asymmetric one not)
                    let model_slope = 1.5 * (v1 - v0) - 0.25 * (m0 + m1);
                    (vm < -tol_k && !below[k])
                        || (vm - model).abs() > 0.25 * margin
                        || (slope_m - model_slope).abs() > margin
                });
                if untrusted {
                    h = 0.5 * delta.abs();
                    ahead = Some(pm);
                    continue;
                }
                forced = 0;
            } else {
                forced += 1;
                if forced > MAX_FORCED_STEPS {
                    return Err(Error::Numerical(format!(
                        "the march along a piece of the nonlinear load stalled at alpha = {:e}: {MAX_FORCED_STEPS} steps in a row of at most 1e-12 of the window (of the load's own α scale for a far window) passed no step control{}",
                        pa.alpha,
                        near_overflow(&pa)
                    )));
                }
            }
            self.graph_step.set(Some(delta.abs()));
            // A guard crosses where it is below its threshold at b, or where it went
            // through zero, decreasing, on this step or the one before (and is below zero
            // at b). Taken as a crossing only once below its threshold, a guard that
            // reached zero first was left for the transition at another's root, or missed
            // where it dipped back: under `f0 + φ(α) f1` on a slender strip, a gap closing
            // at a slope of 6.3e-7 stood at −8.0e-12 (threshold 1.05e-11) where another
            // node's guard crossed, and its node touched down there, 5.5e-5 in φ late;
            // another gap dipped to −5.6e-12 (threshold 1.5e-11) about φ's turn, and its
            // touchdown and lift-off were missing (the affine path, which takes each
            // guard's own root, has them).
            let through = |k: usize| {
                let falling = |row: &GuardRow| dir * row.slope < 0.0;
                gb[k].value < 0.0
                    && falling(&ga[k])
                    && (ga[k].value > 0.0
                        || behind.as_ref().is_some_and(|(_, rows)| {
                            rows[k].guard == gb[k].guard && rows[k].value > 0.0 && falling(&rows[k])
                        }))
            };
            // (A frictionless node's slip guard crosses only below its threshold: its value
            // where it stays at zero is rounding of either sign, see `Tol::label_of`.)
            let c = self.consts();
            let crossing: Vec<usize> = (0..gb.len())
                .filter(|&k| {
                    (tol.below(k, gb[k].value, 1.0) && !(below[k] && dir * gb[k].slope > 0.0))
                        || (through(k) && !c.label_only(gb[k].guard))
                })
                .collect();
            if crossing.is_empty() {
                // Hermite check for a dip below zero inside the step
                if dips(&ga, &gb, delta, &tol, |k| below[k]) && h > hmin {
                    h *= 0.5;
                    continue;
                }
                if at_bound {
                    // From the data where pb came from the basis solutions.
                    let pt = match basis {
                        Some(_) => eval(self, pb.alpha, true)?.0,
                        None => pb,
                    };
                    return Ok(Exit::Window(pt));
                }
                for (k, b) in below.iter_mut().enumerate() {
                    *b = *b && tol.below(k, gb[k].value, 1.0);
                }
                behind = Some((pa.alpha, ga));
                pa = pb;
                ga = gb;
                h = (2.0 * h).min(hmax);
                continue;
            }
            // A step too short to be tested (h ≤ hmin: halved down to there) over which a
            // crossing guard's values disagree with its slopes by more than its threshold:
            // the solves at neighbouring α differ by more than the thresholds (cond · ε of
            // an ill-conditioned piece), so no crossing can be located on them; taking one
            // anyway reported spurious transitions and folds. Stop loudly instead.
            if h <= hmin {
                for &k in &crossing {
                    let drift =
                        gb[k].value - ga[k].value - 0.5 * (ga[k].slope + gb[k].slope) * delta;
                    if drift.abs() > tol[k] {
                        let node = gb[k].guard.node + 1;
                        // One rounding of α moves the guard by |slope| ε |α|: a load
                        // computed from α (sin(ω α) at ω α = 2e7 is off by 2e-9) is no
                        // more accurate than that, whatever the solves.
                        let by_alpha = 0.5
                            * (ga[k].slope.abs() + gb[k].slope.abs())
                            * f64::EPSILON
                            * pb.alpha.abs();
                        let cause = if by_alpha > tol[k] {
                            format!(
                                "at |alpha| = {:e} one rounding of alpha moves this guard by {by_alpha:e}, more than its threshold, so a load (or its weights) computed from alpha is too inaccurate here, whatever the solves: write the load on an alpha axis centred on the window (alpha - alpha_start), or raise zero_tol",
                                pb.alpha.abs()
                            )
                        } else if let Some(h) = self.load.difference_step(pb.alpha) {
                            format!(
                                "this load has no derivative, and its slopes come from central differences with the step h = {h:e} (eps^(1/3) max(1, |alpha|)), too long where the load changes faster (or the solves of the load are too inaccurate here, cond · eps): give the load's derivative, or write the load on an alpha axis centred on the window (alpha - alpha_start)"
                            )
                        } else if self.load.basis_vectors().is_some() {
                            "the solves along this piece (cond · eps) or the load's weights are too inaccurate here: build the problem with extended precision, or raise zero_tol".to_string()
                        } else {
                            "the solves of this nonlinear load are too inaccurate here (cond · eps): give the load as affine or basis (carried in extended precision), or raise zero_tol".to_string()
                        };
                        return Err(Error::Numerical(format!(
                            "the load's solutions at alpha = {:e} and {:e} disagree by {:e} on a guard of node {node}, more than its zero threshold {:e}, so no transition can be located on them; {cause}",
                            pa.alpha,
                            pb.alpha,
                            drift.abs(),
                            tol[k]
                        )));
                    }
                }
            }
            // The root of each crossing guard (safeguarded Newton on its values and
            // slopes), until the guard is within 64 roundings of its own scale (its
            // tolerance is `zero_tol` of that scale), then one more Newton step, not
            // evaluated (see [`newton_bracketed`]): the earliest root wins.
            let roundings = 64.0 * f64::EPSILON / self.opts.zero_tol;
            let fine = roundings.min(0.25);
            let mut first: Option<(f64, Guard)> = None;
            for &k in &crossing {
                let g = gb[k].guard;
                let (a0, b0) = (pa.alpha, pb.alpha);
                let fa = ga[k].value;
                let fb = gb[k].value;
                // A guard already at or below zero at α_a (within its threshold there, so
                // not taken as a crossing then) reached zero on the step before: its root
                // is found there, not taken at α_a. That was up to threshold / slope late
                // (1.4e-7 in α for a gap of terms 1.3e3 closing at a slope of 1.4 per unit
                // α, as general loads' thresholds include the load's change over the
                // window).
                let earlier = behind
                    .as_ref()
                    .map(|(a, rows)| (*a, rows[k].guard, rows[k].value, rows[k].slope))
                    .filter(|&(_, guard, value, _)| guard == g && value > 0.0 && fa <= 0.0);
                // A guard that rose on the step before and turned down to at or below zero
                // by α_a, all of it within its threshold (a node that touched down again
                // within that step: a contact force dipping through zero by less than its
                // threshold opens its node for a stretch of α shorter than a step): its
                // root is the one after its maximum on that step (Brent on its slope),
                // where the maximum is above zero. Taken at α_a, the touchdown was 3.8e-8
                // in α late under a basis load whose force dipped by 2e-12. Also where it
                // was above zero at the step's start (`earlier`): that start may be the
                // guard's other root, the piece's entry. Under a load that turns just past
                // a transition (φ's maximum 1e-5 beyond a lift-off, relative), the gap of
                // the node lifting off rose to 3e-11 (threshold 1.5e-11) and came back,
                // and the root taken on the whole step was the entry itself: the node
                // touched down again at the α where it lifted off, the way back was taken
                // as a fold, and the path went back to the window's start, without an
                // error.
                let turned = behind
                    .as_ref()
                    .filter(|(_, rows)| {
                        fa <= 0.0
                            && dir * ga[k].slope < 0.0
                            && rows[k].guard == g
                            && dir * rows[k].slope > 0.0
                    })
                    .map(|(a, rows)| (*a, rows[k].slope));
                // A guard the piece was entered through (`below`), rising at α_a and
                // falling at α_b: it turned down on this step, and its root is the one
                // after its maximum. Taken from α_a (at or below zero there, the root was α_a,
                // then moved onto the guard's zero along the piece), it was the rising zero,
                // the piece's entry: under a load turning just past a touchdown (φ's maximum
                // 1e-8 beyond it, relative) the touchdown came out 4e-8 in α early (its gap
                // flat within rounding), the contact force at the entry was −1.2e-11
                // (threshold 1.4e-12), and the node lifted off where it had touched down:
                // the way back was taken as a fold, and the path went back to the window's
                // start without an error.
                let entered =
                    below[k] && dir * ga[k].slope > 0.0 && dir * gb[k].slope < 0.0 && fa <= tol[k];
                let top_on = |this: &mut Self, (a, sa): (f64, f64), (b, sb): (f64, f64)| {
                    let top = brent_fallible(a, b, dir * sa, dir * sb, |x| {
                        Ok(dir * eval(this, x, false)?.1[k].slope)
                    })?;
                    let row = eval(this, top, false)?.1[k].clone();
                    Ok::<_, Error>((row.value > 0.0).then_some((top, row.value, row.slope)))
                };
                let peak = match turned {
                    Some((a_prev, s_prev)) => top_on(self, (a_prev, s_prev), (a0, ga[k].slope))?,
                    None if entered => top_on(self, (a0, ga[k].slope), (b0, gb[k].slope))?,
                    None => None,
                };
                // The root's bracket: after the maximum, on the step before, or on this
                // step (none for a guard already at or below zero at α_a: the root is α_a).
                let sa = (a0, fa, ga[k].slope);
                let bracket = if let Some(top) = peak {
                    Some((top, if entered { (b0, fb, gb[k].slope) } else { sa }))
                } else if let Some((a_prev, _, value, slope)) = earlier {
                    Some(((a_prev, value, slope), sa))
                } else if fa <= 0.0 {
                    None
                } else {
                    Some((sa, (b0, fb, gb[k].slope)))
                };
                // After a maximum the guard is flat: a value within `fine` of its
                // threshold may lie far from the root in α, and the maximum itself passed
                // as the root where it was below that (at a turn of φ 1e-8 past a
                // lift-off, the gap's maximum was 8e-14 against 9e-14, and the node touched
                // down at φ's turn, where no direction along α is decided). There the value
                // must also be below a sixteenth of the maximum's.
                // Likewise before a minimum, where the step ends at one (`cut`): there the
                // value must be below a sixteenth of the minimum's depth. At a turn of φ 1e-8
                // past a touchdown, the gap's minimum was −6.7e-15 against 2.1e-14, and the
                // node touched down at φ's turn, 4e-5 in α late.
                let accept = match peak {
                    Some((_, top, _)) => (fine * tol[k]).min(top / 16.0),
                    None if cut.is_some() && fb < 0.0 => (fine * tol[k]).min(-fb / 16.0),
                    None => fine * tol[k],
                };
                let root = match bracket {
                    Some((from, to)) => newton_bracketed(from, to, accept, |x| {
                        let rows = eval(self, x, false)?.1;
                        Ok((rows[k].value, rows[k].slope))
                    })?,
                    None => a0,
                };
                if first.is_none_or(|f| dir * (root - f.0) < 0.0) {
                    first = Some((root, g));
                }
            }
            let (root, g) = first.expect("at least one crossing");
            let (mut pt, tab) = eval(self, root, true)?;
            // Up to the root, no guard may dip below zero: neither at the root itself nor
            // in its cubic Hermite model on [α_a, root] (the models were trusted on the
            // whole step). Else the step is shortened to the first half of that stretch.
            // (A root on the step before lies on a stretch already trusted.)
            let stretch = root - pa.alpha;
            let before = dir * stretch < 0.0;
            let dip = !before && dips(&ga, &tab, stretch, &tol, |k| below[k] || tab[k].guard == g);
            if dip && h > hmin && stretch != 0.0 {
                h = 0.5 * stretch.abs();
                continue;
            }
            // Under a basis load the root is that of the guard combined from the basis
            // solutions, whose terms may cancel (weights that cancel 100-fold): there the
            // combination has lost digits, and the point solved for from the data at the
            // root can miss the guard's zero by more than the join's tolerance. So the
            // root is found again on the piece through that checked point `pt`:
            // `λ(α) = λ(α_r) + Σ_j (w_j(α) − w_j(α_r)) y_j`, whose terms are small near
            // α_r (nothing left to cancel) and smooth in α. (Checking and correcting each
            // trial point from the data instead moved each by up to cond · its residual,
            // differently at each α: on the ill-conditioned pieces of a slender body,
            // cond ~ 1e8 and more, the guards at neighbouring points then disagreed by
            // more than the join's tolerance.) A Newton step from the root, taken where
            // the guard is well inside the join's tolerance there, else a bracket about
            // it and Brent; the point that ends the piece is checked from the data.
            // The stretch of α the root was found on.
            let from = match &behind {
                Some((a_prev, _)) if before => *a_prev,
                _ => pa.alpha,
            };
            let (lo_a, hi_a) = (from.min(pb.alpha), from.max(pb.alpha));
            if let Some(bs) = &basis
                && let Some(k) = tab.iter().position(|r| r.guard == g)
                && let Some((w_r, _)) = self.load.weights_at(root)
            {
                let w_r = w_r.to_vec();
                let root_pt = Entry {
                    q: pt.q.clone(),
                    lam: pt.lam.clone(),
                    d: self.gaps(&pt).to_vec(),
                };
                let through = |this: &mut Self, x: f64| -> Result<(Point, Vec<GuardRow>)> {
                    let at = this.point_at(Vec::new(), x)?;
                    let Some((w, dw)) = this.load.weights_at(x) else {
                        return Err(Error::Numerical(format!(
                            "the basis load's weights at alpha = {x:e} are missing"
                        )));
                    };
                    let [lam, d, mut t, rate] =
                        bs.starting_at((&root_pt, &w_r), &at.q, (w, dw), &at.dq);
                    t.push(1.0);
                    let table = this.guard_rows(&classes, &lam, &d, Some((&t, &rate)));
                    Ok((Point { lam, ..at }, table))
                };
                let (mut x0, mut v0) = (root, tab[k].value);
                let slope = tab[k].slope;
                let accept = self.root_accept(&pt, g);
                let mut bracket = None;
                let mut best: Option<Point> = None;
                let mut step = -v0 / slope;
                for _ in 0..8 {
                    if v0 == 0.0 || !step.is_finite() || step == 0.0 {
                        break;
                    }
                    let x1 = (x0 + step).clamp(lo_a, hi_a);
                    if x1 == x0 {
                        break;
                    }
                    let (p1, t1) = through(self, x1)?;
                    let v1 = t1[k].value;
                    if v1.abs() <= accept {
                        best = Some(p1);
                        break;
                    }
                    if (v1 > 0.0) != (v0 > 0.0) || v1 == 0.0 {
                        bracket = Some((x0, v0, x1, v1, p1));
                        break;
                    }
                    if v1.abs() < v0.abs() {
                        (x0, v0) = (x1, v1);
                        best = Some(p1);
                    }
                    step *= 2.0;
                }
                if let Some((xa, va, xb, vb, at_b)) = bracket {
                    best = Some(if vb == 0.0 {
                        at_b
                    } else {
                        // Brent stops at a value within `accept` (reported as a zero).
                        let r = brent_fallible(xa, xb, va, vb, |x| {
                            let v = through(self, x)?.1[k].value;
                            Ok(if v.abs() <= accept { 0.0 } else { v })
                        })?;
                        if r == xb { at_b } else { through(self, r)?.0 }
                    });
                }
                // The end point from the data: its residual on the piece's equations
                // (one product with W) within a solve's check, else solved for there.
                if let Some(p) = best {
                    let qg = shift_gap(&p.q, self.problem.gap_equilibrated());
                    let (rel, d_data, _) = self.point_residual(&cur.classes, &qg, &p.lam);
                    pt = if rel <= 1e-12 {
                        self.prime_gaps(p.alpha, &p.lam, d_data);
                        p
                    } else {
                        eval(self, p.alpha, true)?.0
                    };
                }
                let tangent = |this: &Self, pt: &Point| {
                    let (w, dw) = this.load.weights_at(pt.alpha)?;
                    let qg = shift_gap(&pt.q, this.problem.gap_equilibrated());
                    let [_, _, t, rate] = bs.at(w, dw, &qg, &pt.dq);
                    Some([t, rate])
                };
                pt = self.onto_guard_zero(pt, g, tangent, (lo_a, hi_a))?;
                if let Some(p) = self.polish_root(cur, bs, (k, slope), (lo_a, hi_a), &pt)? {
                    pt = p;
                }
            } else if basis.is_none() {
                // A general load's root, in α, as above. The load is given in double at
                // each α: the rounding of each entry of f(α) (ε |f|, in no direction along
                // the path) moves the piece's solution by its conditioning times that, a
                // noise from α to α that no refinement of the solves removes, and the
                // root's search in α ends where that noise hides the guard's sign. On a
                // slender strip (F = 5, κ(W) ~ 1e8, carried in extended precision) a cone
                // guard's values at neighbouring doubles of α went +3.9e-11, −2.0e-11,
                // +1.2e-11 (threshold 3.5e-11, slope −1.1e4 per unit α), on another
                // ±6e-10 (threshold 6.5e-12): the search ended with the guard at 1.1 and
                // 49 times its threshold, the node fitted one class or none, and the path
                // stopped. Moved along the piece's tangent by −v/γ' (3.5e-15 and 8.7e-14
                // in α), the point is at the guard's zero, as far from the data as that
                // noise.
                let tangent = |this: &Self, pt: &Point| {
                    let qg = shift_gap(&pt.q, this.problem.gap_equilibrated());
                    let [_, _, t, rate] = solve(this, &qg, &pt.dq);
                    Some([t, rate])
                };
                pt = self.onto_guard_zero(pt, g, tangent, (lo_a, hi_a))?;
            }
            return Ok(Exit::Guards(pt, vec![g]));
        }
    }
}
