//! The fixed-α solver (SPEC §5): finds `λ` with `H(λ, α) = 0` in the condensed variables.
//!
//! 1. **Semi-smooth Newton** (primal–dual active set): the classes are read off the
//!    projection arguments of `H` at the current `λ`; the Newton point is the solution of
//!    that piece's linear equations (H is piecewise linear, so this *is* the Newton step).
//!    A backtracking line search on `½‖H‖²` globalises it; the merit decreases strictly,
//!    so the iteration cannot cycle. It stops when the line search stalls, or after 20
//!    steps at first: where classes change often its steps shrink and it creeps, and
//!    the same steps taken in full (the **active-set iteration**, which stops at a cycle
//!    of class vectors) usually find the classes in a few tens of steps; Newton then
//!    goes on from the best of them.
//! 2. **Projected block Gauss–Seidel** on the 2×2 node blocks, each local Coulomb
//!    problem solved exactly by enumerating its four classes, followed by Newton again:
//!    20 rounds of 20 sweeps each.
//! 3. **Continuation in the friction coefficients** from the frictionless problem (see
//!    `friction_continuation`).
//! 4. A long Gauss–Seidel run (20,000 sweeps) and Newton; Newton from zero forces and
//!    from the all-stick piece.
//! 5. Otherwise: [`crate::Error::SolveFailed`] saying what each stage reached.
//!
//! A returned `λ` always satisfies `‖H‖∞ ≤ 1e-12` relative to its force scale, or is the
//! caller's polish of a stalled iterate (see `solve_fixed_alpha`).

use faer::MatRef;

use crate::class::Class;
use crate::error::{Error, Result};
use crate::path::update::{self, UpdatedLu};
use crate::piece::{DenseLu, PieceConstants, displacement_gaps};

/// Relative residual accepted as a solution.
const TOL: f64 = 1e-12;

/// Nodes whose class is imposed (`Some`) rather than found; used for the directional
/// problems at vertex points of the path (see [`crate::path`]).
pub(crate) type Frozen<'a> = Option<&'a [Option<Class>]>;

fn frozen_class(frozen: Frozen<'_>, i: usize) -> Option<Class> {
    frozen.and_then(|f| f[i])
}

/// `H2, H3` of the seed (2p values) at `λ` (with its `d = q − (g, 0) + W λ`), and the
/// force scale of each node (p values) that makes its two entries relative: the
/// magnitudes of the node's own terms (`λ_i`, `r d_i`, `r (q − g)_i`, `r (W λ)_i`), but
/// not below a thousandth of the point's force scale (forces, `r W λ`, and `r q` where
/// the load alone presses or shears). A node far from the foundation (a large gap) does
/// not set the scale of the others, and a node with small forces is held to its own.
/// Frozen nodes contribute the residuals of their class's equations instead.
fn h_condensed(
    c: &PieceConstants,
    qg: &[f64],
    lam: &[f64],
    d: &[f64],
    frozen: Frozen<'_>,
) -> (Vec<f64>, Vec<f64>) {
    let p = c.p;
    let mut h = vec![0.0; 2 * p];
    let mut own = vec![0.0f64; p];
    let mut global = 1e-300f64;
    for i in 0..p {
        let (ln, lt) = (lam[i], lam[p + i]);
        if let Some(cl) = frozen_class(frozen, i) {
            let [e_nu, e_t] = c.equations(i, cl);
            h[i] = e_nu.eval(lam, d);
            h[p + i] = e_t.eval(lam, d);
        } else {
            h[i] = ln - (ln - c.r * d[i]).min(0.0);
            let b = (-c.friction[i] * ln).max(0.0);
            h[p + i] = lt - (lt - c.r * d[p + i]).clamp(-b, b);
        }
        let (wl_n, wl_t) = ((d[i] - qg[i]).abs(), (d[p + i] - qg[p + i]).abs());
        own[i] = ln
            .abs()
            .max(lt.abs())
            .max(c.r * d[i].abs())
            .max(c.r * d[p + i].abs())
            .max(c.r * qg[i].abs())
            .max(c.r * qg[p + i].abs())
            .max(c.r * wl_n)
            .max(c.r * wl_t);
        global = global
            .max(ln.abs())
            .max(lt.abs())
            .max(c.r * qg[i].max(0.0))
            .max(c.r * qg[p + i].abs())
            .max(c.r * wl_n)
            .max(c.r * wl_t);
    }
    let scales = own.iter().map(|&s| s.max(1e-3 * global)).collect();
    (h, scales)
}

/// `max_i max(|H2_i|, |H3_i|) / scale_i` (see [`h_condensed`]).
fn rel_residual(c: &PieceConstants, qg: &[f64], lam: &[f64], d: &[f64], fr: Frozen<'_>) -> f64 {
    let (h, s) = h_condensed(c, qg, lam, d, fr);
    if h.iter().any(|v| !v.is_finite()) {
        return f64::INFINITY;
    }
    let p = c.p;
    (0..p).fold(0.0f64, |m, i| m.max(h[i].abs().max(h[p + i].abs()) / s[i]))
}

/// [`rel_residual`] of `λ` for `q − (g, 0)` = `qg` with the classes of `fr` imposed, as
/// the solver's stages measure it (one product with W).
pub(crate) fn residual_of(
    problem: &crate::problem::Problem,
    qg: &[f64],
    lam: &[f64],
    fr: Frozen<'_>,
) -> f64 {
    let c = PieceConstants::of(problem);
    let d = displacement_gaps(problem.delassus().w(), qg, lam);
    rel_residual(&c, qg, lam, &d, fr)
}

fn merit(c: &PieceConstants, qg: &[f64], lam: &[f64], d: &[f64], fr: Frozen<'_>) -> f64 {
    let (h, _) = h_condensed(c, qg, lam, d, fr);
    0.5 * h.iter().map(|v| v * v).sum::<f64>()
}

/// The classes of the generalized Jacobian at `λ` (projection arguments), from λ and its
/// `d = q − (g, 0) + W λ` ([`displacement_gaps`]).
pub(crate) fn active_classes(
    c: &PieceConstants,
    lam: &[f64],
    d: &[f64],
    fr: Frozen<'_>,
) -> Vec<Class> {
    let p = c.p;
    (0..p)
        .map(|i| {
            if let Some(cl) = frozen_class(fr, i) {
                return cl;
            }
            let (ln, lt) = (lam[i], lam[p + i]);
            if ln - c.r * d[i] >= 0.0 {
                return Class::Open;
            }
            let b = (-c.friction[i] * ln).max(0.0);
            let xt = lt - c.r * d[p + i];
            if xt > b {
                Class::SlipMinus
            } else if xt < -b {
                Class::SlipPlus
            } else {
                Class::Stick
            }
        })
        .collect()
}

/// Solves the piece equations of `classes` at fixed α (None if the piece is singular).
pub(crate) fn solve_piece(
    c: &PieceConstants,
    w: MatRef<'_, f64>,
    classes: &[Class],
    qg: &[f64],
) -> Option<Vec<f64>> {
    let m = 2 * c.p;
    let zeros = vec![0.0; m];
    let (j, rhs) = c.jacobian(w, classes, qg, &zeros, 0.0);
    let sq = j.as_ref().subcols(0, m);
    let lu = DenseLu::new(sq);
    if lu.det_sign == 0 || lu.pivot_ratio < 1e-14 {
        return None;
    }
    let x = lu.solve(&rhs);
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Piece solves at fixed α by updates of the last factorisation (see
/// [`crate::path::update`]).
struct PieceSolves<'a> {
    c: &'a PieceConstants<'a>,
    w: MatRef<'a, f64>,
    lu: Option<UpdatedLu>,
    row_bound: f64,
}

impl<'a> PieceSolves<'a> {
    /// Starting from `seed` (a factorisation to update, e.g. the path's current one) when
    /// given. `w_row_sums`: W's absolute row sums ([`crate::problem::Problem::w_row_sums`]).
    fn new(
        c: &'a PieceConstants<'a>,
        w: MatRef<'a, f64>,
        w_row_sums: &[f64],
        seed: Option<UpdatedLu>,
    ) -> Self {
        Self {
            c,
            w,
            lu: seed,
            row_bound: update::row_bound(c, w_row_sums),
        }
    }

    /// As [`solve_piece`], with the solution's `d = q − (g, 0) + W λ` (from the product
    /// that checked the solve).
    fn solve(&mut self, classes: &[Class], qg: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        let with_d = |x: Vec<f64>, wx: Vec<f64>| {
            let d: Vec<f64> = qg.iter().zip(&wx).map(|(a, b)| a + b).collect();
            (x.iter().chain(&d).all(|v| v.is_finite())).then_some((x, d))
        };
        let rhs = self.c.piece_rhs(classes, qg);
        let extended = self
            .lu
            .as_ref()
            .filter(|u| u.reaches(classes))
            .and_then(|u| u.extend(self.c, self.w, classes, None, &[]))
            .map(|(u, _)| u);
        if let Some(u) = extended {
            let crate::path::update::Checked { x, rel, wx, .. } =
                u.solve_checked(self.c, self.w, &rhs, self.row_bound);
            if rel <= 1e-12
                && let Some(xd) = with_d(x, wx)
            {
                self.lu = Some(u);
                return Some(xd);
            }
        }
        // A fresh factorisation, with the singularity test of solve_piece.
        let u = UpdatedLu::factor(self.c, self.w, classes)?;
        if u.pivot_ratio() < 1e-14 {
            return None;
        }
        let checked = u.solve_checked(self.c, self.w, &rhs, self.row_bound);
        self.lu = Some(u);
        with_d(checked.x, checked.wx)
    }
}

/// Semi-smooth Newton with Armijo backtracking. Returns the last iterate and whether it
/// converged, plus a short description.
fn newton(
    pieces: &mut PieceSolves<'_>,
    qg: &[f64],
    lam0: Vec<f64>,
    max_iter: usize,
    fr: Frozen<'_>,
) -> (Vec<f64>, bool, String) {
    let (c, w) = (pieces.c, pieces.w);
    let mut lam = lam0;
    // d = q − (g, 0) + W λ of the iterate: one product with W per iteration (W is 8m²
    // bytes, so on a large contact boundary these products, not the O(m²) updated solves,
    // were most of the solver's time when each function below made its own).
    let mut d = displacement_gaps(w, qg, &lam);
    let mut phi = merit(c, qg, &lam, &d, fr);
    // Consecutive Newton steps usually change the classes of a few nodes: their piece
    // matrices are solved by rank-2 updates of one factorisation (O(m²) each), with a
    // fresh factorisation when many nodes changed or an update loses accuracy.
    for it in 0..max_iter {
        if rel_residual(c, qg, &lam, &d, fr) <= TOL {
            return (lam, true, format!("Newton converged in {it} iterations"));
        }
        let classes = active_classes(c, &lam, &d, fr);

        let Some((ln, dn)) = pieces.solve(&classes, qg) else {
            return (
                lam,
                false,
                format!("Newton: singular piece at iteration {it}"),
            );
        };
        if rel_residual(c, qg, &ln, &dn, fr) <= TOL {
            return (
                ln,
                true,
                format!("Newton converged in {} iterations", it + 1),
            );
        }
        // The full step is the piece's solution; d is affine in λ, so a shorter step's d
        // is interpolated for its merit, and computed afresh once the step is taken.
        let between = |tau: f64| -> (Vec<f64>, Vec<f64>) {
            let mix = |a: &[f64], b: &[f64]| -> Vec<f64> {
                a.iter().zip(b).map(|(x, y)| x + tau * (y - x)).collect()
            };
            (mix(&lam, &ln), mix(&d, &dn))
        };
        let mut tau = 1.0;
        let mut accepted = false;
        while tau > 1e-10 {
            let (trial, dt) = if tau == 1.0 {
                (ln.clone(), dn.clone())
            } else {
                between(tau)
            };
            let pt = merit(c, qg, &trial, &dt, fr);
            if pt <= (1.0 - 1e-4 * tau) * phi {
                d = if tau == 1.0 {
                    dt
                } else {
                    displacement_gaps(w, qg, &trial)
                };
                lam = trial;
                phi = merit(c, qg, &lam, &d, fr);
                accepted = true;
                break;
            }
            tau *= 0.5;
        }
        if !accepted {
            let msg = format!(
                "Newton: line search stalled at iteration {it} (residual {:e})",
                rel_residual(c, qg, &lam, &d, fr)
            );
            return (lam, false, msg);
        }
    }
    let res = rel_residual(c, qg, &lam, &d, fr);
    (
        lam,
        false,
        format!("Newton: {max_iter} iterations, residual {res:e}"),
    )
}

/// The primal–dual active-set iteration: Newton's full step (the solution of the piece
/// whose classes the projections give at the current λ), without a line search. It
/// usually finds the classes in a few tens of steps where the damped Newton of
/// [`newton`] creeps (its merit function is not smooth where classes change), but it is
/// not globally convergent: it stops when a class vector comes back (a cycle), when a
/// piece is singular, or after `max_iter` steps, and returns the iterate with the least
/// residual for [`newton`] to go on from.
fn active_set(
    pieces: &mut PieceSolves<'_>,
    qg: &[f64],
    lam0: Vec<f64>,
    max_iter: usize,
    fr: Frozen<'_>,
) -> (Vec<f64>, bool, String) {
    let (c, w) = (pieces.c, pieces.w);
    let mut d = displacement_gaps(w, qg, &lam0);
    let mut res = rel_residual(c, qg, &lam0, &d, fr);
    let mut best = (res, lam0.clone());
    let mut lam = lam0;
    let mut seen = std::collections::HashSet::new();
    for it in 0..max_iter {
        if res <= TOL {
            return (lam, true, format!("active set converged in {it} steps"));
        }
        let classes = active_classes(c, &lam, &d, fr);
        if !seen.insert(classes.clone()) {
            return (
                best.1,
                false,
                format!("active set: a cycle after {it} steps"),
            );
        }
        let Some((next, dn)) = pieces.solve(&classes, qg) else {
            return (
                best.1,
                false,
                format!("active set: singular piece at step {it}"),
            );
        };
        (lam, d) = (next, dn);
        res = rel_residual(c, qg, &lam, &d, fr);
        if res < best.0 {
            best = (res, lam.clone());
        }
    }
    if res <= TOL {
        return (
            lam,
            true,
            format!("active set converged in {max_iter} steps"),
        );
    }
    (
        best.1,
        false,
        format!("active set: {max_iter} steps, residual {:e}", best.0),
    )
}

/// Exact solution of the 2×2 Coulomb problem of one node: `d = d0 + W_ii λ_i`.
/// Among the consistent classes, the one closest to `current` is taken.
fn local_coulomb(
    wl: [[f64; 2]; 2],
    d0: [f64; 2],
    f: f64,
    current: [f64; 2],
    frozen: Option<Class>,
) -> [f64; 2] {
    if let Some(cl) = frozen {
        return local_class(wl, d0, f, cl).unwrap_or(current);
    }
    let mut best: Option<([f64; 2], f64)> = None;
    let mut consider = |l: [f64; 2]| {
        let dist = (l[0] - current[0]).powi(2) + (l[1] - current[1]).powi(2);
        if best.is_none_or(|b| dist < b.1) {
            best = Some((l, dist));
        }
    };
    // open
    if d0[0] <= 0.0 {
        consider([0.0, 0.0]);
    }
    // stick: W l = -d0
    let det = wl[0][0] * wl[1][1] - wl[0][1] * wl[1][0];
    if det > 0.0 {
        let ln = (-d0[0] * wl[1][1] + d0[1] * wl[0][1]) / det;
        let lt = (-d0[1] * wl[0][0] + d0[0] * wl[1][0]) / det;
        if ln <= 0.0 && lt.abs() <= -f * ln {
            consider([ln, lt]);
        }
    }
    // slip±: λt = ±F λν... S+: λt = F λν, dt ≥ 0; S−: λt = −F λν, dt ≤ 0
    for s in [1.0, -1.0] {
        let den = wl[0][0] + s * f * wl[0][1];
        if den > 0.0 {
            let ln = -d0[0] / den;
            let lt = s * f * ln;
            let dt = d0[1] + wl[1][0] * ln + wl[1][1] * lt;
            if ln <= 0.0 && s * dt >= 0.0 {
                consider([ln, lt]);
            }
        }
    }
    best.map(|b| b.0).unwrap_or(current)
}

/// The solution of one node's 2×2 equations for an imposed class (no sign checks).
fn local_class(wl: [[f64; 2]; 2], d0: [f64; 2], f: f64, cl: Class) -> Option<[f64; 2]> {
    match cl {
        Class::Open => Some([0.0, 0.0]),
        Class::Stick => {
            let det = wl[0][0] * wl[1][1] - wl[0][1] * wl[1][0];
            (det != 0.0).then(|| {
                [
                    (-d0[0] * wl[1][1] + d0[1] * wl[0][1]) / det,
                    (-d0[1] * wl[0][0] + d0[0] * wl[1][0]) / det,
                ]
            })
        }
        Class::SlipPlus | Class::SlipMinus => {
            let s = if cl == Class::SlipPlus { 1.0 } else { -1.0 };
            let den = wl[0][0] + s * f * wl[0][1];
            (den != 0.0).then(|| {
                let ln = -d0[0] / den;
                [ln, s * f * ln]
            })
        }
    }
}

fn block_gauss_seidel(
    c: &PieceConstants,
    w: MatRef<'_, f64>,
    qg: &[f64],
    lam0: Vec<f64>,
    sweeps: usize,
    fr: Frozen<'_>,
) -> Vec<f64> {
    let p = c.p;
    let mut lam = lam0;
    let mut d = displacement_gaps(w, qg, &lam);
    for _ in 0..sweeps {
        let mut change = 0.0f64;
        let mut size = 1e-300f64;
        for i in 0..p {
            let (a, b) = (i, p + i);
            let wl = [[w[(a, a)], w[(a, b)]], [w[(b, a)], w[(b, b)]]];
            let cur = [lam[a], lam[b]];
            let d0 = [
                d[a] - wl[0][0] * cur[0] - wl[0][1] * cur[1],
                d[b] - wl[1][0] * cur[0] - wl[1][1] * cur[1],
            ];
            let new = local_coulomb(wl, d0, c.friction[i], cur, frozen_class(fr, i));
            let delta = [new[0] - cur[0], new[1] - cur[1]];
            if delta[0] != 0.0 || delta[1] != 0.0 {
                for (k, dk) in d.iter_mut().enumerate() {
                    *dk += w[(k, a)] * delta[0] + w[(k, b)] * delta[1];
                }
                lam[a] = new[0];
                lam[b] = new[1];
            }
            change = change.max(delta[0].abs()).max(delta[1].abs());
            size = size.max(new[0].abs()).max(new[1].abs());
        }
        if change <= 1e-14 * size {
            break;
        }
    }
    lam
}

/// Solves `H(λ, α) = 0` for `q − (g, 0)` given (2p values), from `guess` or zero forces.
/// `alpha` is only used in messages.
///
/// `polish`, where given, is offered each stage's last iterate when the stage stalls; a
/// point it returns is taken as the solution. The path passes one where W is carried
/// beyond double: it solves the iterate's piece again in double-double until the classes
/// settle (an exact solution of `H = 0` to that precision), which reaches solutions that
/// no double iterate reaches on an ill-conditioned W (κ(W) = 2.7e12: every stage stalled
/// at residuals of 1e-8 to 4e-11, also without friction). `stages`: which of them run.
pub(crate) fn solve_fixed_alpha(
    problem: &crate::problem::Problem,
    qg: &[f64],
    guess: Option<&[f64]>,
    alpha: f64,
    stages: Stages,
    polish: Polish<'_>,
) -> Result<Vec<f64>> {
    solve_with_frozen(problem, qg, guess, alpha, None, stages, None, polish).map(|(lam, _)| lam)
}

/// Which stages of [`solve_with_frozen`] run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stages {
    /// Newton, the active-set iteration, Newton again, and 20 rounds of Gauss–Seidel
    /// sweeps and Newton (a first pass: where these fail, so does the solve).
    First,
    /// [`Stages::First`] and the continuation in the friction coefficients: all but the
    /// long runs, which cost most where they fail too.
    NoLongRuns,
    /// Every stage, down to the continuation in the friction coefficients, the long
    /// Gauss–Seidel run and the restarts.
    All,
}

/// See [`solve_fixed_alpha`]: a last chance for a stalled iterate.
pub(crate) type Polish<'a> = Option<&'a mut dyn FnMut(&[f64]) -> Option<Vec<f64>>>;

/// As [`solve_fixed_alpha`], with the classes of some nodes imposed, and the piece solves
/// by updates of `seed` where given (a factorisation of a nearby piece: the path's, for
/// the directional problem at a vertex, so that it costs O(m²) per piece, not O(m³)).
/// Also returns the factorisation of the last piece it solved, where any (a seed for the
/// next solve nearby, see [`newton_near`]). With [`Stages::First`] it fails where the
/// first stages do, without the costly last ones.
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_with_frozen(
    problem: &crate::problem::Problem,
    qg: &[f64],
    guess: Option<&[f64]>,
    alpha: f64,
    fr: Frozen<'_>,
    stages: Stages,
    seed: Option<UpdatedLu>,
    polish: Polish<'_>,
) -> Result<(Vec<f64>, Option<UpdatedLu>)> {
    let c = PieceConstants::of(problem);
    let w_row_sums = problem.w_row_sums();
    let mut pieces = PieceSolves::new(&c, problem.delassus().w(), w_row_sums, seed);
    let lam = solve_stages(
        &mut pieces,
        w_row_sums,
        qg,
        guess,
        alpha,
        (fr, stages),
        polish,
    )?;
    Ok((lam, pieces.lu))
}

/// Damped Newton alone from `guess`, its piece solves by updates of `seed`: for a problem
/// next to one just solved, whose solution and last factorisation ([`solve_with_frozen`])
/// are `guess` and `seed`. The solution and the factorisation of the last piece it
/// solved; None where Newton does not converge within `max_iter` iterations (the caller
/// then solves from scratch).
pub(crate) fn newton_near(
    problem: &crate::problem::Problem,
    qg: &[f64],
    guess: Vec<f64>,
    fr: Frozen<'_>,
    seed: Option<UpdatedLu>,
    max_iter: usize,
) -> Option<(Vec<f64>, Option<UpdatedLu>)> {
    let c = PieceConstants::of(problem);
    let mut pieces = PieceSolves::new(&c, problem.delassus().w(), problem.w_row_sums(), seed);
    let (lam, ok, _) = newton(&mut pieces, qg, guess, max_iter, fr);
    ok.then_some((lam, pieces.lu))
}

/// The stages of [`solve_with_frozen`] on `pieces`.
fn solve_stages(
    pieces: &mut PieceSolves<'_>,
    w_row_sums: &[f64],
    qg: &[f64],
    guess: Option<&[f64]>,
    alpha: f64,
    (fr, stages): (Frozen<'_>, Stages),
    mut polish: Polish<'_>,
) -> Result<Vec<f64>> {
    let (c, w) = (pieces.c, pieces.w);
    let m = 2 * c.p;
    let lam0 = guess.map(|g| g.to_vec()).unwrap_or_else(|| vec![0.0; m]);
    let mut notes = Vec::new();
    let mut polished = |lam: &[f64]| polish.as_mut().and_then(|f| f(lam));
    let lam = match newton_active_newton(pieces, qg, lam0, [20, 100, 200], fr) {
        Ok(lam) => return Ok(lam),
        Err((lam, msgs)) => {
            notes.extend(msgs);
            lam
        }
    };
    if let Some(lam) = polished(&lam) {
        return Ok(lam);
    }
    // Newton stalls where its merit function is not smooth (classes change): a few block
    // Gauss-Seidel sweeps move the iterate off such a kink, and Newton resumes from there.
    // Rounds of both before the long Gauss-Seidel run below (each sweep is O(m²)).
    let mut lam = lam;
    for round in 0..20 {
        let lam_gs = block_gauss_seidel(c, w, qg, lam, 20, fr);
        let (l, ok, msg) = newton(pieces, qg, lam_gs, 50, fr);
        if ok {
            return Ok(l);
        }
        lam = l;
        if round == 19 {
            notes.push(format!("after 20 rounds of 20 sweeps and Newton: {msg}"));
        }
    }
    if let Some(lam) = polished(&lam) {
        return Ok(lam);
    }
    if stages == Stages::First {
        return Err(Error::SolveFailed {
            alpha,
            message: notes.join("; "),
        });
    }
    // The continuation in the friction coefficients before the long Gauss-Seidel run: on
    // a p = 1000 strip with F = 5, mid-load, Newton stalled at a residual of 1e-6 and
    // the active set cycled on the free end's node (slip ↔ open) in every round; the
    // continuation solved it in 2.1 s, where the 20,000 sweeps took 35–55 s before
    // Newton converged (to the same solution: the path from it had the same events).
    match friction_continuation(c, w, w_row_sums, qg, fr) {
        Ok(lam) => return Ok(lam),
        Err(msg) => notes.push(msg),
    }
    if stages == Stages::NoLongRuns {
        return Err(Error::SolveFailed {
            alpha,
            message: notes.join("; "),
        });
    }
    let lam_gs = block_gauss_seidel(c, w, qg, lam, 20_000, fr);
    let (lam, ok, msg) = newton(pieces, qg, lam_gs, 200, fr);
    if ok {
        return Ok(lam);
    }
    if let Some(lam) = polished(&lam) {
        return Ok(lam);
    }
    notes.push(format!("after block Gauss-Seidel: {msg}"));
    // The same from zero forces and from a uniform-stick start.
    for start in [vec![0.0; m], stick_start(c, w, qg)] {
        let (lam, ok, msg) = newton(pieces, qg, start, 200, fr);
        if ok {
            return Ok(lam);
        }
        notes.push(msg);
    }
    Err(Error::SolveFailed {
        alpha,
        message: notes.join("; "),
    })
}

/// The solver's first stages: damped Newton (its line search keeps it near its start, so
/// on a problem with several solutions at α it finds the same one whatever the rounding),
/// then, where it creeps, the active-set iteration from its iterate, then Newton again,
/// with at most `iters` iterations each. The solution, or the last iterate with each
/// stage's message.
fn newton_active_newton(
    pieces: &mut PieceSolves<'_>,
    qg: &[f64],
    lam0: Vec<f64>,
    iters: [usize; 3],
    fr: Frozen<'_>,
) -> std::result::Result<Vec<f64>, (Vec<f64>, Vec<String>)> {
    let mut notes = Vec::new();
    let (lam, ok, msg) = newton(pieces, qg, lam0, iters[0], fr);
    if ok {
        return Ok(lam);
    }
    notes.push(msg);
    let (lam, ok, msg) = active_set(pieces, qg, lam, iters[1], fr);
    if ok {
        return Ok(lam);
    }
    notes.push(msg);
    let (lam, ok, msg) = newton(pieces, qg, lam, iters[2], fr);
    if ok {
        return Ok(lam);
    }
    notes.push(msg);
    Err((lam, notes))
}

/// Where Newton and Gauss–Seidel stall: continuation in the friction coefficients,
/// `F_i(t) = t F_i` for t from 0 to 1, each step's solve ([`newton_active_newton`])
/// started from the last one's solution. With large friction the damped Newton can stall
/// at a stationary point of its merit function that is no solution (found on random
/// problems with F up to 5: 3 starts in 6000), while the frictionless problem (a
/// monotone complementarity problem in the normal forces) is solved from zero forces,
/// and a solution moves continuously with t except at folds in t (then the step is
/// halved). At most [`FRICTION_STEPS`] solves; the error says where it stopped.
fn friction_continuation(
    c: &PieceConstants,
    w: MatRef<'_, f64>,
    w_row_sums: &[f64],
    qg: &[f64],
    fr: Frozen<'_>,
) -> std::result::Result<Vec<f64>, String> {
    let solve_at = |t: f64, lam0: Vec<f64>| -> Option<Vec<f64>> {
        let f: Vec<f64> = c.friction.iter().map(|x| x * t).collect();
        let ct = PieceConstants { friction: &f, ..*c };
        let mut pieces = PieceSolves::new(&ct, w, w_row_sums, None);
        newton_active_newton(&mut pieces, qg, lam0, [50, 100, 50], fr).ok()
    };
    let (mut t, mut h) = (0.0, 0.25);
    let mut lam = solve_at(0.0, vec![0.0; 2 * c.p])
        .ok_or_else(|| "friction continuation: no solution without friction".to_string())?;
    for _ in 0..FRICTION_STEPS {
        let next = if h >= 1.0 - t { 1.0 } else { t + h };
        match solve_at(next, lam.clone()) {
            Some(l) if next == 1.0 => return Ok(l),
            Some(l) => {
                (t, lam, h) = (next, l, 2.0 * h);
            }
            None => h *= 0.5,
        }
    }
    Err(format!(
        "friction continuation: stopped at {t} times the friction (step {h:e})"
    ))
}

/// Most solves of [`friction_continuation`].
const FRICTION_STEPS: usize = 60;

fn stick_start(c: &PieceConstants, w: MatRef<'_, f64>, qg: &[f64]) -> Vec<f64> {
    let classes = vec![Class::Stick; c.p];
    solve_piece(c, w, &classes, qg).unwrap_or_else(|| vec![0.0; 2 * c.p])
}
