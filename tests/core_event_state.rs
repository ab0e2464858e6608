//! `Path::event_state` rebuilds the state at an event from what the tracer kept: it must
//! never call the load's closures (a host such as MATLAB answers them only during a step),
//! and its u must solve A u = f(α) + Bᵀλ (checked with an independent dense solve).

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use fricont::load::LoadFailure;
use fricont::{CsrMatrix, Load, Path, PathOptions, ProblemBuilder, Storage};
use nalgebra::{DMatrix, DVector};

/// One node, n = 2: A = [[2, ½], [½, 1]], N = [1 0], T = [0 1], F = 0.5,
/// f(α) = (1, sin α): pressed with a tangential load that goes back and forth, so the node
/// sticks and slips both ways over α ∈ [0, 6].
#[test]
fn event_state_calls_no_closure_and_solves_the_equilibrium() {
    let a = [2.0, 0.5, 0.5, 1.0];
    let problem = Arc::new(
        ProblemBuilder::new(
            CsrMatrix::from_dense(2, 2, &a).unwrap(),
            Storage::Full,
            CsrMatrix::from_dense(1, 2, &[1.0, 0.0]).unwrap(),
            CsrMatrix::from_dense(1, 2, &[0.0, 1.0]).unwrap(),
        )
        .friction_uniform(0.5)
        .build()
        .unwrap(),
    );
    let f_of = |x: f64| [1.0, 0.9 * x.sin()];
    for basis in [false, true] {
        let calls = Arc::new(AtomicUsize::new(0));
        let c = calls.clone();
        let load = if basis {
            Load::basis(
                vec![vec![1.0, 0.0], vec![0.0, 0.9]],
                Box::new(move |x, w: &mut [f64], dw: &mut [f64]| {
                    c.fetch_add(1, Ordering::SeqCst);
                    w.copy_from_slice(&[1.0, x.sin()]);
                    dw.copy_from_slice(&[0.0, x.cos()]);
                    Ok::<(), LoadFailure>(())
                }),
            )
            .unwrap()
        } else {
            Load::general(
                2,
                Box::new(move |x, out: &mut [f64]| {
                    c.fetch_add(1, Ordering::SeqCst);
                    out.copy_from_slice(&f_of(x));
                    Ok(())
                }),
                None,
            )
        };
        let mut path = Path::new(problem.clone(), load, PathOptions::window(0.0, 6.0)).unwrap();
        path.start(0.0, None).unwrap();
        path.run().unwrap();
        assert!(path.events().len() >= 2, "events: {:?}", path.events());
        let before = calls.load(Ordering::SeqCst);
        let am = DMatrix::from_row_slice(2, 2, &a);
        for k in 0..path.events().len() {
            let st = path.event_state(k).unwrap();
            let e = &path.events()[k];
            assert_eq!(
                (st.alpha, &st.lambda_n, &st.lambda_t),
                (e.alpha, &e.lambda_n, &e.lambda_t)
            );
            let f = f_of(e.alpha);
            let rhs = DVector::from_vec(vec![f[0] + e.lambda_n[0], f[1] + e.lambda_t[0]]);
            let u = am.clone().lu().solve(&rhs).unwrap();
            for i in 0..2 {
                assert!(
                    (st.u[i] - u[i]).abs() <= 1e-13 * (1.0 + u.amax()),
                    "event {k}: u {:?} vs {u}",
                    st.u
                );
            }
            assert!(st.residual <= 1e-13, "event {k}: residual {}", st.residual);
        }
        assert_eq!(
            calls.load(Ordering::SeqCst),
            before,
            "event_state called the load closure"
        );
    }
}

/// The blocked `event_states` (u by the backward half of a solve, the load's half kept per
/// load vector; or a full solve per event for a general load) agrees with a dense LU solve
/// of A u = f(α) + Nᵀλν + Tᵀλt, with `event_state` one event at a time, and its residual
/// is at rounding level. Affine, basis (the same load as two vectors) and general loads.
#[test]
fn blocked_event_states_solve_the_equilibrium() {
    let mut worst = 0.0f64;
    for seed in 0..9u64 {
        let case = common::fe_case(
            seed,
            8 + seed as usize,
            2,
            [0.3, 1.0, 3.0][seed as usize % 3],
        );
        let data = &case.data;
        let load = match seed % 3 {
            0 => data.affine_load(),
            1 => Load::basis(
                vec![data.f0.as_slice().to_vec(), data.f1.as_slice().to_vec()],
                Box::new(|x, w: &mut [f64], dw: &mut [f64]| {
                    w.copy_from_slice(&[1.0, x]);
                    dw.copy_from_slice(&[0.0, 1.0]);
                    Ok::<(), LoadFailure>(())
                }),
            )
            .unwrap(),
            _ => {
                let (f0, f1) = (data.f0.clone(), data.f1.clone());
                Load::general(
                    data.n,
                    Box::new(move |x, out: &mut [f64]| {
                        for (i, o) in out.iter_mut().enumerate() {
                            *o = f0[i] + x * f1[i];
                        }
                        Ok(())
                    }),
                    None,
                )
            }
        };
        let path = common::trace(std::sync::Arc::new(data.problem()), load, case.a0, case.a1);
        let n_ev = path.events().len();
        assert!(n_ev > 0, "seed {seed}: no events");
        let all = path.event_states(0..n_ev).unwrap();
        let lu = data.a.clone().lu();
        for (k, s) in all.iter().enumerate() {
            let one = path.event_state(k).unwrap();
            assert_eq!(
                (s.alpha, &s.lambda_n, &s.lambda_t, &s.classes),
                (one.alpha, &one.lambda_n, &one.lambda_t, &one.classes),
                "seed {seed}, event {k}"
            );
            let ln = DVector::from_column_slice(&s.lambda_n);
            let lt = DVector::from_column_slice(&s.lambda_t);
            let f = &data.f0 + s.alpha * &data.f1;
            let rhs = &f + data.nm.transpose() * ln + data.tm.transpose() * lt;
            let u_ref = lu.solve(&rhs).unwrap();
            // relative to the larger of u and the free displacement A⁻¹ f (the terms u is
            // made of)
            let scale = u_ref.amax().max(lu.solve(&f).unwrap().amax());
            for (i, (a, b)) in s.u.iter().zip(&one.u).enumerate() {
                let e = (a - u_ref[i]).abs() / scale;
                worst = worst.max(e);
                assert!(
                    e <= 1e-11,
                    "seed {seed}, event {k}, dof {i}: {a} vs {}",
                    u_ref[i]
                );
                assert!((a - b).abs() <= 1e-13 * scale, "seed {seed}, event {k}: u");
            }
            assert!(
                s.residual <= 1e-12,
                "seed {seed}, event {k}: residual {}",
                s.residual
            );
        }
        assert!(path.event_states(0..n_ev + 1).is_err());
        eprintln!("seed {seed}: {n_ev} events, worst relative error of u so far {worst:.1e}");
    }
}
