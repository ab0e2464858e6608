//! r-invariance: solutions and transition points do not
//! depend on the augmentation parameter r (SPEC §1). The same problems are traced with
//! `Problem::with_r(s · default_r)` for s = 1e-3, 1, 1e3; the events must agree (α to
//! 1e-12 relative, same nodes, classes and flags), and agree with the independent
//! expectation (hand derivation or brute-force walk).

mod common;

use std::sync::Arc;

use common::{
    Brute, Data, close, fold_problem, lambda_ev, lambda_of, mirror_pair, random_case, trace,
    vertical_problem,
};
use fricont::{Class, Event, Problem};

const TOL: f64 = 1e-12;

type Expected = Vec<(f64, usize, Class, Class, bool)>;

fn same_events(ctx: &str, a: &[Event], b: &[Event]) {
    assert_eq!(a.len(), b.len(), "{ctx}: {a:#?} vs {b:#?}");
    for (x, y) in a.iter().zip(b) {
        assert!(
            close(x.alpha, y.alpha, TOL),
            "{ctx}: α {:.17e} vs {:.17e}",
            x.alpha,
            y.alpha
        );
        assert_eq!(
            (x.node, x.from, x.to, x.fold, x.bifurcation, x.transition),
            (y.node, y.from, y.to, y.fold, y.bifurcation, y.transition),
            "{ctx}"
        );
        let d = (lambda_ev(x) - lambda_ev(y)).amax();
        assert!(
            d <= 1e-9 * 1f64.max(lambda_ev(x).amax()),
            "{ctx}: λ differs by {d:e}"
        );
    }
}

fn check(ctx: &str, data: &Data, a0: f64, a1: f64, expected: Option<&Expected>) {
    let base: Problem = data.problem();
    let r0 = base.default_r();
    assert!(r0 > 0.0 && r0.is_finite());
    assert_eq!(base.r(), r0, "{ctx}: r defaults to default_r");
    let mut runs = Vec::new();
    for s in [1e-3, 1.0, 1e3] {
        let pr = base.with_r(s * r0).unwrap();
        assert_eq!(pr.r(), s * r0);
        let path = trace(Arc::new(pr), data.affine_load(), a0, a1);
        for e in &common::events_with_state(&path) {
            assert!(
                e.state.residual <= TOL,
                "{ctx}, r = {s}·r0: residual {:e}",
                e.state.residual
            );
        }
        if let Some(x) = expected {
            let ev = path.events();
            assert_eq!(ev.len(), x.len(), "{ctx}, r = {s}·r0: {ev:#?}");
            for (e, x) in ev.iter().zip(x) {
                assert!(
                    close(e.alpha, x.0, TOL),
                    "{ctx}, r = {s}·r0: α {:.17e} expected {:.17e}",
                    e.alpha,
                    x.0
                );
                assert_eq!(
                    (e.node, e.from, e.to, e.fold),
                    (x.1, x.2, x.3, x.4),
                    "{ctx}, r = {s}·r0"
                );
            }
        }
        runs.push((s, path));
    }
    for (s, p) in &runs[1..] {
        same_events(
            &format!("{ctx}: r = 1·r0 vs r = {s}·r0"),
            runs[0].1.events(),
            p.events(),
        );
        assert_eq!(runs[0].1.end_reason(), p.end_reason(), "{ctx}");
        let c0: Vec<_> = runs[0]
            .1
            .pieces()
            .iter()
            .map(|p| p.classes.clone())
            .collect();
        let c1: Vec<_> = p.pieces().iter().map(|p| p.classes.clone()).collect();
        assert_eq!(c0, c1, "{ctx}");
    }
}

#[test]
fn r_invariance_hand_problems() {
    // expected events: derivations in core_hand.rs
    let fold = vec![
        (0.0, 0, Class::Open, Class::SlipPlus, true),
        (-2.0, 0, Class::SlipPlus, Class::Stick, true),
        (1.2, 0, Class::Stick, Class::SlipMinus, false),
    ];
    check("fold problem", &fold_problem(), -3.0, 3.0, Some(&fold));
    let vertical = vec![
        (0.25, 0, Class::Open, Class::SlipPlus, false),
        (0.25, 0, Class::SlipPlus, Class::Stick, false),
    ];
    check(
        "vertical problem",
        &vertical_problem(),
        -1.0,
        1.0,
        Some(&vertical),
    );
    let mirror = vec![
        (0.0, 0, Class::Open, Class::SlipPlus, false),
        (0.0, 1, Class::Open, Class::SlipPlus, false),
        (2.0, 0, Class::SlipPlus, Class::Stick, false),
        (2.0, 1, Class::SlipPlus, Class::Stick, false),
    ];
    check("mirror pair", &mirror_pair(), -1.0, 3.0, Some(&mirror));
}

#[test]
fn r_invariance_random_problems() {
    for seed in 0..30u64 {
        let case = random_case(seed);
        let data = &case.data;
        let br = Brute::new(data);
        let mut p = fricont::Path::new(
            Arc::new(data.problem()),
            data.affine_load(),
            fricont::PathOptions::window(case.a0, case.a1),
        )
        .unwrap();
        p.start(case.a0, None).unwrap();
        let start = lambda_of(&p.start_state().unwrap());
        let expected: Option<Expected> = br.walk(case.a0, case.a1, &start).map(|w| {
            w.events
                .iter()
                .map(|e| (e.phi, e.node, e.from, e.to, e.fold))
                .collect()
        });
        check(
            &format!("seed {seed}"),
            data,
            case.a0,
            case.a1,
            expected.as_ref(),
        );
    }
}
