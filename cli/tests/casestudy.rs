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
//!   are distinct genuine solutions;
//! * the figures are fit for print (text size at 16 cm, a PNG beside each SVG, legends
//!   off the data and only for what is drawn, a zoom that contains what it zooms on);
//! * the numbers quoted in `docs/case-study.md` and the README are the computed ones.

use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;

use fricont::path::{Path, PathOptions, State};
use fricont::{Class, EndReason};
use fricont_cli::casestudy::{CaseStudyOptions, CaseStudyReport, PxRect, run};
use fricont_exchange::generator::{RectSpec, generate};
use fricont_exchange::io::CaseData;
use fricont_exchange::report::fmt_alpha;

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

/// 8 pt when printed 16 cm wide, as a fraction of the figure's width (from the print
/// rule itself, not from the code's constants).
const MIN_FONT_FRACTION: f64 = 8.0 / 72.0 / (16.0 / 2.54);
/// 16 cm at 300 dpi.
const PNG_WIDTH: u32 = 1890;

fn svg_files(dir: &FsPath, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            svg_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "svg") {
            out.push(p);
        }
    }
}

/// The value of attribute `name` in an XML start tag.
fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    Some(tag[start..].split('"').next()?.to_string())
}

/// The start tags `<name …>` of an SVG text.
fn tags<'a>(svg: &'a str, name: &str) -> Vec<&'a str> {
    let open = format!("<{name} ");
    svg.match_indices(&open)
        .map(|(i, _)| &svg[i..i + svg[i..].find('>').unwrap()])
        .collect()
}

/// All text of the SVG's `<text>` elements, in order, joined by spaces.
fn svg_text(svg: &str) -> String {
    svg.split("<text ")
        .skip(1)
        .map(|t| t[t.find('>').unwrap() + 1..t.find("</text>").unwrap()].trim())
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn figures_are_fit_for_print() {
    let (out, report) = run_case_study("cs-print");
    let mut svgs = Vec::new();
    svg_files(&out, &mut svgs);
    svgs.sort();
    let mut reported: Vec<PathBuf> = report.figures.iter().map(|f| f.svg.clone()).collect();
    reported.sort();
    assert_eq!(svgs, reported, "every SVG written is a reported figure");
    assert_eq!(
        svgs.len(),
        7,
        "4 figures and 3 of the high-friction variant"
    );
    for svg in &svgs {
        let name = svg.strip_prefix(&out).unwrap().display().to_string();
        let text = std::fs::read_to_string(svg).unwrap();
        let root = tags(&text, "svg")[0];
        let w: f64 = attr(root, "width").unwrap().parse().unwrap();
        let h: f64 = attr(root, "height").unwrap().parse().unwrap();
        // every text at least 8 pt at 16 cm
        let texts = tags(&text, "text");
        assert!(texts.len() > 5, "{name}: {} texts", texts.len());
        for t in &texts {
            let size: f64 = attr(t, "font-size")
                .unwrap_or_else(|| panic!("{name}: a text without font-size: {t}"))
                .parse()
                .unwrap();
            assert!(
                size >= MIN_FONT_FRACTION * w,
                "{name}: font-size {size} px < 8 pt at 16 cm ({} px of {w})",
                MIN_FONT_FRACTION * w
            );
        }
        // the PNG beside it: 16 cm at 300 dpi, the SVG's proportions, text drawn
        let png = svg.with_extension("png");
        let dec = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(&png).unwrap_or_else(|e| panic!("{name}: no PNG beside it: {e}")),
        ));
        let mut reader = dec.read_info().unwrap();
        let info = reader.info().clone();
        assert_eq!(info.width, PNG_WIDTH, "{name}");
        let expect_h = h * f64::from(PNG_WIDTH) / w;
        assert!(
            (f64::from(info.height) - expect_h).abs() <= 1.0,
            "{name}: PNG height {} for {expect_h}",
            info.height
        );
        let dims = info.pixel_dims.expect("pHYs");
        assert_eq!(dims.unit, png::Unit::Meter);
        assert_eq!((dims.xppu, dims.yppu), (11811, 11811), "{name}: 300 dpi");
        assert_eq!(info.color_type, png::ColorType::Rgb, "{name}");
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut buf).unwrap();
        // the title (only text) occupies the top 3.5 % of the width: it must be drawn
        let band = (0.035 * f64::from(PNG_WIDTH)) as usize;
        let row = 3 * PNG_WIDTH as usize;
        let dark = buf[..band * row]
            .chunks(3)
            .filter(|p| p.iter().all(|&c| c < 100))
            .count();
        assert!(
            dark > 500,
            "{name}: the title is not drawn ({dark} dark pixels)"
        );
        let white = buf
            .chunks(3)
            .filter(|p| p.iter().all(|&c| c == 255))
            .count();
        assert!(white > buf.len() / 3 / 2, "{name}: background not white");
    }
    for fig in &report.figures {
        let name = fig.svg.strip_prefix(&out).unwrap().display().to_string();
        let l = &fig.layout;
        let text = std::fs::read_to_string(&fig.svg).unwrap();
        let root = tags(&text, "svg")[0];
        assert_eq!(attr(root, "width").unwrap(), l.width.to_string(), "{name}");
        assert_eq!(
            attr(root, "height").unwrap(),
            l.height.to_string(),
            "{name}"
        );
        assert!(!l.plots.is_empty() && !l.data.is_empty() && !l.legends.is_empty());
        let canvas = PxRect {
            x0: 0.0,
            y0: 0.0,
            x1: f64::from(l.width),
            y1: f64::from(l.height),
        };
        for (k, g) in l.legends.iter().enumerate() {
            assert!(canvas.contains(g), "{name}: legend {g:?} off the canvas");
            for p in &l.plots {
                assert!(!g.intersects(p), "{name}: legend {g:?} over the plot {p:?}");
            }
            for d in &l.data {
                assert!(!g.intersects(d), "{name}: legend {g:?} over data at {d:?}");
            }
            for o in &l.legends[k + 1..] {
                assert!(!g.intersects(o), "{name}: legends {g:?} and {o:?} overlap");
            }
        }
        for d in &l.data {
            assert!(
                l.plots.iter().any(|p| p.contains(d)),
                "{name}: data at {d:?} outside every plot area"
            );
        }
        for e in &l.legend_entries {
            assert!(
                l.drawn_count(e) > 0,
                "{name}: legend entry {e:?} for nothing drawn"
            );
            assert!(
                text.contains(e.as_str()),
                "{name}: entry {e:?} not in the SVG"
            );
        }
        for (label, n) in &l.drawn {
            assert!(
                *n == 0 || l.legend_entries.contains(label),
                "{name}: {label:?} drawn but not in the legend"
            );
        }
    }
    let fig = |f: &str| {
        report
            .figures
            .iter()
            .find(|x| x.svg == out.join(f))
            .unwrap_or_else(|| panic!("{f}"))
    };
    // the main path has no fold: no fold entry; the variant's has
    assert!(!report.transitions.iter().any(|t| t.fold));
    let fold_entry = |f: &str| {
        fig(f)
            .layout
            .legend_entries
            .iter()
            .any(|e| e.contains("fold"))
    };
    assert!(
        !fold_entry("fig4_path.svg"),
        "a fold entry where there is no fold"
    );
    assert!(fold_entry("high-friction/path.svg"));
    assert!(fold_entry("high-friction/path_folds.svg"));

    // Figure 2: its class entries are the classes of a fresh solve at α = 3.6, and every
    // marker (the legend's too) has the data's colour
    let spec = RectSpec::default();
    let case = generate(&spec).unwrap();
    let problem = Arc::new(case.problem(None).unwrap());
    let mut fresh = Path::new(
        problem,
        case.load().unwrap(),
        PathOptions::window(3.6, -0.5),
    )
    .unwrap();
    fresh.start(3.6, None).unwrap();
    let classes = &fresh.start_state().unwrap().classes;
    let label = |c: Class| match c {
        Class::Open => "no contact",
        Class::Stick => "contact, stick",
        Class::SlipPlus => "contact, slip +x",
        Class::SlipMinus => "contact, slip −x",
    };
    let mut expected: Vec<&str> = Class::ALL
        .iter()
        .filter(|c| classes.contains(c))
        .map(|&c| label(c))
        .collect();
    expected.sort_unstable();
    let mut entries: Vec<&str> = fig("fig2_snapshot.svg")
        .layout
        .legend_entries
        .iter()
        .map(String::as_str)
        .collect();
    entries.sort_unstable();
    assert_eq!(entries, expected, "Figure 2's legend");
    let svg2 = std::fs::read_to_string(out.join("fig2_snapshot.svg")).unwrap();
    let mut markers = 0;
    for name in ["circle", "polygon", "rect"] {
        for t in tags(&svg2, name) {
            let colours: Vec<String> = ["fill", "stroke"]
                .iter()
                .filter_map(|a| attr(t, a))
                .filter(|c| c != "none")
                .collect();
            if colours == ["#FFFFFF"] {
                continue; // the background
            }
            markers += 1;
            assert!(
                colours.iter().all(|c| c == "#1F77B4"),
                "Figure 2: a marker in {colours:?}: {t}"
            );
        }
    }
    // 4 panels × 30 nodes, and one legend marker per entry
    assert_eq!(markers, 4 * 30 + expected.len());

    // the zoom on the folds contains every α with the most solutions and the folds
    // next to them, away from its edges, and names exactly the folds it contains
    let fr = report.fold.as_ref().unwrap();
    let (lo, hi) = fr.zoom.expect("a zoom");
    let hf = RectSpec::high_friction();
    assert!(
        hi - lo < 0.1 * (hf.alpha_end - hf.alpha_start),
        "not a zoom: [{lo}, {hi}]"
    );
    assert_eq!(
        fig("high-friction/path_folds.svg").layout.alpha_axis,
        Some((lo, hi)),
        "the zoom's α axis"
    );
    let (_, mut path) = trace_dir(&out.join("high-friction").join("problem"));
    let mut alphas: Vec<f64> = path.events().iter().map(|e| e.alpha).collect();
    alphas.extend([hf.alpha_start, hf.alpha_end]);
    alphas.sort_by(f64::total_cmp);
    alphas.dedup();
    let counted: Vec<(f64, usize)> = alphas
        .windows(2)
        .map(|w| 0.5 * (w[0] + w[1]))
        .map(|a| (a, path.solutions_at(a).unwrap().len()))
        .collect();
    let most = counted.iter().map(|c| c.1).max().unwrap();
    assert!(most >= 3, "{most}");
    for &(a, c) in &counted {
        if c == most {
            assert!(
                (lo..=hi).contains(&a),
                "α = {a} has {c} solutions, outside the zoom"
            );
        }
    }
    // and it is a zoom on that range: the range fills most of it
    let (mut ra, mut rb) = (f64::INFINITY, f64::NEG_INFINITY);
    for (w, c) in alphas.windows(2).zip(&counted) {
        if c.1 == most {
            ra = ra.min(w[0]);
            rb = rb.max(w[1]);
        }
    }
    assert!(
        rb - ra >= 0.5 * (hi - lo),
        "the range with {most} solutions, [{ra}, {rb}], is lost in the zoom [{lo}, {hi}]"
    );
    assert!((lo..=hi).contains(&fr.alpha_query.unwrap()));
    let inside: Vec<usize> = fr
        .transitions
        .iter()
        .filter(|t| t.fold && (lo..=hi).contains(&t.alpha))
        .map(|t| t.transition)
        .collect();
    assert!(inside.len() >= 2, "{inside:?}");
    for t in fr.transitions.iter().filter(|t| t.fold) {
        if (lo..=hi).contains(&t.alpha) {
            let edge = (t.alpha - lo).min(hi - t.alpha);
            assert!(
                edge >= 0.05 * (hi - lo),
                "fold {} on the zoom's edge",
                t.transition
            );
        }
    }
    let title =
        svg_text(&std::fs::read_to_string(out.join("high-friction/path_folds.svg")).unwrap());
    let named: Vec<usize> = title
        .split("folds ")
        .nth(1)
        .unwrap()
        .split(|c: char| !c.is_ascii_digit() && c != ',' && c != ' ')
        .next()
        .unwrap()
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    assert_eq!(named, inside, "the zoom's title: {title}");
    std::fs::remove_dir_all(&out).unwrap();
}

/// Collapses every run of whitespace to one space.
fn squash(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A text as characters and numbers: a number of 7 or more digits is one token, so that
/// texts can be compared with numbers to the precision the data determine them (the
/// last of 14 printed digits depends on the order of the arithmetic).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Tok {
    Char(char),
    Num(f64),
}

fn tokens(s: &str) -> Vec<Tok> {
    let cs: Vec<char> = s.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < cs.len() {
        let start = i;
        let mut j = i;
        if cs[j] == '-' && j + 1 < cs.len() && cs[j + 1].is_ascii_digit() {
            j += 1;
        }
        if j < cs.len() && cs[j].is_ascii_digit() && (start == 0 || !cs[start - 1].is_ascii_digit())
        {
            while j < cs.len() && (cs[j].is_ascii_digit() || cs[j] == '.') {
                j += 1;
            }
            let word: String = cs[start..j].iter().collect();
            let word = word.trim_end_matches('.');
            let digits = word.chars().filter(char::is_ascii_digit).count();
            if digits >= 7
                && let Ok(v) = word.parse::<f64>()
            {
                out.push(Tok::Num(v));
                i = start + word.chars().count();
                continue;
            }
        }
        out.push(Tok::Char(cs[i]));
        i += 1;
    }
    out
}

/// Equal tokens; numbers to 1e-10 relative.
fn same_tok(a: &Tok, b: &Tok) -> bool {
    match (a, b) {
        (Tok::Num(x), Tok::Num(y)) => (x - y).abs() <= 1e-10 * x.abs().max(y.abs()).max(1.0),
        _ => a == b,
    }
}

fn same_text(a: &str, b: &str) -> bool {
    let (ta, tb) = (tokens(a), tokens(b));
    ta.len() == tb.len() && ta.iter().zip(&tb).all(|(x, y)| same_tok(x, y))
}

fn contains_text(hay: &str, needle: &str) -> bool {
    let (h, n) = (tokens(hay), tokens(needle));
    n.is_empty()
        || h.windows(n.len())
            .any(|w| w.iter().zip(&n).all(|(x, y)| same_tok(x, y)))
}

#[test]
fn documented_numbers_are_the_computed_ones() {
    let (out, report) = run_case_study("cs-docs");
    let repo = FsPath::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let doc = std::fs::read_to_string(repo.join("docs/case-study.md")).unwrap();
    let readme = std::fs::read_to_string(repo.join("README.md")).unwrap();
    // the table of docs/case-study.md is the one printed, line for line
    let table = |s: &str| -> Vec<String> {
        s.lines()
            .map(str::trim)
            .filter(|l| l.starts_with("at transition point "))
            .map(String::from)
            .collect()
    };
    let (dt, rt) = (table(&doc), table(&report.table));
    assert!(
        dt.len() == rt.len() && dt.iter().zip(&rt).all(|(a, b)| same_text(a, b)),
        "docs/case-study.md's table is not the output of `fricont case-study` (α to 1e-10):\n{}",
        rt.join("\n")
    );
    // every other number quoted, to its printed digits
    let main = |k: usize| {
        let t = &report.transitions[k - 1];
        assert_eq!(t.transition, k);
        t.alpha
    };
    let fr = report.fold.as_ref().unwrap();
    let hf = |k: usize| {
        let t = fr.transitions.iter().find(|t| t.transition == k).unwrap();
        assert!(t.fold, "transition {k} is quoted as a fold");
        t.alpha
    };
    let query = fr.alpha_query.unwrap();
    let folds = fr.transitions.iter().filter(|t| t.fold).count();
    let quotes_doc = [
        format!("({:.3}, {:.3}, {:.3} against", main(6), main(7), main(8)),
        format!("transition point 29 (α = {})", fmt_alpha(hf(29))),
        format!("α = {} (transition 30, a second fold)", fmt_alpha(hf(30))),
        format!("until {} (transition 38)", fmt_alpha(hf(38))),
        format!("until {} (transition 46)", fmt_alpha(hf(46))),
        format!("{folds} folds in all"),
        format!("On ({:.4}, {:.4})", hf(46), hf(38)),
        format!("(α = {})", fmt_alpha(query)),
        format!("all **{} solutions**", fr.solutions),
    ];
    let quotes_readme = [
        format!(
            "at α = {:.3}, {:.3}, {:.3} (the paper",
            main(6),
            main(7),
            main(8)
        ),
        format!(
            "{folds} folds, with all {} solutions at α = {:.3} drawn",
            fr.solutions, query
        ),
        format!("has {} transition points", report.transitions.len()),
    ];
    let (sdoc, sreadme) = (squash(&doc), squash(&readme));
    for q in &quotes_doc {
        assert!(
            contains_text(&sdoc, &squash(q)),
            "docs/case-study.md should say {q:?}"
        );
    }
    for q in &quotes_readme {
        assert!(
            contains_text(&sreadme, &squash(q)),
            "README.md should say {q:?}"
        );
    }
    // no long number escapes these checks (the paper's three are its own)
    let papers = ["0.28019791259766", "0.42934036865234", "0.60403706054688"];
    let table_text = table(&report.table).join("\n");
    for (file, text, quotes) in [
        ("docs/case-study.md", &sdoc, &quotes_doc[..]),
        ("README.md", &sreadme, &quotes_readme[..]),
    ] {
        for word in text.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-')) {
            let digits = word.chars().filter(char::is_ascii_digit).count();
            if digits < 7 || word.parse::<f64>().is_err() {
                continue;
            }
            let covered = papers.contains(&word)
                || contains_text(&table_text, word)
                || quotes.iter().any(|q| contains_text(q, word));
            assert!(covered, "{file}: {word} is checked against nothing");
        }
    }
    std::fs::remove_dir_all(&out).unwrap();
}
