//! The path tracer (SPEC §3–5).
//!
//! A [`Path`] starts at a solution found by the fixed-α solver and follows the solution
//! curve piece by piece. [`Path::step`] advances to the next transition point (or the end
//! of the window) and says what happened; [`Path::run`] steps until the path ends.
//!
//! Everything the path reports is kept: the [`Event`]s (one per node that changes class,
//! with the full state at the event), the [`PieceRecord`]s, and enough to answer
//! [`Path::solutions_at`] for any α by one small solve on each stored piece.

use std::sync::Arc;

use crate::class::Class;
use crate::error::{Error, Result};
use crate::load::{BoundLoad, Load, LoadSnapshot};
use crate::piece::{Consts, DenseLu, Guard, PieceLu, displacement_gaps, shift_gap};
use crate::problem::Problem;
use crate::solve::{solve_fixed_alpha, solve_with_frozen};

/// Options of a path. Build with [`PathOptions::window`] and adjust the fields.
#[derive(Debug, Clone, PartialEq)]
pub struct PathOptions {
    /// α where tracing starts (default: `alpha_start` of the window).
    pub alpha_start: f64,
    /// α toward which the path is traced first. The window is
    /// `[min(alpha_start, alpha_end), max(alpha_start, alpha_end)]`; the path ends when α
    /// leaves it, on either side (after a fold it may come back out through the start).
    pub alpha_end: f64,
    /// Maximum number of transition points before the path stops with
    /// [`EndReason::MaxSteps`] (default 10 000).
    pub max_steps: usize,
    /// Relative tolerance for "a guard is at zero" and "two nodes switch at once"
    /// (default 1e-11, relative to the force scale of the current point; displacement
    /// guards are compared after multiplication by [`Problem::default_r`]).
    pub zero_tol: f64,
}

impl PathOptions {
    /// Trace from `alpha_start` toward `alpha_end` (must differ, both finite).
    pub fn window(alpha_start: f64, alpha_end: f64) -> Self {
        Self {
            alpha_start,
            alpha_end,
            max_steps: 10_000,
            zero_tol: 1e-11,
        }
    }
}

/// Why a path ended.
#[derive(Debug, Clone, PartialEq)]
pub enum EndReason {
    /// α reached the edge of the window.
    Window,
    /// `max_steps` transition points were traced.
    MaxSteps,
    /// The path came back to a point and piece it had already traced.
    ClosedLoop,
    /// A non-smooth bifurcation with no unique orientation-preserving branch: choose one
    /// with [`Path::choose_branch`] and step on.
    Bifurcation,
    /// A failure (load callback, numerics); the message says which. What was traced is kept.
    Failed(String),
}

impl EndReason {
    /// The exchange-format name: `"window"`, `"max_steps"`, `"closed_loop"`,
    /// `"bifurcation"`, `"failed"`.
    pub fn name(&self) -> &'static str {
        match self {
            EndReason::Window => "window",
            EndReason::MaxSteps => "max_steps",
            EndReason::ClosedLoop => "closed_loop",
            EndReason::Bifurcation => "bifurcation",
            EndReason::Failed(_) => "failed",
        }
    }
}

/// A point of the solution curve with everything a user reads.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// The load parameter.
    pub alpha: f64,
    /// Displacements (n).
    pub u: Vec<f64>,
    /// Normal contact forces (p), ≤ 0 (compressive).
    pub lambda_n: Vec<f64>,
    /// Tangential contact forces (p).
    pub lambda_t: Vec<f64>,
    /// Class of every node on the piece this point is reported for.
    pub classes: Vec<Class>,
    /// `‖H‖∞ / scale`, see [`crate::piece::residual`].
    pub residual: f64,
}

/// One node changing class at a transition point.
///
/// An event carries the contact forces at the point (2p numbers); the full state (u and
/// the residual) costs one back-solve with the factor of A and is computed on request by
/// [`Path::event_state`], so that tracing costs nothing proportional to n per event.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// 0-based position in [`Path::events`].
    pub index: usize,
    /// 0-based index of the transition point (events of one degenerate transition share it).
    pub transition: usize,
    /// α of the transition point.
    pub alpha: f64,
    /// 0-based contact node (reports add 1).
    pub node: usize,
    /// Class before.
    pub from: Class,
    /// Class after.
    pub to: Class,
    /// α turns back here: the sign of dα/ds after differs from the sign before.
    pub fold: bool,
    /// More than one neighbouring piece continues the path here.
    pub bifurcation: bool,
    /// Normal contact forces at the transition point (p), ≤ 0.
    pub lambda_n: Vec<f64>,
    /// Tangential contact forces at the transition point (p).
    pub lambda_t: Vec<f64>,
    /// Classes of all nodes on the piece after the transition.
    pub classes: Vec<Class>,
}

/// A candidate continuation at a transition point.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Classes of the piece.
    pub classes: Vec<Class>,
    /// Sign of dα/ds along it (0 for a vertical piece).
    pub direction: i8,
    /// True if it keeps the path's orientation (SPEC §4).
    pub orientation_preserving: bool,
}

/// A traced smooth piece.
#[derive(Debug, Clone, PartialEq)]
pub struct PieceRecord {
    /// Classes of all nodes on the piece.
    pub classes: Vec<Class>,
    /// α where the path entered the piece.
    pub alpha_from: f64,
    /// α where the path left it (equal to `alpha_from` for a vertical piece).
    pub alpha_to: f64,
    /// Contact forces `(λν, λt)` (2p) where the path entered.
    pub lambda_from: Vec<f64>,
    /// Contact forces where the path left.
    pub lambda_to: Vec<f64>,
    /// Sign of dα/ds on the piece: +1, −1, or 0 for a vertical piece (a continuum of
    /// solutions at one α).
    pub direction: i8,
    /// The path's orientation sign `sign det [J_S; tᵀ]` (constant along a path unless a
    /// branch was chosen against it).
    pub orientation: i8,
    /// Sign of `det` of the square part `∂H/∂λ` of the piece Jacobian (0 if singular).
    pub det_sign: i8,
}

/// A solution at a given α, as returned by [`Path::solutions_at`].
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Index of the piece in [`Path::pieces`] that gave it.
    pub piece: usize,
    /// The state.
    pub state: State,
    /// True when the piece is vertical at this α: then every point between the piece's
    /// `lambda_from` and `lambda_to` is a solution too (a continuum).
    pub continuum: bool,
}

/// What one [`Path::step`] did.
#[derive(Debug, Clone, PartialEq)]
pub enum StepOutcome {
    /// A transition point was passed: `events` indexes [`Path::events`] (one per node
    /// that changed class, in node order).
    Transition {
        /// The new events.
        events: std::ops::Range<usize>,
        /// α turns back here.
        fold: bool,
        /// Several pieces continue here; the path took the unique orientation-preserving
        /// one (see [`Path::branches`]).
        bifurcation: bool,
    },
    /// The path ended (it may be resumed after [`EndReason::Bifurcation`] by choosing a
    /// branch).
    End(EndReason),
}

/// A path on a shared problem with its own load. `Send`, not `Sync`: one thread at a time.
pub struct Path {
    problem: Arc<Problem>,
    load: BoundLoad,
    opts: PathOptions,
    trace: Option<Trace>,
}

/// The traced data and the current position.
struct Trace {
    start: State,
    events: Vec<Event>,
    pieces: Vec<PieceRecord>,
    cur: Cur,
    end: Option<EndReason>,
    /// The path's orientation σ.
    sigma: i8,
    /// Sign of dα/ds on the last non-vertical piece.
    last_dir: i8,
    transitions: usize,
    /// Consecutive transitions at the same point (guards against cycling in place).
    zero_steps: usize,
    /// The load at each event (index as `events`), for [`Path::event_state`].
    event_loads: Vec<LoadSnapshot>,
    /// Entry points of the pieces: (classes, λ, α), for closed-loop detection.
    entries: Vec<(Vec<Class>, Vec<f64>, f64)>,
    /// The last transition, kept while a branch may still be chosen there.
    pending: Option<Pending>,
    branches: Vec<Branch>,
}

/// Position on the current piece.
#[derive(Clone)]
struct Cur {
    classes: Vec<Class>,
    lam: Vec<f64>,
    alpha: f64,
    /// Tangent (λ̇, α̇), unit in scaled coordinates, oriented along the path.
    t: Vec<f64>,
    /// Factorisation of the piece Jacobian in scaled coordinates, with the scales.
    lu: Arc<PieceLu>,
    scales: (f64, f64),
}

/// A transition point with its continuations, kept until the next step.
struct Pending {
    point: Point,
    from: Vec<Class>,
    cands: Vec<Cand>,
    events_start: usize,
    pieces_len: usize,
    last_dir: i8,
    bifurcation: bool,
}

#[derive(Clone)]
struct Point {
    lam: Vec<f64>,
    alpha: f64,
    q: Vec<f64>,
    dq: Vec<f64>,
}

#[derive(Clone)]
struct Cand {
    classes: Vec<Class>,
    t: Vec<f64>,
    orientation: i8,
    det_sign: i8,
    lu: Arc<PieceLu>,
    scales: (f64, f64),
}

fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Largest number of neighbouring pieces enumerated at one transition point (the product
/// over the nodes at a class boundary of the number of classes that fit there; nodes at
/// the vertex are handled by the directional problem instead).
const MAX_CANDIDATE_PIECES: usize = 4096;

impl Path {
    /// Binds a load to a problem. Computes the condensed load vectors (one back-solve per
    /// basis vector). Errors: load length ≠ n; window bounds not finite or equal;
    /// `zero_tol` not in (0, 1e-3].
    pub fn new(problem: Arc<Problem>, load: Load, opts: PathOptions) -> Result<Path> {
        if !opts.alpha_start.is_finite()
            || !opts.alpha_end.is_finite()
            || opts.alpha_start == opts.alpha_end
        {
            return Err(Error::InvalidParameter(format!(
                "alpha window [{}, {}] must be finite with distinct ends",
                opts.alpha_start, opts.alpha_end
            )));
        }
        if !(opts.zero_tol > 0.0 && opts.zero_tol <= 1e-3) {
            return Err(Error::InvalidParameter(format!(
                "zero_tol = {} must be in (0, 1e-3]",
                opts.zero_tol
            )));
        }
        let load = BoundLoad::new(load, problem.delassus())?;
        Ok(Path {
            problem,
            load,
            opts,
            trace: None,
        })
    }

    /// The problem.
    pub fn problem(&self) -> &Arc<Problem> {
        &self.problem
    }

    /// The options.
    pub fn options(&self) -> &PathOptions {
        &self.opts
    }

    fn window(&self) -> (f64, f64) {
        let (a, b) = (self.opts.alpha_start, self.opts.alpha_end);
        (a.min(b), a.max(b))
    }

    fn alpha_scale(&self) -> f64 {
        (self.opts.alpha_end - self.opts.alpha_start).abs()
    }

    fn consts(&self) -> Consts<'_> {
        Consts::of(&self.problem)
    }

    fn point_at(&mut self, lam: Vec<f64>, alpha: f64) -> Result<Point> {
        let (q, dq) = self.load.q(alpha, self.problem.delassus())?;
        Ok(Point { lam, alpha, q, dq })
    }

    /// Force scale of a point: max(‖λ‖∞, r0 ‖q − (g, 0)‖∞, r0 ‖q'‖∞ |α_end − α_start|).
    /// The last term keeps the scale meaningful where the load passes through zero.
    fn force_scale(&self, pt: &Point) -> f64 {
        let r0 = self.problem.default_r();
        let qg = shift_gap(&pt.q, self.problem.gap());
        inf_norm(&pt.lam)
            .max(r0 * inf_norm(&qg))
            .max(r0 * inf_norm(&pt.dq) * self.alpha_scale())
            .max(1e-300)
    }

    fn state(&mut self, lam: &[f64], alpha: f64, classes: &[Class]) -> Result<State> {
        // One back-solve of f + Bᵀλ: forming u as A⁻¹f + (A⁻¹Bᵀ)λ instead would cancel
        // (the free displacement under the load is often orders of magnitude larger than
        // u) and lose the residual's accuracy.
        let f = self.load.force(alpha)?;
        Ok(self.state_with_force(lam, alpha, classes, f))
    }

    fn state_with_force(&self, lam: &[f64], alpha: f64, classes: &[Class], f: Vec<f64>) -> State {
        let u = self.problem.delassus().displacement(&f, lam);
        let residual = crate::piece::residual(&self.problem, &u, lam, &f);
        let p = self.problem.p();
        State {
            alpha,
            u,
            lambda_n: lam[..p].to_vec(),
            lambda_t: lam[p..].to_vec(),
            classes: classes.to_vec(),
            residual,
        }
    }

    /// Tangent of piece `classes` at `pt` in raw coordinates, from the factorisation of
    /// the Jacobian in scaled coordinates (λ/S, α/A) where the tangent is a unit vector.
    /// Returns (t, factorisation, (S, A)) or None when the Jacobian has rank < 2p.
    fn tangent(
        &self,
        classes: &[Class],
        pt: &Point,
        scale: f64,
    ) -> Option<(Vec<f64>, PieceLu, (f64, f64))> {
        let c = self.consts();
        let m = 2 * c.p;
        let qg = shift_gap(&pt.q, self.problem.gap());
        let (mut js, _) = c.jacobian(self.problem.delassus().w(), classes, &qg, &pt.dq, pt.alpha);
        let a_s = self.alpha_scale();
        for r in 0..m {
            for col in 0..m {
                js[(r, col)] *= scale;
            }
            js[(r, m)] *= a_s;
        }
        let lu = PieceLu::new(js.as_ref())?;
        let mut t = lu.t.clone();
        for v in t.iter_mut().take(m) {
            *v *= scale;
        }
        t[m] *= a_s;
        Some((t, lu, (scale, a_s)))
    }

    /// Values and derivatives along `t` of all guards of `classes` at `pt`.
    fn guard_table(
        &self,
        classes: &[Class],
        pt: &Point,
        t: Option<&[f64]>,
    ) -> Vec<(Guard, f64, f64)> {
        let c = self.consts();
        let m = 2 * c.p;
        let w = self.problem.delassus().w();
        let qg = shift_gap(&pt.q, self.problem.gap());
        let d = displacement_gaps(w, &qg, &pt.lam);
        let (lt, dt) = match t {
            Some(t) => {
                let mut dd = displacement_gaps(w, &vec![0.0; m], &t[..m]);
                for (k, v) in dd.iter_mut().enumerate() {
                    *v += pt.dq[k] * t[m];
                }
                (t[..m].to_vec(), dd)
            }
            None => (vec![0.0; m], vec![0.0; m]),
        };
        c.guards(classes)
            .into_iter()
            .map(|g| {
                let f = c.guard_form(g);
                (g, f.eval(&pt.lam, &d), f.eval(&lt, &dt))
            })
            .collect()
    }

    /// Classes of node `i` whose equations and guards hold at the point (to `tol`, in
    /// force units).
    fn compatible(&self, i: usize, pt: &Point, tol: f64) -> Vec<Class> {
        let w = self.problem.delassus().w();
        let qg = shift_gap(&pt.q, self.problem.gap());
        let d = displacement_gaps(w, &qg, &pt.lam);
        self.compatible_at(i, &pt.lam, &d, tol)
    }

    /// Classes of node `i` compatible with `(λ, d)` (to `tol`, in force units).
    fn compatible_at(&self, i: usize, lam: &[f64], d: &[f64], tol: f64) -> Vec<Class> {
        let c = self.consts();
        let r0 = c.r0;
        Class::ALL
            .into_iter()
            .filter(|&cl| {
                let eq_ok = c.equations(i, cl).iter().all(|e| {
                    // equations in force units: displacement rows scaled by r0 instead of r
                    let v = e.a[0].1 * lam[e.a[0].0]
                        + e.a[1].1 * lam[e.a[1].0]
                        + if e.b.1 != 0.0 {
                            e.b.1.signum() * r0 * d[e.b.0]
                        } else {
                            0.0
                        };
                    v.abs() <= tol
                });
                eq_ok
                    && crate::piece::guard_kinds(cl)
                        .iter()
                        .all(|&kind| c.guard_form(Guard { node: i, kind }).eval(lam, d) >= -tol)
            })
            .collect()
    }

    /// Adds the directions of piece `classes` through `pt` that enter its region.
    #[allow(clippy::too_many_arguments)]
    fn push_candidates(
        &self,
        classes: &[Class],
        pt: &Point,
        scale: f64,
        tol: f64,
        back: Option<(&[Class], &[f64])>,
        relaxed: bool,
        out: &mut Vec<Cand>,
    ) {
        // The piece the path came from cannot continue it: its crossing guard decreases
        // forward, and backward is where the path came from.
        if back.is_some_and(|(bc, _)| bc == classes) {
            return;
        }
        let Some((t, lu, scales)) = self.tangent(classes, pt, scale) else {
            return;
        };
        let lu = Arc::new(lu);
        for s in [1.0, -1.0] {
            let ts: Vec<f64> = t.iter().map(|v| s * v).collect();
            if out.iter().any(|c| {
                c.classes == classes && c.t.iter().zip(&ts).map(|(a, b)| a * b).sum::<f64>() > 0.0
            }) {
                continue;
            }
            let enters = self
                .guard_table(classes, pt, Some(&ts))
                .iter()
                .all(|&(_, v, vd)| {
                    if v > tol {
                        true
                    } else if v < -tol {
                        false
                    } else if relaxed {
                        vd >= -tol
                    } else {
                        vd > tol
                    }
                });
            if enters {
                let orientation = if s > 0.0 {
                    lu.orientation
                } else {
                    -lu.orientation
                };
                let m = ts.len() - 1;
                let det_sign = if ts[m].abs() <= 1e-14 {
                    0
                } else {
                    orientation * sign(ts[m])
                };
                out.push(Cand {
                    orientation,
                    classes: classes.to_vec(),
                    t: ts,
                    det_sign,
                    lu: lu.clone(),
                    scales,
                });
            }
        }
    }

    /// Every neighbouring piece that contains `pt` and whose direction enters its region.
    /// `fixed` gives the class of every node not in `nodes`; the nodes in `nodes` take all
    /// their compatible classes. `back` = (classes, tangent) of the way the path came.
    ///
    /// Nodes at the *vertex* (`λ_i = 0`, `d_i = 0`: every class fits) are not enumerated
    /// when there are more than two of them: the continuation from such a point is
    /// positively homogeneous, so their classes are read off the solution of the
    /// directional contact problem `ḋ = W λ̇ ± q'` (the other nodes keep their class).
    fn continuations(
        &self,
        pt: &Point,
        fixed: &[Class],
        nodes: &[usize],
        back: Option<(&[Class], &[f64])>,
        relaxed: bool,
    ) -> Result<Vec<Cand>> {
        let scale = self.force_scale(pt);
        let tol = self.opts.zero_tol * scale;
        let options: Vec<Vec<Class>> = nodes.iter().map(|&i| self.compatible(i, pt, tol)).collect();
        if let Some(k) = options.iter().position(|o| o.is_empty()) {
            return Err(Error::Numerical(format!(
                "node {} fits no class at alpha = {:e} (the point is not a solution)",
                nodes[k] + 1,
                pt.alpha
            )));
        }
        let is_vertex: Vec<bool> = options.iter().map(|o| o.len() == 4).collect();
        let n_vertex = is_vertex.iter().filter(|&&v| v).count();
        let use_directional = n_vertex > 2;
        let enumerated: Vec<usize> = (0..nodes.len())
            .filter(|&k| !(use_directional && is_vertex[k]))
            .collect();
        let combos = enumerated
            .iter()
            .fold(1usize, |acc, &k| acc.saturating_mul(options[k].len()));
        if combos > MAX_CANDIDATE_PIECES {
            return Err(Error::Numerical(format!(
                "{} nodes are at a class boundary at once at alpha = {:e}: {combos} neighbouring pieces exceed the limit of {MAX_CANDIDATE_PIECES}",
                enumerated.len(),
                pt.alpha
            )));
        }
        let mut out = Vec::new();
        let mut idx = vec![0usize; enumerated.len()];
        loop {
            let mut classes = fixed.to_vec();
            for (k, &e) in enumerated.iter().enumerate() {
                classes[nodes[e]] = options[e][idx[k]];
            }
            if use_directional {
                let frozen: Vec<Option<Class>> = (0..classes.len())
                    .map(|i| {
                        let v = nodes
                            .iter()
                            .position(|&n| n == i)
                            .is_some_and(|k| is_vertex[k]);
                        (!v).then_some(classes[i])
                    })
                    .collect();
                for s in [1.0, -1.0] {
                    if let Some(cl) = self.directional_classes(pt, &frozen, s) {
                        self.push_candidates(&cl, pt, scale, tol, back, relaxed, &mut out);
                    }
                }
            } else {
                self.push_candidates(&classes, pt, scale, tol, back, relaxed, &mut out);
            }
            // next combination
            let mut k = 0;
            loop {
                if k == enumerated.len() {
                    return Ok(out);
                }
                idx[k] += 1;
                if idx[k] < options[enumerated[k]].len() {
                    break;
                }
                idx[k] = 0;
                k += 1;
            }
        }
    }

    /// Classes of the free (vertex) nodes on the continuation with `α̇ = s`: the solution of
    /// the contact problem for the derivatives, `ḋ = W λ̇ + s q'`, with the frozen nodes'
    /// equations. None when that problem has no solution or a free node stays degenerate.
    fn directional_classes(
        &self,
        pt: &Point,
        frozen: &[Option<Class>],
        s: f64,
    ) -> Option<Vec<Class>> {
        let qdir: Vec<f64> = pt.dq.iter().map(|v| s * v).collect();
        let lam = solve_with_frozen(&self.problem, &qdir, None, pt.alpha, Some(frozen)).ok()?;
        let w = self.problem.delassus().w();
        let d = displacement_gaps(w, &qdir, &lam);
        let r0 = self.problem.default_r();
        let sc = inf_norm(&lam).max(r0 * inf_norm(&qdir)).max(1e-300);
        let tol = self.opts.zero_tol * sc;
        let mut classes = Vec::with_capacity(frozen.len());
        for (i, f) in frozen.iter().enumerate() {
            match f {
                Some(c) => classes.push(*c),
                None => {
                    let comp = self.compatible_at(i, &lam, &d, tol);
                    if comp.len() != 1 {
                        return None;
                    }
                    classes.push(comp[0]);
                }
            }
        }
        Some(classes)
    }

    /// Starts (or restarts) the path at `alpha` with the fixed-α solver, from `guess`
    /// (`(λν, λt)`, 2p values) or from zero forces. Clears events and pieces.
    /// Errors: `alpha` outside the window, guess of wrong length or non-finite, the solve
    /// fails, the load fails, no piece leaves the start point toward `alpha_end`.
    pub fn start(&mut self, alpha: f64, guess: Option<&[f64]>) -> Result<()> {
        self.trace = None;
        let (lo, hi) = self.window();
        if !(alpha >= lo && alpha <= hi) {
            return Err(Error::InvalidParameter(format!(
                "start alpha = {alpha} is outside the window [{lo}, {hi}]"
            )));
        }
        let m = 2 * self.problem.p();
        if let Some(g) = guess {
            if g.len() != m {
                return Err(Error::Dimension(format!(
                    "initial guess has {} values, expected 2p = {m}",
                    g.len()
                )));
            }
            if let Some(i) = g.iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFinite(format!(
                    "initial guess entry {} is {}",
                    i + 1,
                    g[i]
                )));
            }
        }
        let pt = self.point_at(vec![0.0; m], alpha)?;
        let qg = shift_gap(&pt.q, self.problem.gap());
        let lam = solve_fixed_alpha(&self.problem, &qg, guess, alpha)?;
        let pt = Point { lam, ..pt };
        let tol = self.opts.zero_tol * self.force_scale(&pt);
        let p = self.problem.p();
        let mut fixed = vec![Class::Open; p];
        let mut nodes = Vec::new();
        for i in 0..p {
            let comp = self.compatible(i, &pt, tol);
            match comp.len() {
                0 => {
                    return Err(Error::SolveFailed {
                        alpha,
                        message: format!("node {} fits no class at the computed point", i + 1),
                    });
                }
                1 => fixed[i] = comp[0],
                _ => nodes.push(i),
            }
        }
        let want = sign(self.opts.alpha_end - self.opts.alpha_start);
        let mut cands = self.continuations(&pt, &fixed, &nodes, None, false)?;
        if cands.is_empty() {
            cands = self.continuations(&pt, &fixed, &nodes, None, true)?;
        }
        let ms = 2 * p;
        let pick = cands
            .iter()
            .position(|c| sign(c.t[ms]) == want)
            .or_else(|| cands.iter().position(|c| c.t[ms].abs() <= 1e-14));
        let Some(k) = pick else {
            return Err(Error::Numerical(format!(
                "no piece leaves the start point alpha = {alpha} toward alpha_end = {}",
                self.opts.alpha_end
            )));
        };
        let cand = cands[k].clone();
        let start = self.state(&pt.lam, alpha, &cand.classes)?;
        let dir = sign(cand.t[ms]);
        let piece = PieceRecord {
            classes: cand.classes.clone(),
            alpha_from: alpha,
            alpha_to: alpha,
            lambda_from: pt.lam.clone(),
            lambda_to: pt.lam.clone(),
            direction: dir,
            orientation: cand.orientation,
            det_sign: cand.det_sign,
        };
        self.trace = Some(Trace {
            start,
            events: Vec::new(),
            event_loads: Vec::new(),
            pieces: vec![piece],
            entries: vec![(cand.classes.clone(), pt.lam.clone(), alpha)],
            cur: Cur {
                classes: cand.classes,
                lam: pt.lam,
                alpha,
                t: cand.t,
                lu: cand.lu,
                scales: cand.scales,
            },
            end: None,
            sigma: cand.orientation,
            last_dir: if dir != 0 { dir } else { want },
            transitions: 0,
            zero_steps: 0,
            pending: None,
            branches: Vec::new(),
        });
        Ok(())
    }

    fn trace_ref(&self) -> Result<&Trace> {
        self.trace
            .as_ref()
            .ok_or_else(|| Error::Usage("the path has not been started (call start first)".into()))
    }

    /// Advances to the next transition point or to the end of the path.
    /// Errors: not started ([`Error::Usage`]), load failure ([`Error::Load`]; the path then
    /// ends with [`EndReason::Failed`] and keeps what it traced), numerical failure
    /// (likewise).
    pub fn step(&mut self) -> Result<StepOutcome> {
        let tr = self.trace_ref()?;
        if let Some(r) = &tr.end {
            return Ok(StepOutcome::End(r.clone()));
        }
        match self.step_inner() {
            Ok(o) => Ok(o),
            Err(e) => {
                if let Some(tr) = self.trace.as_mut() {
                    tr.end = Some(EndReason::Failed(e.to_string()));
                    tr.pending = None;
                }
                Err(e)
            }
        }
    }

    fn finish(&mut self, reason: EndReason) -> StepOutcome {
        let tr = self.trace.as_mut().expect("started");
        tr.end = Some(reason.clone());
        StepOutcome::End(reason)
    }

    fn step_inner(&mut self) -> Result<StepOutcome> {
        {
            let tr = self.trace.as_mut().expect("started");
            tr.pending = None;
            tr.branches.clear();
            if tr.transitions >= self.opts.max_steps {
                return Ok(self.finish(EndReason::MaxSteps));
            }
        }
        let cur = self.trace.as_ref().expect("started").cur.clone();
        let m = 2 * self.problem.p();
        let vertical = cur.t[m].abs() <= 1e-14;
        let exit = if self.load.is_affine() || vertical {
            self.exit_linear(&cur)?
        } else {
            self.exit_graph(&cur)?
        };
        match exit {
            Exit::Window(pt) => {
                self.close_piece(&pt);
                let tr = self.trace.as_mut().expect("started");
                tr.cur.lam = pt.lam;
                tr.cur.alpha = pt.alpha;
                Ok(self.finish(EndReason::Window))
            }
            Exit::Guards(pt, crossing) => self.transit(cur, pt, crossing),
        }
    }

    fn close_piece(&mut self, pt: &Point) {
        let tr = self.trace.as_mut().expect("started");
        let last = tr.pieces.last_mut().expect("one piece");
        last.alpha_to = pt.alpha;
        last.lambda_to = pt.lam.clone();
    }

    /// Exit of a straight piece (affine load, or a vertical piece): ratio test on the
    /// guards and the window, then the exact point by one bordered solve.
    fn exit_linear(&mut self, cur: &Cur) -> Result<Exit> {
        let m = 2 * self.problem.p();
        let pt = self.point_at(cur.lam.clone(), cur.alpha)?;
        let scale = self.force_scale(&pt);
        let tol = self.opts.zero_tol * scale;
        let table = self.guard_table(&cur.classes, &pt, Some(&cur.t));
        let mut best: Option<(f64, Guard)> = None;
        for &(g, v, vd) in &table {
            if vd < -tol {
                let s = (v / -vd).max(0.0);
                if best.is_none_or(|b| s < b.0) {
                    best = Some((s, g));
                }
            }
        }
        let (lo, hi) = self.window();
        let ta = cur.t[m];
        let s_win = if ta > 0.0 {
            Some((hi - cur.alpha) / ta)
        } else if ta < 0.0 {
            Some((lo - cur.alpha) / ta)
        } else {
            None
        };
        let problem = self.problem.clone();
        let c = Consts::of(&problem);
        let w = problem.delassus().w();
        match (best, s_win) {
            (None, None) => Err(Error::Numerical(format!(
                "vertical piece at alpha = {:e} with no exit: the continuum is unbounded",
                cur.alpha
            ))),
            (b, Some(sw)) if b.is_none_or(|b| sw <= b.0) => {
                let alpha = if ta > 0.0 { hi } else { lo };
                let pt = self.point_at(vec![0.0; m], alpha)?;
                let qg = shift_gap(&pt.q, self.problem.gap());
                let mlu = DenseLu::new(c.piece_matrix(w, &cur.classes).as_ref());
                let lam = mlu.solve(&c.piece_rhs(&cur.classes, &qg));
                Ok(Exit::Window(Point { lam, ..pt }))
            }
            (Some((s, g)), _) => {
                let (lam, alpha) = if self.load.is_affine() {
                    // Exact point from the data: x = x_p + τ t with J x_p = rhs (from the
                    // piece's factorisation) and τ from the guard's equation; no drift
                    // from earlier points enters.
                    let qg = shift_gap(&pt.q, self.problem.gap());
                    let (_, rhs) = c.jacobian(w, &cur.classes, &qg, &pt.dq, pt.alpha);
                    let form = c.guard_form(g);
                    let mut row = vec![0.0; m + 1];
                    form.row(w, &pt.dq, &mut row);
                    let v0 = table.iter().find(|e| e.0 == g).map(|e| e.1).unwrap_or(0.0);
                    let c0 = v0
                        - row[..m]
                            .iter()
                            .zip(&cur.lam)
                            .map(|(a, b)| a * b)
                            .sum::<f64>()
                        - row[m] * cur.alpha;
                    let (sc, a_s) = cur.scales;
                    let mut xp = cur.lu.particular(&rhs);
                    for v in xp.iter_mut().take(m) {
                        *v *= sc;
                    }
                    xp[m] *= a_s;
                    let dot = |x: &[f64]| row.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
                    let tau = (-c0 - dot(&xp)) / dot(&cur.t);
                    let x: Vec<f64> = xp.iter().zip(&cur.t).map(|(a, b)| a + tau * b).collect();
                    if x.iter().all(|v| v.is_finite()) {
                        (x[..m].to_vec(), x[m])
                    } else {
                        let lam = cur.lam.iter().zip(&cur.t).map(|(l, t)| l + s * t).collect();
                        (lam, cur.alpha + s * cur.t[m])
                    }
                } else {
                    let lam = cur.lam.iter().zip(&cur.t).map(|(l, t)| l + s * t).collect();
                    (lam, cur.alpha)
                };
                let pt = self.point_at(lam, alpha)?;
                Ok(Exit::Guards(pt, vec![g]))
            }
            (None, Some(_)) => unreachable!("handled by the window arm"),
        }
    }

    /// Exit of a graph piece under a nonlinear load: march in α with steps that the
    /// guards' Hermite interpolants certify free of double crossings, then Brent.
    fn exit_graph(&mut self, cur: &Cur) -> Result<Exit> {
        let m = 2 * self.problem.p();
        let dir = if cur.t[m] > 0.0 { 1.0 } else { -1.0 };
        let (lo, hi) = self.window();
        let bound = if dir > 0.0 { hi } else { lo };
        let span = self.alpha_scale();
        let mlu = {
            let c = self.consts();
            DenseLu::new(
                c.piece_matrix(self.problem.delassus().w(), &cur.classes)
                    .as_ref(),
            )
        };
        let classes = cur.classes.clone();
        let eval = |this: &mut Self, alpha: f64| -> Result<(Point, Vec<GuardRow>)> {
            let (q, dq) = this.load.q(alpha, this.problem.delassus())?;
            let c = this.consts();
            let qg = shift_gap(&q, this.problem.gap());
            let lam = mlu.solve(&c.piece_rhs(&classes, &qg));
            let dl = mlu.solve(&c.piece_rhs(&classes, &dq));
            let mut t = dl;
            t.push(1.0);
            let pt = Point { lam, alpha, q, dq };
            let table = this.guard_table(&classes, &pt, Some(&t));
            Ok((pt, table))
        };
        let (mut pa, mut ga) = eval(self, cur.alpha)?;
        let mut h = (span / 32.0).min((bound - cur.alpha).abs());
        let hmin = span * 1e-12;
        loop {
            let scale = self.force_scale(&pa);
            let tol = self.opts.zero_tol * scale;
            let at_bound = (bound - pa.alpha).abs() <= h;
            let b_alpha = if at_bound { bound } else { pa.alpha + dir * h };
            let (mut pb, mut gb) = eval(self, b_alpha)?;
            // A guard the piece just entered (zero at a, increasing) that is negative at b:
            // the step overshoots the piece's first stretch; shorten it.
            let premature =
                (0..gb.len()).any(|k| ga[k].1 <= tol && dir * ga[k].2 > 0.0 && gb[k].1 < -tol);
            if premature && h > hmin {
                h *= 0.5;
                continue;
            }
            // A guard positive at both ends with a minimum inside (its derivative changes
            // sign) may dip below zero and come back: locate the minimum (Brent on the
            // derivative) and look at the guard there. A double crossing inside one step
            // is never skipped, however close to tangent.
            let mut cut: Option<f64> = None;
            for k in 0..gb.len() {
                if ga[k].1 > -tol && gb[k].1 >= -tol && dir * ga[k].2 < 0.0 && dir * gb[k].2 > 0.0 {
                    let mut err = None;
                    let smin =
                        brent(
                            pa.alpha,
                            pb.alpha,
                            dir * ga[k].2,
                            dir * gb[k].2,
                            |x| match eval(self, x) {
                                Ok((_, tab)) => dir * tab[k].2,
                                Err(e) => {
                                    err = Some(e);
                                    f64::NAN
                                }
                            },
                        );
                    if let Some(e) = err {
                        return Err(e);
                    }
                    let (_, tab) = eval(self, smin)?;
                    if tab[k].1 < -tol && cut.is_none_or(|c| dir * (smin - c) < 0.0) {
                        cut = Some(smin);
                    }
                }
            }
            if let Some(smin) = cut {
                (pb, gb) = eval(self, smin)?;
            }
            let at_bound = at_bound && cut.is_none();
            let delta = pb.alpha - pa.alpha;
            let crossing: Vec<usize> = (0..gb.len()).filter(|&k| gb[k].1 < -tol).collect();
            if crossing.is_empty() {
                // Hermite check for a dip below zero inside the step
                let dip = (0..gb.len()).any(|k| {
                    let (v0, v1) = (ga[k].1, gb[k].1);
                    let (m0, m1) = (ga[k].2 * delta, gb[k].2 * delta);
                    hermite_min(v0, v1, m0, m1) < -tol
                });
                if dip && h > hmin {
                    h *= 0.5;
                    continue;
                }
                if at_bound {
                    return Ok(Exit::Window(pb));
                }
                pa = pb;
                ga = gb;
                h = (2.0 * h).min(span / 8.0);
                continue;
            }
            // Brent on each crossing guard; the earliest root wins.
            let mut first: Option<(f64, Guard)> = None;
            for &k in &crossing {
                let g = gb[k].0;
                let (a0, b0) = (pa.alpha, pb.alpha);
                let fa = ga[k].1;
                let fb = gb[k].1;
                let root = if fa <= 0.0 {
                    a0
                } else {
                    let mut err = None;
                    let r = brent(a0, b0, fa, fb, |x| match eval(self, x) {
                        Ok((_, tab)) => tab[k].1,
                        Err(e) => {
                            err = Some(e);
                            f64::NAN
                        }
                    });
                    if let Some(e) = err {
                        return Err(e);
                    }
                    r
                };
                if first.is_none_or(|f| dir * (root - f.0) < 0.0) {
                    first = Some((root, g));
                }
            }
            let (root, g) = first.expect("at least one crossing");
            let (pt, _) = eval(self, root)?;
            return Ok(Exit::Guards(pt, vec![g]));
        }
    }

    /// Handles a transition point: finds the neighbouring pieces that continue the path,
    /// records the events and moves onto the chosen piece.
    fn transit(&mut self, cur: Cur, pt: Point, crossing: Vec<Guard>) -> Result<StepOutcome> {
        let scale = self.force_scale(&pt);
        let tol = self.opts.zero_tol * scale;
        let mut nodes: Vec<usize> = crossing.iter().map(|g| g.node).collect();
        for (g, v, _) in self.guard_table(&cur.classes, &pt, None) {
            if v <= tol {
                nodes.push(g.node);
            }
        }
        nodes.sort_unstable();
        nodes.dedup();
        let pt = self.snap_to_vertex(pt, tol)?;
        let back = Some((cur.classes.as_slice(), cur.t.as_slice()));
        let mut cands = self.continuations(&pt, &cur.classes, &nodes, back, false)?;
        if cands.is_empty() {
            cands = self.continuations(&pt, &cur.classes, &nodes, back, true)?;
        }
        self.close_piece(&pt);
        let (events_start, pieces_len, last_dir, sigma) = {
            let tr = self.trace.as_ref().expect("started");
            (tr.events.len(), tr.pieces.len(), tr.last_dir, tr.sigma)
        };
        if cands.is_empty() {
            return Err(Error::Numerical(format!(
                "no neighbouring piece continues the path at alpha = {:e} (nodes {:?})",
                pt.alpha,
                nodes.iter().map(|i| i + 1).collect::<Vec<_>>()
            )));
        }
        let bifurcation = cands.len() > 1;
        let choice = if bifurcation {
            let keep: Vec<usize> = (0..cands.len())
                .filter(|&k| cands[k].orientation == sigma)
                .collect();
            if keep.len() == 1 { Some(keep[0]) } else { None }
        } else {
            Some(0)
        };
        let m = 2 * self.problem.p();
        let branches: Vec<Branch> = cands
            .iter()
            .map(|c| Branch {
                classes: c.classes.clone(),
                direction: sign(if c.t[m].abs() <= 1e-14 { 0.0 } else { c.t[m] }),
                orientation_preserving: c.orientation == sigma,
            })
            .collect();
        let pending = Pending {
            point: pt,
            from: cur.classes.clone(),
            cands,
            events_start,
            pieces_len,
            last_dir,
            bifurcation,
        };
        {
            let tr = self.trace.as_mut().expect("started");
            tr.branches = if bifurcation { branches } else { Vec::new() };
            tr.transitions += 1;
        }
        match choice {
            Some(k) => {
                let out = self.apply(&pending, k)?;
                self.trace.as_mut().expect("started").pending = Some(pending);
                Ok(out)
            }
            None => {
                // Stop at the bifurcation point; its events are recorded when the caller
                // chooses a branch.
                let tr = self.trace.as_mut().expect("started");
                tr.cur.lam = pending.point.lam.clone();
                tr.cur.alpha = pending.point.alpha;
                tr.pending = Some(pending);
                Ok(self.finish(EndReason::Bifurcation))
            }
        }
    }

    /// At a point where every node is at the vertex (`λ = 0`, `q(α) = (g, 0)`: the load
    /// passes through the state of zero contact forces), the exit point found from one
    /// guard carries that guard's rounding; the exact point is `λ = 0` at the α that
    /// minimises `‖q(α) − (g, 0)‖` (closed form for an affine load). Other points are
    /// returned unchanged.
    fn snap_to_vertex(&mut self, pt: Point, tol: f64) -> Result<Point> {
        let p = self.problem.p();
        if inf_norm(&pt.lam) > tol || (0..p).any(|i| self.compatible(i, &pt, tol).len() < 4) {
            return Ok(pt);
        }
        let m = 2 * p;
        let alpha = if self.load.is_affine() {
            let qg = shift_gap(&pt.q, self.problem.gap());
            let (num, den) = qg
                .iter()
                .zip(&pt.dq)
                .fold((0.0, 0.0), |(a, b), (x, y)| (a + x * y, b + y * y));
            if den > 0.0 {
                pt.alpha - num / den
            } else {
                pt.alpha
            }
        } else {
            pt.alpha
        };
        let snapped = self.point_at(vec![0.0; m], alpha)?;
        let qg = shift_gap(&snapped.q, self.problem.gap());
        if self.problem.default_r() * inf_norm(&qg) <= tol {
            Ok(snapped)
        } else {
            Ok(pt)
        }
    }

    /// Moves onto candidate `k` of a pending transition and records its events.
    fn apply(&mut self, pend: &Pending, k: usize) -> Result<StepOutcome> {
        let m = 2 * self.problem.p();
        let cand = pend.cands[k].clone();
        let pt = pend.point.clone();
        let dir = if cand.t[m].abs() <= 1e-14 {
            0
        } else {
            sign(cand.t[m])
        };
        let fold = dir != 0 && pend.last_dir != 0 && dir != pend.last_dir;
        let scale = self.force_scale(&pt);
        let a_s = self.alpha_scale();
        let p = self.problem.p();
        let snapshot = self.load.snapshot(pt.alpha)?;
        let tr = self.trace.as_mut().expect("started");
        tr.events.truncate(pend.events_start);
        tr.event_loads.truncate(pend.events_start);
        tr.pieces.truncate(pend.pieces_len);
        let transition = tr.events.last().map(|e| e.transition + 1).unwrap_or(0);
        for i in 0..cand.classes.len() {
            if cand.classes[i] != pend.from[i] {
                let index = tr.events.len();
                tr.events.push(Event {
                    index,
                    transition,
                    alpha: pt.alpha,
                    node: i,
                    from: pend.from[i],
                    to: cand.classes[i],
                    fold,
                    bifurcation: pend.bifurcation,
                    lambda_n: pt.lam[..p].to_vec(),
                    lambda_t: pt.lam[p..].to_vec(),
                    classes: cand.classes.clone(),
                });
                tr.event_loads.push(snapshot.clone());
            }
        }
        tr.pieces.push(PieceRecord {
            classes: cand.classes.clone(),
            alpha_from: pt.alpha,
            alpha_to: pt.alpha,
            lambda_from: pt.lam.clone(),
            lambda_to: pt.lam.clone(),
            direction: dir,
            orientation: cand.orientation,
            det_sign: cand.det_sign,
        });
        if dir != 0 {
            tr.last_dir = dir;
        } else {
            tr.last_dir = pend.last_dir;
        }
        let same_point = tr.cur.alpha == pt.alpha
            && tr
                .cur
                .lam
                .iter()
                .zip(&pt.lam)
                .all(|(a, b)| (a - b).abs() <= 1e-14 * scale);
        tr.zero_steps = if same_point { tr.zero_steps + 1 } else { 0 };
        tr.cur = Cur {
            classes: cand.classes.clone(),
            lam: pt.lam.clone(),
            alpha: pt.alpha,
            t: cand.t.clone(),
            lu: cand.lu.clone(),
            scales: cand.scales,
        };
        let events = pend.events_start..tr.events.len();
        let closed = tr.entries.iter().any(|(c, l, a)| {
            *c == cand.classes
                && (a - pt.alpha).abs() <= 1e-9 * a_s
                && l.iter()
                    .zip(&pt.lam)
                    .all(|(x, y)| (x - y).abs() <= 1e-9 * scale)
        });
        tr.entries
            .push((cand.classes.clone(), pt.lam.clone(), pt.alpha));
        if closed {
            tr.end = Some(EndReason::ClosedLoop);
        } else if tr.zero_steps > 16 {
            tr.end = Some(EndReason::Failed(format!(
                "the path cycles between pieces at alpha = {:e} without moving",
                pt.alpha
            )));
        }
        Ok(StepOutcome::Transition {
            events,
            fold,
            bifurcation: pend.bifurcation,
        })
    }

    /// Steps until the path ends; returns why.
    pub fn run(&mut self) -> Result<EndReason> {
        loop {
            if let StepOutcome::End(r) = self.step()? {
                return Ok(r);
            }
        }
    }

    /// True after a successful [`Path::start`].
    pub fn is_started(&self) -> bool {
        self.trace.is_some()
    }

    /// Why the path ended, if it did.
    pub fn end_reason(&self) -> Option<&EndReason> {
        self.trace.as_ref().and_then(|t| t.end.as_ref())
    }

    /// The start point (after [`Path::start`]).
    pub fn start_state(&self) -> Option<&State> {
        self.trace.as_ref().map(|t| &t.start)
    }

    /// The events so far (empty before the start).
    pub fn events(&self) -> &[Event] {
        self.trace
            .as_ref()
            .map(|t| t.events.as_slice())
            .unwrap_or(&[])
    }

    /// The full state at event `k`: u by one back-solve of `f(α) + Bᵀλ`, and the residual.
    /// Never calls the load's closures: the load at the event was kept when it was found
    /// (nothing for an affine load, the weights for a basis load, f(α) for a general one).
    /// Errors: not started, `k` out of range.
    pub fn event_state(&self, k: usize) -> Result<State> {
        let tr = self.trace_ref()?;
        let e = tr.events.get(k).ok_or_else(|| {
            Error::Usage(format!(
                "event {k} does not exist ({} events)",
                tr.events.len()
            ))
        })?;
        let lam: Vec<f64> = e.lambda_n.iter().chain(&e.lambda_t).copied().collect();
        let f = self.load.force_from(e.alpha, &tr.event_loads[k]);
        Ok(self.state_with_force(&lam, e.alpha, &e.classes, f))
    }

    /// The pieces so far (the last one is the current piece; empty before the start).
    pub fn pieces(&self) -> &[PieceRecord] {
        self.trace
            .as_ref()
            .map(|t| t.pieces.as_slice())
            .unwrap_or(&[])
    }

    /// The current point (u by one back-solve). Errors: not started, load failure.
    pub fn current(&mut self) -> Result<State> {
        let cur = self.trace_ref()?.cur.clone();
        self.state(&cur.lam, cur.alpha, &cur.classes)
    }

    /// Candidate continuations at the last transition point (empty unless it was a
    /// bifurcation and no step has been taken since).
    pub fn branches(&self) -> &[Branch] {
        self.trace
            .as_ref()
            .map(|t| t.branches.as_slice())
            .unwrap_or(&[])
    }

    /// Continue along candidate `k` of [`Path::branches`] instead of the one taken (or
    /// after the path stopped with [`EndReason::Bifurcation`]). Only allowed directly after
    /// the bifurcation step. Errors: not started, no bifurcation pending, `k` out of range.
    pub fn choose_branch(&mut self, k: usize) -> Result<()> {
        let tr = self
            .trace
            .as_mut()
            .ok_or_else(|| Error::Usage("the path has not been started".into()))?;
        let Some(pend) = tr.pending.take() else {
            return Err(Error::Usage(
                "no bifurcation is pending: choose a branch directly after the step that found it"
                    .into(),
            ));
        };
        if !pend.bifurcation {
            tr.pending = Some(pend);
            return Err(Error::Usage(
                "the last transition was not a bifurcation".into(),
            ));
        }
        if k >= pend.cands.len() {
            let n = pend.cands.len();
            tr.pending = Some(pend);
            return Err(Error::Usage(format!(
                "branch {k} does not exist ({n} candidates)"
            )));
        }
        if tr.end == Some(EndReason::Bifurcation) {
            tr.end = None;
        }
        let res = self.apply(&pend, k);
        let tr = self.trace.as_mut().expect("started");
        tr.pending = Some(pend);
        res.map(|_| ())
    }

    /// Every traced solution at `alpha`: one per traced piece whose α-range contains it
    /// (several past a fold), each by one small solve on the stored piece plus one
    /// back-solve for u. Points shared by two pieces (transition points) are reported
    /// once. Empty if the traced path never reached `alpha`. Errors: not started, load
    /// failure.
    pub fn solutions_at(&mut self, alpha: f64) -> Result<Vec<Solution>> {
        let pieces = self.trace_ref()?.pieces.clone();
        let m = 2 * self.problem.p();
        let a_tol = 1e-12 * self.alpha_scale().max(alpha.abs());
        let pt0 = self.point_at(vec![0.0; m], alpha)?;
        let qg = shift_gap(&pt0.q, self.problem.gap());
        let mut out: Vec<Solution> = Vec::new();
        for (k, pc) in pieces.iter().enumerate() {
            let (lo, hi) = (
                pc.alpha_from.min(pc.alpha_to),
                pc.alpha_from.max(pc.alpha_to),
            );
            if !(alpha >= lo - a_tol && alpha <= hi + a_tol) {
                continue;
            }
            let mut lams = Vec::new();
            let continuum = pc.direction == 0;
            if continuum {
                lams.push(pc.lambda_from.clone());
                lams.push(pc.lambda_to.clone());
            } else if (alpha - pc.alpha_from).abs() <= a_tol {
                lams.push(pc.lambda_from.clone());
            } else if (alpha - pc.alpha_to).abs() <= a_tol {
                lams.push(pc.lambda_to.clone());
            } else {
                let c = self.consts();
                let w = self.problem.delassus().w();
                let lu = DenseLu::new(c.piece_matrix(w, &pc.classes).as_ref());
                lams.push(lu.solve(&c.piece_rhs(&pc.classes, &qg)));
            }
            for lam in lams {
                let pt = Point {
                    lam: lam.clone(),
                    ..pt0.clone()
                };
                let scale = self.force_scale(&pt);
                let dup = out.iter().any(|s| {
                    s.state
                        .lambda_n
                        .iter()
                        .chain(&s.state.lambda_t)
                        .zip(&lam)
                        .all(|(a, b)| (a - b).abs() <= 1e-9 * scale)
                });
                if dup {
                    continue;
                }
                let state = self.state(&lam, alpha, &pc.classes)?;
                out.push(Solution {
                    piece: k,
                    state,
                    continuum,
                });
            }
        }
        Ok(out)
    }
}

/// A guard with its value and its derivative along the tangent.
type GuardRow = (Guard, f64, f64);

enum Exit {
    Window(Point),
    Guards(Point, Vec<Guard>),
}

/// Minimum over [0, 1] of the cubic Hermite interpolant with values v0, v1 and
/// derivatives m0, m1 (with respect to the unit interval).
fn hermite_min(v0: f64, v1: f64, m0: f64, m1: f64) -> f64 {
    // p(s) = v0 h00 + m0 h10 + v1 h01 + m1 h11; p'(s) = a s² + b s + c
    let a = 6.0 * v0 + 3.0 * m0 - 6.0 * v1 + 3.0 * m1;
    let b = -6.0 * v0 - 4.0 * m0 + 6.0 * v1 - 2.0 * m1;
    let c = m0;
    let p = |s: f64| {
        let s2 = s * s;
        let s3 = s2 * s;
        v0 * (2.0 * s3 - 3.0 * s2 + 1.0)
            + m0 * (s3 - 2.0 * s2 + s)
            + v1 * (-2.0 * s3 + 3.0 * s2)
            + m1 * (s3 - s2)
    };
    let mut best = v0.min(v1);
    let mut try_s = |s: f64| {
        if s > 0.0 && s < 1.0 {
            best = best.min(p(s));
        }
    };
    if a.abs() < 1e-300 {
        if b != 0.0 {
            try_s(-c / b);
        }
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            try_s((-b + sq) / (2.0 * a));
            try_s((-b - sq) / (2.0 * a));
        }
    }
    best
}

/// Brent's method for a root of `f` in [a, b] with `f(a) > 0 > f(b)` (or any sign change),
/// to machine precision in the argument.
fn brent(a: f64, b: f64, fa: f64, fb: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
    let (mut a, mut b, mut fa, mut fb) = (a, b, fa, fb);
    if fa.abs() < fb.abs() {
        std::mem::swap(&mut a, &mut b);
        std::mem::swap(&mut fa, &mut fb);
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if fb == 0.0 {
            return b;
        }
        if (fb > 0.0) == (fc > 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 1e-300;
        let mid = 0.5 * (c - b);
        if mid.abs() <= tol {
            return b;
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut pp, mut qq);
            if a == c {
                pp = 2.0 * mid * s;
                qq = 1.0 - s;
            } else {
                let q0 = fa / fc;
                let r = fb / fc;
                pp = s * (2.0 * mid * q0 * (q0 - r) - (b - a) * (r - 1.0));
                qq = (q0 - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if pp > 0.0 {
                qq = -qq;
            } else {
                pp = -pp;
            }
            if 2.0 * pp < (3.0 * mid * qq - (tol * qq).abs()).min((e * qq).abs()) {
                e = d;
                d = pp / qq;
            } else {
                d = mid;
                e = d;
            }
        } else {
            d = mid;
            e = d;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol * mid.signum() };
        fb = f(b);
        if fb.is_nan() {
            return b;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_finds_cubic_root() {
        let f = |x: f64| 2.0 - x * x * x;
        let r = brent(0.0, 2.0, f(0.0), f(2.0), f);
        assert!((r - 2f64.cbrt()).abs() < 4.0 * f64::EPSILON);
    }

    #[test]
    fn hermite_detects_dip() {
        // p(s) = (s - 0.5)^2 - 0.01 : values 0.24 at both ends, slopes -1 and +1, min -0.01
        assert!(hermite_min(0.24, 0.24, -1.0, 1.0) < -0.009);
        assert!(hermite_min(1.0, 2.0, 1.0, 1.0) >= 1.0);
    }
}
