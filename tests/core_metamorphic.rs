//! Metamorphic tests: transformations that must not change the answer, each checked
//! against the unmodified problem (no stored numbers).
//!
//! * Far window ends: moving only the far end of the window (to 1e3 … 1e12) leaves the
//!   start and every event inside the original window unchanged — the original events
//!   are a prefix of the far-window events (for nonlinear loads, against the affine
//!   path through φ).
//! * Global force scaling: `f ↦ s f`, `g ↦ s g` (s = 1e-9 … 1e9) gives the same α and
//!   `λ ↦ s λ`.
//! * Global stiffness scaling: `A ↦ s A`, `g ↦ g / s` gives the same α and λ.
//! * Node permutation: permuting the rows of N and T (with friction and gap) permutes
//!   the event nodes and nothing else.
//! * Change of displacement coordinates: `u = Q v` with Q orthogonal (rotated and
//!   renumbered mesh nodes) gives the same events and forces, and displacements `Qᵀu`.

mod common;

use std::sync::Arc;

use common::{Data, Rng, random_case, read_mtx, read_vec, trace};
use fricont::{CsrMatrix, Event, Path, ProblemBuilder, Storage};

/// (node, from, to) of one event.
type NodeChange = (usize, fricont::Class, fricont::Class);

fn run(data: &Data, a0: f64, a1: f64) -> Path {
    trace(Arc::new(data.problem()), data.affine_load(), a0, a1)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
}

/// `base` is a prefix of `other` (α to `tol` relative, same nodes, classes, flags).
fn assert_prefix(ctx: &str, base: &[Event], other: &[Event], tol: f64) {
    assert!(
        other.len() >= base.len(),
        "{ctx}: {} events, the original window has {}",
        other.len(),
        base.len()
    );
    for (x, y) in base.iter().zip(other) {
        assert!(
            close(x.alpha, y.alpha, tol),
            "{ctx}: event {} at α {:.17e}, originally {:.17e}",
            x.index + 1,
            y.alpha,
            x.alpha
        );
        assert_eq!(
            (x.node, x.from, x.to, x.fold, x.transition),
            (y.node, y.from, y.to, y.fold, y.transition),
            "{ctx}: event {}",
            x.index + 1
        );
    }
}

/// One transition point of a path: its α, whether the path folds there, its node changes
/// as `change` gives them (sorted by node: the events of one transition are listed in
/// node order, which a permutation changes) and the contact forces `(λν, λt)` there.
struct TransitionPoint {
    transition: usize,
    alpha: f64,
    fold: bool,
    changes: Vec<NodeChange>,
    lambda: Vec<f64>,
}

fn transition_points(ev: &[Event], change: impl Fn(&Event) -> NodeChange) -> Vec<TransitionPoint> {
    let mut g: Vec<TransitionPoint> = Vec::new();
    for e in ev {
        if g.last().is_none_or(|t| t.transition != e.transition) {
            g.push(TransitionPoint {
                transition: e.transition,
                alpha: e.alpha,
                fold: false,
                changes: Vec::new(),
                lambda: e.lambda_n.iter().chain(&e.lambda_t).copied().collect(),
            });
        }
        let t = g.last_mut().unwrap();
        t.fold |= e.fold;
        t.changes.push(change(e));
    }
    for t in &mut g {
        t.changes.sort_by_key(|k| k.0);
    }
    g
}

fn start_classes(p: &Path) -> Vec<fricont::Class> {
    p.start_state().expect("started").classes.clone()
}

/// The repository's sample (n = 1320, p = 30), read with the tests' own reader.
fn sample() -> (ProblemBuilder, Vec<f64>, Vec<f64>) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sample-rect30");
    let csr = |name: &str| {
        let (r, c, t) = read_mtx(&dir.join(name));
        CsrMatrix::from_triplets(name, r, c, &t).unwrap()
    };
    let b = ProblemBuilder::new(csr("A.mtx"), Storage::Full, csr("N.mtx"), csr("T.mtx"))
        .friction_uniform(0.3);
    (
        b,
        read_vec(&dir.join("f0.txt")),
        read_vec(&dir.join("f1.txt")),
    )
}

#[test]
fn far_window_ends_sample() {
    let (b, f0, f1) = sample();
    let problem = Arc::new(b.build().unwrap());
    let load = || fricont::Load::affine(f0.clone(), f1.clone()).unwrap();
    let base = trace(problem.clone(), load(), -0.5, 1.5);
    assert!(base.events().len() >= 20);
    for far in [1e3, 1e6, 1e9, 1e12] {
        let mut opts = fricont::PathOptions::window(-0.5, far);
        opts.max_steps = base.events().len() + 50;
        let mut path = Path::new(problem.clone(), load(), opts).unwrap();
        path.start(-0.5, None).unwrap();
        // Stop once past the original window: what lies beyond is not compared.
        while path.events().last().is_none_or(|e| e.alpha <= 1.5) {
            if matches!(path.step().unwrap(), fricont::StepOutcome::End(_)) {
                break;
            }
        }
        let ctx = format!("sample, window [-0.5, {far:e}]");
        assert_eq!(start_classes(&path), start_classes(&base), "{ctx}: start");
        // 1e-10: the sample's shallow crossing (event 3) is determined to ~2e-11 only.
        assert_prefix(&ctx, base.events(), path.events(), 1e-10);
    }
}

#[test]
fn far_window_ends_random() {
    for seed in 0..120 {
        let case = random_case(seed);
        let base = run(&case.data, case.a0, case.a1);
        let dir = (case.a1 - case.a0).signum();
        for far in [1e3, 1e8, 1e12] {
            let path = run(&case.data, case.a0, case.a0 + dir * far);
            let ctx = format!("seed {seed}, far end {far:e}");
            assert_eq!(start_classes(&path), start_classes(&base), "{ctx}: start");
            assert_prefix(&ctx, base.events(), path.events(), 1e-11);
        }
    }
}

/// φ(α) = α + 0.2 sin 2α (increasing: φ' ≥ 0.6), the nonlinear loads' weight of f1.
fn phi(a: f64) -> f64 {
    a + 0.2 * (2.0 * a).sin()
}

fn dphi(a: f64) -> f64 {
    1.0 + 0.4 * (2.0 * a).cos()
}

/// φ⁻¹ by Newton's method (φ' ≥ 0.6).
fn inv_phi(p: f64) -> f64 {
    let mut a = p;
    for _ in 0..60 {
        a -= (phi(a) - p) / dphi(a);
    }
    a
}

/// `f0 + φ(α − c) f1` as a basis load (`basis`) or a general load, failing (the host's
/// error) strictly beyond `fail = (α_f, direction)`: a path with a far window end stops
/// there.
fn nonlinear_load(data: &Data, basis: bool, c: f64, fail: Option<(f64, f64)>) -> fricont::Load {
    use fricont::load::LoadFailure;
    let beyond = move |a: f64| -> Result<(), LoadFailure> {
        match fail {
            Some((at, dir)) if dir * (a - at) > 0.0 => Err(LoadFailure {
                code: 1,
                message: "beyond the compared window".into(),
            }),
            _ => Ok(()),
        }
    };
    let (f0, f1) = (data.f0.as_slice().to_vec(), data.f1.as_slice().to_vec());
    if basis {
        let weights = move |a: f64, w: &mut [f64], dw: &mut [f64]| {
            beyond(a)?;
            (w[0], w[1], dw[0], dw[1]) = (1.0, phi(a - c), 0.0, dphi(a - c));
            Ok(())
        };
        return fricont::Load::basis(vec![f0, f1], Box::new(weights)).unwrap();
    }
    let df1 = f1.clone();
    fricont::Load::general(
        f0.len(),
        Box::new(move |a: f64, out: &mut [f64]| {
            beyond(a)?;
            for ((o, x), y) in out.iter_mut().zip(&f0).zip(&f1) {
                *o = x + phi(a - c) * y;
            }
            Ok(())
        }),
        Some(Box::new(move |a: f64, out: &mut [f64]| {
            for (o, y) in out.iter_mut().zip(&df1) {
                *o = dphi(a - c) * y;
            }
            Ok(())
        })),
    )
}

/// A path over `data` under `load` on the window [a0, end], started at a0.
fn started(ctx: &str, data: &Data, load: fricont::Load, a0: f64, end: f64) -> Path {
    let mut path = Path::new(
        Arc::new(data.problem()),
        load,
        fricont::PathOptions::window(a0, end),
    )
    .unwrap();
    path.start(a0, None)
        .unwrap_or_else(|e| panic!("{ctx}: start: {e}"));
    path
}

/// The first events of `got` are `want` (the affine path's events mapped through φ⁻¹:
/// α and node change): the same node changes, and `err(α wanted, α got) ≤ tol`. Returns
/// the largest `err`.
fn assert_mapped<'a>(
    ctx: &str,
    want: &[(f64, NodeChange)],
    got: impl Iterator<Item = &'a Event>,
    err: impl Fn(f64, f64) -> f64,
    tol: f64,
) -> f64 {
    let mut worst = 0.0f64;
    for (k, (w, g)) in want.iter().zip(got).enumerate() {
        let e = err(w.0, g.alpha);
        worst = worst.max(e);
        assert!(
            w.1 == (g.node, g.from, g.to) && e <= tol,
            "{ctx}: event {k}: α {} node {} {:?} → {:?}, the affine path's at α {} node {} {:?} → {:?}",
            g.alpha,
            g.node + 1,
            g.from,
            g.to,
            w.0,
            w.1.0 + 1,
            w.1.1,
            w.1.2
        );
    }
    worst
}

/// Far window ends under nonlinear loads: `f0 + φ(α) f1` (φ = α + 0.2 sin 2α, as a basis
/// and as a general load) on random problems and finite-element meshes, traced over the
/// case's window and over windows whose far end is 1e3, 1e8 and 1e12 away (the load fails
/// half a window past the original end, which stops those paths). Every event inside the
/// original window must be the affine path's (over [φ(α0), φ(α1)], an independent trace:
/// no march, no nonlinear thresholds) at φ⁻¹ of its α, to 1e-12. The march's least step
/// and a general load's estimated thresholds were fractions of the window's length: at
/// 1e12 the general load reported wrong events without an error (every guard counted as
/// at zero) and the basis load stopped loudly (steps of length 1 past the step control).
#[test]
fn far_window_ends_of_nonlinear_loads() {
    let cases = (0..40u64).map(random_case).chain((0..8u64).map(|s| {
        common::fe_case(
            s,
            6 + 3 * s as usize,
            1 + (s % 3) as usize,
            [0.3, 1.5, 5.0][s as usize % 3],
        )
    }));
    let (mut worst, mut events) = (0.0f64, 0);
    for case in cases {
        let (data, a0, a1) = (&case.data, case.a0, case.a1);
        let dir = (a1 - a0).signum();
        let affine = run(data, phi(a0), phi(a1));
        let want: Vec<(f64, NodeChange)> = affine
            .events()
            .iter()
            .map(|e| (inv_phi(e.alpha), (e.node, e.from, e.to)))
            .collect();
        for basis in [false, true] {
            for far in [None, Some(1e3), Some(1e8), Some(1e12)] {
                let ctx = format!(
                    "seed {} (p = {}), basis {basis}, far end {far:?}",
                    case.seed, data.p
                );
                let (end, fail) = match far {
                    None => (a1, None),
                    Some(f) => (a0 + dir * f, Some((a1 + 0.5 * (a1 - a0), dir))),
                };
                let load = nonlinear_load(data, basis, 0.0, fail);
                let mut path = started(&ctx, data, load, a0, end);
                loop {
                    match path.step() {
                        Ok(fricont::StepOutcome::End(_)) => break,
                        Ok(_) => {}
                        Err(fricont::Error::Load { .. }) if far.is_some() => break,
                        Err(e) => panic!("{ctx}: {e}"),
                    }
                }
                let got = path.events();
                events += want.len();
                assert!(
                    got.len() >= want.len(),
                    "{ctx}: {} events, want {}",
                    got.len(),
                    want.len()
                );
                let scaled = |w: f64, g: f64| (w - g).abs() / 1f64.max(w.abs()).max(g.abs());
                worst = worst.max(assert_mapped(&ctx, &want, got.iter(), scaled, 1e-12));
            }
        }
    }
    eprintln!("{events} events, worst relative difference in α {worst:e}");
    assert!(events >= 2000, "{events} events");
}

/// Nonlinear loads on a translated α axis: `f0 + φ(α − c) f1` over the case's window
/// moved by c = 1e4, 1e6, 1e9 and −1e7 (as a basis and as a general load), on random
/// problems and finite-element meshes. There α resolves a point only to ε |α| (1.2e-10
/// at 1e6, against windows of length 2 to 8), more than the thresholds of its guards.
/// Every event must be the affine path's (over [φ(α0), φ(α1)], untranslated) at
/// c + φ⁻¹ of its α, to 1e-12 of the window plus 16 ulps of α. Before: a root one ulp
/// away was halved forever (α near 1e6: the path never returned), and a touchdown's gap,
/// moved onto its zero along the piece where α cannot resolve it, was read back from a
/// cache at its old value (the node fitted no class). Run on a thread: a hang fails the
/// test instead of stalling the suite.
#[test]
fn nonlinear_loads_on_a_translated_alpha_axis() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let cases: Vec<common::Case> = (0..24u64)
            .map(random_case)
            .chain((0..4u64).map(|s| {
                common::fe_case(s, 8 + 4 * s as usize, 2, [0.3, 1.5, 5.0, 0.8][s as usize])
            }))
            .collect();
        let (mut worst, mut events) = (0.0f64, 0);
        for shift in [1e4, 1e6, 1e9, -1e7] {
            for case in &cases {
                let (data, a0, a1) = (&case.data, case.a0, case.a1);
                let want: Vec<(f64, NodeChange)> = run(data, phi(a0), phi(a1))
                    .events()
                    .iter()
                    .map(|e| (shift + inv_phi(e.alpha), (e.node, e.from, e.to)))
                    .collect();
                for basis in [false, true] {
                    let ctx = format!(
                        "seed {} (p = {}), basis {basis}, α + {shift:e}",
                        case.seed, data.p
                    );
                    let load = nonlinear_load(data, basis, shift, None);
                    let mut path = started(&ctx, data, load, a0 + shift, a1 + shift);
                    path.run().unwrap_or_else(|e| panic!("{ctx}: {e}"));
                    let got = path.events();
                    assert_eq!(got.len(), want.len(), "{ctx}: events");
                    // (the difference in units of the tolerance, 1e-12 of the window plus
                    // 16 ulps of α)
                    let err = |w: f64, g: f64| {
                        (g - w).abs() / (1e-12 * (a1 - a0).abs() + 16.0 * f64::EPSILON * w.abs())
                    };
                    worst = worst.max(assert_mapped(&ctx, &want, got.iter(), err, 1.0));
                    events += got.len();
                }
            }
        }
        let _ = tx.send((events, worst));
    });
    let (events, worst) = rx
        .recv_timeout(std::time::Duration::from_secs(600))
        .expect("the traces finished (no hang) without a failure");
    eprintln!("{events} events, worst {worst:.2} of the tolerance");
    assert!(events >= 1000, "{events} events");
}

#[test]
fn global_force_and_stiffness_scalings() {
    for seed in 0..80 {
        let case = random_case(seed);
        let base = run(&case.data, case.a0, case.a1);
        for s in [1e-9, 1e-3, 1e3, 1e9] {
            let mut forces = case.data.clone();
            forces.f0 *= s;
            forces.f1 *= s;
            forces.gap.iter_mut().for_each(|g| *g *= s);
            let mut stiff = case.data.clone();
            stiff.a *= s;
            stiff.gap.iter_mut().for_each(|g| *g /= s);
            for (kind, data, lam_factor) in [("forces", forces, s), ("stiffness", stiff, 1.0)] {
                let ctx = format!("seed {seed}, {kind} × {s:e}");
                let path = run(&data, case.a0, case.a1);
                let (x, y) = (base.events(), path.events());
                assert_eq!(x.len(), y.len(), "{ctx}");
                assert_prefix(&ctx, x, y, 1e-11);
                // λ relative to the largest force along the path (an event where every
                // node is open has λ = 0 up to rounding).
                let lam_scale = x
                    .iter()
                    .flat_map(|e| e.lambda_n.iter().chain(&e.lambda_t))
                    .fold(1e-300f64, |m, v| m.max(v.abs()))
                    .max(case.data.f0.amax() + case.data.f1.amax());
                for (e, f) in x.iter().zip(y) {
                    for (a, b) in e
                        .lambda_n
                        .iter()
                        .chain(&e.lambda_t)
                        .zip(f.lambda_n.iter().chain(&f.lambda_t))
                    {
                        assert!(
                            (a * lam_factor - b).abs() <= 1e-9 * lam_scale * lam_factor,
                            "{ctx}: λ {b:e}, expected {:e}",
                            a * lam_factor
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn node_permutations() {
    for seed in 0..80 {
        let case = random_case(seed);
        let data = &case.data;
        let p = data.p;
        let mut rng = Rng::new(seed + 777);
        // perm[i] = new index of node i
        let mut perm: Vec<usize> = (0..p).collect();
        for i in (1..p).rev() {
            let j = rng.int(0, i);
            perm.swap(i, j);
        }
        let mut q = data.clone();
        for (i, &pi) in perm.iter().enumerate() {
            q.nm.set_row(pi, &data.nm.row(i));
            q.tm.set_row(pi, &data.tm.row(i));
            q.friction[pi] = data.friction[i];
            q.gap[pi] = data.gap[i];
        }
        let base = run(data, case.a0, case.a1);
        let path = run(&q, case.a0, case.a1);
        let ctx = format!("seed {seed}, permutation {perm:?}");
        let (x, y) = (base.events(), path.events());
        assert_eq!(x.len(), y.len(), "{ctx}");
        let gx = transition_points(x, |e| (perm[e.node], e.from, e.to));
        let gy = transition_points(y, |e| (e.node, e.from, e.to));
        for (a, b) in gx.iter().zip(&gy) {
            assert!(
                close(a.alpha, b.alpha, 1e-11),
                "{ctx}: α {} vs {}",
                a.alpha,
                b.alpha
            );
            assert_eq!(a.changes, b.changes, "{ctx}");
        }
    }
}

/// `data` with node i's rows N_i and gap g_i multiplied by `c[i]`, T_i by `d[i]`, and
/// friction F_i by `c[i] / d[i]`: the same problem, with λν_i divided by c_i and λt_i by
/// d_i.
fn rows_scaled(data: &Data, c: &[f64], d: &[f64]) -> Data {
    let mut q = data.clone();
    for (i, (&ci, &di)) in c.iter().zip(d).enumerate() {
        q.nm.row_mut(i).scale_mut(ci);
        q.tm.row_mut(i).scale_mut(di);
        q.gap[i] *= ci;
        q.friction[i] *= ci / di;
    }
    q
}

/// Per-node scaling: multiplying node i's rows N_i, T_i and gap g_i by c_i > 0 (spread
/// over 1e-6 … 1e6) is the same problem with λ_i divided by c_i.
#[test]
fn per_node_row_scalings() {
    check_row_scalings(false);
}

/// Per-row scaling: N_i (and g_i) by c_i, T_i by d_i, independently over 1e-6 … 1e6, with
/// F_i multiplied by c_i / d_i, is the same problem with λν_i divided by c_i and λt_i by
/// d_i. Until both rows of a node had scales of their own, one scale per node measured
/// the smaller row on the larger's: in a sweep of 440 such problems (200 of
/// `random_case`, 200 of `large_friction_case`, 40 meshes), 49 reported event states
/// that violate the unscaled problem's conditions by more than 1e-8 and 103 stopped
/// with an error; none does now, also with scalings spread over 1e-12 … 1e12.
#[test]
fn normal_and_tangential_rows_scaled_apart() {
    check_row_scalings(true);
}

/// The finite-element cases of the row-scaling tests: 4–6 × 2 elements, F = 0.3, 1, 5.
fn scaled_fe_case(s: u64) -> common::Case {
    common::fe_case(
        s,
        4 + (s % 3) as usize,
        2,
        [0.3, 1.0, 5.0][(s % 3) as usize],
    )
}

/// p row factors spread log-uniformly over 1e-6 … 1e6.
fn row_factors(rng: &mut Rng, p: usize) -> Vec<f64> {
    (0..p).map(|_| 10f64.powf(rng.range(-6.0, 6.0))).collect()
}

fn check_row_scalings(apart: bool) {
    let mut cases: Vec<common::Case> = (0..60).map(random_case).collect();
    if apart {
        cases.extend((0..60).map(common::large_friction_case));
    }
    cases.extend((0..12).map(scaled_fe_case));
    for (k, case) in cases.iter().enumerate() {
        let data = &case.data;
        let p = data.p;
        let mut rng = Rng::new(k as u64 + 4242);
        let c = row_factors(&mut rng, p);
        let d: Vec<f64> = if apart {
            row_factors(&mut rng, p)
        } else {
            c.clone()
        };
        let q = rows_scaled(data, &c, &d);
        let base = run(data, case.a0, case.a1);
        let path = run(&q, case.a0, case.a1);
        let ctx = format!("case {k} (seed {}), factors {c:?}, {d:?}", case.seed);
        assert_eq!(start_classes(&base), start_classes(&path), "{ctx}: start");
        let (x, y) = (base.events(), path.events());
        assert_eq!(x.len(), y.len(), "{ctx}");
        assert_prefix(&ctx, x, y, 1e-10);
        // Each node's forces to 1e-8 of its own size, plus 1e-12 of the largest force
        // or load (a node at zero force carries rounding).
        let global = x
            .iter()
            .flat_map(|e| e.lambda_n.iter().chain(&e.lambda_t))
            .fold(data.f0.amax() + data.f1.amax(), |m, v| m.max(v.abs()));
        for (e, f) in x.iter().zip(y) {
            for i in 0..p {
                let own = e.lambda_n[i].abs().max(e.lambda_t[i].abs());
                for (a, b, s) in [
                    (e.lambda_n[i], f.lambda_n[i], c[i]),
                    (e.lambda_t[i], f.lambda_t[i], d[i]),
                ] {
                    assert!(
                        (a - b * s).abs() <= 1e-8 * own + 1e-12 * global,
                        "{ctx}: node {i}: λ {b:e} × scale = {:e}, expected {a:e}",
                        b * s
                    );
                }
            }
        }
    }
}

/// Per-row scalings under an oscillating load, through folds: N_i (and g_i) by c_i, T_i by
/// d_i over 1e-6 … 1e6 (F_i by c_i / d_i), under the basis load `f0 + (m + h sin 40α) f1`
/// that sweeps the case's window [m − h, m + h] back and forth over two periods, give
/// the start and the events of the unscaled problem: the same nodes, classes and folds,
/// α to 1e-10 (measured: at most 1.4e-13 in a sweep of 300 such cases; two of them, not
/// among these, start elsewhere: their affine curve passes the window's midpoint three
/// times and the fixed-α solver picks another of those solutions under the scaling).
#[test]
fn per_row_scalings_under_an_oscillating_load() {
    let omega = 40.0;
    let sine = |data: &Data, a0: f64, a1: f64| -> Path {
        let (m, h) = ((a0 + a1) / 2.0, (a1 - a0) / 2.0);
        let weights = move |a: f64, w: &mut [f64], dw: &mut [f64]| {
            w[0] = 1.0;
            w[1] = m + h * (omega * a).sin();
            dw[0] = 0.0;
            dw[1] = h * omega * (omega * a).cos();
            Ok::<(), fricont::load::LoadFailure>(())
        };
        let fs = vec![data.f0.as_slice().to_vec(), data.f1.as_slice().to_vec()];
        let load = fricont::Load::basis(fs, Box::new(weights)).expect("basis load");
        trace(
            Arc::new(data.problem()),
            load,
            0.0,
            4.0 * std::f64::consts::PI / omega,
        )
    };
    let mut folds = 0;
    for k in 0..60u64 {
        let s = k / 3;
        let case = match k % 3 {
            0 => random_case(s),
            1 => common::large_friction_case(s),
            _ => scaled_fe_case(s),
        };
        let data = &case.data;
        let mut rng = Rng::new(k + 777);
        let c = row_factors(&mut rng, data.p);
        let d = row_factors(&mut rng, data.p);
        let base = sine(data, case.a0, case.a1);
        let path = sine(&rows_scaled(data, &c, &d), case.a0, case.a1);
        let ctx = format!("case {k} (seed {s})");
        assert_eq!(start_classes(&base), start_classes(&path), "{ctx}: start");
        let (x, y) = (base.events(), path.events());
        assert_eq!(x.len(), y.len(), "{ctx}");
        assert_prefix(&ctx, x, y, 1e-10);
        folds += x.iter().filter(|e| e.fold).count();
    }
    assert!(folds > 0, "no fold among the cases");
}

/// A node far from the foundation: giving one node a gap so large that it never touches
/// (1e3, 1e9 and 1e15 times the load's displacements) leaves every other node's events
/// as they are with the smallest such gap, and reported points certified node by node:
/// the far node's gap no longer sets the scale of the others' tolerances and residuals
/// (with a gap of 1e9 one node was left sticking outside its friction cone by 2.7 %,
/// residual reported 5e-13, and an event was missed).
#[test]
fn a_node_far_from_the_foundation_changes_nothing_else() {
    let mut checked = 0;
    for s in 0..12u64 {
        let case = common::fe_case(
            s,
            5 + (s % 3) as usize,
            3,
            [0.3, 1.0, 3.0][(s % 3) as usize],
        );
        let data = &case.data;
        let p = data.p;
        let far = (s as usize * 7 + 3) % p;
        // displacement scale of the load: the largest |q| over the window
        let base_gap = 1e3 * (data.f0.amax() + data.f1.amax() * case.a0.abs().max(case.a1.abs()))
            / data.a.diagonal().amin();
        let mut runs = Vec::new();
        for factor in [1.0, 1e6, 1e12] {
            let mut q = data.clone();
            q.gap[far] = base_gap * factor;
            let path = run(&q, case.a0, case.a1);
            assert!(
                path.events().iter().all(|e| e.node != far),
                "seed {s}: the far node {far} switched"
            );
            for k in 0..path.events().len() {
                let st = path.event_state(k).unwrap();
                assert!(
                    st.residual <= 1e-10,
                    "seed {s}, gap {:e}: event {k} residual {:e}",
                    q.gap[far],
                    st.residual
                );
            }
            runs.push(path);
        }
        let ctx = format!("seed {s}, far node {far}");
        let x = runs[0].events();
        if x.is_empty() {
            continue;
        }
        for other in &runs[1..] {
            assert_eq!(x.len(), other.events().len(), "{ctx}");
            assert_prefix(&ctx, x, other.events(), 1e-10);
        }
        checked += 1;
    }
    assert!(checked >= 8, "only {checked} cases with events");
}

/// Per-node scaling beyond the square root of the floating-point range: node rows of
/// size 1e±160 (their squares over- or underflow) are equilibrated like any other
/// (the node's row norm is taken without squaring its entries): the same events as the
/// unscaled problem.
#[test]
fn per_node_row_scalings_at_extreme_sizes() {
    for seed in 0..20u64 {
        let case = random_case(seed);
        let data = &case.data;
        let c: Vec<f64> = (0..data.p)
            .map(|i| {
                if (i + seed as usize).is_multiple_of(2) {
                    1e160
                } else {
                    1e-160
                }
            })
            .collect();
        let q = rows_scaled(data, &c, &c);
        let base = run(data, case.a0, case.a1);
        let path = run(&q, case.a0, case.a1);
        let ctx = format!("seed {seed}, factors {c:?}");
        assert_eq!(base.events().len(), path.events().len(), "{ctx}");
        assert_prefix(&ctx, base.events(), path.events(), 1e-10);
    }
}

/// An orthogonal matrix Q of order `n`: where `nodes`, each dof pair (2k, 2k + 1) (a mesh
/// node's x and y) rotated by its own random angle and the pairs renumbered at random, so
/// that A keeps its node-block sparsity; else a dense product of 4n random Givens
/// rotations.
fn orthogonal(n: usize, rng: &mut Rng, nodes: bool) -> nalgebra::DMatrix<f64> {
    use std::f64::consts::TAU;
    if nodes {
        let k = n / 2;
        let mut perm: Vec<usize> = (0..k).collect();
        for i in (1..k).rev() {
            let j = rng.int(0, i);
            perm.swap(i, j);
        }
        let mut q = nalgebra::DMatrix::zeros(n, n);
        for (i, &pi) in perm.iter().enumerate() {
            let (s, c) = rng.range(0.0, TAU).sin_cos();
            let (r, col) = (2 * i, 2 * pi);
            q[(r, col)] = c;
            q[(r, col + 1)] = -s;
            q[(r + 1, col)] = s;
            q[(r + 1, col + 1)] = c;
        }
        return q;
    }
    let mut q = nalgebra::DMatrix::identity(n, n);
    for _ in 0..4 * n {
        let (i, j) = (rng.int(0, n - 1), rng.int(0, n - 1));
        if i != j {
            let (s, c) = rng.range(0.0, TAU).sin_cos();
            for r in 0..n {
                let (a, b) = (q[(r, i)], q[(r, j)]);
                q[(r, i)] = c * a - s * b;
                q[(r, j)] = s * a + c * b;
            }
        }
    }
    q
}

/// A change of displacement coordinates: u = Q v with Q orthogonal (each mesh node's
/// dofs rotated and the nodes renumbered, or a dense Q on the random cases) turns the
/// data into `QᵀAQ`, `NQ`, `TQ`, `Qᵀf`. That is the same problem: the same events, the
/// same contact forces, and displacements `Qᵀu`. The transformed data are rounded, and
/// rounding moves the solutions by about κ(W) ε and a transition point by that divided
/// by how steeply its guard crosses zero: the events are compared to 50 κ(W) ε relative
/// to max(1, |α|), with κ(W) the library's own estimate (these problems cross steeply). (Measured: at most 7.3 κ ε over 2100 random, 2100 large-friction
/// and 1100 finite-element cases, with nx up to 200 and F up to 5.) Forces and
/// displacements are compared to the same bound times the largest of each.
#[test]
fn orthogonal_change_of_displacement_coordinates() {
    let mut cases: Vec<(common::Case, bool)> = Vec::new();
    for s in 0..40 {
        cases.push((random_case(s), false));
        cases.push((common::large_friction_case(s), false));
    }
    for s in 0..16u64 {
        let nx = if s < 12 {
            4 + s as usize
        } else {
            40 + 37 * s as usize % 160
        };
        let friction = [0.3, 1.0, 5.0][(s % 3) as usize];
        cases.push((common::fe_case(s, nx, 1 + (s % 3) as usize, friction), true));
    }
    for (k, (case, nodes)) in cases.iter().enumerate() {
        let data = &case.data;
        let mut rng = Rng::new(k as u64 + 9090);
        let q = orthogonal(data.n, &mut rng, *nodes);
        let mut t = data.clone();
        let a = q.transpose() * &data.a * &q;
        // symmetric to the last bit, as a host's assembly would give it
        t.a = (&a + a.transpose()) * 0.5;
        t.nm = &data.nm * &q;
        t.tm = &data.tm * &q;
        t.f0 = q.transpose() * &data.f0;
        t.f1 = q.transpose() * &data.f1;
        let (base, path) = (run(data, case.a0, case.a1), run(&t, case.a0, case.a1));
        let ctx = format!(
            "case {k} (seed {}, n = {}, p = {})",
            case.seed, data.n, data.p
        );
        assert_eq!(start_classes(&base), start_classes(&path), "{ctx}: start");
        assert_eq!(base.end_reason(), path.end_reason(), "{ctx}: end");
        let kappa = [&base, &path]
            .iter()
            .map(|p| p.problem().w_condition_estimate())
            .fold(1.0, f64::max);
        let bound = 50.0 * kappa * f64::EPSILON;
        let (x, y) = (base.events(), path.events());
        assert_eq!(x.len(), y.len(), "{ctx}");
        assert_prefix(&ctx, x, y, bound);
        let lam = x
            .iter()
            .flat_map(|e| e.lambda_n.iter().chain(&e.lambda_t))
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        // displacements of the transformed problem against Qᵀu, to the bound times the
        // largest of them along the path
        let mut us = Vec::new();
        for (k, (e, f)) in x.iter().zip(y).enumerate() {
            let pairs = e.lambda_n.iter().chain(&e.lambda_t);
            for (a, b) in pairs.zip(f.lambda_n.iter().chain(&f.lambda_t)) {
                assert!(
                    (a - b).abs() <= bound * lam,
                    "{ctx}: event {k}: λ {b:e}, expected {a:e}"
                );
            }
            let u = nalgebra::DVector::from_column_slice(&base.event_state(k).unwrap().u);
            us.push((q.transpose() * u, path.event_state(k).unwrap().u));
        }
        let umax = us.iter().map(|(v, _)| v.amax()).fold(0.0, f64::max);
        for (k, (v, w)) in us.iter().enumerate() {
            for (i, (a, b)) in v.iter().zip(w).enumerate() {
                assert!(
                    (a - b).abs() <= bound * umax,
                    "{ctx}: event {k}: u_{i} {b:e}, expected (Qᵀu)_{i} = {a:e}"
                );
            }
        }
    }
}

/// The load of the reversal test: affine, or the basis load `f0 + φ(α) f1` with
/// `φ = α + 0.3 sin 5α` (not monotone: dφ/dα = 1 + 1.5 cos 5α changes sign).
fn reversal_load(data: &Data, oscillating: bool) -> fricont::Load {
    if !oscillating {
        return data.affine_load();
    }
    let (f0, f1) = (data.f0.as_slice().to_vec(), data.f1.as_slice().to_vec());
    fricont::Load::basis(
        vec![f0, f1],
        Box::new(|a: f64, w: &mut [f64], dw: &mut [f64]| {
            w[0] = 1.0;
            w[1] = a + 0.3 * (5.0 * a).sin();
            dw[0] = 0.0;
            dw[1] = 1.0 + 1.5 * (5.0 * a).cos();
            Ok::<(), fricont::load::LoadFailure>(())
        }),
    )
    .unwrap()
}

/// Traces `case` forward, then backward from its end state (given as the guess, which is
/// kept) to the start of the window. `false` where the forward path does not end at the
/// window's far end (it folds back out through the start) or meets a bifurcation, where
/// the way back is not the same curve; else asserts that the way back is the same curve:
/// the same transition points in reverse order (α to 1e-10 relative to max(1, |α|), the
/// contact forces there to 1e-9 of the largest), each node's change reversed, the same
/// folds, and that it ends at the forward start's state.
fn reversal_holds(ctx: &str, case: &common::Case, oscillating: bool) -> bool {
    let problem = Arc::new(case.data.problem());
    let fwd = trace(
        problem.clone(),
        reversal_load(&case.data, oscillating),
        case.a0,
        case.a1,
    );
    let mut fwd = fwd;
    let end = fwd.current().unwrap();
    if end.alpha != case.a1 || fwd.events().iter().any(|e| e.bifurcation) {
        return false;
    }
    let guess: Vec<f64> = end.lambda_n.iter().chain(&end.lambda_t).copied().collect();
    let opts = fricont::PathOptions::window(case.a1, case.a0);
    let mut back = Path::new(problem, reversal_load(&case.data, oscillating), opts).unwrap();
    back.start(case.a1, Some(&guess)).unwrap();
    back.run().unwrap();
    assert_eq!(
        back.end_reason(),
        Some(&fricont::EndReason::Window),
        "{ctx}"
    );
    let there = transition_points(fwd.events(), |e| (e.node, e.from, e.to));
    let mut back_pts = transition_points(back.events(), |e| (e.node, e.to, e.from));
    back_pts.reverse();
    assert_eq!(there.len(), back_pts.len(), "{ctx}: transition points");
    for (k, (x, y)) in there.iter().zip(&back_pts).enumerate() {
        assert!(
            close(x.alpha, y.alpha, 1e-10),
            "{ctx}: transition {} at α {:.17e}, on the way back {:.17e}",
            k + 1,
            x.alpha,
            y.alpha
        );
        assert_eq!(
            (x.fold, &x.changes),
            (y.fold, &y.changes),
            "{ctx}: transition {}",
            k + 1
        );
        let scale = x
            .lambda
            .iter()
            .fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
        for (a, b) in x.lambda.iter().zip(&y.lambda) {
            assert!(
                (a - b).abs() <= 1e-9 * scale,
                "{ctx}: transition {}: λ {b:e} on the way back, {a:e} there",
                k + 1
            );
        }
    }
    let (s0, s1) = (fwd.start_state().unwrap(), back.current().unwrap());
    assert_eq!(s1.classes, s0.classes, "{ctx}: end of the way back");
    let (l0, l1) = (common::lambda_of(&s0), common::lambda_of(&s1));
    let scale = l0.amax().max(f64::MIN_POSITIVE);
    for (a, b) in l0.iter().zip(l1.iter()) {
        assert!(
            (a - b).abs() <= 1e-9 * scale,
            "{ctx}: λ {b:e} back at the start, {a:e} there"
        );
    }
    true
}

/// Path reversal: traced from the end state of a forward trace back to the window's
/// start, the path is the same curve (same transition points in reverse, each change
/// reversed, the same folds) and ends at the forward start's state. Checks that nothing
/// in the ratio test, the joins or the orientation depends on the direction of travel;
/// affine and oscillating (non-monotone basis) loads on random, large-friction,
/// mirror-symmetric and finite-element problems.
#[test]
fn path_reversal() {
    let mut families: Vec<(&str, Vec<common::Case>)> = vec![
        ("random", (0..60).map(random_case).collect()),
        (
            "large friction",
            (0..60).map(common::large_friction_case).collect(),
        ),
        (
            "symmetric",
            (0..40)
                .map(|s| common::symmetric_case(s, s % 2 == 0))
                .collect(),
        ),
    ];
    families.push((
        "mesh",
        (0..24)
            .map(|s| {
                common::fe_case(
                    s,
                    4 + (s % 13) as usize * 5,
                    1 + (s % 4) as usize,
                    [0.1, 0.8, 3.0, 5.0][(s % 4) as usize],
                )
            })
            .collect(),
    ));
    for (name, cases) in &families {
        for oscillating in [false, true] {
            let mut traced = 0;
            for case in cases {
                let ctx = format!("{name} seed {}, oscillating {oscillating}", case.seed);
                traced += usize::from(reversal_holds(&ctx, case, oscillating));
            }
            // Most paths end at the far end without a bifurcation (else the test is empty).
            assert!(
                4 * traced >= 3 * cases.len(),
                "{name}: {traced} of {} traced",
                cases.len()
            );
        }
    }
}

/// A general load through zero: `c f0 + φ(α) f1` traced from α = −1 over [−1, 3] and over
/// windows whose far end is 1e3 and 1e8 (the load fails beyond α = 5, which stops those
/// paths), with c = 1e-6 on random problems and finite-element meshes and c = 1e-8 on the
/// random problems. Its transitions cluster within a few c of φ = 0, where the load is
/// about c times its size at the start. Every event below α = 3 must be the affine path's
/// (`c f0 + s f1` over [φ(−1), φ(3)], exact term magnitudes) at φ⁻¹ of its s, to 1e-11 of
/// its own α. A general load's terms are estimated from the load's change over an α
/// length. That length was the window's (up to 1e3 times the path's own): with the far
/// ends nodes touching down 7e-10 apart were merged into one transition, events moved by
/// up to 3 % of their α, and others went missing, without an error (on some meshes with
/// [−1, 3] too). Then it was the distance from the start: at c = 1e-8 a node's change
/// 1e-12 after another's was merged into it (random problem 34).
#[test]
fn general_loads_through_zero_on_far_windows() {
    let cases = (0..40u64).map(random_case).chain((0..40u64).map(|s| {
        common::fe_case(
            s,
            4 + (7 * s as usize) % 27,
            1 + (s % 4) as usize,
            [0.1, 0.5, 1.5, 3.0, 5.0][s as usize % 5],
        )
    }));
    let (a0, stop) = (-1.0, 3.0);
    let (mut worst, mut events) = (0.0f64, 0);
    let smaller = (0..40u64).map(|s| (random_case(s), 1e-8));
    for (case, c) in cases.map(|case| (case, 1e-6)).chain(smaller) {
        let mut data = case.data.clone();
        data.f0 *= c;
        let affine = run(&data, phi(a0), phi(stop));
        let want: Vec<(f64, NodeChange)> = affine
            .events()
            .iter()
            .map(|e| (inv_phi(e.alpha), (e.node, e.from, e.to)))
            .collect();
        for end in [stop, 1e3, 1e8] {
            let ctx = format!(
                "seed {} (p = {}), c = {c:e}, window [-1, {end:e}]",
                case.seed, data.p
            );
            let load = nonlinear_load(&data, false, 0.0, Some((5.0, 1.0)));
            let mut path = started(&ctx, &data, load, a0, end);
            while path.events().last().is_none_or(|e| e.alpha < stop) {
                match path.step() {
                    Ok(fricont::StepOutcome::End(_)) => break,
                    Ok(_) => {}
                    Err(fricont::Error::Load { .. }) if end > stop => break,
                    Err(e) => panic!("{ctx}: {e}"),
                }
            }
            let got: Vec<&Event> = path.events().iter().filter(|e| e.alpha < stop).collect();
            assert_eq!(
                got.len(),
                want.len(),
                "{ctx}: events {got:?}, want {want:?}"
            );
            let own = |w: f64, g: f64| (w - g).abs() / w.abs();
            worst = worst.max(assert_mapped(&ctx, &want, got.into_iter(), own, 1e-11));
            events += want.len();
        }
    }
    eprintln!("{events} events, worst relative difference in α {worst:e}");
    assert!(events >= 4000, "{events} events");
}
