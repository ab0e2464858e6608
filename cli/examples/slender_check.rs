//! fricont against the independent reference tracer of `tests/common/reference.rs` on
//! slender generated meshes (issue 10, failure mode 4). A measurement, not a test: the
//! dense reference factorises every piece afresh (O(p³) each), so p = 480 takes minutes.
//!
//! ```text
//! cargo run --release -p fricont-cli --example slender_check                # the default list
//! cargo run --release -p fricont-cli --example slender_check -- strip 480   # a p = 480 strip
//! cargo run --release -p fricont-cli --example slender_check -- beam 121 2 48 1 0.3
//! cargo run --release -p fricont-cli --example slender_check -- rect NX NY LX LY F
//! ```
//!
//! `strip P [F]` is the strip of `cli/benches/strips.rs` (`P + 1 × 4` nodes on
//! `(0, P/40) × (0, 0.1)`); `beam`/`rect NX NY LX LY F` a rectangle of `NX × NY` nodes on
//! `(0, LX) × (0, LY)` with friction F. All use the press-shear load and the window
//! [−0.5, 1.5]. Printed per case: sizes, times, both event counts and ends, the largest
//! relative α difference, the first difference if any, and the reference's own
//! diagnostics (largest relative residual of a piece solve, smallest pivot ratio, the
//! closest two separate crossings came, relative to max(1, |α|)).

#[path = "../../tests/common/mod.rs"]
mod common;

use std::sync::Arc;
use std::time::Instant;

use common::reference::{Condensed, Ev, SparseRows, compare_with_fricont, differences};
use fricont_exchange::generator::{RectSpec, generate};

struct Spec {
    name: String,
    spec: RectSpec,
}

fn rect(nx: usize, ny: usize, lx: f64, ly: f64, friction: f64) -> RectSpec {
    RectSpec {
        nx,
        ny,
        lx,
        ly,
        friction,
        ..RectSpec::press_shear()
    }
}

fn strip(p: usize, friction: f64) -> Spec {
    Spec {
        name: format!("strip p = {p}, F = {friction}"),
        spec: rect(p + 1, 4, p as f64 / 40.0, 0.1, friction),
    }
}

fn parse(args: &[String]) -> Vec<Spec> {
    let num = |k: usize| -> f64 { args[k].parse().expect("a number") };
    match args.first().map(String::as_str) {
        None => vec![
            Spec {
                name: "beam 48 x 1, p = 120, F = 0.3".into(),
                spec: rect(121, 2, 48.0, 1.0, 0.3),
            },
            strip(240, 0.3),
            strip(480, 0.3),
        ],
        Some("strip") => vec![strip(
            num(1) as usize,
            if args.len() > 2 { num(2) } else { 0.3 },
        )],
        Some("beam") | Some("rect") => vec![Spec {
            name: format!(
                "rect {} x {} nodes on {} x {}, F = {}",
                args[1], args[2], args[3], args[4], args[5]
            ),
            spec: rect(num(1) as usize, num(2) as usize, num(3), num(4), num(5)),
        }],
        Some(x) => panic!("unknown case kind {x}: strip, beam or rect"),
    }
}

/// fricont's start classes.
fn start_classes(case: &fricont_exchange::io::CaseData) -> Vec<fricont::Class> {
    let mut path = fricont::Path::new(
        Arc::new(case.problem(None).expect("problem")),
        case.load().expect("load"),
        fricont::PathOptions::window(case.alpha_start, case.alpha_end),
    )
    .expect("path");
    path.start(case.alpha_start, None).expect("start");
    path.start_state().unwrap().classes.clone()
}

/// The reference's condensation of a case; with `perturb = Some(u)`, every entry of the
/// (symmetrised) A is first changed by `u r A_ij` (rounded: `u = ε` changes an entry by
/// at most one unit in the last place), `r` uniform in [−1, 1] and the same for `A_ij`
/// and `A_ji`.
fn condensed(case: &fricont_exchange::io::CaseData, perturb: Option<f64>) -> Condensed {
    let p = case.p();
    let mut a = SparseRows::from_csr(&case.a).symmetrised();
    if let Some(u) = perturb {
        let n = a.rows.len() as u64;
        for (i, row) in a.rows.iter_mut().enumerate() {
            for (j, v) in row.iter_mut() {
                let (lo, hi) = ((i as u64).min(*j as u64), (i as u64).max(*j as u64));
                let r = common::Rng::new(lo * n + hi).range(-1.0, 1.0);
                *v += *v * u * r;
            }
        }
    }
    Condensed::from_sparse(
        &a,
        &SparseRows::from_csr(&case.n_mat),
        &SparseRows::from_csr(&case.t_mat),
        &case.f0,
        &case.f1,
        case.gap.clone().unwrap_or_else(|| vec![0.0; p]),
        if case.friction.len() == 1 {
            vec![case.friction[0]; p]
        } else {
            case.friction.clone()
        },
    )
}

/// Per reference event, |Δα| / max(1, |α|) when the data A are perturbed at random by up
/// to one unit in the last place: how well the double-precision data
/// determine each transition point, the accuracy any backward-stable double-precision
/// computation can promise. Ends at the first event where the perturbed trace differs in
/// kind.
fn perturbed_spread(
    start: &[fricont::Class],
    case: &fricont_exchange::io::CaseData,
    want: &[Ev],
) -> Vec<f64> {
    let c2 = condensed(case, Some(f64::EPSILON));
    let tr = c2.trace(
        start,
        case.alpha_start,
        case.alpha_end,
        100_000,
        &mut |_, _| {},
    );
    let mut out = Vec::new();
    for (e, f) in want.iter().zip(&tr.events) {
        if (e.1, e.2, e.3) != (f.node, f.from, f.to) {
            break;
        }
        out.push((e.0 - f.alpha).abs() / 1f64.max(e.0.abs()));
    }
    out
}

/// Where do differences come from? fricont's own W and q (its condensation, in the
/// caller's units) against the reference's, and the reference tracer run on fricont's
/// ", the most at event K (node I, α = A): D" for the first of `d`, or nothing.
fn most(d: &[(usize, f64, Ev)]) -> String {
    d.first().map_or(String::new(), |(k, d, e)| {
        format!(
            ", the most at event {} (node {}, α = {:.14e}): {d:.1e}",
            k + 1,
            e.1 + 1,
            e.0
        )
    })
}

/// condensation against fricont's events (the tracers alone).
fn tracer_only(
    case: &fricont_exchange::io::CaseData,
    cond: &Condensed,
    fr_events: &[common::reference::Ev],
) {
    let problem = case.problem(None).expect("problem");
    let p = case.p();
    let s = problem.row_scale().to_vec();
    let w_int = problem.delassus().w();
    let w = nalgebra::DMatrix::from_fn(2 * p, 2 * p, |k, l| s[k] * w_int[(k, l)] * s[l]);
    let q = |f: &[f64]| {
        let v = problem.delassus().condense(f).expect("condense");
        nalgebra::DVector::from_fn(2 * p, |k, _| s[k] * v[k])
    };
    let (q0, q1) = (q(&case.f0), q(&case.f1));
    println!(
        "   fricont's condensation against the reference's: |ΔW|/|W| = {:.1e}, |Δq0|/|q0| = {:.1e}, |Δq1|/|q1| = {:.1e}",
        (&w - &cond.w).amax() / cond.w.amax(),
        (&q0 - &cond.q0).amax() / cond.q0.amax(),
        (&q1 - &cond.q1).amax() / cond.q1.amax()
    );
    let fc = Condensed::from_double(w, q0, q1, cond.gap.clone(), cond.friction.clone());
    let start = start_classes(case);
    let tr = fc.trace(
        &start,
        case.alpha_start,
        case.alpha_end,
        100_000,
        &mut |_, _| {},
    );
    let want: Vec<common::reference::Ev> = tr
        .events
        .iter()
        .map(|e| (e.alpha, e.node, e.from, e.to))
        .collect();
    let d = differences(fr_events, &want, 1e-8);
    println!(
        "   reference on fricont's W, q: {} events, {} of them differ from fricont's by more than 1e-8{}",
        want.len(),
        d.len(),
        most(&d)
    );
}

/// The tracers alone on identical data: the reference's W, q0, q1 rounded to double,
/// given to fricont as condensed input and to the reference as they are.
fn tracers_on_rounded_data(case: &fricont_exchange::io::CaseData, cond: &Condensed) {
    let c = common::reference::compare_on_rounded(
        cond,
        fricont::ExtendedPrecision::Auto,
        case.alpha_start,
        case.alpha_end,
        1e-8,
    );
    let want: Vec<Ev> = c
        .reference
        .events
        .iter()
        .map(|e| (e.alpha, e.node, e.from, e.to))
        .collect();
    let d = differences(&c.fricont, &want, 1e-12);
    println!(
        "   both tracers on the reference's W, q rounded to double: {} / {} events, fricont ends {:?}; {} differ by more than 1e-12{}",
        c.fricont.len(),
        want.len(),
        c.fricont_end,
        d.len(),
        most(&d)
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    for Spec { name, spec } in parse(&args) {
        println!("== {name}");
        let case = generate(&spec).expect("generate");
        let (n, p) = (case.n(), case.p());
        println!(
            "   n = {n}, p = {p}, window [{}, {}]",
            case.alpha_start, case.alpha_end
        );
        let t = Instant::now();
        let cond = condensed(&case, None);
        println!(
            "   reference condensation {:.2} s",
            t.elapsed().as_secs_f64()
        );
        let problem = Arc::new(case.problem(None).expect("problem"));
        let mut last: Option<Instant> = None;
        let mut progress = |k: usize, a: f64| {
            let t = last.get_or_insert_with(Instant::now);
            if t.elapsed().as_secs_f64() > 10.0 {
                println!("   ... reference: {k} transitions, α = {a:.14e}");
                *t = Instant::now();
            }
        };
        let c = compare_with_fricont(
            &cond,
            problem,
            &case.f0,
            &case.f1,
            case.alpha_start,
            case.alpha_end,
            1e-8,
            &mut progress,
        );
        let r = &c.reference;
        println!(
            "   fricont: {} events, ends at α = {:.14e} ({}), {:.2} s",
            c.fricont.len(),
            c.fricont_end.0,
            c.fricont_end.1,
            c.seconds.0
        );
        println!(
            "   reference: {} events, ends at α = {:.14e} ({}), {:.2} s",
            r.events.len(),
            r.end_alpha,
            match &r.end {
                Ok(()) => "window".to_string(),
                Err(e) => format!("stopped: {e}"),
            },
            c.seconds.1
        );
        println!(
            "   reference diagnostics: largest piece residual {:.1e}, smallest pivot ratio {:.1e}, closest separate crossings {:.1e}, widest group of crossings {:.1e}; start λ differ by {:.1e}",
            r.max_residual, r.min_pivot_ratio, r.min_separation, r.max_group_spread, c.start_diff
        );
        if let Ok(d) = &c.events {
            println!("   events agree: largest relative α difference {d:.2e}");
        }
        match c.check(1e-8) {
            Ok(()) => println!("   AGREE"),
            Err(e) => println!("   MISMATCH: {}", e.replace('\n', "\n   ")),
        }
        let want: Vec<Ev> = r
            .events
            .iter()
            .map(|e| (e.alpha, e.node, e.from, e.to))
            .collect();
        let diffs = differences(&c.fricont, &want, 1e-8);
        if !diffs.is_empty() {
            // How well the data determine those events: the reference again on A
            // perturbed by one unit in the last place.
            let spread = perturbed_spread(&start_classes(&case), &case, &want);
            println!(
                "   {} reference events differ from fricont's nearest event of the same node and kind by more than 1e-8 (relative to max(1, |α|)); the largest:",
                diffs.len()
            );
            for (k, d, e) in diffs.iter().take(12) {
                println!(
                    "     event {:>4}: node {:>4} {} -> {}, reference α = {:.14e}, fricont {}, difference {d:.1e}, moves by {:.1e} when A is perturbed by 1 ulp",
                    k + 1,
                    e.1 + 1,
                    e.2,
                    e.3,
                    e.0,
                    if d.is_finite() {
                        "matched"
                    } else {
                        "has no such event nearby"
                    },
                    spread.get(*k).copied().unwrap_or(f64::NAN)
                );
            }
        }
        // The neighbourhood of the largest difference, in both traces.
        if let Some(&(k, _, _)) = diffs.first() {
            let (lo, hi) = (k.saturating_sub(2), (k + 3).min(want.len()));
            let (a, b) = (
                want[lo].0.min(want[hi - 1].0),
                want[lo].0.max(want[hi - 1].0),
            );
            let show = |e: &Ev| format!("α = {:.14e} node {:>4} {} -> {}", e.0, e.1 + 1, e.2, e.3);
            println!("   around reference event {}:", k + 1);
            for (j, e) in want.iter().enumerate().take(hi).skip(lo) {
                println!("     reference {:>4}: {}", j + 1, show(e));
            }
            let pad = 1e-6 * 1f64.max(a.abs());
            for (j, e) in c.fricont.iter().enumerate() {
                if e.0 >= a - pad && e.0 <= b + pad {
                    println!("     fricont   {:>4}: {}", j + 1, show(e));
                }
            }
        }
        if std::env::var_os("SLENDER_TRACER_ONLY").is_some() {
            tracer_only(&case, &cond, &c.fricont);
            tracers_on_rounded_data(&case, &cond);
        }
    }
}
