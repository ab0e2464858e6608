//! Load paths `f(α)` (SPEC §1) and their condensed images `q(α) = B A⁻¹ f(α)` (SPEC §2).
//!
//! Three forms, from cheapest to most general:
//!
//! * [`Load::affine`]: `f(α) = f0 + α f1`. `q` is affine too: each piece of the solution
//!   curve is a straight segment and every transition is located exactly (one small
//!   linear solve per event).
//! * [`Load::basis`]: `f(α) = Σ_j φ_j(α) f_j` with the weights `φ_j` and their derivatives
//!   `φ_j'` from a closure. After one solve per basis vector, `q(α) = Σ φ_j(α) q_j` costs
//!   nothing per α.
//! * [`Load::general`]: any closure `α ↦ f(α)`, with an optional derivative closure. Each
//!   evaluation of `q` costs one back-solve with the Cholesky factor of `A`. Without a
//!   derivative, `f'(α)` is approximated by central differences with step
//!   `h = ε^{1/3} max(1, |α|)` (ε = 2.2e-16), accurate to about `1e-10` relative. The
//!   derivative is only used for step control and orientation; transition points are
//!   located by a bracketing root finder on the guards themselves, so their accuracy
//!   does not depend on it.
//!
//! Closures return `Err(LoadFailure)` to abort; a non-finite value is treated the same way.
//! Either stops the path cleanly with [`crate::Error::Load`], keeping what was traced.

use crate::condense::Delassus;
use crate::dense::{axpy, dot, inf_norm, max_abs_diff};
use crate::error::{Error, Result};

/// Why a load closure failed: the caller's own code (kept and reported) and a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadFailure {
    /// The callback's nonzero return code.
    pub code: i32,
    /// A human-readable reason.
    pub message: String,
}

/// `f(α)` into the output slice (n entries).
pub type VectorFn = Box<dyn FnMut(f64, &mut [f64]) -> std::result::Result<(), LoadFailure> + Send>;
/// Basis weights: `(α, φ_out, φ'_out)` with k entries each.
pub type WeightsFn =
    Box<dyn FnMut(f64, &mut [f64], &mut [f64]) -> std::result::Result<(), LoadFailure> + Send>;

/// A load path `α ↦ f(α) ∈ R^n`. Force units are those of `A u`.
pub enum Load {
    /// `f0 + α f1`.
    Affine {
        /// Load at α = 0.
        f0: Vec<f64>,
        /// Load per unit α.
        f1: Vec<f64>,
    },
    /// `Σ_j φ_j(α) f_j`.
    Basis {
        /// The k basis vectors, n entries each.
        vectors: Vec<Vec<f64>>,
        /// Weights and their derivatives.
        weights: WeightsFn,
    },
    /// A general closure with an optional derivative closure.
    General {
        /// Number of dofs the closure fills.
        n: usize,
        /// `f(α)`.
        f: VectorFn,
        /// `f'(α)`, if known.
        df: Option<VectorFn>,
    },
}

impl std::fmt::Debug for Load {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Load::Affine { f0, .. } => write!(f, "Load::Affine(n = {})", f0.len()),
            Load::Basis { vectors, .. } => write!(f, "Load::Basis(k = {})", vectors.len()),
            Load::General { n, df, .. } => {
                write!(f, "Load::General(n = {n}, derivative: {})", df.is_some())
            }
        }
    }
}

impl Load {
    /// `f(α) = f0 + α f1`. Errors: lengths differ, non-finite entries.
    pub fn affine(f0: Vec<f64>, f1: Vec<f64>) -> Result<Load> {
        if f0.len() != f1.len() {
            return Err(Error::Dimension(format!(
                "f0 has {} entries, f1 has {}",
                f0.len(),
                f1.len()
            )));
        }
        check_finite("f0", &f0)?;
        check_finite("f1", &f1)?;
        Ok(Load::Affine { f0, f1 })
    }

    /// `f(α) = Σ_j φ_j(α) f_j`, the weights `φ_j(α)`, `φ_j'(α)` from `weights`. Each
    /// vector is condensed once (one solve with A), and along each piece the solution is
    /// solved for once per vector, so the evaluations that locate a piece's end cost
    /// O(k p) each instead of solves with A and the piece matrix (a [`Load::general`]
    /// load). Errors: no vectors, lengths differ, non-finite entries.
    pub fn basis(vectors: Vec<Vec<f64>>, weights: WeightsFn) -> Result<Load> {
        let Some(first) = vectors.first() else {
            return Err(Error::Dimension("basis load with no vectors".into()));
        };
        let n = first.len();
        for (j, v) in vectors.iter().enumerate() {
            if v.len() != n {
                return Err(Error::Dimension(format!(
                    "basis vector {} has {} entries, vector 1 has {n}",
                    j + 1,
                    v.len()
                )));
            }
            check_finite(&format!("basis vector {}", j + 1), v)?;
        }
        Ok(Load::Basis { vectors, weights })
    }

    /// A general load `f(α)` filling `n` entries, with an optional derivative.
    ///
    /// Accuracy: fricont does not see the terms that make up `f(α)`, so it cannot tell how
    /// far rounding moves f where the load passes through (near) zero. It takes them as
    /// large as the load's change along the current piece (from the last transition point,
    /// or the start; or over the load's own α length ‖q‖/‖q'‖ where that is longer; never
    /// more than over the window; and at least over 64 roundings of α over `zero_tol`, as f
    /// computed from α is known to no better than one rounding of α, |f'| ε |α|), and a
    /// guard within their rounding is at zero. Where the load at a transition is far
    /// smaller than that change, transitions that lie closer together can be merged into
    /// one or moved, without an error: f = 1e-8 f0 + φ(α) f1 (φ = α + 0.2 sin 2α) traced
    /// from α = ±1 through φ = 0 had a wrong first transition near φ = 0 in 2 of 80 traces
    /// on finite-element meshes (none of 80 on random problems), and 1e-10 f0 + φ(α) f1
    /// wrong events on 5 of 160 traces. A basis load
    /// ([`Load::basis`]) has exact terms and traced all of them: give the load so where it
    /// is a sum of fixed vectors. On an ill-conditioned body the rounding of each entry of
    /// f(α) (ε |f|, fresh at every α) moves the solution by up to the piece's conditioning
    /// times that, also where the problem is carried in extended precision: transitions
    /// are located to that noise (slender strips with F = 5 and κ(W) ~ 1e8: f0 + φ(α) f1
    /// as a general load put its events within 7.4e-13 in φ of the affine load's). A basis
    /// load has no such noise.
    ///
    /// Cost: each evaluation calls `f` (and `df`, or `f` at α ± h for central differences)
    /// and condenses f(α) and f'(α) to the contact rows. A vector within 64 ε (2-norm,
    /// relative) of the span of the vectors condensed before is condensed as their
    /// combination, O(k n), instead of by a solve with A (exactly, for the vector moved by
    /// at most that much; checked against a solve at the 1st, 2nd, 4th, … such evaluation,
    /// and given up where they differ by more than 1e-6): a load `Σ_j φ_j(α) f_j` of a few
    /// fixed vectors costs a few dozen solves with A in all. A load that spans more than 8
    /// directions solves at every evaluation (the span holds up to 8 vectors of n values),
    /// and so does every load where W was refined
    /// ([`crate::ProblemBuilder::extended_precision`]: `Auto` refines small and
    /// ill-conditioned problems), on condensed input and for n ≤ 32. Each evaluation also
    /// solves with the current piece's matrix, O(p²), where a basis load combines
    /// per-piece solutions, O(k p).
    pub fn general(n: usize, f: VectorFn, df: Option<VectorFn>) -> Load {
        Load::General { n, f, df }
    }

    /// Number of dofs of the load vectors.
    pub fn n(&self) -> usize {
        match self {
            Load::Affine { f0, .. } => f0.len(),
            Load::Basis { vectors, .. } => vectors[0].len(),
            Load::General { n, .. } => *n,
        }
    }
}

/// The step of a general load's central differences at `alpha`, `ε^{1/3} max(1, |α|)`.
fn difference_step(alpha: f64) -> f64 {
    f64::EPSILON.cbrt() * alpha.abs().max(1.0)
}

fn check_finite(name: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(Error::NonFinite(format!(
            "{name}: entry {} is {}",
            i + 1,
            v[i]
        ))),
        None => Ok(()),
    }
}

/// The load at one α, kept with an event so that its state can be computed later without
/// calling the user's closures (a host such as MATLAB may only answer them during a
/// step).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum LoadSnapshot {
    /// Affine load: f(α) is known.
    Affine,
    /// Basis load: the weights φ_j(α).
    Weights(Vec<f64>),
    /// General load: f(α) itself (n values).
    Force(Vec<f64>),
}

/// A load bound to a problem: the condensed vectors are precomputed where possible.
pub(crate) struct BoundLoad {
    load: Load,
    /// Affine: `[q0, q1]`; basis: `q_j`; general: empty.
    q_basis: Vec<Vec<f64>>,
    /// The low parts of `q_basis` when the problem's W was refined
    /// ([`Delassus::w_lo`]): `exact(B A⁻¹ f_j) − q_basis[j]`, rounded
    /// ([`Delassus::condense_lo`]). None otherwise (and for condensed input, whose q is the
    /// caller's data, and for a general load).
    q_lo: Option<Vec<Vec<f64>>>,
    /// `‖exact(B A⁻¹ f_j) − q_j‖∞` of each vector as the solve gave it (computed on first
    /// use, see [`Self::determination`]).
    errors: std::cell::OnceCell<Option<Vec<f64>>>,
    /// The same vectors half-solved, `L⁻¹ Pᵀ f_j` (n × k), when the problem has half
    /// solves ([`Delassus::displacements`]): u at an event then costs a backward half only.
    half: Option<faer::Mat<f64>>,
    weights: Vec<f64>,
    dweights: Vec<f64>,
    /// α of `weights` (NaN before the first evaluation).
    weights_alpha: f64,
    /// The last few `(α, w(α), w'(α))` of a basis load, newest last: the term magnitudes
    /// at a point ([`Self::term_magnitude_rows`], [`Self::term_rate_rows`]) must not
    /// depend on which α was evaluated since (the tracer evaluates the entry of a piece
    /// after its exit point).
    recent_weights: Vec<(f64, Vec<f64>, Vec<f64>)>,
    /// A general load's last evaluation: the tracer often asks again at the same α (a
    /// root, then the join at it), and each evaluation costs the user's callbacks and a
    /// solve with A.
    last_general: Option<GeneralEval>,
    /// A general load's anchor `(f(α_a), q(α_a))` ([`Self::anchor_at`]).
    anchor: Option<(Vec<f64>, Vec<f64>)>,
    /// A general load's condensations so far, reused for the vectors in their span.
    span: Span,
    /// n-vectors of a general load's evaluations, reused: allocated afresh at each
    /// evaluation, vectors of a large mesh's n were paged in (and zeroed by the kernel)
    /// again and again.
    pool: Vec<Vec<f64>>,
}

/// A zeroed vector of `n` values from `pool` (or a new one).
fn take(pool: &mut Vec<Vec<f64>>, n: usize) -> Vec<f64> {
    let mut v = pool.pop().unwrap_or_default();
    v.clear();
    v.resize(n, 0.0);
    v
}

/// Returns `v` to `pool` (at most a few are kept).
fn give(pool: &mut Vec<Vec<f64>>, v: Vec<f64>) {
    if pool.len() < 6 {
        pool.push(v);
    }
}

/// Most vectors of a [`Span`]: a general load `Σ_j φ_j(α) f_j` of up to this many fixed
/// vectors is condensed by solves with A only for its first few evaluations.
const SPAN_MAX: usize = 8;

/// How far (2-norm, relative) a vector may lie off a [`Span`] and be condensed from it:
/// a few roundings, as a user's `f0 + φ(α) f1` evaluated in double is off the span of f0
/// and f1 by at most about 2 ε.
const SPAN_TOL: f64 = 64.0 * f64::EPSILON;

/// A general load's condensed vectors, reused: an orthonormal basis (2-norm) `e_j` of the
/// vectors condensed so far and their images `B A⁻¹ e_j`. A vector `v` within
/// [`SPAN_TOL`] of their span (one pass of classical Gram–Schmidt) is condensed as `Σ_j
/// (e_j · v) B A⁻¹ e_j`, O(k n) instead of a solve with A (which is most of a general
/// load's cost on a large mesh): the exact condensation of `v` perturbed by at most
/// `SPAN_TOL ‖v‖₂` (a normwise backward error, of the size of the user's rounding in
/// evaluating `f`), smooth in α where fresh solves differ by `κ(A) ε`. A vector off the
/// span adds its direction (modified Gram–Schmidt twice, one solve); past [`SPAN_MAX`]
/// directions, or where a check against a solve ([`SPAN_CHECK_TOL`]) fails, the span is
/// given up and every evaluation solves. Off for condensed input (no solves to save), where
/// W was refined (q's low parts need the solves) and for n ≤ 32.
struct Span {
    on: bool,
    basis: Vec<Vec<f64>>,
    images: Vec<Vec<f64>>,
    /// Calls served from the span alone (see [`SPAN_CHECK_TOL`]).
    served: usize,
}

/// Calls of [`Span::condense`] served from the span alone are checked against solves
/// with A (the 1st, 2nd, 4th, 8th, …: a few dozen solves in a trace of thousands of
/// evaluations): where an image differs from the solve's by more than this, relative to
/// the larger of the two (∞-norm), the span is given up. The normwise test passes a part
/// of f below 64 ε of ‖f‖₂ even where it is what reaches the contact (a load far larger
/// than the rest on dofs the contact barely feels: test
/// `a_load_mostly_off_the_contact_gives_the_span_up`, a constant load traced otherwise).
/// Solves with A differ from the span's images by about κ(A) ε, far below this.
const SPAN_CHECK_TOL: f64 = 1e-6;

impl Span {
    fn new(on: bool) -> Self {
        Span {
            on,
            basis: Vec::new(),
            images: Vec::new(),
            served: 0,
        }
    }

    /// Off for good: every evaluation solves (and the basis's memory is freed).
    fn give_up(&mut self) {
        self.on = false;
        self.basis.clear();
        self.images.clear();
    }

    /// `B A⁻¹ v` for each `(v, r)` of `vs` from the span, `r` the 2-norm that `v`'s
    /// distance from the span is measured against (`None`: `‖v‖₂`; for the difference of
    /// two evaluations, the larger of theirs, whose rounding it carries). New directions
    /// are condensed in one solve. `Ok(None)` where the span is off or given up, or a
    /// vector's norm is outside 1e-150 … 1e150 (the caller solves).
    fn condense(
        &mut self,
        del: &Delassus,
        vs: &[(&[f64], Option<f64>)],
    ) -> Result<Option<Vec<Vec<f64>>>> {
        if !self.on {
            return Ok(None);
        }
        let k0 = self.basis.len();
        let mut fresh: Vec<Vec<f64>> = Vec::new();
        let mut coeffs: Vec<Vec<f64>> = Vec::with_capacity(vs.len());
        for &(v, reference) in vs {
            // One pass for every e_j · v and v · v, one for the distance from the span
            // (classical Gram–Schmidt, its rounding k ε ‖v‖₂ below SPAN_TOL's): a vector in
            // the span is neither copied nor written.
            let (c, vv) = Fused {
                es: &self.basis,
                more: &fresh,
                v,
                c: None,
            }
            .run();
            let nv = vv.sqrt();
            if nv == 0.0 {
                coeffs.push(Vec::new());
                continue;
            }
            // (within this range no dot product over- or underflows)
            if !(nv > 1e-150 && nv < 1e150) {
                return Ok(None);
            }
            let reference = reference.unwrap_or(nv).max(nv);
            let (_, rr) = Fused {
                es: &self.basis,
                more: &fresh,
                v,
                c: Some(&c),
            }
            .run();
            if rr.sqrt() <= SPAN_TOL * reference {
                coeffs.push(c);
                continue;
            }
            // Off the span (or nearly): modified Gram–Schmidt on a copy, twice, for an
            // orthogonal new direction.
            let mut r = v.to_vec();
            let mut c = vec![0.0; k0 + fresh.len()];
            let mut off = nv;
            for _ in 0..2 {
                for (j, e) in self.basis.iter().chain(&fresh).enumerate() {
                    let cj = dot(e, &r);
                    axpy(&mut r, -cj, e);
                    c[j] += cj;
                }
                off = dot(&r, &r).sqrt();
                if off <= SPAN_TOL * reference {
                    break;
                }
            }
            if off > SPAN_TOL * reference {
                if k0 + fresh.len() == SPAN_MAX || !off.is_normal() {
                    self.give_up();
                    return Ok(None);
                }
                r.iter_mut().for_each(|x| *x /= off);
                fresh.push(r);
                c.push(off);
            }
            coeffs.push(c);
        }
        if !fresh.is_empty() {
            let cols: Vec<&[f64]> = fresh.iter().map(|e| e.as_slice()).collect();
            let images = del.condense_many(&cols)?;
            self.basis.append(&mut fresh);
            self.images.extend(images);
        }
        let m = del.w().nrows();
        let out: Vec<Vec<f64>> = coeffs
            .iter()
            .map(|c| {
                let mut q = vec![0.0; m];
                for (cj, img) in c.iter().zip(&self.images) {
                    axpy(&mut q, *cj, img);
                }
                q
            })
            .collect();
        if !out.iter().all(|q| q.iter().all(|x| x.is_finite())) {
            return Ok(None);
        }
        if k0 == self.basis.len() {
            self.served += 1;
            if self.served.is_power_of_two() {
                let cols: Vec<&[f64]> = vs.iter().map(|(v, _)| *v).collect();
                let solved = del.condense_many(&cols)?;
                let agree = out.iter().zip(&solved).all(|(a, b)| {
                    max_abs_diff(a, b) <= SPAN_CHECK_TOL * inf_norm(a).max(inf_norm(b))
                });
                if !agree {
                    self.give_up();
                    return Ok(Some(solved));
                }
            }
        }
        Ok(Some(out))
    }
}

/// One pass over `v` and the vectors `es`, then `more` (at most [`SPAN_MAX`] in all):
/// without `c`, `((e_j · v)_j, v · v)`; with `c`, `((), ‖v − Σ_j c_j e_j‖₂²)`, the
/// residual formed entry by entry and not stored. In eight lanes, compiled for the
/// machine's vector instructions by faer's dispatch (as [`crate::dense::dot`]).
struct Fused<'a> {
    es: &'a [Vec<f64>],
    more: &'a [Vec<f64>],
    v: &'a [f64],
    c: Option<&'a [f64]>,
}

impl Fused<'_> {
    fn run(self) -> (Vec<f64>, f64) {
        faer::traits::pulp::Arch::new().dispatch(self)
    }
}

impl faer::traits::pulp::WithSimd for Fused<'_> {
    type Output = (Vec<f64>, f64);
    #[inline(always)]
    fn with_simd<S: faer::traits::pulp::Simd>(self, _: S) -> (Vec<f64>, f64) {
        const L: usize = 8;
        let es: Vec<&[f64]> = self.es.iter().chain(self.more).map(|e| &e[..]).collect();
        let k = es.len().min(SPAN_MAX);
        let n = self.v.len();
        let body = n - n % L;
        let mut acc = [[0.0f64; L]; SPAN_MAX + 1];
        let fold = |a: &[f64; L]| ((a[0] + a[4]) + (a[1] + a[5])) + ((a[2] + a[6]) + (a[3] + a[7]));
        match self.c {
            None => {
                for i in (0..body).step_by(L) {
                    let v: &[f64; L] = self.v[i..i + L].try_into().expect("a lane");
                    for l in 0..L {
                        acc[SPAN_MAX][l] = v[l].mul_add(v[l], acc[SPAN_MAX][l]);
                    }
                    for (a, e) in acc.iter_mut().zip(&es[..k]) {
                        let e: &[f64; L] = e[i..i + L].try_into().expect("a lane");
                        for l in 0..L {
                            a[l] = e[l].mul_add(v[l], a[l]);
                        }
                    }
                }
                let mut out: Vec<f64> = acc[..k].iter().map(fold).collect();
                let mut vv = fold(&acc[SPAN_MAX]);
                for i in body..n {
                    vv += self.v[i] * self.v[i];
                    for (o, e) in out.iter_mut().zip(&es[..k]) {
                        *o += e[i] * self.v[i];
                    }
                }
                (out, vv)
            }
            Some(c) => {
                let k = k.min(c.len());
                let at = |i: usize| {
                    let mut r = self.v[i];
                    for (cj, e) in c[..k].iter().zip(&es[..k]) {
                        r = (-cj).mul_add(e[i], r);
                    }
                    r
                };
                for i in (0..body).step_by(L) {
                    let mut r: [f64; L] = self.v[i..i + L].try_into().expect("a lane");
                    for (cj, e) in c[..k].iter().zip(&es[..k]) {
                        let e: &[f64; L] = e[i..i + L].try_into().expect("a lane");
                        for l in 0..L {
                            r[l] = (-cj).mul_add(e[l], r[l]);
                        }
                    }
                    for l in 0..L {
                        acc[0][l] = r[l].mul_add(r[l], acc[0][l]);
                    }
                }
                let mut rr = fold(&acc[0]);
                for i in body..n {
                    rr += at(i) * at(i);
                }
                (Vec::new(), rr)
            }
        }
    }
}

/// A general load evaluated at `alpha`: `q(α)`, `q'(α)` and, where W was refined, the
/// low part of q (see [`BoundLoad::general_q_lo`]).
struct GeneralEval {
    alpha: f64,
    f: Vec<f64>,
    q: Vec<f64>,
    dq: Vec<f64>,
    q_lo: Option<Vec<f64>>,
    /// `‖exact(B A⁻¹ f(α)) − q‖∞` (computed on first use, see [`BoundLoad::determination`]).
    error: std::cell::OnceCell<Option<f64>>,
}

impl GeneralEval {
    /// How far `q` is from the exact condensation of `f`: from the low part where W was
    /// refined, else by the refinement of [`Delassus::condense_error`] (a few solves with
    /// the factor of A). None where neither is possible.
    fn error(&self, del: &Delassus) -> Option<f64> {
        *self.error.get_or_init(|| match &self.q_lo {
            Some(lo) => Some(inf_norm(lo)),
            None => del
                .condense_error(&[&self.f], &[&self.q])
                .ok()
                .flatten()
                .and_then(|mut v| v.pop())
                .map(|lo| inf_norm(&lo)),
        })
    }
}

impl BoundLoad {
    pub(crate) fn new(load: Load, del: &Delassus) -> Result<Self> {
        if load.n() != del.load_len() {
            return Err(Error::Dimension(if del.is_condensed() {
                format!(
                    "the load has {} entries; a condensed problem takes condensed loads of 2p = {} entries",
                    load.n(),
                    del.load_len()
                )
            } else {
                format!("the load has {} entries, A has n = {}", load.n(), del.n())
            }));
        }
        let vectors: Vec<&Vec<f64>> = match &load {
            Load::Affine { f0, f1 } => vec![f0, f1],
            Load::Basis { vectors, .. } => vectors.iter().collect(),
            Load::General { .. } => Vec::new(),
        };
        let k = if matches!(load, Load::Basis { .. }) {
            vectors.len()
        } else {
            0
        };
        let f: Vec<&[f64]> = vectors.iter().map(|v| v.as_slice()).collect();
        let (q_basis, half) = del.condense_many_keep_half(&f)?;
        let mut q_lo = if vectors.is_empty() {
            None
        } else {
            let q: Vec<&[f64]> = q_basis.iter().map(|v| v.as_slice()).collect();
            del.condense_lo(&f, &q)?
        };
        // With low parts, q_j becomes B A⁻¹ f_j correctly rounded (the stored q_j is
        // accurate only to ~κ(A) ε), and its low part the rest.
        // (where W was refined, the solves' errors are at hand: see `condensation_errors`)
        let errors = std::cell::OnceCell::new();
        if let Some(lo) = &q_lo {
            let _ = errors.set(Some(lo.iter().map(|l| inf_norm(l)).collect()));
        }
        let span = Span::new(
            matches!(load, Load::General { .. })
                && !del.is_condensed()
                && del.w_lo().is_none()
                && del.load_len() > 4 * SPAN_MAX,
        );
        let mut q_basis = q_basis;
        if let Some(lo) = &mut q_lo {
            for (q, l) in q_basis.iter_mut().zip(lo.iter_mut()) {
                for (a, b) in q.iter_mut().zip(l.iter_mut()) {
                    (*a, *b) = crate::dd::two_sum(*a, *b);
                }
            }
        }
        Ok(Self {
            load,
            q_basis,
            q_lo,
            errors,
            half,
            weights: vec![0.0; k],
            dweights: vec![0.0; k],
            weights_alpha: f64::NAN,
            recent_weights: Vec::new(),
            last_general: None,
            anchor: None,
            span,
            pool: Vec::new(),
        })
    }

    /// The magnitude of the terms that make up each row of `q(α)`: `Σ_j |w_j(α)| |q_j,k|`
    /// (affine: `w = (1, α)`; basis: the weights evaluated at this α, if among the last
    /// few evaluations). Rounding errors in `q_k(α)` are proportional to it, not to
    /// `|q_k(α)|`, which can cancel to zero. `None` for a general load (or basis weights
    /// not evaluated at α lately).
    pub(crate) fn term_magnitude_rows(&self, alpha: f64) -> Option<Vec<f64>> {
        self.abs_combination(&self.abs_weights(alpha, false)?)
    }

    /// `Σ_j |w'_j(α)| |q_j,k|` for a basis load whose weights were evaluated at α lately:
    /// the magnitude of the terms of `q'_k(α)`. None otherwise.
    pub(crate) fn term_rate_rows(&self, alpha: f64) -> Option<Vec<f64>> {
        let Load::Basis { .. } = &self.load else {
            return None;
        };
        let (_, _, dw) = self
            .recent_weights
            .iter()
            .rev()
            .find(|(a, _, _)| *a == alpha)?;
        self.abs_combination(dw)
    }

    /// `Σ_j |c_j| |q_j,k|` for each row k of the basis vectors (None without any).
    fn abs_combination(&self, c: &[f64]) -> Option<Vec<f64>> {
        let m = self.q_basis.first()?.len();
        Some(
            (0..m)
                .map(|k| {
                    c.iter()
                        .zip(&self.q_basis)
                        .map(|(cj, qj)| cj.abs() * qj[k].abs())
                        .sum()
                })
                .collect(),
        )
    }

    /// `|w_j(α)|`: `(1, |α|)` for an affine load; a basis load's weights at α if among its
    /// last few evaluations, or else, with `latest`, its latest ones. None for a general
    /// load (or a basis load's weights not at hand).
    fn abs_weights(&self, alpha: f64, latest: bool) -> Option<Vec<f64>> {
        match &self.load {
            Load::Affine { .. } => Some(vec![1.0, alpha.abs()]),
            Load::Basis { .. } => {
                let mut recent = self.recent_weights.iter().rev();
                let at = recent.clone().find(|(a, _, _)| *a == alpha);
                let (_, w, _) = if latest { at.or(recent.next())? } else { at? };
                Some(w.iter().map(|w| w.abs()).collect())
            }
            Load::General { .. } => None,
        }
    }

    /// `‖δq_j‖∞` for each vector of an affine or basis load: the error of the solve that
    /// condensed `f_j` (kept from the low parts where W was refined, else found by the same
    /// refinement, [`Delassus::condense_error`]: a few solves with the factor of A per
    /// vector, once). None for a general load, a host's solve, condensed input, or where
    /// the refinement fails.
    fn condensation_errors(&self, del: &Delassus) -> Option<&[f64]> {
        self.errors
            .get_or_init(|| {
                let f: Vec<&[f64]> = match &self.load {
                    Load::Affine { f0, f1 } => vec![f0, f1],
                    Load::Basis { vectors, .. } => vectors.iter().map(|v| v.as_slice()).collect(),
                    Load::General { .. } => return None,
                };
                let q: Vec<&[f64]> = self.q_basis.iter().map(|v| v.as_slice()).collect();
                let lo = del.condense_error(&f, &q).ok()??;
                Some(lo.iter().map(|l| inf_norm(l)).collect())
            })
            .as_deref()
    }

    /// How far the data determine each row of `q(α)`: `Σ_j |w_j(α)| ‖δq_j‖∞`
    /// ([`Self::condensation_errors`], about κ(A) ε ‖q_j‖∞ in every row; the weights as in
    /// [`Self::term_magnitude_rows`]); for a general load evaluated last at α, the error of
    /// that evaluation's q ([`GeneralEval::error`]). Perturbing A by its own rounding (an
    /// element matrix whose entries that are equal by symmetry came out of different sums)
    /// moves q by about as much, so a row below it has no sign: on a mirror-symmetric
    /// body, the node on the axis touched down with a tangential displacement of 1.6e-14
    /// of the load's scale where it is 0 by symmetry, and no class fitted it. None where
    /// not known. Used only where the usual thresholds find no continuation, or several
    /// (the latest weights of a basis load stand in for α's where those are no longer at
    /// hand).
    pub(crate) fn determination(&self, alpha: f64, del: &Delassus) -> Option<f64> {
        if let Load::General { .. } = self.load {
            return self.general_at(alpha)?.error(del);
        }
        let w = self.abs_weights(alpha, true)?;
        let e = self.condensation_errors(del)?;
        Some(w.iter().zip(e).map(|(a, b)| a * b).sum())
    }

    /// `max_j ‖δq_j‖∞ / ‖q_j‖∞` ([`Self::condensation_errors`]): the relative error of the
    /// condensation in double, about κ(A) ε; for a general load evaluated last at α, its
    /// q's error relative to ‖q‖∞. None where not known.
    pub(crate) fn relative_determination(&self, alpha: f64, del: &Delassus) -> Option<f64> {
        if let Load::General { .. } = self.load {
            let e = self.general_at(alpha)?;
            return Some(e.error(del)? / inf_norm(&e.q)).filter(|r| r.is_finite());
        }
        self.condensation_errors(del)?
            .iter()
            .zip(&self.q_basis)
            .map(|(e, q)| e / inf_norm(q))
            .filter(|r| r.is_finite())
            .reduce(f64::max)
    }

    /// A general load's last evaluation if it was at `alpha`.
    fn general_at(&self, alpha: f64) -> Option<&GeneralEval> {
        self.last_general.as_ref().filter(|e| e.alpha == alpha)
    }

    /// `(q0_lo, q1_lo)`: the low parts of the condensed affine load `q(α) = q0 + α q1`
    /// (2p entries each; `q0 + q0_lo` is `B A⁻¹ f0` to double-double accuracy) when the
    /// problem's W was refined ([`Delassus::w_lo`]). None for other loads or when W was not
    /// refined.
    pub(crate) fn affine_lo(&self) -> Option<(&[f64], &[f64])> {
        match (&self.load, &self.q_lo) {
            (Load::Affine { .. }, Some(lo)) => Some((&lo[0], &lo[1])),
            _ => None,
        }
    }

    /// The low parts of the condensed basis vectors (`q_j + q_lo[j]` is `B A⁻¹ f_j` to
    /// double-double accuracy) of an affine or basis load when the problem's W was refined.
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) fn q_lo(&self) -> Option<&[Vec<f64>]> {
        self.q_lo.as_deref()
    }

    /// For a general load on a problem whose W was refined ([`Delassus::w_lo`]): the
    /// condensed load `q` of its last evaluation by [`Self::q`] and its low part (`q +
    /// q_lo` is `B A⁻¹ f(α)` to double-double accuracy), 2p entries each. None otherwise.
    pub(crate) fn general_q_lo(&self) -> Option<(&[f64], &[f64])> {
        let e = self.last_general.as_ref()?;
        Some((&e.q, e.q_lo.as_deref()?))
    }

    /// Anchors a general load at `alpha` (a no-op for other loads): until
    /// [`Self::drop_anchor`], [`Self::q`] condenses the change `f(α) − f(α_a)` and adds it
    /// to `q(α_a)`. The rounding of q(α) is then proportional to that change: smooth in α
    /// near α_a, where a fresh condensation at each α differs from the next by
    /// `κ(A) ε ‖q‖`, noise that can exceed a slender body's guard thresholds. Errors:
    /// those of [`Self::q`] at `alpha`.
    pub(crate) fn anchor_at(&mut self, alpha: f64, del: &Delassus) -> Result<()> {
        self.drop_anchor();
        if !matches!(self.load, Load::General { .. }) {
            return Ok(());
        }
        self.q(alpha, del)?;
        self.anchor = self
            .last_general
            .as_ref()
            .map(|e| (e.f.clone(), e.q.clone()));
        Ok(())
    }

    /// Drops the anchor of [`Self::anchor_at`] (and the last evaluation, made relative to
    /// it).
    pub(crate) fn drop_anchor(&mut self) {
        self.anchor = None;
        self.last_general = None;
    }

    /// For a basis load: its condensed vectors `q_j`, so that `q(α) = Σ_j w_j(α) q_j`.
    /// None for other loads.
    pub(crate) fn basis_vectors(&self) -> Option<&[Vec<f64>]> {
        matches!(self.load, Load::Basis { .. }).then_some(&self.q_basis[..])
    }

    /// For a basis load whose weights were last evaluated at `alpha` (by [`Self::q`]):
    /// `(w(α), w'(α))`. None otherwise.
    pub(crate) fn weights_at(&self, alpha: f64) -> Option<(&[f64], &[f64])> {
        (matches!(self.load, Load::Basis { .. }) && self.weights_alpha == alpha)
            .then_some((&self.weights[..], &self.dweights[..]))
    }

    /// For a general load without a derivative: the step of its central differences at
    /// `alpha`, `ε^{1/3} max(1, |α|)`. None for other loads.
    pub(crate) fn difference_step(&self, alpha: f64) -> Option<f64> {
        matches!(self.load, Load::General { df: None, .. }).then(|| difference_step(alpha))
    }

    /// True when `f` (hence `q`) is affine in α.
    pub(crate) fn is_affine(&self) -> bool {
        matches!(self.load, Load::Affine { .. })
    }

    fn eval_weights(&mut self, alpha: f64) -> Result<()> {
        let Load::Basis { weights, .. } = &mut self.load else {
            return Ok(());
        };
        self.weights_alpha = f64::NAN;
        weights(alpha, &mut self.weights, &mut self.dweights).map_err(|e| Error::Load {
            alpha,
            code: e.code,
            message: e.message,
        })?;
        if self
            .weights
            .iter()
            .chain(self.dweights.iter())
            .any(|w| !w.is_finite())
        {
            return Err(Error::Load {
                alpha,
                code: 0,
                message: "the basis weights returned a NaN or infinite value".into(),
            });
        }
        self.weights_alpha = alpha;
        const RECENT: usize = 8;
        if self.recent_weights.len() == RECENT {
            self.recent_weights.remove(0);
        }
        self.recent_weights
            .push((alpha, self.weights.clone(), self.dweights.clone()));
        Ok(())
    }

    /// What is needed to rebuild `f(α)` later without calling the user's closures:
    /// nothing for an affine load, the weights for a basis load, `f(α)` itself otherwise.
    pub(crate) fn snapshot(&mut self, alpha: f64) -> Result<LoadSnapshot> {
        Ok(match &self.load {
            Load::Affine { .. } => LoadSnapshot::Affine,
            Load::Basis { .. } => {
                self.eval_weights(alpha)?;
                LoadSnapshot::Weights(self.weights.clone())
            }
            Load::General { .. } => LoadSnapshot::Force(self.force(alpha)?),
        })
    }

    /// `f(α)` into `out` (n entries) from a snapshot taken at the same α (no closure is
    /// called).
    pub(crate) fn force_into(&self, alpha: f64, snap: &LoadSnapshot, out: &mut [f64]) {
        match (&self.load, snap) {
            (Load::Affine { f0, f1 }, _) => {
                for ((o, a), b) in out.iter_mut().zip(f0.iter()).zip(f1.iter()) {
                    *o = a + alpha * b;
                }
            }
            (Load::Basis { vectors, .. }, LoadSnapshot::Weights(w)) => {
                out.fill(0.0);
                for (wj, v) in w.iter().zip(vectors) {
                    for (fi, vi) in out.iter_mut().zip(v) {
                        *fi += wj * vi;
                    }
                }
            }
            (_, LoadSnapshot::Force(f)) => out.copy_from_slice(f),
            (_, _) => unreachable!("a snapshot always matches its load"),
        }
    }

    /// True when [`Self::half_solved_into`] answers (an affine or basis load on a problem
    /// with half solves).
    pub(crate) fn has_half(&self) -> bool {
        self.half.is_some()
    }

    /// `L⁻¹ Pᵀ f(α)` into `out` (n entries) for an affine or basis load whose vectors were
    /// half-solved (see [`Delassus::half_solve`]); false (nothing written) otherwise (a
    /// general load: half-solve `f` itself).
    pub(crate) fn half_solved_into(
        &self,
        alpha: f64,
        snap: &LoadSnapshot,
        out: &mut [f64],
    ) -> bool {
        let Some(y) = self.half.as_ref() else {
            return false;
        };
        let w: Vec<f64> = match (&self.load, snap) {
            (Load::Affine { .. }, _) => vec![1.0, alpha],
            (Load::Basis { .. }, LoadSnapshot::Weights(w)) => w.clone(),
            _ => return false,
        };
        out.fill(0.0);
        for (c, wc) in w.iter().enumerate() {
            for (o, v) in out.iter_mut().zip(y.col(c).iter()) {
                *o += wc * v;
            }
        }
        true
    }

    /// The load vector `f(α)` (n entries).
    pub(crate) fn force(&mut self, alpha: f64) -> Result<Vec<f64>> {
        match &mut self.load {
            Load::Affine { f0, f1 } => Ok(f0
                .iter()
                .zip(f1.iter())
                .map(|(a, b)| a + alpha * b)
                .collect()),
            Load::Basis { .. } => {
                self.eval_weights(alpha)?;
                let Load::Basis { vectors, .. } = &self.load else {
                    unreachable!()
                };
                let mut f = vec![0.0; vectors[0].len()];
                for (w, v) in self.weights.iter().zip(vectors) {
                    for (fi, vi) in f.iter_mut().zip(v) {
                        *fi += w * vi;
                    }
                }
                Ok(f)
            }
            Load::General { n, f, .. } => {
                let mut out = vec![0.0; *n];
                call_vector(f, alpha, &mut out, "f")?;
                Ok(out)
            }
        }
    }

    /// `(q(α), q'(α))`, 2p entries each.
    pub(crate) fn q(&mut self, alpha: f64, del: &Delassus) -> Result<(Vec<f64>, Vec<f64>)> {
        match &mut self.load {
            Load::Affine { .. } => {
                let q = self.q_basis[0]
                    .iter()
                    .zip(&self.q_basis[1])
                    .map(|(a, b)| a + alpha * b)
                    .collect();
                Ok((q, self.q_basis[1].clone()))
            }
            Load::Basis { .. } => {
                self.eval_weights(alpha)?;
                let m = self.q_basis[0].len();
                let mut q = vec![0.0; m];
                let mut dq = vec![0.0; m];
                for ((w, dw), qj) in self.weights.iter().zip(&self.dweights).zip(&self.q_basis) {
                    for i in 0..m {
                        q[i] += w * qj[i];
                        dq[i] += dw * qj[i];
                    }
                }
                Ok((q, dq))
            }
            Load::General { n, f, df } => {
                if let Some(e) = &self.last_general
                    && e.alpha == alpha
                {
                    return Ok((e.q.clone(), e.dq.clone()));
                }
                let n = *n;
                let mut fv = take(&mut self.pool, n);
                call_vector(f, alpha, &mut fv, "f")?;
                let norm2 = |v: &[f64]| dot(v, v).sqrt();
                // f'(α) given, or the central difference f(α + h) − f(α − h), divided by
                // 2h (once condensed, where condensed from the span); with the 2-norm
                // that a difference's rounding is measured against (see Span::condense)
                let (dv, d_ref, d_div) = match df {
                    Some(df) => {
                        let mut d = take(&mut self.pool, n);
                        call_vector(df, alpha, &mut d, "f'")?;
                        (d, None, 1.0)
                    }
                    None => {
                        let h = difference_step(alpha);
                        let mut fp = take(&mut self.pool, n);
                        let mut fm = take(&mut self.pool, n);
                        call_vector(f, alpha + h, &mut fp, "f")?;
                        call_vector(f, alpha - h, &mut fm, "f")?;
                        let reference = norm2(&fp).max(norm2(&fm));
                        for (a, b) in fp.iter_mut().zip(&fm) {
                            *a -= b;
                        }
                        give(&mut self.pool, fm);
                        (fp, Some(reference), 2.0 * h)
                    }
                };
                // (with an anchor, q as q(α_a) plus the condensed change of f, whose
                // rounding is that of the two evaluations)
                let change: Option<Vec<f64>> = self.anchor.as_ref().map(|(fa, _)| {
                    let mut c = take(&mut self.pool, n);
                    for ((c, a), b) in c.iter_mut().zip(&fv).zip(fa) {
                        *c = a - b;
                    }
                    c
                });
                let base: &[f64] = change.as_deref().unwrap_or(&fv);
                let base_ref = self
                    .anchor
                    .as_ref()
                    .map(|(fa, _)| norm2(&fv).max(norm2(fa)));
                // (a load near the largest double overflows in the solves: say so)
                let hint = |e: Error| match e {
                    Error::Numerical(m) => {
                        let big = inf_norm(&fv).max(inf_norm(&dv) / d_div);
                        Error::Numerical(m + &crate::path::overflow_hint(big))
                    }
                    e => e,
                };
                let spanned = self
                    .span
                    .condense(del, &[(base, base_ref), (&dv, d_ref)])
                    .map_err(hint)?;
                let (mut q, dq) = match spanned {
                    Some(mut qs) => {
                        let mut dq = qs.pop().expect("two columns");
                        dq.iter_mut().for_each(|x| *x /= d_div);
                        (qs.pop().expect("two columns"), dq)
                    }
                    // q and q' in one pass over the factor of A
                    None => {
                        let scaled: Vec<f64>;
                        let d: &[f64] = if d_div == 1.0 {
                            &dv
                        } else {
                            scaled = dv.iter().map(|x| x / d_div).collect();
                            &scaled
                        };
                        let mut qs = del.condense_many(&[base, d]).map_err(hint)?;
                        let dq = qs.pop().expect("two columns");
                        (qs.pop().expect("two columns"), dq)
                    }
                };
                if let Some((_, qa)) = &self.anchor {
                    for (a, b) in q.iter_mut().zip(qa) {
                        *a += b;
                    }
                }
                // Where W was refined, q's low part too: the tracer refines its points
                // under this load on q + q_lo.
                let q_lo = del
                    .condense_lo(&[&fv], &[&q])
                    .map_err(hint)?
                    .and_then(|mut v| v.pop());
                give(&mut self.pool, dv);
                if let Some(c) = change {
                    give(&mut self.pool, c);
                }
                let old = self.last_general.replace(GeneralEval {
                    alpha,
                    f: fv,
                    q: q.clone(),
                    dq: dq.clone(),
                    q_lo,
                    error: std::cell::OnceCell::new(),
                });
                if let Some(old) = old {
                    give(&mut self.pool, old.f);
                }
                Ok((q, dq))
            }
        }
    }
}

fn call_vector(f: &mut VectorFn, alpha: f64, out: &mut [f64], what: &str) -> Result<()> {
    f(alpha, out).map_err(|e| Error::Load {
        alpha,
        code: e.code,
        message: e.message,
    })?;
    if let Some(i) = out.iter().position(|x| !x.is_finite()) {
        return Err(Error::Load {
            alpha,
            code: 0,
            message: format!("{what} returned {} in entry {}", out[i], i + 1),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CsrMatrix, ExtendedPrecision, ProblemBuilder, Storage};

    /// A 3-dof chain with one contact node on dofs 0 and 1.
    fn problem(mode: ExtendedPrecision) -> crate::Problem {
        let a = CsrMatrix::from_dense(3, 3, &[3.0, -1.0, 0.0, -1.0, 3.0, -1.0, 0.0, -1.0, 3.0])
            .unwrap();
        let n = CsrMatrix::from_dense(1, 3, &[1.0, 0.0, 0.0]).unwrap();
        let t = CsrMatrix::from_dense(1, 3, &[0.0, 1.0, 0.0]).unwrap();
        ProblemBuilder::new(a, Storage::Full, n, t)
            .extended_precision(mode)
            .build()
            .unwrap()
    }

    /// The low parts of an affine load complete the stored `q0`, `q1` to `B A⁻¹ f`
    /// (`Delassus::condense_lo` finds nothing else missing), and exist only when W was
    /// refined.
    #[test]
    fn affine_low_parts_follow_the_refinement() {
        let (f0, f1) = (vec![0.1, 0.7, 1.0 / 3.0], vec![1.0, -0.3, 0.2]);
        let on = problem(ExtendedPrecision::On);
        let del = on.delassus();
        let bl = BoundLoad::new(Load::affine(f0.clone(), f1.clone()).unwrap(), del).unwrap();
        let (lo0, lo1) = bl.affine_lo().expect("refined");
        let want = del
            .condense_lo(&[&f0, &f1], &[&bl.q_basis[0], &bl.q_basis[1]])
            .unwrap()
            .unwrap();
        // q_j + q_lo,j is B A⁻¹ f_j (what condense_lo finds missing from q_j is q_lo,j, to
        // double-double accuracy), and q_j is it correctly rounded (|q_lo| ≤ half an ulp).
        for (lo, (want, q)) in [lo0, lo1].into_iter().zip(want.iter().zip(&bl.q_basis)) {
            for k in 0..lo.len() {
                assert!(
                    (lo[k] - want[k]).abs() <= 1e-28 * q[k].abs(),
                    "{} {}",
                    lo[k],
                    want[k]
                );
                assert!(lo[k].abs() <= 0.5 * f64::EPSILON * q[k].abs() * (1.0 + 1e-12));
            }
        }
        assert_eq!(bl.q_lo().map(|q| q.len()), Some(2));
        // A basis load has low parts but no affine ones.
        let basis = Load::basis(
            vec![f0.clone()],
            Box::new(|_, w, d| {
                w[0] = 1.0;
                d[0] = 0.0;
                Ok(())
            }),
        )
        .unwrap();
        let bl = BoundLoad::new(basis, del).unwrap();
        assert!(bl.affine_lo().is_none() && bl.q_lo().is_some());
        let off = problem(ExtendedPrecision::Off);
        let bl = BoundLoad::new(Load::affine(f0, f1).unwrap(), off.delassus()).unwrap();
        assert!(bl.affine_lo().is_none() && bl.q_lo().is_none());
    }
}
