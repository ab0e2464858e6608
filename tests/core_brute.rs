//! Brute force on random small problems: the traced events equal those of an independent
//! enumeration of every class vector.
//!
//! For random problems (p ≤ 5, n = 2p + 0..3, random SPD A, random dense full-rank N and
//! T, friction up to 3, a random gap for some, a random affine load) the independent
//! nalgebra code of `tests/common` enumerates all `4^p` class assignments, solves each
//! piece's linear equations as an affine function of α and keeps the α-interval where its
//! guards hold. From that it
//!
//! * lists every solution at any α: each `solutions_at(α)` of the traced path must be one
//!   of them (containment, always);
//! * walks the connected component through the start point, joining pieces at shared
//!   endpoints (its own path tracer, with no orientation logic: in the generic case each
//!   transition point is shared by exactly two pieces). The library must report the same
//!   events (α, node, classes, fold) and `solutions_at(α)` must equal the walk's solutions
//!   at every sampled α (equality whenever the path is connected to them).

mod common;

use std::sync::Arc;

use common::{
    Brute, Case, check_state, lambda_of, large_friction_case, random_case, samples, trace, vclose,
};
use fricont::EndReason;
use nalgebra::DVector;

/// Tolerance for α of events against the brute force (two different algorithms, each
/// with rounding of order cond(K_S)·ε).
const ALPHA_TOL: f64 = 1e-12;
const LAMBDA_TOL: f64 = 1e-9;

#[test]
fn random_problems_against_enumeration() {
    against_enumeration(0..400, random_case);
}

/// Friction up to 5. Seeds 527, 3908 and 5017 start where the damped Newton, the
/// active-set iteration and block Gauss–Seidel all stall (the start needs the friction
/// continuation of the fixed-α solver).
#[test]
fn large_friction_problems_against_enumeration() {
    against_enumeration((0..1000).chain([527, 3908, 5017]), large_friction_case);
}

fn against_enumeration(seeds: impl Iterator<Item = u64>, case_of: fn(u64) -> Case) {
    let mut walked = 0;
    let mut folds = 0;
    let mut events = 0;
    let mut multi = 0;
    let mut nseeds = 0;
    for seed in seeds {
        nseeds += 1;
        let case = case_of(seed);
        let data = &case.data;
        let problem = Arc::new(data.problem());
        let mut path = trace(problem, data.affine_load(), case.a0, case.a1);
        let br = Brute::new(data);
        let ctx = format!(
            "seed {seed} (p = {}, n = {}, F = {:?}, window [{}, {}])",
            data.p, data.n, data.friction, case.a0, case.a1
        );

        // The start is one of the brute-force solutions.
        let start = path.start_state().expect("started");
        let start_l = lambda_of(&start);
        assert!(
            br.solutions_at(case.a0)
                .iter()
                .any(|(c, l)| *c == start.classes && vclose(l, &start_l, LAMBDA_TOL)),
            "{ctx}: start {start:?} is not a brute-force solution"
        );
        assert!(
            start.residual <= 1e-12,
            "{ctx}: start residual {:e}",
            start.residual
        );

        // Every event state solves the problem.
        for e in &common::events_with_state(&path) {
            assert!(
                e.state.residual <= 1e-12,
                "{ctx}: event {} residual {:e}",
                e.index,
                e.state.residual
            );
            check_state(data, &data.force(e.alpha), &e.state, 1e-9)
                .unwrap_or_else(|m| panic!("{ctx}: event {}: {m}", e.index));
        }

        let walk = br.walk(case.a0, case.a1, &start_l);
        if let Some(w) = &walk {
            walked += 1;
            let ev = path.events();
            folds += common::assert_events_match_walk(&ctx, ev, w, ALPHA_TOL);
            events += ev.len();
            let pcs: Vec<_> = path.pieces().iter().map(|p| p.classes.clone()).collect();
            let wpcs: Vec<_> = w
                .steps
                .iter()
                .map(|s| br.pieces[s.piece].classes.clone())
                .collect();
            assert_eq!(pcs, wpcs, "{ctx}: pieces");
            let want_end = if w.closed {
                EndReason::ClosedLoop
            } else {
                EndReason::Window
            };
            assert_eq!(path.end_reason(), Some(&want_end), "{ctx}");
        }

        for alpha in samples(&case, &br, 9, 1e-6) {
            let sols = path
                .solutions_at(alpha)
                .unwrap_or_else(|e| panic!("{ctx}: solutions_at({alpha}): {e}"));
            let all = br.solutions_at(alpha);
            if all.len() > 1 {
                multi += 1;
            }
            for s in &sols {
                let l = lambda_of(&s.state);
                assert!(
                    all.iter()
                        .any(|(c, bl)| *c == s.state.classes && vclose(bl, &l, LAMBDA_TOL)),
                    "{ctx}: solutions_at({alpha}) gave {:?}, not among the brute-force solutions {all:?}",
                    s.state
                );
                assert!(
                    s.state.residual <= 1e-12,
                    "{ctx}: residual {:e} at α = {alpha}",
                    s.state.residual
                );
                check_state(data, &data.force(alpha), &s.state, 1e-9)
                    .unwrap_or_else(|m| panic!("{ctx}: α = {alpha}: {m}"));
                let u = br.displacement(alpha, &l);
                assert!(
                    vclose(&u, &DVector::from_column_slice(&s.state.u), LAMBDA_TOL),
                    "{ctx}: u at α = {alpha}"
                );
            }
            if let Some(w) = &walk {
                let want = w.solutions_at(&br, alpha);
                assert_eq!(
                    sols.len(),
                    want.len(),
                    "{ctx}: solutions_at({alpha}): got {sols:#?}, brute-force walk {want:?}"
                );
                for x in &want {
                    assert!(
                        sols.iter()
                            .any(|s| vclose(&lambda_of(&s.state), x, LAMBDA_TOL)),
                        "{ctx}: α = {alpha}: missing {x:?}"
                    );
                }
            }
        }
    }
    eprintln!(
        "{walked}/{nseeds} walks compared, {events} events, {folds} folds, {multi} samples with several solutions"
    );
    assert!(walked >= nseeds * 3 / 4, "too few generic cases: {walked}");
    assert!(folds > 0, "the random cases should exercise folds");
}
