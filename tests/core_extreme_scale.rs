//! Extreme but valid scales of A (issue 10, item 5): the repository's sample with A and the
//! load multiplied by the same factor s is the same contact problem (u unchanged, λ × s),
//! so it must give the same transition points, in every storage of A, or an accurate
//! error where the scale makes the data themselves unrepresentable.
//!
//! * s = 2^k (k = ±130, −900, +1020): exact in floating point, so the events must agree
//!   with the unscaled ones to 1e-10 relative, λ must be 2^k times theirs and u equal.
//! * s = 4e307 (the largest entry of A becomes 9.2e307: `(a + b)/2` of two such entries
//!   overflows) and s = 1e-310 (every entry of A subnormal, at most 45 significant bits;
//!   the load's entries down to ~30 bits). For 1e-310 the data themselves are rounded to
//!   ~2e-10 relative, so they are compared with the *same rounded numbers* brought back
//!   into the normal range by the exact factor 2^1030 (tight), and with the unscaled
//!   sample to what that rounding allows.
//! * Below 40 significant bits (A × 1e-315) the build refuses with a range error that
//!   says how to rescale; A tiny with an unscaled load (u overflows) is an error, not an
//!   infinite u; a condensed W near f64::MAX works; a non-symmetric A near f64::MAX is
//!   reported with the caller's numbers.

mod common;

use std::sync::Arc;

use common::{Brute, random_case, read_mtx, read_vec};
use fricont::path::State;
use fricont::{CsrMatrix, Error, Event, Load, Path, PathOptions, Problem, ProblemBuilder, Storage};

/// The sample's data as read from tests/data/sample-rect30 with the tests' own reader.
struct Sample {
    n: usize,
    a: Vec<(usize, usize, f64)>,
    nm: CsrMatrix,
    tm: CsrMatrix,
    f0: Vec<f64>,
    f1: Vec<f64>,
}

fn sample() -> Sample {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sample-rect30");
    let (n, _, a) = read_mtx(&dir.join("A.mtx"));
    let csr = |name: &str| {
        let (r, c, t) = read_mtx(&dir.join(name));
        CsrMatrix::from_triplets(name, r, c, &t).unwrap()
    };
    Sample {
        n,
        a,
        nm: csr("N.mtx"),
        tm: csr("T.mtx"),
        f0: read_vec(&dir.join("f0.txt")),
        f1: read_vec(&dir.join("f1.txt")),
    }
}

/// The problem with every entry of A mapped by `sa`, in `storage`.
fn builder(s: &Sample, storage: Storage, sa: impl Fn(f64) -> f64) -> ProblemBuilder {
    let t: Vec<(usize, usize, f64)> =
        s.a.iter()
            .filter(|e| match storage {
                Storage::Full => true,
                Storage::Lower => e.0 >= e.1,
                Storage::Upper => e.0 <= e.1,
            })
            .map(|&(i, j, v)| (i, j, sa(v)))
            .collect();
    let a = CsrMatrix::from_triplets("A", s.n, s.n, &t).unwrap();
    ProblemBuilder::new(a, storage, s.nm.clone(), s.tm.clone()).friction_uniform(0.3)
}

/// Events and their full states on [-0.5, 1.5], the load's entries mapped by `sf`.
fn trace(problem: Problem, s: &Sample, sf: impl Fn(f64) -> f64) -> (Vec<Event>, Vec<State>) {
    let f0 = s.f0.iter().map(|&v| sf(v)).collect();
    let f1 = s.f1.iter().map(|&v| sf(v)).collect();
    let load = Load::affine(f0, f1).unwrap();
    let mut path = Path::new(Arc::new(problem), load, PathOptions::window(-0.5, 1.5)).unwrap();
    path.start(-0.5, None).unwrap();
    let end = path.run().unwrap();
    assert_eq!(end.name(), "window", "{end:?}");
    let states = path.event_states(0..path.events().len()).unwrap();
    (path.events().to_vec(), states)
}

/// `‖A u − f − Nᵀλν − Tᵀλt‖∞` over the largest magnitude of the terms that make it up
/// (the sum of |terms| per row), all computed after scaling u, f and λ by one power of two
/// that keeps the products in range (exact): SPEC's relative residual, independently of
/// the library's.
fn own_residual(d: &common::Data, s: &State, f: &[f64]) -> f64 {
    let big = inf(&s.u)
        .max(inf(f))
        .max(inf(&s.lambda_n))
        .max(inf(&s.lambda_t));
    let k = if big > 0.0 {
        -(big.log2().ceil() as i32)
    } else {
        0
    };
    let sc = |x: f64| x * 2f64.powi(k / 2) * 2f64.powi(k - k / 2);
    let (mut r, mut scale) = (0.0f64, 0.0f64);
    for (i, &fi) in f.iter().enumerate() {
        let mut terms = vec![-sc(fi)];
        for j in 0..d.n {
            terms.push(d.a[(i, j)] * sc(s.u[j]));
        }
        for l in 0..d.p {
            terms.push(-d.nm[(l, i)] * sc(s.lambda_n[l]));
            terms.push(-d.tm[(l, i)] * sc(s.lambda_t[l]));
        }
        r = r.max(terms.iter().sum::<f64>().abs());
        scale = scale.max(terms.iter().map(|t| t.abs()).fold(0.0, f64::max));
    }
    r / scale
}

fn inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The scaled trace `y` against the reference `x`: α to `tol_alpha` relative, the same
/// nodes, classes and flags; λ of `y` mapped by `unscale` equal to λ of `x` (to `tol_lam`
/// relative to its largest entry) and u equal (to `tol_u`); every state's residual of `y`
/// ≤ 1e-10.
#[allow(clippy::too_many_arguments)]
fn compare(
    ctx: &str,
    x: &(Vec<Event>, Vec<State>),
    y: &(Vec<Event>, Vec<State>),
    unscale: &dyn Fn(f64) -> f64,
    tol_alpha: f64,
    tol_lam: f64,
    tol_u: f64,
) {
    let close = |a: f64, b: f64| (a - b).abs() <= tol_alpha * 1f64.max(a.abs()).max(b.abs());
    assert_eq!(x.0.len(), y.0.len(), "{ctx}: number of events");
    assert!(x.0.len() >= 20, "{ctx}: the sample has ≥ 20 events");
    for ((e, f), (s, t)) in x.0.iter().zip(&y.0).zip(x.1.iter().zip(&y.1)) {
        assert!(
            close(e.alpha, f.alpha),
            "{ctx}: event {} at α {:.14e}, unscaled {:.14e}",
            e.index + 1,
            f.alpha,
            e.alpha
        );
        assert_eq!(
            (e.node, e.from, e.to, e.fold, e.transition),
            (f.node, f.from, f.to, f.fold, f.transition),
            "{ctx}: event {}",
            e.index + 1
        );
        let lx: Vec<f64> = e.lambda_n.iter().chain(&e.lambda_t).copied().collect();
        let ly: Vec<f64> = f.lambda_n.iter().chain(&f.lambda_t).copied().collect();
        let lscale = inf(&lx);
        for (a, b) in lx.iter().zip(&ly) {
            assert!(
                (unscale(*b) - a).abs() <= tol_lam * lscale,
                "{ctx}: event {}: λ {b:e} unscaled {:e} vs {a:e} (max |λ| {lscale:e})",
                e.index + 1,
                unscale(*b)
            );
        }
        let uscale = inf(&s.u);
        let du =
            s.u.iter()
                .zip(&t.u)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            du <= tol_u * uscale,
            "{ctx}: event {}: u differs by {du:e} (max |u| {uscale:e})",
            e.index + 1
        );
        assert!(
            t.residual <= 1e-10,
            "{ctx}: event {}: residual {:e}",
            e.index + 1,
            t.residual
        );
    }
}

const STORAGES: [Storage; 3] = [Storage::Full, Storage::Lower, Storage::Upper];

/// 2^k for |k| ≤ 1023.
fn pow2(k: i32) -> f64 {
    2f64.powi(k)
}

#[test]
fn power_of_two_scalings_give_the_same_events() {
    let s = sample();
    for storage in [Storage::Full, Storage::Lower] {
        let base = trace(builder(&s, storage, |v| v).build().unwrap(), &s, |v| v);
        // k = 40: within [2^-64, 2^64], A is used as given.
        for k in [40, 130, -130, -900, 1020] {
            let c = pow2(k);
            let ctx = format!("{storage:?}, A and f × 2^{k}");
            let problem = builder(&s, storage, |v| v * c).build().unwrap();
            // The internal scaling brings A's largest entry (2.31 × 2^k) into [1, 4).
            let ka = problem.a_scale_log2();
            if k == 40 {
                assert_eq!(ka, 0, "{ctx}");
            } else {
                let m = problem.a().unwrap().max_abs();
                assert!(
                    (1.0..4.0).contains(&m) && ka % 2 == 0,
                    "{ctx}: 2^{ka} A, max {m}"
                );
            }
            let scaled = trace(problem, &s, |v| v * c);
            compare(&ctx, &base, &scaled, &|v| v / c, 1e-10, 1e-9, 1e-9);
        }
    }
}

#[test]
fn a_times_4e307_in_every_storage() {
    let s = sample();
    let full = trace(
        builder(&s, Storage::Full, |v| v).build().unwrap(),
        &s,
        |v| v,
    );
    for storage in STORAGES {
        let ctx = format!("{storage:?}, A and f × 4e307");
        let base = trace(builder(&s, storage, |v| v).build().unwrap(), &s, |v| v);
        // (a + b)/2 of two entries 9.2e307 overflows: full storage used to be refused as
        // not positive definite.
        let problem = builder(&s, storage, |v| v * 4e307).build().unwrap();
        assert_eq!(problem.a_scale_log2(), -1022, "{ctx}");
        let scaled = trace(problem, &s, |v| v * 4e307);
        compare(&ctx, &base, &scaled, &|v| v / 4e307, 1e-10, 1e-9, 1e-9);
        // the storages agree with each other (the sample's A is symmetric to ~3e-17)
        compare(
            &format!("{ctx} vs full"),
            &full,
            &scaled,
            &|v| v / 4e307,
            1e-10,
            1e-9,
            1e-9,
        );
    }
}

#[test]
fn a_times_1e_minus_310_in_every_storage() {
    let s = sample();
    let sub = |v: f64| v * 1e-310;
    // × 2^1030, exact (2^1030 itself is not a double)
    let back = |v: f64| v * pow2(1000) * pow2(30);
    for storage in STORAGES {
        let ctx = format!("{storage:?}, A and f × 1e-310");
        let problem = builder(&s, storage, sub).build().unwrap();
        assert_eq!(problem.a_scale_log2(), 1030, "{ctx}");
        let scaled = trace(problem, &s, sub);
        // The same rounded numbers times 2^1030 (exact): a problem in the normal range.
        let normal = builder(&s, storage, |v| back(sub(v))).build().unwrap();
        assert_eq!(normal.a_scale_log2(), 0);
        let normal = trace(normal, &s, |v| back(sub(v)));
        // λ of the subnormal problem is itself subnormal (~1e-314, ~31 significant bits):
        // it and the u solved from it are good to ~1e-9.
        compare(&ctx, &normal, &scaled, &back, 1e-10, 1e-8, 1e-7);
        // Against the unscaled sample: the data were rounded by the scaling (f1's entries
        // ~6e-315 keep ~30 bits, 4e-10 relative), which moves the events by up to ~1e-10.
        let base = trace(builder(&s, storage, |v| v).build().unwrap(), &s, |v| v);
        compare(
            &format!("{ctx} vs unscaled"),
            &base,
            &scaled,
            &|v| v / 1e-310,
            5e-10,
            1e-8,
            1e-7,
        );
    }
}

#[test]
fn a_too_small_to_represent_is_a_range_error() {
    let s = sample();
    for storage in STORAGES {
        // 2.3e-315: 29 significant bits
        let e = builder(&s, storage, |v| v * 1e-315).build().unwrap_err();
        assert!(
            matches!(&e, Error::InvalidParameter(m) if m.contains("subnormal") && m.contains("29 significant bits") && m.contains("power of two")),
            "{storage:?}: {e}"
        );
    }
}

#[test]
fn tiny_a_with_an_unscaled_load_is_an_error_not_an_infinite_u() {
    let s = sample();
    let problem = builder(&s, Storage::Full, |v| v * 1e-310).build().unwrap();
    let load = Load::affine(s.f0.clone(), s.f1.clone()).unwrap();
    let mut path = Path::new(Arc::new(problem), load, PathOptions::window(-0.5, 1.5)).unwrap();
    // u is asked for where a state is (the start's here), and overflows there.
    let e = path
        .start(-0.5, None)
        .and_then(|()| path.start_state())
        .unwrap_err();
    assert!(
        matches!(&e, Error::Numerical(m) if m.contains("overflows")),
        "{e}"
    );
    // A huge A with an unscaled load: u is tiny (subnormal), λ those of the sample.
    let base = trace(
        builder(&s, Storage::Full, |v| v).build().unwrap(),
        &s,
        |v| v,
    );
    let huge = trace(
        builder(&s, Storage::Full, |v| v * 4e307).build().unwrap(),
        &s,
        |v| v,
    );
    assert_eq!(base.0.len(), huge.0.len());
    for (e, f) in base.0.iter().zip(&huge.0) {
        assert!((e.alpha - f.alpha).abs() <= 1e-10, "{e:?} vs {f:?}");
        assert_eq!((e.node, e.from, e.to), (f.node, f.from, f.to));
    }
    for (x, y) in base.1.iter().zip(&huge.1) {
        let (ux, uy) = (inf(&x.u), inf(&y.u));
        assert!(
            (uy * 4e307 - ux).abs() <= 1e-6 * ux && y.residual <= 1e-10,
            "u {uy:e} × 4e307 vs {ux:e}, residual {:e}",
            y.residual
        );
    }
}

#[test]
fn non_symmetric_a_near_the_largest_double_reports_the_callers_numbers() {
    let s = sample();
    // Perturb the largest off-diagonal entry of row 1 in one triangle only, by 1e-6 of
    // max |A|, then scale by 4e307.
    let amax = s.a.iter().fold(0.0f64, |m, e| m.max(e.2.abs()));
    let k = (0..s.a.len())
        .filter(|&k| s.a[k].0 == 0 && s.a[k].1 != 0)
        .max_by(|&x, &y| s.a[x].2.abs().total_cmp(&s.a[y].2.abs()))
        .unwrap();
    let mut t = s.a.clone();
    t[k].2 += 1e-6 * amax;
    let t: Vec<_> = t.into_iter().map(|(i, j, v)| (i, j, v * 4e307)).collect();
    let a = CsrMatrix::from_triplets("A", s.n, s.n, &t).unwrap();
    let e = ProblemBuilder::new(a, Storage::Full, s.nm.clone(), s.tm.clone())
        .build()
        .unwrap_err();
    let Error::NotSymmetric(m) = &e else {
        panic!("{e}")
    };
    // "... differ by D (tolerance 1e-10 * max|A| = T)": D = 1e-6 max|A| × 4e307 (up to
    // the sample's own asymmetry, 3e-17), T = 1e-10 × 4e307 max|A|.
    let num = |after: &str| -> f64 {
        let rest = &m[m.find(after).unwrap() + after.len()..];
        rest.split([' ', ')', ';']).next().unwrap().parse().unwrap()
    };
    let (d, tol) = (num("differ by "), num("max|A| = "));
    let want = 1e-6 * amax * 4e307;
    assert!((d - want).abs() <= 1e-9 * want, "{m}");
    assert!((tol - 1e-10 * amax * 4e307).abs() <= 1e-12 * tol, "{m}");
}

/// W near f64::MAX from a host that condenses itself: `(w_ij + w_ji)/2` overflowed.
#[test]
fn condensed_w_near_the_largest_double() {
    for seed in 0..10 {
        let case = random_case(seed);
        let br = Brute::condensed_only(&case.data);
        // W × c with q and g × c/1e6 is the same problem with λ / 1e6 (q × c would
        // overflow). c = 1.2 × 2^1023 / max|W|: the largest entry of W becomes
        // 1.2 × 2^1023 ≈ 1.08e308, and the sum of two such overflows. (c itself may not
        // be a double: it is applied as (1.2 / max|W|) × 2^1023.)
        let c1 = 1.2 / br.w.amax();
        let run = |big: bool| {
            let m = br.w.nrows();
            let sw = |v: f64| if big { v * c1 * pow2(1023) } else { v };
            let sq = |v: f64| if big { v * c1 * 1e-6 * pow2(1023) } else { v };
            let w = fricont::faer::Mat::from_fn(m, m, |i, j| sw(br.w[(i, j)]));
            let q0: Vec<f64> = br.q0.iter().map(|&v| sq(v)).collect();
            let q1: Vec<f64> = br.q1.iter().map(|&v| sq(v)).collect();
            let problem = ProblemBuilder::condensed(w)
                .friction(case.data.friction.clone())
                .gap(case.data.gap.iter().map(|&g| sq(g)).collect())
                .build()
                .unwrap_or_else(|e| panic!("seed {seed}, big W {big}: {e}"));
            common::trace(
                Arc::new(problem),
                Load::affine(q0, q1).unwrap(),
                case.a0,
                case.a1,
            )
        };
        let (base, big) = (run(false), run(true));
        assert_eq!(base.events().len(), big.events().len(), "seed {seed}");
        for (e, f) in base.events().iter().zip(big.events()) {
            assert!(
                (e.alpha - f.alpha).abs() <= 1e-10 * 1f64.max(e.alpha.abs()),
                "seed {seed}: {e:?} vs {f:?}"
            );
            assert_eq!(
                (e.node, e.from, e.to),
                (f.node, f.from, f.to),
                "seed {seed}"
            );
        }
    }
}

/// A path (not started) over random case `case` with its load vectors and its gap scaled
/// by `c`; `load` builds the load from f0·c and f1·c.
fn scaled_path(case: &common::Case, c: f64, load: impl FnOnce(Vec<f64>, Vec<f64>) -> Load) -> Path {
    let f0 = case.data.f0.iter().map(|v| v * c).collect();
    let f1 = case.data.f1.iter().map(|v| v * c).collect();
    let mut data = case.data.clone();
    data.gap.iter_mut().for_each(|g| *g *= c);
    let opts = PathOptions::window(case.a0, case.a1);
    Path::new(Arc::new(data.problem()), load(f0, f1), opts).unwrap()
}

fn affine(f0: Vec<f64>, f1: Vec<f64>) -> Load {
    Load::affine(f0, f1).unwrap()
}

/// Runs `scaled_path(case, c, load)` through its window, and checks it against the
/// unscaled run `base` (`None`: returns this run as the base): the same end and the same
/// events (α to 1e-9, nodes, classes, flags) with λ scaled by c; or, for a load scaled
/// beyond 1e300 (`target`), an error that says the numbers are near the largest double
/// (or that the load function itself returned an infinity), after events that are the
/// first of the base's. Returns whether it traced.
fn check_scaled(
    ctx: &str,
    case: &common::Case,
    c: f64,
    target: f64,
    load: impl FnOnce(Vec<f64>, Vec<f64>) -> Load,
    base: Option<&(fricont::EndReason, Vec<Event>)>,
) -> Option<(fricont::EndReason, Vec<Event>)> {
    let mut path = scaled_path(case, c, load);
    let end = path.start(case.a0, None).and_then(|()| path.run());
    let events = path.events().to_vec();
    let end = match end {
        Ok(e) => Some(e),
        Err(Error::Numerical(m)) if target > 1e300 => {
            assert!(m.contains("near the largest double"), "{ctx}: {m}");
            None
        }
        // (this test's general load, f0 c + φ(α) f1 c, overflows itself further on)
        Err(Error::Load {
            code: 0, message, ..
        }) if target > 1e300 => {
            assert!(
                message.contains("returned") && message.contains("inf"),
                "{ctx}: {message}"
            );
            None
        }
        Err(e) => panic!("{ctx}: {e}"),
    };
    let Some((base_end, base)) = base else {
        return end.map(|e| (e, events));
    };
    match &end {
        Some(end) => {
            assert_eq!(end, base_end, "{ctx}");
            assert_eq!(events.len(), base.len(), "{ctx}: {events:?} vs {base:?}");
        }
        None => assert!(events.len() <= base.len(), "{ctx}: {events:?} vs {base:?}"),
    }
    for (x, y) in base.iter().zip(&events) {
        assert!(
            (x.alpha - y.alpha).abs() <= 1e-9 * (1.0 + x.alpha.abs()),
            "{ctx}: {x:?} vs {y:?}"
        );
        assert_eq!(
            (x.node, x.from, x.to, x.fold, x.bifurcation),
            (y.node, y.from, y.to, y.fold, y.bifurcation),
            "{ctx}"
        );
        let lx: Vec<f64> = x.lambda_n.iter().chain(&x.lambda_t).copied().collect();
        let ly: Vec<f64> = y.lambda_n.iter().chain(&y.lambda_t).copied().collect();
        let big = inf(&lx).max(1e-300);
        for (a, b) in lx.iter().zip(&ly) {
            assert!(
                (a - b / c).abs() <= 1e-9 * big,
                "{ctx}: λ {lx:?} vs {ly:?} / c"
            );
        }
    }
    end.map(|e| (e, events))
}

/// Loads near the largest double (entries up to 1e308 on ordinary A): the residual of a
/// reported state is computed without overflow (its terms are scaled by a power of two
/// first), so a correct state is not reported with an infinite residual. (Within a few
/// percent of f64::MAX, 1.7e308, the tracer itself fails with a clean error.)
#[test]
fn residual_of_loads_near_the_largest_double() {
    for seed in 0..20 {
        let case = random_case(seed);
        let fmax = case.data.f0.amax().max(case.data.f1.amax()) * (1.0 + case.a0.abs());
        for target in [1e306, 1e308] {
            let c = target / fmax;
            let mut path = scaled_path(&case, c, affine);
            let state = path.start(case.a0, None).and_then(|()| path.start_state());
            match state {
                Ok(s) => {
                    // The reported residual against the test's own, computed from the
                    // state's u and λ (an overflowed scale used to report h / inf = 0
                    // whatever u was).
                    let f: Vec<f64> = (0..case.data.n)
                        .map(|i| (case.data.f0[i] + s.alpha * case.data.f1[i]) * c)
                        .collect();
                    let own = own_residual(&case.data, &s, &f);
                    assert!(
                        own <= 1e-12 && s.residual <= 1e-12 && (s.residual - own).abs() <= 1e-14,
                        "seed {seed}, load {target:e}: residual {:e}, the test's own {own:e}",
                        s.residual
                    );
                }
                // u itself beyond the range of a double: an error, never a wrong state
                Err(Error::Numerical(m)) => assert!(m.contains("overflows"), "{m}"),
                Err(e) => panic!("seed {seed}, load {target:e}: {e}"),
            }
        }
    }
}

/// The path is homogeneous in the load and the gap: scaled by c, the same events (α, nodes,
/// classes, flags) with λ times c. On 40 random problems, loads (and gaps) scaled up to
/// 1e300 must trace exactly so, and up to 1e308 either so or with a clean error that says
/// the numbers are near the largest double. (Above 1e154 the vertex snap squared the loads
/// into inf / inf = NaN and stopped with "alpha = NaN"; near 1e308 the unit tangent
/// overflowed into inf and the path ran to the window's end with no event: silently
/// wrong.)
#[test]
fn loads_scaled_toward_the_largest_double_give_the_same_events_or_a_clean_error() {
    let mut scaled_runs = 0;
    for seed in 0..40 {
        let case = random_case(seed);
        let base = check_scaled(&format!("seed {seed}"), &case, 1.0, 1.0, affine, None);
        let fmax = case.data.f0.amax().max(case.data.f1.amax()) * (1.0 + case.a0.abs());
        for target in [1e100, 1e160, 1e250, 1e300, 1e306, 1e308] {
            let ctx = format!("seed {seed}, load {target:e}");
            let c = target / fmax;
            if check_scaled(&ctx, &case, c, target, affine, base.as_ref()).is_some() {
                scaled_runs += 1;
            }
        }
    }
    // Nearly all scaled runs trace (a clean error is the exception near 1e308).
    assert!(
        scaled_runs >= 230,
        "{scaled_runs} of 240 scaled runs traced"
    );
}

/// As above for nonlinear loads, `f0 + φ(α) f1` with `φ(α) = α + 0.3 sin 3α`, given as a
/// basis load and as a general one: the same events as unscaled, or above 1e300 a clean
/// error. (Near 1e308 the march of a basis load crawled at 1e-12 of the window for ever:
/// its step control's Hermite model overflowed, so every longer step failed it.)
#[test]
fn nonlinear_loads_scaled_toward_the_largest_double_never_hang_or_mislead() {
    let phi = |a: f64| a + 0.3 * (3.0 * a).sin();
    let basis = |f0: Vec<f64>, f1: Vec<f64>| {
        let weights = move |a: f64, w: &mut [f64], dw: &mut [f64]| {
            (w[0], w[1]) = (1.0, phi(a));
            (dw[0], dw[1]) = (0.0, 1.0 + 0.9 * (3.0 * a).cos());
            Ok(())
        };
        Load::basis(vec![f0, f1], Box::new(weights)).unwrap()
    };
    let general = |f0: Vec<f64>, f1: Vec<f64>| {
        let n = f1.len();
        let f = move |a: f64, out: &mut [f64]| {
            for (i, o) in out.iter_mut().enumerate() {
                *o = f0[i] + phi(a) * f1[i];
            }
            Ok(())
        };
        Load::general(n, Box::new(f), None)
    };
    for seed in 0..20 {
        let case = random_case(seed);
        let fmax = case.data.f0.amax().max(case.data.f1.amax()) * (1.0 + case.a0.abs());
        let ctx = |kind: &str, target: f64| format!("seed {seed}, {kind} load {target:e}");
        let base_b = check_scaled(&ctx("basis", 1.0), &case, 1.0, 1.0, basis, None);
        let base_g = check_scaled(&ctx("general", 1.0), &case, 1.0, 1.0, general, None);
        for target in [1e160, 1e300, 1e308] {
            let c = target / fmax;
            check_scaled(
                &ctx("basis", target),
                &case,
                c,
                target,
                basis,
                base_b.as_ref(),
            );
            check_scaled(
                &ctx("general", target),
                &case,
                c,
                target,
                general,
                base_g.as_ref(),
            );
        }
    }
}
