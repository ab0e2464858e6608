//! The two constructors for hosts that do not hand over A (issue 13), against the A, N, T
//! constructor on the test families (random brute-force problems, finite-element meshes,
//! symmetric bodies, folds, vertical pieces, mirror pairs):
//!
//! * **condensed input**: W and the condensed load `q = B A⁻¹ f` formed here with
//!   nalgebra's dense Cholesky (not fricont's sparse one), given to
//!   [`ProblemBuilder::condensed`];
//! * **a host's solve**: N, T and a solve closure by nalgebra's dense Cholesky, given to
//!   [`ProblemBuilder::with_solve`] in blocks of at most 3 columns.
//!
//! Both must trace the same events (α to 1e-12 relative, nodes, classes, fold and
//! bifurcation flags) with the same λ; u at events through the solve equals the built-in
//! u to 1e-12 relative. Bad input gives its documented error.

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use common::{
    Brute, Case, Data, fe_case, fold_problem, mirror_pair, random_case, symmetric_case,
    vertical_problem,
};
use fricont::condense::{HostSolve, SolveFailure};
use fricont::load::Load;
use fricont::path::{Path, PathOptions};
use fricont::problem::{CsrMatrix, Problem, ProblemBuilder};
use fricont::{Error, faer};
use nalgebra::{DMatrix, DVector};

fn csr(m: &DMatrix<f64>) -> CsrMatrix {
    let rm: Vec<f64> = (0..m.nrows())
        .flat_map(|i| (0..m.ncols()).map(move |j| (i, j)))
        .map(|(i, j)| m[(i, j)])
        .collect();
    CsrMatrix::from_dense(m.nrows(), m.ncols(), &rm).unwrap()
}

fn to_faer(m: &DMatrix<f64>) -> faer::Mat<f64> {
    faer::Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

/// W and the condensed affine load, by nalgebra.
fn condensed_data(data: &Data) -> (DMatrix<f64>, DVector<f64>, DVector<f64>) {
    let (b, w) = Brute::condensed(data);
    let chol = data.a.clone().cholesky().expect("A SPD");
    (w, &b * chol.solve(&data.f0), &b * chol.solve(&data.f1))
}

fn condensed_problem(data: &Data) -> (Problem, Load) {
    let (w, q0, q1) = condensed_data(data);
    let problem = ProblemBuilder::condensed(to_faer(&w))
        .friction(data.friction.clone())
        .gap(data.gap.clone())
        .build()
        .expect("condensed problem");
    let load = Load::affine(q0.as_slice().to_vec(), q1.as_slice().to_vec()).unwrap();
    (problem, load)
}

/// A host's solve by nalgebra's Cholesky, counting the columns it was asked to solve.
fn nalgebra_solve(a: &DMatrix<f64>, max_block: usize, columns: Arc<AtomicUsize>) -> HostSolve {
    let chol = a.clone().cholesky().expect("A SPD");
    HostSolve::new(
        Box::new(move |mut x| {
            assert!(x.ncols() <= max_block, "block of {} columns", x.ncols());
            columns.fetch_add(x.ncols(), Ordering::Relaxed);
            for c in 0..x.ncols() {
                let b = DVector::from_fn(x.nrows(), |i, _| x[(i, c)]);
                let y = chol.solve(&b);
                for i in 0..x.nrows() {
                    x[(i, c)] = y[i];
                }
            }
            Ok(())
        }),
        max_block,
    )
}

fn solve_problem(data: &Data) -> Problem {
    let nm = csr(&data.nm);
    let tm = csr(&data.tm);
    let solve = nalgebra_solve(&data.a, 3, Arc::new(AtomicUsize::new(0)));
    ProblemBuilder::with_solve(data.n, solve, nm, tm)
        .friction(data.friction.clone())
        .gap(data.gap.clone())
        .build()
        .expect("problem with a host's solve")
}

fn run(problem: Problem, load: Load, a0: f64, a1: f64) -> Path {
    let mut path = Path::new(Arc::new(problem), load, PathOptions::window(a0, a1)).unwrap();
    path.start(a0, None).expect("start");
    path.run().expect("run");
    path
}

fn inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Same events and λ; returns the number of events.
fn assert_same_path(ctx: &str, reference: &Path, other: &Path) -> usize {
    assert_same_path_within(ctx, reference, other, 1e-12, 1e-10)
}

/// Same events (α to `alpha_tol` relative, nodes, classes, flags) and λ (to `lambda_tol` of
/// the path's force scale), the same end; returns the number of events.
fn assert_same_path_within(
    ctx: &str,
    reference: &Path,
    other: &Path,
    alpha_tol: f64,
    lambda_tol: f64,
) -> usize {
    let (er, eo) = (reference.events(), other.events());
    assert_eq!(er.len(), eo.len(), "{ctx}: number of events");
    // λ compared on the path's force scale (at a point where all forces vanish, the
    // event's own forces are rounding noise).
    let scale = reference.pieces().iter().fold(1e-300f64, |m, pc| {
        m.max(inf(&pc.lambda_from)).max(inf(&pc.lambda_to))
    });
    for (x, y) in er.iter().zip(eo) {
        let tol = alpha_tol * 1f64.max(x.alpha.abs());
        assert!(
            (x.alpha - y.alpha).abs() <= tol,
            "{ctx}: event {} at α {:.17e} (A, N, T) vs {:.17e}",
            x.index + 1,
            x.alpha,
            y.alpha
        );
        assert_eq!(
            (x.node, x.from, x.to, x.fold, x.bifurcation, x.transition),
            (y.node, y.from, y.to, y.fold, y.bifurcation, y.transition),
            "{ctx}: event {}",
            x.index + 1
        );
        for (a, b) in x
            .lambda_n
            .iter()
            .chain(&x.lambda_t)
            .zip(y.lambda_n.iter().chain(&y.lambda_t))
        {
            assert!(
                (a - b).abs() <= lambda_tol * scale,
                "{ctx}: event {}: λ {a:e} vs {b:e} (scale {scale:e})",
                x.index + 1
            );
        }
    }
    assert_eq!(
        reference.end_reason(),
        other.end_reason(),
        "{ctx}: end reason"
    );
    er.len()
}

fn check_case(ctx: &str, data: &Data, a0: f64, a1: f64) -> usize {
    let reference = run(data.problem(), data.affine_load(), a0, a1);
    // Condensed input: same events and λ; states have no u, and a small residual.
    let (cp, cl) = condensed_problem(data);
    assert!(!cp.has_displacement() && cp.is_condensed() && cp.n() == 0);
    let condensed = run(cp, cl, a0, a1);
    let n = assert_same_path(&format!("{ctx} (condensed)"), &reference, &condensed);
    // A host's solve: same events and λ, and u at events equal to fricont's own u.
    let hosted = run(solve_problem(data), data.affine_load(), a0, a1);
    assert_same_path(&format!("{ctx} (host's solve)"), &reference, &hosted);
    if n > 0 {
        let all = 0..n;
        let (sr, sc, sh) = (
            reference.event_states(all.clone()).unwrap(),
            condensed.event_states(all.clone()).unwrap(),
            hosted.event_states(all).unwrap(),
        );
        // u against the magnitude of its terms, A⁻¹f and A⁻¹Bᵀλ (where they cancel, u is
        // rounding noise of that size).
        let chol = data.a.clone().cholesky().expect("A SPD");
        let free = |alpha: f64| inf(chol.solve(&data.force(alpha)).as_slice());
        for k in 0..n {
            let scale = inf(&sr[k].u).max(free(sr[k].alpha)).max(1e-300);
            assert!(sc[k].u.is_empty(), "{ctx}: condensed state has a u");
            assert!(
                sc[k].residual <= 1e-12,
                "{ctx}: event {}: condensed residual {:e}",
                k + 1,
                sc[k].residual
            );
            assert!(
                sh[k].residual <= 1e-12,
                "{ctx}: event {}: host-solve residual {:e}",
                k + 1,
                sh[k].residual
            );
            let d = sr[k]
                .u
                .iter()
                .zip(&sh[k].u)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(
                d <= 1e-12 * scale,
                "{ctx}: event {}: u differs by {:e} relative",
                k + 1,
                d / scale
            );
        }
    }
    n
}

fn check(ctx: &str, case: &Case) -> usize {
    check_case(ctx, &case.data, case.a0, case.a1)
}

#[test]
fn random_problems() {
    let mut events = 0;
    for seed in 0..120 {
        events += check(&format!("random seed {seed}"), &random_case(seed));
    }
    assert!(events > 250, "only {events} events compared");
}

#[test]
fn finite_element_meshes() {
    let mut events = 0;
    for seed in 0..24u64 {
        let nx = 3 + (seed % 4) as usize;
        let ny = 1 + ((seed / 4) % 3) as usize;
        let friction = [0.3, 1.0, 3.0, 5.0][((seed / 6) % 4) as usize];
        events += check(
            &format!("FE seed {seed} ({nx}x{ny}, F = {friction})"),
            &fe_case(seed, nx, ny, friction),
        );
    }
    assert!(events > 60, "only {events} events compared");
}

#[test]
fn symmetric_bodies_folds_and_vertical_pieces() {
    for seed in 0..16 {
        check(
            &format!("symmetric seed {seed}"),
            &symmetric_case(seed, seed % 2 == 1),
        );
    }
    let mut folds = 0;
    for (name, data, a0, a1) in [
        ("fold problem", fold_problem(), -3.0, 3.0),
        ("vertical problem", vertical_problem(), -2.0, 2.0),
        ("mirror pair", mirror_pair(), -2.0, 2.0),
    ] {
        check_case(name, &data, a0, a1);
        folds += run(data.problem(), data.affine_load(), a0, a1)
            .events()
            .iter()
            .filter(|e| e.fold)
            .count();
    }
    assert!(folds > 0, "the fold family has no fold");
}

/// W by the host's solve equals W by fricont's own factor; the solve is called in blocks
/// of at most `max_block` columns, 2p columns in all for W.
#[test]
fn host_solve_forms_w_in_blocks() {
    let case = fe_case(3, 5, 2, 1.0);
    let data = &case.data;
    let cols = Arc::new(AtomicUsize::new(0));
    let hosted = ProblemBuilder::with_solve(
        data.n,
        nalgebra_solve(&data.a, 4, cols.clone()),
        csr(&data.nm),
        csr(&data.tm),
    )
    .build()
    .unwrap();
    assert_eq!(cols.load(Ordering::Relaxed), 2 * data.p);
    let own = data.problem();
    let (wh, wo) = (hosted.delassus().w(), own.delassus().w());
    let big = (0..wo.nrows()).fold(0.0f64, |m, i| m.max(wo[(i, i)]));
    for i in 0..wo.nrows() {
        for j in 0..wo.ncols() {
            assert!(
                (wh[(i, j)] - wo[(i, j)]).abs() <= 1e-13 * big,
                "W({i}, {j})"
            );
        }
    }
    assert!(hosted.a().is_none() && hosted.has_displacement());
}

#[test]
fn bad_condensed_input_is_rejected() {
    let data = fe_case(1, 4, 1, 1.0).data;
    let (w, _, _) = condensed_data(&data);
    let m = w.nrows();
    let build = |w: DMatrix<f64>| ProblemBuilder::condensed(to_faer(&w)).build();
    // Not symmetric.
    let mut ns = w.clone();
    ns[(0, 1)] += 1e-6 * w[(0, 0)];
    assert!(matches!(build(ns), Err(Error::NotSymmetric(_))));
    // Indefinite: a row that is a combination of others (rank-deficient), and a negative
    // diagonal; the message names the row.
    let mut dep = w.clone();
    dep.row_mut(m - 1).copy_from(&w.row(0));
    dep.column_mut(m - 1).copy_from(&w.column(0));
    dep[(m - 1, m - 1)] = w[(0, 0)];
    match build(dep) {
        Err(Error::WNotSpd(msg)) => assert!(msg.contains(&format!("row {m}")), "{msg}"),
        other => panic!("dependent row: {other:?}"),
    }
    let mut neg = w.clone();
    neg[(2, 2)] = -1.0;
    match build(neg) {
        Err(Error::WNotSpd(msg)) => assert!(msg.contains("row 3"), "{msg}"),
        other => panic!("negative diagonal: {other:?}"),
    }
    // NaN, odd size, empty.
    let mut nan = w.clone();
    nan[(1, 0)] = f64::NAN;
    assert!(matches!(build(nan), Err(Error::NonFinite(_))));
    assert!(matches!(
        build(w.view((0, 0), (m - 1, m - 1)).into_owned()),
        Err(Error::Dimension(_))
    ));
    assert!(matches!(
        build(DMatrix::zeros(0, 0)),
        Err(Error::InvalidParameter(_))
    ));
    // A load of n entries given to a condensed problem.
    let (cp, _) = condensed_problem(&data);
    let e = Path::new(
        Arc::new(cp),
        data.affine_load(),
        PathOptions::window(0.0, 1.0),
    )
    .err()
    .expect("an n-entry load for a condensed problem");
    assert!(
        matches!(e, Error::Dimension(ref m) if m.contains("2p")),
        "{e:?}"
    );
}

#[test]
fn failing_or_wrong_host_solves_are_errors() {
    let data = random_case(8).data;
    let with = |f: fricont::condense::SolveFn| {
        ProblemBuilder::with_solve(data.n, HostSolve::new(f, 8), csr(&data.nm), csr(&data.tm))
            .build()
    };
    // Fatal code: an error with the host's code.
    let e = with(Box::new(|_| {
        Err(SolveFailure {
            code: -7,
            message: "out of licences".into(),
        })
    }))
    .unwrap_err();
    assert!(matches!(e, Error::HostSolve { code: -7, .. }), "{e:?}");
    // Recoverable once: retried on the restored right-hand sides, and then succeeds
    // (the first call scribbles over x before failing).
    let chol = data.a.clone().cholesky().unwrap();
    let mut calls = 0;
    let flaky = with(Box::new(move |mut x| {
        calls += 1;
        if calls == 1 {
            x.fill(123.0);
            return Err(SolveFailure {
                code: 2,
                message: "busy".into(),
            });
        }
        for c in 0..x.ncols() {
            let y = chol.solve(&DVector::from_fn(x.nrows(), |i, _| x[(i, c)]));
            for i in 0..x.nrows() {
                x[(i, c)] = y[i];
            }
        }
        Ok(())
    }))
    .expect("a recoverable failure is retried");
    let own = data.problem();
    let (wf, wo) = (flaky.delassus().w(), own.delassus().w());
    assert!((wf[(0, 0)] - wo[(0, 0)]).abs() <= 1e-13 * wo[(0, 0)]);
    // Recoverable twice in a row: an error.
    let e = with(Box::new(|_| {
        Err(SolveFailure {
            code: 3,
            message: "busy".into(),
        })
    }))
    .unwrap_err();
    assert!(matches!(e, Error::HostSolve { code: 3, .. }), "{e:?}");
    // NaN in the result.
    let e = with(Box::new(|mut x| {
        x[(0, 0)] = f64::NAN;
        Ok(())
    }))
    .unwrap_err();
    assert!(matches!(e, Error::HostSolve { code: 0, .. }), "{e:?}");
    // A solve that is not that of a symmetric matrix (A + a skew part).
    let mut skew = data.a.clone();
    skew[(0, 1)] += 0.3 * data.a[(0, 0)];
    let lu = skew.lu();
    let e = with(Box::new(move |mut x| {
        for c in 0..x.ncols() {
            let y = lu
                .solve(&DVector::from_fn(x.nrows(), |i, _| x[(i, c)]))
                .unwrap();
            for i in 0..x.nrows() {
                x[(i, c)] = y[i];
            }
        }
        Ok(())
    }))
    .unwrap_err();
    assert!(
        matches!(e, Error::NotSymmetric(ref m) if m.contains("host")),
        "{e:?}"
    );
}

/// The load vector of [`general_loads_condense_by_solves_only_the_directions_they_span`]:
/// `f0 + φ(α) f1` with φ(α) = α + 0.2 sin 2α (in the span of f0 and f1), plus, when
/// `spread`, `0.05 ‖f1‖∞ sin(ω_i α + θ_i)` in every entry i with its own ω_i and θ_i
/// (in the span of no few vectors).
fn general_force(data: &Data, spread: bool, alpha: f64, out: &mut [f64]) {
    let phi = alpha + 0.2 * (2.0 * alpha).sin();
    let amp = 0.05 * inf(data.f1.as_slice());
    for (i, o) in out.iter_mut().enumerate() {
        *o = data.f0[i] + phi * data.f1[i];
        if spread {
            let (om, th) = (1.0 + 0.37 * i as f64, 0.91 * i as f64);
            *o += amp * (om * alpha + th).sin();
        }
    }
}

/// The reference for a general load [`general_force`] on `data`: q(α) = B A⁻¹ f(α) by
/// nalgebra at every α, on condensed input (where fricont solves nothing), traced over
/// (a0, a1).
fn condensed_general_reference(data: &Arc<Data>, spread: bool, a0: f64, a1: f64) -> Path {
    let (b, w) = Brute::condensed(data);
    let chol = data.a.clone().cholesky().expect("A SPD");
    let problem = ProblemBuilder::condensed(to_faer(&w))
        .friction(data.friction.clone())
        .gap(data.gap.clone())
        .build()
        .expect("condensed problem");
    let d = data.clone();
    let q = Box::new(move |al: f64, out: &mut [f64]| {
        let mut f = DVector::zeros(d.n);
        general_force(&d, spread, al, f.as_mut_slice());
        out.copy_from_slice((&b * chol.solve(&f)).as_slice());
        Ok(())
    });
    run(problem, Load::general(w.nrows(), q, None), a0, a1)
}

/// A general load is condensed by solves with A only for the directions its evaluations
/// span: on finite-element meshes (n from 48 to 96) under `f0 + φ(α) f1` as a general
/// load, a host's solve is asked for at most 8 columns over the whole trace for the span's
/// directions (its limit) and two for each of its checks against a solve (1st, 2nd, 4th,
/// … evaluation it serves), against hundreds of evaluations of f, and the events are
/// those of the same
/// load condensed here by nalgebra at every α and given to [`ProblemBuilder::condensed`]
/// (no solves to save there: every α its own condensation). With a term in every entry
/// that no few vectors span, the span is given up after 8 directions and every
/// evaluation solves: the same events as the condensed reference again. Events: α to
/// 1e-10 relative, nodes, classes, flags; λ to 1e-9 of the path's force scale.
#[test]
fn general_loads_condense_by_solves_only_the_directions_they_span() {
    let mut events = 0;
    for seed in 0..12u64 {
        let nx = 8 + (seed % 5) as usize;
        let ny = 2 + (seed % 2) as usize;
        let friction = [0.3, 1.0, 5.0][(seed % 3) as usize];
        let case = fe_case(seed, nx, ny, friction);
        let data = Arc::new(case.data.clone());
        assert!(
            data.n > 32,
            "seed {seed}: n = {} (the span is off below 33)",
            data.n
        );
        for spread in [false, true] {
            let ctx = format!("FE seed {seed} ({nx}x{ny}, F = {friction}, spread {spread})");
            let reference = condensed_general_reference(&data, spread, case.a0, case.a1);
            // fricont's condensation through a host's solve, counting its columns
            let columns = Arc::new(AtomicUsize::new(0));
            let calls = Arc::new(AtomicUsize::new(0));
            let problem = ProblemBuilder::with_solve(
                data.n,
                nalgebra_solve(&data.a, 3, columns.clone()),
                csr(&data.nm),
                csr(&data.tm),
            )
            .friction(data.friction.clone())
            .gap(data.gap.clone())
            .build()
            .expect("problem with a host's solve");
            let (d, c) = (data.clone(), calls.clone());
            let f = Box::new(move |al: f64, out: &mut [f64]| {
                c.fetch_add(1, Ordering::Relaxed);
                general_force(&d, spread, al, out);
                Ok(())
            });
            let before = columns.load(Ordering::Relaxed);
            let hosted = run(problem, Load::general(data.n, f, None), case.a0, case.a1);
            let (solved, evaluated) = (
                columns.load(Ordering::Relaxed) - before,
                calls.load(Ordering::Relaxed),
            );
            if spread {
                assert!(solved > 8, "{ctx}: {solved} columns solved");
            } else {
                // 8 directions at most, and two columns for each check of the span
                // against a solve (the 1st, 2nd, 4th, … evaluation it serves)
                let checks = (evaluated as f64).log2().floor() as usize + 1;
                assert!(
                    solved <= 8 + 2 * checks && evaluated >= 100,
                    "{ctx}: {solved} columns solved for {evaluated} evaluations of f"
                );
            }
            let n = assert_same_path_within(&ctx, &reference, &hosted, 1e-10, 1e-9);
            events += n;
            eprintln!("{ctx}: {n} events, {solved} columns for {evaluated} evaluations");
        }
    }
    assert!(events > 100, "only {events} events compared");
}

/// A load whose part that drives the contact is below 64 ε of its 2-norm: a finite-element
/// mesh with one more dof, decoupled from the mesh (A = diag(A_mesh, 1), no contact row
/// reaches it), loaded by `G e_extra + f0 + φ(α) f1` with G = 1e16 ‖f0‖₂. The span's
/// normwise test takes every evaluation for the first one (the mesh's part is 1e-16 of
/// the load), which would trace a constant load; its check against a solve with A finds
/// the images far apart and gives the span up. The events must be those of the mesh's own
/// load `f0 + φ(α) f1` condensed by nalgebra (the extra dof adds nothing to q).
#[test]
fn a_load_mostly_off_the_contact_gives_the_span_up() {
    for seed in 0..4u64 {
        let case = fe_case(
            seed,
            8 + seed as usize,
            2,
            [0.3, 1.0, 5.0][seed as usize % 3],
        );
        let data = Arc::new(case.data.clone());
        let n = data.n + 1;
        let mut a = DMatrix::zeros(n, n);
        a.view_mut((0, 0), (data.n, data.n)).copy_from(&data.a);
        a[(data.n, data.n)] = 1.0;
        let widen = |m: &DMatrix<f64>| {
            let mut w = DMatrix::zeros(m.nrows(), n);
            w.view_mut((0, 0), (m.nrows(), data.n)).copy_from(m);
            csr(&w)
        };
        let big = 1e16 * data.f0.norm();
        let problem = ProblemBuilder::with_solve(
            n,
            nalgebra_solve(&a, 3, Arc::new(AtomicUsize::new(0))),
            widen(&data.nm),
            widen(&data.tm),
        )
        .friction(data.friction.clone())
        .gap(data.gap.clone())
        .build()
        .expect("problem with a host's solve");
        let d = data.clone();
        let f = Box::new(move |al: f64, out: &mut [f64]| {
            general_force(&d, false, al, &mut out[..d.n]);
            out[d.n] = big;
            Ok(())
        });
        let hosted = run(problem, Load::general(n, f, None), case.a0, case.a1);
        let reference = condensed_general_reference(&data, false, case.a0, case.a1);
        let ctx = format!("FE seed {seed} with a decoupled dof loaded by {big:e}");
        let events = assert_same_path_within(&ctx, &reference, &hosted, 1e-10, 1e-9);
        assert!(events > 0, "{ctx}: no events");
    }
}
