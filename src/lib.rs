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
//! ```
//! use std::sync::Arc;
//! use fricont::{problem::{CsrMatrix, ProblemBuilder, Storage}, load::Load, path::{Path, PathOptions}};
//! // one dof pressed onto a foundation: A = [1], N = [1; 0]-like 2-dof toy
//! let a = CsrMatrix::from_dense(2, 2, &[2.0, 0.0, 0.0, 1.0]).unwrap();
//! let n = CsrMatrix::from_dense(1, 2, &[1.0, 0.0]).unwrap();
//! let t = CsrMatrix::from_dense(1, 2, &[0.0, 1.0]).unwrap();
//! let problem = Arc::new(ProblemBuilder::new(a, Storage::Full, n, t).friction_uniform(0.5).build().unwrap());
//! let load = Load::affine(vec![-1.0, 0.0], vec![0.0, 1.0]).unwrap();
//! let mut path = Path::new(problem, load, PathOptions::window(0.0, 2.0)).unwrap();
//! path.start(0.0, None).unwrap();
//! let end = path.run().unwrap();
//! assert!(path.events().len() >= 1);
//! # let _ = end;
//! ```

pub mod casestudy;
pub mod class;
pub mod condense;
pub mod error;
pub mod generator;
pub mod io;
pub mod load;
pub mod path;
pub mod piece;
pub mod problem;
pub mod solve;

pub use class::Class;
pub use error::{Error, Result};
pub use load::Load;
pub use path::{EndReason, Event, Path, PathOptions, PieceRecord, Solution, StepOutcome};
pub use problem::{CsrMatrix, Problem, ProblemBuilder, Storage};
