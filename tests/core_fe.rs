//! Small finite-element problems (plane-strain Q1, clamped left edge, p ≤ 5 contact nodes
//! on the bottom, friction 0.3 to 3) against the brute-force enumeration and walk of
//! `tests/common`: the same checks as `core_brute.rs`, on realistic stiffness matrices
//! (κ(A) of a real mesh, strong normal–tangential coupling through A⁻¹) where large
//! friction gives folds.

mod common;

use std::sync::Arc;

use common::{Brute, check_state, fe_case, lambda_of, samples, trace, vclose};
use fricont::EndReason;

#[test]
fn fe_problems_against_enumeration() {
    let mut walked = 0;
    let mut total = 0;
    let mut events = 0;
    let mut folds = 0;
    let mut multi = 0;
    for seed in 0..120u64 {
        let nx = 3 + (seed % 3) as usize;
        let ny = 1 + ((seed / 3) % 3) as usize;
        let friction = [0.3, 1.0, 2.0, 3.0][((seed / 9) % 4) as usize];
        let case = fe_case(seed, nx, ny, friction);
        let data = &case.data;
        total += 1;
        let ctx = format!(
            "FE seed {seed} ({nx}x{ny} elements, p = {}, n = {}, F = {friction}, window [{}, {}])",
            data.p, data.n, case.a0, case.a1
        );
        let problem = Arc::new(data.problem());
        let mut path = trace(problem, data.affine_load(), case.a0, case.a1);
        let br = Brute::new(data);
        let start = path.start_state().unwrap();
        let sl = lambda_of(&start);
        assert!(
            br.solutions_at(case.a0)
                .iter()
                .any(|(c, l)| *c == start.classes && vclose(l, &sl, 1e-9)),
            "{ctx}: start"
        );
        for e in &common::events_with_state(&path) {
            assert!(
                e.state.residual <= 1e-12,
                "{ctx}: residual {:e}",
                e.state.residual
            );
            check_state(data, &data.force(e.alpha), &e.state, 1e-9)
                .unwrap_or_else(|m| panic!("{ctx}: event {}: {m}", e.index));
        }
        let walk = br.walk(case.a0, case.a1, &sl);
        if let Some(w) = &walk {
            walked += 1;
            let ev = path.events();
            folds += common::assert_events_match_walk(&ctx, ev, w, 1e-12);
            events += ev.len();
            let want_end = if w.closed {
                EndReason::ClosedLoop
            } else {
                EndReason::Window
            };
            assert_eq!(path.end_reason(), Some(&want_end), "{ctx}");
        }
        for alpha in samples(&case, &br, 8, 1e-6) {
            let sols = path.solutions_at(alpha).unwrap();
            let all = br.solutions_at(alpha);
            if all.len() > 1 {
                multi += 1;
            }
            for s in &sols {
                let l = lambda_of(&s.state);
                assert!(
                    all.iter()
                        .any(|(c, b)| *c == s.state.classes && vclose(b, &l, 1e-9)),
                    "{ctx}: solutions_at({alpha}) not a solution: {:?}",
                    s.state
                );
            }
            if let Some(w) = &walk {
                let want = w.solutions_at(&br, alpha);
                assert_eq!(sols.len(), want.len(), "{ctx}: solutions_at({alpha})");
                for x in &want {
                    assert!(
                        sols.iter().any(|s| vclose(&lambda_of(&s.state), x, 1e-9)),
                        "{ctx}: α = {alpha}: missing {x:?}"
                    );
                }
            }
        }
    }
    eprintln!(
        "FE: {walked}/{total} walks compared, {events} events, {folds} folds, {multi} samples with several solutions"
    );
    assert!(walked * 4 >= total * 3, "too few generic cases");
}

/// Small meshes are refined by default (`ExtendedPrecision::Auto`, cost below
/// `AUTO_SMALL_FLOPS`): their transition points agree with the double-double reference
/// (`Brute::condensed_precise`, at the events where its two pieces meet to 1e-13) to
/// 5e-13 relative. In double they were off by 5.5e-12, 1.3e-12 and 9.3e-13 on these three
/// (W well conditioned, κ ≈ 4e3–8e3, but guards crossing zero at shallow angles).
#[test]
fn small_meshes_are_refined_and_their_events_exact() {
    for (seed, nx, ny, friction) in [(219u64, 17, 1, 2.0), (175, 33, 2, 4.0), (109, 27, 1, 2.0)] {
        let case = fe_case(seed, nx, ny, friction);
        let data = &case.data;
        let problem = Arc::new(data.problem());
        assert!(problem.extended_precision(), "seed {seed}: not refined");
        let path = trace(problem, data.affine_load(), case.a0, case.a1);
        let br = Brute::condensed_precise(data);
        let pieces = path.pieces();
        let mut checked = 0;
        for (k, e) in path.events().iter().enumerate() {
            if e.bifurcation || k + 1 >= pieces.len() {
                continue;
            }
            let near = |pc: common::BrutePiece| {
                if (pc.lo - e.alpha).abs() < (pc.hi - e.alpha).abs() {
                    pc.lo
                } else {
                    pc.hi
                }
            };
            let before = near(br.piece_interval(&pieces[k].classes).expect("regular"));
            let after = near(br.piece_interval(&pieces[k + 1].classes).expect("regular"));
            let scale = before.abs().max(1.0);
            // (the reference is only as exact as its pieces meet)
            if (before - after).abs() > 1e-13 * scale {
                continue;
            }
            assert!(
                (e.alpha - before).abs() <= 5e-13 * scale,
                "seed {seed}: event {} at {:.17e}, reference {before:.17e}",
                k + 1,
                e.alpha
            );
            checked += 1;
        }
        assert!(checked >= 10, "seed {seed}: {checked} events");
    }
}
