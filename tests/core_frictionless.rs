//! Frictionless contact nodes (F = 0, the library's default friction): their stick region
//! (`F λν < λt < −F λν`) is empty and their S+ and S− have the same equations (`dν = 0`,
//! `λt = 0`), so where their dt stays at zero (the node on a symmetric body's axis, or
//! between sticking neighbours) every slip sign fits. Checked on mirror-symmetric bodies,
//! every node frictionless or every other one, under affine and basis loads, against
//! the data: every event's state and the state at every piece's midpoint solve the problem
//! (equilibrium, complementarity, the classes' signs), the path reaches the window's end
//! with no bifurcation flagged and no frictionless node in stick, and scaling the
//! tangential rows changes no event.
//! Before, these paths stopped at a bifurcation that was none (S+, S− and stick of the
//! node on the axis as three continuations, the same solution) or with "34 nodes are at a
//! class boundary at once" (3^34 pieces where the tangential load turns); with the
//! enumeration of one slip class alone, a body took the root of a dt that stays at zero
//! (its value the rounding of W's entries) as an exit 1.0 in α behind the piece's entry.

mod common;

use std::sync::Arc;

use common::{Case, Rng, check_state, events_with_state};
use fricont::load::LoadFailure;
use fricont::{EndReason, Load, Path, PathOptions};

/// `symmetric_fe_case` with every node frictionless, or (`mixed`) every node frictionless
/// or, at random, with F in (0.1, 5).
fn case(seed: u64, nx: usize, ny: usize, mixed: bool) -> Case {
    let mut c = common::symmetric_fe_case(seed, nx, ny, 0.0);
    let mut rng = Rng::new(seed * 31 + 7);
    for f in c.data.friction.iter_mut() {
        if mixed && rng.int(0, 1) == 1 {
            *f = rng.range(0.1, 5.0);
        }
    }
    c
}

/// φ(α) = α + 0.3 sin 2α, increasing.
fn phi(a: f64) -> f64 {
    a + 0.3 * (2.0 * a).sin()
}

/// The load `f0 + φ(α) f1` as basis vectors (`basis`) or the affine load (φ(α) = α).
fn load(case: &Case, basis: bool) -> Load {
    let d = &case.data;
    if !basis {
        return d.affine_load();
    }
    let weights = |a: f64, w: &mut [f64], dw: &mut [f64]| {
        w[0] = 1.0;
        w[1] = phi(a);
        dw[0] = 0.0;
        dw[1] = 1.0 + 0.6 * (2.0 * a).cos();
        Ok::<(), LoadFailure>(())
    };
    let vectors = vec![d.f0.as_slice().to_vec(), d.f1.as_slice().to_vec()];
    Load::basis(vectors, Box::new(weights)).unwrap()
}

/// Traces the case over its window and checks every event's state and every piece's
/// midpoint against the data (relative tolerance 1e-9); the path's events as (α, node,
/// from, to).
fn traced(
    ctx: &str,
    case: &Case,
    basis: bool,
) -> Vec<(f64, usize, fricont::Class, fricont::Class)> {
    let d = &case.data;
    let force = |a: f64| d.force(if basis { phi(a) } else { a });
    let problem = Arc::new(d.problem());
    let opts = PathOptions::window(case.a0, case.a1);
    let mut path = Path::new(problem, load(case, basis), opts).unwrap();
    path.start(case.a0, None).unwrap();
    let end = path.run().unwrap_or_else(|e| panic!("{ctx}: {e}"));
    assert_eq!(end, EndReason::Window, "{ctx}");
    let events = events_with_state(&path);
    for e in &events {
        assert!(
            !e.ev.bifurcation,
            "{ctx}: event at {} flagged a bifurcation",
            e.ev.alpha
        );
        check_state(d, &force(e.ev.alpha), &e.state, 1e-9)
            .unwrap_or_else(|m| panic!("{ctx}: event at {}: {m}", e.ev.alpha));
    }
    for (k, pc) in path.pieces().iter().enumerate() {
        for (i, &cl) in pc.classes.iter().enumerate() {
            let stuck = cl == fricont::Class::Stick && d.friction[i] == 0.0;
            assert!(
                !stuck,
                "{ctx}: piece {k}: frictionless node {} in stick",
                i + 1
            );
        }
    }
    let mids: Vec<f64> = path
        .pieces()
        .iter()
        .map(|pc| 0.5 * (pc.alpha_from + pc.alpha_to))
        .collect();
    for a in mids {
        for s in path.solutions_at(a).unwrap() {
            check_state(d, &force(a), &s.state, 1e-9)
                .unwrap_or_else(|m| panic!("{ctx}: piece {} at {a}: {m}", s.piece));
        }
    }
    events
        .iter()
        .map(|e| (e.ev.alpha, e.ev.node, e.ev.from, e.ev.to))
        .collect()
}

#[test]
fn frictionless_symmetric_bodies_trace_through_the_axis_and_where_the_tangential_load_turns() {
    // (seed, nx, ny, mixed): before, under both loads, seeds 7, 61, 13 and 3 stopped at a
    // bifurcation and 108, 1 and 4 with 3^N pieces (N = 34, 21, 42); 2 and 5 traced
    let cases = [
        (7, 14, 1, true),
        (108, 33, 1, false),
        (61, 56, 2, true),
        (13, 31, 1, true),
        (1, 20, 1, false),
        (2, 25, 2, false),
        (3, 18, 3, true),
        (4, 41, 1, false),
        (5, 30, 2, true),
    ];
    for (seed, nx, ny, mixed) in cases {
        let c = case(seed, nx, ny, mixed);
        for basis in [false, true] {
            let ctx = format!("seed {seed}, {nx} × {ny}, mixed {mixed}, basis {basis}");
            let events = traced(&ctx, &c, basis);
            assert!(!events.is_empty(), "{ctx}");
        }
    }
}

#[test]
fn scaling_the_tangential_rows_moves_no_event_of_a_frictionless_body() {
    // λt = 0 at every node whatever T's scale, and dt's sign is T's: the same events.
    for (seed, nx, ny) in [(108, 33, 1), (1, 20, 1), (4, 41, 1)] {
        let c = case(seed, nx, ny, false);
        let mut scaled = case(seed, nx, ny, false);
        scaled.data.tm *= 4.0;
        let ctx = format!("seed {seed}, {nx} × {ny}");
        let (a, b) = (traced(&ctx, &c, false), traced(&ctx, &scaled, false));
        assert_eq!(a.len(), b.len(), "{ctx}: {a:?}\n{b:?}");
        for (x, y) in a.iter().zip(&b) {
            assert_eq!((x.1, x.2, x.3), (y.1, y.2, y.3), "{ctx}");
            assert!(
                (x.0 - y.0).abs() <= 1e-9 * (1.0 + x.0.abs()),
                "{ctx}: {x:?} {y:?}"
            );
        }
    }
}
