//! Degenerate transitions and non-smooth bifurcations on random mirror-symmetric problems
//! (SPEC §3: "a symmetric body under a symmetric load switches mirrored nodes at the same
//! α, and a node at the axis of symmetry touches down with dt = 0 exactly, so it enters
//! ST, not S±").
//!
//! Every transition point the library reports is checked against the independent
//! enumeration of `tests/common`: the pieces whose closure contains the point, less the
//! piece the path came from, are exactly the continuations. So a transition not flagged
//! as a bifurcation must have exactly one such piece, the one the path took; one flagged
//! as a bifurcation must offer exactly those pieces in `branches()`. After a bifurcation
//! where the library stops (`EndReason::Bifurcation`), `choose_branch` is exercised, on
//! every candidate index in turn, and the path is checked on along the chosen branch.
//! While the traced solution is symmetric, mirrored nodes switch together (same α, same
//! classes, one event per node in node order) and the centre node is never in slip.

mod common;

use std::collections::BTreeSet;
use std::sync::Arc;

use common::{
    Brute, Case, check_state, class_equations_hold, lambda_ev, lambda_of, mirror_class, samples,
    symmetric_case, vclose,
};
use fricont::{Class, EndReason, Path, PathOptions, StepOutcome};

#[derive(Default, Debug)]
struct Stats {
    transitions: usize,
    degenerate: usize,
    bifurcations: usize,
    stopped: usize,
    centre_touchdowns: usize,
    /// Stops where branch 0, 1, 2 or a later one was chosen.
    chosen: [usize; 3],
}

fn set(v: &[Vec<Class>]) -> BTreeSet<Vec<Class>> {
    v.iter().cloned().collect()
}

fn check_case(case: &Case, st: &mut Stats) {
    let data = &case.data;
    let p = data.p;
    let br = Brute::new(data);
    let ctx = format!(
        "symmetric seed {} (p = {p}, F = {:?}, window [{}, {}])",
        case.seed, data.friction, case.a0, case.a1
    );
    let mut path = Path::new(
        Arc::new(data.problem()),
        data.affine_load(),
        PathOptions::window(case.a0, case.a1),
    )
    .unwrap();
    path.start(case.a0, None)
        .unwrap_or_else(|e| panic!("{ctx}: start: {e}"));
    let mut prev = path.start_state().unwrap().classes.clone();
    for _ in 0..200 {
        let out = path.step().unwrap_or_else(|e| panic!("{ctx}: step: {e}"));
        let (range, bif, offered) = match out {
            StepOutcome::Transition {
                events,
                bifurcation,
                ..
            } => (events, bifurcation, path.branches().to_vec()),
            StepOutcome::End(EndReason::Bifurcation) => {
                st.stopped += 1;
                let offered = path.branches().to_vec();
                assert!(
                    offered.len() >= 2,
                    "{ctx}: stopped at a bifurcation with {} branches",
                    offered.len()
                );
                let before = path.events().len();
                // Every candidate index is taken somewhere: the seed and the stops so far
                // pick it.
                let k = (case.seed as usize + st.stopped) % offered.len();
                path.choose_branch(k)
                    .unwrap_or_else(|e| panic!("{ctx}: choose_branch({k}): {e}"));
                assert_eq!(
                    path.pieces().last().unwrap().classes,
                    offered[k].classes,
                    "{ctx}: chosen branch"
                );
                st.chosen[k.min(2)] += 1;
                (before..path.events().len(), true, offered)
            }
            StepOutcome::End(_) => break,
        };
        st.transitions += 1;
        let all = common::events_with_state(&path);
        let ev = &all[range.clone()];
        assert!(!ev.is_empty(), "{ctx}: a transition without events");
        let e0 = &ev[0];
        for e in ev {
            assert_eq!(
                (e.alpha, e.transition),
                (e0.alpha, e0.transition),
                "{ctx}: one transition, one α"
            );
            assert_eq!(e.bifurcation, bif, "{ctx}");
        }
        assert!(
            ev.windows(2).all(|w| w[0].node < w[1].node),
            "{ctx}: events not in node order: {ev:#?}"
        );
        if ev.len() > 1 {
            st.degenerate += 1;
        }
        let new = path.pieces().last().unwrap().classes.clone();
        for e in ev {
            assert_eq!(
                (prev[e.node], new[e.node]),
                (e.from, e.to),
                "{ctx}: event classes"
            );
            class_equations_hold(data, &e.state, e.node, e.from, 1e-9)
                .unwrap_or_else(|m| panic!("{ctx}: {m}"));
            class_equations_hold(data, &e.state, e.node, e.to, 1e-9)
                .unwrap_or_else(|m| panic!("{ctx}: {m}"));
            assert!(
                e.state.residual <= 1e-12,
                "{ctx}: residual {:e}",
                e.state.residual
            );
        }
        for i in 0..p {
            if ev.iter().all(|e| e.node != i) {
                assert_eq!(
                    prev[i], new[i],
                    "{ctx}: node {i} changed class without an event"
                );
            }
        }
        // the continuations by enumeration
        let lam = lambda_ev(e0);
        let mut expected = br.incident(e0.alpha, &lam, 1e-9);
        expected.retain(|c| *c != prev);
        if bif {
            st.bifurcations += 1;
            let got: Vec<Vec<Class>> = offered.iter().map(|b| b.classes.clone()).collect();
            assert_eq!(
                set(&got),
                set(&expected),
                "{ctx}: bifurcation at α = {}: branches",
                e0.alpha
            );
            assert!(expected.contains(&new), "{ctx}");
        } else {
            assert_eq!(
                expected,
                vec![new.clone()],
                "{ctx}: transition at α = {} (from {prev:?})",
                e0.alpha
            );
        }
        // symmetry while the solution is symmetric
        let s = &e0.state;
        let symmetric = (s.lambda_n[0] - s.lambda_n[1]).abs() <= 1e-9 * (1.0 + s.lambda_n[0].abs())
            && (s.lambda_t[0] - s.lambda_t[1]).abs() <= 1e-9 * (1.0 + s.lambda_t[0].abs());
        if symmetric && !bif && prev[0] == prev[1] {
            assert_eq!(
                new[0], new[1],
                "{ctx}: mirrored nodes split at a non-bifurcation point α = {}",
                e0.alpha
            );
            if p == 3 {
                assert!(
                    !matches!(new[2], Class::SlipPlus | Class::SlipMinus),
                    "{ctx}: centre node slips: {new:?} at α = {}",
                    e0.alpha
                );
                if ev.iter().any(|e| e.node == 2 && e.from == Class::Open) {
                    st.centre_touchdowns += 1;
                }
            }
        }
        prev = new;
    }
    // solutions at sampled α are solutions (containment in the enumeration)
    for alpha in samples(case, &br, 6, 1e-6) {
        let all = br.solutions_at(alpha);
        for s in path.solutions_at(alpha).unwrap() {
            let l = lambda_of(&s.state);
            assert!(
                all.iter()
                    .any(|(c, b)| *c == s.state.classes && vclose(b, &l, 1e-9)),
                "{ctx}: solutions_at({alpha}) gave {:?}, not a solution",
                s.state
            );
            check_state(data, &data.force(alpha), &s.state, 1e-9).unwrap();
        }
    }
}

#[test]
fn mirror_pairs() {
    let mut st = Stats::default();
    for seed in 0..300u64 {
        check_case(&symmetric_case(seed, false), &mut st);
    }
    eprintln!("{st:?}");
    assert!(
        st.degenerate >= 150 && st.bifurcations >= 10 && st.chosen.iter().all(|&c| c > 0),
        "{st:?}"
    );
}

#[test]
fn mirror_pairs_with_centre_node() {
    let mut st = Stats::default();
    for seed in 1000..1300u64 {
        check_case(&symmetric_case(seed, true), &mut st);
    }
    eprintln!("{st:?}");
    assert!(
        st.degenerate >= 150
            && st.centre_touchdowns >= 20
            && st.bifurcations >= 10
            && st.chosen.iter().all(|&c| c > 0),
        "{st:?}"
    );
}

/// The mirror-symmetric finite-element body of `seed` ([`common::symmetric_fe_case`],
/// 4–27 × 1–4 elements, F from 0.1 to 5), its last contact node's index nx (the nodes are
/// 0 … nx), and a description for messages.
fn mirror_body(seed: u64) -> (Case, usize, String) {
    let mut rng = common::Rng::new(seed);
    let nx = 2 * (2 + rng.int(0, 11)) + (seed % 2) as usize;
    let ny = rng.int(1, 4);
    let friction = [0.1, 0.3, 0.8, 1.5, 3.0, 5.0][rng.int(0, 5)];
    let case = common::symmetric_fe_case(seed, nx, ny, friction);
    (
        case,
        nx,
        format!("seed {seed} (nx = {nx}, ny = {ny}, F = {friction})"),
    )
}

/// On a mirror-symmetric body with contact nodes 0 … nx: every event of a node off the
/// axis has its mirror image (node nx − i, the same α to 1e-9, S+ and S− swapped), and the
/// centre node never enters slip. Returns the number of events off the axis.
fn assert_mirrored(ctx: &str, ev: &[(f64, usize, Class, Class)], nx: usize) -> usize {
    let mut pairs = 0;
    for &(al, i, from, to) in ev {
        if 2 * i == nx {
            assert!(
                !matches!(to, Class::SlipPlus | Class::SlipMinus),
                "{ctx}: the centre node enters {to} at α = {al}"
            );
            continue;
        }
        assert!(
            ev.iter().any(|&(b, j, f, t)| j == nx - i
                && (b - al).abs() <= 1e-9 * al.abs().max(1.0)
                && (f, t) == (mirror_class(from), mirror_class(to))),
            "{ctx}: node {} {from} -> {to} at α = {al} has no mirror image",
            i + 1
        );
        pairs += 1;
    }
    pairs
}

/// The basis load `f0 + 2 sin(50 α) f1` of `case` and the end of its window, two periods
/// from α = 0.
fn oscillating_load(case: &Case) -> (fricont::Load, f64) {
    let omega = 50.0;
    let weights = move |a: f64, w: &mut [f64], dw: &mut [f64]| {
        w[0] = 1.0;
        w[1] = 2.0 * (omega * a).sin();
        dw[0] = 0.0;
        dw[1] = 2.0 * omega * (omega * a).cos();
        Ok::<(), fricont::load::LoadFailure>(())
    };
    let fs = vec![
        case.data.f0.as_slice().to_vec(),
        case.data.f1.as_slice().to_vec(),
    ];
    let load = fricont::Load::basis(fs, Box::new(weights)).expect("basis load");
    (load, 4.0 * std::f64::consts::PI / omega)
}

/// The load of [`oscillating_load`] as a general load, `f(α)` itself (condensed by the
/// solver at every α instead of once per basis vector).
fn oscillating_general_load(case: &Case) -> fricont::Load {
    let omega = 50.0;
    let (f0, f1) = (
        case.data.f0.as_slice().to_vec(),
        case.data.f1.as_slice().to_vec(),
    );
    let df1 = f1.clone();
    fricont::Load::general(
        f0.len(),
        Box::new(move |a: f64, out: &mut [f64]| {
            let s = 2.0 * (omega * a).sin();
            for ((o, x), y) in out.iter_mut().zip(&f0).zip(&f1) {
                *o = x + s * y;
            }
            Ok(())
        }),
        Some(Box::new(move |a: f64, out: &mut [f64]| {
            let s = 2.0 * omega * (omega * a).cos();
            for (o, y) in out.iter_mut().zip(&df1) {
                *o = s * y;
            }
            Ok(())
        })),
    )
}

/// Mirror-symmetric finite-element bodies under an oscillating load: the body and load
/// family of [`mirror_symmetric_finite_element_bodies`] with the basis load `f0 +
/// 2 sin(50 α) f1` over two periods (the symmetric press held, the symmetric bump and
/// the antisymmetric shear swept back and forth), traced to the window's end or to a
/// non-smooth bifurcation: the events keep their mirror images and the centre node never
/// slips. (Against the reference's affine events walked through the sine, a sweep of 80
/// such bodies agreed to 2.5e-13 in φ.)
#[test]
fn mirror_symmetric_bodies_under_an_oscillating_load() {
    let (mut windows, mut pairs) = (0, 0);
    for seed in 0..24u64 {
        let (case, nx, ctx) = mirror_body(seed);
        let data = &case.data;
        let (load, a1) = oscillating_load(&case);
        let mut path =
            Path::new(Arc::new(data.problem()), load, PathOptions::window(0.0, a1)).expect("path");
        path.start(0.0, None).expect("start");
        path.run().unwrap_or_else(|e| panic!("{ctx}: {e}"));
        match path.end_reason() {
            Some(EndReason::Window) => windows += 1,
            Some(EndReason::Bifurcation) => {}
            r => panic!("{ctx}: ends with {r:?}"),
        }
        let ev = common::reference::path_events(&path);
        pairs += assert_mirrored(&ctx, &ev, nx);
    }
    eprintln!("{windows} windows, {pairs} mirrored events");
    assert!(
        windows >= 18 && pairs >= 1000,
        "{windows} windows, {pairs} events"
    );
}

/// Mirror-symmetric finite-element bodies ([`common::symmetric_fe_case`]): W comes from
/// the condensation of A, so it is mirror-symmetric only to rounding, and no rounding error
/// may decide a class (SPEC §3). Checked on every case:
/// - each event of a node off the axis has its mirror image: the mirrored node, the same
///   α to 1e-9, the classes mirrored (S+ and S− swap);
/// - the centre node never enters slip (on the symmetric path its λt is 0);
/// - against the independent reference tracer of `tests/common/reference.rs` (dense, a
///   fresh factorisation per piece, its own condensation): the same events to 1e-8 up to
///   where fricont stops; a stop is at a non-smooth bifurcation, where the reference
///   either stops too (several continuations fit) or goes on along one branch, its next
///   transition at the same α.
#[test]
fn mirror_symmetric_finite_element_bodies() {
    use common::reference::{compare_case, compare_events};
    let (mut windows, mut stops, mut pairs) = (0, 0, 0);
    for seed in 0..30u64 {
        let (case, nx, ctx) = mirror_body(seed);
        let data = &case.data;
        let c = compare_case(&case, Arc::new(data.problem()), 1e-8);
        assert!(
            c.start_diff <= 1e-8,
            "{ctx}: start λ differ by {:e}",
            c.start_diff
        );
        let ev = &c.fricont;
        pairs += assert_mirrored(&ctx, ev, nx);
        let want = c.reference.evs();
        let (end_alpha, reason) = &c.fricont_end;
        match reason.as_str() {
            "window" => {
                assert!(c.reference.end.is_ok(), "{ctx}: {:?}", c.reference.end);
                compare_events(ev, &want, 1e-8).unwrap_or_else(|e| panic!("{ctx}: {e}"));
                windows += 1;
            }
            "bifurcation" => {
                assert!(
                    want.len() >= ev.len(),
                    "{ctx}: the reference stopped earlier"
                );
                compare_events(ev, &want[..ev.len()], 1e-8)
                    .unwrap_or_else(|e| panic!("{ctx}: {e}"));
                let next = want.get(ev.len()).map_or(c.reference.end_alpha, |e| e.0);
                assert!(
                    (next - end_alpha).abs() <= 1e-8 * end_alpha.abs().max(1.0),
                    "{ctx}: fricont stops at a bifurcation at α = {end_alpha}, the reference \
                     goes on to α = {next} ({:?})",
                    c.reference.end
                );
                stops += 1;
            }
            r => panic!("{ctx}: fricont ends with {r} at α = {end_alpha}"),
        }
    }
    eprintln!("{windows} windows, {stops} bifurcation stops, {pairs} mirrored events");
    assert!(
        windows >= 10 && stops >= 2 && pairs >= 200,
        "{windows} {stops} {pairs}"
    );
}

/// Mirror-symmetric finite-element bodies of 100–151 contact nodes in double precision
/// ([`fricont::ExtendedPrecision::Off`]). W and q are then mirror-symmetric to about
/// κ(A) ε only (the element matrices themselves are, to their rounding), so mirrored nodes
/// switch up to 1e-9 apart in α instead of together, and the node on the axis touches
/// down with a tangential displacement of that size instead of 0. Each case must trace
/// its window: no "no neighbouring piece continues the path" at the node on the axis or
/// at a mirrored pair, and no event flagged as a bifurcation (the piece before a piece a
/// rounding long is the way the path came). Checked against the independent reference
/// tracer (its own condensation in double): the same events to 1e-8; and mirrored.
#[test]
fn mirror_symmetric_bodies_in_double_precision() {
    use common::reference::{compare_case, compare_events};
    let cases = [
        (2u64, 100usize, 3usize, 0.3),
        (2, 150, 3, 0.3),
        (5, 151, 2, 1.5),
        (7, 120, 1, 5.0),
        (11, 101, 4, 0.8),
    ];
    let mut pairs = 0;
    for (seed, nx, ny, friction) in cases {
        let ctx = format!("seed {seed} (nx = {nx}, ny = {ny}, F = {friction}, double)");
        let case = common::symmetric_fe_case(seed, nx, ny, friction);
        let data = &case.data;
        let problem = data
            .builder()
            .extended_precision(fricont::ExtendedPrecision::Off)
            .build()
            .expect("problem");
        assert!(!problem.extended_precision(), "{ctx}: refined");
        let problem = Arc::new(problem);
        // The flags, from a trace of fricont's own.
        let mut path = Path::new(
            problem.clone(),
            data.affine_load(),
            PathOptions::window(case.a0, case.a1),
        )
        .expect("path");
        path.start(case.a0, None).expect("start");
        path.run().unwrap_or_else(|e| panic!("{ctx}: {e}"));
        assert_eq!(
            path.end_reason(),
            Some(&EndReason::Window),
            "{ctx}: ends early"
        );
        if let Some(e) = path.events().iter().find(|e| e.bifurcation) {
            panic!(
                "{ctx}: node {} {} -> {} at α = {} flagged as a bifurcation",
                e.node + 1,
                e.from,
                e.to,
                e.alpha
            );
        }
        let c = compare_case(&case, problem, 1e-8);
        assert!(c.reference.end.is_ok(), "{ctx}: {:?}", c.reference.end);
        let want = c.reference.evs();
        compare_events(&c.fricont, &want, 1e-8).unwrap_or_else(|e| panic!("{ctx}: {e}"));
        pairs += assert_mirrored(&ctx, &c.fricont, nx);
    }
    eprintln!("{pairs} mirrored events");
}

/// Larger mirror-symmetric bodies in double (162–401 contact nodes; too large for the
/// dense reference), W's and q's symmetry broken by more than in the test above. Each
/// item says what its case exposed when it was added. Markers on the join's retries (a
/// scratch build, 2026-12-01) found seven of them still reaching the retry named; the
/// 162-node and the 201-node F = 5 cases no longer do (every join of theirs finds its
/// continuation at the usual thresholds) and stay as regression cases:
/// - 401 nodes: the node on the axis touches down with a tangential displacement of
///   1.6e-14 of the load's scale, below what the data determine
///   (`BoundLoad::determination`) but above the row's threshold otherwise;
/// - 162 nodes, F = 0.8: a mirrored node's contact forces 1.2e-11 of the forces apart from
///   its image's (zero_tol 1e-11), so that the class its image took does not fit it at the
///   usual thresholds (`transit`'s widened ones take it);
/// - 302 nodes, F = 5, under the oscillating load of
///   [`mirror_symmetric_bodies_under_an_oscillating_load`]: the same at two end nodes
///   lifting off together;
/// - 401 nodes, F = 0.1: the node on the axis, lifting off, reaches its stick cone 3.6e-11
///   of the forces before λ = 0 (its λt is rounding there), and slip either way fits: a
///   bifurcation at the usual thresholds, where the path stopped; the node lifts off;
/// - 401 nodes, F = 5, under the oscillating load: a mirrored node fits no class at all at
///   the usual thresholds (the error "fits no class" was returned before the widened ones
///   were tried);
/// - 61 and 201 nodes under the oscillating load given as a general load (q condensed at
///   every α, so how far the data determine it is that evaluation's own error): the node
///   on the axis touches down and no piece continued the path;
/// - 151 nodes, F = 0.1, under the oscillating load: the node on the axis touches down with
///   a tangential displacement below what the data determine but above the usual
///   threshold, so that slip fitted and stick did not (a unique continuation at the usual
///   thresholds): it slipped for 2e-12 in α before it stuck, two events for one, the
///   second flagged as a bifurcation;
/// - 201 nodes, F = 5: the two end nodes, slipping, lift off together; one reaches λ = 0
///   and its image is left with λν at 0.84 of its threshold and λt = 5 λν, beyond it, so
///   that open did not fit it and no piece continued the path.
///
/// Each must give the events of the trace refined to double-double
/// ([`fricont::ExtendedPrecision::On`]; under the basis load where the double trace's is
/// general) to 1e-8 in α, end as it ends, keep the events mirrored, and flag no
/// bifurcation where it goes on.
#[test]
fn larger_mirror_symmetric_bodies_in_double_match_extended_precision() {
    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Kind {
        Affine,
        Oscillating,
        OscillatingGeneral,
    }
    use Kind::*;
    for (seed, nx, ny, friction, kind) in [
        (2u64, 400usize, 3usize, 0.3, Affine),
        (35, 161, 4, 0.8, Affine),
        (51, 301, 2, 5.0, Oscillating),
        (55, 400, 1, 0.1, Affine),
        (51, 400, 1, 5.0, Oscillating),
        (68, 60, 4, 0.3, OscillatingGeneral),
        (53, 200, 2, 0.8, OscillatingGeneral),
        (4, 150, 1, 0.1, Oscillating),
        (235, 200, 1, 5.0, Affine),
    ] {
        let ctx = format!("seed {seed} (nx = {nx}, ny = {ny}, F = {friction}, {kind:?})");
        let case = common::symmetric_fe_case(seed, nx, ny, friction);
        let data = &case.data;
        let (a0, a1) = match kind {
            Affine => (case.a0, case.a1),
            _ => (0.0, oscillating_load(&case).1),
        };
        let trace = |mode: fricont::ExtendedPrecision| {
            let problem = data
                .builder()
                .extended_precision(mode)
                .build()
                .expect("problem");
            let load = match kind {
                Affine => data.affine_load(),
                OscillatingGeneral if mode == fricont::ExtendedPrecision::Off => {
                    oscillating_general_load(&case)
                }
                _ => oscillating_load(&case).0,
            };
            let mut path =
                Path::new(Arc::new(problem), load, PathOptions::window(a0, a1)).expect("path");
            path.start(a0, None).expect("start");
            path.run()
                .unwrap_or_else(|e| panic!("{ctx}, {mode:?}: {e}"));
            let end = path.end_reason().cloned();
            assert!(
                matches!(end, Some(EndReason::Window | EndReason::Bifurcation)),
                "{ctx}, {mode:?}: ends with {end:?}"
            );
            assert!(
                path.events().iter().all(|e| !e.bifurcation),
                "{ctx}, {mode:?}: an event flagged as a bifurcation"
            );
            let ev = common::reference::path_events(&path);
            (ev, end)
        };
        let (double, end_double) = trace(fricont::ExtendedPrecision::Off);
        let (refined, end_refined) = trace(fricont::ExtendedPrecision::On);
        assert_eq!(end_double, end_refined, "{ctx}: end");
        assert_mirrored(&ctx, &double, nx);
        // Mirrored nodes switch together in double-double and up to 1e-9 apart in
        // double, so their order within a pair may differ: each event is matched by node
        // and classes.
        assert_eq!(double.len(), refined.len(), "{ctx}: numbers of events");
        let mut used = vec![false; refined.len()];
        for &(a, i, from, to) in &double {
            let k = (0..refined.len())
                .filter(|&k| {
                    !used[k] && refined[k].1 == i && (refined[k].2, refined[k].3) == (from, to)
                })
                .min_by(|&x, &y| {
                    (refined[x].0 - a)
                        .abs()
                        .total_cmp(&(refined[y].0 - a).abs())
                })
                .unwrap_or_else(|| {
                    panic!(
                        "{ctx}: node {} {from} -> {to} at α = {a}: not in double-double",
                        i + 1
                    )
                });
            assert!(
                (refined[k].0 - a).abs() <= 1e-8 * a.abs().max(1.0),
                "{ctx}: node {} {from} -> {to}: α = {a} in double, {} in double-double",
                i + 1,
                refined[k].0
            );
            used[k] = true;
        }
    }
}

/// A mirror-symmetric body of 1002 contact nodes in double ([`common::symmetric_fe_case`]
/// seed 51, 1001 × 2 elements, F = 5) under the oscillating basis load of
/// [`oscillating_load`], over its first 4300 events (α from 0 to 0.0645). At α = 0.0634
/// one node of a mirrored pair (node 948) lifted off alone, its image's λν at zero by
/// rounding only, onto a piece of length 0; the only piece found at its end was the one
/// before it walked backwards, and the path took it: a fold that the trace in
/// double-double does not have (it has none in the load's two periods), then 2000 events
/// walked back along the path's own, to a closed loop. The way the path came across
/// pieces a rounding long is taken only where no retry of the join finds another
/// continuation (here they switch the image too): the path must reach the window's end
/// with no fold and no bifurcation flagged, every event mirrored (the body's symmetry:
/// the same α to 1e-9, S+ and S− swapped), the centre node never slipping. (Over the two
/// periods the trace in double now has the 14,432 events of double-double, α within
/// 1e-8: a scratch run of `larger_mirror_symmetric_bodies_in_double_match_extended_precision`
/// on this body, 5 minutes.)
#[test]
fn a_mirrored_pair_lifting_off_in_double_is_not_a_fold() {
    let nx = 1001;
    let ctx = "seed 51 (nx = 1001, ny = 2, F = 5, oscillating, double)";
    let ev = unflagged_in_double(ctx, (51, nx, 2, 5.0), Some(0.0645));
    let pairs = assert_mirrored(ctx, &ev, nx);
    assert!(pairs >= 4000, "{ctx}: {pairs} mirrored events");
}

/// The body `(seed, nx, ny, F)` of [`common::symmetric_fe_case`] traced in double under
/// [`oscillating_load`] from α = 0 to `a1` (`Some(a1)`), or under the case's affine load
/// over its window (`None`): the path must reach the window's end with no event flagged
/// as a fold or a bifurcation. Returns its events.
fn unflagged_in_double(
    ctx: &str,
    (seed, nx, ny, friction): (u64, usize, usize, f64),
    oscillating_to: Option<f64>,
) -> Vec<(f64, usize, Class, Class)> {
    let case = common::symmetric_fe_case(seed, nx, ny, friction);
    let problem = case
        .data
        .builder()
        .extended_precision(fricont::ExtendedPrecision::Off)
        .build()
        .expect("problem");
    let (load, a0, a1) = match oscillating_to {
        Some(a1) => (oscillating_load(&case).0, 0.0, a1),
        None => (case.data.affine_load(), case.a0, case.a1),
    };
    let mut path = Path::new(Arc::new(problem), load, PathOptions::window(a0, a1)).expect("path");
    path.start(a0, None).expect("start");
    path.run().unwrap_or_else(|e| panic!("{ctx}: {e}"));
    assert_eq!(path.end_reason(), Some(&EndReason::Window), "{ctx}");
    if let Some(e) = path.events().iter().find(|e| e.fold || e.bifurcation) {
        panic!(
            "{ctx}: event {} (node {} {} -> {} at α = {:e}) flagged as a fold or bifurcation",
            e.index,
            e.node + 1,
            e.from,
            e.to,
            e.alpha
        );
    }
    common::reference::path_events(&path)
}

/// A mirror-symmetric body of 660 contact nodes ([`common::symmetric_fe_case`] seed 107,
/// 659 × 3 elements, F = 5) under the oscillating basis load of [`oscillating_load`]: in
/// double-double the path stops after 176 events at a non-smooth bifurcation (node 89
/// and its image 572 reach their cone's edge together, three pieces continue, two of
/// them mirror images keeping the orientation). In double the two reached it 2.1e-13
/// apart (3.3 times the usual threshold; the data determine the forces to about κ(W)
/// times the condensation's error, more than that): node 89 switched alone and the path
/// went on along one of the asymmetric branches for 323 more events (nine folds), with no
/// flag. The trace in double must stop where double-double does: the same events (nodes
/// and classes; α to 1e-8), the same stop (α to 1e-8) and branches (their classes).
#[test]
fn a_symmetric_bifurcation_in_double_is_not_decided_by_rounding() {
    let nx = 659;
    let case = common::symmetric_fe_case(107, nx, 3, 5.0);
    let trace = |mode: fricont::ExtendedPrecision| {
        let ctx = format!("seed 107 (nx = 659, ny = 3, F = 5, oscillating), {mode:?}");
        let problem = case
            .data
            .builder()
            .extended_precision(mode)
            .build()
            .expect("problem");
        let (load, a1) = oscillating_load(&case);
        let mut path =
            Path::new(Arc::new(problem), load, PathOptions::window(0.0, a1)).expect("path");
        path.start(0.0, None).expect("start");
        path.run().unwrap_or_else(|e| panic!("{ctx}: {e}"));
        assert_eq!(path.end_reason(), Some(&EndReason::Bifurcation), "{ctx}");
        let ev = common::reference::path_events(&path);
        let branches: BTreeSet<Vec<Class>> =
            path.branches().iter().map(|b| b.classes.clone()).collect();
        let stop = path.current().expect("state at the stop").alpha;
        (ev, stop, branches, ctx)
    };
    let (refined, stop_r, branches_r, _) = trace(fricont::ExtendedPrecision::On);
    let (double, stop_d, branches_d, ctx) = trace(fricont::ExtendedPrecision::Off);
    assert_eq!(
        refined.len(),
        176,
        "double-double: {} events",
        refined.len()
    );
    assert_mirrored(&ctx, &double, nx);
    assert_eq!(double.len(), refined.len(), "{ctx}: numbers of events");
    // (mirrored nodes switch a rounding apart in double: matched by node and classes)
    for &(a, i, from, to) in &double {
        assert!(
            refined
                .iter()
                .any(|&(b, j, f, t)| (j, f, t) == (i, from, to)
                    && (a - b).abs() <= 1e-8 * a.abs().max(1.0)),
            "{ctx}: node {} {from} -> {to} at α = {a}: not in double-double",
            i + 1
        );
    }
    assert!(
        (stop_d - stop_r).abs() <= 1e-8 * stop_r.abs().max(1.0),
        "{ctx}: stops at α = {stop_d}, double-double at {stop_r}"
    );
    assert_eq!(branches_d, branches_r, "{ctx}: branches");
}

/// A mirror-symmetric body of 721 contact nodes in double ([`common::symmetric_fe_case`]
/// seed 220, 720 × 2 elements, F = 0.1) under the oscillating basis load of
/// [`oscillating_load`], α from 0 to 0.07 (about 2500 events). Two rounding artefacts,
/// each silent, that double-double does not have:
/// - at α = 0.00254 the node on the axis, the last in contact, lifts off; its λt is 0 by
///   symmetry (rounding in double, 1.8e-12 of the force scale), so it reached its stick
///   cone 1.4e-13 in α before its λν reached 0, and slipped for that long before it
///   lifted off: a slip the symmetry excludes, and an event too many;
/// - at α = 0.0629 a mirrored pair (nodes 16 and 706) sticking then slipping switched
///   9.1e-13 apart in α; at the second switch the walk back along the piece before was
///   taken for a second continuation, and the first event was flagged as a bifurcation.
///
/// By the symmetry every event must have its mirror image (the same α to 1e-9, S+ and S−
/// swapped), the centre node must never slip, and no event may be flagged.
#[test]
fn the_last_node_lifting_off_on_the_axis_in_double_does_not_slip() {
    let nx = 720;
    let ctx = "seed 220 (nx = 720, ny = 2, F = 0.1, oscillating, double)";
    let ev = unflagged_in_double(ctx, (220, nx, 2, 0.1), Some(0.07));
    let centre_lift_offs = ev
        .iter()
        .filter(|&&(_, i, _, to)| 2 * i == nx && to == Class::Open)
        .count();
    assert!(
        centre_lift_offs >= 1,
        "{ctx}: the centre node never lifts off"
    );
    let pairs = assert_mirrored(ctx, &ev, nx);
    assert!(pairs >= 2000, "{ctx}: {pairs} mirrored events");
}

/// Mirror-symmetric bodies in double ([`common::symmetric_fe_case`], one row of elements)
/// where a mirrored pair, sticking, slipped briefly and lifted off; their tangential
/// displacements had moved by a fraction of their threshold in double, so that stick fitted
/// the point again, and the way back along the sticking piece was taken for a second
/// continuation: the lift-off was flagged as a bifurcation, which double-double does not
/// have (the path went on, the events right). No event may be flagged, and every event must
/// have its mirror image:
/// - seed 274, 570 × 1 elements, F = 5, the oscillating basis load of
///   [`oscillating_load`] from α = 0 to 0.0735 (about 2300 events): at α = 0.0732688 the
///   pair beside the node on the axis slipped for 2.5e-9 in α (a third of the threshold);
/// - seed 315, 429 × 1 elements, F = 5, its affine load over its window (about 1060
///   events): at α = 2.2007 and 2.2059 two pairs slipped for 1.1e-6 in α (a fifth of the
///   threshold; under an affine load two pieces' lines meet once);
/// - seed 348, 490 × 1 elements, F = 0.8, the oscillating load from α = 0 to 0.0763
///   (about 1970 events): at α = 0.0761752 a pair slipped for 2.1e-8 in α (a seventh of
///   the threshold), where the sticking piece's own point lies off its cone.
#[test]
fn a_pair_slipping_briefly_before_it_lifts_off_is_not_a_bifurcation() {
    for (seed, nx, friction, oscillating_to) in [
        (274u64, 570, 5.0, Some(0.0735)),
        (315, 429, 5.0, None),
        (348, 490, 0.8, Some(0.0763)),
    ] {
        let ctx =
            format!("seed {seed} (nx = {nx}, ny = 1, F = {friction}, {oscillating_to:?}, double)");
        let ev = unflagged_in_double(&ctx, (seed, nx, 1, friction), oscillating_to);
        let pairs = assert_mirrored(&ctx, &ev, nx);
        assert!(pairs >= 1000, "{ctx}: {pairs} mirrored events");
    }
}
