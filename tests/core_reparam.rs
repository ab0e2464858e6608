//! Reparametrisation: tracing f(α) and f(φ(α)) gives the same transition points mapped by φ.
//!
//! With `f(β) = f0 + φ(β) f1`, `φ(β) = β³ + β` (strictly increasing), the solution set at
//! β is the affine problem's solution set at α = φ(β). So the traced events must be at
//! `β_k = φ⁻¹(α_k)` with the same nodes, classes and fold flags, where `α_k` are the
//! affine events. The α_k come from the independent brute-force walk of `tests/common`
//! (and from the hand derivation for the fold problem); the library's own affine path must
//! agree with them too. The load is given three ways: `Load::basis` with vectors
//! `[f0, f1]`, weights `(1, φ)` and derivatives `(0, φ')`; `Load::general` with the
//! derivative; `Load::general` without it (finite differences, used only for steps).

mod common;

use std::sync::Arc;

use common::{Brute, Data, close, fold_problem, lambda_ev, lambda_of, random_case, trace};
use fricont::load::{LoadFailure, VectorFn};
use fricont::{Class, Load, Problem};

const TOL: f64 = 1e-12;

fn phi(b: f64) -> f64 {
    b * b * b + b
}
fn dphi(b: f64) -> f64 {
    3.0 * b * b + 1.0
}
/// `φ⁻¹(y)` by Newton's method from `y / (1 + |y|^{2/3})`, polished to a fixed point.
fn phi_inv(y: f64) -> f64 {
    let mut b = y.signum() * y.abs().cbrt().min(y.abs());
    for _ in 0..100 {
        let nb = b - (phi(b) - y) / dphi(b);
        if nb == b {
            break;
        }
        b = nb;
    }
    b
}

fn loads(data: &Data) -> Vec<(&'static str, Load)> {
    let (f0, f1) = (data.f0.as_slice().to_vec(), data.f1.as_slice().to_vec());
    let basis = Load::basis(
        vec![f0.clone(), f1.clone()],
        Box::new(
            |b: f64, w: &mut [f64], dw: &mut [f64]| -> Result<(), LoadFailure> {
                w[0] = 1.0;
                w[1] = phi(b);
                dw[0] = 0.0;
                dw[1] = dphi(b);
                Ok(())
            },
        ),
    )
    .unwrap();
    let mk_f = |f0: Vec<f64>, f1: Vec<f64>| -> VectorFn {
        Box::new(move |b: f64, out: &mut [f64]| {
            let s = phi(b);
            for ((o, a), b) in out.iter_mut().zip(&f0).zip(&f1) {
                *o = a + s * b;
            }
            Ok(())
        })
    };
    let f1d = f1.clone();
    let df: VectorFn = Box::new(move |b: f64, out: &mut [f64]| {
        let s = dphi(b);
        for (o, b) in out.iter_mut().zip(&f1d) {
            *o = s * b;
        }
        Ok(())
    });
    let n = f0.len();
    vec![
        ("basis", basis),
        (
            "general with f'",
            Load::general(n, mk_f(f0.clone(), f1.clone()), Some(df)),
        ),
        ("general without f'", Load::general(n, mk_f(f0, f1), None)),
    ]
}

/// Expected affine events `(α, node, from, to, fold)`.
type Expected = Vec<(f64, usize, Class, Class, bool)>;

fn check_reparam(
    ctx: &str,
    data: &Data,
    problem: Arc<Problem>,
    a0: f64,
    a1: f64,
    expected: &Expected,
) {
    // The library's affine path agrees with the independent expectation.
    let affine = trace(problem.clone(), data.affine_load(), a0, a1);
    let ev = affine.events();
    assert_eq!(ev.len(), expected.len(), "{ctx}: affine events {ev:#?}");
    for (e, x) in ev.iter().zip(expected) {
        assert!(
            close(e.alpha, x.0, TOL),
            "{ctx}: affine event α {:.17e} expected {:.17e}",
            e.alpha,
            x.0
        );
        assert_eq!(
            (e.node, e.from, e.to, e.fold),
            (x.1, x.2, x.3, x.4),
            "{ctx}"
        );
    }
    let (b0, b1) = (phi_inv(a0), phi_inv(a1));
    for (name, load) in loads(data) {
        let path = trace(problem.clone(), load, b0, b1);
        assert_eq!(path.end_reason(), affine.end_reason(), "{ctx}, {name}");
        let ev = common::events_with_state(&path);
        assert_eq!(ev.len(), expected.len(), "{ctx}, {name}: events {ev:#?}");
        for (k, (e, x)) in ev.iter().zip(expected).enumerate() {
            let want = phi_inv(x.0);
            assert!(
                close(e.alpha, want, TOL),
                "{ctx}, {name}: event {k} at β = {:.17e}, expected φ⁻¹({:.17e}) = {want:.17e} (diff {:e})",
                e.alpha,
                x.0,
                e.alpha - want
            );
            // and against the library's own affine path
            assert!(
                close(e.alpha, phi_inv(affine.events()[k].alpha), TOL),
                "{ctx}, {name}: event {k}"
            );
            assert_eq!(
                (e.node, e.from, e.to, e.fold),
                (x.1, x.2, x.3, x.4),
                "{ctx}, {name}: event {k}"
            );
            assert!(
                e.state.residual <= TOL,
                "{ctx}, {name}: residual {:e}",
                e.state.residual
            );
            // the state equals the affine state at α = φ(β)
            let a = &affine.events()[k];
            let d = (lambda_ev(e) - lambda_ev(a)).amax();
            assert!(
                d <= 1e-9 * 1f64.max(lambda_ev(a).amax()),
                "{ctx}, {name}: λ differs by {d:e}"
            );
        }
    }
}

#[test]
fn reparametrised_fold_problem() {
    // Hand-derived events of core_hand.rs::two_folds_three_solutions.
    let data = fold_problem();
    let expected = vec![
        (0.0, 0, Class::Open, Class::SlipPlus, true),
        (-2.0, 0, Class::SlipPlus, Class::Stick, true),
        (1.2, 0, Class::Stick, Class::SlipMinus, false),
    ];
    check_reparam(
        "fold problem",
        &data,
        Arc::new(data.problem()),
        -3.0,
        3.0,
        &expected,
    );
}

#[test]
fn reparametrised_random_problems() {
    let mut done = 0;
    for seed in 0..24u64 {
        let case = random_case(seed);
        let data = &case.data;
        let problem = Arc::new(data.problem());
        let br = Brute::new(data);
        // the brute-force walk from the affine path's start point
        let mut start_path = fricont::Path::new(
            problem.clone(),
            data.affine_load(),
            fricont::PathOptions::window(case.a0, case.a1),
        )
        .unwrap();
        start_path.start(case.a0, None).unwrap();
        let start = lambda_of(&start_path.start_state().unwrap());
        let Some(walk) = br.walk(case.a0, case.a1, &start) else {
            continue;
        };
        if walk.closed {
            continue;
        }
        let expected: Expected = walk
            .events
            .iter()
            .map(|e| (e.phi, e.node, e.from, e.to, e.fold))
            .collect();
        check_reparam(
            &format!("seed {seed}"),
            data,
            problem,
            case.a0,
            case.a1,
            &expected,
        );
        done += 1;
    }
    assert!(done >= 18, "only {done} random cases compared");
}

/// The affine load `f0 + α f1` written in another basis, `[f0, f0 + ε f1]` with weights
/// `(1 − α/ε, α/ε)`: the weights are 1/ε times the load and cancel, so the condensed load
/// (and anything combined from per-vector solutions) carries 1/ε times the rounding of
/// the affine one. The transition points must be those of the affine path, to what a
/// direct solve at each α gives, on both tracers. Measured worst differences: ε = 1e-2,
/// 5.6e-11 (updated) and 4.5e-11 (fresh); ε = 1e-4, 8.8e-9 and 5.9e-9. With roots taken
/// from the basis solutions' combination without a second look at the data, an updated
/// path at ε = 1e-2 stopped ("no neighbouring piece continues the path"); with the join's
/// tolerances from the term magnitudes of the last-evaluated α only, a fresh one at
/// ε = 1e-4 did.
#[test]
fn a_basis_whose_weights_cancel() {
    let mut cases: Vec<common::Case> = (0..100).map(random_case).collect();
    cases.extend((0..60u64).map(|s| {
        let (nx, ny) = (3 + (s % 20) as usize, 1 + ((s / 3) % 3) as usize);
        common::fe_case(s, nx, ny, [0.3, 1.0, 3.0, 5.0][(s % 4) as usize])
    }));
    // About five times the measured worst (rounding differs between machines).
    for (eps, tol) in [(1e-2, 3e-10), (1e-4, 5e-8)] {
        for fresh in [false, true] {
            let mut worst = 0f64;
            let mut events = 0;
            for (k, case) in cases.iter().enumerate() {
                let data = &case.data;
                let problem = Arc::new(data.problem());
                let affine = trace(problem.clone(), data.affine_load(), case.a0, case.a1);
                let (f0, f1) = (data.f0.as_slice().to_vec(), data.f1.as_slice().to_vec());
                let g: Vec<f64> = f0.iter().zip(&f1).map(|(a, b)| a + eps * b).collect();
                let weights = move |a: f64, w: &mut [f64], dw: &mut [f64]| {
                    w[0] = 1.0 - a / eps;
                    w[1] = a / eps;
                    dw[0] = -1.0 / eps;
                    dw[1] = 1.0 / eps;
                    Ok::<(), LoadFailure>(())
                };
                let load = Load::basis(vec![f0, g], Box::new(weights)).unwrap();
                let mut opts = fricont::PathOptions::window(case.a0, case.a1);
                opts.fresh_factorisations = fresh;
                let mut path = fricont::Path::new(problem, load, opts).unwrap();
                let ctx = format!("ε = {eps:e}, fresh {fresh}, case {k} (seed {})", case.seed);
                path.start(case.a0, None).expect(&ctx);
                path.run().expect(&ctx);
                assert_eq!(path.end_reason(), affine.end_reason(), "{ctx}");
                let (x, y) = (affine.events(), path.events());
                assert_eq!(x.len(), y.len(), "{ctx}: events");
                for (a, b) in x.iter().zip(y) {
                    assert_eq!(
                        (a.node, a.from, a.to, a.fold),
                        (b.node, b.from, b.to, b.fold),
                        "{ctx}: event {}",
                        a.index + 1
                    );
                    worst = worst.max((a.alpha - b.alpha).abs() / 1f64.max(a.alpha.abs()));
                }
                events += x.len();
            }
            assert!(events > 1000, "only {events} events compared");
            assert!(
                worst <= tol,
                "ε = {eps:e}, fresh {fresh}: worst α difference {worst:e}"
            );
        }
    }
}
