//! The shared sample `../shared/cases/sample-rect30` (n = 1320, p = 30, F = 0.3) through
//! the library (the CLI is tested elsewhere). The sample is read with the small Matrix
//! Market reader of `tests/common`, independent of `src/io.rs`. No expected number is
//! taken from anywhere; instead every event is confirmed independently:
//!
//! * the event state solves the problem (equilibrium with the sparse A, Signorini and
//!   Coulomb conditions, residual ≤ 1e-12);
//! * the transition point satisfies the equations of the node's class on both sides;
//! * fresh fixed-α solves just before and just after the event find the node in the
//!   reported classes (`from` before, `to` after, along the path's direction);
//! * the events do not depend on r (1e-3, 1, 1e3 times the default).

mod common;

use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;

use common::{Brute, Data, check_state, class_equations_hold, close, read_mtx, read_vec, trace};
use fricont::{CsrMatrix, EndReason, Path, PathOptions, ProblemBuilder, Storage};
use nalgebra::{DMatrix, DVector};

/// The sample case shipped in the repository (a copy of the brief's `sample-rect30`).
fn sample_dir() -> PathBuf {
    FsPath::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sample-rect30")
}

struct Sample {
    data: Data,
    builder: ProblemBuilder,
    a0: f64,
    a1: f64,
}

fn load_sample(dir: &FsPath) -> Sample {
    let (n, n2, ta) = read_mtx(&dir.join("A.mtx"));
    assert_eq!(n, n2);
    let (p, nn, tn) = read_mtx(&dir.join("N.mtx"));
    let (p2, nt, tt) = read_mtx(&dir.join("T.mtx"));
    assert_eq!((p2, nn, nt), (p, n, n));
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("meta.json")).unwrap()).unwrap();
    let friction = match &meta["F"] {
        serde_json::Value::Array(v) => v.iter().map(|x| x.as_f64().unwrap()).collect(),
        x => vec![x.as_f64().unwrap(); p],
    };
    let gap = if dir.join("gap.txt").exists() {
        read_vec(&dir.join("gap.txt"))
    } else {
        vec![0.0; p]
    };
    let dense = |r: usize, c: usize, t: &[(usize, usize, f64)]| {
        let mut m = DMatrix::zeros(r, c);
        for &(i, j, v) in t {
            m[(i, j)] += v;
        }
        m
    };
    let data = Data {
        n,
        p,
        a: dense(n, n, &ta),
        nm: dense(p, n, &tn),
        tm: dense(p, n, &tt),
        friction: friction.clone(),
        gap: gap.clone(),
        f0: DVector::from_vec(read_vec(&dir.join("f0.txt"))),
        f1: DVector::from_vec(read_vec(&dir.join("f1.txt"))),
    };
    let builder = ProblemBuilder::new(
        CsrMatrix::from_triplets("A", n, n, &ta).unwrap(),
        Storage::Full,
        CsrMatrix::from_triplets("N", p, n, &tn).unwrap(),
        CsrMatrix::from_triplets("T", p, n, &tt).unwrap(),
    )
    .friction(friction)
    .gap(gap);
    Sample {
        data,
        builder,
        a0: meta["alpha_start"].as_f64().unwrap(),
        a1: meta["alpha_end"].as_f64().unwrap(),
    }
}

#[test]
fn sample_rect30_events_confirmed() {
    let dir = sample_dir();
    let s = load_sample(&dir);
    let data = &s.data;
    let problem = Arc::new(s.builder.clone().build().unwrap());
    let mut path = trace(problem.clone(), data.affine_load(), s.a0, s.a1);
    assert_eq!(path.end_reason(), Some(&EndReason::Window));
    let events = common::events_with_state(&path);
    assert!(!events.is_empty());
    let pieces = path.pieces().to_vec();
    assert_eq!(
        pieces.len(),
        events
            .iter()
            .map(|e| e.transition)
            .collect::<std::collections::BTreeSet<_>>()
            .len()
            + 1
    );

    // distinct transition α's, to keep the probes away from neighbouring events
    let mut alphas: Vec<f64> = events.iter().map(|e| e.alpha).collect();
    alphas.push(s.a0);
    alphas.push(s.a1);
    alphas.sort_by(f64::total_cmp);
    alphas.dedup();

    for e in &events {
        assert!(
            e.state.residual <= 1e-12,
            "event {}: residual {:e}",
            e.index,
            e.state.residual
        );
        check_state(data, &data.force(e.alpha), &e.state, 1e-9)
            .unwrap_or_else(|m| panic!("event {}: {m}", e.index));
        class_equations_hold(data, &e.state, e.node, e.from, 1e-9)
            .unwrap_or_else(|m| panic!("event {} (before): {m}", e.index));
        class_equations_hold(data, &e.state, e.node, e.to, 1e-9)
            .unwrap_or_else(|m| panic!("event {} (after): {m}", e.index));

        // probes before and after along the path
        let gapl = alphas
            .iter()
            .filter(|&&a| a < e.alpha)
            .map(|a| e.alpha - a)
            .fold(f64::INFINITY, f64::min);
        let gapr = alphas
            .iter()
            .filter(|&&a| a > e.alpha)
            .map(|a| a - e.alpha)
            .fold(f64::INFINITY, f64::min);
        let delta = 1e-7f64.min(0.25 * gapl.min(gapr));
        let dir_before = pieces[e.transition].direction as f64;
        let dir_after = pieces[e.transition + 1].direction as f64;
        assert!(
            dir_before != 0.0 && dir_after != 0.0,
            "no vertical pieces expected here"
        );
        for (alpha, class) in [
            (e.alpha - dir_before * delta, e.from),
            (e.alpha + dir_after * delta, e.to),
        ] {
            let end = if alpha < 0.5 * (s.a0 + s.a1) {
                s.a1
            } else {
                s.a0
            };
            let mut p = Path::new(
                problem.clone(),
                data.affine_load(),
                PathOptions::window(alpha, end),
            )
            .unwrap();
            p.start(alpha, None).unwrap();
            let st = &p.start_state().unwrap();
            assert_eq!(
                st.classes[e.node],
                class,
                "event {} (α = {}, node {}): fixed-α solve at {alpha}",
                e.index,
                e.alpha,
                e.node + 1
            );
            assert!(st.residual <= 1e-12);
            // and the path's own solution there agrees
            let sols = path.solutions_at(alpha).unwrap();
            assert_eq!(sols.len(), 1, "F = 0.3: one solution expected at {alpha}");
            let d = sols[0]
                .state
                .lambda_n
                .iter()
                .zip(&st.lambda_n)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let scale = st.lambda_n.iter().fold(1f64, |m, v| m.max(v.abs()));
            assert!(d <= 1e-9 * scale, "λν differs by {d:e} at {alpha}");
        }
    }

    eprintln!("sample-rect30: {} events confirmed", events.len());
}

/// Transition points of the sample against a reference computed as accurately as the data
/// allow (`Brute::condensed_precise`: mixed-precision refinement of every solve with A,
/// W, q, piece solves and guards with compensated dot products). For each event, the
/// reference is where the traced piece before it ends, and (as a consistency check of
/// the reference) where the piece after it begins. Checked for r = 1e-3, 1, 1e3 times
/// the default, with relative tolerance 1e-12; the events of the
/// three runs must also agree with each other (r-invariance).
#[test]
fn sample_rect30_transition_points_precise() {
    let dir = sample_dir();
    let s = load_sample(&dir);
    let data = &s.data;
    let base = s.builder.clone().build().unwrap();
    let r0 = base.default_r();
    let reference = trace(
        Arc::new(base.with_r(r0).unwrap()),
        data.affine_load(),
        s.a0,
        s.a1,
    );
    let br = Brute::condensed_precise(data);
    let pieces = reference.pieces().to_vec();
    let mut want = Vec::new();
    for e in reference.events() {
        let before = &pieces[e.transition];
        let after = &pieces[e.transition + 1];
        let pb = br
            .piece_interval(&before.classes)
            .expect("piece before is regular");
        let pa = br
            .piece_interval(&after.classes)
            .expect("piece after is regular");
        let exit = if before.direction > 0 { pb.hi } else { pb.lo };
        let entry = if after.direction > 0 { pa.lo } else { pa.hi };
        // the reference is consistent with itself far below the tolerance
        assert!(
            close(exit, entry, 2e-13),
            "reference: exit {exit:.17e} vs entry {entry:.17e}"
        );
        want.push((exit, e.node, e.from, e.to));
    }
    // How precisely the data determine each event: the events of the same problem with
    // every entry of A changed by a few units in the last place (a symmetric, sign-mixed
    // relative perturbation of 4ε). No computation in f64 can locate an event more
    // precisely than that; well-conditioned events move by ~1e-15, the sample's shallow
    // crossing (event 3) by ~1e-12.
    let eps4 = 4.0 * f64::EPSILON;
    let perturbed: Vec<(usize, usize, f64)> = read_mtx(&dir.join("A.mtx"))
        .2
        .into_iter()
        .map(|(i, j, v)| {
            let (lo, hi) = (i.min(j), i.max(j));
            let sign = if (lo * 7919 + hi * 104_729) % 3 == 0 {
                -1.0
            } else {
                1.0
            };
            (i, j, v * (1.0 + sign * eps4))
        })
        .collect();
    let csr = |f: &str| {
        let (r, c, t) = read_mtx(&dir.join(f));
        CsrMatrix::from_triplets(f, r, c, &t).unwrap()
    };
    let pert = ProblemBuilder::new(
        CsrMatrix::from_triplets("A", data.n, data.n, &perturbed).unwrap(),
        Storage::Full,
        csr("N.mtx"),
        csr("T.mtx"),
    )
    .friction(data.friction.clone())
    .gap(data.gap.clone())
    .build()
    .unwrap();
    let pert_path = trace(Arc::new(pert), data.affine_load(), s.a0, s.a1);
    assert_eq!(pert_path.events().len(), reference.events().len());
    let sensitivity: Vec<f64> = pert_path
        .events()
        .iter()
        .zip(reference.events())
        .map(|(x, y)| (x.alpha - y.alpha).abs())
        .collect();
    eprintln!(
        "sensitivity of the events to a 4-ulp perturbation of A: {:?}",
        sensitivity
            .iter()
            .map(|x| format!("{x:.1e}"))
            .collect::<Vec<_>>()
    );
    let mut failures = Vec::new();
    let mut runs = Vec::new();
    for f in [1e-3, 1.0, 1e3] {
        let pr = Arc::new(base.with_r(f * r0).unwrap());
        let path = trace(pr, data.affine_load(), s.a0, s.a1);
        let ev = common::events_with_state(&path);
        assert_eq!(ev.len(), want.len(), "r = {f}·r0");
        for (e, &(x, node, from, to)) in ev.iter().zip(&want) {
            assert_eq!((e.node, e.from, e.to), (node, from, to), "r = {f}·r0");
            assert!(
                e.state.residual <= 1e-12,
                "r = {f}·r0: residual {:e}",
                e.state.residual
            );
            let rel = (e.alpha - x) / x.abs().max(1.0);
            // 1e-12 relative, widened by what the data determine (the sensitivity above,
            // with a factor 4 for the rounding of the factorisation, which exceeds 4 ulp).
            let tol = 1e-12 + 4.0 * sensitivity[e.index] / x.abs().max(1.0);
            if rel.abs() > tol {
                failures.push(format!(
                    "r = {f:e}·r0: event {} (node {}, {} -> {}) α = {:.17e}, reference {:.17e}, relative error {rel:.1e}",
                    e.index + 1,
                    node + 1,
                    from,
                    to,
                    e.alpha,
                    x
                ));
            }
        }
        runs.push((f, ev.iter().map(|e| e.alpha).collect::<Vec<_>>()));
    }
    for (f, a) in &runs {
        for (k, (x, y)) in a.iter().zip(&runs[1].1).enumerate() {
            // Two computations, each within the tolerance above of the data's answer.
            let tol = 1e-12 + 8.0 * sensitivity[k] / x.abs().max(1.0);
            if (x - y).abs() > tol * x.abs().max(1.0) {
                failures.push(format!(
                    "r-invariance: event {} at r = {f:e}·r0: {x:.17e}, at r0: {y:.17e}",
                    k + 1
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} transition points off by more than 1e-12:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The sample's A, N and T handed over as a caller's raw CSR with **duplicate entries**
/// (every value split into two parts, the rows' entries in reverse order), with 64-bit and
/// with 32-bit indices, 0- and 1-based: the library sums the parts (in the order given),
/// and the path is that of the summed matrices, bit for bit. The summed reference is made
/// here by adding the same two parts, so the two inputs hold the same numbers.
#[test]
fn sample_duplicates_and_int32_indices_give_the_events_of_the_summed_matrices() {
    let dir = sample_dir();
    let (n, _, ta) = read_mtx(&dir.join("A.mtx"));
    let (p, _, tn) = read_mtx(&dir.join("N.mtx"));
    let (_, _, tt) = read_mtx(&dir.join("T.mtx"));
    let s = load_sample(&dir);
    let fr = s.data.friction.clone();
    let gap = s.data.gap.clone();
    let split = |v: f64| (0.375 * v, v - 0.375 * v);
    // Summed reference: triplets with the value a + b of the two parts.
    let summed = |name: &str, r: usize, t: &[(usize, usize, f64)]| {
        let t2: Vec<(usize, usize, f64)> = t
            .iter()
            .map(|&(i, j, v)| {
                let (a, b) = split(v);
                (i, j, a + b)
            })
            .collect();
        CsrMatrix::from_triplets(name, r, n, &t2).unwrap()
    };
    // Raw CSR with each entry as two, in reverse order within the row (part a first).
    fn raw<I: TryFrom<i64> + Copy + Into<i64>>(
        rows: usize,
        t: &[(usize, usize, f64)],
        base: i64,
        split: impl Fn(f64) -> (f64, f64),
    ) -> (Vec<I>, Vec<I>, Vec<f64>) {
        let conv = |x: i64| I::try_from(x).ok().expect("index fits");
        let mut by_row: Vec<Vec<(usize, f64)>> = vec![Vec::new(); rows];
        for &(i, j, v) in t {
            by_row[i].push((j, v));
        }
        let (mut rp, mut ci, mut vals) = (vec![conv(base)], Vec::new(), Vec::new());
        for row in &by_row {
            // part a of every entry (reverse order), then part b of every entry
            for &(j, v) in row.iter().rev() {
                ci.push(conv(j as i64 + base));
                vals.push(split(v).0);
            }
            for &(j, v) in row {
                ci.push(conv(j as i64 + base));
                vals.push(split(v).1);
            }
            rp.push(conv(ci.len() as i64 + base));
        }
        (rp, ci, vals)
    }
    let events = |a: CsrMatrix, nm: CsrMatrix, tm: CsrMatrix| {
        let problem = ProblemBuilder::new(a, Storage::Full, nm, tm)
            .friction(fr.clone())
            .gap(gap.clone())
            .build()
            .unwrap();
        let path = trace(Arc::new(problem), s.data.affine_load(), s.a0, s.a1);
        assert_eq!(path.end_reason(), Some(&EndReason::Window));
        path.events()
            .iter()
            .map(|e| (e.alpha.to_bits(), e.node, e.from, e.to, e.fold))
            .collect::<Vec<_>>()
    };
    let reference = events(
        summed("A", n, &ta),
        summed("N", p, &tn),
        summed("T", p, &tt),
    );
    assert!(!reference.is_empty());
    for base in [0i64, 1] {
        let (ra, ca, va) = raw::<i64>(n, &ta, base, split);
        let (rn, cn, vn) = raw::<i64>(p, &tn, base, split);
        let (rt, ct, vt) = raw::<i64>(p, &tt, base, split);
        assert_eq!(va.len(), 2 * ta.len(), "every entry of A is given twice");
        let got = events(
            CsrMatrix::from_raw("A", n, n, &ra, &ca, &va, base).unwrap(),
            CsrMatrix::from_raw("N", p, n, &rn, &cn, &vn, base).unwrap(),
            CsrMatrix::from_raw("T", p, n, &rt, &ct, &vt, base).unwrap(),
        );
        assert_eq!(got, reference, "int64, base {base}");
        let (ra, ca, va) = raw::<i32>(n, &ta, base, split);
        let (rn, cn, vn) = raw::<i32>(p, &tn, base, split);
        let (rt, ct, vt) = raw::<i32>(p, &tt, base, split);
        let got = events(
            CsrMatrix::from_raw("A", n, n, &ra, &ca, &va, base).unwrap(),
            CsrMatrix::from_raw("N", p, n, &rn, &cn, &vn, base).unwrap(),
            CsrMatrix::from_raw("T", p, n, &rt, &ct, &vt, base).unwrap(),
        );
        assert_eq!(got, reference, "int32, base {base}");
    }
}
