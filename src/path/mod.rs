//! The path tracer (SPEC §3–5).
//!
//! A [`Path`] starts at a solution found by the fixed-α solver and follows the solution
//! curve piece by piece. [`Path::step`] advances to the next transition point (or the end
//! of the window) and says what happened; [`Path::run`] steps until the path ends.
//!
//! Everything the path reports is kept: the [`Event`]s (one per node that changes class,
//! with the full state at the event), the [`PieceRecord`]s, and enough to answer
//! [`Path::solutions_at`] for any α by one small solve on each stored piece.

mod advance;
mod join;
mod polish;
mod query;
mod roots;
pub(crate) mod update;

use advance::Exit;

use std::sync::Arc;

use crate::class::Class;
use crate::dense::inf_norm;
use crate::error::{Error, Result};
use crate::load::{BoundLoad, Load, LoadSnapshot};
use crate::piece::{DenseLu, Guard, PieceConstants, PieceLu, displacement_gaps, shift_gap};
use crate::problem::Problem;
use crate::solve::{Stages, newton_near, solve_fixed_alpha, solve_with_frozen};
use std::cell::{Cell, RefCell};
use update::UpdatedLu;

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
    /// (default 1e-11). It is relative to local scales of the current point, never to
    /// the window: a force guard to the contact forces there, a displacement guard
    /// (compared after multiplication by [`Problem::default_r`]) to the magnitude of the
    /// terms of its own row of `q + W λ − (g, 0)`. A node's friction below about
    /// `zero_tol` times the forces is not resolved: where such a node's slip reverses
    /// while it is pressed, the run stops with [`Error::Numerical`] ("without the stick
    /// phase"; F = 1e-10 traced with 1e-12). Give frictionless nodes F = 0.
    pub zero_tol: f64,
    /// Factorise every piece matrix afresh (O(m³) per piece, m = 2p) instead of updating
    /// one factorised base by rank-2 changes (O(m²) per piece; default `false`). The
    /// fresh factorisations are the reference the updated ones are tested against.
    pub fresh_factorisations: bool,
    /// Largest α step of the step control of a basis or general (nonlinear) load (α
    /// units; default `None`: 1/8 of the window's length). Each step is also shortened
    /// until the cubic Hermite model of every guard predicts a fresh evaluation at the
    /// step's midpoint, value and slope; a load that varies faster than that test can
    /// see (an excursion of a guard below zero and back, narrower than the step at which
    /// the test passes) is caught only by a step no longer than the excursion: set this
    /// to a fraction of the shortest period or feature of a load that oscillates. No
    /// effect on affine loads, whose pieces are followed exactly. Must be finite and > 0.
    pub max_alpha_step: Option<f64>,
}

impl PathOptions {
    /// Trace from `alpha_start` toward `alpha_end` (must differ, both finite).
    pub fn window(alpha_start: f64, alpha_end: f64) -> Self {
        Self {
            alpha_start,
            alpha_end,
            max_steps: 10_000,
            zero_tol: 1e-11,
            fresh_factorisations: false,
            max_alpha_step: None,
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
    /// The monitor of [`Path::run_monitored`] asked to stop. Not final: [`Path::step`]
    /// and the run functions continue from where the path stopped.
    Stopped,
}

impl EndReason {
    /// The exchange-format name: `"window"`, `"max_steps"`, `"closed_loop"`,
    /// `"bifurcation"`, `"failed"`, `"stopped"`.
    pub fn name(&self) -> &'static str {
        match self {
            EndReason::Window => "window",
            EndReason::MaxSteps => "max_steps",
            EndReason::ClosedLoop => "closed_loop",
            EndReason::Bifurcation => "bifurcation",
            EndReason::Failed(_) => "failed",
            EndReason::Stopped => "stopped",
        }
    }
}

/// How [`Path::start`] reached the start point. Whichever it was, the start point is a
/// solution of the problem at the start's α, checked the same way (to 1e-12 relative);
/// the route says how hard it was to find, and, where the problem has several solutions
/// there (large friction, a path that folds back over α), which search picked this one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StartRoute {
    /// The fixed-α solver at α, from the guess or from zero forces.
    Solved,
    /// The solver failed at α, and so did the paths from zero load and from every node
    /// open ([`StartRoute::ZeroLoad`], [`StartRoute::Open`]); a path traced from a nearby
    /// α reached it.
    Nearby,
    /// The solver failed at α; the path of the load `τ f(α)` from zero load (τ = 0)
    /// reached it at τ = 1.
    ZeroLoad,
    /// As [`StartRoute::ZeroLoad`], but that ray could not leave τ = 0 (every gap zero);
    /// the ray from a load that holds every node open reached it.
    Open,
}

impl StartRoute {
    /// Its name in the bindings (Python, MATLAB): `"solved"`, `"nearby"`, `"zero_load"`,
    /// `"open"`.
    pub fn name(&self) -> &'static str {
        match self {
            StartRoute::Solved => "solved",
            StartRoute::Nearby => "nearby",
            StartRoute::ZeroLoad => "zero_load",
            StartRoute::Open => "open",
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
    /// branch, and after [`EndReason::Stopped`] by stepping on).
    End(EndReason),
}

/// What the monitor of [`Path::run_monitored`] is told after each transition point.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// α of the transition point just passed.
    pub alpha: f64,
    /// Transition points traced so far (events of one degenerate transition count once).
    pub transitions: usize,
    /// The new events: a range of [`Path::events`] (one per node that changed class).
    pub events: std::ops::Range<usize>,
    /// α's position in the window, `(α − α_start) / (α_end − α_start)` (in [0, 1] inside
    /// the window; a path that folds back may move both ways).
    pub fraction: f64,
}

/// A path on a shared problem with its own load. `Send`, not `Sync`: one thread at a time.
pub struct Path {
    problem: Arc<Problem>,
    load: BoundLoad,
    opts: PathOptions,
    trace: Option<Trace>,
    /// The factorisation the next pieces are updated from (see [`update`]).
    updater: RefCell<Option<UpdatedLu>>,
    /// Fresh factorisations of a base piece matrix so far.
    refactorisations: Cell<usize>,
    /// The last few `d = q − (g, 0) + W λ` with their (α, λ): every candidate piece at a
    /// transition point needs the point's, and the ratio test on the piece taken needs
    /// that of the piece's own point (primed when it was solved for).
    gaps_cache: PointCache<Arc<Vec<f64>>>,
    /// The last few points' "at zero" thresholds with their (α, λ).
    tol_cache: PointCache<Tol>,
    /// The last few force scales with their (α, λ): a transition reads those of its point
    /// and of the point it came from several times, each an O(m) scan.
    scale_cache: PointCache<f64>,
    /// The last step (α units) that the march of a nonlinear load trusted: the next
    /// piece's march starts from twice that, not from the window's scale.
    graph_step: Cell<Option<f64>>,
    /// Guards that the current transition point found positive in double-double though
    /// within their thresholds (see `join::transit`): they let a candidate piece in.
    resolved: RefCell<Vec<crate::piece::Guard>>,
    /// The current point's last directional solutions (`join::directional_classes`), one
    /// per way `s` (±1) and `q'`: the forces and the factorisation of their piece, from
    /// which the same point's next directional problem is solved.
    directional_warm: RefCell<Vec<join::DirectionalWarm>>,
    /// In extended precision, the last straight piece's exit on its refined line (see
    /// `polish::CarriedPoint`).
    carried: Option<polish::CarriedPoint>,
    /// In extended precision, the current straight piece as its exit refined it (see
    /// `advance::exit_linear`), with the piece's entry α and classes: the transition
    /// point's roots (`join::transit`) are taken on the same line instead of refining
    /// the piece a second time.
    refined: Option<(f64, Vec<Class>, polish::RefinedPiece)>,
}

/// The traced data and the current position.
struct Trace {
    start: StartPoint,
    /// How the start point was reached.
    route: StartRoute,
    events: Vec<Event>,
    pieces: Vec<PieceRecord>,
    cur: CurrentPiece,
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
    entries: Vec<PieceEntry>,
    /// The entries by a hash of their classes.
    entry_index: std::collections::HashMap<u64, Vec<usize>>,
    /// The last transition, kept while a branch may still be chosen there.
    pending: Option<PendingJoin>,
    branches: Vec<Branch>,
}

/// The start point, whose full state [`Path::start_state`] computes on request.
struct StartPoint {
    alpha: f64,
    /// λ (internal units).
    lam: Vec<f64>,
    classes: Vec<Class>,
    /// The load there.
    load: LoadSnapshot,
}

/// "At zero" thresholds at a point, in force units: `force` for a form in λ only (per
/// unit of its coefficients); for a form with a displacement term `d_k`, the threshold of
/// that row of `d = q − (g, 0) + W λ`, relative to the magnitude of the terms that make it
/// up (see [`Path::tol_at`]); `disp` is the point's threshold, the largest of them.
#[derive(Clone, Debug)]
pub(super) struct Tol {
    force: f64,
    disp: f64,
    rows: Option<Arc<TolRows>>,
    /// `zero_tol`: the distance along a unit tangent (scaled coordinates) within which a
    /// guard's crossing is the point's own (see [`Tol::at_zero`]).
    arc: f64,
    /// The uncertainty of a guard's value at the point, as a fraction of [`Tol::of`]:
    /// [`ROUNDING`] at a point found exactly (a transition point), 1 at a point of the
    /// fixed-α solver (a start), which is accurate to its 1e-12 only.
    rounding: f64,
    /// Factor on the per-row thresholds, and the floor under them ([`Widen::min_row`],
    /// [`Widen::determined`], [`TolRows::floor_with`]); 1, 0 and 0 otherwise.
    widen: f64,
    min_row: f64,
    determined: f64,
    /// An open node's `λt = 0` judged against 1 + F times its threshold ([`Widen::cone`],
    /// [`Tol::cone_factor`]; false otherwise).
    cone: bool,
    /// The rows' terms are estimated (a general load, see [`Path::term_rows`]): a guard
    /// approaching zero is at zero by its value only where its own root lies within
    /// [`ROUNDING_LONG`] along the tangent (see [`Tol::at_zero`]).
    estimated: bool,
}

/// How the thresholds of `join::transit`'s retries differ from the usual ones
/// ([`Tol::widened`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Widen {
    /// Factor on every threshold (and on `arc`).
    pub k: f64,
    /// A floor under every displacement row's threshold (force units): twice how far the
    /// data determine q in the whole vector (its error's largest row).
    pub min_row: f64,
    /// How far the data determine q (and W), relative to the terms of each row (about
    /// κ(A) ε): no displacement row's floor above a few times that of the larger of its
    /// node's two rows ([`TolRows::floor_with`]). The rows of q on a slender body differ
    /// by orders of magnitude (on a cantilevered strip of 1000 contact nodes, |q| was
    /// 4.6e3 at the free end and 7 near the clamp), and `min_row` alone made a node
    /// touching down near the clamp with a tangential displacement of 5e-5 fit stick:
    /// the path stuck, and stopped there; on smaller strips it reported open → stick
    /// where the node slips first, without an error.
    pub determined: f64,
    /// An open node's `λt = 0` judged against `1 + F_i` (at most 64,
    /// [`Tol::cone_factor`]) times its threshold. A node leaving contact has
    /// `|λt| ≤ F λν`, so where `λν` is at zero to its threshold, `λt` is at zero to F
    /// times it; and a slipping node's `λt = ∓F λν` holds to its own threshold, which is
    /// 1 + F times the force threshold (the form's coefficients), so at `λν = 0` its `λt`
    /// is rounding up to that. A slipping node (F = 5) lifting off with its mirror image
    /// had λν = 4.6e-15 against a threshold of 5.4e-15 and λt = 2.3e-14, and open did not
    /// fit it. On slender strips in double, F = 1, a slipping node's λν reached 0 with
    /// λt = −2.2e-12 against a threshold of 1.5e-12 (F times it did not fit either), and
    /// a node fitting no class at the usual thresholds fitted the wrong one at the data's
    /// determination (see `Path::widening`).
    pub cone: bool,
}

impl Widen {
    /// The usual thresholds.
    pub const USUAL: Widen = Widen {
        k: 1.0,
        min_row: 0.0,
        determined: 0.0,
        cone: false,
    };
}

/// The rounding of a guard's value at an exactly computed point, as a fraction of
/// [`Tol::of`].
const ROUNDING: f64 = 1e-2;

/// A piece "a rounding long" for `join::transit`: α and the contact forces change by at
/// most this fraction along it (mirrored nodes of a symmetric body in double switch up to
/// 1e-9 apart). Also how near a guard's own root must lie for [`Tol::at_zero`] to count
/// it at zero by its value where the thresholds are estimated.
const ROUNDING_LONG: f64 = 1e-8;

/// How near its own root, on a piece refined in double-double, a guard at zero by its value
/// only must lie for `join::transit` to switch its node at a transition point: in α's unit
/// (the change of α that moves the load by the point's force scale). Such roots are
/// resolved far below [`ROUNDING_LONG`]: on a strip (180 × 8 on 2.48 × 0.059, F = 0.1,
/// α's unit 25) two nodes' stick roots lay 2.3e-8 apart in α, 1e-9 of the unit, and
/// were one transition with 1e-8.
const RESOLVED_APART: f64 = 1e-10;

/// Most that the window's length counts for a nonlinear load's march beyond the point's
/// own α length (see [`Path::load_span`]): windows up to a thousand times that scale
/// march as the window's length says (the suites' windows, and far windows up to 1e3 of
/// the load's scale, traced the same events either way). A general load's estimated
/// terms use the own length itself (a factor of 1, see [`Path::term_rows`]).
const FAR_WINDOW: f64 = 1e3;

/// How many roundings of α a general load's thresholds cover: its terms
/// ([`Path::term_rows`]) count its change over at least `ALPHA_ROUNDINGS ε |α| /
/// zero_tol`, so that its thresholds are at least `ALPHA_ROUNDINGS ε |α| r0 |q'_k|`. A
/// load computed from α is known to no better than one rounding of α, `|q'| ε |α|`,
/// whatever its own arithmetic (an oscillating `φ(α) = s − A cos ω(α − α0)` at ω = 118,
/// α = 27 moves by 7e-13 of A per rounding), and where that exceeded the thresholds,
/// solutions at points a rounding apart disagreed by more than they: on symmetric bodies
/// under such loads (ω 30–300, α0 up to ±100), 100 of 742 traces stopped, 98 with "node
/// k fits no class", at |α| 8.6–99 (most beyond 27); as basis loads none did. With 16
/// roundings 1 of them still stopped, with 64 none (and every trace agreed with the
/// reference's events).
const ALPHA_ROUNDINGS: f64 = 64.0;

/// Most pieces the start point is refined on in extended precision before its classes
/// settle ([`Path::start_on_its_piece`]); one or two in every case seen (an active-set
/// iteration from the fixed-α solver's classes, which differ from the refined point's in
/// a few nodes at most).
const START_REFINE_ROUNDS: usize = 8;

/// As [`START_REFINE_ROUNDS`], from a stalled iterate of the fixed-α solver (its classes
/// differ from the solution's in tens of nodes): on a 2001 × 3 node strip (200 × 0.2,
/// F = 1, κ(W) = 2.7e12) the classes changed in 51, 12, 9, 6, 3, 8, 6, 3, … nodes and
/// settled after 17 pieces (2.4 s at p = 2000), where every stage of the solver stalled
/// at residuals of 1e-8.
const ITERATE_REFINE_ROUNDS: usize = 40;

/// The per-row thresholds of displacement forms, computed on first use: row k costs one
/// pass over row k of W (`(|W| |λ|)_k`), so a transition pays only for the rows it asks.
#[derive(Debug)]
pub(super) struct TolRows {
    problem: Arc<Problem>,
    /// `zero_tol · r0`.
    factor: f64,
    r0: f64,
    /// `|q_k|ₜ` per row (the magnitude of the terms of `q_k(α)`).
    terms: Vec<f64>,
    abs_lam: Vec<f64>,
    lam_max: f64,
    floor: f64,
    /// `(|W| |λ|)_k` found so far, as f64 bits (NaN: not yet).
    wl: Vec<std::sync::atomic::AtomicU64>,
}

impl TolRows {
    /// `(|W| |λ|)_k`: one pass over row k of the symmetric W, read as its contiguous
    /// column k (once per row).
    fn wl(&self, k: usize) -> f64 {
        use std::sync::atomic::Ordering::Relaxed;
        let v = f64::from_bits(self.wl[k].load(Relaxed));
        if !v.is_nan() {
            return v;
        }
        let w = self.problem.delassus().w();
        let col = w.col(k).try_as_col_major().expect("contiguous column");
        let v = crate::dense::abs_dot(col.as_slice(), &self.abs_lam);
        self.wl[k].store(v.to_bits(), Relaxed);
        v
    }

    /// `|q_k|ₜ + |g_k|` (the gap in the normal rows only).
    fn base(&self, k: usize) -> f64 {
        let p = self.terms.len() / 2;
        self.terms[k]
            + if k < p {
                self.problem.gap_equilibrated()[k].abs()
            } else {
                0.0
            }
    }

    fn exact(&self, k: usize) -> f64 {
        (self.factor * (self.base(k) + self.wl(k))).max(self.floor)
    }

    /// An upper bound of `(|W||λ|)_k` in O(1): `(|W| 1)_k ‖λ‖∞`.
    fn wl_upper(&self, k: usize) -> f64 {
        self.problem.w_row_sums()[k] * self.lam_max
    }

    /// An upper bound of [`Self::exact`] in O(1).
    fn upper(&self, k: usize) -> f64 {
        (self.factor * (self.base(k) + self.wl_upper(k))).max(self.floor)
    }

    /// The floor under row k's threshold ([`Widen::min_row`], [`Widen::determined`]):
    /// `min_row`, but not above [`DETERMINED_FACTOR`] `· r0 · determined ·` the larger
    /// of `|q_j|ₜ + (|W| |λ|)_j` over the two rows j of k's node (a node's tangential row
    /// can vanish by symmetry where its normal one does not, and its rounding is as
    /// large). With `wl` = [`Self::wl_upper`]: a bound in O(1).
    fn floor_with(
        &self,
        k: usize,
        min_row: f64,
        determined: f64,
        wl: impl Fn(usize) -> f64,
    ) -> f64 {
        if min_row == 0.0 || determined == 0.0 {
            return min_row;
        }
        let p = self.terms.len() / 2;
        let other = if k < p { k + p } else { k - p };
        let row = |j: usize| self.terms[j] + wl(j);
        min_row.min(DETERMINED_FACTOR * self.r0 * determined * row(k).max(row(other)))
    }
}

/// The factor of [`TolRows::floor_with`]. On a mirror-symmetric body in double, the node
/// on the axis touched down with a tangential displacement (0 by symmetry) of 3.1 times
/// `r0 · determined ·` its normal row's terms: the data's own asymmetry (the element
/// matrices of mirrored elements, summed in different orders) moves q by more than the
/// error of the solve that measures `determined`. On a cantilevered strip, a node touching
/// down near the clamp slid with a tangential displacement 1000 times it: that must stay
/// determined.
const DETERMINED_FACTOR: f64 = 8.0;

impl Tol {
    /// One threshold for every form.
    fn uniform(t: f64) -> Self {
        Tol {
            force: t,
            disp: t,
            rows: None,
            arc: 0.0,
            rounding: 1.0,
            widen: 1.0,
            min_row: 0.0,
            determined: 0.0,
            cone: false,
            estimated: false,
        }
    }

    /// The same thresholds for a point that is known to the fixed-α solver's accuracy
    /// only (see [`Tol::rounding`]).
    fn approximate(mut self) -> Self {
        self.rounding = 1.0;
        self
    }

    /// Every threshold (and `arc`) times `k`, no displacement row's below the floor of
    /// [`Widen::min_row`] and [`Widen::determined`], and open nodes' `λt` as
    /// [`Widen::cone`] says: see `join::transit`, its retries where the usual thresholds
    /// find no continuation or several, or one that the data do not determine.
    pub(super) fn widened(mut self, w: Widen) -> Self {
        self.force *= w.k;
        self.disp *= w.k;
        self.arc *= w.k;
        self.widen *= w.k;
        self.min_row = self.min_row.max(w.min_row);
        self.determined = self.determined.max(w.determined);
        self.cone |= w.cone;
        self
    }

    /// The factor on the threshold of an open node's `λt = 0` (`open_t`) at a node of
    /// (equilibrated) friction coefficient `friction`: `1 + F`, at most the retries'
    /// widest factor ([`join::MAX_WIDENING`]), where [`Widen::cone`] is set, else 1.
    /// Beyond that, F times a threshold is no longer rounding: with a node's tangential
    /// row 1e300 times its normal one (F 1e300 times larger once equilibrated), open
    /// fitted a node whose λt was not zero, and the event's residual was 1.7e-3.
    pub(super) fn cone_factor(&self, open_t: bool, friction: f64) -> f64 {
        if self.cone && open_t {
            (1.0 + friction).min(join::MAX_WIDENING)
        } else {
            1.0
        }
    }

    /// The threshold for the derivative of a form along a unit tangent (scaled
    /// coordinates): relative to the point's force scale.
    fn slope(&self) -> f64 {
        self.disp
    }

    /// The threshold for a linear form.
    fn of(&self, f: &crate::piece::LinForm) -> f64 {
        if f.disp.coef != 0.0 {
            let k = f.disp.index;
            self.rows.as_ref().map_or(self.disp.max(self.min_row), |r| {
                let floor = r.floor_with(k, self.min_row, self.determined, |j| r.wl(j));
                (self.widen * r.exact(k)).max(floor)
            })
        } else {
            self.force * (f.lam[0].coef.abs() + f.lam[1].coef.abs()).max(1.0)
        }
    }

    /// True when a guard of value `v` with slope `vd` along a unit tangent (scaled
    /// coordinates) is at zero at this point: within the rounding of its value (a
    /// hundredth of [`Self::of`] at a transition point, all of it at a start), or crossing
    /// zero within `zero_tol` of the point along
    /// the tangent (`|v| ≤ zero_tol |vd|`), nearer than the point itself is determined.
    /// A guard that is small against its terms but crosses zero a distinct step away (on
    /// slender bodies the contact forces are a thousandth of the load's scale, and their
    /// guards' slopes tiny) is not at zero: it has its own transition.
    ///
    /// Where the terms are estimated (a general load), the thresholds hold the load's
    /// change over the window and can be far above the value's rounding: there, at a
    /// point found exactly (not a start, whose values are the fixed-α solver's), a
    /// positive guard that decreases is at zero by its value only where its own root lies
    /// within [`ROUNDING_LONG`] along the tangent (a relative change of the forces and of
    /// α in its unit). A gap closing at a grazing slope (4.6e-12 against a threshold of
    /// 6.4e-10, its root 2.1e-5 away) was counted at zero at another node's transition,
    /// and the node touched down there, 4.4e-4 in φ before its own root, without an error.
    fn at_zero(&self, f: &crate::piece::LinForm, v: f64, vd: f64) -> bool {
        let a = v.abs();
        let own_root =
            self.estimated && self.rounding < 1.0 && v > 0.0 && vd < 0.0 && a > ROUNDING_LONG * -vd;
        a.is_finite()
            && ((vd.is_finite() && a <= self.arc * vd.abs())
                || (!own_root
                    && a <= self.rounding * self.upper(f)
                    && a <= self.rounding * self.of(f)))
    }

    /// [`Self::at_zero`] for the slip guard of a frictionless node
    /// ([`PieceConstants::label_only`]), against [`Self::label_of`].
    fn at_zero_label(&self, f: &crate::piece::LinForm, v: f64, vd: f64) -> bool {
        let a = v.abs();
        a.is_finite()
            && ((vd.is_finite() && a <= self.arc * vd.abs())
                || a <= self.rounding * self.label_of(f))
    }

    /// The threshold of a frictionless node's slip guard (its dt): [`Self::upper`], with
    /// row k's terms bounded by `(|W| 1)_k ‖λ‖∞`. A dt that vanishes by symmetry or
    /// because its neighbours stick (the node on a symmetric body's axis) is the rounding
    /// of W's entries against all of λ: with its own row's terms (those entries' rounding
    /// too) the threshold was a hundredth of it. The guard's side only names the class.
    fn label_of(&self, f: &crate::piece::LinForm) -> f64 {
        self.upper(f)
    }

    /// `a ≤` [`Self::of`]`(f)`, its O(1) bound [`Self::upper`] tested first (`of` may cost
    /// a pass over a row of W). False for a NaN `a`.
    fn within(&self, f: &crate::piece::LinForm, a: f64) -> bool {
        a <= self.upper(f) && a <= self.of(f)
    }

    /// An upper bound of [`Self::of`] that costs O(1): a value above it is above the
    /// threshold without computing the threshold.
    fn upper(&self, f: &crate::piece::LinForm) -> f64 {
        match (&self.rows, f.disp.coef != 0.0) {
            (Some(r), true) => {
                let k = f.disp.index;
                let floor = r.floor_with(k, self.min_row, self.determined, |j| r.wl_upper(j));
                (self.widen * r.upper(k)).max(floor)
            }
            _ => self.of(f),
        }
    }
}

/// Values computed at the last few points `(α, λ)`, found again by exact equality of α
/// and λ (q, and so all the point's data, follows from α).
struct PointCache<T>(RefCell<Vec<(f64, Vec<f64>, T)>>);

impl<T: Clone> PointCache<T> {
    /// Entries kept: a transition reads its point's, the point it came from, and the
    /// points of the pieces it examines.
    const KEEP: usize = 4;

    fn new() -> Self {
        Self(RefCell::new(Vec::new()))
    }

    fn get(&self, alpha: f64, lam: &[f64]) -> Option<T> {
        self.0
            .borrow()
            .iter()
            .find(|(a, l, _)| *a == alpha && l == lam)
            .map(|(_, _, v)| v.clone())
    }

    fn clear(&self) {
        self.0.borrow_mut().clear();
    }

    /// Keeps `v` for `(alpha, lam)`, in place of an entry for the same point (a point
    /// moved along its tangent by less than α's resolution keeps its α and λ, and only its
    /// d moves: on an open piece at α ≈ 1e4 a touchdown's gap stayed at the root's
    /// double's, 1.7 times its threshold, and the node fitted no class), dropping the
    /// oldest entry beyond [`Self::KEEP`].
    fn put(&self, alpha: f64, lam: &[f64], v: T) {
        let mut cache = self.0.borrow_mut();
        if let Some(k) = cache.iter().position(|(a, l, _)| *a == alpha && l == lam) {
            cache.remove(k);
        }
        if cache.len() == Self::KEEP {
            cache.remove(0);
        }
        cache.push((alpha, lam.to_vec(), v));
    }
}

/// Position on the current piece.
#[derive(Clone)]
struct CurrentPiece {
    classes: Vec<Class>,
    lam: Vec<f64>,
    alpha: f64,
    /// Tangent (λ̇, α̇), unit in scaled coordinates, oriented along the path.
    t: Vec<f64>,
    /// Factorisation of the piece, with the scales of its Jacobian.
    lu: Arc<PieceSolver>,
    scales: JacobianScaling,
    /// The rate of `d` along `t`: `W t_λ + q' t_α`.
    rate: Arc<Vec<f64>>,
    /// λ on the piece at the α where the path entered it, solved from the data with the
    /// piece's updated factorisation (None for a full-pivoting solver).
    xp: Option<Arc<Vec<f64>>>,
}

/// A transition point with its continuations, kept until the next step.
struct PendingJoin {
    point: Point,
    from: Vec<Class>,
    cands: Vec<Candidate>,
    events_start: usize,
    pieces_len: usize,
    last_dir: i8,
    bifurcation: bool,
    /// The branches leave the start point (no events; choosing one restarts there).
    at_start: bool,
}

#[derive(Clone)]
struct Point {
    lam: Vec<f64>,
    alpha: f64,
    q: Vec<f64>,
    dq: Vec<f64>,
    /// A basis load's weight derivatives `w'(α)` (`dq = Σ_j w'_j q_j`); None otherwise.
    dw: Option<Vec<f64>>,
}

#[derive(Clone)]
struct Candidate {
    classes: Vec<Class>,
    t: Vec<f64>,
    orientation: i8,
    det_sign: i8,
    lu: Arc<PieceSolver>,
    scales: JacobianScaling,
    /// The rate of `d` along `t`.
    rate: Arc<Vec<f64>>,
    /// λ on the piece at the point, solved from the data (see [`CurrentPiece::xp`]).
    xp: Option<Arc<Vec<f64>>>,
}

impl Candidate {
    /// The piece `classes` along `s t` (s = ±1) from its tangent `t`, the rate of d along
    /// `t` and its factorisation (`lu`, with the orientation of `t` and the scaling).
    fn along(
        classes: &[Class],
        s: f64,
        (lu, lu_orientation, scales): (&Arc<PieceSolver>, i8, JacobianScaling),
        (t, rate): (&[f64], &Arc<Vec<f64>>),
        xp: Option<Arc<Vec<f64>>>,
    ) -> Candidate {
        let ts: Vec<f64> = t.iter().map(|v| s * v).collect();
        let orientation = if s > 0.0 {
            lu_orientation
        } else {
            -lu_orientation
        };
        let m = ts.len() - 1;
        let det_sign = if scales.is_vertical(&ts) {
            0
        } else {
            orientation * sign(ts[m])
        };
        let rate = if s > 0.0 {
            rate.clone()
        } else {
            Arc::new(rate.iter().map(|v| -v).collect())
        };
        Candidate {
            orientation,
            classes: classes.to_vec(),
            t: ts,
            det_sign,
            lu: lu.clone(),
            scales,
            rate,
            xp,
        }
    }

    /// Sign of dα/ds along the candidate (0 for a vertical piece).
    fn direction(&self) -> i8 {
        if self.scales.is_vertical(&self.t) {
            0
        } else {
            sign(self.t[self.t.len() - 1])
        }
    }

    /// The candidate as the caller sees it.
    fn branch(&self, orientation_preserving: bool) -> Branch {
        Branch {
            classes: self.classes.clone(),
            direction: self.direction(),
            orientation_preserving,
        }
    }
}

/// How a piece's equations are solved: a full-pivoting LU of the Jacobian in scaled
/// coordinates (vertical pieces, and every piece when
/// [`PathOptions::fresh_factorisations`] is set), or `M_S` by updates of a base.
enum PieceSolver {
    Full(PieceLu),
    Updated(UpdatedLu),
}

impl PieceSolver {
    /// The updated factorisation, where this is one.
    fn updated(&self) -> Option<&UpdatedLu> {
        match self {
            PieceSolver::Updated(u) => Some(u),
            PieceSolver::Full(_) => None,
        }
    }

    /// A solution `x` (raw coordinates (λ, α)) of `J x = b`. The updated form returns the
    /// one at `near_alpha` (`x_α = near_alpha`, the α of the current point), so that no cancellation
    /// with a far-away α = 0 enters.
    #[allow(clippy::too_many_arguments)]
    fn particular_raw(
        &self,
        c: &PieceConstants<'_>,
        w: faer::MatRef<'_, f64>,
        b: &[f64],
        near_alpha: f64,
        dq_col: &[f64],
        scales: JacobianScaling,
        row_bound: f64,
    ) -> Vec<f64> {
        match self {
            PieceSolver::Full(lu) => {
                let m = b.len();
                let mut x = lu.particular(b);
                for v in x.iter_mut().take(m) {
                    *v *= scales.force;
                }
                x[m] *= scales.alpha;
                x
            }
            PieceSolver::Updated(u) => {
                // M λ = b − c α with α = near_alpha.
                let alpha = near_alpha;
                let rhs: Vec<f64> = b
                    .iter()
                    .zip(dq_col)
                    .map(|(bi, ci)| bi - ci * alpha)
                    .collect();
                let mut x = u.solve_checked(c, w, &rhs, row_bound).x;
                x.push(alpha);
                x
            }
        }
    }
}

/// A piece's tangent at a point with its factorisation.
struct PieceTangent {
    /// Unit in scaled coordinates, given in raw coordinates.
    t: Vec<f64>,
    lu: PieceSolver,
    scales: JacobianScaling,
    /// `sign det [J_S; tᵀ]`.
    orientation: i8,
    /// The rate of `d` along `t`: `W t_λ + q' t_α`.
    rate: Vec<f64>,
    /// λ on the piece at the point's α (updated factorisations only).
    xp: Option<Vec<f64>>,
}

/// The scaling of a piece Jacobian: λ is measured in units of `force`, α in units of
/// `alpha`, so that the tangent is a unit vector in scaled coordinates.
#[derive(Clone, Copy)]
struct JacobianScaling {
    force: f64,
    alpha: f64,
}

impl JacobianScaling {
    /// A tangent (raw coordinates) along which α does not move to working accuracy.
    fn is_vertical(&self, t: &[f64]) -> bool {
        t[t.len() - 1].abs() / self.alpha <= 1e-14
    }
}

/// Where the path entered a piece (for closed-loop detection).
struct PieceEntry {
    classes: Vec<Class>,
    lam: Vec<f64>,
    alpha: f64,
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

/// A hash of a class vector (for the closed-loop index).
fn classes_hash(classes: &[Class]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    classes.hash(&mut h);
    h.finish()
}

/// Numbers beyond 2^1000 ≈ 1.07e301 lie within a few orders of the largest double, where
/// sums and products of the tracer's quantities can overflow.
const NEAR_OVERFLOW: f64 = f64::from_bits((1023 + 1000) << 52);

/// A hint for a failure at a point whose forces or loads exceed [`NEAR_OVERFLOW`], where
/// the tracer's products can overflow; empty elsewhere.
fn near_overflow(pt: &Point) -> String {
    overflow_hint(inf_norm(&pt.lam).max(inf_norm(&pt.q)).max(inf_norm(&pt.dq)))
}

/// The hint of [`near_overflow`] for numbers of magnitude `big` (forces or loads); empty
/// where `big` is at most [`NEAR_OVERFLOW`].
pub(crate) fn overflow_hint(big: f64) -> String {
    if big > NEAR_OVERFLOW {
        format!(
            "; the forces and loads there reach {big:e}, near the largest double, where \
             products overflow: scale the load and the gap down (the path's λ is \
             proportional to them)"
        )
    } else {
        String::new()
    }
}

/// Largest number of neighbouring pieces enumerated at one transition point (the product
/// over the nodes at a class boundary of the number of classes that fit there). Beyond it,
/// nodes at a zero-force vertex are handled by the directional problem (one solution per
/// way along α), and only the other nodes are enumerated; where those are still too many
/// (beyond [`MAX_DIRECTIONAL_COMBINATIONS`]) and each fits two classes, they take theirs
/// by pivoting (`Path::pivoted_classes`, the vertex nodes' classes from the directional
/// problem at each step).
const MAX_CANDIDATE_PIECES: usize = 4096;

/// Where the vertex nodes take their classes from the directional problem, the largest
/// number of combinations of the other nodes' classes enumerated before pivoting is tried
/// (each combination costs a nonlinear solve per way, not a tangent). On a slender strip
/// in double (458 × 3, F = 5, κ(W) 5e9), 138 nodes were at the vertex within the widened
/// thresholds, with 10 nodes at a boundary between two classes: the 2048 directional
/// solves of that one point took 32 s. Where pivoting finds no continuation, every
/// combination up to [`MAX_CANDIDATE_PIECES`] is enumerated as before.
const MAX_DIRECTIONAL_COMBINATIONS: usize = 64;

/// Relative residual (as the fixed-α solver measures it) below which a stalled solve of
/// the directional problem is taken while pivoting on many nodes' classes
/// ([`Path::directional_classes`]): its classes are only a candidate's, which its piece's
/// tangent, from the data, then checks. On the p = 2000 strip of `fricont gen-rect
/// --press-shear --nx 2001 --ny 76 --lx 20 --ly 0.76` Newton stalled there at residuals of
/// 1e-10 to 2e-8, where the solver's later stages took 0.3–2 s each and, once, 143 s
/// (20,000 Gauss–Seidel sweeps).
const DIRECTIONAL_LOOSE: f64 = 1e-7;

impl Path {
    /// Binds a load to a problem. Computes the condensed load vectors (one back-solve per
    /// basis vector). Errors: load length ≠ n; window bounds not finite or equal;
    /// `zero_tol` not in (0, 1e-3]; `max_alpha_step` not finite and > 0.
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
        if let Some(h) = opts.max_alpha_step
            && !(h.is_finite() && h > 0.0)
        {
            return Err(Error::InvalidParameter(format!(
                "max_alpha_step = {h} must be finite and > 0"
            )));
        }
        if !(opts.zero_tol > 0.0 && opts.zero_tol <= 1e-3) {
            return Err(Error::InvalidParameter(format!(
                "zero_tol = {} must be in (0, 1e-3]",
                opts.zero_tol
            )));
        }
        // The dense working set of a path: about eight m × m matrices at its peak (the
        // factorised base piece, its factors, |W|, the fixed-α solver's Jacobians).
        let m = 2 * problem.p();
        crate::problem::preflight(
            m.saturating_mul(m).saturating_mul(8 * 8),
            "the dense working set of a path (about 8 matrices of 2p x 2p)",
        )?;
        let load = BoundLoad::new(load, problem.delassus())?;
        Ok(Path {
            problem,
            load,
            opts,
            trace: None,
            updater: RefCell::new(None),
            refactorisations: Cell::new(0),
            gaps_cache: PointCache::new(),
            tol_cache: PointCache::new(),
            scale_cache: PointCache::new(),
            graph_step: Cell::new(None),
            resolved: RefCell::new(Vec::new()),
            directional_warm: RefCell::new(Vec::new()),
            carried: None,
            refined: None,
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

    /// The private pool of this call's dense passes (see [`crate::ProblemBuilder::threads`]).
    fn pool_scope(&self) -> crate::dense::TracePoolScope {
        crate::dense::TracePoolScope::enter(self.problem.threads(), 2 * self.problem.p())
    }

    fn consts(&self) -> PieceConstants<'_> {
        PieceConstants::of(&self.problem)
    }

    /// λ of the piece `classes` for the right-hand side `rhs` (the seed's rows), from the
    /// data: by the updated factorisation `updated` where its solve passes its check (a
    /// relative residual of at most 1e-12, every entry finite), else by one LU of M_S.
    /// The flag says whether the update served.
    fn piece_solve(
        &self,
        classes: &[Class],
        updated: Option<&UpdatedLu>,
        rhs: &[f64],
    ) -> (Vec<f64>, bool) {
        let c = self.consts();
        let w = self.problem.delassus().w();
        if let Some(u) = updated {
            let k = u.solve_checked(&c, w, rhs, self.row_bound());
            if k.rel <= 1e-12 && k.x.iter().all(|v| v.is_finite()) {
                return (k.x, true);
            }
        }
        let lu = DenseLu::new(c.piece_matrix(w, classes).as_ref());
        (lu.solve(rhs), false)
    }

    fn point_at(&mut self, lam: Vec<f64>, alpha: f64) -> Result<Point> {
        let (q, dq) = self.load.q(alpha, self.problem.delassus())?;
        let dw = self.load.weights_at(alpha).map(|(_, dw)| dw.to_vec());
        Ok(Point {
            lam,
            alpha,
            q,
            dq,
            dw,
        })
    }

    /// Force scale of a point: `max(‖λ‖∞, r0 T, r0 max_i (q − g)ν_i⁺)` with T the
    /// magnitude of the terms that make up q(α) (see [`Self::term_rows`]): where the load
    /// passes through zero the rounding of q is still proportional to T. A gap enters only
    /// where it is negative enough to press (an initial overlap): a node far from the
    /// foundation does not set the scale of the others. For affine and basis loads it
    /// depends on the point alone, never on the window.
    fn force_scale(&self, pt: &Point) -> f64 {
        if let Some(s) = self.scale_cache.get(pt.alpha, &pt.lam) {
            return s;
        }
        let r0 = self.problem.default_r();
        let terms = self.term_rows(pt).0.iter().fold(0.0f64, |a, &b| a.max(b));
        let overlap =
            pt.q.iter()
                .zip(self.problem.gap_equilibrated())
                .fold(0.0f64, |a, (q, g)| a.max(q - g));
        let scale = inf_norm(&pt.lam)
            .max(r0 * terms)
            .max(r0 * overlap)
            .max(1e-300);
        self.scale_cache.put(pt.alpha, &pt.lam, scale);
        scale
    }

    /// The α length that a nonlinear load's march (its first and its shortest steps, with
    /// `factor` = [`FAR_WINDOW`], `from` = α_start) and a general load's estimated term
    /// magnitudes ([`Self::term_rows`], `factor` = 1, `from` = the current piece's entry)
    /// are relative to at `pt`: the window's length, but at most `factor` times the
    /// point's own α length, `max(|α − from|, ‖q‖∞ / ‖q'‖∞)` (how far the path has come,
    /// and how far α moves the load by its own size; the window's length where both are
    /// 0).
    /// A far window end does not make the thresholds of a general load, or the least step
    /// of a march, a fixed fraction of the window: with the window's length itself, a
    /// window [a, 1e12] around a load varying on a scale of 1 made every guard "at zero"
    /// (a general load: wrong events, no error) or forced steps of length 1 past the step
    /// control (a basis load: loud stops).
    fn load_span(&self, pt: &Point, factor: f64, from: f64) -> f64 {
        let window = self.alpha_scale();
        let own = inf_norm(&pt.q) / inf_norm(&pt.dq);
        // (f64::max ignores a NaN own length, 0 / 0)
        let local = (pt.alpha - from).abs().max(own);
        if local.is_finite() && local > 0.0 {
            window.min(factor * local)
        } else {
            window
        }
    }

    /// The magnitude of the terms of each row of `q(α)`: exact for affine and basis loads
    /// ([`BoundLoad::term_magnitude_rows`]), a basis load's plus its change since the
    /// current piece's entry α_e, `|α − α_e| Σ_j |w'_j(α)| |q_j|`
    /// ([`BoundLoad::term_rate_rows`]: a point's q and λ on the piece carry that change's
    /// rounding, which does not vanish where the weights do); for a general load, whose
    /// terms are not known, `|q_k| + L |q'_k|` (the change of q over an α length L: the
    /// window's, but no more than the point's own, see [`Self::load_span`]; and at least
    /// [`ALPHA_ROUNDINGS`] roundings of α over `zero_tol`, see there). With whether they
    /// are estimated so.
    ///
    /// The estimate cannot tell a load whose terms cancel (where it passes through zero)
    /// from one that is small by itself, and it errs to the larger: thresholds too large
    /// merge transitions that lie closer together than they say (see [`Load::general`]).
    /// The window's length counts no more than the point's own length: with a thousand
    /// times it, a load `1e-6 f0 + φ(α) f1` (φ = α + 0.2 sin 2α) traced from α = −1
    /// through φ = 0 over a window [−1, 1e3] merged a node's touchdown into another
    /// node's transition 7.4e-10 before it (at α = −1.04e-6), without an error, and on
    /// finite-element meshes moved events by up to 3 % of their α. And the own length
    /// counts from the current piece's entry, not from the path's start: from the start,
    /// under `1e-8 f0 + φ(α) f1` from α = ±1, every transition near φ = 0 had thresholds
    /// of the load's size at the start, and 23 of 160 traces (random problems and meshes)
    /// merged or moved events there without an error; 2 do now (their first transition).
    fn term_rows(&self, pt: &Point) -> (Vec<f64>, bool) {
        let from = match &self.trace {
            Some(tr) => tr.cur.alpha,
            None => self.opts.alpha_start,
        };
        match self.load.term_magnitude_rows(pt.alpha) {
            Some(mut rows) => {
                // A basis load's q at a point reached along a piece is found relative to
                // the piece's entry: its rounding holds the change since the entry,
                // |α − α_e| |q'|ₜ, which does not vanish where the weights do.
                if let Some(rate) = self.load.term_rate_rows(pt.alpha) {
                    let span = (pt.alpha - from).abs();
                    if span.is_finite() {
                        for (r, d) in rows.iter_mut().zip(&rate) {
                            *r += span * d;
                        }
                    }
                }
                (rows, false)
            }
            None => {
                let span = self
                    .load_span(pt, 1.0, from)
                    .max(ALPHA_ROUNDINGS * f64::EPSILON / self.opts.zero_tol * pt.alpha.abs());
                let rows =
                    pt.q.iter()
                        .zip(&pt.dq)
                        .map(|(q, dq)| q.abs() + span * dq.abs())
                        .collect();
                (rows, true)
            }
        }
    }

    /// The "at zero" thresholds at a point. A row `d_k` of the displacement gaps is at
    /// zero below `zero_tol · r0 (|q_k|ₜ + |g_k| + (|W| |λ|)_k)` (but not below 1e-3 of the
    /// point's threshold: the rows of q come from solves with A), with `|q_k|ₜ` the
    /// magnitude of the terms of `q_k(α)` (see [`BoundLoad::term_magnitude_rows`]): what its
    /// rounding is proportional to, row by row (on slender bodies the rows of q differ by
    /// orders of magnitude). A force form is at zero below `zero_tol` times the contact
    /// forces, `max(‖λ‖∞, force scale / 10)` (the floor keeps the rounding of λ, which is
    /// relative to the load, below it where all forces vanish together).
    fn tol_at(&self, pt: &Point) -> Tol {
        if let Some(t) = self.tol_cache.get(pt.alpha, &pt.lam) {
            return t;
        }
        // The rows of q come from solves with A, whose rounding is relative to the whole
        // vector: no row's threshold goes below 1e-3 of the point's.
        const ROW_FLOOR: f64 = 1e-3;
        let scale = self.force_scale(pt);
        let z = self.opts.zero_tol;
        let r0 = self.problem.default_r();
        let m = pt.lam.len();
        let (qt, estimated) = self.term_rows(pt);
        let rows = TolRows {
            problem: self.problem.clone(),
            factor: z * r0,
            r0,
            abs_lam: pt.lam.iter().map(|v| v.abs()).collect(),
            lam_max: inf_norm(&pt.lam),
            floor: ROW_FLOOR * z * scale,
            terms: qt,
            wl: (0..m)
                .map(|_| std::sync::atomic::AtomicU64::new(f64::NAN.to_bits()))
                .collect(),
        };
        let tol = Tol {
            force: z * inf_norm(&pt.lam).max(0.1 * scale),
            disp: z * scale,
            rows: Some(Arc::new(rows)),
            arc: z,
            rounding: ROUNDING,
            widen: 1.0,
            min_row: 0.0,
            determined: 0.0,
            cone: false,
            estimated,
        };
        self.tol_cache.put(pt.alpha, &pt.lam, tol.clone());
        tol
    }

    /// The unit of α at a point: the change of α that moves the load by the force scale,
    /// `scale / (r0 ‖q'‖∞)` (the window's length where q' = 0). Tangents are unit vectors
    /// in λ / scale and α / unit, and "vertical" means a negligible α component there.
    fn alpha_unit(&self, pt: &Point, scale: f64) -> f64 {
        let rate = self.problem.default_r() * inf_norm(&pt.dq);
        let unit = scale / rate;
        if unit.is_finite() && unit > 0.0 {
            unit
        } else {
            self.alpha_scale()
        }
    }

    fn state(&mut self, lam: &[f64], alpha: f64, classes: &[Class]) -> Result<State> {
        // One back-solve of f + Bᵀλ: forming u as A⁻¹f + (A⁻¹Bᵀ)λ instead would cancel
        // (the free displacement under the load is often orders of magnitude larger than
        // u) and lose the residual's accuracy.
        let f = self.load.force(alpha)?;
        self.state_with_force(lam, alpha, classes, f)
    }

    /// The state at a point; u is empty when the problem cannot solve with A (condensed
    /// input). Errors: the host's solve failed.
    fn state_with_force(
        &self,
        lam: &[f64],
        alpha: f64,
        classes: &[Class],
        f: Vec<f64>,
    ) -> Result<State> {
        let del = self.problem.delassus();
        let u = if del.has_solve() {
            del.displacement(&f, lam)?
        } else {
            Vec::new()
        };
        Ok(self.state_from_u(lam, alpha, classes, &f, u))
    }

    /// The state with u already solved for.
    fn state_from_u(
        &self,
        lam: &[f64],
        alpha: f64,
        classes: &[Class],
        f: &[f64],
        u: Vec<f64>,
    ) -> State {
        let residual = crate::piece::residual(&self.problem, &u, lam, f);
        self.state_with(lam, alpha, classes, u, residual)
    }

    /// A state from its parts (λ internal; `residual` computed by the caller).
    fn state_with(
        &self,
        lam: &[f64],
        alpha: f64,
        classes: &[Class],
        u: Vec<f64>,
        residual: f64,
    ) -> State {
        let p = self.problem.p();
        let user = self.lam_to_user(lam);
        State {
            alpha,
            u,
            lambda_n: user[..p].to_vec(),
            lambda_t: user[p..].to_vec(),
            classes: classes.to_vec(),
            residual,
        }
    }

    /// The right-hand sides `rhs_S(q_j)` of a basis load's vectors for the piece
    /// `classes`, then the gap's, `rhs_S(−(g, 0))` (the seed's row scaling): the piece's
    /// solutions of these combine into its point and tangent at any α. None for other
    /// loads.
    fn basis_rhs(&self, classes: &[Class]) -> Option<Vec<Vec<f64>>> {
        let qs = self.load.basis_vectors()?;
        let c = self.consts();
        let g = shift_gap(&vec![0.0; 2 * c.p], self.problem.gap_equilibrated());
        Some(
            qs.iter()
                .chain(std::iter::once(&g))
                .map(|q| c.piece_rhs(classes, q))
                .collect(),
        )
    }

    /// The α column `∂H/∂α` of the piece Jacobian (raw coordinates).
    fn alpha_column(&self, classes: &[Class], dq: &[f64]) -> Vec<f64> {
        let c = self.consts();
        let mut col = vec![0.0; 2 * c.p];
        for (i, &cl) in classes.iter().enumerate() {
            let [nu, t] = c.equations(i, cl);
            col[i] = nu.disp.coef * dq[nu.disp.index];
            col[c.p + i] = t.disp.coef * dq[t.disp.index];
        }
        col
    }

    /// Forces in the caller's units from the internal (equilibrated) ones: `λ_k` divided
    /// by [`Problem::row_scale`]`[k]`.
    fn lam_to_user(&self, lam: &[f64]) -> Vec<f64> {
        let s = self.problem.row_scale();
        lam.iter().zip(s).map(|(v, s)| v / s).collect()
    }

    /// The inverse of [`Self::lam_to_user`].
    fn lam_to_internal(&self, lam: &[f64]) -> Vec<f64> {
        let s = self.problem.row_scale();
        lam.iter().zip(s).map(|(v, s)| v * s).collect()
    }

    /// `d = q − (g, 0) + W λ` at a point (one product with W, cached for the last few
    /// points).
    fn gaps(&self, pt: &Point) -> Arc<Vec<f64>> {
        if let Some(d) = self.gaps_cache.get(pt.alpha, &pt.lam) {
            return d;
        }
        let qg = shift_gap(&pt.q, self.problem.gap_equilibrated());
        let d = displacement_gaps(self.problem.delassus().w(), &qg, &pt.lam);
        self.prime_gaps(pt.alpha, &pt.lam, d)
    }

    /// Keeps `d` of the point `(α, λ)`, computed by the caller, for [`Self::gaps`].
    fn prime_gaps(&self, alpha: f64, lam: &[f64], d: Vec<f64>) -> Arc<Vec<f64>> {
        let d = Arc::new(d);
        self.gaps_cache.put(alpha, lam, d.clone());
        d
    }

    /// The rate of `d` along `t` (raw coordinates): `W t_λ + q' t_α` (one product with W).
    fn rate_along(&self, t: &[f64], dq: &[f64]) -> Vec<f64> {
        let m = t.len() - 1;
        let mut dd = displacement_gaps(self.problem.delassus().w(), &vec![0.0; m], &t[..m]);
        for (v, q) in dd.iter_mut().zip(dq) {
            *v += q * t[m];
        }
        dd
    }

    /// Bound on the absolute row sums of every piece matrix (for residual checks).
    fn row_bound(&self) -> f64 {
        update::row_bound(&self.consts(), self.problem.w_row_sums())
    }

    /// The path moves onto a piece: later pieces are updated from its factorisation.
    fn commit_solver(&self, lu: &PieceSolver) {
        if let PieceSolver::Updated(u) = lu {
            *self.updater.borrow_mut() = Some(u.clone());
        }
    }

    /// Fresh factorisations of a base piece matrix so far on this path (each O(m³); the
    /// pieces between them cost O(m²) each). With
    /// [`PathOptions::fresh_factorisations`], fresh factorisations of the Jacobians are
    /// not counted.
    pub fn refactorisations(&self) -> usize {
        self.refactorisations.get()
    }

    /// Tangent of piece `classes` at `pt` in raw coordinates, unit in the scaled
    /// coordinates (λ/S, α/A). By an update of the current base when `M_S` is regular
    /// (O(m²)); by a full-pivoting LU of the Jacobian otherwise (a vertical piece) or on
    /// request. `None` when the Jacobian has rank < 2p.
    fn tangent(&self, classes: &[Class], pt: &Point, scale: f64) -> Option<PieceTangent> {
        let scales = JacobianScaling {
            force: scale,
            alpha: self.alpha_unit(pt, scale),
        };
        if !self.opts.fresh_factorisations
            && let Some(t) = self.tangent_updated(classes, pt, scales)
        {
            return Some(t);
        }
        self.tangent_full(classes, pt, scales)
    }

    /// The tangent from `M_S y = −∂H/∂α` (t ∝ (y, 1)); `None` when `M_S` is singular or
    /// so close to it that the piece is vertical to working accuracy.
    fn tangent_updated(
        &self,
        classes: &[Class],
        pt: &Point,
        scales: JacobianScaling,
    ) -> Option<PieceTangent> {
        let c = self.consts();
        let w = self.problem.delassus().w();
        let m = 2 * c.p;
        let rb = self.row_bound();
        let neg: Vec<f64> = self
            .alpha_column(classes, &pt.dq)
            .iter()
            .map(|v| -v)
            .collect();
        let qg = shift_gap(&pt.q, self.problem.gap_equilibrated());
        let rhs = c.piece_rhs(classes, &qg);
        let d = self.gaps(pt);
        let zeros = vec![0.0; m];
        let resid = update::residual_rows(&c, classes, &pt.lam, &d, &zeros);
        // The right-hand sides carried from piece to piece by the rank-2 updates (O(km),
        // see update::Carried): an affine load's α column (the tangent itself); a basis
        // load's columns rhs_S(q_j) and the gap's, from which the tangent is combined
        // (λ' = Σ_j w'_j y_j) and which the march on the piece reuses
        // (advance::BasisSolutions) instead of solving for them. None for a general load,
        // whose α column changes with α.
        let basis_dw = pt
            .dw
            .as_deref()
            .zip(self.load.basis_vectors())
            .filter(|(dw, qs)| dw.len() == qs.len());
        let targets: Option<Vec<Vec<f64>>> = if self.load.is_affine() {
            Some(vec![neg.clone()])
        } else {
            basis_dw.and_then(|_| self.basis_rhs(classes))
        };
        let add =
            |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| x + y).collect() };
        // Solutions of the carried columns checked from the data: each kept where its
        // residual is at rounding level, else solved for from it (as a correction).
        let check_cols = |u: &UpdatedLu,
                          mut ys: Vec<Vec<f64>>,
                          mut wys: Vec<Vec<f64>>,
                          bs: &[Vec<f64>]|
         -> Option<update::CheckedCols> {
            let rs: Vec<(Vec<f64>, f64)> = (0..bs.len())
                .map(|j| {
                    let r = update::residual_rows(&c, classes, &ys[j], &wys[j], &bs[j]);
                    let rel = update::relative_residual(&c, classes, &r, &ys[j], &bs[j], rb);
                    (r, rel)
                })
                .collect();
            let again: Vec<usize> = (0..bs.len())
                .filter(|&j| rs[j].1.is_nan() || rs[j].1 > update::REFINE_ABOVE)
                .collect();
            if !again.is_empty() {
                let solved = {
                    let cols: Vec<update::Rhs<'_>> = again
                        .iter()
                        .map(|&j| update::Rhs {
                            b: &bs[j],
                            guess: Some((&ys[j], &rs[j].0)),
                        })
                        .collect();
                    u.solve_checked_many(&c, w, &cols, rb)
                };
                for (&j, k) in again.iter().zip(solved) {
                    if k.rel > 1e-12 {
                        return None;
                    }
                    // For a guess, wx is W times the correction only.
                    wys[j] = add(&wys[j], &k.wx);
                    ys[j] = k.x;
                }
            }
            ys.iter()
                .all(|y| y.iter().all(|v| v.is_finite()))
                .then_some((ys, wys))
        };
        // The tangent y (M_S y = −∂H/∂α) with W y: from the checked columns (an affine
        // load's α column, a basis load's combination) where its residual from the data is
        // at rounding level, else solved for (from that residual, as a correction).
        let tangent_of = |u: &UpdatedLu, cols: Option<&update::CheckedCols>| {
            // An affine load's column is the tangent's, checked already.
            if let (None, Some((ys, wys))) = (basis_dw, cols) {
                return Some((ys[0].clone(), wys[0].clone()));
            }
            let guess = cols.zip(basis_dw).map(|((ys, wys), (dw, _))| {
                let (mut y, mut wy) = (vec![0.0; m], vec![0.0; m]);
                for (j, &f) in dw.iter().enumerate() {
                    crate::dense::axpy(&mut y, f, &ys[j]);
                    crate::dense::axpy(&mut wy, f, &wys[j]);
                }
                let r = update::residual_rows(&c, classes, &y, &wy, &neg);
                let rel = update::relative_residual(&c, classes, &r, &y, &neg, rb);
                (y, wy, r, rel)
            });
            if let Some(g) = guess.as_ref().filter(|g| g.3 <= update::REFINE_ABOVE) {
                return Some((g.0.clone(), g.1.clone()));
            }
            let col = update::Rhs {
                b: &neg,
                guess: guess.as_ref().map(|g| (&g.0[..], &g.2[..])),
            };
            let k = u
                .solve_checked_many(&c, w, &[col], rb)
                .pop()
                .filter(|k| k.rel <= 1e-12)?;
            let wy = match &guess {
                Some(g) => add(&g.1, &k.wx),
                None => k.wx,
            };
            Some((k.x, wy))
        };
        // Keeps the checked columns with the factorisation: a basis load's piece reuses
        // them (a fresh carry first where there was none).
        let keep = |u: &mut UpdatedLu, cols: update::CheckedCols, fresh_carry: bool| {
            if let Some(bs) = &targets {
                if fresh_carry {
                    u.set_carry(&c, bs, &cols.0);
                }
                if basis_dw.is_some() {
                    u.set_checked(cols);
                }
            }
        };
        // On an update of the current base, the point is the current λ corrected from
        // its residual on this piece's equations (O(m) with the point's d): on a
        // neighbouring piece that residual is at rounding level, and so is the
        // correction's error; its solve shares the pass over the base's factor with the
        // new nodes' columns.
        // Where that residual is at rounding level already, the point is kept as it is
        // (a correction would be below its rounding) and neither pass carries it.
        let corrected = update::relative_residual(&c, classes, &resid, &pt.lam, &rhs, rb)
            > update::REFINE_ABOVE;
        let extras = if corrected {
            std::slice::from_ref(&resid)
        } else {
            &[]
        };
        let extended = self
            .updater
            .borrow()
            .as_ref()
            .filter(|u| u.reaches(classes))
            .and_then(|u| u.extend(&c, w, classes, targets.as_deref(), extras));
        let on_update = |(mut u, dx): (UpdatedLu, Vec<Vec<f64>>)| {
            // W times the point's correction and the carried columns: one pass over W.
            let carried = u.carried();
            let mut cols: Vec<&[f64]> = dx.iter().map(|v| &v[..]).collect();
            if let Some(cs) = &carried {
                cols.extend(cs.iter().map(|v| &v[..]));
            }
            let mut prods = crate::dense::mat_mul(w, &cols).into_iter();
            // The point and its residual from the data; refined once when that is above
            // rounding level, and then it must be small.
            let (mut xp, mut dp) = match dx.first() {
                Some(dx) => (add(&pt.lam, dx), add(&d, &prods.next()?)),
                None => (pt.lam.clone(), d.to_vec()),
            };
            let mut r = update::residual_rows(&c, classes, &xp, &dp, &zeros);
            if update::relative_residual(&c, classes, &r, &xp, &rhs, rb) > update::REFINE_ABOVE {
                let dx2 = u.solve_many(&c, std::slice::from_ref(&r)).pop()?;
                xp = add(&xp, &dx2);
                dp = add(&dp, &crate::dense::mat_mul(w, &[&dx2]).pop()?);
                r = update::residual_rows(&c, classes, &xp, &dp, &zeros);
                if update::relative_residual(&c, classes, &r, &xp, &rhs, rb) > 1e-12 {
                    return None;
                }
            }
            if !xp.iter().all(|v| v.is_finite()) {
                return None;
            }
            // d at the piece's point, for the ratio test that starts there.
            self.prime_gaps(pt.alpha, &xp, dp);
            // The carried columns (or, where nothing was carried, solved for afresh).
            let fresh_carry = carried.is_none();
            let checked = match (&targets, carried) {
                (Some(bs), Some(ys)) => {
                    let wys: Vec<Vec<f64>> = prods.collect();
                    check_cols(&u, ys, wys, bs)
                }
                (Some(bs), None) => u.solve_cols(&c, w, bs, rb),
                _ => None,
            };
            let (y, wy) = tangent_of(&u, checked.as_ref())?;
            if let Some(cols) = checked {
                keep(&mut u, cols, fresh_carry);
            }
            Some((u, (y, wy, xp)))
        };
        // A fresh base: the carried columns (or the tangent's) and the point in one
        // checked solve.
        let on_fresh = |u: &mut UpdatedLu| {
            let mut cols: Vec<update::Rhs<'_>> = match &targets {
                Some(bs) => bs.iter().map(|b| update::Rhs { b, guess: None }).collect(),
                None => vec![update::Rhs {
                    b: &neg,
                    guess: None,
                }],
            };
            cols.push(update::Rhs {
                b: &rhs,
                guess: Some((&pt.lam, &resid)),
            });
            let mut ch = u.solve_checked_many(&c, w, &cols, rb);
            let xp = ch.pop().expect("the point's column");
            if xp.rel > 1e-12 || ch.iter().any(|k| k.rel > 1e-12) {
                return None;
            }
            self.prime_gaps(
                pt.alpha,
                &xp.x,
                d.iter().zip(&xp.wx).map(|(a, b)| a + b).collect(),
            );
            let cols: update::CheckedCols = ch.into_iter().map(|k| (k.x, k.wx)).unzip();
            let (y, wy) = if targets.is_some() {
                let yw = tangent_of(u, Some(&cols))?;
                keep(u, cols, true);
                yw
            } else {
                (cols.0[0].clone(), cols.1[0].clone())
            };
            Some((y, wy, xp.x))
        };
        let (upd, (y, wy, xp), fresh) = match extended.and_then(on_update) {
            Some((u, y)) => (u, y, false),
            None => {
                let mut u = UpdatedLu::factor(&c, w, classes)?;
                self.refactorisations.set(self.refactorisations.get() + 1);
                let y = on_fresh(&mut u)?;
                (u, y, true)
            }
        };
        // Unit tangent in scaled coordinates, (y/S, 1/A) normalised.
        let mut t: Vec<f64> = y.iter().map(|v| v / scales.force).collect();
        t.push(1.0 / scales.alpha);
        let mut norm = t.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm == f64::INFINITY {
            // The same direction times A, (A y/S, 1), where (1/A)² overflows: at zero load
            // the force scale S is its floor, 1e-300, and A = S / (r ‖q'‖) with it (the
            // start of `start_from_zero_load`'s ray, every node open). Its tangent fell back
            // to a full-pivoting LU of the whole Jacobian, twice, 15 s of the ray's 22 s on
            // a strip with p = 1500.
            let k = scales.alpha / scales.force;
            t = y.iter().map(|v| v * k).chain([1.0]).collect();
            norm = t.iter().map(|v| v * v).sum::<f64>().sqrt();
        }
        if !(norm.is_finite() && norm > 0.0) || t[m] / norm <= 1e-13 {
            return None;
        }
        // (by S / norm, or, where that overflows (forces near the largest double), by 1 / norm
        // and then S)
        let by = |v: f64, s: f64| {
            let f = s / norm;
            if f.is_finite() { v * f } else { v / norm * s }
        };
        for v in t.iter_mut().take(m) {
            *v = by(*v, scales.force);
        }
        t[m] = by(t[m], scales.alpha);
        if t.iter().any(|v| !v.is_finite()) {
            return None;
        }
        if fresh {
            *self.updater.borrow_mut() = Some(upd.clone());
        }
        // t = (y, 1) / ‖(y/S, 1/A)‖, so the rate of d along t is (W y + q') by the same.
        let k = t[m];
        let rate = wy.iter().zip(&pt.dq).map(|(a, b)| k * (a + b)).collect();
        Some(PieceTangent {
            t,
            orientation: upd.det_sign(),
            lu: PieceSolver::Updated(upd),
            scales,
            rate,
            xp: Some(xp),
        })
    }

    /// The tangent from a full-pivoting LU of the Jacobian in scaled coordinates.
    fn tangent_full(
        &self,
        classes: &[Class],
        pt: &Point,
        scales: JacobianScaling,
    ) -> Option<PieceTangent> {
        let c = self.consts();
        let m = 2 * c.p;
        let qg = shift_gap(&pt.q, self.problem.gap_equilibrated());
        let (mut js, _) = c.jacobian(self.problem.delassus().w(), classes, &qg, &pt.dq, pt.alpha);
        for r in 0..m {
            for col in 0..m {
                js[(r, col)] *= scales.force;
            }
            js[(r, m)] *= scales.alpha;
        }
        let lu = PieceLu::new(js.as_ref())?;
        let mut t = lu.t.clone();
        for v in t.iter_mut().take(m) {
            *v *= scales.force;
        }
        t[m] *= scales.alpha;
        let rate = self.rate_along(&t, &pt.dq);
        Some(PieceTangent {
            t,
            orientation: lu.orientation,
            lu: PieceSolver::Full(lu),
            scales,
            rate,
            xp: None,
        })
    }

    /// Starts (or restarts) the path at `alpha` with the fixed-α solver, from `guess`
    /// (`(λν, λt)`, 2p values) or from zero forces. Clears events and pieces.
    /// The problem at one α can have several solutions (large friction, a path that folds
    /// back over `alpha`); the solver returns one, and which one can depend on rounding. A
    /// `guess` that already solves the problem (to 1e-12 relative) is kept: the path starts
    /// from that solution. Pass a known one to trace from it.
    /// When several pieces leave the start point toward `alpha_end`, the path takes the
    /// first and [`Path::branches`] lists them all (see [`Path::choose_branch`]). When the
    /// start lies on a vertical piece (a continuum at this α), the path follows the way
    /// along it that leads toward `alpha_end` (tried by stepping along each; events met on
    /// the way are the path's own).
    /// Where the problem is carried beyond double ([`Problem::extended_precision`]), a
    /// stage of the fixed-α solver that stalls has its last iterate solved again on its
    /// piece in double-double until the classes settle (an exact solution of `H = 0` to
    /// that precision, reached where no double iterate reaches 1e-12 on an ill-conditioned W).
    /// Where the fixed-α solver fails at `alpha` (every stage but its long runs, the
    /// 20,000 Gauss–Seidel sweeps and the restarts), the start is reached from zero load:
    /// the path of the same problem under the load `τ f(alpha)` is traced from τ = 0 (zero
    /// forces, where every gap is ≥ 0) to τ = 1, through its folds, and its point at τ = 1
    /// is the start; where that path does not get there (it cannot leave τ = 0 where every
    /// gap is zero), the same ray from a load that holds every node open at τ = 0 (on the
    /// equilibrated W in double; its point at τ = 1 is the start's guess).
    /// Where that fails too, every stage of the solver runs at `alpha`, and where that
    /// fails, it solves at a nearby α instead (1e-3, 1e-2, 1e-1 of the window's length
    /// away, or of 1e3 times the load's own α scale at `alpha`, `max(‖q‖∞ / ‖q'‖∞,
    /// |alpha − alpha_start|)`, where that is shorter, toward `alpha_end` first) and
    /// traces the path from there back to `alpha`: its point there is the start.
    /// [`Path::start_route`] says which of these reached the start.
    /// Errors: `alpha` outside the window, guess of wrong length or non-finite, the solve
    /// fails (also from every nearby α and from zero load), the load fails, no piece
    /// leaves the start point toward `alpha_end`.
    pub fn start(&mut self, alpha: f64, guess: Option<&[f64]>) -> Result<()> {
        // The rays before the solver's long runs and the nearby α: where those fail, they
        // cost far more than the rays (each nearby α is a solve of its own; see
        // `start_from_zero_load`). Where the rays fail, every stage of the solver runs
        // (the first ones again), then the nearby α.
        let r = match self.start_solved(alpha, guess, Stages::NoLongRuns) {
            Err(Error::SolveFailed { message, .. }) => self.start_from_zero_load(alpha, message),
            r => r.map(|()| StartRoute::Solved),
        };
        let r = match r {
            Err(Error::SolveFailed { message, .. }) => {
                match self.start_solved(alpha, guess, Stages::All) {
                    Err(Error::SolveFailed { message: all, .. }) => Err(Error::SolveFailed {
                        alpha,
                        message: format!("{message}; every stage of the solver: {all}"),
                    }),
                    r => r.map(|()| StartRoute::Solved),
                }
            }
            r => r,
        };
        let route = match r {
            Err(Error::SolveFailed { message, .. }) => self
                .start_from_nearby(alpha, message)
                .map(|()| StartRoute::Nearby)?,
            r => r?,
        };
        if let Some(tr) = self.trace.as_mut() {
            tr.route = route;
        }
        Ok(())
    }

    /// The fixed-α solver's first fallback where it fails at `alpha`. It can fail near
    /// `alpha` as well: on a body in a corner (p = 35, F = 5) and on a curved foundation
    /// (p = 24, F = 5) every stage stalled at α = 4 (residuals 2e-4 to 9e-2) and at every
    /// nearby α, while the path of the load `τ f(4)` from τ = 0 reached τ = 1 in 9 and 13
    /// transitions (two folds each). And a nearby α is a solve of its own, which costs as
    /// much as the one that failed where it fails too: on a strip with p = 1500 and
    /// F = 5 (`fe_strip` seed 3 of the tests, 1500 × 2 elements) every stage failed at
    /// α = −2 in 64 s and at three nearby α in 54–64 s each, while this ray reached the
    /// start in 1.3 s (59 transitions); of the 64 s at α = −2, the solver's long runs
    /// (20,000 Gauss–Seidel sweeps and the restarts) took 29 s. So the rays come before
    /// those long runs, and the nearby α after them.
    /// At τ = 0 the load is zero, and where every gap is ≥ 0 the forces are zero: a start
    /// the solver finds at once, and the only solution there (with no load, forces that
    /// satisfy the contact and friction conditions do no positive work, `λᵀ W λ ≤ 0`, and
    /// W is positive definite). The path cannot come back to τ = 0 through another
    /// solution, and the solutions stay bounded, so (barring a bifurcation on the way) it
    /// reaches τ = 1, where its point solves the problem at `alpha`; that point is the
    /// start's guess (kept by the solver as it solves the problem). The ray's path is a
    /// path of its own (an affine load `0 + τ f(alpha)`, window [0, 1], this path's other
    /// options); its events are dropped. Where it does not reach τ = 1, the ray from every
    /// node open ([`Self::ray_from_open`]); where neither does: `SolveFailed` with `failed`
    /// and where each ended. Ok: which ray reached the start.
    fn start_from_zero_load(&mut self, alpha: f64, failed: String) -> Result<StartRoute> {
        #[cfg(test)]
        if tests::REFUSE_RAYS.get() {
            return Err(Error::SolveFailed {
                alpha,
                message: format!("{failed}; the rays refused by the test switch"),
            });
        }
        let f = self.load.force(alpha)?;
        let ray = Load::affine(vec![0.0; f.len()], f)?;
        let end = match self.ray_end(self.problem.clone(), ray)? {
            Ok(lam) => Ok((lam, StartRoute::ZeroLoad)),
            Err(why) => match self.ray_from_open(alpha) {
                Ok(lam) => Ok((lam, StartRoute::Open)),
                Err(why2) => Err(format!(
                    "{why}; the path from every node open, on W in double, did not reach it either: {why2}"
                )),
            },
        };
        match end {
            Ok((lam, route)) => self
                .start_solved(alpha, Some(&lam), Stages::All)
                .map(|()| route),
            Err(why) => Err(Error::SolveFailed {
                alpha,
                message: format!(
                    "{failed}; the path from zero load, tau f(alpha) for tau from 0 to 1, did not reach it: {why}"
                ),
            }),
        }
    }

    /// The ray of [`Self::start_from_zero_load`] where its own start fails: where every
    /// gap is zero, zero load puts every node at the vertex of its cone (zero force and
    /// zero gap), and no piece may leave that point (on a body in a corner, p = 24, F = 5,
    /// α = 20, the directional problem of 24 nodes at once found none). This ray starts
    /// with every node open instead: on the equilibrated problem (W, gaps and friction of
    /// the internal rows, in double), the condensed load `(1 − τ) q_open + τ q(alpha)`,
    /// where `q_open` pulls every node away from contact (`q_open,ν = −s + min(0, g)`,
    /// s = max(‖q(alpha)‖∞, ‖g‖∞), tangential rows 0: at zero forces `d_ν = −s − max(0, g)
    /// ≤ −s` at every node, so the forces are zero at τ = 0 and no node is at a vertex;
    /// that solution is the only one there, as at zero load). Its point at
    /// τ = 1 solves the problem at `alpha` (to W's rounding in double), in the caller's
    /// units. Err: why it did not get there.
    fn ray_from_open(&mut self, alpha: f64) -> std::result::Result<Vec<f64>, String> {
        let p = self.problem.p();
        let (q, _) = self
            .load
            .q(alpha, self.problem.delassus())
            .map_err(|e| e.to_string())?;
        let g = self.problem.gap_equilibrated().to_vec();
        let s = inf_norm(&q).max(inf_norm(&g));
        let s = if s > 0.0 && s.is_finite() { s } else { 1.0 };
        let open: Vec<f64> = (0..2 * p)
            .map(|k| if k < p { -s + g[k].min(0.0) } else { 0.0 })
            .collect();
        let rise: Vec<f64> = q.iter().zip(&open).map(|(a, b)| a - b).collect();
        let copy = crate::ProblemBuilder::condensed(self.problem.delassus().w().to_owned())
            .friction(self.problem.friction_equilibrated().to_vec())
            .gap(g)
            .extended_precision(crate::ExtendedPrecision::Off)
            .threads(self.problem.threads())
            .build()
            .map_err(|e| e.to_string())?;
        let ray = Load::affine(open, rise).map_err(|e| e.to_string())?;
        let lam = self
            .ray_end(Arc::new(copy), ray)
            .map_err(|e| e.to_string())??;
        Ok(self.lam_to_user(&lam))
    }

    /// The point at τ = 1 (forces in `problem`'s units) of the path of `problem` under
    /// `ray` from τ = 0 to 1 (a window of its own, this path's other options; its events
    /// are dropped), or why it did not get there. Errors: the host's load failed (its
    /// error, not the solver's), the path cannot be made.
    fn ray_end(
        &self,
        problem: Arc<Problem>,
        ray: Load,
    ) -> Result<std::result::Result<Vec<f64>, String>> {
        let opts = PathOptions {
            alpha_start: 0.0,
            alpha_end: 1.0,
            max_alpha_step: None,
            ..self.opts.clone()
        };
        let mut sub = Path::new(problem, ray, opts)?;
        let run = sub
            .start_solved(0.0, None, Stages::All)
            .and_then(|_| sub.run());
        Ok(match run {
            Ok(EndReason::Window) => match sub.pieces().last() {
                Some(pc) if pc.alpha_to == 1.0 => Ok(pc.lambda_to.clone()),
                Some(pc) => Err(format!("it came back to tau = {:e}", pc.alpha_to)),
                None => Err("it traced no piece".to_string()),
            },
            Ok(r) => Err(format!("it ended ({})", r.name())),
            Err(e @ Error::Load { .. }) => return Err(e),
            Err(e) => Err(e.to_string()),
        })
    }

    /// The last fallback of [`Self::start`], where the fixed-α solver and the rays of
    /// [`Self::start_from_zero_load`] fail. The solver can stall where the problem has a
    /// regular solution: on a slender strip (400 × 4 elements on 10 × 0.1, F = 5, in
    /// double) every stage failed at α = −2 and on 1e-3 around it, while at α = −1.996 it
    /// converged and the path from there reached −2 on the same piece (the ray from zero
    /// load reaches that start too, and comes first now). Here the start is solved at
    /// α ± δ (δ = 1e-3, 1e-2, 1e-1 of the window's length, or of the shorter
    /// [`Self::load_span`] at α: a window with a far end, [−2, 1e12], probed 1e9 away and
    /// failed; toward `alpha_end` first, inside the window) and the path traced from there
    /// to α (a window of its own; its events are dropped); the point it reaches is the
    /// start's guess, kept by the solver as it solves the problem. Where none leads to α:
    /// `SolveFailed` with the message `failed` (the solver's at α and the rays') and what
    /// the nearby starts reached.
    fn start_from_nearby(&mut self, alpha: f64, failed: String) -> Result<()> {
        let opts = self.opts.clone();
        let (lo, hi) = self.window();
        let toward = if opts.alpha_end >= alpha { 1.0 } else { -1.0 };
        let mut tried = Vec::new();
        let mut reached = None;
        let m = 2 * self.problem.p();
        let span = match self.point_at(vec![0.0; m], alpha) {
            Ok(pt) => self.load_span(&pt, FAR_WINDOW, self.opts.alpha_start),
            Err(_) => hi - lo,
        };
        'nearby: for frac in [1e-3, 1e-2, 1e-1] {
            for side in [toward, -toward] {
                let a1 = (alpha + side * frac * span).clamp(lo, hi);
                if a1 == alpha {
                    continue;
                }
                self.opts.alpha_start = a1;
                self.opts.alpha_end = alpha;
                let run = self
                    .start_solved(a1, None, Stages::All)
                    .and_then(|_| self.run());
                let end = self
                    .pieces()
                    .last()
                    .filter(|p| p.alpha_to == alpha)
                    .map(|p| p.lambda_to.clone());
                self.opts = opts.clone();
                match (run, end) {
                    (Ok(EndReason::Window), Some(lam)) => {
                        reached = Some(Ok(lam));
                        break 'nearby;
                    }
                    // The host's load failed: its error, not the solver's.
                    (Err(e @ Error::Load { .. }), _) => {
                        reached = Some(Err(e));
                        break 'nearby;
                    }
                    (Ok(r), _) => tried.push(format!("from alpha = {a1:e}: ended ({})", r.name())),
                    (Err(e), _) => tried.push(format!("from alpha = {a1:e}: {e}")),
                }
            }
        }
        // The thresholds of a general load depend on the window's length; nothing of the
        // probes stays with the path.
        self.tol_cache.clear();
        self.scale_cache.clear();
        self.trace = None;
        match reached {
            Some(lam) => self.start_solved(alpha, Some(&lam?), Stages::All),
            None => Err(Error::SolveFailed {
                alpha,
                message: format!(
                    "{failed}; no path from a nearby alpha reached it ({})",
                    tried.join("; ")
                ),
            }),
        }
    }

    /// [`Self::start`] with the fixed-α solver at `alpha` only.
    fn start_solved(&mut self, alpha: f64, guess: Option<&[f64]>, stages: Stages) -> Result<()> {
        let _pool = self.pool_scope();
        self.trace = None;
        // A path's numbers depend on its own history only: no factorisation from an
        // earlier start is reused.
        *self.updater.borrow_mut() = None;
        self.graph_step.set(None);
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
        let qg = shift_gap(&pt.q, self.problem.gap_equilibrated());
        let guess = guess.map(|g| self.lam_to_internal(g));
        // (In double `start_on_its_piece` declines at once: no polish.)
        let problem = Arc::clone(&self.problem);
        let mut polish = |lam: &[f64]| {
            let iterate = Point {
                lam: lam.to_vec(),
                ..pt.clone()
            };
            self.start_on_its_piece(&iterate, &qg, ITERATE_REFINE_ROUNDS)
                .map(|(lam, _)| lam)
        };
        #[cfg(test)]
        if guess.is_none()
            && tests::REFUSE_START_AT
                .get()
                .is_some_and(|(a, long)| a == alpha && (long || stages != Stages::All))
        {
            return Err(Error::SolveFailed {
                alpha,
                message: "refused by the test switch".to_string(),
            });
        }
        let lam = solve_fixed_alpha(
            &problem,
            &qg,
            guess.as_deref(),
            alpha,
            stages,
            Some(&mut polish),
        )?;
        let mut pt = Point { lam, ..pt };
        let mut tol = self.tol_at(&pt);
        let p = self.problem.p();
        let mut fixed = vec![Class::Open; p];
        let mut nodes = Vec::new();
        let every: Vec<usize> = (0..p).collect();
        let mut all = self.compatible(&every, &pt, &tol);
        // The fixed-α solver's point is accurate to its residual (1e-12 of each node's
        // scale) only: on an ill-conditioned W a row whose terms are small can miss its
        // threshold by that (a stick node's dt at 8.8e-14 against 7.6e-14, κ(W) = 1.2e6),
        // and where κ(W) ε is large the point is off by that, so that its classes are not
        // the solution's (κ(W) = 8e11: a node stuck at the double point whose solution
        // slips; the start on that piece, refined, lay outside its cone by 1.6e-3 of
        // max|λ|, with a residual of 8e-7). In extended precision the point is therefore
        // always solved again on its piece from the data, in double-double, until its
        // classes are those of the refined point.
        let mut refined_classes = None;
        if let Some((lam, classes)) = self.start_on_its_piece(&pt, &qg, START_REFINE_ROUNDS) {
            pt.lam = lam;
            tol = self.tol_at(&pt);
            all = self.compatible(&every, &pt, &tol);
            refined_classes = Some(classes);
        }
        for (i, comp) in all.into_iter().enumerate() {
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
        let cands =
            self.continuations_either(&pt, &fixed, &nodes, None, &mut Vec::new(), Widen::USUAL);
        self.directional_warm.borrow_mut().clear();
        let mut cands = cands?;
        let ms = 2 * p;
        let mut toward: Vec<usize> = (0..cands.len())
            .filter(|&k| cands[k].direction() == want)
            .collect();
        // In extended precision a piece leaving the point toward alpha_end must pass
        // through it in double-double too. Its degenerate nodes are found with the
        // thresholds of double, which on an ill-conditioned W (κ = 8e11) let a slipping
        // node's small dt count as zero: the path began to stick there, on a piece that
        // lies 1.6e-3 of max|λ| away (its cone crossed by that), and the node's own
        // transition, slip to stick 5.7e-4 further in α, was never reported. Where no
        // candidate passes, or none leaves toward alpha_end at all, the refined point's
        // own piece leaves it where it is interior: the thresholds of double took an open
        // node whose refined gap was 1e-11, 20 times below its threshold, for one at
        // zero, and offered only the piece leaving the other way (a 2001 × 3 node strip,
        // κ(W) = 2.7e12, started at α = −1.6 toward −2).
        if self.problem.extended_precision() {
            let offered = !toward.is_empty();
            toward.retain(|&k| self.passes_through(&pt, &cands[k]));
            if toward.is_empty() {
                let interior = refined_classes
                    .as_deref()
                    .and_then(|classes| self.interior_candidate(&pt, classes, want));
                match interior {
                    Some(cand) => {
                        cands = vec![cand];
                        toward = vec![0];
                    }
                    None if offered => {
                        return Err(Error::Numerical(format!(
                            "no piece leaves the start point alpha = {alpha} toward alpha_end = {} \
                             in double-double (each candidate of double precision lies off it)",
                            self.opts.alpha_end
                        )));
                    }
                    None => {}
                }
            }
        }
        if let Some(&k) = toward.first() {
            self.begin(&pt, cands[k].clone(), want)?;
            if toward.len() > 1 {
                // Several pieces leave the start point toward alpha_end: a bifurcation at
                // the start. The path takes the first; `branches` lists them all and
                // `choose_branch` (directly after the start) takes another.
                let cands: Vec<Candidate> = toward.iter().map(|&k| cands[k].clone()).collect();
                self.offer_start_branches(pt, cands);
            }
            return Ok(());
        }
        let verticals: Vec<usize> = (0..cands.len())
            .filter(|&k| cands[k].direction() == 0)
            .collect();
        let Some(&first) = verticals.first() else {
            return Err(Error::Numerical(format!(
                "no piece leaves the start point alpha = {alpha} toward alpha_end = {}{}",
                self.opts.alpha_end,
                near_overflow(&pt)
            )));
        };
        // The start lies on a vertical piece (a continuum at this α): which way along it
        // leads toward alpha_end shows only where the path leaves it. Follow each way to
        // the first piece that moves α, and keep the one that moves it toward alpha_end.
        for &k in &verticals {
            self.begin_afresh(&pt, cands[k].clone(), want)?;
            for _ in 0..16 {
                match self.step() {
                    Ok(StepOutcome::Transition { .. }) => {
                        let cur = &self.trace.as_ref().expect("started").cur;
                        if !cur.scales.is_vertical(&cur.t) {
                            if sign(cur.t[ms]) == want {
                                return Ok(());
                            }
                            break;
                        }
                    }
                    Ok(StepOutcome::End(_)) | Err(_) => break,
                }
            }
        }
        self.begin_afresh(&pt, cands[first].clone(), want)
    }

    /// [`Self::begin`] with no factorisation kept from what the path did before (a probe
    /// along another way, another branch).
    fn begin_afresh(&mut self, pt: &Point, cand: Candidate, want: i8) -> Result<()> {
        *self.updater.borrow_mut() = None;
        self.begin(pt, cand, want)
    }

    /// The fixed-α solver's point `pt` (`qg = q(α) − (g, 0)`) solved again on the piece
    /// of its projection classes and refined in double-double, until the refined point's
    /// projection classes are those of the piece it was solved on (at most
    /// [`START_REFINE_ROUNDS`] pieces: an active-set iteration in double-double); its d
    /// kept for [`Self::gaps`]. None in double, on a vertical piece, or when a refinement
    /// fails or the classes do not settle.
    fn start_on_its_piece(
        &mut self,
        pt: &Point,
        qg: &[f64],
        rounds: usize,
    ) -> Option<(Vec<f64>, Vec<Class>)> {
        if !self.problem.extended_precision() {
            return None;
        }
        let mut cur = pt.clone();
        let mut d = crate::piece::displacement_gaps(self.problem.delassus().w(), qg, &pt.lam);
        let mut classes = crate::solve::active_classes(&self.consts(), &cur.lam, &d, None);
        let mut seen = Vec::new();
        for round in 0..rounds {
            let piece = self.tangent(&classes, &cur, self.force_scale(&cur))?;
            if piece.scales.is_vertical(&piece.t) {
                return None;
            }
            // From a point far from the piece's solution the refinement's first correction
            // is too large to trust, and it fails (after a fresh O(m³) LU of the piece, its
            // last resort): it starts from the piece's own solution in double instead. The
            // first round tries the point itself first (the solver's solution, or its
            // stalled iterate); later rounds start from the piece's own solution (the point
            // is the last piece's, off this one in every node whose class changed: on a
            // 1500 × 2 strip, F = 1, each of 83 rounds paid for one, 0.5 s at m = 3000).
            let own = |this: &mut Self| {
                let rhs = this.consts().piece_rhs(&classes, qg);
                let (x, _) = this.piece_solve(&classes, piece.lu.updated(), &rhs);
                this.polish_point(&classes, &piece.lu, cur.alpha, &x)
            };
            let polished = if round == 0 {
                self.polish_point(&classes, &piece.lu, cur.alpha, &cur.lam)
                    .or_else(|| own(self))
            } else {
                own(self).or_else(|| self.polish_point(&classes, &piece.lu, cur.alpha, &cur.lam))
            };
            let (lam, d_new) = polished?;
            (cur.lam, d) = (lam, d_new);
            let next = crate::solve::active_classes(&self.consts(), &cur.lam, &d, None);
            if next == classes {
                self.prime_gaps(cur.alpha, &cur.lam, d);
                return Some((cur.lam, classes));
            }
            // A piece's refined solution does not depend on where its refinement started,
            // so classes seen before begin a cycle, and the rounds left would repeat it (on
            // the same strip, the second of three stalled iterates alternated between two
            // sets of classes for 38 of its 40 rounds).
            seen.push(std::mem::replace(&mut classes, next));
            if seen.contains(&classes) {
                return None;
            }
        }
        None
    }

    /// The piece `classes` leaving `pt` toward `want` (the sign of α's way), where `pt` is
    /// inside its region: every guard strictly positive (in extended precision, from the
    /// refined point's d). None on a vertical piece, a singular one, or a guard at zero or
    /// below.
    fn interior_candidate(&mut self, pt: &Point, classes: &[Class], want: i8) -> Option<Candidate> {
        if self
            .guard_table(classes, pt, None)
            .iter()
            .any(|g| g.value <= 0.0 || g.value.is_nan())
        {
            return None;
        }
        let PieceTangent {
            t,
            lu,
            scales,
            orientation,
            rate,
            xp,
        } = self.tangent(classes, pt, self.force_scale(pt))?;
        if scales.is_vertical(&t) {
            return None;
        }
        let s = if sign(t[t.len() - 1]) == want {
            1.0
        } else {
            -1.0
        };
        Some(Candidate::along(
            classes,
            s,
            (&Arc::new(lu), orientation, scales),
            (&t, &Arc::new(rate)),
            xp.map(Arc::new),
        ))
    }

    /// Whether candidate `cand`'s piece passes through the start point `pt` in
    /// double-double: its point at `pt`'s α refined from `pt` still has every node in its
    /// class (to the point's thresholds). True where there is no refinement (a vertical
    /// piece, a refinement that fails): [`Self::begin`] then keeps `pt` itself. (In double,
    /// [`Self::passes_through_at`]'s point solved from the data; the start asks in extended
    /// precision only.)
    fn passes_through(&mut self, pt: &Point, cand: &Candidate) -> bool {
        let tol = self.tol_at(pt);
        self.passes_through_at(pt, cand, &tol)
    }

    /// Whether candidate `cand`'s own point at `pt`'s α fits its classes to `tol`: in
    /// extended precision refined from `pt` in double-double ([`Self::passes_through`]); in
    /// double solved from the data with its updated factorisation (`xp`, one product with
    /// W for its gaps). True where there is none (a full-pivoting solver in double, a
    /// vertical piece, a refinement that fails).
    fn passes_through_at(&mut self, pt: &Point, cand: &Candidate, tol: &Tol) -> bool {
        if cand.scales.is_vertical(&cand.t) {
            return true;
        }
        let own = if self.problem.extended_precision() {
            self.polish_point(&cand.classes, &cand.lu, pt.alpha, &pt.lam)
        } else {
            cand.xp.as_ref().map(|xp| {
                let at = Point {
                    lam: xp.to_vec(),
                    ..pt.clone()
                };
                let d = self.gaps(&at).to_vec();
                (at.lam, d)
            })
        };
        let Some((lam, d)) = own else {
            return true;
        };
        (0..cand.classes.len()).all(|i| {
            self.compatible_at(i, &lam, &d, tol)
                .contains(&cand.classes[i])
        })
    }

    /// Starts the trace at `pt` on candidate `cand` (`want`: the sign of α's way toward
    /// alpha_end).
    fn begin(&mut self, pt: &Point, cand: Candidate, want: i8) -> Result<()> {
        let alpha = pt.alpha;
        let mut pt = pt.clone();
        // On a graph piece of a problem carried beyond double, the start point too is
        // refined in double-double (from the fixed-α solve's point).
        if !cand.scales.is_vertical(&cand.t)
            && let Some((lam, _)) = self.polish_point(&cand.classes, &cand.lu, alpha, &pt.lam)
        {
            pt.lam = lam;
        }
        self.consts()
            .satisfy_local(&cand.classes, &cand.classes, &mut pt.lam);
        self.commit_solver(&cand.lu);
        let start = StartPoint {
            alpha,
            lam: pt.lam.clone(),
            classes: cand.classes.clone(),
            load: self.load.snapshot(alpha)?,
        };
        let dir = cand.direction();
        let piece = PieceRecord {
            classes: cand.classes.clone(),
            alpha_from: alpha,
            alpha_to: alpha,
            lambda_from: self.lam_to_user(&pt.lam),
            lambda_to: self.lam_to_user(&pt.lam),
            direction: dir,
            orientation: cand.orientation,
            det_sign: cand.det_sign,
        };
        self.trace = Some(Trace {
            start,
            route: StartRoute::Solved,
            events: Vec::new(),
            event_loads: Vec::new(),
            pieces: vec![piece],
            entries: vec![PieceEntry {
                classes: cand.classes.clone(),
                lam: pt.lam.clone(),
                alpha,
            }],
            entry_index: [(classes_hash(&cand.classes), vec![0])].into(),
            cur: CurrentPiece {
                classes: cand.classes,
                lam: pt.lam,
                alpha,
                t: cand.t,
                lu: cand.lu,
                scales: cand.scales,
                rate: cand.rate,
                xp: cand.xp,
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
    /// (likewise). A basis or general load that fails ahead of the path is approached by
    /// shorter steps: the transitions before the failure are reported first, and the
    /// error comes where the path reaches the failure (to within 1e-12 of the window's
    /// length).
    pub fn step(&mut self) -> Result<StepOutcome> {
        let _pool = self.pool_scope();
        let tr = self.trace_ref()?;
        match &tr.end {
            Some(EndReason::Stopped) => self.trace.as_mut().expect("started").end = None,
            Some(r) => return Ok(StepOutcome::End(r.clone())),
            None => {}
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
        self.refined = None;
        let vertical = cur.scales.is_vertical(&cur.t);
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
        let user = self.lam_to_user(&pt.lam);
        let tr = self.trace.as_mut().expect("started");
        let last = tr.pieces.last_mut().expect("one piece");
        last.alpha_to = pt.alpha;
        last.lambda_to = user;
    }

    /// Ends a started path that has not ended with [`EndReason::Stopped`] and returns true
    /// (false, changing nothing, when it is not started or has ended). What was traced is
    /// kept; [`Path::step`] continues from where it stopped. This is what a monitor's stop
    /// does; a host that steps by itself may use it to mark why it stopped.
    pub fn stop(&mut self) -> bool {
        match self.trace.as_mut() {
            Some(tr) if tr.end.is_none() => {
                tr.end = Some(EndReason::Stopped);
                true
            }
            _ => false,
        }
    }

    /// The progress after the last transition point (None before the first one).
    pub fn progress(&self) -> Option<Progress> {
        let tr = self.trace.as_ref()?;
        let last = tr.events.last()?;
        let first = tr
            .events
            .iter()
            .rposition(|e| e.transition != last.transition)
            .map_or(0, |k| k + 1);
        let (a0, a1) = (self.opts.alpha_start, self.opts.alpha_end);
        Some(Progress {
            alpha: last.alpha,
            transitions: tr.transitions,
            events: first..tr.events.len(),
            fraction: (last.alpha - a0) / (a1 - a0),
        })
    }

    /// Steps until the path ends; returns why. Errors: those of [`Path::step`].
    pub fn run(&mut self) -> Result<EndReason> {
        self.run_monitored(|_, _| std::ops::ControlFlow::Continue(()))
    }

    /// Steps until the path ends, calling `monitor` after each transition point with the
    /// path (to read the new events) and the [`Progress`]. Returning
    /// `ControlFlow::Break(())` ends the path with [`EndReason::Stopped`], keeping
    /// everything traced; stepping or running it again continues from there. Returns why
    /// the path ended. Errors: those of [`Path::step`].
    pub fn run_monitored(
        &mut self,
        mut monitor: impl FnMut(&Path, &Progress) -> std::ops::ControlFlow<()>,
    ) -> Result<EndReason> {
        let _pool = self.pool_scope();
        loop {
            match self.step()? {
                StepOutcome::End(r) => return Ok(r),
                StepOutcome::Transition { .. } => {
                    let progress = self.progress().expect("a transition was just passed");
                    if monitor(self, &progress).is_break() && self.stop() {
                        return Ok(EndReason::Stopped);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CsrMatrix, ProblemBuilder, Storage};

    thread_local! {
        /// Test switch: the fixed-α solver fails at this α when started without a guess,
        /// as where every stage stalls at the start's α but not near it; with `false`, the
        /// long runs of `Stages::All` succeed (as where only they reach a solution).
        pub(super) static REFUSE_START_AT: std::cell::Cell<Option<(f64, bool)>> =
            const { std::cell::Cell::new(None) };
        /// Test switch: the rays of `start_from_zero_load` fail at once.
        pub(super) static REFUSE_RAYS: std::cell::Cell<bool> =
            const { std::cell::Cell::new(false) };
    }

    /// The block on a foundation of the tests below: A = diag(2, 1), N = [1, 0],
    /// T = [0, 1], F = 1/2, with the gap `gap`.
    fn block(gap: f64) -> Arc<Problem> {
        let csr = |r, c, v: &[f64]| CsrMatrix::from_dense(r, c, v).unwrap();
        Arc::new(
            ProblemBuilder::new(
                csr(2, 2, &[2.0, 0.0, 0.0, 1.0]),
                Storage::Full,
                csr(1, 2, &[1.0, 0.0]),
                csr(1, 2, &[0.0, 1.0]),
            )
            .friction_uniform(0.5)
            .gap(vec![gap])
            .build()
            .unwrap(),
        )
    }

    /// The block of the next test with a gap of 0.1 under the load ray f(α) = α (1, 1/4),
    /// as `start_from_zero_load` traces it: at α = 0 the load and the forces are zero and
    /// the node is open; its piece's tangent is λ' = 0 (t = (0, 0, t_α), t_α > 0). The
    /// force scale there is its floor, 1e-300, and (1/A)² overflowed in the tangent's norm:
    /// it came from a full-pivoting LU of the whole Jacobian instead of the updated
    /// factorisation (15 s of the 22 s ray at p = 1500). By hand, u₁ = α/2 reaches the gap
    /// at α = 0.2, where u₂ = α/4 > 0: the node slips (λν = 0.2 − α, λt = F λν) until
    /// u₂ = α/4 + λt = 0.1 − α/4 reaches 0 at α = 0.4, and sticks from there on
    /// (λ = (0.2 − α, −α/4), within the cone).
    #[test]
    fn the_tangent_at_zero_load_comes_from_the_updated_factorisation() {
        let problem = block(0.1);
        let load = Load::affine(vec![0.0, 0.0], vec![1.0, 0.25]).unwrap();
        let mut path = Path::new(problem, load, PathOptions::window(0.0, 1.0)).unwrap();
        path.start(0.0, None).unwrap();
        assert_eq!(path.start_route(), Some(StartRoute::Solved));
        let pt = path.point_at(vec![0.0; 2], 0.0).unwrap();
        let scale = path.force_scale(&pt);
        assert_eq!(scale, 1e-300);
        let tan = path.tangent(&[Class::Open], &pt, scale).unwrap();
        assert!(
            matches!(tan.lu, PieceSolver::Updated(_)),
            "a full-pivoting LU"
        );
        assert!(
            tan.t[0] == 0.0 && tan.t[1] == 0.0 && tan.t[2] > 0.0 && tan.t[2].is_finite(),
            "t = {:?}",
            tan.t
        );
        assert_eq!(path.run().unwrap(), EndReason::Window);
        let ev = path.events();
        assert_eq!(ev.len(), 2, "{ev:?}");
        for (e, (alpha, from, to)) in ev.iter().zip([
            (0.2, Class::Open, Class::SlipPlus),
            (0.4, Class::SlipPlus, Class::Stick),
        ]) {
            assert!((e.alpha - alpha).abs() <= 1e-15, "{e:?}");
            assert_eq!((e.from, e.to), (from, to));
        }
    }

    /// The block on a foundation, solved by hand: A = diag(2, 1), N = [1, 0], T = [0, 1],
    /// F = 1/2, gap 0, f(α) = (1, 0) + α (0, 1). At α ∈ [0, 1/2] the node sticks with
    /// λ = (−1, −α); it slips in +t from α = 1/2 (λt reaches F λν = −1/2). Started at
    /// α = 1/4: where the solver fails there, the start comes from the ray `τ f(1/4)` from
    /// zero load (along which the node sticks, λ = −τ (1, 1/4), from τ = 0 on), also where
    /// the solver's long runs would solve it (they come after the rays); where the rays
    /// fail, from those long runs, and where they fail too, from a nearby α. Each says so;
    /// the same start and event.
    #[test]
    fn a_start_the_solver_misses_comes_from_a_ray_or_a_nearby_alpha_and_says_so() {
        let problem = block(0.0);
        for (refuse, rays, route) in [
            (None, true, StartRoute::Solved),
            (Some((0.25, false)), false, StartRoute::ZeroLoad),
            (Some((0.25, false)), true, StartRoute::Solved),
            (Some((0.25, true)), true, StartRoute::Nearby),
        ] {
            let load = Load::affine(vec![1.0, 0.0], vec![0.0, 1.0]).unwrap();
            let mut path =
                Path::new(problem.clone(), load, PathOptions::window(0.25, 2.0)).unwrap();
            REFUSE_START_AT.set(refuse);
            REFUSE_RAYS.set(rays);
            let started = path.start(0.25, None);
            REFUSE_START_AT.set(None);
            REFUSE_RAYS.set(false);
            started.unwrap();
            assert_eq!(path.start_route(), Some(route));
            let st = path.start_state().unwrap();
            assert!(
                st.alpha == 0.25 && st.classes == [Class::Stick],
                "{route:?}: {st:?}"
            );
            assert!(
                (st.lambda_n[0] + 1.0).abs() <= 1e-15 && (st.lambda_t[0] + 0.25).abs() <= 1e-15,
                "{route:?}: λ = ({}, {})",
                st.lambda_n[0],
                st.lambda_t[0]
            );
            assert_eq!(path.run().unwrap(), EndReason::Window);
            let ev = path.events();
            assert_eq!(ev.len(), 1, "{route:?}");
            assert!(
                (ev[0].alpha - 0.5).abs() <= 1e-15,
                "{route:?}: α = {}",
                ev[0].alpha
            );
            assert_eq!((ev[0].from, ev[0].to), (Class::Stick, Class::SlipPlus));
        }
    }
}
