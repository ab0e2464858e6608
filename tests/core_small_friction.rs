//! Friction coefficients too small for `zero_tol` to resolve (F = 1e-10 at every node of
//! finite-element bodies). Where such a node's slip reverses, its stick phase is a change
//! of λt by 2 F |λν|, within the threshold of the forces: stick, slip+ and slip− all fit
//! it at one point. Before, the path went straight from one slip class to the other (an
//! event no node with F > 0 can have while it is pressed) and traced on to the window
//! with every state solving the problem to 1e-6; the reference tracer (`common::reference`)
//! finds a stick phase there, about 1e-10 of α long. Now the path stops with an error
//! that says so, at the α where the reference's stick phase begins, its events up to there
//! the reference's. Where the path found no continuation at such a point, the error now
//! names the node and why. With `zero_tol` = 1e-12, as the messages advise, they trace to the
//! window with the reference's events. The same bodies frictionless (F = 0), or with
//! F = 1e-3, trace to the window's end.

mod common;

use std::sync::Arc;

use common::Case;
use fricont::Class;

/// The bodies (`common` generators) on which a sweep at F = 1e-10 saw a slip reversal
/// without stick (the first four) or stopped with "no neighbouring piece continues the
/// path" (the last three), with every node's friction set to `f`.
fn bodies(f: f64) -> Vec<(&'static str, Case)> {
    let mut out = vec![
        ("fe_case(12, 52, 1)", common::fe_case(12, 52, 1, f)),
        ("fe_case(18, 47, 1)", common::fe_case(18, 47, 1, f)),
        ("fe_case(50, 46, 3)", common::fe_case(50, 46, 3, f)),
        ("curved_body(54)", common::curved_body(54, false)),
        ("fe_case(38, 45, 1)", common::fe_case(38, 45, 1, f)),
        ("fe_case(68, 17, 2)", common::fe_case(68, 17, 2, f)),
        ("fe_case(112, 16, 1)", common::fe_case(112, 16, 1, f)),
    ];
    for (_, c) in &mut out {
        c.data.friction.iter_mut().for_each(|x| *x = f);
    }
    out
}

/// The case traced at `zero_tol` with the default options otherwise: the path, and
/// Ok where it reached the window's end, else its error or end.
fn trace(case: &Case, zero_tol: f64) -> (fricont::Path, Result<(), String>) {
    let d = &case.data;
    let mut opts = fricont::PathOptions::window(case.a0, case.a1);
    opts.zero_tol = zero_tol;
    let mut path = fricont::Path::new(Arc::new(d.problem()), d.affine_load(), opts).unwrap();
    let run = path.start(case.a0, None).and_then(|_| path.run());
    let r = match run {
        Ok(fricont::EndReason::Window) => Ok(()),
        Ok(r) => Err(format!("ended with {}", r.name())),
        Err(e) => Err(e.to_string()),
    };
    (path, r)
}

#[test]
fn unresolved_stick_phases_are_errors_that_say_so_not_events() {
    for (name, case) in bodies(1e-10) {
        let reference =
            common::reference::compare_case(&case, Arc::new(case.data.problem()), 1e-9).reference;
        assert!(
            reference.end.is_ok(),
            "{name}: the reference stopped: {:?}",
            reference.end
        );
        let want = reference.evs();
        let (path, r) = trace(&case, 1e-11);
        let err = r.expect_err(&format!("{name}: traced to the window at F = 1e-10"));
        let got = common::reference::path_events(&path);
        // Up to the error, the reference's events; there, the reference's node begins a
        // stick phase.
        common::reference::compare_events(&got, &want[..got.len()], 1e-9)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let (a, node, from, _) = want[got.len()];
        let stop = path.pieces().last().unwrap().alpha_to;
        let says = if err.contains("no neighbouring piece") {
            format!(
                "node {}'s friction coefficient F = 1e-10 times its normal force is within",
                node + 1
            )
        } else {
            format!("node {} changes from {from} to slip", node + 1)
        };
        assert!(
            (a - stop).abs() <= 1e-9 * a.abs().max(1.0)
                && err.contains(&says)
                && err.contains("not resolved")
                && want[got.len()].3 == Class::Stick,
            "{name}: stopped at {stop} with {err}; the reference's next event {:?}",
            want[got.len()]
        );
        // The advice in the message: with a smaller zero_tol, the stick phases are
        // resolved, and the path is the reference's.
        let (path, r) = trace(&case, 1e-12);
        r.unwrap_or_else(|e| panic!("{name}: zero_tol 1e-12: {e}"));
        common::reference::compare_events(&common::reference::path_events(&path), &want, 1e-9)
            .unwrap_or_else(|e| panic!("{name}: zero_tol 1e-12: {e}"));
    }
}

/// The same bodies frictionless, and with F = 1e-3, trace to the window's end; at F =
/// 1e-3 with the reference's events.
#[test]
fn the_same_bodies_frictionless_or_with_small_friction_trace_on() {
    for (name, case) in bodies(0.0) {
        let (path, r) = trace(&case, 1e-11);
        r.unwrap_or_else(|e| panic!("{name}, F = 0: {e}"));
        assert!(!path.events().is_empty(), "{name}");
    }
    for (name, case) in bodies(1e-3) {
        let want = common::reference::compare_case(&case, Arc::new(case.data.problem()), 1e-9)
            .reference
            .evs();
        let (path, r) = trace(&case, 1e-11);
        r.unwrap_or_else(|e| panic!("{name}, F = 1e-3: {e}"));
        common::reference::compare_events(&common::reference::path_events(&path), &want, 1e-9)
            .unwrap_or_else(|e| panic!("{name}, F = 1e-3: {e}"));
    }
}
