//! # fricont — exact path-following for discrete 2D contact with Coulomb friction
//!
//! The library traces the solution curves of the discrete static contact problem with
//! Coulomb friction (see `SPEC.md` of the project and the founding paper of Janovský and
//! Kučera) as the load varies along a path `f(α)`, and reports every *transition point*
//! where a contact node changes between no contact, stick and slip.
//!
//! The modules follow the mathematical objects:
//!
//! | module | object |
//! |---|---|
//! | [`problem`] | the data `A`, `N`, `T`, `F`, `g`, `r` and their validation |
//! | [`condense`] | the Cholesky factor of `A` and the Delassus operator `W = B A⁻¹ Bᵀ` |
//! | [`load`] | load paths `f(α)` and their condensed images `q(α) = B A⁻¹ f(α)` |
//! | [`class`] | node classes (open, stick, slip±) |
//! | [`piece`] | smooth pieces: piece equations, guards, orientation |
//! | [`solve`] | the fixed-α solver that starts every path |
//! | [`path`] | the path tracer: stepping, events, folds, bifurcations, queries |
//!
//! Conventions (signs, units): `λν ≤ 0` is compressive; `N u ≤ g` is non-penetration;
//! `S+` slips with `T u > 0` and carries `λt = F λν`. All indices are 0-based in the Rust
//! API; reports (CLI, JSON) count nodes from 1 as the paper does.
//!
//! ## Example
//!
//! One contact node with two dofs: `A = diag(2, 1)`, normal dof 1, tangential dof 2.
//! The load `f = (1, α)` presses the node with `λν = −1` and shears it; it sticks while
//! `|λt| = |α| ≤ F |λν| = 0.5` and slips in +t beyond: one transition at α = 0.5.
//! ```
//! use std::sync::Arc;
//! use fricont::{Class, CsrMatrix, Load, Path, PathOptions, ProblemBuilder, Storage};
//! let a = CsrMatrix::from_dense(2, 2, &[2.0, 0.0, 0.0, 1.0]).unwrap();
//! let n = CsrMatrix::from_dense(1, 2, &[1.0, 0.0]).unwrap();
//! let t = CsrMatrix::from_dense(1, 2, &[0.0, 1.0]).unwrap();
//! let problem = ProblemBuilder::new(a, Storage::Full, n, t).friction_uniform(0.5).build().unwrap();
//! let load = Load::affine(vec![1.0, 0.0], vec![0.0, 1.0]).unwrap();
//! let mut path = Path::new(Arc::new(problem), load, PathOptions::window(0.0, 2.0)).unwrap();
//! path.start(0.0, None).unwrap();
//! path.run().unwrap();
//! let e = &path.events()[0];
//! assert_eq!((e.node, e.from, e.to), (0, Class::Stick, Class::SlipPlus));
//! assert!((e.alpha - 0.5).abs() < 1e-14);
//! ```

// Dense linear algebra on small index ranges reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

pub mod class;
pub mod condense;
mod dd;
mod dense;
pub mod error;
pub mod ffi;
pub mod load;
pub mod path;
pub mod piece;
pub mod problem;
pub mod solve;

pub use class::Class;
pub use condense::{HostSolve, SolveFailure, SolveFn};
pub use dense::PARALLEL_MIN_ORDER;
pub use error::{Error, Result};
/// The faer version fricont is built with (W of [`ProblemBuilder::condensed`] and the
/// blocks of a [`HostSolve`] are faer matrices).
pub use faer;
pub use load::Load;
pub use path::{
    EndReason, Event, Path, PathOptions, PieceRecord, Progress, Solution, StartRoute, StepOutcome,
};
pub use problem::{CsrMatrix, ExtendedPrecision, Problem, ProblemBuilder, Storage};
