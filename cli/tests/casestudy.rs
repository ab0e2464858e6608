//! The case study end to end:
//!
//! * the printed transition list (the text the CLI prints, also in `transitions.txt`)
//!   agrees with tracing the generated files read back through the exchange format:
//!   same events, α to 1e-12;
//! * every reported point is checked against the contact conditions computed directly
//!   from `A`, `f`, `N`, `T` (an independent check, not the tracer's own residual);
//! * the profiles of Figure 3 ("the cheap solution at any α") agree with the fixed-α
//!   solver started afresh at those α (a different algorithm);
//! * the high-friction variant has a fold, and the several solutions it reports at one α
//!   are distinct genuine solutions.

use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;

use fricont::path::{Path, PathOptions, State};
use fricont::{Class, EndReason};
use fricont_cli::casestudy::{CaseStudyOptions, CaseStudyReport, run};
use fricont_exchange::generator::{RectSpec, generate};
use fricont_exchange::io::CaseData;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fricont-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// One line of the printed table, parsed back from the text.
#[derive(Debug)]
struct Printed {
    transition: usize,
    alpha: f64,
    node: usize,
    from: String,
    to: String,
    fold: bool,
}

/// Parses "at transition point K, α = A, contact node N changes from X to Y[ (±x)][; fold…]".
fn parse_table(text: &str) -> Vec<Printed> {
    let mut out = Vec::new();
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("at transition point ") else {
            continue;
        };
        let (k, rest) = rest.split_once(", α = ").unwrap();
        let (a, rest) = rest.split_once(", contact node ").unwrap();
        let (node, rest) = rest.split_once(" changes from ").unwrap();
        let (classes, flags) = rest.split_once(';').unwrap_or((rest, ""));
        let classes = classes.replace(" (+x)", "").replace(" (−x)", "");
        let (from, to) = classes.split_once(" to ").unwrap();
        out.push(Printed {
            transition: k.parse().unwrap(),
            alpha: a.parse().unwrap(),
            node: node.parse().unwrap(),
            from: from.to_string(),
            to: to.to_string(),
            fold: flags.contains("fold"),
        });
    }
    out
}

/// Traces a problem directory as `fricont trace` does: read, build, start at the window's
/// start, run.
fn trace_dir(dir: &FsPath) -> (CaseData, Path) {
    let case = CaseData::read_dir(dir).unwrap();
    let problem = Arc::new(case.problem(None).unwrap());
    let mut path = Path::new(
        problem,
        case.load().unwrap(),
        PathOptions::window(case.alpha_start, case.alpha_end),
    )
    .unwrap();
    path.start(case.alpha_start, None).unwrap();
    assert_eq!(path.run().unwrap(), EndReason::Window);
    (case, path)
}

fn assert_same_events(printed: &[Printed], path: &Path, what: &str) {
    let ev = path.events();
    assert_eq!(printed.len(), ev.len(), "{what}: number of events");
    for (p, e) in printed.iter().zip(ev) {
        assert_eq!(p.transition, e.transition + 1, "{what}");
        assert_eq!(p.node, e.node + 1, "{what}: transition {}", p.transition);
        assert_eq!(
            p.from,
            e.from.words(),
            "{what}: transition {}",
            p.transition
        );
        assert_eq!(p.to, e.to.words(), "{what}: transition {}", p.transition);
        assert_eq!(p.fold, e.fold, "{what}: transition {}", p.transition);
        assert!(
            (p.alpha - e.alpha).abs() <= 1e-12,
            "{what}: transition {}: printed α = {} but the files give {}",
            p.transition,
            p.alpha,
            e.alpha
        );
    }
}

/// Checks the contact conditions of a state directly from the data (independent of the
/// tracer's pieces and residual): equilibrium `A u = f(α) + Nᵀλν + Tᵀλt`, `N u ≤ g`,
/// `λν ≤ 0`, complementarity, Coulomb's cone and the direction of slip.
fn check_state(case: &CaseData, s: &State, what: &str) {
    let n = case.n();
    let p = case.p();
    let friction = |i: usize| case.friction[if case.friction.len() == 1 { 0 } else { i }];
    let mut r = vec![0.0; n];
    case.a.mul_vec(&s.u, &mut r);
    let mut rhs: Vec<f64> = (0..n).map(|k| case.f0[k] + s.alpha * case.f1[k]).collect();
    case.n_mat.mul_t_vec_add(&s.lambda_n, &mut rhs);
    case.t_mat.mul_t_vec_add(&s.lambda_t, &mut rhs);
    let fscale = rhs
        .iter()
        .chain(&case.f0)
        .chain(&case.f1)
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 0..n {
        assert!(
            (r[k] - rhs[k]).abs() <= 1e-9 * fscale,
            "{what}: equilibrium at dof {k}: {} vs {}",
            r[k],
            rhs[k]
        );
    }
    let mut un = vec![0.0; p];
    let mut ut = vec![0.0; p];
    case.n_mat.mul_vec(&s.u, &mut un);
    case.t_mat.mul_vec(&s.u, &mut ut);
    let uscale = s.u.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    let (ut_tol, un_tol, l_tol) = (1e-9 * uscale, 1e-9 * uscale, 1e-9 * fscale);
    let gap = |i: usize| case.gap.as_ref().map_or(0.0, |g| g[i]);
    for i in 0..p {
        let (ln, lt, f) = (s.lambda_n[i], s.lambda_t[i], friction(i));
        let d = un[i] - gap(i);
        assert!(d <= un_tol, "{what}: node {} penetrates: {d}", i + 1);
        assert!(ln <= l_tol, "{what}: node {} pulls: λν = {ln}", i + 1);
        assert!(
            (ln * d).abs() <= l_tol * un_tol.max(d.abs()) + un_tol * ln.abs(),
            "{what}: node {} complementarity λν = {ln}, N u − g = {d}",
            i + 1
        );
        assert!(
            lt.abs() <= -f * ln + l_tol,
            "{what}: node {} outside Coulomb's cone: λt = {lt}, F λν = {}",
            i + 1,
            f * ln
        );
        if ut[i].abs() > ut_tol {
            // slipping: friction at the bound, opposing the slip (λt = F λν sign(T u))
            assert!(
                (lt - f * ln * ut[i].signum()).abs() <= l_tol,
                "{what}: node {} slips (T u = {}) but λt = {lt}, F λν = {}",
                i + 1,
                ut[i],
                f * ln
            );
        }
        // the class reported agrees with the data
        match s.classes[i] {
            Class::Open => assert!(ln.abs() <= l_tol && lt.abs() <= l_tol),
            Class::Stick => assert!(ut[i].abs() <= ut_tol && d.abs() <= un_tol),
            Class::SlipPlus => assert!(ut[i] >= -ut_tol && d.abs() <= un_tol),
            Class::SlipMinus => assert!(ut[i] <= ut_tol && d.abs() <= un_tol),
        }
    }
}

fn run_case_study(name: &str) -> (PathBuf, CaseStudyReport) {
    let out = tmp(name);
    let report = run(&CaseStudyOptions::new(&out)).unwrap();
    (out, report)
}

#[test]
fn printed_transitions_agree_with_tracing_the_files_read_back() {
    let (out, report) = run_case_study("cs-agree");
    // the text written is the text printed
    let written = std::fs::read_to_string(out.join("transitions.txt")).unwrap();
    assert_eq!(written, report.table);
    let printed = parse_table(&report.table);
    assert_eq!(printed.len(), report.transitions.len());
    let (case, path) = trace_dir(&out.join("problem"));
    assert_same_events(&printed, &path, "case study");
    assert_eq!(case.n(), 1320);
    assert_eq!(case.p(), 30);
    for k in 0..path.events().len() {
        let st = path.event_state(k).unwrap();
        check_state(&case, &st, &format!("event {}", k + 1));
    }
    // the high-friction variant too
    let fold = report.fold.as_ref().unwrap();
    let hf = out.join("high-friction");
    let written = std::fs::read_to_string(hf.join("transitions.txt")).unwrap();
    assert_eq!(written, fold.table);
    let (case, path) = trace_dir(&hf.join("problem"));
    assert_same_events(&parse_table(&fold.table), &path, "high-friction variant");
    for k in 0..path.events().len() {
        let st = path.event_state(k).unwrap();
        check_state(&case, &st, &format!("variant event {}", k + 1));
    }
    // the figures and data files are where the report says
    for f in [
        "fig1_mesh.svg",
        "fig2_snapshot.svg",
        "fig3_profiles.svg",
        "fig4_path.svg",
        "path.json",
        "path.csv",
        "events.csv",
        "high-friction/path.svg",
        "high-friction/solutions.svg",
    ] {
        assert!(report.files.contains(&out.join(f)), "{f} not reported");
        assert!(std::fs::metadata(out.join(f)).unwrap().len() > 100, "{f}");
    }
    // the JSON lists the same events
    let js: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("path.json")).unwrap()).unwrap();
    let jev = js["events"].as_array().unwrap();
    assert_eq!(jev.len(), printed.len());
    for (j, p) in jev.iter().zip(&printed) {
        assert_eq!(j["node"].as_u64().unwrap() as usize, p.node);
        assert!((j["alpha"].as_f64().unwrap() - p.alpha).abs() <= 1e-12);
    }
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn printed_transitions_agree_with_the_fricont_trace_binary() {
    // The acceptance criterion literally: `fricont trace DIR --json FILE` on the files the
    // case study wrote gives the events it printed.
    let out = tmp("cs-binary");
    let mut opts = CaseStudyOptions::new(&out);
    opts.profile_alphas = vec![0.0];
    let report = run(&opts).unwrap();
    for (dir, table) in [
        (out.join("problem"), report.table.clone()),
        (
            out.join("high-friction").join("problem"),
            report.fold.as_ref().unwrap().table.clone(),
        ),
    ] {
        let json = out.join("trace.json");
        let st = std::process::Command::new(env!("CARGO_BIN_EXE_fricont"))
            .arg("trace")
            .arg(&dir)
            .arg("--json")
            .arg(&json)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{}",
            String::from_utf8_lossy(&st.stderr)
        );
        let js: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let ev = js["events"].as_array().unwrap();
        let printed = parse_table(&table);
        assert_eq!(ev.len(), printed.len(), "{}", dir.display());
        for (j, p) in ev.iter().zip(&printed) {
            assert_eq!(j["node"].as_u64().unwrap() as usize, p.node);
            let words = |name: &str| Class::from_name(name).unwrap().words();
            assert_eq!(words(j["from"].as_str().unwrap()), p.from);
            assert_eq!(words(j["to"].as_str().unwrap()), p.to);
            assert_eq!(j["fold"].as_bool().unwrap(), p.fold);
            let a = j["alpha"].as_f64().unwrap();
            assert!(
                (a - p.alpha).abs() <= 1e-12,
                "{}: transition {}: printed {} vs fricont trace {a}",
                dir.display(),
                p.transition,
                p.alpha
            );
        }
        assert_eq!(js["end"]["reason"], "window");
    }
    assert_eq!(report.snapshot_alpha, 3.6, "Figure 2 shows the paper's α");
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn the_reconstruction_shows_the_papers_kinds_of_transitions() {
    // The claims of docs/case-study.md about the default reconstruction.
    let spec = RectSpec::default();
    let case = generate(&spec).unwrap();
    let problem = Arc::new(case.problem(None).unwrap());
    let mut path = Path::new(
        problem,
        case.load().unwrap(),
        PathOptions::window(-0.5, 1.5),
    )
    .unwrap();
    path.start(-0.5, None).unwrap();
    path.run().unwrap();
    let ev = path.events();
    let transitions = ev.last().unwrap().transition + 1;
    assert!(
        (12..=16).contains(&transitions),
        "about 14 transition points, got {transitions}"
    );
    let has = |from: fn(Class) -> bool, to: fn(Class) -> bool| {
        ev.iter().any(|e| from(e.from) && to(e.to))
    };
    let slip = |c: Class| matches!(c, Class::SlipPlus | Class::SlipMinus);
    assert!(has(|c| c == Class::Open, slip), "no contact → slip");
    assert!(has(slip, |c| c == Class::Stick), "slip → stick");
    assert!(!ev.iter().any(|e| e.fold), "F = 0.3: no fold expected");
}

#[test]
fn cheap_solutions_at_any_alpha_agree_with_a_fresh_fixed_alpha_solve() {
    let spec = RectSpec::default();
    let case = generate(&spec).unwrap();
    let problem = Arc::new(case.problem(None).unwrap());
    // the window of Figure 2's extended path (the paper's snapshot is at α = 3.6)
    let mut path = Path::new(
        problem.clone(),
        case.load().unwrap(),
        PathOptions::window(-0.5, 3.7),
    )
    .unwrap();
    path.start(-0.5, None).unwrap();
    path.run().unwrap();
    for alpha in [-0.5, -0.1234, 0.0, 0.5, 1.0, 1.37, 1.5, 3.6] {
        let sols = path.solutions_at(alpha).unwrap();
        assert_eq!(sols.len(), 1, "α = {alpha}: F = 0.3 has one solution");
        let s = &sols[0].state;
        check_state(&case, s, &format!("solution at α = {alpha}"));
        // a different algorithm: the fixed-α solver from zero forces
        let mut fresh = Path::new(
            problem.clone(),
            case.load().unwrap(),
            PathOptions::window(alpha, if alpha < 3.7 { 3.7 } else { -0.5 }),
        )
        .unwrap();
        fresh.start(alpha, None).unwrap();
        let f = fresh.start_state().unwrap();
        let scale = f.lambda_n.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..case.p() {
            assert!(
                (f.lambda_n[i] - s.lambda_n[i]).abs() <= 1e-9 * scale
                    && (f.lambda_t[i] - s.lambda_t[i]).abs() <= 1e-9 * scale,
                "α = {alpha}, node {}: path ({}, {}) vs fresh solve ({}, {})",
                i + 1,
                s.lambda_n[i],
                s.lambda_t[i],
                f.lambda_n[i],
                f.lambda_t[i]
            );
        }
    }
}

#[test]
fn high_friction_variant_folds_and_its_solutions_are_distinct_and_genuine() {
    let spec = RectSpec::high_friction();
    assert!(spec.friction >= 0.9);
    let case = generate(&spec).unwrap();
    let problem = Arc::new(case.problem(None).unwrap());
    let mut path = Path::new(
        problem,
        case.load().unwrap(),
        PathOptions::window(spec.alpha_start, spec.alpha_end),
    )
    .unwrap();
    path.start(spec.alpha_start, None).unwrap();
    assert_eq!(path.run().unwrap(), EndReason::Window);
    let folds: Vec<f64> = path
        .events()
        .iter()
        .filter(|e| e.fold)
        .map(|e| e.alpha)
        .collect();
    assert!(!folds.is_empty(), "the variant must fold");
    // just past the first fold (towards where α came from) there are at least two
    // solutions: the path went through that α before the fold and after it
    let first = path.events().iter().find(|e| e.fold).unwrap();
    let k = first.index;
    let before = path.events()[..k]
        .iter()
        .rev()
        .find(|e| e.alpha != first.alpha)
        .map_or(spec.alpha_start, |e| e.alpha);
    let after = path.events()[k + 1..]
        .iter()
        .find(|e| e.alpha != first.alpha)
        .unwrap()
        .alpha;
    let near = if (before - first.alpha).abs() < (after - first.alpha).abs() {
        before
    } else {
        after
    };
    let alpha = 0.5 * (first.alpha + near);
    let sols = path.solutions_at(alpha).unwrap();
    assert!(sols.len() >= 2, "α = {alpha}: {} solutions", sols.len());
    for (a, s) in sols.iter().enumerate() {
        check_state(
            &case,
            &s.state,
            &format!("solution {} at α = {alpha}", a + 1),
        );
        for t in &sols[..a] {
            let diff = s
                .state
                .u
                .iter()
                .zip(&t.state.u)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            let scale = s.state.u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(diff > 1e-6 * scale, "two reported solutions coincide");
        }
    }
    // and the case study reports the same fold region
    let out = tmp("cs-fold");
    let mut opts = CaseStudyOptions::new(&out);
    opts.profile_alphas = vec![0.0];
    let rep = run(&opts).unwrap();
    let fr = rep.fold.unwrap();
    assert_eq!(fr.folds, folds.len());
    assert!(fr.solutions >= 2);
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn case_study_transitions_do_not_depend_on_r() {
    // SPEC §1: solutions and transition points do not depend on the augmentation r.
    for spec in [RectSpec::default(), RectSpec::high_friction()] {
        let case = generate(&spec).unwrap();
        let r0 = case.problem(None).unwrap().default_r();
        let mut runs = Vec::new();
        for r in [r0, 1e-3 * r0, 1e3 * r0] {
            let problem = Arc::new(case.problem(Some(r)).unwrap());
            let mut path = Path::new(
                problem,
                case.load().unwrap(),
                PathOptions::window(spec.alpha_start, spec.alpha_end),
            )
            .unwrap();
            path.start(spec.alpha_start, None).unwrap();
            path.run().unwrap();
            runs.push(path.events().to_vec());
        }
        for other in &runs[1..] {
            assert_eq!(other.len(), runs[0].len(), "{}", spec.load_name);
            for (a, b) in runs[0].iter().zip(other) {
                assert_eq!(
                    (a.node, a.from, a.to, a.fold),
                    (b.node, b.from, b.to, b.fold)
                );
                assert!(
                    (a.alpha - b.alpha).abs() <= 1e-12,
                    "{} vs {}",
                    a.alpha,
                    b.alpha
                );
            }
        }
    }
}
