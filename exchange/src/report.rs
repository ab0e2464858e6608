//! Reports of a traced path: the JSON report (specified key by key in
//! `docs/json-report.md`, a test keeps the two in step) and the text table of the CLI.
//!
//! Both count nodes, events and transition points from 1, as the founding paper does.
//! In JSON, α and every other number are written by `serde_json` in shortest round-trip
//! form (reading the number back gives the same `f64`); a non-finite number (which a
//! correct path never produces) is written as `null`. In the tables, α is written with 14
//! significant digits by [`fmt_alpha`] (positional where readable, as the paper does).

use std::fmt::Write as _;

use serde_json::Value;

use fricont::class::Class;
use fricont::path::{EndReason, Event, Path};

/// Wall-clock times of a run, in seconds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Timing {
    /// Set-up: validation, sparse Cholesky of A, the Delassus operator W and the condensed
    /// load vectors (building the [`fricont::Problem`] and the [`Path`]).
    pub setup_s: f64,
    /// Tracing: the start solve and every step ([`Path::start`] + [`Path::run`]).
    pub trace_s: f64,
}

/// Where and why the path ended, as reported: α of the last point reached and the reason
/// (`None` while the path is still running).
fn end_point(path: &mut Path) -> (Option<f64>, Option<EndReason>) {
    let reason = path.end_reason().cloned();
    let alpha = if path.is_started() {
        match path.current() {
            Ok(s) => Some(s.alpha),
            Err(_) => path.pieces().last().map(|p| p.alpha_to),
        }
    } else {
        None
    };
    (alpha, reason)
}

/// A finite number as JSON, `null` otherwise.
fn num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// Serialises an `f64` as a JSON number (shortest round-trip form), or `null` when it is
/// not finite (JSON has no NaN or infinity).
fn ser_num<S: serde::Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    if x.is_finite() {
        s.serialize_f64(*x)
    } else {
        s.serialize_none()
    }
}

fn ser_nums<S: serde::Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = s.serialize_seq(Some(v.len()))?;
    for x in v {
        if x.is_finite() {
            seq.serialize_element(x)?;
        } else {
            seq.serialize_element(&Option::<f64>::None)?;
        }
    }
    seq.end()
}

fn ser_classes<S: serde::Serializer>(v: &[Class], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(v.iter().map(|c| c.name()))
}

fn ser_opt_num<S: serde::Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match x {
        Some(x) if x.is_finite() => s.serialize_f64(*x),
        _ => s.serialize_none(),
    }
}

/// The report of a path (`docs/json-report.md`), with its fields in the order of SPEC §8. Serialise it
/// with `serde_json` (the CLI does); [`path_json`] gives it as a [`Value`].
///
/// Required keys: `n`, `p`, `r`, `alpha_start`, `alpha_end` (the window as asked),
/// `start {alpha, classes, residual}`, `events [{index, alpha, node, from, to, fold,
/// bifurcation, residual}]` (index and node 1-based), `pieces [{alpha_from, alpha_to,
/// classes}]`, `end {alpha, reason}`, `timing {setup_s, trace_s}`. Extra keys: `F`
/// (number when uniform, else array), `precision {extended, w_condition_estimate}`,
/// `start.lambda_n`, `start.lambda_t`, per event
/// `transition` (1-based transition point) and the node's `lambda_n`, `lambda_t` at the
/// event, per piece `direction` (sign of dα/ds, 0 for a vertical piece), `orientation`,
/// `det_sign`, `end.message` for a failure, `end.branches` for a bifurcation stop, and
/// `n_events`, `n_transitions`, `residual_max`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PathReport {
    /// Number of dofs.
    pub n: usize,
    /// Number of contact nodes.
    pub p: usize,
    /// Augmentation parameter in use.
    #[serde(serialize_with = "ser_num")]
    pub r: f64,
    /// Window start (where the path starts).
    #[serde(serialize_with = "ser_num")]
    pub alpha_start: f64,
    /// Window end (traced toward first).
    #[serde(serialize_with = "ser_num")]
    pub alpha_end: f64,
    /// Friction: a number when uniform, else one per node.
    #[serde(rename = "F")]
    pub friction: Value,
    /// The precision W and the loads were traced in, with W's condition estimate.
    pub precision: PrecisionReport,
    /// The start point (`null` if the path was never started).
    pub start: Option<StartReport>,
    /// One per event, in path order.
    pub events: Vec<EventReport>,
    /// One per traced piece, in path order.
    pub pieces: Vec<PieceReport>,
    /// Number of events.
    pub n_events: usize,
    /// Number of transition points.
    pub n_transitions: usize,
    /// Largest residual of the start point and the events.
    #[serde(serialize_with = "ser_num")]
    pub residual_max: f64,
    /// Where and why the path ended.
    pub end: EndReport,
    /// Wall-clock times.
    pub timing: TimingReport,
}

/// The start point in a [`PathReport`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct StartReport {
    /// α of the start.
    #[serde(serialize_with = "ser_num")]
    pub alpha: f64,
    /// Class of every node.
    #[serde(serialize_with = "ser_classes")]
    pub classes: Vec<Class>,
    /// `‖H‖∞` relative to the data scale.
    #[serde(serialize_with = "ser_num")]
    pub residual: f64,
    /// Normal contact forces (≤ 0 compressive).
    #[serde(serialize_with = "ser_nums")]
    pub lambda_n: Vec<f64>,
    /// Tangential contact forces.
    #[serde(serialize_with = "ser_nums")]
    pub lambda_t: Vec<f64>,
}

/// One event in a [`PathReport`] (1-based counts).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EventReport {
    /// 1-based position in the event list.
    pub index: usize,
    /// α of the transition point.
    #[serde(serialize_with = "ser_num")]
    pub alpha: f64,
    /// 1-based contact node.
    pub node: usize,
    /// Class before (`"open"`, `"stick"`, `"slip+"`, `"slip-"`).
    pub from: &'static str,
    /// Class after.
    pub to: &'static str,
    /// α turns back here.
    pub fold: bool,
    /// Several pieces continue the path here.
    pub bifurcation: bool,
    /// `‖H‖∞` relative to the data scale, at the event.
    #[serde(serialize_with = "ser_num")]
    pub residual: f64,
    /// 1-based transition point (shared by the events of a degenerate transition).
    pub transition: usize,
    /// λν of the node at the event.
    #[serde(serialize_with = "ser_opt_num")]
    pub lambda_n: Option<f64>,
    /// λt of the node at the event.
    #[serde(serialize_with = "ser_opt_num")]
    pub lambda_t: Option<f64>,
}

/// One traced piece in a [`PathReport`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PieceReport {
    /// α where the path entered the piece.
    #[serde(serialize_with = "ser_num")]
    pub alpha_from: f64,
    /// α where the path left it.
    #[serde(serialize_with = "ser_num")]
    pub alpha_to: f64,
    /// Class of every node on the piece.
    #[serde(serialize_with = "ser_classes")]
    pub classes: Vec<Class>,
    /// Sign of dα/ds (0: vertical piece, a continuum of solutions at one α).
    pub direction: i8,
    /// Orientation sign of the path on the piece.
    pub orientation: i8,
    /// Sign of det ∂H/∂λ on the piece.
    pub det_sign: i8,
}

/// The end of the path in a [`PathReport`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EndReport {
    /// α of the last point reached (`null` if never started).
    #[serde(serialize_with = "ser_opt_num")]
    pub alpha: Option<f64>,
    /// [`EndReason::name`] (`null` while the path is still running).
    pub reason: Option<&'static str>,
    /// The failure message, for `"failed"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
    /// The candidate branches, for `"bifurcation"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub branches: Option<Vec<BranchReport>>,
}

/// A candidate continuation at a bifurcation stop.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BranchReport {
    /// Classes of the candidate piece.
    #[serde(serialize_with = "ser_classes")]
    pub classes: Vec<Class>,
    /// Sign of dα/ds along it.
    pub direction: i8,
    /// Whether it keeps the path's orientation.
    pub orientation_preserving: bool,
}

/// The precision of a [`PathReport`]'s path: whether W and the condensed loads were carried
/// beyond double (`Problem::extended_precision`), and the estimate of the 2-norm condition
/// number of the equilibrated W (`Problem::w_condition_estimate`, dimensionless): in double,
/// the rounding of W moves transition points by up to about 50 times that times ε,
/// relative to max(1, |α|) (see `docs/json-report.md`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PrecisionReport {
    /// Traced in extended precision.
    pub extended: bool,
    /// Condition estimate of the equilibrated W.
    #[serde(serialize_with = "ser_num")]
    pub w_condition_estimate: f64,
}

/// Timing in a [`PathReport`], seconds.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TimingReport {
    /// Set-up time (see [`Timing::setup_s`]).
    #[serde(serialize_with = "ser_num")]
    pub setup_s: f64,
    /// Trace time (see [`Timing::trace_s`]).
    #[serde(serialize_with = "ser_num")]
    pub trace_s: f64,
}

impl PathReport {
    /// Collects the report of a path (started, and normally run to its end). For a path
    /// never started, `start` and `end.alpha` are `None`; for one still running,
    /// `end.reason` is `None`. The path is taken `&mut` only to evaluate the current point
    /// (one back-solve).
    pub fn from_path(path: &mut Path, timing: Timing) -> PathReport {
        let (end_alpha, reason) = end_point(path);
        let problem = path.problem().clone();
        let opts = path.options().clone();
        let fr = problem.friction();
        let friction = if fr.iter().all(|&x| x == fr[0]) {
            num(fr[0])
        } else {
            Value::Array(fr.iter().map(|&x| num(x)).collect())
        };
        // None before the start; likewise if the start's back-solve fails (as the events'
        // residuals below, which are then NaN).
        let start = path.start_state().ok().map(|s| StartReport {
            alpha: s.alpha,
            classes: s.classes,
            residual: s.residual,
            lambda_n: s.lambda_n,
            lambda_t: s.lambda_t,
        });
        let list: Vec<Event> = path.events().to_vec();
        // Residuals only (no u is kept).
        let residuals: Option<Vec<f64>> = path.event_residuals(0..list.len()).ok();
        let mut events: Vec<EventReport> = Vec::with_capacity(list.len());
        for e in &list {
            events.push(EventReport {
                index: e.index + 1,
                alpha: e.alpha,
                node: e.node + 1,
                from: e.from.name(),
                to: e.to.name(),
                fold: e.fold,
                bifurcation: e.bifurcation,
                residual: residuals.as_ref().map_or(f64::NAN, |r| r[e.index]),
                transition: e.transition + 1,
                lambda_n: e.lambda_n.get(e.node).copied(),
                lambda_t: e.lambda_t.get(e.node).copied(),
            });
        }
        let residual_max = start
            .iter()
            .map(|s| s.residual)
            .chain(events.iter().map(|e| e.residual))
            .fold(0.0_f64, f64::max);
        let pieces = path
            .pieces()
            .iter()
            .map(|p| PieceReport {
                alpha_from: p.alpha_from,
                alpha_to: p.alpha_to,
                classes: p.classes.clone(),
                direction: p.direction,
                orientation: p.orientation,
                det_sign: p.det_sign,
            })
            .collect();
        let end = EndReport {
            alpha: end_alpha,
            reason: reason.as_ref().map(EndReason::name),
            message: match &reason {
                Some(EndReason::Failed(m)) => Some(m.clone()),
                _ => None,
            },
            branches: match &reason {
                Some(EndReason::Bifurcation) => Some(
                    path.branches()
                        .iter()
                        .map(|b| BranchReport {
                            classes: b.classes.clone(),
                            direction: b.direction,
                            orientation_preserving: b.orientation_preserving,
                        })
                        .collect(),
                ),
                _ => None,
            },
        };
        PathReport {
            n: problem.n(),
            p: problem.p(),
            r: problem.r(),
            alpha_start: opts.alpha_start,
            alpha_end: opts.alpha_end,
            friction,
            precision: PrecisionReport {
                extended: problem.extended_precision(),
                w_condition_estimate: problem.w_condition_estimate(),
            },
            start,
            n_events: events.len(),
            n_transitions: events.last().map_or(0, |e| e.transition),
            events,
            pieces,
            residual_max,
            end,
            timing: TimingReport {
                setup_s: timing.setup_s,
                trace_s: timing.trace_s,
            },
        }
    }

    /// The report as pretty-printed JSON text (keys in the order of the doc), ending with a
    /// newline.
    pub fn to_json_string(&self) -> String {
        // Serialising plain data with string keys cannot fail.
        let mut s = serde_json::to_string_pretty(self).unwrap_or_default();
        s.push('\n');
        s
    }
}

/// The JSON report of a path, as a [`Value`] (see [`PathReport`] for the keys;
/// a `Value` does not keep the key order, [`PathReport::to_json_string`] does).
pub fn path_json(path: &mut Path, timing: Timing) -> Value {
    serde_json::to_value(PathReport::from_path(path, timing)).unwrap_or(Value::Null)
}

/// α with 14 significant digits: in positional notation where that is readable
/// (magnitudes from 1e-4 to below 1e15: `0.28019791259766`, `-0.50000000000000`,
/// `3.6000000000000`), in scientific notation otherwise (`1.2500000000000e-7`); `0` and
/// non-finite values as Rust prints them. Reading the text back gives α to 5e-14 relative.
pub fn fmt_alpha(alpha: f64) -> String {
    if alpha == 0.0 || !alpha.is_finite() {
        return format!("{alpha}");
    }
    let e = alpha.abs().log10().floor() as i32;
    if (-4..15).contains(&e) {
        let decimals = (13 - e).max(0) as usize;
        let s = format!("{alpha:.decimals$}");
        // Rounding may carry into a new leading digit (9.99…95 → 10.000…): one digit
        // fewer after the point keeps 14 significant digits.
        let significant = s
            .chars()
            .filter(char::is_ascii_digit)
            .skip_while(|&c| c == '0')
            .count();
        if significant > 14 && decimals > 0 {
            let decimals = decimals - 1;
            return format!("{alpha:.decimals$}");
        }
        s
    } else {
        format!("{alpha:.13e}")
    }
}

/// One row of a transition table: one event, with 1-based numbers as in the paper.
#[derive(Debug, Clone, PartialEq)]
pub struct TransitionRow {
    /// 1-based transition point (shared by the rows of a degenerate transition).
    pub transition: usize,
    /// α of the transition point.
    pub alpha: f64,
    /// 1-based contact node.
    pub node: usize,
    /// Class before.
    pub from: Class,
    /// Class after.
    pub to: Class,
    /// α turns back here.
    pub fold: bool,
    /// Several pieces continue the path here.
    pub bifurcation: bool,
}

impl TransitionRow {
    /// The flags of the row: `fold`, `bifurcation` (space-separated, possibly empty).
    pub fn flags(&self) -> String {
        let mut flags = Vec::new();
        if self.fold {
            flags.push("fold");
        }
        if self.bifurcation {
            flags.push("bifurcation");
        }
        flags.join(" ")
    }
}

/// The transition rows of a path, one per event in path order (1-based numbers).
pub fn transition_rows(path: &Path) -> Vec<TransitionRow> {
    path.events()
        .iter()
        .map(|e| TransitionRow {
            transition: e.transition + 1,
            alpha: e.alpha,
            node: e.node + 1,
            from: e.from,
            to: e.to,
            fold: e.fold,
            bifurcation: e.bifurcation,
        })
        .collect()
}

/// The rows of the transition table, as the CLI prints them (after a header line
/// `k  alpha  node  before -> after  flags`), each ending with a newline.
pub fn table_rows(rows: &[TransitionRow]) -> String {
    let mut s = String::new();
    for r in rows {
        let change = format!("{} -> {}", r.from.name(), r.to.name());
        let row = format!(
            "{:>4}  {:>21}  {:>4}  {:<15}  {}",
            r.transition,
            fmt_alpha(r.alpha),
            r.node,
            change,
            r.flags()
        );
        s.push_str(row.trim_end());
        s.push('\n');
    }
    s
}

/// The events as CSV: `transition,alpha,node,from,to,fold,bifurcation`, α in shortest
/// round-trip form, 1-based numbers.
pub fn events_csv(rows: &[TransitionRow]) -> String {
    let mut s = String::from("transition,alpha,node,from,to,fold,bifurcation\n");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{:e},{},{},{},{},{}",
            r.transition,
            r.alpha,
            r.node,
            r.from.name(),
            r.to.name(),
            r.fold,
            r.bifurcation
        );
    }
    s
}

/// A count with its noun in the right number: `plural(1, "fold")` is "1 fold",
/// `plural(0, "fold")` "0 folds" (nouns whose plural adds an `s`).
pub fn plural(k: usize, noun: &str) -> String {
    if k == 1 {
        format!("{k} {noun}")
    } else {
        format!("{k} {noun}s")
    }
}

/// "1 event at 1 transition point", "3 events at 2 transition points".
pub fn count_words(events: usize, transitions: usize) -> String {
    format!(
        "{} at {}",
        plural(events, "event"),
        plural(transitions, "transition point")
    )
}

/// Counts of each class, e.g. `"12 open, 18 stick, 0 slip+, 0 slip-"`.
fn class_counts(c: &[Class]) -> String {
    Class::ALL
        .iter()
        .map(|k| format!("{} {}", c.iter().filter(|x| *x == k).count(), k.name()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The transition table, as the CLI prints it: a header with the problem and the start
/// point, one row per event
///
/// ```text
///    k                 alpha  node  before -> after  flags
///    6   2.8019791259766e-1    13  open -> slip+
/// ```
///
/// (`k`: the 1-based transition point, shared by the rows of a degenerate transition;
/// α with 14 significant digits; 1-based node; flags `fold`, `bifurcation`), then the end
/// of the path and, if given, the timing. Ends with a newline.
pub fn table(path: &mut Path, timing: Option<Timing>) -> String {
    let (end_alpha, reason) = end_point(path);
    let problem = path.problem().clone();
    let opts = path.options().clone();
    let mut s = String::new();
    let fr = problem.friction();
    let f = if fr.iter().all(|&x| x == fr[0]) {
        format!("{}", fr[0])
    } else {
        let (lo, hi) = fr
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        format!("{lo}..{hi} (per node)")
    };
    let _ = writeln!(
        s,
        "n = {}, p = {}, F = {f}, r = {:e}, alpha from {} to {}",
        problem.n(),
        problem.p(),
        problem.r(),
        opts.alpha_start,
        opts.alpha_end
    );
    match path.start_state() {
        Ok(st) => {
            let _ = writeln!(
                s,
                "start: alpha = {}, residual {:.1e}, {}",
                fmt_alpha(st.alpha),
                st.residual,
                class_counts(&st.classes)
            );
        }
        Err(_) if !path.is_started() => {
            let _ = writeln!(s, "start: (path not started)");
        }
        Err(e) => {
            let _ = writeln!(s, "start: (its state failed: {e})");
        }
    }
    let _ = writeln!(
        s,
        "{:>4}  {:>21}  {:>4}  before -> after  flags",
        "k", "alpha", "node"
    );
    s.push_str(&table_rows(&transition_rows(path)));
    let n_tp = path.events().last().map_or(0, |e| e.transition + 1);
    let alpha = end_alpha.map_or_else(|| "-".to_string(), fmt_alpha);
    let why = match &reason {
        Some(EndReason::Failed(m)) => format!("failed: {m}"),
        Some(r) => r.name().to_string(),
        None => "running".to_string(),
    };
    let _ = write!(
        s,
        "{}; end: alpha = {alpha}, reason {why}",
        count_words(path.events().len(), n_tp)
    );
    if let Some(t) = timing {
        let ratio = if t.setup_s > 0.0 {
            format!(" (trace/setup = {:.3})", t.trace_s / t.setup_s)
        } else {
            String::new()
        };
        let _ = write!(
            s,
            "; setup {:.6} s, trace {:.6} s{ratio}",
            t.setup_s, t.trace_s
        );
    }
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alpha_has_fourteen_significant_digits() {
        // Positional where readable, as the founding paper prints α.
        assert_eq!(fmt_alpha(0.28019791259766), "0.28019791259766");
        assert_eq!(fmt_alpha(-0.5), "-0.50000000000000");
        assert_eq!(fmt_alpha(3.6), "3.6000000000000");
        assert_eq!(fmt_alpha(1.25e-7), "1.2500000000000e-7");
        assert_eq!(fmt_alpha(0.0), "0");
        // A carry into a new leading digit keeps 14 digits.
        assert_eq!(fmt_alpha(9.999999999999999), "10.000000000000");
        for &x in &[
            0.28019791259766_f64,
            -0.5,
            1.5,
            0.42934036865234,
            -1.234567890123456e-7,
            6.02214076e23,
            123_456.789_012_35,
            9.999999999999999,
            0.000123456789012345,
        ] {
            let s = fmt_alpha(x);
            let mant = s.split_once('e').map_or(s.as_str(), |(m, _)| m);
            let digits: String = mant.chars().filter(char::is_ascii_digit).collect();
            let significant = digits.trim_start_matches('0').len();
            assert_eq!(significant, 14, "{s}");
            let back: f64 = s.parse().unwrap();
            assert!((back - x).abs() <= 5e-14 * x.abs(), "{s} vs {x}");
        }
    }

    #[test]
    fn counts_are_in_good_english() {
        assert_eq!(count_words(1, 1), "1 event at 1 transition point");
        assert_eq!(count_words(3, 2), "3 events at 2 transition points");
        assert_eq!(count_words(0, 0), "0 events at 0 transition points");
        assert_eq!(plural(1, "fold"), "1 fold");
        assert_eq!(plural(2, "fold"), "2 folds");
    }

    #[test]
    fn class_counts_cover_all_classes() {
        let c = [Class::Open, Class::Stick, Class::Open, Class::SlipMinus];
        assert_eq!(class_counts(&c), "2 open, 1 stick, 0 slip+, 1 slip-");
    }

    #[test]
    fn json_numbers_round_trip() {
        // f64::from_bits(4595965843552456931) = 0.18867749756794358 is read back one ulp off
        // by serde_json without its `float_roundtrip` feature (which the crate enables).
        for &x in &[
            0.1 + 0.2,
            1.0 / 3.0,
            -0.28019791259766,
            5e-324,
            f64::MAX,
            f64::from_bits(4595965843552456931),
        ] {
            let s = serde_json::to_string(&num(x)).unwrap();
            let back: f64 = serde_json::from_str(&s).unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{s}");
        }
        assert_eq!(num(f64::NAN), Value::Null);
    }
}
