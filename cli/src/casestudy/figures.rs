//! The case study's figures, laid out for print.
//!
//! Every figure is drawn as SVG ([plotters]) [`FIG_WIDTH`] pixels wide and is meant to be
//! printed [`PRINT_WIDTH_CM`] wide (a page's text width): all text is at least
//! [`MIN_TEXT_PT`] there, so font sizes are computed from the figure's width
//! ([`pt_to_px`]). Legends are drawn outside the plot areas (in a strip below them), list
//! only what was drawn, and show each series' own colour and marker. A PNG is rendered
//! beside each SVG ([`write_png`]: resvg, [`png_width`] pixels wide, i.e. 16 cm at
//! [`PNG_DPI`]) with the font embedded in the program (DejaVu Sans, `cli/fonts/`), so it
//! needs no font installed on the machine.
//!
//! Each drawing function returns a [`FigureLayout`]: where the plot areas, the data and
//! the legends landed, in SVG pixels, so that tests can check the print rules on the
//! coordinates actually drawn.

use std::ops::Range;
use std::path::{Path as FsPath, PathBuf};
use std::sync::{Arc, OnceLock};

use plotters::coord::Shift;
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use fricont::class::Class;
use fricont_exchange::generator::{RectSpec, Side};
use fricont_exchange::{Error, Result};

use super::{ContactData, MarkedPoint, PieceLine};

/// Width at which the figures are meant to be printed, centimetres.
pub const PRINT_WIDTH_CM: f64 = 16.0;
/// Smallest text on any figure, points, when printed [`PRINT_WIDTH_CM`] wide.
pub const MIN_TEXT_PT: f64 = 8.0;
/// Resolution of the PNGs at the print width, dots per inch.
pub const PNG_DPI: f64 = 300.0;
/// Width of every figure, SVG pixels (user units).
pub const FIG_WIDTH: u32 = 1000;

/// Width of the PNGs, pixels: [`PRINT_WIDTH_CM`] at [`PNG_DPI`] (1890).
pub fn png_width() -> u32 {
    (PRINT_WIDTH_CM / 2.54 * PNG_DPI).round() as u32
}

/// SVG pixels of a length of `pt` points on a figure printed [`PRINT_WIDTH_CM`] wide.
pub fn pt_to_px(pt: f64) -> f64 {
    pt * f64::from(FIG_WIDTH) / (PRINT_WIDTH_CM / 2.54 * 72.0)
}

// Text sizes, points at the print width (all ≥ MIN_TEXT_PT).
const TICK_PT: f64 = 8.5;
const LABEL_PT: f64 = 9.0;
const CAPTION_PT: f64 = 9.5;
const TITLE_PT: f64 = 10.5;
const LEGEND_PT: f64 = 8.5;
const NOTE_PT: f64 = 8.2;

/// plotters' SVG backend writes `font-size = size / 1.24` (plotters-svg 0.3, `draw_text`).
const PLOTTERS_SVG_FONT: f64 = 1.24;

/// The plotters font of `pt` points at the print width.
fn font(pt: f64) -> FontDesc<'static> {
    FontDesc::new(
        FontFamily::SansSerif,
        pt_to_px(pt) * PLOTTERS_SVG_FONT,
        FontStyle::Normal,
    )
}

/// The figures' font, embedded: DejaVu Sans 2.37 (Bitstream Vera licence, public-domain
/// changes: `cli/fonts/LICENSE-DejaVu`). It covers every glyph the figures use (Greek,
/// arrows, ≤, ∈, ·, superscripts).
static FONT_TTF: &[u8] = include_bytes!("../../fonts/DejaVuSans.ttf");
const FONT_FAMILY: &str = "DejaVu Sans";

fn fontdb() -> Arc<resvg::usvg::fontdb::Database> {
    static DB: OnceLock<Arc<resvg::usvg::fontdb::Database>> = OnceLock::new();
    DB.get_or_init(|| {
        let mut db = resvg::usvg::fontdb::Database::new();
        db.load_font_data(FONT_TTF.to_vec());
        db.set_sans_serif_family(FONT_FAMILY);
        Arc::new(db)
    })
    .clone()
}

/// usvg's options: the embedded font only (for `sans-serif` and as the default family).
fn svg_options() -> resvg::usvg::Options<'static> {
    let mut o = resvg::usvg::Options {
        font_family: FONT_FAMILY.into(),
        ..Default::default()
    };
    o.fontdb = fontdb();
    o
}

/// Width in SVG pixels of `text` set in the embedded font at `pt` points (print width),
/// as resvg lays it out.
fn text_width(text: &str, pt: f64) -> f64 {
    let size = pt_to_px(pt);
    let escaped = text
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;");
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="8000" height="400"><text x="0" y="200" font-family="sans-serif" font-size="{size}">{escaped}</text></svg>"#
    );
    match resvg::usvg::Tree::from_str(&svg, &svg_options()) {
        Ok(t) if !text.trim().is_empty() && t.root().has_children() => {
            f64::from(t.root().abs_bounding_box().right())
        }
        // never reached with the embedded font; a generous estimate otherwise
        _ => 0.65 * size * text.chars().count() as f64,
    }
}

/// Renders the SVG file `svg` to a PNG beside it (same name, `.png`): [`png_width`] pixels
/// wide, the height in proportion, opaque RGB, the resolution ([`PNG_DPI`]) in its `pHYs`
/// chunk, text in the embedded font. Returns the PNG's path. Errors: the SVG cannot be
/// read or parsed, the PNG cannot be written.
pub fn write_png(svg: &FsPath) -> Result<PathBuf> {
    let png_file = svg.with_extension("png");
    let fail = |what: &str, e: &dyn std::fmt::Display| {
        Error::Io(format!("cannot {what} {}: {e}", png_file.display()))
    };
    let data = std::fs::read(svg).map_err(|e| fail("read the SVG for", &e))?;
    let tree = resvg::usvg::Tree::from_data(&data, &svg_options())
        .map_err(|e| fail("parse the SVG for", &e))?;
    let size = tree.size();
    let w = png_width();
    let scale = w as f32 / size.width();
    let h = (size.height() * scale).round().max(1.0) as u32;
    let mut pix = resvg::tiny_skia::Pixmap::new(w, h)
        .ok_or_else(|| fail("allocate", &format!("{w} × {h} pixels")))?;
    pix.fill(resvg::tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::from_scale(scale, scale),
        &mut pix.as_mut(),
    );
    let rgb: Vec<u8> = pix
        .pixels()
        .iter()
        .flat_map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue()]
        })
        .collect();
    let file = std::fs::File::create(&png_file).map_err(|e| fail("create", &e))?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let per_metre = (PNG_DPI / 0.0254).round() as u32;
    enc.set_pixel_dims(Some(png::PixelDimensions {
        xppu: per_metre,
        yppu: per_metre,
        unit: png::Unit::Meter,
    }));
    let mut wr = enc.write_header().map_err(|e| fail("write", &e))?;
    wr.write_image_data(&rgb).map_err(|e| fail("write", &e))?;
    wr.finish().map_err(|e| fail("write", &e))?;
    Ok(png_file)
}

/// A rectangle in SVG pixels (origin at the top left, y down), edges included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PxRect {
    /// Left edge.
    pub x0: f64,
    /// Top edge.
    pub y0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y1: f64,
}

impl PxRect {
    /// The square of half-side `half` around `c`.
    fn around(c: (i32, i32), half: i32) -> Self {
        let (x, y, h) = (f64::from(c.0), f64::from(c.1), f64::from(half));
        Self {
            x0: x - h,
            y0: y - h,
            x1: x + h,
            y1: y + h,
        }
    }

    /// Whether the two rectangles share a point.
    pub fn intersects(&self, o: &PxRect) -> bool {
        self.x0 <= o.x1 && o.x0 <= self.x1 && self.y0 <= o.y1 && o.y0 <= self.y1
    }

    /// Whether `o` lies inside this rectangle.
    pub fn contains(&self, o: &PxRect) -> bool {
        self.x0 <= o.x0 && o.x1 <= self.x1 && self.y0 <= o.y0 && o.y1 <= self.y1
    }
}

/// Where a figure put its parts, in SVG pixels: what the tests check the print rules on.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FigureLayout {
    /// Canvas width.
    pub width: u32,
    /// Canvas height.
    pub height: u32,
    /// The charts' plot areas (inside the axes).
    pub plots: Vec<PxRect>,
    /// Every drawn data item: the box of each marker and of each arrow head, each vertex
    /// of a data line (a zero-size box).
    pub data: Vec<PxRect>,
    /// Legend boxes (the extent of their symbols and text).
    pub legends: Vec<PxRect>,
    /// Legend entries, in the order shown.
    pub legend_entries: Vec<String>,
    /// What was drawn, under the legend label it has (or would have), with the number of
    /// elements drawn.
    pub drawn: Vec<(String, usize)>,
    /// The α axis of a path figure (its x range).
    pub alpha_axis: Option<(f64, f64)>,
}

impl FigureLayout {
    fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            ..Default::default()
        }
    }

    /// Number of elements drawn under `label` (as the legend writes it: numbers with a
    /// true minus sign).
    pub fn drawn_count(&self, label: &str) -> usize {
        let label = minus_numbers(label);
        self.drawn
            .iter()
            .filter(|d| d.0 == label)
            .map(|d| d.1)
            .sum()
    }

    fn add_drawn(&mut self, label: &str, count: usize) {
        let label = minus_numbers(label);
        match self.drawn.iter_mut().find(|d| d.0 == label) {
            Some(d) => d.1 += count,
            None => self.drawn.push((label, count)),
        }
    }

    fn plot_of<DB: DrawingBackend, CT: CoordTranslate>(&mut self, area: &DrawingArea<DB, CT>) {
        let (xr, yr) = area.get_pixel_range();
        self.plots.push(PxRect {
            x0: f64::from(xr.start),
            y0: f64::from(yr.start),
            x1: f64::from(xr.end),
            y1: f64::from(yr.end),
        });
    }
}

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
/// The colour of the class-marker key when several series share the markers.
const KEY_GREY: RGBColor = RGBColor(90, 90, 90);
const FOLD_RED: RGBColor = RGBColor(214, 39, 40);

/// The markers of the figures: classes (circle: no contact, diamond: stick, filled
/// square: slip +x, open square: slip −x), transition points, folds, contact nodes, and
/// a line (for legends).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Marker {
    Class(Class),
    Transition,
    Fold,
    Node,
    Line,
}

impl Marker {
    /// Half the marker's extent, pixels.
    fn half(self) -> i32 {
        match self {
            Marker::Class(Class::Stick) => 7,
            Marker::Class(_) => 5,
            Marker::Transition => 4,
            Marker::Fold => 8,
            Marker::Node => 4,
            Marker::Line => 14,
        }
    }

    /// Draws the marker centred at `at` (a coordinate of `area`).
    fn draw<DB: DrawingBackend, CT: CoordTranslate>(
        self,
        area: &DrawingArea<DB, CT>,
        at: CT::From,
        color: RGBColor,
    ) -> std::result::Result<(), String>
    where
        CT::From: Clone + 'static,
    {
        let e = |err: plotters::drawing::DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
        let h = self.half();
        let hollow = color.stroke_width(2);
        match self {
            Marker::Class(Class::Open) => area
                .draw(&(EmptyElement::at(at) + Circle::new((0, 0), h, hollow)))
                .map_err(e),
            Marker::Class(Class::Stick) => area
                .draw(
                    &(EmptyElement::at(at)
                        + Polygon::new(vec![(0, -h), (h, 0), (0, h), (-h, 0)], color.filled())),
                )
                .map_err(e),
            Marker::Class(Class::SlipPlus) => area
                .draw(&(EmptyElement::at(at) + Rectangle::new([(-h, -h), (h, h)], color.filled())))
                .map_err(e),
            Marker::Class(Class::SlipMinus) => area
                .draw(&(EmptyElement::at(at) + Rectangle::new([(-h, -h), (h, h)], hollow)))
                .map_err(e),
            Marker::Transition | Marker::Node => area
                .draw(&(EmptyElement::at(at) + Circle::new((0, 0), h, color.filled())))
                .map_err(e),
            Marker::Fold => area
                .draw(&(EmptyElement::at(at) + TriangleMarker::new((0, 0), h, color.filled())))
                .map_err(e),
            Marker::Line => area
                .draw(
                    &(EmptyElement::at(at)
                        + PathElement::new(vec![(-h, 0), (h, 0)], color.stroke_width(3))),
                )
                .map_err(e),
        }
    }
}

/// The paper's words for a class (legend labels).
fn class_label(c: Class) -> &'static str {
    match c {
        Class::Open => "no contact",
        Class::Stick => "contact, stick",
        Class::SlipPlus => "contact, slip +x",
        Class::SlipMinus => "contact, slip −x",
    }
}

/// A legend entry: the series' marker (or line) in its colour, and its label.
struct Item {
    marker: Marker,
    color: RGBColor,
    label: String,
}

impl Item {
    /// An entry; numbers in the label get a true minus sign.
    fn new(marker: Marker, color: RGBColor, label: impl Into<String>) -> Self {
        Self {
            marker,
            color,
            label: minus_numbers(&label.into()),
        }
    }
}

const LEGEND_SYMBOL: f64 = 30.0;
const LEGEND_GAP: f64 = 8.0;
const LEGEND_SPACING: f64 = 26.0;

fn legend_row_height() -> f64 {
    1.7 * pt_to_px(LEGEND_PT)
}

fn item_width(it: &Item) -> f64 {
    LEGEND_SYMBOL + LEGEND_GAP + text_width(&it.label, LEGEND_PT)
}

/// The entries in rows no wider than `width` (in order, greedily).
fn legend_rows(items: &[Item], width: f64) -> Vec<Vec<usize>> {
    let mut rows: Vec<Vec<usize>> = Vec::new();
    let mut used = 0.0;
    for (k, it) in items.iter().enumerate() {
        let w = item_width(it);
        match rows.last_mut() {
            Some(r) if used + LEGEND_SPACING + w <= width => {
                r.push(k);
                used += LEGEND_SPACING + w;
            }
            _ => {
                rows.push(vec![k]);
                used = w;
            }
        }
    }
    rows
}

/// Height of the strip that [`draw_legend`] needs for `items` in a strip `width` wide.
fn legend_height(items: &[Item], width: u32) -> u32 {
    let rows = legend_rows(items, f64::from(width) - 20.0).len();
    (rows as f64 * legend_row_height() + 12.0).ceil() as u32
}

/// Draws the entries in rows centred in `area` (a strip outside the plot areas) and
/// records the legend's box and entries.
fn draw_legend(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    items: &[Item],
    rec: &mut FigureLayout,
) -> std::result::Result<(), String> {
    if items.is_empty() {
        return Ok(());
    }
    let (w, h) = area.dim_in_pixel();
    let rows = legend_rows(items, f64::from(w) - 20.0);
    let row_h = legend_row_height();
    let row_w = |r: &Vec<usize>| -> f64 {
        r.iter().map(|&k| item_width(&items[k])).sum::<f64>()
            + LEGEND_SPACING * (r.len() as f64 - 1.0)
    };
    let widest = rows.iter().map(row_w).fold(0.0, f64::max);
    let left = ((f64::from(w) - widest) / 2.0).max(0.0);
    let top = ((f64::from(h) - rows.len() as f64 * row_h) / 2.0).max(0.0);
    let style = TextStyle::from(font(LEGEND_PT)).pos(Pos::new(HPos::Left, VPos::Center));
    for (j, r) in rows.iter().enumerate() {
        let y = (top + (j as f64 + 0.5) * row_h).round() as i32;
        let mut x = left;
        for &k in r {
            let it = &items[k];
            let cx = (x + LEGEND_SYMBOL / 2.0).round() as i32;
            it.marker.draw(area, (cx, y), it.color)?;
            let tx = (x + LEGEND_SYMBOL + LEGEND_GAP).round() as i32;
            area.draw(&Text::new(it.label.clone(), (tx, y), style.clone()))
                .map_err(|e| e.to_string())?;
            rec.legend_entries.push(it.label.clone());
            x += item_width(it) + LEGEND_SPACING;
        }
    }
    let (bx, by) = area.get_base_pixel();
    let text_h = pt_to_px(LEGEND_PT);
    rec.legends.push(PxRect {
        x0: f64::from(bx) + left,
        y0: f64::from(by) + top + 0.5 * row_h - 0.5 * text_h.max(LEGEND_SYMBOL / 2.0),
        x1: f64::from(bx) + left + widest,
        y1: f64::from(by)
            + top
            + (rows.len() as f64 - 0.5) * row_h
            + 0.5 * text_h.max(LEGEND_SYMBOL / 2.0),
    });
    Ok(())
}

/// Draws `text` centred at the top of `area`, in as many lines as it needs, and returns
/// the area below it.
fn titled<'a>(
    area: &DrawingArea<SVGBackend<'a>, Shift>,
    text: &str,
) -> std::result::Result<DrawingArea<SVGBackend<'a>, Shift>, String> {
    let px = pt_to_px(TITLE_PT);
    let (w, _) = area.dim_in_pixel();
    let text = minus_numbers(text);
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ') {
        match lines.last_mut() {
            Some(l) if text_width(&format!("{l} {word}"), TITLE_PT) <= f64::from(w) - 40.0 => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    let line_h = 1.35 * px;
    let style = TextStyle::from(font(TITLE_PT)).pos(Pos::new(HPos::Center, VPos::Center));
    for (k, l) in lines.iter().enumerate() {
        let y = (0.3 * px + (k as f64 + 0.5) * line_h).round() as i32;
        area.draw(&Text::new(l.clone(), (w as i32 / 2, y), style.clone()))
            .map_err(|e| e.to_string())?;
    }
    let h = (0.6 * px + lines.len() as f64 * line_h).round() as i32;
    Ok(area.split_vertically(h).1)
}

fn sum(v: &[f64]) -> f64 {
    v.iter().sum()
}

/// Data range with a margin; never empty.
fn range(vals: impl IntoIterator<Item = f64>) -> Range<f64> {
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

/// The power of ten factored out of an axis (shown in its label) so that its ticks read
/// as short decimals: 0 when the largest |value| lies in [0.01, 10⁴).
fn axis_exponent(r: &Range<f64>) -> i32 {
    let m = r.start.abs().max(r.end.abs());
    if m == 0.0 || !m.is_finite() {
        return 0;
    }
    let e = m.log10().floor() as i32;
    if (-2..4).contains(&e) { 0 } else { e }
}

fn superscript(k: i32) -> String {
    k.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

/// "quantity  [10ᵏ unit]".
fn axis_label(quantity: &str, unit: &str, k: i32) -> String {
    let scale = if k == 0 {
        String::new()
    } else {
        format!("10{}", superscript(k))
    };
    match (scale.is_empty(), unit.is_empty()) {
        (true, true) => quantity.to_string(),
        (true, false) => format!("{quantity}  [{unit}]"),
        (false, true) => format!("{quantity}  [{scale}]"),
        (false, false) => format!("{quantity}  [{scale} {unit}]"),
    }
}

/// Tick label for an axis spanning `span`: one format per axis (decimals when the span
/// is between 0.01 and 1e5, scientific otherwise), no "−0", a true minus sign.
fn tick(v: f64, span: f64) -> String {
    if v.abs() <= 1e-9 * span {
        return "0".into();
    }
    let t = if (0.01..1e5).contains(&span) {
        let digits = (2 - span.log10().floor() as i32).clamp(0, 8) as usize;
        let t = format!("{v:.digits$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    } else {
        format!("{v:.1e}")
    };
    minus(&t)
}

/// A number's text with the minus sign (U+2212) instead of the hyphen.
fn minus(t: &str) -> String {
    t.replace('-', "−")
}

/// `text` with the minus sign (U+2212) for every hyphen that starts a number (a hyphen
/// before a digit or a point, not after a letter or digit: "α = -0.5" but not "x-1").
fn minus_numbers(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    chars
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            let next = chars
                .get(k + 1)
                .is_some_and(|n| n.is_ascii_digit() || *n == '.');
            let prev = k > 0 && chars[k - 1].is_alphanumeric();
            if c == '-' && next && !prev { '−' } else { c }
        })
        .collect()
}

/// A tick formatter for a range with exponent `k`.
fn ticker(r: &Range<f64>, k: i32) -> impl Fn(&f64) -> String + use<> {
    let scale = 10f64.powi(k);
    let span = (r.end - r.start) / scale;
    move |v: &f64| tick(*v / scale, span)
}

/// Width of the y label area: the widest tick label, the rotated axis label, padding.
fn y_label_area(r: &Range<f64>, k: i32) -> u32 {
    let f = ticker(r, k);
    let widest = (0..=20)
        .map(|j| r.start + (r.end - r.start) * f64::from(j) / 20.0)
        .map(|v| text_width(&f(&v), TICK_PT))
        .fold(0.0, f64::max);
    (widest + 1.4 * pt_to_px(LABEL_PT) + 22.0).ceil() as u32
}

fn x_label_area() -> u32 {
    (pt_to_px(TICK_PT) + 1.6 * pt_to_px(LABEL_PT) + 14.0).ceil() as u32
}

/// Draws the axes of a chart: ticks and labels at the print sizes, no grid.
#[allow(clippy::too_many_arguments)]
fn axes<X>(
    chart: &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<X, RangedCoordf64>>,
    xdesc: &str,
    xfmt: &dyn Fn(&f64) -> String,
    nx: usize,
    ydesc: &str,
    yfmt: &dyn Fn(&f64) -> String,
    ny: usize,
) -> std::result::Result<(), String>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(xdesc)
        .y_desc(ydesc)
        .x_labels(nx)
        .y_labels(ny)
        .x_label_formatter(xfmt)
        .y_label_formatter(yfmt)
        .label_style(font(TICK_PT))
        .axis_desc_style(font(LABEL_PT))
        .draw()
        .map_err(|e| e.to_string())
}

/// Draws a data line through `pts` and records its vertices.
fn data_line<CT: CoordTranslate<From = (f64, f64)>>(
    area: &DrawingArea<SVGBackend<'_>, CT>,
    pts: &[(f64, f64)],
    style: ShapeStyle,
    rec: &mut FigureLayout,
) -> std::result::Result<(), String> {
    area.draw(&PathElement::new(pts.to_vec(), style))
        .map_err(|e| e.to_string())?;
    for p in pts {
        rec.data.push(PxRect::around(area.map_coordinate(p), 0));
    }
    Ok(())
}

/// Draws a marker at a data point and records its box.
fn data_marker<CT: CoordTranslate<From = (f64, f64)>>(
    area: &DrawingArea<SVGBackend<'_>, CT>,
    m: Marker,
    p: (f64, f64),
    color: RGBColor,
    rec: &mut FigureLayout,
) -> std::result::Result<(), String> {
    m.draw(area, p, color)?;
    rec.data
        .push(PxRect::around(area.map_coordinate(&p), m.half()));
    Ok(())
}

/// The class-marker entries for the classes in `present`, in the series' colour.
fn class_items(present: &[Class], color: RGBColor) -> Vec<Item> {
    Class::ALL
        .iter()
        .filter(|c| present.contains(c))
        .map(|&c| Item::new(Marker::Class(c), color, class_label(c)))
        .collect()
}

/// One series of a node panel: values at nodes 1..p, their classes, its colour.
type NodeSeries<'s> = (&'s [f64], &'s [Class], RGBColor);

/// One panel: values against the node index, a thin line per series and a class marker
/// at every node. Records the classes drawn (under their legend labels).
fn node_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    caption: &str,
    quantity: &str,
    unit: &str,
    series: &[NodeSeries<'_>],
    rec: &mut FigureLayout,
) -> std::result::Result<(), String> {
    let p = series.first().map_or(1, |s| s.0.len());
    let yr = range(series.iter().flat_map(|s| s.0.iter().copied()).chain([0.0]));
    let k = axis_exponent(&yr);
    let mut builder = ChartBuilder::on(area);
    if !caption.is_empty() {
        builder.caption(caption, font(CAPTION_PT));
    }
    let mut chart = builder
        .margin(8)
        .margin_right(16)
        .x_label_area_size(x_label_area())
        .y_label_area_size(y_label_area(&yr, k))
        .build_cartesian_2d(0.5..p as f64 + 0.5, yr.clone())
        .map_err(|e| e.to_string())?;
    let xt = |v: &f64| format!("{}", v.round() as i64);
    let yt = ticker(&yr, k);
    axes(
        &mut chart,
        "contact node i",
        &xt,
        p.min(7),
        &axis_label(quantity, unit, k),
        &yt,
        6,
    )?;
    let plot = chart.plotting_area();
    rec.plot_of(plot);
    plot.draw(&PathElement::new(
        vec![(0.5, 0.0), (p as f64 + 0.5, 0.0)],
        BLACK.mix(0.3),
    ))
    .map_err(|e| e.to_string())?;
    for (vals, classes, color) in series {
        let pts: Vec<(f64, f64)> = vals
            .iter()
            .enumerate()
            .map(|(i, &v)| ((i + 1) as f64, v))
            .collect();
        data_line(plot, &pts, color.mix(0.6).stroke_width(1), rec)?;
        for (&pt, &c) in pts.iter().zip(classes.iter()) {
            data_marker(plot, Marker::Class(c), pt, *color, rec)?;
            rec.add_drawn(class_label(c), 1);
        }
    }
    Ok(())
}

/// The classes drawn on a figure, in the order of [`Class::ALL`].
fn classes_drawn(rec: &FigureLayout) -> Vec<Class> {
    Class::ALL
        .iter()
        .copied()
        .filter(|&c| rec.drawn_count(class_label(c)) > 0)
        .collect()
}

fn plot_err<E: std::fmt::Display>(file: &FsPath) -> impl FnOnce(E) -> Error + '_ {
    move |e| Error::Io(format!("cannot draw {}: {e}", file.display()))
}

/// Figure 2: λν, λt, uν, ut at the contact nodes for one point, markers by class; the
/// legend (below the panels) lists the classes present, in the data's colour.
pub fn plot_snapshot(data: &ContactData, title: &str, file: &FsPath) -> Result<FigureLayout> {
    let (w, h) = (FIG_WIDTH, 860);
    let root = SVGBackend::new(file, (w, h)).into_drawing_area();
    let mut rec = FigureLayout::new(w, h);
    let mut draw = || -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let body = titled(&root, title)?;
        let blue = PALETTE[0];
        let present: Vec<Class> = Class::ALL
            .iter()
            .copied()
            .filter(|c| data.classes.contains(c))
            .collect();
        let items = class_items(&present, blue);
        let lh = legend_height(&items, w);
        let bh = body.dim_in_pixel().1;
        let (panels, strip) = body.split_vertically(bh - lh);
        let areas = panels.split_evenly((2, 2));
        let c = &data.classes;
        node_panel(
            &areas[0],
            "normal contact force (≤ 0: pressure)",
            "λν",
            "E·L",
            &[(&data.lambda_n, c, blue)],
            &mut rec,
        )?;
        node_panel(
            &areas[1],
            "tangential contact force (along +x)",
            "λt",
            "E·L",
            &[(&data.lambda_t, c, blue)],
            &mut rec,
        )?;
        node_panel(
            &areas[2],
            "normal displacement (< 0: lifted off)",
            "uν = −u_y",
            "L",
            &[(&data.u_n, c, blue)],
            &mut rec,
        )?;
        node_panel(
            &areas[3],
            "tangential displacement",
            "ut = u_x",
            "L",
            &[(&data.u_t, c, blue)],
            &mut rec,
        )?;
        let items = class_items(&classes_drawn(&rec), blue);
        draw_legend(&strip, &items, &mut rec)?;
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(plot_err(file))?;
    Ok(rec)
}

/// A node panel of a multi-series figure: caption, quantity, unit, the values drawn.
type Panel = (
    &'static str,
    &'static str,
    &'static str,
    fn(&ContactData) -> &[f64],
);

/// Several series over the same node panels with two legends below them: the series'
/// lines in their colours, and the class-marker key (grey: all series share the shapes).
fn node_series_figure(
    list: &[ContactData],
    labels: &[String],
    title: &str,
    panels: &[Panel],
    height: u32,
    file: &FsPath,
) -> Result<FigureLayout> {
    let w = FIG_WIDTH;
    let root = SVGBackend::new(file, (w, height)).into_drawing_area();
    let mut rec = FigureLayout::new(w, height);
    let color = |k: usize| PALETTE[k % PALETTE.len()];
    let mut draw = || -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let body = titled(&root, title)?;
        // the legend's size depends only on the labels and the classes present
        let present: Vec<Class> = Class::ALL
            .iter()
            .copied()
            .filter(|c| list.iter().any(|d| d.classes.contains(c)))
            .collect();
        let series_items = || -> Vec<Item> {
            labels
                .iter()
                .enumerate()
                .map(|(k, l)| Item::new(Marker::Line, color(k), l.clone()))
                .collect()
        };
        let lh1 = legend_height(&series_items(), w);
        let lh2 = legend_height(&class_items(&present, KEY_GREY), w);
        let bh = body.dim_in_pixel().1;
        let (panel_area, strips) = body.split_vertically(bh - lh1 - lh2);
        let (strip1, strip2) = strips.split_vertically(lh1);
        let areas = panel_area.split_evenly((panels.len(), 1));
        for (area, (caption, quantity, unit, get)) in areas.iter().zip(panels) {
            let series: Vec<NodeSeries<'_>> = list
                .iter()
                .enumerate()
                .map(|(k, d)| (get(d), d.classes.as_slice(), color(k)))
                .collect();
            node_panel(area, caption, quantity, unit, &series, &mut rec)?;
        }
        for l in labels {
            rec.add_drawn(l, panels.len());
        }
        draw_legend(&strip1, &series_items(), &mut rec)?;
        let key = class_items(&classes_drawn(&rec), KEY_GREY);
        draw_legend(&strip2, &key, &mut rec)?;
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(plot_err(file))?;
    Ok(rec)
}

/// Figure 3: λν against the node index for several points, markers by class.
pub fn plot_profiles(list: &[ContactData], title: &str, file: &FsPath) -> Result<FigureLayout> {
    let labels: Vec<String> = list.iter().map(|d| format!("α = {}", d.alpha)).collect();
    node_series_figure(
        list,
        &labels,
        title,
        &[("", "λν", "E·L", |d| &d.lambda_n)],
        680,
        file,
    )
}

/// All solutions at one α (high-friction variant): λν, λt and uν against the node
/// index, one colour per solution (`labels`), markers by class.
pub fn plot_solutions(
    list: &[ContactData],
    labels: &[String],
    title: &str,
    file: &FsPath,
) -> Result<FigureLayout> {
    let labels: Vec<String> = (0..list.len())
        .map(|k| {
            labels
                .get(k)
                .cloned()
                .unwrap_or_else(|| format!("solution {}", k + 1))
        })
        .collect();
    node_series_figure(
        list,
        &labels,
        title,
        &[
            ("normal contact force", "λν", "E·L", |d| &d.lambda_n),
            ("tangential contact force", "λt", "E·L", |d| &d.lambda_t),
            (
                "normal displacement (< 0: lifted off)",
                "uν = −u_y",
                "L",
                |d| &d.u_n,
            ),
        ],
        1250,
        file,
    )
}

/// Figure 1: the mesh, with the clamped side, the contact side and the loaded sides;
/// equal scales on both axes, the legend below the chart.
pub fn plot_mesh(spec: &RectSpec, file: &FsPath) -> Result<FigureLayout> {
    let (lx, ly) = (spec.lx, spec.ly);
    let m = lx.max(ly);
    let xr = (-0.1 * m)..(lx + 0.12 * m);
    let yr = (-0.15 * m)..(ly + 0.17 * m);
    let clamp = RGBColor(60, 60, 60);
    let found = RGBColor(140, 90, 40);
    let red = PALETTE[3];
    let loads = [
        (&spec.load0, PALETTE[0], "f0"),
        (&spec.load1, PALETTE[2], "α·f1"),
    ];
    // legend entries: what will be drawn (a load with no non-zero traction is not)
    let mut items = vec![
        Item::new(Marker::Line, clamp, "clamped side (u = 0)"),
        Item::new(Marker::Line, found, "rigid foundation"),
        Item::new(
            Marker::Node,
            red,
            format!("contact nodes i = 1..{} (Γ_C)", spec.p()),
        ),
    ];
    let load_label = |name: &str, tracs: &[fricont_exchange::generator::Traction]| {
        format!(
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
        )
    };
    for (tracs, color, name) in &loads {
        if tracs
            .iter()
            .any(|t| t.start != [0.0; 2] || t.end != [0.0; 2])
        {
            items.push(Item::new(Marker::Line, *color, load_label(name, tracs)));
        }
    }
    // equal scales: the plot width fixes the pixels per unit length
    let w = FIG_WIDTH;
    let yla = (text_width("3.5", TICK_PT) + 1.4 * pt_to_px(LABEL_PT) + 22.0).ceil() as u32;
    let margin = 14u32;
    let plot_w = f64::from(w - yla - 2 * margin);
    let px_per_l = plot_w / (xr.end - xr.start);
    let plot_h = ((yr.end - yr.start) * px_per_l).round() as u32;
    let title_h = (2.0 * pt_to_px(TITLE_PT)).round() as u32;
    let lh = legend_height(&items, w);
    let h = title_h + 2 * margin + plot_h + x_label_area() + lh;
    let root = SVGBackend::new(file, (w, h)).into_drawing_area();
    let mut rec = FigureLayout::new(w, h);
    let title = format!(
        "Case study mesh: Q1, {}×{} nodes, n = {}, p = {}",
        spec.nx,
        spec.ny,
        spec.n(),
        spec.p()
    );
    let mut draw = || -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let body = titled(&root, &title)?;
        let bh = body.dim_in_pixel().1;
        let (chart_area, strip) = body.split_vertically(bh - lh);
        let mut chart = ChartBuilder::on(&chart_area)
            .margin(margin)
            .x_label_area_size(x_label_area())
            .y_label_area_size(yla)
            .build_cartesian_2d(xr.clone(), yr.clone())
            .map_err(|e| e.to_string())?;
        let xt = ticker(&xr, 0);
        let yt = ticker(&yr, 0);
        axes(&mut chart, "x  [L]", &xt, 8, "y  [L]", &yt, 6)?;
        let plot = chart.plotting_area();
        rec.plot_of(plot);
        let (hx, hy) = spec.h();
        let grey = RGBColor(150, 150, 150).stroke_width(1);
        for i in 0..spec.nx {
            let x = i as f64 * hx;
            data_line(plot, &[(x, 0.0), (x, ly)], grey, &mut rec)?;
        }
        for j in 0..spec.ny {
            let y = j as f64 * hy;
            data_line(plot, &[(0.0, y), (lx, y)], grey, &mut rec)?;
        }
        // clamped side: thick line with hatching
        data_line(
            plot,
            &[(0.0, 0.0), (0.0, ly)],
            clamp.stroke_width(4),
            &mut rec,
        )?;
        rec.add_drawn(&items[0].label, 1);
        let nh = 14;
        for k in 0..=nh {
            let y = ly * k as f64 / nh as f64;
            data_line(
                plot,
                &[(0.0, y), (-0.06 * lx, y - 0.06 * lx)],
                clamp.stroke_width(1),
                &mut rec,
            )?;
        }
        // foundation and contact nodes
        data_line(
            plot,
            &[(-0.02 * lx, 0.0), (lx + 0.05 * lx, 0.0)],
            found.stroke_width(2),
            &mut rec,
        )?;
        rec.add_drawn(&items[1].label, 1);
        for k in 0..=2 * spec.nx {
            let x = lx * 1.05 * k as f64 / (2 * spec.nx) as f64 - 0.02 * lx;
            data_line(
                plot,
                &[(x, 0.0), (x - 0.03 * lx, -0.04 * lx)],
                found.stroke_width(1),
                &mut rec,
            )?;
        }
        for i in 0..spec.p() {
            data_marker(plot, Marker::Node, (spec.contact_x(i), 0.0), red, &mut rec)?;
        }
        rec.add_drawn(&items[2].label, spec.p());
        let style = font(NOTE_PT)
            .color(&red)
            .pos(Pos::new(HPos::Center, VPos::Top));
        for i in [0, spec.p() / 2, spec.p() - 1] {
            plot.draw(&Text::new(
                format!("{}", i + 1),
                (spec.contact_x(i), -0.065 * lx),
                style.clone(),
            ))
            .map_err(|e| e.to_string())?;
        }
        // tractions: arrows at a few points of each loaded side
        let arrow_len = 0.12 * m;
        for (li, (tracs, color, name)) in loads.iter().enumerate() {
            let maxmag = tracs
                .iter()
                .flat_map(|t| [t.start, t.end])
                .map(|v| v[0].hypot(v[1]))
                .fold(0.0, f64::max);
            if maxmag == 0.0 {
                continue;
            }
            let label = load_label(name, tracs);
            for t in tracs.iter() {
                // f0 arrows at the ends and every eighth of the side, α·f1 arrows halfway
                // between them, so the two loads do not hide each other
                let nseg = 8;
                for k in 0..=(nseg - li) {
                    let s = (k as f64 + 0.5 * li as f64) / nseg as f64;
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
                        let off = 0.05 * m;
                        (x + off * out[0], y + off * out[1])
                    } else {
                        (x, y)
                    };
                    let (x0, y0, x1, y1) = if pushing {
                        (x - v[0] * sc, y - v[1] * sc, x, y)
                    } else {
                        (x, y, x + v[0] * sc, y + v[1] * sc)
                    };
                    data_line(plot, &[(x0, y0), (x1, y1)], color.stroke_width(2), &mut rec)?;
                    // arrow head
                    let (dx, dy) = (x1 - x0, y1 - y0);
                    let l = dx.hypot(dy);
                    let (ux, uy) = (dx / l, dy / l);
                    let hl = 0.025 * m;
                    let head = [
                        (x1 - hl * ux + 0.5 * hl * uy, y1 - hl * uy - 0.5 * hl * ux),
                        (x1, y1),
                        (x1 - hl * ux - 0.5 * hl * uy, y1 - hl * uy + 0.5 * hl * ux),
                    ];
                    data_line(plot, &head, color.stroke_width(2), &mut rec)?;
                    rec.add_drawn(&label, 1);
                }
            }
        }
        let items: Vec<Item> = items
            .iter()
            .filter(|it| rec.drawn_count(&it.label) > 0)
            .map(|it| Item::new(it.marker, it.color, it.label.clone()))
            .collect();
        draw_legend(&strip, &items, &mut rec)?;
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(plot_err(file))?;
    Ok(rec)
}

const TRANSITION_LABEL: &str = "transition point";
/// A total drawn on the path figure: its label, and its value from `(λν, λt)`.
type Total = (&'static str, fn(&[f64], &[f64]) -> f64);
const FOLD_LABEL: &str = "fold (α turns back)";

/// The path figure: top, the total contact forces `Σλν`, `Σλt` against α; bottom, `λν`
/// of the nodes in `nodes` (0-based) against α. Transition points are marked (black
/// dots) and numbered; folds (α turns back) get a red triangle. Each panel has its
/// legend below it, listing only what it draws.
pub fn plot_path(
    pieces: &[PieceLine],
    points: &[MarkedPoint],
    nodes: &[usize],
    title: &str,
    file: &FsPath,
) -> Result<FigureLayout> {
    plot_path_window(pieces, points, nodes, None, title, file)
}

/// [`plot_path`] with the α axis spanning exactly `window` (a zoom: give the pieces
/// clipped to it, [`super::clip_pieces`]); `None`: the pieces' α range with a margin.
pub fn plot_path_window(
    pieces: &[PieceLine],
    points: &[MarkedPoint],
    nodes: &[usize],
    window: Option<(f64, f64)>,
    title: &str,
    file: &FsPath,
) -> Result<FigureLayout> {
    let (w, h) = (FIG_WIDTH, 1040);
    let root = SVGBackend::new(file, (w, h)).into_drawing_area();
    let mut rec = FigureLayout::new(w, h);
    let ar = match window {
        Some((lo, hi)) => lo..hi,
        None => range(pieces.iter().flat_map(|p| [p.alpha_from, p.alpha_to])),
    };
    rec.alpha_axis = Some((ar.start, ar.end));
    let has_fold = points.iter().any(|m| m.fold);
    let has_plain = points.iter().any(|m| !m.fold);
    let point_items = || {
        let mut v = Vec::new();
        if has_plain {
            v.push(Item::new(Marker::Transition, BLACK, TRANSITION_LABEL));
        }
        if has_fold {
            v.push(Item::new(Marker::Fold, FOLD_RED, FOLD_LABEL));
        }
        v
    };
    let totals: [Total; 2] = [
        ("Σ λν (normal)", |n, _| sum(n)),
        ("Σ λt (tangential)", |_, t| sum(t)),
    ];
    let mut draw = || -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let body = titled(&root, title)?;
        let bh = body.dim_in_pixel().1;
        let (top, bottom) = body.split_vertically(bh / 2);
        // top panel: the totals
        let mut top_items: Vec<Item> = totals
            .iter()
            .enumerate()
            .map(|(k, (name, _))| Item::new(Marker::Line, PALETTE[k], *name))
            .collect();
        top_items.extend(point_items());
        let lh = legend_height(&top_items, w);
        let th = top.dim_in_pixel().1;
        let (top_chart, top_strip) = top.split_vertically(th - lh);
        let yr = range(pieces.iter().flat_map(|p| {
            [
                sum(&p.lambda_n_from),
                sum(&p.lambda_n_to),
                sum(&p.lambda_t_from),
                sum(&p.lambda_t_to),
                0.0,
            ]
        }));
        let k = axis_exponent(&yr);
        let mut chart = ChartBuilder::on(&top_chart)
            .caption(
                "total contact forces along the path (transition points numbered)",
                font(CAPTION_PT),
            )
            .margin(8)
            .margin_right(20)
            .x_label_area_size(x_label_area())
            .y_label_area_size(y_label_area(&yr, k))
            .build_cartesian_2d(ar.clone(), yr.clone())
            .map_err(|e| e.to_string())?;
        let xt = ticker(&ar, 0);
        let yt = ticker(&yr, k);
        axes(
            &mut chart,
            "load parameter α",
            &xt,
            8,
            &axis_label("Σ λ", "E·L", k),
            &yt,
            6,
        )?;
        let plot = chart.plotting_area();
        rec.plot_of(plot);
        for (k, (name, get)) in totals.iter().enumerate() {
            for p in pieces {
                data_line(
                    plot,
                    &[
                        (p.alpha_from, get(&p.lambda_n_from, &p.lambda_t_from)),
                        (p.alpha_to, get(&p.lambda_n_to, &p.lambda_t_to)),
                    ],
                    PALETTE[k].stroke_width(2),
                    &mut rec,
                )?;
            }
            rec.add_drawn(name, pieces.len());
            draw_points(
                plot,
                points,
                |m| (m.alpha, get(&m.lambda_n, &m.lambda_t)),
                k == 0,
                &mut rec,
            )?;
        }
        let top_items: Vec<Item> = top_items
            .into_iter()
            .filter(|it| rec.drawn_count(&it.label) > 0)
            .collect();
        draw_legend(&top_strip, &top_items, &mut rec)?;

        // bottom panel: λν of the selected nodes
        let node_label = |i: usize| format!("node {}", i + 1);
        let mut items: Vec<Item> = nodes
            .iter()
            .enumerate()
            .map(|(k, &i)| Item::new(Marker::Line, PALETTE[k % PALETTE.len()], node_label(i)))
            .collect();
        let own = |i: usize| points.iter().filter(move |m| m.node == i);
        if nodes.iter().any(|&i| own(i).any(|m| !m.fold)) {
            items.push(Item::new(Marker::Transition, BLACK, TRANSITION_LABEL));
        }
        if nodes.iter().any(|&i| own(i).any(|m| m.fold)) {
            items.push(Item::new(Marker::Fold, FOLD_RED, FOLD_LABEL));
        }
        let lh = legend_height(&items, w);
        let bh = bottom.dim_in_pixel().1;
        let (bottom_chart, bottom_strip) = bottom.split_vertically(bh - lh);
        let yr = range(pieces.iter().flat_map(|p| {
            nodes
                .iter()
                .flat_map(|&i| [p.lambda_n_from[i], p.lambda_n_to[i]])
                .chain([0.0])
                .collect::<Vec<_>>()
        }));
        let k = axis_exponent(&yr);
        let mut chart = ChartBuilder::on(&bottom_chart)
            .caption("normal contact force of selected nodes", font(CAPTION_PT))
            .margin(8)
            .margin_right(20)
            .x_label_area_size(x_label_area())
            .y_label_area_size(y_label_area(&yr, k))
            .build_cartesian_2d(ar.clone(), yr.clone())
            .map_err(|e| e.to_string())?;
        let yt = ticker(&yr, k);
        axes(
            &mut chart,
            "load parameter α",
            &xt,
            8,
            &axis_label("λν_i", "E·L", k),
            &yt,
            6,
        )?;
        let plot = chart.plotting_area();
        rec.plot_of(plot);
        let mut bottom_rec = FigureLayout::default();
        for (k, &i) in nodes.iter().enumerate() {
            let c = PALETTE[k % PALETTE.len()];
            for p in pieces {
                data_line(
                    plot,
                    &[
                        (p.alpha_from, p.lambda_n_from[i]),
                        (p.alpha_to, p.lambda_n_to[i]),
                    ],
                    c.stroke_width(2),
                    &mut bottom_rec,
                )?;
            }
            bottom_rec.add_drawn(&node_label(i), pieces.len());
            let own: Vec<MarkedPoint> = own(i).cloned().collect();
            draw_points(
                plot,
                &own,
                |m| (m.alpha, m.lambda_n[i]),
                false,
                &mut bottom_rec,
            )?;
        }
        let items: Vec<Item> = items
            .into_iter()
            .filter(|it| bottom_rec.drawn_count(&it.label) > 0)
            .collect();
        for (l, n) in bottom_rec.drawn.drain(..) {
            rec.add_drawn(&l, n);
        }
        rec.data.append(&mut bottom_rec.data);
        draw_legend(&bottom_strip, &items, &mut rec)?;
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(plot_err(file))?;
    Ok(rec)
}

/// Marks transition points (black dots) and folds (red triangles) on a path chart;
/// with `numbers`, writes the transition numbers above them, one label per group of
/// consecutive points closer than three text heights, labels that would overlap moved up.
fn draw_points(
    plot: &DrawingArea<SVGBackend<'_>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    points: &[MarkedPoint],
    at: impl Fn(&MarkedPoint) -> (f64, f64),
    numbers: bool,
    rec: &mut FigureLayout,
) -> std::result::Result<(), String> {
    for m in points.iter().filter(|m| !m.fold) {
        data_marker(plot, Marker::Transition, at(m), BLACK, rec)?;
        rec.add_drawn(TRANSITION_LABEL, 1);
    }
    for m in points.iter().filter(|m| m.fold) {
        data_marker(plot, Marker::Fold, at(m), FOLD_RED, rec)?;
        rec.add_drawn(FOLD_LABEL, 1);
    }
    if !numbers {
        return Ok(());
    }
    let text_h = pt_to_px(NOTE_PT);
    let px = |m: &MarkedPoint| plot.map_coordinate(&at(m));
    let mut clusters: Vec<(usize, Vec<usize>)> = Vec::new();
    for (k, m) in points.iter().enumerate() {
        match clusters.last_mut() {
            Some((first, ts))
                if f64::from((px(&points[*first]).0 - px(m).0).abs()) < 3.0 * text_h =>
            {
                if !ts.contains(&m.transition) {
                    ts.push(m.transition);
                }
            }
            _ => clusters.push((k, vec![m.transition])),
        }
    }
    let style = TextStyle::from(font(NOTE_PT)).pos(Pos::new(HPos::Left, VPos::Bottom));
    let mut placed: Vec<PxRect> = Vec::new();
    let (_, plot_y) = plot.get_pixel_range();
    for (first, ts) in clusters {
        let text = if ts.len() > 3 {
            let (lo, hi) = (ts.iter().min().unwrap_or(&0), ts.iter().max().unwrap_or(&0));
            format!("{lo}–{hi}")
        } else {
            ts.iter()
                .map(|t| t.to_string())
                .collect::<Vec<_>>()
                .join(",")
        };
        let (x, y) = px(&points[first]);
        let tw = text_width(&text, NOTE_PT);
        // above the point, one or two lines higher, or below it: the first place that
        // overlaps no label placed so far and stays inside the plot
        let rect = |lift: f64| PxRect {
            x0: f64::from(x) + 3.0,
            y0: f64::from(y) - 6.0 - lift - text_h,
            x1: f64::from(x) + 3.0 + tw,
            y1: f64::from(y) - 6.0 - lift,
        };
        let step = text_h + 2.0;
        let lift = [
            0.0,
            step,
            2.0 * step,
            -(text_h + 12.0),
            -(text_h + 12.0) - step,
        ]
        .into_iter()
        .find(|&l| {
            let r = rect(l);
            r.y0 >= f64::from(plot_y.start)
                && r.y1 <= f64::from(plot_y.end)
                && !placed.iter().any(|q| q.intersects(&r))
        })
        .unwrap_or(0.0);
        placed.push(rect(lift));
        let dy = (-6.0 - lift).round() as i32;
        plot.draw(
            &(EmptyElement::at(at(&points[first])) + Text::new(text, (3, dy), style.clone())),
        )
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn print_geometry() {
        // 16 cm at 300 dpi; 8 pt at 16 cm on a 1000 px figure is 17.6 px
        assert_eq!(png_width(), 1890);
        assert!((pt_to_px(8.0) - 8.0 / 72.0 / (16.0 / 2.54) * 1000.0).abs() < 1e-9);
        for pt in [TICK_PT, LABEL_PT, CAPTION_PT, TITLE_PT, LEGEND_PT, NOTE_PT] {
            assert!(pt >= MIN_TEXT_PT);
        }
    }

    #[test]
    fn text_is_measured_with_the_embedded_font() {
        // DejaVu Sans: "M" advances 0.863 em, "i" 0.278 em; ink is a little narrower
        let em = pt_to_px(10.0);
        let m = text_width("MMMMMMMMMM", 10.0);
        let i = text_width("iiiiiiiiii", 10.0);
        assert!((8.0 * em..8.7 * em).contains(&m), "{m} vs em {em}");
        assert!((2.3 * em..2.8 * em).contains(&i), "{i} vs em {em}");
        assert!(text_width("λν αβ ≤ ∈ →", 10.0) > 4.0 * em);
    }

    #[test]
    fn axis_exponents_and_labels() {
        assert_eq!(axis_exponent(&(-0.5..1.5)), 0);
        assert_eq!(axis_exponent(&(-0.0031..0.0)), -3);
        assert_eq!(axis_exponent(&(0.0..25_000.0)), 4);
        assert_eq!(axis_label("λν", "E·L", -3), "λν  [10⁻³ E·L]");
        assert_eq!(axis_label("α", "", 0), "α");
        assert_eq!(ticker(&(-0.0031..0.0), -3)(&-0.0025), "−2.5");
        assert_eq!(tick(-0.5, 2.0), "−0.5");
        assert_eq!(tick(1e-12, 2.0), "0");
        assert_eq!(
            minus_numbers("high-friction: α from -0.5 to -.5, x-1 (-1)"),
            "high-friction: α from −0.5 to −.5, x-1 (−1)"
        );
    }

    #[test]
    fn rectangles() {
        let a = PxRect {
            x0: 0.0,
            y0: 0.0,
            x1: 10.0,
            y1: 10.0,
        };
        let b = PxRect {
            x0: 10.0,
            y0: 5.0,
            x1: 20.0,
            y1: 6.0,
        };
        let c = PxRect {
            x0: 10.5,
            y0: 5.0,
            x1: 20.0,
            y1: 6.0,
        };
        assert!(a.intersects(&b) && b.intersects(&a));
        assert!(!a.intersects(&c) && !c.intersects(&a));
        assert!(a.contains(&PxRect::around((5, 5), 5)));
        assert!(!a.contains(&PxRect::around((5, 5), 6)));
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

    /// Legends outside every plot area, inside the canvas, disjoint from the data and
    /// from each other; every data item inside a plot area; legend entries only for
    /// what was drawn.
    fn check_layout(l: &FigureLayout, what: &str) {
        let canvas = PxRect {
            x0: 0.0,
            y0: 0.0,
            x1: f64::from(l.width),
            y1: f64::from(l.height),
        };
        assert!(!l.legends.is_empty() && !l.data.is_empty(), "{what}");
        for (k, g) in l.legends.iter().enumerate() {
            assert!(canvas.contains(g), "{what}: legend {g:?} off the canvas");
            for p in &l.plots {
                assert!(!g.intersects(p), "{what}: legend {g:?} over plot {p:?}");
            }
            for d in &l.data {
                assert!(!g.intersects(d), "{what}: legend {g:?} over data {d:?}");
            }
            for h in &l.legends[k + 1..] {
                assert!(!g.intersects(h), "{what}: legends overlap");
            }
        }
        for d in &l.data {
            assert!(
                l.plots.iter().any(|p| p.contains(d)),
                "{what}: {d:?} outside the plots"
            );
        }
        for e in &l.legend_entries {
            assert!(
                l.drawn_count(e) > 0,
                "{what}: legend entry {e} for nothing drawn"
            );
        }
        for (label, n) in &l.drawn {
            assert!(
                *n == 0 || l.legend_entries.contains(label),
                "{what}: {label} drawn but not in the legend"
            );
        }
    }

    #[test]
    fn figures_draw_on_synthetic_data() {
        let dir = std::env::temp_dir().join(format!("fricont-fig-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let spec = RectSpec::default();
        let l = plot_mesh(&spec, &dir.join("mesh.svg")).unwrap();
        check_layout(&l, "mesh");
        assert_eq!(l.drawn_count("contact nodes i = 1..30 (Γ_C)"), 30);
        let d = synthetic(30, 3.6);
        let l = plot_snapshot(&d, "snapshot", &dir.join("snap.svg")).unwrap();
        check_layout(&l, "snapshot");
        assert_eq!(l.plots.len(), 4);
        // every class is present in the synthetic data: four entries, 4 × 30 markers
        assert_eq!(l.legend_entries.len(), 4);
        let markers: usize = Class::ALL
            .iter()
            .map(|&c| l.drawn_count(class_label(c)))
            .sum();
        assert_eq!(markers, 4 * 30);
        let list: Vec<ContactData> = [-0.5, 0.0, 0.5, 1.0, 1.5]
            .iter()
            .map(|&a| synthetic(30, a))
            .collect();
        check_layout(
            &plot_profiles(&list, "profiles", &dir.join("prof.svg")).unwrap(),
            "profiles",
        );
        let l = plot_solutions(&list[..3], &[], "solutions", &dir.join("sols.svg")).unwrap();
        check_layout(&l, "solutions");
        assert!(l.legend_entries.iter().any(|e| e == "solution 3"));
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
        let l = plot_path(&pieces, &pts, &[0, 5, 12], "path", &dir.join("path.svg")).unwrap();
        check_layout(&l, "path");
        assert!(l.legend_entries.iter().any(|e| e == FOLD_LABEL));
        // without the fold, no fold entry
        let no_fold: Vec<MarkedPoint> = pts.iter().filter(|m| !m.fold).cloned().collect();
        let l = plot_path(&pieces, &no_fold, &[0], "path", &dir.join("path2.svg")).unwrap();
        check_layout(&l, "path without fold");
        assert!(!l.legend_entries.iter().any(|e| e == FOLD_LABEL));
        for f in ["mesh", "snap", "prof", "sols", "path"] {
            let svg = dir.join(format!("{f}.svg"));
            let s = std::fs::read_to_string(&svg).unwrap();
            assert!(s.starts_with("<svg") && s.contains("</svg>"), "{f}");
            let png = write_png(&svg).unwrap();
            let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
            let info = dec.read_info().unwrap().info().clone();
            assert_eq!(info.width, png_width(), "{f}");
        }
        let s = std::fs::read_to_string(dir.join("snap.svg")).unwrap();
        for label in [
            "contact node i",
            "λν  [E·L]",
            "no contact",
            "contact, stick",
        ] {
            assert!(s.contains(label), "snapshot lacks {label}");
        }
        if std::env::var_os("FRICONT_KEEP_FIGS").is_none() {
            std::fs::remove_dir_all(&dir).unwrap();
        } else {
            eprintln!("figures kept in {}", dir.display());
        }
    }
}
