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
use crate::load::{BoundLoad, Load};
use crate::problem::Problem;

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
    /// Full state at the transition point (classes: those of the piece after).
    pub state: State,
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
}

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

    /// Starts (or restarts) the path at `alpha` with the fixed-α solver, from `guess`
    /// (`(λν, λt)`, 2p values) or from zero forces. Clears events and pieces.
    /// Errors: `alpha` outside the window, guess of wrong length or non-finite, the solve
    /// fails, the load fails.
    pub fn start(&mut self, alpha: f64, guess: Option<&[f64]>) -> Result<()> {
        let _ = (alpha, guess);
        todo!()
    }

    /// Advances to the next transition point or to the end of the path.
    /// Errors: not started ([`Error::Usage`]), load failure ([`Error::Load`]; the path then
    /// ends with [`EndReason::Failed`] and keeps what it traced).
    pub fn step(&mut self) -> Result<StepOutcome> {
        todo!()
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
        todo!()
    }

    /// Why the path ended, if it did.
    pub fn end_reason(&self) -> Option<&EndReason> {
        todo!()
    }

    /// The start point (after [`Path::start`]).
    pub fn start_state(&self) -> Option<&State> {
        todo!()
    }

    /// The events so far.
    pub fn events(&self) -> &[Event] {
        todo!()
    }

    /// The pieces so far (the last one is the current piece).
    pub fn pieces(&self) -> &[PieceRecord] {
        todo!()
    }

    /// The current point (u by one back-solve). Errors: not started.
    pub fn current(&mut self) -> Result<State> {
        todo!()
    }

    /// Candidate continuations at the last transition point (empty unless it was a
    /// bifurcation).
    pub fn branches(&self) -> &[Branch] {
        todo!()
    }

    /// Continue along candidate `k` of [`Path::branches`] instead of the one taken (or
    /// after the path stopped with [`EndReason::Bifurcation`]). Only allowed directly after
    /// the bifurcation step. Errors: no bifurcation pending, `k` out of range.
    pub fn choose_branch(&mut self, k: usize) -> Result<()> {
        let _ = k;
        todo!()
    }

    /// Every traced solution at `alpha`: one per traced piece whose α-range contains it
    /// (several past a fold), each by one small solve on the stored piece plus one
    /// back-solve for u. Points shared by two pieces (transition points) are reported
    /// once. Empty if the traced path never reached `alpha`. Errors: not started, load
    /// failure.
    pub fn solutions_at(&mut self, alpha: f64) -> Result<Vec<Solution>> {
        let _ = alpha;
        todo!()
    }
}
