//! Fixed-α solves agree with the path: the traced solution at α equals an independent
//! fixed-α solve there.
//!
//! At sampled α a fresh path is started with the fixed-α solver: from no guess its
//! solution must be one of the brute-force solutions (and the traced one when that is
//! the only one); from each of the traced `solutions_at(α)` as a guess it must return
//! that same solution; from random guesses it must find the unique solution when there is
//! only one. Every reported residual is ≤ 1e-12.

mod common;

use std::sync::Arc;

use common::{
    Brute, Case, Rng, fold_problem, lambda_ev, lambda_of, random_case, samples, trace, vclose,
};
use fricont::{Path, PathOptions};
use nalgebra::DVector;

const LTOL: f64 = 1e-9;

fn fresh(case: &Case, problem: &Arc<fricont::Problem>, alpha: f64, guess: Option<&[f64]>) -> Path {
    let end = if (case.a1 - alpha).abs() > 1e-3 {
        case.a1
    } else {
        case.a0
    };
    let mut p = Path::new(
        problem.clone(),
        case.data.affine_load(),
        PathOptions::window(alpha, end),
    )
    .unwrap();
    p.start(alpha, guess)
        .unwrap_or_else(|e| panic!("seed {}: start at {alpha} from {guess:?}: {e}", case.seed));
    p
}

fn check_case(case: &Case, nsamples: usize) -> usize {
    let data = &case.data;
    let problem = Arc::new(data.problem());
    let mut path = trace(problem.clone(), data.affine_load(), case.a0, case.a1);
    let br = Brute::new(data);
    let ctx = format!("seed {}", case.seed);
    let mut rng = Rng::new(case.seed + 77);
    let mut unique = 0;
    for alpha in samples(case, &br, nsamples, 1e-6) {
        let sols = path.solutions_at(alpha).unwrap();
        let all = br.solutions_at(alpha);
        // from no guess
        let p = fresh(case, &problem, alpha, None);
        let st = &p.start_state().unwrap();
        assert!(st.residual <= 1e-12, "{ctx}: residual {:e}", st.residual);
        let l = lambda_of(st);
        assert!(
            all.iter()
                .any(|(c, b)| *c == st.classes && vclose(b, &l, LTOL)),
            "{ctx}: fixed-α solve at {alpha} gave {st:?}, not a solution"
        );
        if all.len() == sols.len() {
            assert!(
                sols.iter().any(|s| vclose(&lambda_of(&s.state), &l, LTOL)),
                "{ctx}: α = {alpha}: fixed-α solve not on the path"
            );
        }
        // from each traced solution
        for s in &sols {
            assert!(
                s.state.residual <= 1e-12,
                "{ctx}: residual {:e}",
                s.state.residual
            );
            let g = lambda_of(&s.state);
            let p = fresh(case, &problem, alpha, Some(g.as_slice()));
            let st = &p.start_state().unwrap();
            assert!(
                vclose(&lambda_of(st), &g, LTOL),
                "{ctx}: α = {alpha}: started from the path's solution {g:?}, got {st:?}"
            );
            assert_eq!(st.classes, s.state.classes, "{ctx}: α = {alpha}");
            assert!(st.residual <= 1e-12);
        }
        // unique solution: found from random guesses as well
        if all.len() == 1 {
            unique += 1;
            // (the path may not reach α: after a fold it can leave through the start side;
            // core_brute.rs checks coverage against its walk)
            assert!(
                sols.len() <= 1,
                "{ctx}: α = {alpha}: unique solution but the path gives {sols:#?}"
            );
            let scale = 1.0 + all[0].1.amax();
            for _ in 0..3 {
                let g = DVector::from_fn(2 * data.p, |_, _| rng.range(-3.0, 3.0) * scale);
                let p = fresh(case, &problem, alpha, Some(g.as_slice()));
                let st = &p.start_state().unwrap();
                assert!(
                    vclose(&lambda_of(st), &all[0].1, LTOL),
                    "{ctx}: α = {alpha} from guess {g:?}: {st:?}, want {:?}",
                    all[0].1
                );
                assert!(st.residual <= 1e-12);
            }
        }
    }
    // Solves exactly at transition points reproduce the event state when the solution
    // there is unique (unique on both sides).
    for e in &common::events_with_state(&path) {
        if br.solutions_at(e.alpha - 1e-7).len() == 1 && br.solutions_at(e.alpha + 1e-7).len() == 1
        {
            let p = fresh(case, &problem, e.alpha, None);
            let st = &p.start_state().unwrap();
            assert!(
                vclose(&lambda_of(st), &lambda_ev(e), 1e-8),
                "{ctx}: solve at event {} α = {}: {st:?} vs {:?}",
                e.index,
                e.alpha,
                e.state
            );
            assert!(
                st.residual <= 1e-12,
                "{ctx}: residual {:e} at event α",
                st.residual
            );
        }
    }
    unique
}

#[test]
fn fixed_alpha_solves_random_problems() {
    let mut unique = 0;
    for seed in 0..40u64 {
        unique += check_case(&random_case(seed), 6);
    }
    assert!(unique > 100, "too few unique samples: {unique}");
}

#[test]
fn fixed_alpha_solves_fold_problem() {
    // three solutions at α = −1 (core_hand.rs): each reproduced from itself as a guess
    let case = Case {
        seed: 1000,
        data: fold_problem(),
        a0: -3.0,
        a1: 3.0,
    };
    check_case(&case, 12);
    let problem = Arc::new(case.data.problem());
    for l in [[0.0, 0.0], [-1.0, -2.0], [-1.5, -2.5]] {
        let p = fresh(&case, &problem, -1.0, Some(&l));
        let st = &p.start_state().unwrap();
        assert!(
            vclose(&lambda_of(st), &DVector::from_column_slice(&l), 1e-12),
            "{st:?}"
        );
    }
}
