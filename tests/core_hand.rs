//! Hand-derived one- and two-node problems: events and states against closed forms.
//!
//! Every expected number below is derived by hand in the comments, in the condensed
//! variables `d = q(α) + W λ − (g, 0)`, `W = B A⁻¹ Bᵀ`, `q = B A⁻¹ f(α)` (SPEC §2–3).
//! The data are chosen so that `W` and `q` are exact in floating point (A diagonal with
//! entries 1 and 4, B with small integers), so the hand values are the exact answers.
//! Each derivation is also cross-checked against the independent nalgebra brute force of
//! `tests/common` where that applies.
//!
//! The one-node problems use `common::one_node`: n = 3 dofs, `A = diag(1, 1, 4)`,
//! `N = [1 0 0]`, `T = [−1 1 0]`, so `A⁻¹ = diag(1, 1, 1/4)` and with
//! `B = [[1, 0, 0], [−1, 1, 0]]`
//!
//! ```text
//! W = B A⁻¹ Bᵀ = [[1, −1], [−1, 2]],    q = B A⁻¹ f = (f₁, f₂ − f₁)
//! ```
//!
//! (the third dof is decoupled from the contact node and only makes n > 2p).

mod common;

use std::sync::Arc;

use common::{
    Brute, Data, check_state, close, lambda_ev, lambda_of, mirror_pair, one_node, trace, vclose,
};
use fricont::{Class, EndReason};
use nalgebra::DVector;

const TOL: f64 = 1e-12;

fn lam(v: &[f64]) -> DVector<f64> {
    DVector::from_column_slice(v)
}

/// Every event's state solves the problem (independent check) and has a small residual.
fn check_events(data: &Data, path: &mut fricont::Path) {
    for e in &common::events_with_state(path) {
        assert!(
            e.state.residual <= TOL,
            "event {} residual {:e}",
            e.index,
            e.state.residual
        );
        check_state(data, &data.force(e.alpha), &e.state, 1e-10)
            .unwrap_or_else(|m| panic!("event {}: {m}", e.index));
    }
}

/// (a) Two non-smooth folds and three solutions (Klarbring-type, large friction).
///
/// Data: `one_node` with `F = 2`, `f0 = (0, 1, 0.7)`, `f1 = (1, −1.5, −0.3)`, so
/// `qν = α`, `qt = f₂ − f₁ = 1 − 1.5α − α = 1 − 2.5α`. With `W = [[1, −1], [−1, 2]]`:
///
/// ```text
/// dν = qν + λν − λt,      dt = qt − λν + 2 λt.
/// ```
///
/// * Open: `λ = 0`, guard `dν = α < 0`  →  α < 0.
/// * S+: `λt = 2 λν`, `dν = α + λν − 2λν = 0` → `λν = α`, `λt = 2α`.
///   Guards `λν < 0` → α < 0; `dt = qt − λν + 4λν = 1 − 2.5α + 3α = 1 + α/2 > 0` → α > −2.
///   S+ lives on (−2, 0); its square Jacobian `[[r, −r], [−2, 1]]` has det −r < 0.
/// * Stick: `dν = dt = 0`: adding, `qν + qt + λt = 0` → `λt = 1.5α − 1`, `λν = λt − qν
///   = 0.5α − 1`. Guards `λν < 0` → α < 2; `λt − Fλν = 0.5α + 1 > 0` → α > −2;
///   `−Fλν − λt = 3 − 2.5α > 0` → α < 1.2. Stick lives on (−2, 1.2); det `r²` > 0.
/// * S−: `λt = −2λν`, `dν = α + 3λν = 0` → `λν = −α/3`, `λt = 2α/3`. Guards α > 0 and
///   `dt = qt − 5λν = 1 − (5/6)α < 0` → α > 1.2. S− lives on (1.2, ∞); det 3r > 0.
///
/// Joins: Open and S+ meet at α = 0 (λ = 0); S+ and Stick meet at α = −2 (λ = (−2, −4)
/// on both); Stick and S− meet at α = 1.2 (λ = (−0.4, 0.8) on both).
/// The path from α = −3 (open, the only solution there) therefore goes up to α = 0, turns
/// back (fold: Open exists for α < 0 only, S+ as well), goes down along S+ to α = −2,
/// turns again (fold) onto Stick, goes up to α = 1.2, continues on S− to α = 3:
///
/// ```text
/// event 1: α = 0,   node 0, open  -> slip+, fold
/// event 2: α = −2,  node 0, slip+ -> stick, fold
/// event 3: α = 1.2, node 0, stick -> slip-, no fold
/// ```
///
/// Between the folds, at α = −1, there are three solutions: open λ = (0, 0), S+
/// λ = (−1, −2), stick λ = (0.5·(−1) − 1, 1.5·(−1) − 1) = (−1.5, −2.5).
/// Elsewhere the solution is unique (one piece covers each α outside (−2, 0)).
#[test]
fn two_folds_three_solutions() {
    let data = one_node(2.0, [0.0, 1.0, 0.7], [1.0, -1.5, -0.3]);
    let problem = Arc::new(data.problem());
    let mut path = trace(problem, data.affine_load(), -3.0, 3.0);
    assert_eq!(path.end_reason(), Some(&EndReason::Window));

    let expected = [
        (0.0, Class::Open, Class::SlipPlus, true),
        (-2.0, Class::SlipPlus, Class::Stick, true),
        (1.2, Class::Stick, Class::SlipMinus, false),
    ];
    let ev = path.events();
    assert_eq!(ev.len(), expected.len(), "events: {ev:#?}");
    for (e, &(alpha, from, to, fold)) in ev.iter().zip(&expected) {
        assert!(
            close(e.alpha, alpha, TOL),
            "event α {} expected {alpha}",
            e.alpha
        );
        assert_eq!(
            (e.node, e.from, e.to, e.fold, e.bifurcation),
            (0, from, to, fold, false)
        );
    }
    // λ at the events, by hand: (0, 0), (−2, −4), (−0.4, 0.8).
    for (e, l) in ev.iter().zip([[0.0, 0.0], [-2.0, -4.0], [-0.4, 0.8]]) {
        assert!(
            vclose(&lambda_ev(e), &lam(&l), TOL),
            "λ at event {}: {:?}",
            e.index,
            e
        );
    }
    check_events(&data, &mut path);

    let dirs: Vec<i8> = path.pieces().iter().map(|pc| pc.direction).collect();
    assert_eq!(dirs, vec![1, -1, 1, 1]);
    let classes: Vec<Class> = path.pieces().iter().map(|pc| pc.classes[0]).collect();
    assert_eq!(
        classes,
        vec![Class::Open, Class::SlipPlus, Class::Stick, Class::SlipMinus]
    );

    // Three solutions between the folds.
    let sols = path.solutions_at(-1.0).unwrap();
    let want = [lam(&[0.0, 0.0]), lam(&[-1.0, -2.0]), lam(&[-1.5, -2.5])];
    assert_eq!(sols.len(), 3, "{sols:#?}");
    for w in &want {
        assert!(
            sols.iter().any(|s| vclose(&lambda_of(&s.state), w, TOL)),
            "missing λ = {w:?} at α = −1"
        );
    }
    for s in &sols {
        assert!(s.state.residual <= TOL);
        assert!(!s.continuum);
        check_state(&data, &data.force(-1.0), &s.state, 1e-10).unwrap();
    }
    // Unique elsewhere.
    for (alpha, l) in [
        (-2.5, [0.0, 0.0]),
        (0.5, [-0.75, -0.25]),
        (2.0, [-2.0 / 3.0, 4.0 / 3.0]),
    ] {
        let sols = path.solutions_at(alpha).unwrap();
        assert_eq!(sols.len(), 1, "α = {alpha}: {sols:#?}");
        assert!(
            vclose(&lambda_of(&sols[0].state), &lam(&l), TOL),
            "α = {alpha}: {:?}",
            sols[0].state
        );
    }

    // Cross-check of the hand derivation with the independent brute force.
    let br = Brute::new(&data);
    let walk = br.walk(-3.0, 3.0, &lam(&[0.0, 0.0])).expect("generic walk");
    let got: Vec<(f64, Class, Class, bool)> = walk
        .events
        .iter()
        .map(|e| (e.phi, e.from, e.to, e.fold))
        .collect();
    assert_eq!(got.len(), 3);
    for (g, x) in got.iter().zip(&expected) {
        assert!(
            close(g.0, x.0, 1e-14) && (g.1, g.2, g.3) == (x.1, x.2, x.3),
            "{g:?} vs {x:?}"
        );
    }
    assert_eq!(br.solutions_at(-1.0).len(), 3);
}

/// (b) A vertical piece: a continuum of solutions at one α (Hild–Renard).
///
/// Data: `one_node` with `F = 1`, `f0 = (−0.25, 0.75, 0)`, `f1 = (1, 1, 0)`, so
/// `qν = α − 0.25`, `qt = f₂ − f₁ = 1`. With `dν = qν + λν − λt`, `dt = qt − λν + 2λt`:
///
/// * Open: guard `qν < 0` → α < 0.25.
/// * S+: `λt = λν`, `dν = qν + λν − λν = qν`: the piece matrix `K = w₁₁ + F w₁₂ = 0` is
///   singular, and `c = qν` is in its range only at α = 0.25. There every
///   `λ = (t, t)` with guards `t < 0` and `dt = 1 − t + 2t = 1 + t > 0`, i.e.
///   `t ∈ (−1, 0)`, is a solution: a vertical segment from λ = (0, 0) to λ = (−1, −1).
/// * Stick: `λ = −W⁻¹ q` with `W⁻¹ = [[2, 1], [1, 1]]`: `λν = −2qν − qt = −2α − 0.5`,
///   `λt = −qν − qt = −α − 0.75`. Guards `λν < 0` ↔ α > −0.25, `λt − Fλν = α − 0.25 > 0`
///   ↔ α > 0.25, `−Fλν − λt = 3α + 1.25 > 0`. Stick lives on (0.25, ∞), starting at
///   λ = (−1, −1), the lower end of the vertical segment.
/// * S−: `λt = −λν`, `dν = qν + 2λν = 0`, λν < 0 needs α > 0.25, but then
///   `dt = 1 − 3λν > 0`: never a solution.
///
/// So the solution is unique for α ≠ 0.25 (open below, stick above) and the path goes
/// open → (vertical S+ at α = 0.25 from λ = 0 down to λ = (−1, −1)) → stick:
///
/// ```text
/// event 1: α = 0.25, node 0, open  -> slip+   (no fold: α increases before and after)
/// event 2: α = 0.25, node 0, slip+ -> stick
/// ```
#[test]
fn vertical_piece_continuum() {
    let data = one_node(1.0, [-0.25, 0.75, 0.0], [1.0, 1.0, 0.0]);
    let problem = Arc::new(data.problem());
    let mut path = trace(problem, data.affine_load(), -1.0, 1.0);
    assert_eq!(path.end_reason(), Some(&EndReason::Window));

    let ev = path.events();
    assert_eq!(ev.len(), 2, "events: {ev:#?}");
    let expected = [
        (Class::Open, Class::SlipPlus, [0.0, 0.0]),
        (Class::SlipPlus, Class::Stick, [-1.0, -1.0]),
    ];
    for (e, (from, to, l)) in ev.iter().zip(expected) {
        assert!(close(e.alpha, 0.25, TOL), "event α {}", e.alpha);
        assert_eq!(
            (e.node, e.from, e.to, e.fold, e.bifurcation),
            (0, from, to, false, false)
        );
        assert!(vclose(&lambda_ev(e), &lam(&l), TOL), "{e:?}");
    }
    check_events(&data, &mut path);

    let pcs = path.pieces();
    assert_eq!(pcs.len(), 3, "{pcs:#?}");
    assert_eq!(
        pcs.iter()
            .map(|p| (p.classes[0], p.direction))
            .collect::<Vec<_>>(),
        vec![(Class::Open, 1), (Class::SlipPlus, 0), (Class::Stick, 1)]
    );
    let v = &pcs[1];
    assert!(close(v.alpha_from, 0.25, TOL) && close(v.alpha_to, 0.25, TOL));
    assert!(
        vclose(&lam(&v.lambda_from), &lam(&[0.0, 0.0]), TOL),
        "{v:?}"
    );
    assert!(
        vclose(&lam(&v.lambda_to), &lam(&[-1.0, -1.0]), TOL),
        "{v:?}"
    );

    // At α = 0.25: a continuum flagged, all reported points on the segment λ = (t, t),
    // t ∈ [−1, 0].
    let sols = path.solutions_at(0.25).unwrap();
    assert!(
        sols.iter()
            .any(|s| s.continuum && path.pieces()[s.piece].classes[0] == Class::SlipPlus),
        "{sols:#?}"
    );
    for s in &sols {
        let (t, tt) = (s.state.lambda_n[0], s.state.lambda_t[0]);
        assert!(
            (t - tt).abs() <= TOL && (-1.0 - TOL..=TOL).contains(&t),
            "{s:?}"
        );
        check_state(&data, &data.force(0.25), &s.state, 1e-10).unwrap();
    }
    // Unique elsewhere: open below, stick above.
    for (alpha, l) in [
        (0.0, [0.0, 0.0]),
        (0.5, [-1.5, -1.25]),
        (0.9, [-2.3, -1.65]),
    ] {
        let sols = path.solutions_at(alpha).unwrap();
        assert_eq!(sols.len(), 1, "α = {alpha}: {sols:#?}");
        assert!(!sols[0].continuum);
        assert!(
            vclose(&lambda_of(&sols[0].state), &lam(&l), TOL),
            "α = {alpha}: {:?}",
            sols[0].state
        );
        // brute force agrees and finds nothing else
        let br = Brute::new(&data);
        let bs = br.solutions_at(alpha);
        assert_eq!(bs.len(), 1);
        assert!(vclose(&bs[0].1, &lam(&l), 1e-13));
    }
    // The brute force sees the S+ piece as singular.
    let br = Brute::new(&data);
    assert!(br.piece(&[Class::SlipPlus]).is_none());
}

/// Two mirror-symmetric nodes, n = 5 dofs `(a₁, b₁, a₂, b₂, c)`, `A = I`,
///
/// ```text
/// N₁ = a₁ + c,  T₁ = b₁ + c,  N₂ = a₂ − c,  T₂ = −b₂ − c
/// ```
///
/// The mirror `a₁ ↔ a₂, b₁ ↔ −b₂, c ↔ −c` maps row N₁ to N₂ and T₁ to T₂. With
/// `W = B Bᵀ` in the order (ν₁, ν₂, t₁, t₂):
///
/// ```text
/// W = [[ 2, −1,  1, −1],
///      [−1,  2, −1,  1],
///      [ 1, −1,  2, −1],
///      [−1,  1, −1,  2]]
/// ```
///
/// Load `f = (α, 1, α, −1, 0)` (mirror-symmetric): `q = B f = (α, α, 1, 1)`. F = 0.5.
///
/// * α < 0: both open (`dν = α < 0`), unique (any contact piece needs `λν < 0`, below).
/// * At α = 0 both normal guards reach zero at once with `dt = 1 > 0`: the candidates are
///   (S+, O), (O, S+), (S+, S+). (S+, O): `dν₁ = α + 2λν₁ + λt₁ = α + 2.5 λν₁ = 0` →
///   `λν₁ = −0.4α` (needs α > 0), but then `dν₂ = α − λν₁ − λt₁ = α − 1.5 λν₁ = 1.6α > 0`
///   violates node 2's open guard: it does not enter its region; (O, S+) likewise by
///   symmetry. (S+, S+): by symmetry `λν₁ = λν₂ = μ`, `λt = μ/2`,
///   `dν₁ = α + 2μ − μ + μ/2 − μ/2 = α + μ = 0` → `μ = −α`, and
///   `dt₁ = 1 − α + α − α + α/2 = 1 − α/2 > 0` for α < 2: it enters (α increasing).
///   Two events at α = 0: node 0 open → slip+, node 1 open → slip+.
/// * At α = 2 both `dt` reach zero at once at λ = (−2, −2, −1, −1). (Stick, Stick):
///   `dν₁ = α + μ = 0`, `dt₁ = 1 + 2τ − τ = 1 + τ = 0` → `λ = (−α, −α, −1, −1)`, guards
///   `τ − Fμ = α/2 − 1 > 0` ↔ α > 2 (others hold): enters for α increasing.
///   (S+, Stick): unknowns `(λν₁, λν₂, λt₂)`, `λt₁ = λν₁/2`; the equations
///   `dν₁ = α + 2.5λν₁ − λν₂ − λt₂`, `dν₂ = α − 1.5λν₁ + 2λν₂ + λt₂`,
///   `dt₂ = 1 − 1.5λν₁ + λν₂ + 2λt₂` hold at the point; their α-derivative is
///   `x = (−8/9, −10/9, −1/9)`, so `dt₁ = 1 + 2λν₁ − λν₂ − λt₂` changes at rate `−5/9`
///   (negative for α > 2) and `λt₂ − Fλν₂` at rate `4/9` (negative for α < 2): it enters
///   in neither direction; (Stick, S+) likewise. Unique continuation (Stick, Stick):
///   two events at α = 2: node 0 slip+ → stick, node 1 slip+ → stick. No fold, no
///   bifurcation.
///
/// Solutions: `λ = (−α, −α, −α/2, −α/2)` on (0, 2), `(−α, −α, −1, −1)` beyond.
#[test]
fn degenerate_symmetric_transition() {
    let data = mirror_pair();
    let problem = Arc::new(data.problem());
    let mut path = trace(problem, data.affine_load(), -1.0, 3.0);
    assert_eq!(path.end_reason(), Some(&EndReason::Window));
    let ev = path.events();
    let expected = [
        (0.0, 0, Class::Open, Class::SlipPlus),
        (0.0, 1, Class::Open, Class::SlipPlus),
        (2.0, 0, Class::SlipPlus, Class::Stick),
        (2.0, 1, Class::SlipPlus, Class::Stick),
    ];
    assert_eq!(ev.len(), 4, "events: {ev:#?}");
    for (e, &(alpha, node, from, to)) in ev.iter().zip(&expected) {
        assert!(
            close(e.alpha, alpha, TOL),
            "event α {} expected {alpha}",
            e.alpha
        );
        assert_eq!(
            (e.node, e.from, e.to, e.fold, e.bifurcation),
            (node, from, to, false, false)
        );
    }
    assert_eq!(ev[0].transition, ev[1].transition);
    assert_eq!(ev[2].transition, ev[3].transition);
    assert_ne!(ev[0].transition, ev[2].transition);
    assert_eq!(ev[0].alpha, ev[1].alpha);
    assert_eq!(ev[2].alpha, ev[3].alpha);
    assert!(vclose(
        &lambda_ev(&ev[3]),
        &lam(&[-2.0, -2.0, -1.0, -1.0]),
        TOL
    ));
    check_events(&data, &mut path);
    let classes: Vec<Vec<Class>> = path.pieces().iter().map(|p| p.classes.clone()).collect();
    assert_eq!(
        classes,
        vec![
            vec![Class::Open, Class::Open],
            vec![Class::SlipPlus, Class::SlipPlus],
            vec![Class::Stick, Class::Stick]
        ]
    );

    let br = Brute::new(&data);
    for alpha in [-0.5, 0.3, 1.0, 1.7, 2.5, 2.9] {
        let want = if alpha < 0.0 {
            lam(&[0.0; 4])
        } else if alpha < 2.0 {
            lam(&[-alpha, -alpha, -alpha / 2.0, -alpha / 2.0])
        } else {
            lam(&[-alpha, -alpha, -1.0, -1.0])
        };
        let sols = path.solutions_at(alpha).unwrap();
        assert_eq!(sols.len(), 1, "α = {alpha}: {sols:#?}");
        assert!(
            vclose(&lambda_of(&sols[0].state), &want, TOL),
            "α = {alpha}: {:?}",
            sols[0].state
        );
        // brute force: the hand solution is the only one
        let bs = br.solutions_at(alpha);
        assert_eq!(bs.len(), 1, "brute force at α = {alpha}: {bs:?}");
        assert!(vclose(&bs[0].1, &want, 1e-13));
    }
}

/// (c′) A node touching down with `dt = 0` exactly enters Stick, not S± (SPEC §3: decided
/// by the entering rule, not by the sign of a rounding error).
///
/// Data: `one_node` with `F = 0.5`, `f0 = 0`, `f1 = (1, 0.5, 0)`: `q = α (1, −0.5)`.
/// At α = 0, λ = 0 and `d = 0`: every contact piece contains the point.
/// * Stick: `λ = −W⁻¹ q = −α (2·1 − 0.5, 1 − 0.5) = (−1.5α, −0.5α)`; guards
///   `λν < 0` ↔ α > 0, `|λt| = 0.5α < −Fλν = 0.75α`: enters for α > 0.
/// * S+: `λν = −qν / (w₁₁ + F w₁₂) = −α/0.5 = −2α`, `dt = qt + (w₁₂ + F w₂₂) λν = −0.5α`,
///   must be > 0 with α > 0: no.
/// * S−: `λν = −α/(1 + 0.5) = −2α/3`, `dt = −0.5α + (−1 − 1)(−2α/3) = (5/6)α`, must be
///   < 0 with α > 0: no.
///
/// One event: α = 0, node 0, open → stick; then stick up to α = 1.
#[test]
fn touch_down_with_zero_slip_enters_stick() {
    let data = one_node(0.5, [0.0, 0.0, 0.0], [1.0, 0.5, 0.0]);
    let problem = Arc::new(data.problem());
    let mut path = trace(problem, data.affine_load(), -1.0, 1.0);
    assert_eq!(path.end_reason(), Some(&EndReason::Window));
    let ev = path.events();
    assert_eq!(ev.len(), 1, "events: {ev:#?}");
    assert!(close(ev[0].alpha, 0.0, TOL));
    assert_eq!(
        (ev[0].node, ev[0].from, ev[0].to, ev[0].fold),
        (0, Class::Open, Class::Stick, false)
    );
    check_events(&data, &mut path);
    let sols = path.solutions_at(0.6).unwrap();
    assert_eq!(sols.len(), 1);
    assert!(vclose(&lambda_of(&sols[0].state), &lam(&[-0.9, -0.3]), TOL));
    let br = Brute::new(&data);
    let bs = br.solutions_at(0.6);
    assert_eq!(bs.len(), 1);
    assert!(vclose(&bs[0].1, &lam(&[-0.9, -0.3]), 1e-13));
}
