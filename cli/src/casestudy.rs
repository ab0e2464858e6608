//! The founding paper's case study, end to end: generate the rectangle problem
//! ([`fricont_exchange::generator`]), write it in the exchange format, trace the path over the
//! paper's window, and write the transition table (in the paper's words), the figures
//! (SVG, and a PNG beside each) and the path (CSV, JSON). A high-friction variant of the
//! same geometry is traced through its non-smooth folds, and every solution at one α
//! inside a fold region is drawn.
//!
//! The figures are laid out to be printed [`PRINT_WIDTH_CM`] wide with all text at least
//! [`MIN_TEXT_PT`] there, legends outside the plot areas listing only what is drawn; the
//! PNGs ([`write_png`]) are rendered with a font embedded in the program. Each drawing
//! function returns a [`FigureLayout`] (plot areas, data and legends in pixels) that the
//! tests check these rules on.
//!
//! The library never prints: [`run`] returns the text of the table in
//! [`CaseStudyReport::table`] and the CLI (`fricont case-study --out DIR`) prints it.
//!
//! ## Units and signs in the figures and files
//!
//! Lengths are in the units `L` of the rectangle's sides, stresses (tractions, `E`) in
//! the units of `E`, so nodal forces per unit thickness are in `E·L`. `λν ≤ 0` is the
//! normal contact force on the body along the outward normal `(0, −1)` (compressive),
//! `λt` the tangential one along `+x`; `uν = (N u)_i = −u_y` (negative when the node
//! lifts off; 0 in contact, since the gap is 0) and `ut = (T u)_i = u_x`. Nodes are
//! counted from 1 (left to right) as in the paper.

use std::fmt::Write as _;
use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use serde_json::{Value, json};

use fricont::class::Class;
use fricont::path::{EndReason, Path, PathOptions, State};
use fricont::problem::Problem;
use fricont_exchange::generator::{RectSpec, generate};
use fricont_exchange::io::CaseData;
use fricont_exchange::report::{
    PathReport, Timing, TransitionRow, events_csv, fmt_alpha, transition_rows,
};
use fricont_exchange::{Error, Result};

mod figures;
pub use figures::{
    FIG_WIDTH, FigureLayout, MIN_TEXT_PT, PNG_DPI, PRINT_WIDTH_CM, PxRect, plot_mesh, plot_path,
    plot_path_window, plot_profiles, plot_snapshot, plot_solutions, png_width, pt_to_px, write_png,
};

/// What to run. `CaseStudyOptions::new(out)` gives the paper's case study.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseStudyOptions {
    /// Output directory (created). Everything is written below it.
    pub out: PathBuf,
    /// The problem (window: `spec.alpha_start` → `spec.alpha_end`).
    pub spec: RectSpec,
    /// α of the contact-data snapshot (Figure 2); the paper shows α = 3.6. When it lies
    /// outside the window, a second path is traced from `alpha_start` until past it.
    pub snapshot_alpha: f64,
    /// α values of the normal-force profiles (Figure 3), computed by
    /// [`Path::solutions_at`] on the traced path.
    pub profile_alphas: Vec<f64>,
    /// The high-friction variant, if wanted.
    pub fold_variant: Option<FoldVariant>,
}

impl CaseStudyOptions {
    /// The paper's case study written to `out`: [`RectSpec::default`], snapshot at
    /// α = 3.6, profiles at α = −0.5, 0, 0.5, 1, 1.5, and the default high-friction variant.
    pub fn new(out: impl Into<PathBuf>) -> Self {
        Self {
            out: out.into(),
            spec: RectSpec::default(),
            snapshot_alpha: 3.6,
            profile_alphas: vec![-0.5, 0.0, 0.5, 1.0, 1.5],
            fold_variant: Some(FoldVariant::default()),
        }
    }
}

/// The high-friction variant: a problem whose path has a non-smooth fold.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldVariant {
    /// The problem (same geometry as the case study; friction and load changed).
    pub spec: RectSpec,
    /// α at which all solutions are drawn; `None`: the middle of the first fold region
    /// found (between the first fold and the nearer neighbouring transition point).
    pub alpha_query: Option<f64>,
}

impl Default for FoldVariant {
    /// [`RectSpec::high_friction`], α of the solutions figure chosen automatically.
    fn default() -> Self {
        Self {
            spec: RectSpec::high_friction(),
            alpha_query: None,
        }
    }
}

/// What the high-friction variant gave.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldReport {
    /// Its transition table (text).
    pub table: String,
    /// Its transitions.
    pub transitions: Vec<TransitionRow>,
    /// Why its path ended.
    pub end_reason: String,
    /// Number of fold events.
    pub folds: usize,
    /// α where all solutions were computed (None when the path has no fold).
    pub alpha_query: Option<f64>,
    /// Number of solutions found there.
    pub solutions: usize,
    /// The α window of the zoom on the folds (`path_folds.svg`), when the path folds.
    pub zoom: Option<(f64, f64)>,
}

/// What [`run`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseStudyReport {
    /// Number of dofs.
    pub n: usize,
    /// Number of contact nodes.
    pub p: usize,
    /// The transition table in the paper's words, ending with a newline (what the CLI
    /// prints).
    pub table: String,
    /// The transitions of the main path.
    pub transitions: Vec<TransitionRow>,
    /// Why the main path ended (`"window"` normally).
    pub end_reason: String,
    /// α actually shown in Figure 2.
    pub snapshot_alpha: f64,
    /// Set-up time (Cholesky, Delassus, condensed loads), seconds.
    pub setup_s: f64,
    /// Tracing time of the main path (start solve + all steps), seconds.
    pub trace_s: f64,
    /// Files written.
    pub files: Vec<PathBuf>,
    /// The figures written (SVG, PNG, layout), the high-friction variant's included.
    pub figures: Vec<Figure>,
    /// The high-friction variant, if run.
    pub fold: Option<FoldReport>,
}

impl CaseStudyReport {
    /// Everything the CLI prints: the main table, the high-friction variant's table, the
    /// timings and the list of files written. Ends with a newline.
    pub fn text(&self) -> String {
        let mut s = self.table.clone();
        if let Some(f) = &self.fold {
            s.push_str("\nhigh-friction variant:\n");
            s.push_str(&f.table);
        }
        let _ = writeln!(
            s,
            "\nset-up {:.3} s, tracing {:.3} s (main path); Figure 2 at alpha = {}",
            self.setup_s, self.trace_s, self.snapshot_alpha
        );
        let _ = writeln!(s, "files written:");
        for f in &self.files {
            let _ = writeln!(s, "  {}", f.display());
        }
        s
    }
}

/// The contact data at one point: what Figures 2 and 3 draw.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactData {
    /// α.
    pub alpha: f64,
    /// `λν` (p).
    pub lambda_n: Vec<f64>,
    /// `λt` (p).
    pub lambda_t: Vec<f64>,
    /// `uν = N u` (p).
    pub u_n: Vec<f64>,
    /// `ut = T u` (p).
    pub u_t: Vec<f64>,
    /// Classes (p).
    pub classes: Vec<Class>,
}

impl ContactData {
    /// From a path state and the case's `N`, `T`.
    pub fn from_state(s: &State, case: &CaseData) -> Self {
        let p = case.p();
        let mut u_n = vec![0.0; p];
        let mut u_t = vec![0.0; p];
        case.n_mat.mul_vec(&s.u, &mut u_n);
        case.t_mat.mul_vec(&s.u, &mut u_t);
        Self {
            alpha: s.alpha,
            lambda_n: s.lambda_n.clone(),
            lambda_t: s.lambda_t.clone(),
            u_n,
            u_t,
            classes: s.classes.clone(),
        }
    }
}

/// One traced smooth piece as drawn: end points in `(α, λν, λt)`.
#[derive(Debug, Clone, PartialEq)]
pub struct PieceLine {
    /// α at the start of the piece.
    pub alpha_from: f64,
    /// α at its end.
    pub alpha_to: f64,
    /// `λν` (p) at the start.
    pub lambda_n_from: Vec<f64>,
    /// `λν` (p) at the end.
    pub lambda_n_to: Vec<f64>,
    /// `λt` (p) at the start.
    pub lambda_t_from: Vec<f64>,
    /// `λt` (p) at the end.
    pub lambda_t_to: Vec<f64>,
}

fn io_err<E: std::fmt::Display>(file: &FsPath) -> impl FnOnce(E) -> Error + '_ {
    move |e| Error::Io(format!("cannot write {}: {e}", file.display()))
}

/// A transition point as drawn on the path figure.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkedPoint {
    /// 1-based transition number.
    pub transition: usize,
    /// α.
    pub alpha: f64,
    /// `λν` (p) there.
    pub lambda_n: Vec<f64>,
    /// `λt` (p) there.
    pub lambda_t: Vec<f64>,
    /// α turns back here.
    pub fold: bool,
    /// 0-based node that changes class (one point per event).
    pub node: usize,
}

/// One figure written by [`run`]: the SVG, the PNG rendered from it beside it, and where
/// its parts landed (SVG pixels).
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// The SVG file.
    pub svg: PathBuf,
    /// The PNG beside it ([`write_png`]).
    pub png: PathBuf,
    /// Plot areas, data, legends.
    pub layout: FigureLayout,
}

/// Renders the PNG beside `svg` and records both files and the figure.
fn add_figure(
    svg: PathBuf,
    layout: FigureLayout,
    files: &mut Vec<PathBuf>,
    figures: &mut Vec<Figure>,
) -> Result<()> {
    let png = write_png(&svg)?;
    files.push(svg.clone());
    files.push(png.clone());
    figures.push(Figure { svg, png, layout });
    Ok(())
}

/// A traced path with its problem data, as the case study uses it.
struct Traced {
    path: Path,
    setup_s: f64,
    trace_s: f64,
    end: EndReason,
}

fn trace(case: &CaseData, problem: Arc<Problem>, a0: f64, a1: f64) -> Result<Traced> {
    let t0 = Instant::now();
    let mut path = Path::new(problem, case.load()?, PathOptions::window(a0, a1))?;
    let setup_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    path.start(a0, None)?;
    let end = path.run()?;
    Ok(Traced {
        path,
        setup_s,
        trace_s: t1.elapsed().as_secs_f64(),
        end,
    })
}

/// The transition table in the paper's words, one line per event:
/// "at transition point 6, α = 0.28019791259766, contact node 13 changes from no contact
/// to contact, slip (slip+)". Folds and bifurcations are flagged at the end of the line.
pub fn seed_words(rows: &[TransitionRow]) -> String {
    let mut s = String::new();
    for r in rows {
        let dir = match r.to {
            Class::SlipPlus => " (+x)",
            Class::SlipMinus => " (−x)",
            _ => "",
        };
        let _ = write!(
            s,
            "at transition point {}, α = {}, contact node {} changes from {} to {}{dir}",
            r.transition,
            fmt_alpha(r.alpha),
            r.node,
            r.from.words(),
            r.to.words()
        );
        if r.fold {
            s.push_str("; fold: α turns back");
        }
        if r.bifurcation {
            s.push_str("; bifurcation point");
        }
        s.push('\n');
    }
    s
}

fn piece_lines(path: &Path) -> Vec<PieceLine> {
    let p = path.problem().p();
    path.pieces()
        .iter()
        .map(|r| PieceLine {
            alpha_from: r.alpha_from,
            alpha_to: r.alpha_to,
            lambda_n_from: r.lambda_from[..p].to_vec(),
            lambda_n_to: r.lambda_to[..p].to_vec(),
            lambda_t_from: r.lambda_from[p..].to_vec(),
            lambda_t_to: r.lambda_to[p..].to_vec(),
        })
        .collect()
}

fn marked_points(path: &Path) -> Vec<MarkedPoint> {
    path.events()
        .iter()
        .map(|e| MarkedPoint {
            transition: e.transition + 1,
            alpha: e.alpha,
            lambda_n: e.lambda_n.clone(),
            lambda_t: e.lambda_t.clone(),
            fold: e.fold,
            node: e.node,
        })
        .collect()
}

/// Nodes (0-based) to show on the path figure: those of the events, at most 8, spread
/// over the path.
fn event_nodes(path: &Path) -> Vec<usize> {
    let mut v: Vec<usize> = Vec::new();
    for e in path.events().iter().filter(|e| e.fold) {
        if !v.contains(&e.node) && v.len() < 4 {
            v.push(e.node);
        }
    }
    let mut rest: Vec<usize> = Vec::new();
    for e in path.events() {
        if !v.contains(&e.node) && !rest.contains(&e.node) {
            rest.push(e.node);
        }
    }
    let room = 8 - v.len();
    if rest.len() > room {
        let step = rest.len() as f64 / room as f64;
        rest = (0..room)
            .map(|k| rest[(k as f64 * step) as usize])
            .collect();
    }
    v.extend(rest);
    v.sort_unstable();
    v
}

/// The path as JSON: the report of SPEC §8 ([`PathReport`], the one JSON writer of the
/// project) extended with every vertex's contact data (`λν`, `λt`, `uν`, `ut` per node at
/// the start and at each event, under `state`) and the units.
fn path_json(path: &mut Path, case: &CaseData, setup_s: f64, trace_s: f64) -> Result<Value> {
    let report = PathReport::from_path(path, Timing { setup_s, trace_s });
    let mut v = serde_json::to_value(&report)
        .map_err(|e| Error::Io(format!("cannot serialise the path: {e}")))?;
    let vertex = |s: &State| {
        let d = ContactData::from_state(s, case);
        json!({
            "alpha": s.alpha, "residual": s.residual,
            "lambda_n": d.lambda_n, "lambda_t": d.lambda_t, "u_n": d.u_n, "u_t": d.u_t,
        })
    };
    v["start"]["state"] = vertex(&path.start_state()?);
    let list = path.events().to_vec();
    if let Some(events) = v["events"].as_array_mut() {
        for (e, ev) in list.iter().zip(events.iter_mut()) {
            ev["state"] = vertex(&path.event_state(e.index)?);
        }
    }
    v["units"] = json!(
        "lengths in L, stresses in E, nodal forces per unit thickness in E*L; lambda_n <= 0 compressive; u_n = N u = -u_y; u_t = T u = u_x; nodes 1-based"
    );
    Ok(v)
}

/// The path's vertices (start, every transition point, end) as CSV: one row per vertex,
/// α then `λν_i`, `λt_i`, `uν_i`, `ut_i`, class_i for i = 1..p.
fn path_csv(path: &mut Path, case: &CaseData) -> Result<String> {
    let p = case.p();
    let mut s = String::from("kind,transition,alpha");
    for name in ["lambda_n", "lambda_t", "u_n", "u_t", "class"] {
        for i in 1..=p {
            let _ = write!(s, ",{name}_{i}");
        }
    }
    s.push('\n');
    let mut row = |kind: &str, k: usize, st: &State| {
        let d = ContactData::from_state(st, case);
        let _ = write!(s, "{kind},{k},{:e}", st.alpha);
        for v in d
            .lambda_n
            .iter()
            .chain(&d.lambda_t)
            .chain(&d.u_n)
            .chain(&d.u_t)
        {
            let _ = write!(s, ",{v:e}");
        }
        for c in &d.classes {
            let _ = write!(s, ",{}", c.name());
        }
        s.push('\n');
    };
    row("start", 0, &path.start_state()?);
    let mut last = None;
    for e in path.events().to_vec() {
        if last == Some(e.transition) {
            continue;
        }
        last = Some(e.transition);
        row("transition", e.transition + 1, &path.event_state(e.index)?);
    }
    let cur = path.current()?;
    row("end", 0, &cur);
    Ok(s)
}

fn write(file: PathBuf, text: &str, files: &mut Vec<PathBuf>) -> Result<()> {
    std::fs::write(&file, text).map_err(io_err(&file))?;
    files.push(file);
    Ok(())
}

fn header(spec: &RectSpec, end: &EndReason, path: &Path) -> String {
    let pieces = path.pieces();
    let last = pieces.last().map_or(spec.alpha_start, |r| r.alpha_to);
    let folds = path.events().iter().filter(|e| e.fold).count();
    let tp = path.events().last().map_or(0, |e| e.transition + 1);
    format!(
        "{}\nn = {}, p = {}, E = {}, nu = {}, F = {}, load \"{}\"\n\
         traced alpha from {} to {}: {} ({}, {}), ended by \"{}\" at alpha = {}\n",
        spec.mesh_description(),
        spec.n(),
        spec.p(),
        spec.e,
        spec.nu,
        spec.friction,
        spec.load_name,
        spec.alpha_start,
        spec.alpha_end,
        fricont_exchange::report::plural(tp, "transition point"),
        fricont_exchange::report::plural(path.events().len(), "event"),
        fricont_exchange::report::plural(folds, "fold"),
        end.name(),
        fmt_alpha(last)
    )
}

/// Runs the case study: see the module documentation. Writes below `opts.out`:
/// `problem/` (the exchange format), `transitions.txt` (the table in the paper's words),
/// `fig1_mesh.svg`, `fig2_snapshot.svg`, `fig3_profiles.svg`, `fig4_path.svg` (each with
/// its `.png`), `path.json`, `path.csv` (vertices), `events.csv`, and for the
/// high-friction variant `high-friction/` with its own `problem/`, `transitions.txt`,
/// `path.svg`, `path_folds.svg` (the zoom, [`fold_zoom`]), `solutions.svg` (with their
/// PNGs), `path.json`, `path.csv`, `events.csv`.
///
/// Errors: invalid spec, I/O, and the errors of the tracer (a path that ends by
/// [`EndReason::Failed`] is reported in the table, not as an error).
pub fn run(opts: &CaseStudyOptions) -> Result<CaseStudyReport> {
    let out = &opts.out;
    std::fs::create_dir_all(out).map_err(io_err(out))?;
    let mut files = Vec::new();
    let spec = &opts.spec;
    let case = generate(spec)?;
    let pdir = out.join("problem");
    case.write_dir(&pdir)?;
    files.push(pdir);

    let t0 = Instant::now();
    let problem = Arc::new(case.problem(None)?);
    let prob_s = t0.elapsed().as_secs_f64();
    let mut tr = trace(&case, problem.clone(), spec.alpha_start, spec.alpha_end)?;
    let rows = transition_rows(&tr.path);
    let mut table = header(spec, &tr.end, &tr.path);
    table.push_str(&seed_words(&rows));
    write(out.join("transitions.txt"), &table, &mut files)?;

    let mut figures = Vec::new();
    let svg = out.join("fig1_mesh.svg");
    let layout = plot_mesh(spec, &svg)?;
    add_figure(svg, layout, &mut files, &mut figures)?;

    // Figure 2: the snapshot (trace further when it lies outside the window)
    let (lo, hi) = (
        spec.alpha_start.min(spec.alpha_end),
        spec.alpha_start.max(spec.alpha_end),
    );
    let mut snap_alpha = opts.snapshot_alpha;
    let snap_sols = if (lo..=hi).contains(&snap_alpha) {
        tr.path.solutions_at(snap_alpha)?
    } else {
        let beyond = if snap_alpha > hi {
            snap_alpha + 0.05 * (hi - lo)
        } else {
            snap_alpha - 0.05 * (hi - lo)
        };
        // a failure of the extended path only costs the snapshot its α (fallback below)
        match trace(&case, problem.clone(), spec.alpha_start, beyond) {
            Ok(mut ext) => ext.path.solutions_at(snap_alpha).unwrap_or_default(),
            Err(_) => Vec::new(),
        }
    };
    let snap_sols = if snap_sols.is_empty() {
        snap_alpha = spec.alpha_end;
        tr.path.solutions_at(snap_alpha)?
    } else {
        snap_sols
    };
    if let Some(sol) = snap_sols.first() {
        let d = ContactData::from_state(&sol.state, &case);
        let extra = if snap_sols.len() > 1 {
            format!(" (first of {} solutions)", snap_sols.len())
        } else {
            String::new()
        };
        let svg = out.join("fig2_snapshot.svg");
        let layout = plot_snapshot(
            &d,
            &format!(
                "Contact data at the {} contact nodes for α = {}{extra}",
                spec.p(),
                snap_alpha
            ),
            &svg,
        )?;
        add_figure(svg, layout, &mut files, &mut figures)?;
    }

    // Figure 3: profiles by the cheap solution at any α
    let mut profiles = Vec::new();
    for &a in &opts.profile_alphas {
        for sol in tr.path.solutions_at(a)? {
            profiles.push(ContactData::from_state(&sol.state, &case));
        }
    }
    let svg = out.join("fig3_profiles.svg");
    let layout = plot_profiles(
        &profiles,
        "Profiles of the normal contact force λν (the solution at any α from the traced path)",
        &svg,
    )?;
    add_figure(svg, layout, &mut files, &mut figures)?;

    // Figure 4: the path
    let svg = out.join("fig4_path.svg");
    let layout = plot_path(
        &piece_lines(&tr.path),
        &marked_points(&tr.path),
        &event_nodes(&tr.path),
        &format!(
            "The traced path, α from {} to {} (F = {}): {}",
            spec.alpha_start,
            spec.alpha_end,
            spec.friction,
            fricont_exchange::report::plural(
                rows.last().map_or(0, |r| r.transition),
                "transition point"
            )
        ),
        &svg,
    )?;
    add_figure(svg, layout, &mut files, &mut figures)?;

    let setup_s = prob_s + tr.setup_s;
    let js = path_json(&mut tr.path, &case, setup_s, tr.trace_s)?;
    write(
        out.join("path.json"),
        &(serde_json::to_string_pretty(&js).unwrap_or_default() + "\n"),
        &mut files,
    )?;
    let csv = path_csv(&mut tr.path, &case)?;
    write(out.join("path.csv"), &csv, &mut files)?;
    write(out.join("events.csv"), &events_csv(&rows), &mut files)?;

    let fold = match &opts.fold_variant {
        Some(v) => Some(run_fold_variant(
            v,
            &out.join("high-friction"),
            &mut files,
            &mut figures,
        )?),
        None => None,
    };

    Ok(CaseStudyReport {
        n: case.n(),
        p: case.p(),
        table,
        transitions: rows,
        end_reason: tr.end.name().to_string(),
        snapshot_alpha: snap_alpha,
        setup_s,
        trace_s: tr.trace_s,
        files,
        figures,
        fold,
    })
}

/// The parts of the pieces with α in `[lo, hi]` (pieces of an affine load are straight
/// segments in (α, λ), so cutting them is a linear interpolation; vertical pieces are
/// kept when their α is inside).
pub fn clip_pieces(pieces: &[PieceLine], lo: f64, hi: f64) -> Vec<PieceLine> {
    let lerp = |a: &[f64], b: &[f64], t: f64| -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| x + t * (y - x)).collect()
    };
    let mut out = Vec::new();
    for p in pieces {
        let (a0, a1) = (p.alpha_from, p.alpha_to);
        if a0 == a1 {
            if (lo..=hi).contains(&a0) {
                out.push(p.clone());
            }
            continue;
        }
        let t = |a: f64| ((a - a0) / (a1 - a0)).clamp(0.0, 1.0);
        let (ta, tb) = {
            let (x, y) = (t(lo), t(hi));
            (x.min(y), x.max(y))
        };
        if tb <= ta {
            continue;
        }
        out.push(PieceLine {
            alpha_from: a0 + ta * (a1 - a0),
            alpha_to: a0 + tb * (a1 - a0),
            lambda_n_from: lerp(&p.lambda_n_from, &p.lambda_n_to, ta),
            lambda_n_to: lerp(&p.lambda_n_from, &p.lambda_n_to, tb),
            lambda_t_from: lerp(&p.lambda_t_from, &p.lambda_t_to, ta),
            lambda_t_to: lerp(&p.lambda_t_from, &p.lambda_t_to, tb),
        });
    }
    out
}

/// The open α intervals between consecutive distinct transition α's and piece ends, each
/// with the number of traced (non-vertical) pieces over it: the number of solutions the
/// traced path has at any α inside.
fn solution_counts(path: &Path) -> Vec<(f64, f64, usize)> {
    let mut alphas: Vec<f64> = path.events().iter().map(|e| e.alpha).collect();
    for r in path.pieces() {
        alphas.push(r.alpha_from);
        alphas.push(r.alpha_to);
    }
    alphas.sort_by(f64::total_cmp);
    alphas.dedup();
    alphas
        .windows(2)
        .map(|w| {
            let a = 0.5 * (w[0] + w[1]);
            let count = path
                .pieces()
                .iter()
                .filter(|r| r.alpha_from.min(r.alpha_to) < a && a < r.alpha_from.max(r.alpha_to))
                .count();
            (w[0], w[1], count)
        })
        .collect()
}

/// An α inside a fold region where the traced path has the most solutions: the middle
/// of the widest of the intervals with the most solutions. `None` when no α has two.
fn fold_query(path: &Path) -> Option<f64> {
    let counts = solution_counts(path);
    let most = counts.iter().map(|c| c.2).max().filter(|&m| m >= 2)?;
    counts
        .iter()
        .filter(|c| c.2 == most)
        .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
        .map(|c| 0.5 * (c.0 + c.1))
}

/// The α window of the zoom on the folds (`path_folds.svg`): the α range where the
/// traced path has the most solutions (at least two), widened to the folds that lie
/// within 10 % of its width of it, plus a margin of 10 % of the result on each side.
/// Folds far from that region (such as the first fold of the high-friction variant,
/// where the corner starts to slip) are seen on the whole path's figure. `None` when no
/// α has two solutions.
pub fn fold_zoom(path: &Path) -> Option<(f64, f64)> {
    let counts = solution_counts(path);
    let most = counts.iter().map(|c| c.2).max().filter(|&m| m >= 2)?;
    let best = counts.iter().filter(|c| c.2 == most);
    let lo = best.clone().map(|c| c.0).reduce(f64::min)?;
    let hi = best.map(|c| c.1).reduce(f64::max)?;
    let near = 0.1 * (hi - lo);
    let (mut a, mut b) = (lo, hi);
    for e in path.events().iter().filter(|e| e.fold) {
        if (lo - near..=hi + near).contains(&e.alpha) {
            a = a.min(e.alpha);
            b = b.max(e.alpha);
        }
    }
    let margin = 0.1 * (b - a);
    Some((a - margin, b + margin))
}

fn run_fold_variant(
    v: &FoldVariant,
    out: &FsPath,
    files: &mut Vec<PathBuf>,
    figures: &mut Vec<Figure>,
) -> Result<FoldReport> {
    std::fs::create_dir_all(out).map_err(io_err(out))?;
    let spec = &v.spec;
    let case = generate(spec)?;
    case.write_dir(&out.join("problem"))?;
    files.push(out.join("problem"));
    let problem = Arc::new(case.problem(None)?);
    let mut tr = trace(&case, problem, spec.alpha_start, spec.alpha_end)?;
    let rows = transition_rows(&tr.path);
    let folds = rows.iter().filter(|r| r.fold).count();
    let alpha_query = v.alpha_query.or_else(|| fold_query(&tr.path));
    let mut table = header(spec, &tr.end, &tr.path);
    table.push_str(&seed_words(&rows));
    let mut n_sol = 0;
    if let Some(a) = alpha_query {
        let sols = tr.path.solutions_at(a)?;
        n_sol = sols.len();
        let _ = writeln!(
            table,
            "at α = {}: {} solutions on the traced path",
            fmt_alpha(a),
            n_sol
        );
        for (k, s) in sols.iter().enumerate() {
            let r = &tr.path.pieces()[s.piece];
            let _ = writeln!(
                table,
                "  solution {}: piece {} (dα/ds {:+}), {} nodes in contact, Σλν = {:.6e}{}",
                k + 1,
                s.piece + 1,
                r.direction,
                s.state.classes.iter().filter(|c| c.in_contact()).count(),
                s.state.lambda_n.iter().sum::<f64>(),
                if s.continuum {
                    " (a continuum: vertical piece)"
                } else {
                    ""
                }
            );
        }
        let data: Vec<ContactData> = sols
            .iter()
            .map(|s| ContactData::from_state(&s.state, &case))
            .collect();
        let labels: Vec<String> = sols
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let d = tr.path.pieces()[s.piece].direction;
                format!(
                    "{}: piece {}, α {}",
                    k + 1,
                    s.piece + 1,
                    match d {
                        1 => "↑",
                        -1 => "↓",
                        _ => "const",
                    }
                )
            })
            .collect();
        let svg = out.join("solutions.svg");
        let layout = plot_solutions(
            &data,
            &labels,
            &format!(
                "F = {}: all {} solutions at α = {} (inside a fold region)",
                spec.friction,
                n_sol,
                fmt_alpha(a)
            ),
            &svg,
        )?;
        add_figure(svg, layout, files, figures)?;
    } else {
        table.push_str("no fold on this path\n");
    }
    write(out.join("transitions.txt"), &table, files)?;
    let svg = out.join("path.svg");
    let layout = plot_path(
        &piece_lines(&tr.path),
        &marked_points(&tr.path),
        &event_nodes(&tr.path),
        &format!(
            "High-friction variant (F = {}): the traced path, {} folds",
            spec.friction, folds
        ),
        &svg,
    )?;
    add_figure(svg, layout, files, figures)?;
    // a zoom on the region with the most solutions and its folds
    let zoom = fold_zoom(&tr.path);
    if let Some((lo, hi)) = zoom {
        let pieces = clip_pieces(&piece_lines(&tr.path), lo, hi);
        let points: Vec<MarkedPoint> = marked_points(&tr.path)
            .into_iter()
            .filter(|m| (lo..=hi).contains(&m.alpha))
            .collect();
        let mut nodes: Vec<usize> = Vec::new();
        for m in &points {
            if !nodes.contains(&m.node) && nodes.len() < 8 {
                nodes.push(m.node);
            }
        }
        nodes.sort_unstable();
        let inside: Vec<String> = points
            .iter()
            .filter(|m| m.fold)
            .map(|m| m.transition.to_string())
            .collect();
        let most = solution_counts(&tr.path)
            .iter()
            .map(|c| c.2)
            .max()
            .unwrap_or(0);
        let svg = out.join("path_folds.svg");
        let layout = plot_path_window(
            &pieces,
            &points,
            &nodes,
            Some((lo, hi)),
            &format!(
                "F = {}: zoom on the folds {} (the α range with {most} solutions)",
                spec.friction,
                inside.join(", "),
            ),
            &svg,
        )?;
        add_figure(svg, layout, files, figures)?;
    }
    let js = path_json(&mut tr.path, &case, tr.setup_s, tr.trace_s)?;
    write(
        out.join("path.json"),
        &(serde_json::to_string_pretty(&js).unwrap_or_default() + "\n"),
        files,
    )?;
    let csv = path_csv(&mut tr.path, &case)?;
    write(out.join("path.csv"), &csv, files)?;
    write(out.join("events.csv"), &events_csv(&rows), files)?;
    Ok(FoldReport {
        table,
        transitions: rows,
        end_reason: tr.end.name().to_string(),
        folds,
        alpha_query,
        solutions: n_sol,
        zoom,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_a_piece_interpolates_its_end_points() {
        let p = PieceLine {
            alpha_from: 1.0,
            alpha_to: 0.0,
            lambda_n_from: vec![-2.0],
            lambda_n_to: vec![0.0],
            lambda_t_from: vec![1.0],
            lambda_t_to: vec![3.0],
        };
        let c = clip_pieces(std::slice::from_ref(&p), 0.25, 0.5);
        assert_eq!(c.len(), 1);
        assert_eq!((c[0].alpha_from, c[0].alpha_to), (0.5, 0.25));
        assert_eq!((c[0].lambda_n_from[0], c[0].lambda_n_to[0]), (-1.0, -0.5));
        assert_eq!((c[0].lambda_t_from[0], c[0].lambda_t_to[0]), (2.0, 2.5));
        assert!(clip_pieces(std::slice::from_ref(&p), 2.0, 3.0).is_empty());
        let v = PieceLine { alpha_to: 1.0, ..p };
        assert_eq!(clip_pieces(std::slice::from_ref(&v), 0.5, 1.5).len(), 1);
    }

    #[test]
    fn seed_words_read_like_the_paper() {
        let rows = [TransitionRow {
            transition: 6,
            alpha: 0.28019791259766,
            node: 13,
            from: Class::Open,
            to: Class::SlipPlus,
            fold: false,
            bifurcation: false,
        }];
        assert_eq!(
            seed_words(&rows),
            "at transition point 6, α = 0.28019791259766, contact node 13 changes from no contact to contact, slip (+x)\n"
        );
    }
}
