//! A non-monotone load with a near-tangent double crossing (steps controlled by the
//! guards' derivatives, so that a double crossing inside one step is not skipped).
//!
//! For random problems whose affine path is unique and fold-free on [−3, 3] (checked by
//! the brute-force enumeration at many α), the load `f(β) = f0 + φ(β) f1` with
//! `φ(β) = A sin β`, β ∈ [0, 2π], sweeps α = φ(β) up to A, down to −A and back. The
//! amplitude A is set 1e-6 above the largest affine event α_top, so φ crosses α_top twice
//! within about ±1.4e-3 of β = π/2, with the guard barely dipping below zero in between.
//!
//! Expected events (independent: the brute-force walk's affine events α_k): every β in
//! the window with φ(β) = α_k, in increasing β, node as in the affine event, classes as in
//! the affine event where φ increases and reversed where it decreases, no folds. The
//! located β must satisfy `φ(β) = α_k` to 1e-12 (relative to max(1, |α_k|)); β itself is
//! compared with the closed form `asin(α_k / A)` to 1e-12 plus the conditioning
//! `ε / |φ'(β)|` of the crossing.

mod common;

use std::f64::consts::PI;
use std::sync::Arc;

use common::{Brute, lambda_of, random_case};
use fricont::load::{LoadFailure, VectorFn};
use fricont::{Class, EndReason, Load, Path, PathOptions};

fn loads(f0: &[f64], f1: &[f64], amp: f64) -> Vec<(&'static str, Load)> {
    let mk = |f0: Vec<f64>, f1: Vec<f64>| -> VectorFn {
        Box::new(move |b: f64, out: &mut [f64]| -> Result<(), LoadFailure> {
            let s = amp * b.sin();
            for ((o, a), c) in out.iter_mut().zip(&f0).zip(&f1) {
                *o = a + s * c;
            }
            Ok(())
        })
    };
    let f1d = f1.to_vec();
    let df: VectorFn = Box::new(move |b: f64, out: &mut [f64]| {
        let s = amp * b.cos();
        for (o, c) in out.iter_mut().zip(&f1d) {
            *o = s * c;
        }
        Ok(())
    });
    let basis = Load::basis(
        vec![f0.to_vec(), f1.to_vec()],
        Box::new(move |b: f64, w: &mut [f64], dw: &mut [f64]| {
            w[0] = 1.0;
            w[1] = amp * b.sin();
            dw[0] = 0.0;
            dw[1] = amp * b.cos();
            Ok(())
        }),
    )
    .unwrap();
    vec![
        ("basis", basis),
        (
            "general with f'",
            Load::general(f0.len(), mk(f0.to_vec(), f1.to_vec()), Some(df)),
        ),
        (
            "general without f'",
            Load::general(f0.len(), mk(f0.to_vec(), f1.to_vec()), None),
        ),
    ]
}

#[test]
fn sine_load_double_crossing_margin_1e_2() {
    sine_load(1e-2);
}

#[test]
fn sine_load_double_crossing_margin_1e_6() {
    sine_load(1e-6);
}

/// `margin`: how far the amplitude exceeds the top affine event.
fn sine_load(margin: f64) {
    let mut done = 0;
    let mut failures: Vec<String> = Vec::new();
    for seed in (0..200u64).filter(|s| s % 2 == 0) {
        let case = random_case(seed);
        let data = &case.data;
        let br = Brute::new(data);
        // unique solution on [−3, 3] (checked on a fine grid) and a fold-free walk
        let unique = (0..=600).all(|k| br.solutions_at(-3.0 + 0.01 * k as f64 + 1e-7).len() == 1);
        if !unique {
            continue;
        }
        let start = &br.solutions_at(-3.0)[0].1;
        let Some(walk) = br.walk(-3.0, 3.0, start) else {
            continue;
        };
        if walk.events.iter().any(|e| e.fold) || walk.events.is_empty() {
            continue;
        }
        let top = walk
            .events
            .iter()
            .map(|e| e.phi)
            .fold(f64::NEG_INFINITY, f64::max);
        if !(0.3..2.9).contains(&top) {
            continue;
        }
        let amp = top + margin;
        // expected events in β ∈ [0, 2π]
        let mut expected: Vec<(f64, usize, Class, Class, f64)> = Vec::new();
        for e in walk
            .events
            .iter()
            .filter(|e| e.phi.abs() < amp && e.phi != 0.0)
        {
            let s = (e.phi / amp).asin(); // in (−π/2, π/2)
            let (up, down) = if e.phi > 0.0 {
                (s, PI - s)
            } else {
                (2.0 * PI + s, PI - s)
            };
            expected.push((up, e.node, e.from, e.to, e.phi));
            expected.push((down, e.node, e.to, e.from, e.phi));
        }
        expected.sort_by(|a, b| a.0.total_cmp(&b.0));
        let problem = Arc::new(data.problem());
        for (name, load) in loads(data.f0.as_slice(), data.f1.as_slice(), amp) {
            let ctx = format!("seed {seed}, {name}, A = {amp}");
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let mut path =
                    Path::new(problem.clone(), load, PathOptions::window(0.0, 2.0 * PI)).unwrap();
                path.start(0.0, None).unwrap();
                assert_eq!(path.run().unwrap(), EndReason::Window, "{ctx}");
                let ev = common::events_with_state(&path);
                let show = || {
                    format!(
                        "expected {:#?}\ngot {:#?}",
                        expected
                            .iter()
                            .map(|x| format!("β {:.15} node {} {} -> {}", x.0, x.1, x.2, x.3))
                            .collect::<Vec<_>>(),
                        ev.iter()
                            .map(|e| format!(
                                "β {:.15} node {} {} -> {}",
                                e.alpha, e.node, e.from, e.to
                            ))
                            .collect::<Vec<_>>()
                    )
                };
                assert_eq!(ev.len(), expected.len(), "{ctx}: {}", show());
                for (e, x) in ev.iter().zip(&expected) {
                    assert_eq!(
                        (e.node, e.from, e.to, e.fold),
                        (x.1, x.2, x.3, false),
                        "{ctx}: {}",
                        show()
                    );
                    let phi = amp * e.alpha.sin();
                    assert!(
                        (phi - x.4).abs() <= 1e-12 * x.4.abs().max(1.0),
                        "{ctx}: φ(β) = {phi:.17e} at the event, affine event {:.17e}",
                        x.4
                    );
                    // β = φ⁻¹(φ_e): the 1e-12 accuracy required of φ at the event (checked
                    // just above) propagates to β through 1/|dφ/dβ| = 1/|A cos β|, which
                    // is large near the crest of the sine (near-tangent crossings).
                    let dphi = (amp * x.0.cos()).abs();
                    let cond = f64::EPSILON / dphi;
                    let phi_tol = 1e-12 * x.4.abs().max(1.0) / dphi;
                    assert!(
                        (e.alpha - x.0).abs()
                            <= (1e-12 * x.0.abs().max(1.0)).max(phi_tol) + 4.0 * cond,
                        "{ctx}: β = {:.17e}, expected {:.17e}",
                        e.alpha,
                        x.0
                    );
                    assert!(e.state.residual <= 1e-12, "{ctx}");
                }
                // the traced solution follows the affine one: λ(β) = λ_aff(φ(β))
                for k in 0..40 {
                    let b = 2.0 * PI * (k as f64 + 0.5) / 40.0;
                    let sols = path.solutions_at(b).unwrap();
                    assert_eq!(sols.len(), 1, "{ctx}: β = {b}");
                    let want = &br.solutions_at(amp * b.sin())[0].1;
                    let got = lambda_of(&sols[0].state);
                    assert!(
                        (want - &got).amax() <= 1e-9 * (1.0 + want.amax()),
                        "{ctx}: β = {b}"
                    );
                }
            }));
            if let Err(e) = r {
                let msg = e
                    .downcast_ref::<String>()
                    .cloned()
                    .unwrap_or_else(|| "panic".into());
                failures.push(msg.lines().next().unwrap_or("").to_string());
            }
        }
        done += 1;
    }
    assert!(done >= 10, "only {done} suitable cases");
    assert!(
        failures.is_empty(),
        "{} of {} (case, load form) runs failed:\n{}",
        failures.len(),
        3 * done,
        failures.join("\n")
    );
}
