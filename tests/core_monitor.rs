//! The monitor of `Path::run_monitored`: called once per transition point with the new
//! events, and able to stop the path cleanly (`EndReason::Stopped`) so that stepping on
//! continues where it stopped. Reference: the same path traced without a monitor.

mod common;

use std::ops::ControlFlow;
use std::sync::Arc;

use fricont::{EndReason, Path, PathOptions, Progress};

#[test]
fn the_monitor_sees_every_transition_and_stops_the_path_cleanly() {
    let mut checked = 0;
    for seed in 0..8u64 {
        let case = common::fe_case(seed, 8, 3, [0.3, 1.0][seed as usize % 2]);
        let data = &case.data;
        let problem = Arc::new(data.problem());
        let reference = common::trace(problem.clone(), data.affine_load(), case.a0, case.a1);
        let n_tr = reference.events().last().map_or(0, |e| e.transition + 1);
        if n_tr < 4 {
            continue;
        }
        let mut path = Path::new(
            problem,
            data.affine_load(),
            PathOptions::window(case.a0, case.a1),
        )
        .unwrap();
        path.start(case.a0, None).unwrap();
        // Stop at the third transition point, recording what the monitor was told.
        let mut seen: Vec<Progress> = Vec::new();
        let reason = path
            .run_monitored(|p, pr| {
                // the new events are the last ones, of one transition point, at pr.alpha
                assert_eq!(pr.events.end, p.events().len());
                assert!(
                    p.events()[pr.events.clone()]
                        .iter()
                        .all(|e| e.alpha == pr.alpha)
                );
                seen.push(pr.clone());
                if pr.transitions == 3 {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            })
            .unwrap();
        assert_eq!(reason, EndReason::Stopped, "seed {seed}");
        assert_eq!(path.end_reason(), Some(&EndReason::Stopped));
        assert_eq!(seen.len(), 3);
        let stopped_events = path.events().len();
        for (k, pr) in seen.iter().enumerate() {
            assert_eq!(pr.transitions, k + 1);
            let evs: Vec<_> = reference
                .events()
                .iter()
                .filter(|e| e.transition == k)
                .collect();
            assert_eq!(pr.alpha, evs[0].alpha, "seed {seed}: transition {k}");
            assert_eq!(pr.events.len(), evs.len());
            let want = (pr.alpha - case.a0) / (case.a1 - case.a0);
            assert!((pr.fraction - want).abs() <= 1e-15);
        }
        assert_eq!(stopped_events, seen[2].events.end);
        // Running again continues from the stopped point: the same events as the
        // reference, and a path that ends for the reference's reason.
        let mut more = 0;
        let reason = path
            .run_monitored(|_, _| {
                more += 1;
                ControlFlow::Continue(())
            })
            .unwrap();
        assert_eq!(Some(&reason), reference.end_reason(), "seed {seed}");
        assert_eq!(more + 3, n_tr, "seed {seed}: transitions after the restart");
        assert_eq!(path.events(), reference.events(), "seed {seed}");
        // stop() on an ended path changes nothing
        assert!(!path.stop());
        assert_eq!(Some(&reason), path.end_reason());
        checked += 1;
    }
    assert!(
        checked >= 4,
        "only {checked} cases with 4 transition points or more"
    );
}
