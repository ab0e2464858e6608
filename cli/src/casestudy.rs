//! The founding paper's case study, end to end: generate the rectangle problem
//! ([`fricont_exchange::generator`]), write it in the exchange format, trace the path over the
//! paper's window, and write the transition table (in the paper's words), the figures
//! (SVG) and the path (CSV, JSON). A high-friction variant of the same geometry is traced
//! through its non-smooth folds, and every solution at one α inside a fold region is
//! drawn.
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

use plotters::coord::Shift;
use plotters::prelude::*;
use serde_json::{Value, json};

use fricont::class::Class;
use fricont::path::{EndReason, Path, PathOptions, State};
use fricont::problem::Problem;
use fricont_exchange::generator::{RectSpec, Side, generate};
use fricont_exchange::io::CaseData;
use fricont_exchange::report::{
    PathReport, Timing, TransitionRow, events_csv, fmt_alpha, transition_rows,
};
use fricont_exchange::{Error, Result};

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

fn plot_err<E: std::fmt::Display>(file: &FsPath) -> impl FnOnce(E) -> Error + '_ {
    move |e| Error::Io(format!("cannot draw {}: {e}", file.display()))
}

fn io_err<E: std::fmt::Display>(file: &FsPath) -> impl FnOnce(E) -> Error + '_ {
    move |e| Error::Io(format!("cannot write {}: {e}", file.display()))
}

const FONT: &str = "sans-serif";
const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

fn sum(v: &[f64]) -> f64 {
    v.iter().sum()
}

/// Data range with a margin; never empty.
fn range(vals: impl IntoIterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if !lo.is_finite() {
        return -1.0..1.0;
    }
    let span = hi - lo;
    let pad = if span > 0.0 {
        0.08 * span
    } else {
        0.1 * lo.abs().max(1e-12)
    };
    (lo - pad)..(hi + pad)
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Draws class markers (circle: no contact, diamond: stick, square: slip; filled square
/// slip+, open square slip−) at `(x, y)`, with legend entries when `legend` is set.
fn draw_class_markers<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    pts: &[(f64, f64, Class)],
    color: RGBColor,
    legend: bool,
) -> std::result::Result<(), String> {
    let filled = color.filled();
    let hollow = color.stroke_width(2);
    let pick = |c: Class| pts.iter().filter(move |p| p.2 == c).map(|p| (p.0, p.1));
    let black = BLACK.stroke_width(2);
    let a = chart
        .draw_series(pick(Class::Open).map(|p| Circle::new(p, 4, hollow)))
        .map_err(|e| e.to_string())?;
    if legend {
        a.label("no contact")
            .legend(move |(x, y)| Circle::new((x, y), 4, black));
    }
    let diamond = |s: ShapeStyle| {
        move |p: (f64, f64)| {
            EmptyElement::at(p) + Polygon::new(vec![(0, -6), (6, 0), (0, 6), (-6, 0)], s)
        }
    };
    let a = chart
        .draw_series(pick(Class::Stick).map(diamond(filled)))
        .map_err(|e| e.to_string())?;
    if legend {
        a.label("contact, stick").legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + Polygon::new(vec![(0, -6), (6, 0), (0, 6), (-6, 0)], BLACK.filled())
        });
    }
    let square = |s: ShapeStyle| {
        move |p: (f64, f64)| EmptyElement::at(p) + Rectangle::new([(-4, -4), (4, 4)], s)
    };
    let a = chart
        .draw_series(pick(Class::SlipPlus).map(square(filled)))
        .map_err(|e| e.to_string())?;
    if legend {
        a.label("contact, slip (+x)").legend(move |(x, y)| {
            EmptyElement::at((x, y)) + Rectangle::new([(-4, -4), (4, 4)], BLACK.filled())
        });
    }
    let a = chart
        .draw_series(pick(Class::SlipMinus).map(square(hollow)))
        .map_err(|e| e.to_string())?;
    if legend {
        a.label("contact, slip (−x)").legend(move |(x, y)| {
            EmptyElement::at((x, y)) + Rectangle::new([(-4, -4), (4, 4)], black)
        });
    }
    Ok(())
}

/// Tick label for an axis spanning `span`: one format per axis (decimals when the span
/// is between 0.01 and 1e5, scientific otherwise), no "-0".
fn tick(v: f64, span: f64) -> String {
    if v.abs() <= 1e-9 * span {
        return "0".into();
    }
    if (0.01..1e5).contains(&span) {
        let digits = (2 - span.log10().floor() as i32).clamp(0, 8) as usize;
        let t = format!("{v:.digits$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    } else {
        format!("{v:.1e}")
    }
}

/// An entry of a legend strip.
enum Entry {
    /// A class marker (black) with its words.
    Class(Class),
    /// A coloured line with a label.
    Line(RGBColor, String),
}

/// Draws a horizontal legend strip (below the panels) in pixel coordinates.
fn legend_strip(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    entries: &[Entry],
) -> std::result::Result<(), String> {
    let (w, h) = area.dim_in_pixel();
    let font = (FONT, 15).into_font();
    let widths: Vec<i32> = entries
        .iter()
        .map(|e| match e {
            Entry::Class(c) => 40 + 8 * class_label(*c).chars().count() as i32,
            Entry::Line(_, l) => 40 + 8 * l.chars().count() as i32,
        })
        .collect();
    let total: i32 = widths.iter().sum();
    let mut x = ((w as i32 - total) / 2).max(10);
    let y = h as i32 / 2;
    let e = |err: plotters::drawing::DrawingAreaErrorKind<_>| err.to_string();
    for (entry, wd) in entries.iter().zip(&widths) {
        match entry {
            Entry::Class(c) => {
                let black = BLACK.stroke_width(2);
                match c {
                    Class::Open => area.draw(&Circle::new((x + 8, y), 5, black)).map_err(e)?,
                    Class::Stick => area
                        .draw(&Polygon::new(
                            vec![(x + 8, y - 7), (x + 15, y), (x + 8, y + 7), (x + 1, y)],
                            BLACK.filled(),
                        ))
                        .map_err(e)?,
                    Class::SlipPlus => area
                        .draw(&Rectangle::new(
                            [(x + 3, y - 5), (x + 13, y + 5)],
                            BLACK.filled(),
                        ))
                        .map_err(e)?,
                    Class::SlipMinus => area
                        .draw(&Rectangle::new([(x + 3, y - 5), (x + 13, y + 5)], black))
                        .map_err(e)?,
                }
                area.draw(&Text::new(class_label(*c), (x + 24, y - 8), font.clone()))
                    .map_err(e)?;
            }
            Entry::Line(color, l) => {
                area.draw(&PathElement::new(
                    vec![(x, y), (x + 22, y)],
                    color.stroke_width(3),
                ))
                .map_err(e)?;
                area.draw(&Text::new(l.as_str(), (x + 28, y - 8), font.clone()))
                    .map_err(e)?;
            }
        }
        x += wd;
    }
    Ok(())
}

/// The paper's marker words for a class.
fn class_label(c: Class) -> &'static str {
    match c {
        Class::Open => "no contact (circle)",
        Class::Stick => "contact, stick (diamond)",
        Class::SlipPlus => "contact, slip +x (square)",
        Class::SlipMinus => "contact, slip −x (open square)",
    }
}

fn class_entries() -> Vec<Entry> {
    Class::ALL.iter().map(|&c| Entry::Class(c)).collect()
}

/// One panel: values against node index with class markers.
fn node_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    ylabel: &str,
    series: &[(&[f64], &[Class], RGBColor)],
) -> std::result::Result<(), String> {
    let p = series.first().map_or(1, |s| s.0.len());
    let yr = range(series.iter().flat_map(|s| s.0.iter().copied()).chain([0.0]));
    let span = yr.end - yr.start;
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(75)
        .build_cartesian_2d(0.5..p as f64 + 0.5, yr)
        .map_err(|e| e.to_string())?;
    let xt = |v: &f64| format!("{}", v.round() as i64);
    let yt = |v: &f64| tick(*v, span);
    chart
        .configure_mesh()
        .x_desc("contact node i (1 = next to the clamped side)")
        .y_desc(ylabel)
        .x_labels(p.min(16))
        .x_label_formatter(&xt)
        .y_label_formatter(&yt)
        .light_line_style(WHITE.mix(0.0))
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(LineSeries::new(
            [(0.5, 0.0), (p as f64 + 0.5, 0.0)],
            BLACK.mix(0.3),
        ))
        .map_err(|e| e.to_string())?;
    for (vals, classes, color) in series {
        chart
            .draw_series(LineSeries::new(
                vals.iter().enumerate().map(|(i, &v)| ((i + 1) as f64, v)),
                color.mix(0.6).stroke_width(1),
            ))
            .map_err(|e| e.to_string())?;
        let pts: Vec<(f64, f64, Class)> = vals
            .iter()
            .zip(classes.iter())
            .enumerate()
            .map(|(i, (&v, &c))| ((i + 1) as f64, v, c))
            .collect();
        draw_class_markers(&mut chart, &pts, *color, false)?;
    }
    Ok(())
}

/// Figure 2: λν, λt, uν, ut at the contact nodes for one point, markers by class.
pub fn plot_snapshot(data: &ContactData, title: &str, file: &FsPath) -> Result<()> {
    let root = SVGBackend::new(file, (1200, 950)).into_drawing_area();
    let draw = || -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root.titled(title, (FONT, 22)).map_err(|e| e.to_string())?;
        let (h, _) = (root.dim_in_pixel().1, ());
        let (panels, strip) = root.split_vertically(h - 45);
        let areas = panels.split_evenly((2, 2));
        let c = &data.classes;
        let blue = PALETTE[0];
        node_panel(
            &areas[0],
            "normal contact force λν (≤ 0: compression)",
            "λν  [E·L]",
            &[(&data.lambda_n, c, blue)],
        )?;
        node_panel(
            &areas[1],
            "tangential contact force λt (along +x)",
            "λt  [E·L]",
            &[(&data.lambda_t, c, blue)],
        )?;
        node_panel(
            &areas[2],
            "normal displacement uν = −u_y (< 0: lifted off)",
            "uν  [L]",
            &[(&data.u_n, c, blue)],
        )?;
        node_panel(
            &areas[3],
            "tangential displacement ut = u_x",
            "ut  [L]",
            &[(&data.u_t, c, blue)],
        )?;
        legend_strip(&strip, &class_entries())?;
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(plot_err(file))
}

/// Figure 3: λν against the node index for several points, markers by class.
pub fn plot_profiles(list: &[ContactData], title: &str, file: &FsPath) -> Result<()> {
    let root = SVGBackend::new(file, (1100, 760)).into_drawing_area();
    let draw = || -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let h = root.dim_in_pixel().1;
        let (panel, strips) = root.split_vertically(h - 80);
        let (strip1, strip2) = strips.split_vertically(40);
        let series: Vec<(&[f64], &[Class], RGBColor)> = list
            .iter()
            .enumerate()
            .map(|(k, d)| {
                (
                    d.lambda_n.as_slice(),
                    d.classes.as_slice(),
                    PALETTE[k % PALETTE.len()],
                )
            })
            .collect();
        node_panel(&panel, title, "λν  [E·L]", &series)?;
        let lines: Vec<Entry> = list
            .iter()
            .enumerate()
            .map(|(k, d)| Entry::Line(PALETTE[k % PALETTE.len()], format!("α = {}", d.alpha)))
            .collect();
        legend_strip(&strip1, &lines)?;
        legend_strip(&strip2, &class_entries())?;
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(plot_err(file))
}

/// Figure 1: the mesh, with the clamped side, the contact side and the loaded sides.
pub fn plot_mesh(spec: &RectSpec, file: &FsPath) -> Result<()> {
    let (lx, ly) = (spec.lx, spec.ly);
    let pad = 0.22 * lx.max(ly);
    let top_pad = 0.45 * lx.max(ly);
    // equal scales on both axes: plot width ≈ 1100 − 60 (labels) − 30 (margins)
    let px_per_l = 1010.0 / (lx + 2.0 * pad);
    let height = ((ly + pad + top_pad) * px_per_l + 120.0).clamp(300.0, 2000.0) as u32;
    let root = SVGBackend::new(file, (1100, height)).into_drawing_area();
    let draw = || -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "Case study mesh: Q1, {}×{} nodes, n = {}, p = {}",
                    spec.nx,
                    spec.ny,
                    spec.n(),
                    spec.p()
                ),
                (FONT, 22),
            )
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(-pad..lx + pad, -pad..ly + top_pad)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x  [L]")
            .y_desc("y  [L]")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(|e| e.to_string())?;
        let (hx, hy) = spec.h();
        let grey = RGBColor(150, 150, 150).stroke_width(1);
        for i in 0..spec.nx {
            let x = i as f64 * hx;
            chart
                .draw_series(LineSeries::new([(x, 0.0), (x, ly)], grey))
                .map_err(|e| e.to_string())?;
        }
        for j in 0..spec.ny {
            let y = j as f64 * hy;
            chart
                .draw_series(LineSeries::new([(0.0, y), (lx, y)], grey))
                .map_err(|e| e.to_string())?;
        }
        // clamped side: thick line with hatching
        let clamp = RGBColor(60, 60, 60);
        chart
            .draw_series(LineSeries::new(
                [(0.0, 0.0), (0.0, ly)],
                clamp.stroke_width(4),
            ))
            .map_err(|e| e.to_string())?
            .label("clamped side (u = 0)")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x - 8, y), (x + 12, y)], clamp.stroke_width(4))
            });
        let nh = 14;
        for k in 0..=nh {
            let y = ly * k as f64 / nh as f64;
            chart
                .draw_series(LineSeries::new(
                    [(0.0, y), (-0.06 * lx, y - 0.06 * lx)],
                    clamp.stroke_width(1),
                ))
                .map_err(|e| e.to_string())?;
        }
        // foundation and contact nodes
        let found = RGBColor(140, 90, 40);
        chart
            .draw_series(LineSeries::new(
                [(-0.02 * lx, 0.0), (lx + 0.05 * lx, 0.0)],
                found.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?
            .label("rigid foundation")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x - 8, y), (x + 12, y)], found.stroke_width(2))
            });
        for k in 0..=2 * spec.nx {
            let x = lx * 1.05 * k as f64 / (2 * spec.nx) as f64 - 0.02 * lx;
            chart
                .draw_series(LineSeries::new(
                    [(x, 0.0), (x - 0.03 * lx, -0.04 * lx)],
                    found.stroke_width(1),
                ))
                .map_err(|e| e.to_string())?;
        }
        let red = PALETTE[3];
        chart
            .draw_series(
                (0..spec.p()).map(|i| Circle::new((spec.contact_x(i), 0.0), 4, red.filled())),
            )
            .map_err(|e| e.to_string())?
            .label(format!("contact nodes i = 1..{} (Γ_C)", spec.p()))
            .legend(move |(x, y)| Circle::new((x, y), 4, red.filled()));
        for i in [0, spec.p() / 2, spec.p() - 1] {
            chart
                .draw_series([Text::new(
                    format!("{}", i + 1),
                    (spec.contact_x(i) - 0.3 * hx, -0.11 * lx),
                    (FONT, 13).into_font().color(&red),
                )])
                .map_err(|e| e.to_string())?;
        }
        // tractions: arrows at a few points of each loaded side
        let arrow_len = 0.12 * lx.max(ly);
        let loads = [
            (&spec.load0, PALETTE[0], "f0"),
            (&spec.load1, PALETTE[2], "α·f1"),
        ];
        for (li, (tracs, color, name)) in loads.into_iter().enumerate() {
            let maxmag = tracs
                .iter()
                .flat_map(|t| [t.start, t.end])
                .map(|v| v[0].hypot(v[1]))
                .fold(0.0, f64::max);
            if maxmag == 0.0 {
                continue;
            }
            let mut first = true;
            for t in tracs.iter() {
                // f0 arrows at the ends and every eighth of the side, α·f1 arrows halfway
                // between them, so the two loads do not hide each other
                let m = 8;
                for k in 0..=(m - li) {
                    let s = (k as f64 + 0.5 * li as f64) / m as f64;
                    let (x, y) = match t.side {
                        Side::Bottom => (s * lx, 0.0),
                        Side::Top => (s * lx, ly),
                        Side::Left => (0.0, s * ly),
                        Side::Right => (lx, s * ly),
                    };
                    let v = [
                        t.start[0] * (1.0 - s) + t.end[0] * s,
                        t.start[1] * (1.0 - s) + t.end[1] * s,
                    ];
                    let mag = v[0].hypot(v[1]);
                    if mag < 1e-3 * maxmag {
                        continue;
                    }
                    let sc = arrow_len / maxmag;
                    // arrows end on the boundary for pushing loads, start on it otherwise
                    let out = match t.side {
                        Side::Top => [0.0, 1.0],
                        Side::Bottom => [0.0, -1.0],
                        Side::Left => [-1.0, 0.0],
                        Side::Right => [1.0, 0.0],
                    };
                    let normal = v[0] * out[0] + v[1] * out[1];
                    let pushing = normal < 0.0;
                    // mainly tangential tractions are drawn a little outside the side
                    let (x, y) = if normal.abs() < 0.5 * mag {
                        let off = 0.05 * lx.max(ly);
                        (x + off * out[0], y + off * out[1])
                    } else {
                        (x, y)
                    };
                    let (x0, y0, x1, y1) = if pushing {
                        (x - v[0] * sc, y - v[1] * sc, x, y)
                    } else {
                        (x, y, x + v[0] * sc, y + v[1] * sc)
                    };
                    let a = chart
                        .draw_series(LineSeries::new([(x0, y0), (x1, y1)], color.stroke_width(2)))
                        .map_err(|e| e.to_string())?;
                    if first {
                        let lab = format!(
                            "{name}: {}",
                            tracs
                                .iter()
                                .map(|t| format!(
                                    "{} ({}, {}) → ({}, {})",
                                    t.side.name(),
                                    t.start[0],
                                    t.start[1],
                                    t.end[0],
                                    t.end[1]
                                ))
                                .collect::<Vec<_>>()
                                .join("; ")
                        );
                        a.label(lab).legend(move |(x, y)| {
                            PathElement::new(vec![(x - 8, y), (x + 12, y)], color.stroke_width(2))
                        });
                        first = false;
                    }
                    // arrow head
                    let (dx, dy) = (x1 - x0, y1 - y0);
                    let l = dx.hypot(dy);
                    let (ux, uy) = (dx / l, dy / l);
                    let hl = 0.025 * lx.max(ly);
                    let head = [
                        (x1 - hl * ux + 0.5 * hl * uy, y1 - hl * uy - 0.5 * hl * ux),
                        (x1, y1),
                        (x1 - hl * ux - 0.5 * hl * uy, y1 - hl * uy + 0.5 * hl * ux),
                    ];
                    chart
                        .draw_series(LineSeries::new(head, color.stroke_width(2)))
                        .map_err(|e| e.to_string())?;
                }
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.mix(0.5))
            .label_font((FONT, 13))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(plot_err(file))
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

/// The path figure: top, the total contact forces `Σλν`, `Σλt` against α; bottom, `λν`
/// of the nodes in `nodes` (0-based) against α. Transition points are marked and
/// numbered; folds (α turning back) get a red triangle.
pub fn plot_path(
    pieces: &[PieceLine],
    points: &[MarkedPoint],
    nodes: &[usize],
    title: &str,
    file: &FsPath,
) -> Result<()> {
    let root = SVGBackend::new(file, (1200, 1000)).into_drawing_area();
    let draw = || -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root.titled(title, (FONT, 22)).map_err(|e| e.to_string())?;
        let (top, bottom) = root.split_vertically(470);
        let ar = range(pieces.iter().flat_map(|p| [p.alpha_from, p.alpha_to]));
        // top panel
        let yr = range(pieces.iter().flat_map(|p| {
            [
                sum(&p.lambda_n_from),
                sum(&p.lambda_n_to),
                sum(&p.lambda_t_from),
                sum(&p.lambda_t_to),
                0.0,
            ]
        }));
        let yspan = yr.end - yr.start;
        let mut chart = ChartBuilder::on(&top)
            .caption("total contact forces along the path", (FONT, 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(75)
            .build_cartesian_2d(ar.clone(), yr.clone())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("load parameter α  [–]")
            .y_desc("Σ λ  [E·L]")
            .y_label_formatter(&|v: &f64| tick(*v, yspan))
            .light_line_style(WHITE.mix(0.0))
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(|e| e.to_string())?;
        for (k, (name, getf, gett)) in [
            (
                "Σ λν (normal)",
                (|p: &PieceLine| sum(&p.lambda_n_from)) as fn(&PieceLine) -> f64,
                (|p: &PieceLine| sum(&p.lambda_n_to)) as fn(&PieceLine) -> f64,
            ),
            (
                "Σ λt (tangential)",
                |p: &PieceLine| sum(&p.lambda_t_from),
                |p: &PieceLine| sum(&p.lambda_t_to),
            ),
        ]
        .into_iter()
        .enumerate()
        {
            let c = PALETTE[k];
            let mut first = true;
            for p in pieces {
                let a = chart
                    .draw_series(LineSeries::new(
                        [(p.alpha_from, getf(p)), (p.alpha_to, gett(p))],
                        c.stroke_width(2),
                    ))
                    .map_err(|e| e.to_string())?;
                if first {
                    a.label(name).legend(move |(x, y)| {
                        PathElement::new(vec![(x - 8, y), (x + 12, y)], c.stroke_width(3))
                    });
                    first = false;
                }
            }
            draw_points(
                &mut chart,
                points,
                |m| {
                    (
                        m.alpha,
                        if k == 0 {
                            sum(&m.lambda_n)
                        } else {
                            sum(&m.lambda_t)
                        },
                    )
                },
                (k == 0).then_some(ar.end - ar.start),
            )?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .label_font((FONT, 13))
            .draw()
            .map_err(|e| e.to_string())?;
        // bottom panel
        let yr = range(pieces.iter().flat_map(|p| {
            nodes
                .iter()
                .flat_map(|&i| [p.lambda_n_from[i], p.lambda_n_to[i]])
                .chain([0.0])
                .collect::<Vec<_>>()
        }));
        let yspan = yr.end - yr.start;
        let mut chart = ChartBuilder::on(&bottom)
            .caption("normal contact force of selected nodes", (FONT, 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(75)
            .build_cartesian_2d(ar, yr.clone())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("load parameter α  [–]")
            .y_desc("λν_i  [E·L]")
            .y_label_formatter(&|v: &f64| tick(*v, yspan))
            .light_line_style(WHITE.mix(0.0))
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(|e| e.to_string())?;
        for (k, &i) in nodes.iter().enumerate() {
            let c = PALETTE[k % PALETTE.len()];
            let mut first = true;
            for p in pieces {
                let a = chart
                    .draw_series(LineSeries::new(
                        [
                            (p.alpha_from, p.lambda_n_from[i]),
                            (p.alpha_to, p.lambda_n_to[i]),
                        ],
                        c.stroke_width(2),
                    ))
                    .map_err(|e| e.to_string())?;
                if first {
                    a.label(format!("node {}", i + 1)).legend(move |(x, y)| {
                        PathElement::new(vec![(x - 8, y), (x + 12, y)], c.stroke_width(3))
                    });
                    first = false;
                }
            }
            let own: Vec<MarkedPoint> = points.iter().filter(|m| m.node == i).cloned().collect();
            draw_points(&mut chart, &own, |m| (m.alpha, m.lambda_n[i]), None)?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .label_font((FONT, 13))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(plot_err(file))
}

/// Marks transition points (black dots, numbered when `numbers`) and folds (red
/// triangles).
fn draw_points<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    points: &[MarkedPoint],
    at: impl Fn(&MarkedPoint) -> (f64, f64),
    numbers: Option<f64>,
) -> std::result::Result<(), String> {
    chart
        .draw_series(
            points
                .iter()
                .filter(|m| !m.fold)
                .map(|m| Circle::new(at(m), 3, BLACK.filled())),
        )
        .map_err(|e| e.to_string())?;
    let red = PALETTE[3];
    let a = chart
        .draw_series(
            points
                .iter()
                .filter(|m| m.fold)
                .map(|m| TriangleMarker::new(at(m), 7, red.filled())),
        )
        .map_err(|e| e.to_string())?;
    if let Some(alpha_span) = numbers {
        a.label("fold (α turns back)")
            .legend(move |(x, y)| TriangleMarker::new((x, y), 7, red.filled()));
        chart
            .draw_series(
                points
                    .iter()
                    .filter(|m| !m.fold)
                    .take(0)
                    .map(|m| Circle::new(at(m), 3, BLACK.filled())),
            )
            .map_err(|e| e.to_string())?
            .label("transition point k")
            .legend(|(x, y)| Circle::new((x, y), 3, BLACK.filled()));
        // one label per cluster of transition points closer than 2% of the α range
        let mut clusters: Vec<(usize, Vec<usize>)> = Vec::new();
        for (k, m) in points.iter().enumerate() {
            match clusters.last_mut() {
                Some((first, ts)) if (points[*first].alpha - m.alpha).abs() < 0.04 * alpha_span => {
                    if !ts.contains(&m.transition) {
                        ts.push(m.transition);
                    }
                }
                _ => clusters.push((k, vec![m.transition])),
            }
        }
        for (first, ts) in clusters {
            let text = if ts.len() > 3 {
                format!("{}–{}", ts[0], ts[ts.len() - 1])
            } else {
                ts.iter()
                    .map(|t| t.to_string())
                    .collect::<Vec<_>>()
                    .join(",")
            };
            chart
                .draw_series([
                    EmptyElement::at(at(&points[first])) + Text::new(text, (3, -16), (FONT, 12))
                ])
                .map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

/// All solutions at one α (high-friction variant): λν and λt against the node index,
/// one colour per solution, markers by class.
pub fn plot_solutions(
    list: &[ContactData],
    labels: &[String],
    title: &str,
    file: &FsPath,
) -> Result<()> {
    let root = SVGBackend::new(file, (1200, 1300)).into_drawing_area();
    let draw = || -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root.titled(title, (FONT, 22)).map_err(|e| e.to_string())?;
        let h = root.dim_in_pixel().1;
        let (panels, strips) = root.split_vertically(h - 80);
        let areas = panels.split_evenly((3, 1));
        let (strip1, strip2) = strips.split_vertically(40);
        let ser = |f: fn(&ContactData) -> &[f64]| -> Vec<(&[f64], &[Class], RGBColor)> {
            list.iter()
                .enumerate()
                .map(|(k, d)| (f(d), d.classes.as_slice(), PALETTE[k % PALETTE.len()]))
                .collect()
        };
        node_panel(
            &areas[0],
            "normal contact force λν",
            "λν  [E·L]",
            &ser(|d| &d.lambda_n),
        )?;
        node_panel(
            &areas[1],
            "tangential contact force λt",
            "λt  [E·L]",
            &ser(|d| &d.lambda_t),
        )?;
        node_panel(
            &areas[2],
            "normal displacement uν = −u_y (< 0: lifted off)",
            "uν  [L]",
            &ser(|d| &d.u_n),
        )?;
        let lines: Vec<Entry> = (0..list.len())
            .map(|k| {
                let l = labels
                    .get(k)
                    .cloned()
                    .unwrap_or_else(|| format!("solution {}", k + 1));
                Entry::Line(PALETTE[k % PALETTE.len()], l)
            })
            .collect();
        legend_strip(&strip1, &lines)?;
        legend_strip(&strip2, &class_entries())?;
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(plot_err(file))
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
    if let Some(start) = path.start_state().cloned() {
        v["start"]["state"] = vertex(&start);
    }
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
    if let Some(st) = path.start_state() {
        row("start", 0, st);
    }
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
/// `fig1_mesh.svg`, `fig2_snapshot.svg`, `fig3_profiles.svg`, `fig4_path.svg`,
/// `path.json`, `path.csv` (vertices), `events.csv`, and for the high-friction variant
/// `high-friction/` with its own `problem/`, `transitions.txt`, `path.svg`,
/// `solutions.svg`, `path.json`, `path.csv`, `events.csv`.
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

    plot_mesh(spec, &out.join("fig1_mesh.svg"))?;
    files.push(out.join("fig1_mesh.svg"));

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
        plot_snapshot(
            &d,
            &format!(
                "Contact data at the {} contact nodes for α = {}{extra}",
                spec.p(),
                snap_alpha
            ),
            &out.join("fig2_snapshot.svg"),
        )?;
        files.push(out.join("fig2_snapshot.svg"));
    }

    // Figure 3: profiles by the cheap solution at any α
    let mut profiles = Vec::new();
    for &a in &opts.profile_alphas {
        for sol in tr.path.solutions_at(a)? {
            profiles.push(ContactData::from_state(&sol.state, &case));
        }
    }
    plot_profiles(
        &profiles,
        "Profiles of the normal contact force λν (by the solution at any α from the traced path)",
        &out.join("fig3_profiles.svg"),
    )?;
    files.push(out.join("fig3_profiles.svg"));

    // Figure 4: the path
    plot_path(
        &piece_lines(&tr.path),
        &marked_points(&tr.path),
        &event_nodes(&tr.path),
        &format!(
            "The traced path, α from {} to {} (F = {}): {} transition points",
            spec.alpha_start,
            spec.alpha_end,
            spec.friction,
            rows.last().map_or(0, |r| r.transition)
        ),
        &out.join("fig4_path.svg"),
    )?;
    files.push(out.join("fig4_path.svg"));

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
        Some(v) => Some(run_fold_variant(v, &out.join("high-friction"), &mut files)?),
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

/// An α inside a fold region where the traced path has the most solutions: the middle
/// of the widest gap between consecutive distinct transition α's among the gaps covered
/// by the largest number of traced (non-vertical) pieces. `None` when no α has two.
fn fold_query(path: &Path) -> Option<f64> {
    let mut alphas: Vec<f64> = path.events().iter().map(|e| e.alpha).collect();
    for r in path.pieces() {
        alphas.push(r.alpha_from);
        alphas.push(r.alpha_to);
    }
    alphas.sort_by(f64::total_cmp);
    alphas.dedup();
    let mut best: Option<(usize, f64, f64)> = None;
    for w in alphas.windows(2) {
        let (a, width) = (0.5 * (w[0] + w[1]), w[1] - w[0]);
        let count = path
            .pieces()
            .iter()
            .filter(|r| r.alpha_from.min(r.alpha_to) < a && a < r.alpha_from.max(r.alpha_to))
            .count();
        let better = match best {
            None => true,
            Some((c, wd, _)) => count > c || (count == c && width > wd),
        };
        if better {
            best = Some((count, width, a));
        }
    }
    best.filter(|b| b.0 >= 2).map(|b| b.2)
}

fn run_fold_variant(v: &FoldVariant, out: &FsPath, files: &mut Vec<PathBuf>) -> Result<FoldReport> {
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
        plot_solutions(
            &data,
            &labels,
            &format!(
                "F = {}: all {} solutions at α = {} (inside a fold region)",
                spec.friction,
                n_sol,
                fmt_alpha(a)
            ),
            &out.join("solutions.svg"),
        )?;
        files.push(out.join("solutions.svg"));
    } else {
        table.push_str("no fold on this path\n");
    }
    write(out.join("transitions.txt"), &table, files)?;
    plot_path(
        &piece_lines(&tr.path),
        &marked_points(&tr.path),
        &event_nodes(&tr.path),
        &format!(
            "High-friction variant (F = {}): the traced path, {} folds",
            spec.friction, folds
        ),
        &out.join("path.svg"),
    )?;
    files.push(out.join("path.svg"));
    // a zoom on the folds
    let fold_alphas: Vec<f64> = rows.iter().filter(|r| r.fold).map(|r| r.alpha).collect();
    if !fold_alphas.is_empty() {
        let (lo, hi) = fold_alphas
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        let w = (hi - lo).max(1e-3 * (spec.alpha_end - spec.alpha_start).abs());
        let (lo, hi) = (lo - 0.15 * w, hi + 0.15 * w);
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
        plot_path(
            &pieces,
            &points,
            &nodes,
            &format!(
                "High-friction variant (F = {}): zoom on the folds, α ∈ [{:.4}, {:.4}]",
                spec.friction, lo, hi
            ),
            &out.join("path_folds.svg"),
        )?;
        files.push(out.join("path_folds.svg"));
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

    fn synthetic(p: usize, alpha: f64) -> ContactData {
        let classes: Vec<Class> = (0..p).map(|i| Class::ALL[i % 4]).collect();
        ContactData {
            alpha,
            lambda_n: (0..p)
                .map(|i| {
                    if i % 4 == 0 {
                        0.0
                    } else {
                        -(i as f64) * 0.01 * (1.0 + alpha)
                    }
                })
                .collect(),
            lambda_t: (0..p).map(|i| 0.003 * i as f64 - 0.02).collect(),
            u_n: (0..p)
                .map(|i| if i % 4 == 0 { -1e-3 * i as f64 } else { 0.0 })
                .collect(),
            u_t: (0..p).map(|i| 1e-4 * (i as f64).sin()).collect(),
            classes,
        }
    }

    #[test]
    fn figures_draw_on_synthetic_data() {
        let dir = std::env::temp_dir().join(format!("fricont-fig-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let spec = RectSpec::default();
        plot_mesh(&spec, &dir.join("mesh.svg")).unwrap();
        let d = synthetic(30, 3.6);
        plot_snapshot(&d, "snapshot", &dir.join("snap.svg")).unwrap();
        let list: Vec<ContactData> = [-0.5, 0.0, 0.5, 1.0, 1.5]
            .iter()
            .map(|&a| synthetic(30, a))
            .collect();
        plot_profiles(&list, "profiles", &dir.join("prof.svg")).unwrap();
        plot_solutions(&list[..3], &[], "solutions", &dir.join("sols.svg")).unwrap();
        let pieces: Vec<PieceLine> = (0..4)
            .map(|k| {
                let a = [0.0, 1.0, 0.5, 1.5, 2.0][k];
                let b = [0.0, 1.0, 0.5, 1.5, 2.0][k + 1];
                PieceLine {
                    alpha_from: a,
                    alpha_to: b,
                    lambda_n_from: vec![-a; 30],
                    lambda_n_to: vec![-b; 30],
                    lambda_t_from: vec![0.1 * a; 30],
                    lambda_t_to: vec![0.1 * b; 30],
                }
            })
            .collect();
        let pts: Vec<MarkedPoint> = (1..4)
            .map(|k| MarkedPoint {
                transition: k,
                alpha: pieces[k].alpha_from,
                lambda_n: pieces[k].lambda_n_from.clone(),
                lambda_t: pieces[k].lambda_t_from.clone(),
                fold: k == 1,
                node: k,
            })
            .collect();
        plot_path(&pieces, &pts, &[0, 5, 12], "path", &dir.join("path.svg")).unwrap();
        for f in ["mesh", "snap", "prof", "sols", "path"] {
            let s = std::fs::read_to_string(dir.join(format!("{f}.svg"))).unwrap();
            assert!(s.starts_with("<svg") && s.contains("</svg>"), "{f}");
        }
        let s = std::fs::read_to_string(dir.join("snap.svg")).unwrap();
        for label in [
            "contact node i",
            "λν  [E·L]",
            "uν  [L]",
            "no contact",
            "contact, stick",
        ] {
            assert!(s.contains(label), "snapshot lacks {label}");
        }
        let s = std::fs::read_to_string(dir.join("path.svg")).unwrap();
        assert!(s.contains("fold (α turns back)") && s.contains("load parameter α"));
        if std::env::var_os("FRICONT_KEEP_FIGS").is_none() {
            std::fs::remove_dir_all(&dir).unwrap();
        } else {
            eprintln!("figures kept in {}", dir.display());
        }
    }
}
