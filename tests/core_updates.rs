//! Updated factorisations against fresh ones: on every test family (random brute-force
//! problems, finite-element meshes, symmetric bodies, folds, vertical pieces, a sample
//! mesh, nonlinear loads) the path traced by rank-2 updates of one factorised base must
//! be the path traced by a fresh full-pivoting factorisation of every piece Jacobian: the
//! same events (α to 1e-12 relative, nodes, classes, fold and bifurcation flags), and on
//! every piece the same direction, orientation and determinant sign — the signs the
//! updated tracer carries by the matrix determinant lemma, the fresh one reads off the
//! pivots.

mod common;

use std::sync::Arc;

use common::{
    Case, Data, fe_case, fold_problem, mirror_pair, random_case, symmetric_case, vertical_problem,
};
use fricont::load::{Load, LoadFailure};
use fricont::path::{Path, PathOptions};
use fricont::problem::Problem;

fn run(problem: &Arc<Problem>, load: Load, a0: f64, a1: f64, fresh: bool) -> Path {
    let mut opts = PathOptions::window(a0, a1);
    opts.fresh_factorisations = fresh;
    let mut path = Path::new(problem.clone(), load, opts).expect("Path::new");
    path.start(a0, None).expect("start");
    path.run().expect("run");
    path
}

/// Compares the two tracers; returns the number of events compared.
fn compare(ctx: &str, problem: Arc<Problem>, load: impl Fn() -> Load, a0: f64, a1: f64) -> usize {
    let up = run(&problem, load(), a0, a1, false);
    let fr = run(&problem, load(), a0, a1, true);
    let (eu, ef) = (up.events(), fr.events());
    assert_eq!(eu.len(), ef.len(), "{ctx}: number of events");
    for (x, y) in eu.iter().zip(ef) {
        let tol = 1e-12 * 1f64.max(x.alpha.abs());
        assert!(
            (x.alpha - y.alpha).abs() <= tol,
            "{ctx}: event {} at α {:.17e} (updated) vs {:.17e} (fresh)",
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
    }
    let (pu, pf) = (up.pieces(), fr.pieces());
    assert_eq!(pu.len(), pf.len(), "{ctx}: number of pieces");
    for (k, (x, y)) in pu.iter().zip(pf).enumerate() {
        assert_eq!(x.classes, y.classes, "{ctx}: piece {k}");
        assert_eq!(
            (x.direction, x.orientation, x.det_sign),
            (y.direction, y.orientation, y.det_sign),
            "{ctx}: piece {k} (direction, orientation, det sign)"
        );
    }
    assert_eq!(up.end_reason(), fr.end_reason(), "{ctx}: end reason");
    eu.len()
}

fn compare_case(ctx: &str, case: &Case) -> usize {
    let data = &case.data;
    compare(
        ctx,
        Arc::new(data.problem()),
        || data.affine_load(),
        case.a0,
        case.a1,
    )
}

#[test]
fn random_problems() {
    let mut events = 0;
    for seed in 0..200 {
        events += compare_case(&format!("random seed {seed}"), &random_case(seed));
    }
    assert!(events > 400, "only {events} events compared");
}

#[test]
fn finite_element_meshes() {
    let mut events = 0;
    for seed in 0..40u64 {
        let nx = 3 + (seed % 4) as usize;
        let ny = 1 + ((seed / 4) % 3) as usize;
        let friction = [0.3, 1.0, 3.0, 5.0][((seed / 12) % 4) as usize];
        let case = fe_case(seed, nx, ny, friction);
        events += compare_case(
            &format!("FE seed {seed} ({nx}x{ny}, F = {friction})"),
            &case,
        );
    }
    assert!(events > 100, "only {events} events compared");
}

#[test]
fn symmetric_bodies() {
    for seed in 0..40 {
        let centre = seed % 2 == 1;
        compare_case(
            &format!("symmetric seed {seed}"),
            &symmetric_case(seed, centre),
        );
    }
}

#[test]
fn folds_vertical_pieces_and_mirror_pairs() {
    for (name, data, a0, a1) in [
        ("fold problem", fold_problem(), -3.0, 3.0),
        ("vertical problem", vertical_problem(), -2.0, 2.0),
        ("mirror pair", mirror_pair(), -2.0, 2.0),
    ] {
        compare(
            name,
            Arc::new(data.problem()),
            || data.affine_load(),
            a0,
            a1,
        );
    }
}

/// A mesh with many more transitions than updates kept on one base, so that the base is
/// refactorised several times along the path, and the nonlinear-load stepping (which
/// solves with the updated factorisation) on the same mesh.
#[test]
fn long_paths_refactorise_and_nonlinear_loads() {
    let case = fe_case(7, 24, 2, 1.0);
    let data: &Data = &case.data;
    let problem = Arc::new(data.problem());
    let n = compare(
        "FE 24x2",
        problem.clone(),
        || data.affine_load(),
        case.a0,
        case.a1,
    );
    let up = run(&problem, data.affine_load(), case.a0, case.a1, false);
    let m = 2 * data.p;
    assert!(
        n > m / 8 && up.refactorisations() >= 2 && up.refactorisations() < n,
        "{n} events, {} refactorisations: the updates were not exercised",
        up.refactorisations()
    );
    let (f0, f1) = (data.f0.as_slice().to_vec(), data.f1.as_slice().to_vec());
    let basis = || {
        Load::basis(
            vec![f0.clone(), f1.clone()],
            Box::new(
                |a: f64, w: &mut [f64], dw: &mut [f64]| -> Result<(), LoadFailure> {
                    w[0] = 1.0;
                    w[1] = a + 0.1 * a * a * a;
                    dw[0] = 0.0;
                    dw[1] = 1.0 + 0.3 * a * a;
                    Ok(())
                },
            ),
        )
        .unwrap()
    };
    compare("FE 24x2, cubic load", problem, basis, case.a0, case.a1);
}

/// A homogeneous load `f = α f1` on meshes with 7 to 9 contact nodes: at α = 0 every node
/// is at the zero-force vertex at once (4^p > 4096 neighbouring pieces; before the vertex
/// was snapped against the forces of the piece the path came by, the updated tracer
/// failed there on 5 of these 12 meshes with "node i fits no class"), so the classes
/// after it come from the directional contact problem, whose piece solves update the
/// path's factorisation (O(m²) per piece) on the updated tracer and factorise afresh on
/// the reference: both must trace the same path through the vertex, and by positive
/// homogeneity the piece that leaves it is the piece of the fixed-α solution at α = 1/2
/// scaled (checked through `solutions_at`).
#[test]
fn directional_problem_at_a_vertex_of_many_nodes() {
    let mut through = 0;
    for seed in 0..12u64 {
        let nx = 7 + (seed % 3) as usize;
        let friction = [0.3, 1.0, 3.0][(seed / 3 % 3) as usize];
        let mut case = fe_case(seed, nx, 1 + (seed % 2) as usize, friction);
        case.data.f0.fill(0.0);
        let ctx = format!("vertex seed {seed} (p = {}, F = {friction})", case.data.p);
        let problem = Arc::new(case.data.problem());
        compare(&ctx, problem.clone(), || case.data.affine_load(), -1.0, 1.0);
        let mut path = run(&problem, case.data.affine_load(), -1.0, 1.0, false);
        let at_zero: Vec<_> = path
            .events()
            .iter()
            .filter(|e| e.alpha == 0.0)
            .cloned()
            .collect();
        if at_zero.is_empty() || path.end_reason() != Some(&fricont::EndReason::Window) {
            continue;
        }
        through += 1;
        // The classes leaving the vertex are those of the solution at α > 0 up to the
        // first event after it.
        let next = path
            .events()
            .iter()
            .map(|e| e.alpha)
            .find(|&a| a > 0.0)
            .unwrap_or(1.0);
        let sols = path.solutions_at(0.5 * next).expect("solutions_at");
        assert_eq!(sols.len(), 1, "{ctx}: one solution at {}", 0.5 * next);
        assert_eq!(
            sols[0].state.classes, at_zero[0].classes,
            "{ctx}: classes after the vertex"
        );
    }
    assert!(
        through >= 6,
        "only {through} paths went through a vertex of ≥ 7 nodes"
    );
}

/// `W = D + c G Gᵀ / m` (D diagonal in [1, 2], G uniform in [−1, 1], both from `rng`):
/// SPD, every node coupled to every other (entries about `c/√m` of the diagonal).
fn coupled_w(rng: &mut common::Rng, m: usize, c: f64) -> nalgebra::DMatrix<f64> {
    let g = nalgebra::DMatrix::<f64>::from_fn(m, m, |_, _| rng.range(-1.0, 1.0));
    let d = nalgebra::DVector::<f64>::from_fn(m, |_, _| rng.range(1.0, 2.0));
    let w = nalgebra::DMatrix::from_diagonal(&d) + &g * g.transpose() * (c / m as f64);
    (&w + w.transpose()) * 0.5
}

/// Checks `path` (from before α = 0 through it) halfway to its first event after α = 0
/// against the fixed-α solver started afresh there: one solution, with the same classes
/// and λ (to 1e-10 of the forces). Returns the fresh solver's state.
fn fresh_after_zero(
    path: &mut Path,
    problem: &Arc<Problem>,
    load: impl Fn() -> Load,
    ctx: &str,
) -> fricont::path::State {
    let next = path
        .events()
        .iter()
        .map(|e| e.alpha)
        .find(|&a| a > 1e-12)
        .unwrap_or(1.0);
    let at = 0.5 * next;
    let sols = path.solutions_at(at).expect("solutions_at");
    assert_eq!(sols.len(), 1, "{ctx}: one solution at {at}");
    let mut fresh = Path::new(problem.clone(), load(), PathOptions::window(at, 1.0)).unwrap();
    fresh.start(at, None).expect("fresh start");
    let want = fresh.start_state().expect("start state");
    assert_eq!(
        sols[0].state.classes, want.classes,
        "{ctx}: classes at {at}"
    );
    let scale = want.lambda_n.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for (a, b) in sols[0]
        .state
        .lambda_n
        .iter()
        .chain(&sols[0].state.lambda_t)
        .zip(want.lambda_n.iter().chain(&want.lambda_t))
    {
        assert!((a - b).abs() <= 1e-10 * scale, "{ctx}: λ {a} vs {b}");
    }
    want
}

/// A condensed problem whose `p` nodes (13 to 40: 2^p > 4096 neighbouring pieces) all
/// reach their friction cone's edge at α = 0 together: on the all-stick piece `d = 0`, so
/// `λ(α) = −W⁻¹ q(α)` whatever W, and `q(α) = −W (λ* + α y)` puts λ on the all-stick
/// piece with every node's λt at `−σ_i F λν_i` at α = 0 (σ_i = ±1, λν_i < 0) and inside
/// its cone before. W is random SPD and couples the nodes, so which of them slip after
/// α = 0 is the directional problem of that point (the path pivots on their classes, see
/// `Path::pivoted_classes`). Checked against the fixed-α solver started afresh at half
/// the way to the next event: the same classes and the same λ (1e-10 of the forces).
/// Every second problem is traced in double-double.
#[test]
fn many_nodes_reach_their_friction_limit_together() {
    use fricont::problem::ProblemBuilder;
    let mut mixed = 0;
    for seed in 0..10u64 {
        let mut rng = common::Rng::new(4000 + seed);
        let p = 13 + rng.int(0, 27);
        let m = 2 * p;
        let friction = rng.range(0.05, 0.6);
        // W = D + G Gᵀ / m: SPD, every node coupled to every other (entries about
        // 1/√m of the diagonal), near enough to diagonal for one solution at each α.
        let w = coupled_w(&mut rng, m, 2.0);
        let (mut lam0, mut y) = (vec![0.0; m], vec![0.0; m]);
        for i in 0..p {
            let (a, sigma) = (
                rng.range(1.0, 2.0),
                if rng.uniform() < 0.5 { 1.0 } else { -1.0 },
            );
            let yn = rng.range(-0.1, 0.1);
            lam0[i] = -a;
            lam0[p + i] = sigma * friction * a;
            y[i] = yn;
            // Inside the cone before α = 0: σ (λt + σ F λν) < 0 there, zero at 0.
            y[p + i] = sigma * (friction * yn.abs() + 10f64.powf(rng.range(-3.0, 0.0)));
        }
        let wl = |v: &[f64]| -> Vec<f64> {
            let x = &w * nalgebra::DVector::from_column_slice(v);
            x.iter().map(|v| -v).collect()
        };
        let load = || Load::affine(wl(&lam0), wl(&y)).unwrap();
        let wf = faer::Mat::<f64>::from_fn(m, m, |i, j| w[(i, j)]);
        // Every second problem in double-double (condensed input is otherwise traced in
        // double where W is well conditioned, as here).
        let mode = if seed % 2 == 0 {
            fricont::ExtendedPrecision::On
        } else {
            fricont::ExtendedPrecision::Auto
        };
        let problem = Arc::new(
            ProblemBuilder::condensed(wf)
                .extended_precision(mode)
                .friction_uniform(friction)
                .build()
                .expect("problem"),
        );
        let ctx = format!("seed {seed} (p = {p}, F = {friction:.3}, {mode:?})");
        compare(&ctx, problem.clone(), load, -friction, 1.0);
        // From α = −F: there every λt is still inside its cone on both sides.
        let mut path = run(&problem, load(), -friction, 1.0, false);
        assert_eq!(
            path.end_reason(),
            Some(&fricont::EndReason::Window),
            "{ctx}: end"
        );
        let at_zero = path
            .events()
            .iter()
            .filter(|e| e.alpha.abs() < 1e-12)
            .count();
        assert!(at_zero > 0, "{ctx}: no event at α = 0");
        assert!(
            path.events().iter().all(|e| e.alpha > -1e-12),
            "{ctx}: an event before α = 0"
        );
        let want = fresh_after_zero(&mut path, &problem, load, &ctx);
        // Whether the directional problem's answer is not the trivial one: some nodes
        // keep sticking.
        let slipping = want
            .classes
            .iter()
            .filter(|c| **c != fricont::Class::Stick)
            .count();
        eprintln!("{ctx}: {at_zero} events at 0, {slipping} of {p} slip after");
        mixed += usize::from(slipping > 0 && slipping < p);
    }
    assert!(
        mixed >= 5,
        "only {mixed} of 10 with nodes sticking and slipping after"
    );
}

/// `p` identical decoupled nodes: condensed W = I/2, F = 1/2.
fn decoupled_nodes(p: usize) -> Arc<Problem> {
    use fricont::problem::ProblemBuilder;
    let w = faer::Mat::<f64>::from_fn(2 * p, 2 * p, |i, j| if i == j { 0.5 } else { 0.0 });
    Arc::new(
        ProblemBuilder::condensed(w)
            .friction_uniform(0.5)
            .build()
            .expect("problem"),
    )
}

/// Twenty identical decoupled nodes (W = I/2, condensed), each pressed by
/// `q_ν = (1 − α)/2` and sheared by `q_t = 3/8`, with F = 1/2. By hand: they slip in +t
/// from α = 0 (stick would need |λt| = 3/4 ≤ F (1 − α)): `λν = α − 1`, `λt = F λν`,
/// `dt = 3/8 + λt/2 > 0`; at α = 1 every normal force reaches zero together while each
/// node still slides (`dt = 3/8`: slip+ or open fit, 2^20 neighbouring pieces), and after
/// it each is open with `dν = q_ν < 0`, `λ = 0`; backwards, they touch down together.
#[test]
fn identical_decoupled_nodes_lift_off_together() {
    let p = 20;
    let problem = decoupled_nodes(p);
    let load = || {
        let (mut q0, mut q1) = (vec![0.0; 2 * p], vec![0.0; 2 * p]);
        q0[..p].fill(0.5);
        q1[..p].fill(-0.5);
        q0[p..].fill(0.375);
        Load::affine(q0, q1).unwrap()
    };
    let mut path = run(&problem, load(), 0.0, 2.0, false);
    assert_eq!(path.end_reason(), Some(&fricont::EndReason::Window));
    let start = path.start_state().expect("start state");
    assert!(start.classes.iter().all(|c| *c == fricont::Class::SlipPlus));
    let ev = path.events();
    assert_eq!(ev.len(), p, "one event per node");
    for e in ev {
        assert!((e.alpha - 1.0).abs() <= 1e-15, "event at α = {}", e.alpha);
        assert_eq!(
            (e.from, e.to, e.fold, e.bifurcation),
            (fricont::Class::SlipPlus, fricont::Class::Open, false, false)
        );
    }
    // Backwards from α = 2 the open nodes touch down together, sliding.
    let back = run(&problem, load(), 2.0, 0.0, false);
    assert_eq!(back.end_reason(), Some(&fricont::EndReason::Window));
    assert_eq!(back.events().len(), p, "one event per node (backwards)");
    for e in back.events() {
        assert!((e.alpha - 1.0).abs() <= 1e-15, "event at α = {}", e.alpha);
        assert_eq!(
            (e.from, e.to),
            (fricont::Class::Open, fricont::Class::SlipPlus)
        );
    }
    let sols = path.solutions_at(1.5).expect("solutions_at");
    assert_eq!(sols.len(), 1);
    assert!(
        sols[0]
            .state
            .classes
            .iter()
            .all(|c| *c == fricont::Class::Open)
    );
    assert!(
        sols[0]
            .state
            .lambda_n
            .iter()
            .chain(&sols[0].state.lambda_t)
            .all(|v| *v == 0.0)
    );
}

/// Twenty identical decoupled nodes (W = I/2, condensed), each pressed by `q_ν = 1/2`
/// and sheared by `q_t = α/2`, with F = 1/2. By hand: on the all-stick piece `d = 0`
/// gives `λν = −1`, `λt = −α`, inside the cone (|λt| < −F λν) for α < 1/2; at α = 1/2
/// every node reaches `λt = F λν` together (2^20 neighbouring pieces), and after it each
/// slips in +t: `λν = −1`, `λt = F λν = −1/2`, `dt = α/2 − 1/4 > 0`. Under an affine, a
/// basis and a general load.
#[test]
fn identical_decoupled_nodes_slip_together() {
    let p = 20;
    let problem = decoupled_nodes(p);
    let (mut q0, mut q1) = (vec![0.0; 2 * p], vec![0.0; 2 * p]);
    q0[..p].fill(0.5);
    q1[p..].fill(0.5);
    // Every node stick → slip+ at `at`, the path to the window's end.
    let slip_together = |path: &Path, at: f64, tol: f64, what: &str| {
        assert_eq!(
            path.end_reason(),
            Some(&fricont::EndReason::Window),
            "{what}"
        );
        assert_eq!(path.events().len(), p, "one event per node ({what})");
        for e in path.events() {
            assert!(
                (e.alpha - at).abs() <= tol,
                "{what}: event at α = {} ({at})",
                e.alpha
            );
            assert_eq!(
                (e.from, e.to, e.fold, e.bifurcation),
                (
                    fricont::Class::Stick,
                    fricont::Class::SlipPlus,
                    false,
                    false
                ),
                "{what}"
            );
        }
    };
    let mut path = run(
        &problem,
        Load::affine(q0.clone(), q1.clone()).unwrap(),
        0.0,
        2.0,
        false,
    );
    slip_together(&path, 0.5, 1e-15, "affine load");
    let sols = path.solutions_at(1.0).expect("solutions_at");
    assert_eq!(sols.len(), 1);
    for i in 0..p {
        assert!((sols[0].state.lambda_n[i] + 1.0).abs() <= 1e-15);
        assert!((sols[0].state.lambda_t[i] + 0.5).abs() <= 1e-15);
    }
    // The same under the basis load `q0 + φ(α) q1`, φ(α) = α³ + α/4, and as a general
    // load: the nodes slip together where φ = 1/2, at the root of 4α³ + α − 2 (by
    // Newton here).
    let basis = Load::basis(
        vec![q0, q1],
        Box::new(
            |a: f64, w: &mut [f64], dw: &mut [f64]| -> Result<(), LoadFailure> {
                w[0] = 1.0;
                w[1] = a * a * a + 0.25 * a;
                dw[0] = 0.0;
                dw[1] = 3.0 * a * a + 0.25;
                Ok(())
            },
        ),
    )
    .unwrap();
    let mut root = 0.7f64;
    for _ in 0..60 {
        root -= (4.0 * root.powi(3) + root - 2.0) / (12.0 * root * root + 1.0);
    }
    let mut path = run(&problem, basis, 0.0, 2.0, false);
    slip_together(&path, root, 1e-13, "basis load");
    let sols = path.solutions_at(1.5).expect("solutions_at");
    for i in 0..p {
        assert!((sols[0].state.lambda_t[i] + 0.5).abs() <= 1e-14);
    }
    let general = Load::general(
        2 * p,
        Box::new(move |a: f64, out: &mut [f64]| -> Result<(), LoadFailure> {
            out[..p].fill(0.5);
            out[p..].fill(0.5 * (a * a * a + 0.25 * a));
            Ok(())
        }),
        None,
    );
    let path = run(&problem, general, 0.0, 2.0, false);
    slip_together(&path, root, 1e-13, "general load");
}

/// The nodes of [`identical_decoupled_nodes_slip_together`] (8 or 20, reaching
/// `λt = F λν` at α = 1/2) and three more that touch down at that α with no tangential
/// displacement (a zero-force vertex: `q_ν = (α − 1/2)/2`, `q_t = (α − 1/2)/10`). By hand:
/// the first slip in +t after it, the three stick (`λ = −2q`: `λν = 1/2 − α`,
/// `|λt| = |λν|/5 < F |λν|`). The vertex nodes take their classes from the directional
/// problem at each step of the pivot on the others (2^20 combinations of their classes are
/// beyond any enumeration; 2^8 = 256 are beyond the 64 enumerated with directional solves,
/// each solve started from the last one's solution).
#[test]
fn identical_nodes_slip_while_others_touch_down() {
    for pa in [8, 20] {
        let p = pa + 3;
        let problem = decoupled_nodes(p);
        let (mut q0, mut q1) = (vec![0.0; 2 * p], vec![0.0; 2 * p]);
        q0[..pa].fill(0.5);
        q1[p..p + pa].fill(0.5);
        q0[pa..p].fill(-0.25);
        q1[pa..p].fill(0.5);
        q0[p + pa..].fill(-0.05);
        q1[p + pa..].fill(0.1);
        let mut path = run(&problem, Load::affine(q0, q1).unwrap(), 0.0, 2.0, false);
        assert_eq!(path.end_reason(), Some(&fricont::EndReason::Window), "{pa}");
        assert_eq!(path.events().len(), p, "one event per node ({pa})");
        for e in path.events() {
            assert!((e.alpha - 0.5).abs() <= 1e-15, "event at α = {}", e.alpha);
            let want = if e.node < pa {
                (fricont::Class::Stick, fricont::Class::SlipPlus)
            } else {
                (fricont::Class::Open, fricont::Class::Stick)
            };
            assert_eq!((e.from, e.to), want, "node {} ({pa})", e.node);
        }
        let sols = path.solutions_at(1.0).expect("solutions_at");
        assert_eq!(sols.len(), 1);
        let st = &sols[0].state;
        for i in 0..p {
            let want = if i < pa { (-1.0, -0.5) } else { (-0.5, -0.1) };
            assert!(
                (st.lambda_n[i] - want.0).abs() <= 1e-15
                    && (st.lambda_t[i] - want.1).abs() <= 1e-15,
                "node {i} ({pa}): λ = ({}, {})",
                st.lambda_n[i],
                st.lambda_t[i]
            );
        }
    }
}

/// A coupled condensed problem (W random SPD) where at α = 0 six to eleven nodes reach the
/// zero-force vertex (sticking before, `λ = α y` with `yν > 0`), three to eight others reach
/// their friction cone's edge (as in [`many_nodes_reach_their_friction_limit_together`])
/// and the rest stick inside their cones: more than 4096 neighbouring pieces, so the
/// vertex nodes take their classes from the directional problem, for each of the 8 to 256
/// combinations of the others' classes (64 at most enumerated, each solve started from
/// the last one's solution; beyond, pivoting). Checked against the fixed-α solver started
/// afresh at half the way to the next event: the same classes and λ (1e-10 of the
/// forces), in double and in double-double.
#[test]
fn vertex_nodes_beside_nodes_at_their_friction_limit() {
    use fricont::problem::ProblemBuilder;
    for seed in 0..12u64 {
        let mut rng = common::Rng::new(9000 + seed);
        let nv = 6 + rng.int(0, 5);
        let ns = 3 + rng.int(0, 5);
        let p = nv + ns + rng.int(0, 20);
        let m = 2 * p;
        let friction = [0.1, 0.3, 0.6, 1.0, 3.0][rng.int(0, 4)];
        let coupling = rng.range(0.5, 4.0);
        let w = coupled_w(&mut rng, m, coupling);
        // On the all-stick piece d = 0 and λ(α) = λ* + α y, for q(α) = −W (λ* + α y).
        let (mut lam0, mut y) = (vec![0.0; m], vec![0.0; m]);
        for i in 0..p {
            if i < nv {
                // at the vertex at α = 0, inside the cone before
                y[i] = rng.range(0.5, 1.5);
                y[p + i] = rng.range(-1.0, 1.0) * friction * y[i];
            } else if i < nv + ns {
                // at the cone's edge at α = 0, inside before
                let (a, sigma) = (
                    rng.range(1.0, 2.0),
                    if rng.uniform() < 0.5 { 1.0 } else { -1.0 },
                );
                lam0[i] = -a;
                lam0[p + i] = sigma * friction * a;
                y[i] = rng.range(-0.1, 0.1);
                y[p + i] = sigma * (friction * y[i].abs() + 10f64.powf(rng.range(-3.0, 0.0)));
            } else {
                let a = rng.range(1.0, 2.0);
                lam0[i] = -a;
                lam0[p + i] = rng.range(-0.5, 0.5) * friction * a;
                y[i] = rng.range(-0.1, 0.1);
                y[p + i] = rng.range(-0.1, 0.1) * friction;
            }
        }
        let wl = |v: &[f64]| -> Vec<f64> {
            let x = &w * nalgebra::DVector::from_column_slice(v);
            x.iter().map(|v| -v).collect()
        };
        let load = || Load::affine(wl(&lam0), wl(&y)).unwrap();
        let wf = faer::Mat::<f64>::from_fn(m, m, |i, j| w[(i, j)]);
        for mode in [
            fricont::ExtendedPrecision::Off,
            fricont::ExtendedPrecision::On,
        ] {
            let problem = Arc::new(
                ProblemBuilder::condensed(wf.clone())
                    .extended_precision(mode)
                    .friction_uniform(friction)
                    .build()
                    .expect("problem"),
            );
            let ctx = format!(
                "seed {seed} (p = {p}, {nv} at the vertex, {ns} at the edge, F = {friction}, {mode:?})"
            );
            // From before α = 0, where every node sticks inside its cone.
            let a0 = -0.2 * friction.min(1.0);
            let mut path = run(&problem, load(), a0, 1.0, false);
            assert_eq!(
                path.end_reason(),
                Some(&fricont::EndReason::Window),
                "{ctx}: end"
            );
            let at_zero = path.events().iter().filter(|e| e.alpha.abs() < 1e-12);
            assert!(
                at_zero.count() >= nv,
                "{ctx}: the vertex nodes' events at α = 0"
            );
            fresh_after_zero(&mut path, &problem, load, &ctx);
        }
    }
}
