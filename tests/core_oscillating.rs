//! Oscillating loads with analytic transitions: every narrow excursion of a guard below
//! zero is found (issue: steps certified only by end-point derivatives skipped them).
//!
//! One node, A = I (2 dofs), N = [1, 0], T = [0, 1], no gap, load f(α) = (c(α), 0) with
//! c(α) = c0 + sin(ω α + φ): the node is open where c ≤ 0 (u = f) and sticks where c > 0
//! (u_n = 0, λν = −c, λt = 0), so the transitions are exactly the roots of c on the
//! window, where sin(ω α + φ) = −c0. With c0 = 0.9 and ω = 20, 64 of them on [−5, 5],
//! each open for a stretch of α of width 0.045 only (1/220 of the window).

mod common;

use std::f64::consts::PI;
use std::sync::Arc;

use fricont::load::LoadFailure;
use fricont::{Class, CsrMatrix, EndReason, Load, Path, PathOptions, ProblemBuilder, Storage};

/// The roots of c(α) = c0 + sin(ω α + φ) strictly between a0 and a1 in the order of
/// tracing from a0, with the classes before and after.
fn roots(c0: f64, omega: f64, phase: f64, a0: f64, a1: f64) -> Vec<(f64, Class, Class)> {
    let s = (-c0).asin(); // in (−π/2, 0)
    let (lo, hi) = (a0.min(a1), a0.max(a1));
    let mut out = Vec::new();
    let kmax = (omega * hi.abs().max(lo.abs()) / (2.0 * PI)).ceil() as i64 + 2;
    for k in -kmax..=kmax {
        let base = 2.0 * PI * k as f64;
        // sin decreasing through −c0 at π − s: contact → open; increasing at 2π + s:
        // open → contact (the other way round when traced downward)
        let down = (PI - s + base - phase) / omega;
        let up = (2.0 * PI + s + base - phase) / omega;
        for (a, from, to) in [
            (down, Class::Stick, Class::Open),
            (up, Class::Open, Class::Stick),
        ] {
            if a > lo && a < hi {
                out.push(if a1 > a0 {
                    (a, from, to)
                } else {
                    (a, to, from)
                });
            }
        }
    }
    out.sort_by(|x, y| x.0.total_cmp(&y.0));
    if a1 < a0 {
        out.reverse();
    }
    out
}

/// How the one node's load is given: as a general load (with its derivative, or without
/// it: central differences), or as the basis load `c0 b + sin(ω α + φ) b`, b = (1, 0).
#[derive(Clone, Copy, Debug)]
enum Given {
    General { derivative: bool },
    Basis,
}

/// Traces the one node under c0 + sin(ω α + φ), given as `given`, from a0 to a1 and
/// returns the events, or the error that ended the trace.
fn trace_one_node(
    (c0, omega, phase): (f64, f64, f64),
    (a0, a1): (f64, f64),
    given: Given,
) -> Result<Vec<(f64, Class, Class)>, fricont::Error> {
    let a = CsrMatrix::from_dense(2, 2, &[1.0, 0.0, 0.0, 1.0]).unwrap();
    let n = CsrMatrix::from_dense(1, 2, &[1.0, 0.0]).unwrap();
    let t = CsrMatrix::from_dense(1, 2, &[0.0, 1.0]).unwrap();
    let problem = Arc::new(
        ProblemBuilder::new(a, Storage::Full, n, t)
            .friction_uniform(0.3)
            .build()
            .unwrap(),
    );
    let load = match given {
        Given::General { derivative } => {
            let f = Box::new(move |al: f64, out: &mut [f64]| -> Result<(), LoadFailure> {
                out[0] = c0 + (omega * al + phase).sin();
                out[1] = 0.0;
                Ok(())
            });
            let df = Box::new(move |al: f64, out: &mut [f64]| -> Result<(), LoadFailure> {
                out[0] = omega * (omega * al + phase).cos();
                out[1] = 0.0;
                Ok(())
            });
            Load::general(2, f, derivative.then_some(df as _))
        }
        Given::Basis => {
            let weights = move |al: f64, w: &mut [f64], dw: &mut [f64]| {
                w[0] = c0;
                w[1] = (omega * al + phase).sin();
                dw[0] = 0.0;
                dw[1] = omega * (omega * al + phase).cos();
                Ok::<(), LoadFailure>(())
            };
            Load::basis(vec![vec![1.0, 0.0], vec![1.0, 0.0]], Box::new(weights)).unwrap()
        }
    };
    let mut path = Path::new(problem, load, PathOptions::window(a0, a1)).unwrap();
    path.start(a0, None).unwrap();
    assert_eq!(path.run()?, EndReason::Window);
    Ok(path
        .events()
        .iter()
        .map(|e| (e.alpha, e.from, e.to))
        .collect())
}

/// Traces the one node (as [`trace_one_node`]) and checks its events against `want`: the
/// same count, α to 1e-9, the same classes.
fn check_one_node(
    (c0, omega, phase): (f64, f64, f64),
    (a0, a1): (f64, f64),
    given: Given,
    want: &[(f64, Class, Class)],
) {
    let got = trace_one_node((c0, omega, phase), (a0, a1), given).unwrap();
    let case = format!("c0 {c0} ω {omega} φ {phase} window ({a0}, {a1}), {given:?}");
    assert_eq!(got.len(), want.len(), "{case}: events {got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g.0 - w.0).abs() <= 1e-9,
            "{case}: α {} expected {}",
            g.0,
            w.0
        );
        assert_eq!((g.1, g.2), (w.1, w.2), "{case}: at α = {}", w.0);
    }
}

#[test]
fn one_node_sine_load_finds_every_transition() {
    let want = roots(0.9, 20.0, 0.0, -5.0, 5.0);
    assert_eq!(want.len(), 64);
    let got = trace_one_node(
        (0.9, 20.0, 0.0),
        (-5.0, 5.0),
        Given::General { derivative: true },
    )
    .unwrap();
    assert_eq!(got.len(), want.len(), "events {got:?}");
    for (g, w) in got.iter().zip(&want) {
        assert!((g.0 - w.0).abs() <= 1e-10, "α {} expected {}", g.0, w.0);
        assert_eq!((g.1, g.2), (w.1, w.2), "at α = {}", w.0);
    }
}

/// The same node under sines of other frequencies, phases and depths, traced upward and
/// downward, with and without the load's derivative: the steps' grid then falls
/// differently on the sine each time, and no excursion may be skipped on any of them.
#[test]
fn one_node_sine_loads_at_many_phases_frequencies_and_directions() {
    let mut cases = 0;
    for c0 in [0.9, 0.5, 0.97] {
        for omega in [7.3, 20.0, 31.7, 53.0] {
            for phase in [0.0, 0.37, 1.1, 2.9, 4.4] {
                for (a0, a1) in [(-5.0, 5.0), (5.0, -5.0), (-1.3, 3.9)] {
                    let want = roots(c0, omega, phase, a0, a1);
                    // a start at a transition point is not this test's subject
                    let c_start = c0 + (omega * a0 + phase).sin();
                    if c_start.abs() < 1e-3 {
                        continue;
                    }
                    check_one_node(
                        (c0, omega, phase),
                        (a0, a1),
                        Given::General {
                            derivative: cases % 2 == 0,
                        },
                        &want,
                    );
                    cases += 1;
                }
            }
        }
    }
    assert!(cases >= 150, "only {cases} cases");
}

/// The same node far out on the α axis, under sin(20 α) on [1e6, 1e6 + 50]: the load's
/// own evaluation is off by up to 2e-9 there (20 α = 2e7 is rounded to 3.7e-9, one ulp of
/// α moves the load by 2.3e-9), far above the guards' usual thresholds (about 2e-12).
/// * As a general load with its derivative, the thresholds cover 64 roundings of α (a
///   load computed from α is known to no better), and every transition is found, each
///   within 1e-9 in α of the exact root (2.3e-10: two ulps of α). Before, the trace
///   stopped, as a basis load still does.
/// * Without its derivative the central differences' step is ε^(1/3) |α| = 6, 19 periods
///   of the load: the trace stops with an error that names them and the remedies.
/// * As a basis load (whose thresholds hold its exact terms) it stops with an error that
///   names the cause, α's rounding, and the remedy (an α axis centred on the window).
///
/// The same load centred on the window traces in every form (the tests above).
#[test]
fn a_sine_far_out_on_the_alpha_axis_is_traced_or_stops_naming_the_cause() {
    let (load, window) = ((0.9, 20.0, 0.0), (1e6, 1e6 + 50.0));
    let want = roots(0.9, 20.0, 0.0, window.0, window.1);
    assert!(want.len() >= 300, "{} roots", want.len());
    check_one_node(load, window, Given::General { derivative: true }, &want);
    for (given, names) in [
        (
            Given::General { derivative: false },
            ["central differences", "give the load's derivative"],
        ),
        (
            Given::Basis,
            ["one rounding of alpha", "centred on the window"],
        ),
    ] {
        match trace_one_node(load, window, given) {
            Err(fricont::Error::Numerical(msg)) => {
                assert!(names.iter().all(|n| msg.contains(n)), "{given:?}: {msg}")
            }
            other => panic!("{given:?}: expected a numerical error, got {other:?}"),
        }
    }
}

/// Loads whose period divides the march's first step: the cases of a random scan (3000
/// one-node sines per seed) where a first step of span/32 spanned two whole periods,
/// starting near a peak of the guard, so that its midpoint (a whole period in) agreed
/// with the model from the ends in value and nearly in slope, and the excursions of the
/// first periods were skipped (8 to 20 roots each), and one made so on purpose.
#[test]
fn loads_with_periods_dividing_the_first_step_lose_no_excursion() {
    let span = 6.0;
    let omega = 2.0 * PI * 64.0 / span; // span/32 is two periods
    let cases = [
        (
            0.31678089385249214,
            73.99046340197118,
            5.748431089800185,
            -1.49874225850236,
            -6.9660747451580685,
        ),
        (
            0.68977177164903,
            96.28808334746007,
            3.7881837902635493,
            -0.2200655926670101,
            3.986777683037896,
        ),
        (
            0.9341313183508408,
            67.94694152818262,
            3.4675096973587367,
            -0.027452766974642273,
            -5.959651686182518,
        ),
        (
            0.3546877687505156,
            73.81193687859387,
            1.510572494327531,
            -1.4477829113840561,
            4.088107545000279,
        ),
        // the guard at its peak at the start
        (
            0.9,
            omega,
            (PI / 2.0 + omega).rem_euclid(2.0 * PI),
            -1.0,
            -1.0 + span,
        ),
    ];
    for (k, &(c0, om, phase, a0, a1)) in cases.iter().enumerate() {
        let want = roots(c0, om, phase, a0, a1);
        check_one_node(
            (c0, om, phase),
            (a0, a1),
            Given::General {
                derivative: k % 2 == 0,
            },
            &want,
        );
    }
}

/// The general load `f(α) = f0 + φ(α) f1` of a finite-element case (f itself, without a
/// derivative).
fn general_along(data: &common::Data, phi: impl Fn(f64) -> f64 + Send + 'static) -> Load {
    let (g0, g1) = (data.f0.as_slice().to_vec(), data.f1.as_slice().to_vec());
    let n = g0.len();
    let f = Box::new(move |al: f64, out: &mut [f64]| -> Result<(), LoadFailure> {
        let s = phi(al);
        for ((o, a), b) in out.iter_mut().zip(&g0).zip(&g1) {
            *o = a + s * b;
        }
        Ok(())
    });
    Load::general(n, f, None)
}

/// The general load `f(α) = f0 + A sin(50 α) f1` of a finite-element case.
fn sine_shear_general(data: &common::Data, amp: f64) -> Load {
    general_along(data, move |al| amp * (50.0 * al).sin())
}

/// A finite-element mesh under `f(α) = f0 + A sin(50 α) f1` over three periods: every
/// transition point of the affine path with |φ| < A is met six times (up and down in each
/// period), at the α where A sin(50 α) equals it. Reference: the same mesh traced under
/// the affine load `f0 + φ f1` on [−A, A] (fold-free cases only), mapped through asin.
/// The load is given as a general load (f itself, each α condensed and solved for) and
/// as a basis load `[f0, f1]` with weights `(1, A sin 50α)` (each piece solved once per
/// basis vector, the guards along it combined from those solutions).
#[test]
fn finite_element_sine_shear_finds_every_transition() {
    let mut checked = 0;
    for seed in 0..12u64 {
        let case = common::fe_case(seed, 6, 2, 0.5);
        let data = &case.data;
        let problem = Arc::new(data.problem());
        let amp = 2.0;
        let affine = common::trace(problem.clone(), data.affine_load(), -amp, amp);
        let aff: Vec<&fricont::Event> = affine.events().iter().collect();
        if aff.is_empty() || aff.iter().any(|e| e.fold || e.bifurcation) {
            continue;
        }
        // expected α (with class change) in three periods of 50 α, from α = −π/100
        // (φ = −A) upward
        let period = 2.0 * PI / 50.0;
        let a0 = -PI / 100.0;
        let mut want: Vec<(f64, usize, Class, Class)> = Vec::new();
        for k in 0..3 {
            let base = a0 + k as f64 * period;
            for e in &aff {
                let s = (e.alpha / amp).asin(); // in (−π/2, π/2)
                // φ increasing through e.alpha: 50 α − 50 a0 = s + π/2 (from φ = −A)
                let up = base + (s + PI / 2.0) / 50.0;
                let down = base + (1.5 * PI - s) / 50.0;
                want.push((up, e.node, e.from, e.to));
                want.push((down, e.node, e.to, e.from));
            }
        }
        want.sort_by(|x, y| x.0.total_cmp(&y.0));
        let (f0, f1) = (data.f0.as_slice().to_vec(), data.f1.as_slice().to_vec());
        let weights = Box::new(
            move |al: f64, w: &mut [f64], dw: &mut [f64]| -> Result<(), LoadFailure> {
                w[0] = 1.0;
                w[1] = amp * (50.0 * al).sin();
                dw[0] = 0.0;
                dw[1] = 50.0 * amp * (50.0 * al).cos();
                Ok(())
            },
        );
        let loads = [
            ("general", sine_shear_general(data, amp)),
            ("basis", Load::basis(vec![f0, f1], weights).unwrap()),
        ];
        for (name, load) in loads {
            let mut path = Path::new(
                problem.clone(),
                load,
                PathOptions::window(a0, a0 + 3.0 * period),
            )
            .unwrap();
            path.start(a0, None).unwrap();
            assert_eq!(path.run().unwrap(), EndReason::Window, "seed {seed} {name}");
            let got = path.events();
            assert_eq!(
                got.len(),
                want.len(),
                "seed {seed} {name}: {} events, expected {}",
                got.len(),
                want.len()
            );
            for (g, w) in got.iter().zip(&want) {
                // compare in φ: the affine event is determined to 1e-12 there
                let (pg, pw) = (amp * (50.0 * g.alpha).sin(), amp * (50.0 * w.0).sin());
                assert!(
                    (pg - pw).abs() <= 1e-10,
                    "seed {seed} {name}: φ {pg} expected {pw} (α {} vs {})",
                    g.alpha,
                    w.0
                );
                assert_eq!(
                    (g.node, g.from, g.to),
                    (w.1, w.2, w.3),
                    "seed {seed} {name} at α {}",
                    w.0
                );
            }
        }
        checked += 1;
    }
    assert!(checked >= 4, "only {checked} fold-free cases");
}

/// A general load's transitions are located to the rounding of its guards: the sine
/// shear `f0 + A sin(50 α) f1` on three meshes (14 × 3, 21 × 1, 14 × 2 elements), every
/// event's φ = A sin(50 α) against the affine path `f0 + φ f1` traced in extended
/// precision (its events exact to about 1e-15). The root search used to end at the
/// point it evaluated once the guard was within 64 roundings of its scale: 2.3e-10 off in
/// φ on seed 52; the Newton step from that point (not evaluated) lands within 1e-11.
#[test]
fn general_load_transitions_to_the_rounding_of_the_guards() {
    let amp = 2.0;
    let (a0, a1) = (-PI / 100.0, -PI / 100.0 + 2.0 * PI / 50.0);
    for (seed, nx, ny, friction) in [(29u64, 14, 3, 1.0), (36, 21, 1, 0.5), (52, 14, 2, 0.5)] {
        let case = common::fe_case(seed, nx, ny, friction);
        let data = &case.data;
        let exact = Arc::new(
            data.builder()
                .extended_precision(fricont::ExtendedPrecision::On)
                .build()
                .unwrap(),
        );
        let phis: Vec<f64> = common::trace(exact, data.affine_load(), -amp, amp)
            .events()
            .iter()
            .map(|e| e.alpha)
            .collect();
        let problem = Arc::new(data.problem());
        let mut path = Path::new(
            problem,
            sine_shear_general(data, amp),
            PathOptions::window(a0, a1),
        )
        .unwrap();
        path.start(a0, None).unwrap();
        assert_eq!(path.run().unwrap(), EndReason::Window, "seed {seed}");
        // each affine event is met twice in a period (up and down)
        assert_eq!(path.events().len(), 2 * phis.len(), "seed {seed}");
        for e in path.events() {
            let phi = amp * (50.0 * e.alpha).sin();
            let off = phis
                .iter()
                .map(|x| (x - phi).abs())
                .fold(f64::INFINITY, f64::min);
            assert!(
                off <= 1e-11,
                "seed {seed}: event at φ = {phi} is {off:e} off"
            );
        }
    }
}

/// One node as above under the normal load `c(α) = 0.5 − 0.6 exp(−((α − α_b)/w)²)`: a
/// bump of width w = 2e-3 at α_b = 21.5/64 (half-way between two points of the dyadic
/// grid of 1/64 on which the default step control evaluates here) opens the node for a stretch of α of width
/// 2 w √ln 1.2 ≈ 1.7e-3 around α_b (transitions where the exponential equals 5/6). The
/// step control of the default (steps up to 1/8 of the window, each checked at its
/// midpoint) evaluates the load nowhere near the bump, sees a flat load and misses it:
/// the documented limit. `max_alpha_step` = 1e-3 (below the stretch) finds both
/// transitions, at the analytic α to 1e-10.
#[test]
fn a_narrow_bump_needs_max_alpha_step_and_is_found_with_it() {
    let (ab, w) = (21.5f64 / 64.0, 2e-3f64);
    let half = w * (6.0f64 / 5.0).ln().sqrt();
    let want = [
        (ab - half, Class::Stick, Class::Open),
        (ab + half, Class::Open, Class::Stick),
    ];
    let trace = |max_step: Option<f64>| {
        let a = CsrMatrix::from_dense(2, 2, &[1.0, 0.0, 0.0, 1.0]).unwrap();
        let n = CsrMatrix::from_dense(1, 2, &[1.0, 0.0]).unwrap();
        let t = CsrMatrix::from_dense(1, 2, &[0.0, 1.0]).unwrap();
        let problem = Arc::new(
            ProblemBuilder::new(a, Storage::Full, n, t)
                .friction_uniform(0.3)
                .build()
                .unwrap(),
        );
        let f = Box::new(move |al: f64, out: &mut [f64]| -> Result<(), LoadFailure> {
            out[0] = 0.5 - 0.6 * (-((al - ab) / w).powi(2)).exp();
            out[1] = 0.0;
            Ok(())
        });
        let mut opts = PathOptions::window(-1.0, 1.0);
        opts.max_alpha_step = max_step;
        let mut path = Path::new(problem, Load::general(2, f, None), opts).unwrap();
        path.start(-1.0, None).unwrap();
        assert_eq!(path.run().unwrap(), EndReason::Window);
        path.events()
            .iter()
            .map(|e| (e.alpha, e.from, e.to))
            .collect::<Vec<_>>()
    };
    let coarse = trace(None);
    assert!(
        coarse.is_empty(),
        "the default steps were expected to step over the bump (the documented limit), got {coarse:?}; \
         if the step control now sees it, update this test and the docs"
    );
    let fine = trace(Some(1e-3));
    assert_eq!(fine.len(), 2, "events {fine:?}");
    for (g, w) in fine.iter().zip(&want) {
        assert!((g.0 - w.0).abs() <= 1e-10, "α {} expected {}", g.0, w.0);
        assert_eq!((g.1, g.2), (w.1, w.2));
    }
    // invalid values are refused when the path is made
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let mut opts = PathOptions::window(-1.0, 1.0);
        opts.max_alpha_step = Some(bad);
        let data = common::one_node(0.3, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert!(
            Path::new(Arc::new(data.problem()), data.affine_load(), opts).is_err(),
            "max_alpha_step {bad} accepted"
        );
    }
}

/// Slender cantilevered strips (F = 5, random forces on every dof) under the basis load
/// `[f0, f1]` with weights `(1, φ(α))`, φ = −2 cos 5α, walked along the affine path
/// ([`walk_the_affine_path`]). The march used to take a guard as crossing
/// only once it was below its threshold: on the first strip a gap that reached zero
/// within its threshold where another node's guard crossed touched down there, 5.5e-5
/// in φ late; on the second a gap that dipped within its threshold about φ's turn lost
/// its touchdown and lift-off. On the third (κ(W) = 1.5e8, carried in extended
/// precision) a node stuck again 2.8e-8 in φ late: the root was refined in double-double
/// only where an estimate of its error (without the piece's conditioning) asked for it.
#[test]
fn slender_strips_under_an_oscillating_basis_load_walk_the_affine_path() {
    for (seed, nx, ny, ly) in [
        (4u64, 150usize, 2usize, 0.2),
        (8, 200, 3, 0.1),
        (0, 150, 2, 0.1),
    ] {
        walk_the_affine_path((seed, nx, ny, ly), |d: &common::Data| {
            let weights = move |a: f64, w: &mut [f64], dw: &mut [f64]| {
                w[0] = 1.0;
                w[1] = -WALK_AMP * (WALK_OMEGA * a).cos();
                dw[0] = 0.0;
                dw[1] = WALK_AMP * WALK_OMEGA * (WALK_OMEGA * a).sin();
                Ok::<(), LoadFailure>(())
            };
            Load::basis(
                vec![d.f0.as_slice().to_vec(), d.f1.as_slice().to_vec()],
                Box::new(weights),
            )
            .unwrap()
        });
    }
}

/// Curved bodies touching the foundation at their apex node with zero gap
/// ([`common::curved_body`] with `through_zero`) under `φ(α) f1`, φ = −2 cos 5α, as a basis
/// load and as a general load: the load passes through zero four times, where every
/// contact force vanishes and the apex is at the vertex, and the path walks the affine
/// path of `φ f1` up, back, up and back ([`walk_the_affine_path`]). (Swept on 150 such
/// bodies under each form of the load: every walk the same.)
#[test]
fn curved_bodies_under_a_load_oscillating_through_zero_walk_the_affine_path() {
    for seed in [0u64, 3, 6, 9] {
        let case = common::curved_body(seed, true);
        let ctx = format!("curved body seed {seed} (p = {})", case.data.p);
        walk_case(
            &format!("{ctx}, basis"),
            common::curved_body(seed, true),
            10,
            WALK,
            |d| {
                let weights = move |a: f64, w: &mut [f64], dw: &mut [f64]| {
                    w[0] = -WALK_AMP * (WALK_OMEGA * a).cos();
                    dw[0] = WALK_AMP * WALK_OMEGA * (WALK_OMEGA * a).sin();
                    Ok::<(), LoadFailure>(())
                };
                Load::basis(vec![d.f1.as_slice().to_vec()], Box::new(weights)).unwrap()
            },
        );
        walk_case(&format!("{ctx}, general"), case, 10, WALK, |d| {
            general_along(d, |a| -WALK_AMP * (WALK_OMEGA * a).cos())
        });
    }
}

/// Symmetric bodies (mirrored nodes switch together) under a fast oscillating general
/// load far out on the α axis, `φ = 1 − 2 cos ω(α − α0)` with ω = 30–180 and |α0| = 72–91,
/// walk the affine path of `f0 + φ f1` over φ ∈ [−1, 3] up, back, up and back (see
/// [`walk_the_affine_path`]). One rounding of α there moves φ by up to 2ω|α|ε, 1e-12 to
/// 7e-12, more than the thresholds of guards near zero: solutions a rounding apart
/// disagreed by more than those. In the sweep that found these three (742 such loads on
/// other windows, 100 of which stopped, none below |α| = 8.6) each stopped with "node k
/// fits no class", and so did this test's first walk without the change. A general
/// load's thresholds now cover 64 roundings of α (`ALPHA_ROUNDINGS`).
#[test]
fn symmetric_bodies_under_a_fast_general_load_far_out_walk_the_affine_path() {
    for (seed, nx, ny, f, omega, a0) in [
        (
            42u64,
            16usize,
            1usize,
            4.06188104778501,
            122.17555322003926,
            71.80009461076676,
        ),
        (
            54,
            15,
            1,
            0.307116830262165,
            30.072745203957446,
            82.8521901470101,
        ),
        (
            88,
            15,
            3,
            0.4151214020315178,
            181.59085315414504,
            -91.47841317441856,
        ),
    ] {
        let walk = Walk {
            sc: 1.0,
            amp: 2.0,
            omega,
            a0,
        };
        let ctx = format!("symmetric_fe_case({seed}, {nx}, {ny}, {f}), ω = {omega}, α0 = {a0}");
        walk_case(
            &ctx,
            common::symmetric_fe_case(seed, nx, ny, f),
            10,
            walk,
            move |d| general_along(d, move |a| walk.phi(a)),
        );
    }
}

/// The walk above under the same load given as a general load. On the first strip a
/// piece entered after ten updates of the path's factorisation (pivot ratio 2e-6) was
/// solved at the march's first point to a relative residual of 1.9e-9 only: that λ was
/// wrong by more than its size, its refinement in double-double failed, and the march
/// stopped with "the load's solutions … disagree" after 2050 of 3096 events. The march
/// now goes on with one LU of the piece where an updated solve fails its check. On the
/// second, a node lifted off at the end of a piece with dα/ds = 3.9e-5, just before a
/// fold: at the root's double its normal force was 1.7 times its threshold, no class but
/// slip fitted it, and "no neighbouring piece continues the path" after 297 of 736
/// events. The point is now moved along the piece's tangent to the guard's zero, as
/// under a basis load. The load's own rounding (each entry of f(α) in double) makes the
/// refined solutions noisy from α to α: on the first strip, once the reduced piece
/// matrix was built in another order of roundings, a cone guard's values at neighbouring
/// doubles of α went ±4e-11 about its root (threshold 3.5e-11) and the path stopped after
/// 654 events ("no neighbouring piece continues the path"); on the third (200 × 3) they
/// went ±6e-10 (threshold 6.5e-12) and a node fitted no class. The point is now moved
/// onto the guard's zero whatever the step in α (within the stretch of its root).
#[test]
fn slender_strips_under_an_oscillating_general_load_walk_the_affine_path() {
    for strip in [(5, 150, 2, 0.1), (2, 100, 4, 0.1), (2, 200, 3, 0.1)] {
        walk_the_affine_path(strip, |d: &common::Data| {
            general_along(d, |a| -WALK_AMP * (WALK_OMEGA * a).cos())
        });
    }
}

/// φ = −A cos ωα of the walks along the affine path.
const WALK_AMP: f64 = 2.0;
const WALK_OMEGA: f64 = 5.0;

/// The load factor of a walk along the affine path, `φ(α) = sc − amp cos ω(α − a0)`: from
/// α = a0 it sweeps [sc − amp, sc + amp] up and down.
#[derive(Clone, Copy, Debug)]
struct Walk {
    sc: f64,
    amp: f64,
    omega: f64,
    a0: f64,
}

impl Walk {
    fn phi(&self, a: f64) -> f64 {
        self.sc - self.amp * (self.omega * (a - self.a0)).cos()
    }
}

/// The walks' usual φ, −A cos ωα.
const WALK: Walk = Walk {
    sc: 0.0,
    amp: WALK_AMP,
    omega: WALK_OMEGA,
    a0: 0.0,
};

/// A slender cantilevered strip `(seed, nx, ny, ly)` (F = 5, 10 long) under the load
/// `load_of(data)`, `f0 + φ(α) f1` with φ = −2 cos 5α given some way, over two periods:
/// φ sweeps [−2, 2] up, down, up and down, and the path goes along the affine path's
/// curve and back. Reference: the independent tracer of `tests/common/reference.rs` on
/// the affine load `f0 + φ f1` over [−2, 2] (fricont's affine path checked against it
/// first), its events walked up, back (in reverse, each event's classes swapped), up and
/// back: the same events, each at the same φ to 1e-8.
fn walk_the_affine_path(
    (seed, nx, ny, ly): (u64, usize, usize, f64),
    load_of: impl Fn(&common::Data) -> Load,
) {
    let ctx = format!("seed {seed}, {nx} × {ny} elements on 10 × {ly}");
    walk_case(
        &ctx,
        common::fe_strip(seed, nx, ny, 5.0, 10.0, ly),
        100,
        WALK,
        load_of,
    );
}

/// [`walk_the_affine_path`] on `case` (its window replaced), its affine path with at
/// least `min_events` events, under `f0 + φ f1` with φ of `walk` over two periods from
/// α = `walk.a0`, given as `load_of(data)`.
fn walk_case(
    ctx: &str,
    mut case: common::Case,
    min_events: usize,
    walk: Walk,
    load_of: impl Fn(&common::Data) -> Load,
) {
    (case.a0, case.a1) = (walk.sc - walk.amp, walk.sc + walk.amp);
    let problem = Arc::new(case.data.problem());
    let c = common::reference::compare_case(&case, problem.clone(), 1e-9);
    c.check(1e-9)
        .unwrap_or_else(|e| panic!("{ctx}, affine: {e}"));
    let up = c.reference.evs();
    assert!(up.len() >= min_events, "{ctx}: {} events", up.len());
    // back: the transitions in reverse order (events of one transition in node
    // order), each event's classes swapped
    let mut back: Vec<(f64, usize, Class, Class)> = Vec::new();
    let mut end = up.len();
    while end > 0 {
        let mut start = end - 1;
        while start > 0 && up[start - 1].0 == up[end - 1].0 {
            start -= 1;
        }
        back.extend(
            up[start..end]
                .iter()
                .map(|&(a, i, from, to)| (a, i, to, from)),
        );
        end = start;
    }
    let want: Vec<_> = [&up, &back, &up, &back].into_iter().flatten().collect();
    let load = load_of(&case.data);
    let a1 = walk.a0 + 4.0 * PI / walk.omega;
    let mut path = Path::new(problem, load, PathOptions::window(walk.a0, a1)).unwrap();
    path.start(walk.a0, None).unwrap();
    assert_eq!(path.run().unwrap(), EndReason::Window, "{ctx}");
    let got: Vec<(f64, usize, Class, Class)> = path
        .events()
        .iter()
        .map(|e| (walk.phi(e.alpha), e.node, e.from, e.to))
        .collect();
    assert_eq!(got.len(), want.len(), "{ctx}: events");
    for (k, (g, w)) in got.iter().zip(&want).enumerate() {
        assert!(
            (g.1, g.2, g.3) == (w.1, w.2, w.3) && (g.0 - w.0).abs() <= 1e-8 * w.0.abs().max(1.0),
            "{ctx}: event {k}: {g:?}, the reference's {w:?}"
        );
    }
}

/// A general load near the point where the last contact force vanishes: a slender strip
/// (150 × 3 elements on 10 × 0.1, F = 5, κ(W) ~ 1e8, carried in extended precision) under
/// `f0 + α f1` given as a general load, every event against the independent reference's
/// affine trace (its own condensation and pieces in double-double). The path lifts the
/// body off node by node; on its last piece only node 1 is closed (slipping), so that
/// piece's normal force is `−(q_ν1(α) − g_1) / D` whatever D, and the lift-off is the
/// root of `q_ν1(α) = g_1`: `(g_1 − q0_ν1) / q1_ν1` by hand from the reference's
/// condensed load. There the march's points, refined in double-double, were measured
/// against max|λ| → 0: the refinement failed, the double-precision points (off by
/// κ(A) ε of the load) stood, and the lift-off came 1.1e-8 in α early.
#[test]
fn a_general_load_locates_the_last_lift_off_from_the_data() {
    let mut case = common::fe_strip(3, 150, 3, 5.0, 10.0, 0.1);
    (case.a0, case.a1) = (-2.0, 2.0);
    let problem = Arc::new(case.data.problem());
    assert!(problem.extended_precision());
    let c = common::reference::compare_case(&case, problem.clone(), 1e-12);
    c.check(1e-12).unwrap_or_else(|e| panic!("affine: {e}"));
    let want = &c.reference.events;
    let last = want.last().expect("events");
    assert_eq!(
        (last.node, last.from, last.to),
        (0, Class::SlipPlus, Class::Open)
    );
    let pieces = &c.reference.pieces;
    let before = &pieces[pieces.len() - 2].0;
    assert!(before[0] == Class::SlipPlus && before[1..].iter().all(|&k| k == Class::Open));
    let cond = common::reference::Condensed::from_data(&case.data);
    let root = (cond.gap[0] - cond.q0[0] - cond.q0_lo[0]) / (cond.q1[0] + cond.q1_lo[0]);
    assert!(
        (last.alpha - root).abs() <= 1e-14,
        "{} by hand, {}",
        root,
        last.alpha
    );

    let load = general_along(&case.data, |a| a);
    let mut path = Path::new(problem, load, PathOptions::window(-2.0, 2.0)).unwrap();
    path.start(-2.0, None).unwrap();
    assert_eq!(path.run().unwrap(), EndReason::Window);
    let got = path.events();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g.node, g.from, g.to) == (w.node, w.from, w.to)
                && (g.alpha - w.alpha).abs() <= 1e-12 * w.alpha.abs().max(1.0),
            "event {}: α {} node {} {:?} → {:?}, the reference's α {} node {} {:?} → {:?}",
            g.index,
            g.alpha,
            g.node,
            g.from,
            g.to,
            w.alpha,
            w.node,
            w.from,
            w.to
        );
    }
}

/// The node's contact force dips through zero by less than its zero threshold (about
/// 1e-11 of the load's scale): c0 = 1 − δ with δ from 2e-12 to 1e-11 opens it for a
/// stretch of α of width 2 √(2δ) / ω (3e-7 at most) about each minimum of the sine. The
/// march took a guard as crossing only once it was below its threshold, and reported no
/// event at all; a guard that goes through zero crosses there, as on an affine load.
/// Given as a basis load (whose thresholds are those of its exact terms, not the smaller
/// ones of a general load at the dip), the whole open stretch fitted inside one step and
/// each touchdown was taken at the next step's start: 3.8e-8 to 1.6e-7 in α late.
#[test]
fn dips_through_zero_within_the_threshold_are_transitions() {
    for delta in [2e-12, 5e-12, 1e-11] {
        for omega in [20.0, 53.0] {
            for (k, (a0, a1)) in [(-1.0, 1.0), (1.0, -1.0)].into_iter().enumerate() {
                let c0 = 1.0 - delta;
                let want = roots(c0, omega, 0.0, a0, a1);
                assert!(want.len() >= 10, "{} roots", want.len());
                for given in [Given::General { derivative: k == 0 }, Given::Basis] {
                    check_one_node((c0, omega, 0.0), (a0, a1), given, &want);
                }
            }
        }
    }
}

/// A gap closing at a grazing slope under a general load: on a slender strip (F = 5) under
/// `f0 + φ(α) f1`, φ = −2 cos 5α, node 190 (1-based) touches down at φ = 1.29396 on the
/// affine path, while node 10 sticks at φ = 1.29352. There, node 190's gap was 4.6e-12
/// against a threshold of 6.4e-10 (a general load's thresholds hold the load's change
/// over the window, 2.5 in α here), and its root 2.1e-5 away along the tangent: it was
/// counted at zero, and touched down with node 10, 4.4e-4 in φ early, without an error.
/// Reference: the affine path in φ (the reference tracer), mapped through φ; the first
/// rise of φ, from −2 to 1.35, on the window of two periods.
#[test]
fn a_general_load_does_not_merge_a_grazing_touchdown_into_another_transition() {
    let (amp, omega) = (WALK_AMP, WALK_OMEGA);
    let phi = move |a: f64| -amp * (omega * a).cos();
    let mut case = common::fe_strip(5, 200, 2, 5.0, 10.0, 0.1);
    (case.a0, case.a1) = (-amp, amp);
    let problem = Arc::new(case.data.problem());
    let c = common::reference::compare_case(&case, problem.clone(), 1e-9);
    c.check(1e-9).unwrap_or_else(|e| panic!("affine: {e}"));
    let stop = 1.35;
    let want: Vec<_> = c
        .reference
        .events
        .iter()
        .filter(|e| e.alpha <= stop)
        .collect();
    // the two events of the case, 4.4e-4 apart in φ on the reference
    let at = |node: usize| {
        want.iter()
            .find(|e| e.node == node && e.alpha > 1.29 && e.alpha < 1.3)
            .unwrap_or_else(|| panic!("node {} near φ = 1.29", node + 1))
            .alpha
    };
    assert!(at(189) - at(9) > 4e-4, "{} {}", at(189), at(9));

    let load = general_along(&case.data, phi);
    let a1 = 4.0 * PI / omega;
    let mut path = Path::new(problem, load, PathOptions::window(0.0, a1)).unwrap();
    path.start(0.0, None).unwrap();
    // up to φ = stop on the first rise (α < π/ω)
    let a_stop = (-stop / amp).acos() / omega;
    while path.events().last().is_none_or(|e| e.alpha <= a_stop) {
        path.step().unwrap();
    }
    let got: Vec<_> = path.events().iter().filter(|e| e.alpha <= a_stop).collect();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        let gp = phi(g.alpha);
        assert!(
            (g.node, g.from, g.to) == (w.node, w.from, w.to) && (gp - w.alpha).abs() <= 1e-8,
            "event {}: φ {gp} node {} {:?} → {:?}, the reference's φ {} node {} {:?} → {:?}",
            g.index,
            g.node + 1,
            g.from,
            g.to,
            w.alpha,
            w.node + 1,
            w.from,
            w.to
        );
    }
}

/// Loads that turn just past a transition: `φ(α) = s_max − A + A(1 − cos 5α)`, A = 1/2,
/// rising to its maximum `s_max = s_k + d max(1, |s_k|)` at α = π/5 and back, where `s_k`
/// is a lift-off or a touchdown of the affine path (the independent reference of
/// `tests/common/reference.rs` on a stretch of φ around it). The node switches at the α
/// where φ = s_k rising and switches back at its mirror image about π/5, and every
/// other transition of the stretch is met up and back the same way: the expected events
/// are the reference's through φ (classes swapped where φ falls), to 1e-9 in φ (a
/// switch taken at φ's turn is d = 1e-8 off), no fold, and the path must reach the
/// window's end. The guard of the switching node goes beyond zero by a few thresholds at
/// most (d = 1e-5) or less than one (d = 1e-8): the march took the piece's entry as that
/// guard's root, or φ's turn itself, and the path folded back to the window's start
/// without an error (found by a sweep of 7,702 turning loads against the reference:
/// three such traces, all near a turn; graze scans of one strip at d = 1e-8 … 1e-2 gave
/// 70 of 1440 under a basis load, 111 under a general one, and after the lift-offs were
/// mended 4 and 35, touchdowns at d = 1e-8: 23 of them folded back without an error).
#[test]
fn a_load_turning_just_past_a_transition_comes_back_through_it() {
    // (strip, node switching at s_k (1-based), its class after, s_k roughly where the node
    // switches more than once, d, the load as a general load too, whether the path may
    // stop with the error naming a way back instead)
    let strip98 = (98u64, 138usize, 1usize, 0.4951900771206396, 0.178);
    let cases = [
        (
            (2u64, 57usize, 3usize, 0.46368478231107124, 0.277),
            46usize,
            Class::Open,
            None,
            1e-5,
            true,
            false,
        ),
        (
            (2, 57, 3, 0.46368478231107124, 0.277),
            46,
            Class::Open,
            None,
            1e-6,
            true,
            false,
        ),
        (strip98, 129, Class::Open, None, 1e-8, false, false),
        // touchdowns whose contact force, entered 4e-8 in α early (the gap flat within its
        // rounding), was taken to leave at the touchdown's own α; and whose gap, 6.7e-15
        // below zero at φ's turn, had its root taken there
        (
            strip98,
            117,
            Class::SlipMinus,
            Some(-0.237),
            1e-8,
            true,
            false,
        ),
        (
            strip98,
            87,
            Class::SlipMinus,
            Some(-0.179),
            1e-8,
            true,
            false,
        ),
        // a lift-off whose gap, 1e-10 past it, rises to 4e-17 about φ's turn, below its
        // rounding: the lift-off and the touchdown 8e-6 in α later are not resolved, and
        // the path took the gap's root 1.9e-13 after the lift-off, walked back along the
        // slipping piece and went back to the window's start without an error
        (strip98, 99, Class::Open, Some(0.504), 1e-10, false, true),
        // a lift-off whose gap's root was taken 2.6e-6 in α after it (before φ's turn,
        // the forces moving by 1e-10 of their scale along that piece): the walk back
        // along the slipping piece was taken as a fold
        (strip98, 105, Class::Open, Some(0.173), 1e-10, false, true),
    ];
    let (amp, omega, wspan) = (0.5, 5.0, 0.05);
    for ((seed, nx, ny, f, ly), node, after, near, d, general, may_stop) in cases {
        // The affine reference over a stretch of φ holding the transition (found first on a
        // wider one, then each trace's expected events from it).
        let mut case = common::fe_strip(seed, nx, ny, f, 10.0, ly);
        (case.a0, case.a1) = (-3.0, 3.0);
        let problem = Arc::new(case.data.problem());
        let wide = common::reference::compare_case(&case, problem.clone(), 1e-9);
        let sk = wide
            .reference
            .evs()
            .into_iter()
            .filter(|e| e.1 + 1 == node && e.3 == after)
            .min_by(|x, y| {
                let off = |s: f64| near.map_or(0.0, |n: f64| (s - n).abs());
                off(x.0).total_cmp(&off(y.0))
            })
            .expect("the transition")
            .0;
        let smax = sk + d * sk.abs().max(1.0);
        (case.a0, case.a1) = (smax - 2.0 * wspan, smax + wspan);
        let c = common::reference::compare_case(&case, problem.clone(), 1e-9);
        c.check(1e-9)
            .unwrap_or_else(|e| panic!("seed {seed}, affine: {e}"));
        let sc = smax - amp;
        let phi = move |a: f64| sc - amp * (omega * a).cos();
        let th = ((sc - (smax - wspan)) / amp).acos();
        let (start, end) = (th / omega, (2.0 * PI - th) / omega);
        // Each reference event on (φ(start), s_max) met rising at α = acos((sc − s)/A)/ω
        // and falling at its mirror image 2π/ω − α.
        let mut want: Vec<(f64, f64, usize, Class, Class)> = Vec::new();
        for (s, i, from, to) in c.reference.evs() {
            if s > smax - wspan && s < smax {
                let a = ((sc - s) / amp).acos() / omega;
                want.push((a, s, i, from, to));
                want.push((2.0 * PI / omega - a, s, i, to, from));
            }
        }
        want.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)));
        assert!(
            want.iter().any(|w| w.2 + 1 == node),
            "seed {seed}: the transition"
        );
        let forms: &[&str] = if general {
            &["basis", "general"]
        } else {
            &["basis"]
        };
        for &form in forms {
            let ctx = format!("seed {seed}, {nx} × {ny}, d = {d:e}, {form} load");
            let load = if form == "basis" {
                let weights = move |a: f64, w: &mut [f64], dw: &mut [f64]| {
                    w[0] = 1.0;
                    w[1] = phi(a);
                    dw[0] = 0.0;
                    dw[1] = amp * omega * (omega * a).sin();
                    Ok::<(), LoadFailure>(())
                };
                let vs = vec![
                    case.data.f0.as_slice().to_vec(),
                    case.data.f1.as_slice().to_vec(),
                ];
                Load::basis(vs, Box::new(weights)).unwrap()
            } else {
                general_along(&case.data, phi)
            };
            let mut path =
                Path::new(problem.clone(), load, PathOptions::window(start, end)).unwrap();
            path.start(start, None).unwrap();
            match path.run() {
                Err(e) if may_stop => {
                    let msg = e.to_string();
                    assert!(
                        msg.contains("walks back along the path's own pieces"),
                        "{ctx}: {msg}"
                    );
                    continue;
                }
                end => assert_eq!(end.unwrap(), EndReason::Window, "{ctx}"),
            }
            assert!(path.events().iter().all(|e| !e.fold), "{ctx}: a fold");
            let mut got: Vec<(f64, f64, usize, Class, Class)> = path
                .events()
                .iter()
                .map(|e| (e.alpha, phi(e.alpha), e.node, e.from, e.to))
                .collect();
            // (events of one transition in node order, as the expected ones)
            got.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)));
            assert_eq!(got.len(), want.len(), "{ctx}: events {got:?}");
            for (g, w) in got.iter().zip(&want) {
                assert!(
                    (g.2, g.3, g.4) == (w.2, w.3, w.4)
                        && (g.1 - w.1).abs() <= 1e-9 * w.1.abs().max(1.0),
                    "{ctx}: event at φ {} node {} {:?} → {:?}, expected φ {} node {} {:?} → {:?}",
                    g.1,
                    g.2 + 1,
                    g.3,
                    g.4,
                    w.1,
                    w.2 + 1,
                    w.3,
                    w.4
                );
            }
        }
    }
}
