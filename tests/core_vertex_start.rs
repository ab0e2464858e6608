//! Starts at a zero-force vertex on a vertical piece (issue 10, failure mode 5).
//!
//! Random problems of `common::random_case` made degenerate by hand: every gap zero, the
//! friction coefficient of node 1 set to `W_νν / |W_νt|` (so that its slip piece in the
//! direction of `W_νt` is singular: a vertical piece), and the path started at the α where
//! node 1's normal load `q_ν` vanishes (a node touching with zero load). For even seeds
//! the load is homogeneous (`f0 = 0`), so the start α = 0 is a zero-force vertex of every
//! node at once, where several solution curves leave the start point.
//!
//! Independent check: the brute force (`common::Brute`, every class vector solved with
//! nalgebra) gives every solution just inside the window, `α0 + δ`. Those that continue
//! the start point (distance to the start state of order δ) are the solution curves
//! through it into the window. The traced path, together with the branches it offers at
//! the start (`Path::branches`, `Path::choose_branch`), must contain each of them, and
//! contain nothing else there.

mod common;

use std::sync::Arc;

use common::{Brute, lambda_of, random_case};
use fricont::{EndReason, Path, PathOptions};
use nalgebra::DVector;

/// The traced solutions at `alpha` (internal check of a finished path).
fn traced_at(path: &mut Path, alpha: f64) -> Vec<DVector<f64>> {
    path.solutions_at(alpha)
        .expect("solutions_at")
        .into_iter()
        .map(|s| lambda_of(&s.state))
        .collect()
}

#[test]
fn a_start_at_a_zero_force_vertex_traces_into_the_window() {
    let (mut cases, mut with_branches, mut curves) = (0, 0, 0);
    for seed in 0u64..400 {
        let case = random_case(seed);
        let mut data = case.data.clone();
        let p = data.p;
        let w = Brute::new(&data).w;
        data.friction[0] = w[(0, 0)] / w[(0, p)].abs();
        if seed.is_multiple_of(2) {
            data.f0.fill(0.0);
        }
        data.gap.fill(0.0);
        let br = Brute::new(&data);
        if br.q1[0].abs() < 1e-9 {
            continue;
        }
        let a0 = -br.q0[0] / br.q1[0];
        for a1 in [a0 - 1.0, a0 + 1.0] {
            let ctx = format!("seed {seed}, p = {p}, start {a0} toward {a1}");
            cases += 1;
            let problem = Arc::new(data.problem());
            let mut path = Path::new(problem, data.affine_load(), PathOptions::window(a0, a1))
                .unwrap_or_else(|e| panic!("{ctx}: {e}"));
            path.start(a0, None)
                .unwrap_or_else(|e| panic!("{ctx}: start: {e}"));
            let start = lambda_of(&path.start_state().expect("started"));
            let n_branches = path.branches().len().max(1);
            if n_branches > 1 {
                with_branches += 1;
            }
            // The brute-force solution curves through the start point into the window.
            let delta = 1e-6 * (a1 - a0);
            let scale = 1f64.max(start.amax());
            let through: Vec<DVector<f64>> = br
                .solutions_at(a0 + delta)
                .into_iter()
                .map(|(_, l)| l)
                .filter(|l| (l - &start).amax() <= 1e-4 * scale)
                .collect();
            curves += through.len();
            let mut traced = Vec::new();
            for k in 0..n_branches {
                if k > 0 {
                    path.start(a0, None)
                        .unwrap_or_else(|e| panic!("{ctx}: start: {e}"));
                    path.choose_branch(k)
                        .unwrap_or_else(|e| panic!("{ctx}: choose_branch({k}): {e}"));
                }
                path.run()
                    .unwrap_or_else(|e| panic!("{ctx}, branch {k}: run: {e}"));
                assert_eq!(
                    path.end_reason(),
                    Some(&EndReason::Window),
                    "{ctx}, branch {k}"
                );
                traced.extend(traced_at(&mut path, a0 + delta));
            }
            let near = |a: &DVector<f64>, b: &DVector<f64>| (a - b).amax() <= 1e-8 * scale;
            for l in &through {
                assert!(
                    traced.iter().any(|t| near(t, l)),
                    "{ctx}: the solution curve through the start point with λ = {:?} at α0 + δ is not traced (traced: {traced:?})",
                    l.as_slice()
                );
            }
            for t in &traced {
                assert!(
                    br.solutions_at(a0 + delta).iter().any(|(_, l)| near(t, l)),
                    "{ctx}: traced λ = {:?} at α0 + δ is no brute-force solution",
                    t.as_slice()
                );
            }
        }
    }
    eprintln!("{cases} starts, {with_branches} with several branches, {curves} curves");
    // The family must exercise what it is about.
    assert!(
        cases > 700 && with_branches >= 5 && curves > cases / 2,
        "{cases} {with_branches} {curves}"
    );
}
