//! Reports of a traced path: the JSON object of SPEC §8 and the text table of the CLI.
//!
//! Both count nodes, events and transition points from 1, as the founding paper does.
//! In JSON, α and every other number are written by `serde_json` in shortest round-trip
//! form (reading the number back gives the same `f64`); a non-finite number (which a
//! correct path never produces) is written as `null`. In the table, α is written with 14
//! significant digits (`{:.13e}`).

use std::fmt::Write as _;

use serde_json::{Map, Value, json};

use crate::class::Class;
use crate::path::{EndReason, Event, Path};

/// Wall-clock times of a run, in seconds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Timing {
    /// Set-up: validation, sparse Cholesky of A, the Delassus operator W and the condensed
    /// load vectors (building the [`crate::Problem`] and the [`Path`]).
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

fn class_names(c: &[Class]) -> Value {
    Value::Array(c.iter().map(|c| Value::from(c.name())).collect())
}

fn event_json(e: &Event) -> Value {
    let mut o = Map::new();
    o.insert("index".into(), json!(e.index + 1));
    o.insert("alpha".into(), num(e.alpha));
    o.insert("node".into(), json!(e.node + 1));
    o.insert("from".into(), json!(e.from.name()));
    o.insert("to".into(), json!(e.to.name()));
    o.insert("fold".into(), json!(e.fold));
    o.insert("bifurcation".into(), json!(e.bifurcation));
    o.insert("residual".into(), num(e.state.residual));
    // Extra keys.
    o.insert("transition".into(), json!(e.transition + 1));
    if let Some(&l) = e.state.lambda_n.get(e.node) {
        o.insert("lambda_n".into(), num(l));
    }
    if let Some(&l) = e.state.lambda_t.get(e.node) {
        o.insert("lambda_t".into(), num(l));
    }
    Value::Object(o)
}

/// The JSON object of SPEC §8 for a path (started, and normally run to its end).
///
/// Required keys: `n`, `p`, `r`, `alpha_start`, `alpha_end` (the window as asked),
/// `start {alpha, classes, residual}`, `events [{index, alpha, node, from, to, fold,
/// bifurcation, residual}]` (index and node 1-based), `pieces [{alpha_from, alpha_to,
/// classes}]`, `end {alpha, reason}`, `timing {setup_s, trace_s}`. Extra keys: `F`
/// (number when uniform, else array), `start.lambda_n`, `start.lambda_t`, per event
/// `transition` (1-based transition point) and the node's `lambda_n`, `lambda_t` at the
/// event, per piece `direction` (sign of dα/ds, 0 for a vertical piece), `orientation`,
/// `det_sign`, `end.message` for a failure, `end.branches` for a bifurcation stop, and
/// `n_events`, `n_transitions`, `residual_max`.
///
/// For a path that was never started, `start` and `end.alpha` are `null`; for one still
/// running, `end.reason` is `null`. The path is taken `&mut` only to evaluate the current
/// point (one back-solve).
pub fn path_json(path: &mut Path, timing: Timing) -> Value {
    let (end_alpha, reason) = end_point(path);
    let problem = path.problem().clone();
    let opts = path.options().clone();
    let mut o = Map::new();
    o.insert("n".into(), json!(problem.n()));
    o.insert("p".into(), json!(problem.p()));
    o.insert("r".into(), num(problem.r()));
    o.insert("alpha_start".into(), num(opts.alpha_start));
    o.insert("alpha_end".into(), num(opts.alpha_end));
    let fr = problem.friction();
    let f = if fr.iter().all(|&x| x == fr[0]) {
        num(fr[0])
    } else {
        Value::Array(fr.iter().map(|&x| num(x)).collect())
    };
    o.insert("F".into(), f);
    let mut residual_max: f64 = 0.0;
    let start = match path.start_state() {
        Some(s) => {
            residual_max = residual_max.max(s.residual);
            json!({
                "alpha": num(s.alpha),
                "classes": class_names(&s.classes),
                "residual": num(s.residual),
                "lambda_n": s.lambda_n.iter().map(|&x| num(x)).collect::<Vec<_>>(),
                "lambda_t": s.lambda_t.iter().map(|&x| num(x)).collect::<Vec<_>>(),
            })
        }
        None => Value::Null,
    };
    o.insert("start".into(), start);
    let events = path.events();
    for e in events {
        residual_max = residual_max.max(e.state.residual);
    }
    o.insert(
        "events".into(),
        Value::Array(events.iter().map(event_json).collect()),
    );
    o.insert("n_events".into(), json!(events.len()));
    o.insert(
        "n_transitions".into(),
        json!(events.last().map_or(0, |e| e.transition + 1)),
    );
    o.insert("residual_max".into(), num(residual_max));
    let pieces: Vec<Value> = path
        .pieces()
        .iter()
        .map(|p| {
            json!({
                "alpha_from": num(p.alpha_from),
                "alpha_to": num(p.alpha_to),
                "classes": class_names(&p.classes),
                "direction": p.direction,
                "orientation": p.orientation,
                "det_sign": p.det_sign,
            })
        })
        .collect();
    o.insert("pieces".into(), Value::Array(pieces));
    let mut end = Map::new();
    end.insert("alpha".into(), end_alpha.map_or(Value::Null, num));
    end.insert(
        "reason".into(),
        reason.as_ref().map_or(Value::Null, |r| json!(r.name())),
    );
    match &reason {
        Some(EndReason::Failed(msg)) => {
            end.insert("message".into(), json!(msg));
        }
        Some(EndReason::Bifurcation) => {
            let br: Vec<Value> = path
                .branches()
                .iter()
                .map(|b| {
                    json!({
                        "classes": class_names(&b.classes),
                        "direction": b.direction,
                        "orientation_preserving": b.orientation_preserving,
                    })
                })
                .collect();
            end.insert("branches".into(), Value::Array(br));
        }
        _ => {}
    }
    o.insert("end".into(), Value::Object(end));
    o.insert(
        "timing".into(),
        json!({"setup_s": num(timing.setup_s), "trace_s": num(timing.trace_s)}),
    );
    Value::Object(o)
}

/// α with 14 significant digits, e.g. `2.8019791259766e-1`.
pub fn fmt_alpha(alpha: f64) -> String {
    format!("{alpha:.13e}")
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
        Some(st) => {
            let _ = writeln!(
                s,
                "start: alpha = {}, residual {:.1e}, {}",
                fmt_alpha(st.alpha),
                st.residual,
                class_counts(&st.classes)
            );
        }
        None => {
            let _ = writeln!(s, "start: (path not started)");
        }
    }
    let _ = writeln!(
        s,
        "{:>4}  {:>21}  {:>4}  before -> after  flags",
        "k", "alpha", "node"
    );
    for e in path.events() {
        let mut flags = Vec::new();
        if e.fold {
            flags.push("fold");
        }
        if e.bifurcation {
            flags.push("bifurcation");
        }
        let change = format!("{} -> {}", e.from.name(), e.to.name());
        let row = format!(
            "{:>4}  {:>21}  {:>4}  {:<15}  {}",
            e.transition + 1,
            fmt_alpha(e.alpha),
            e.node + 1,
            change,
            flags.join(" ")
        );
        s.push_str(row.trim_end());
        s.push('\n');
    }
    let n_tp = path.events().last().map_or(0, |e| e.transition + 1);
    let alpha = end_alpha.map_or_else(|| "-".to_string(), fmt_alpha);
    let why = match &reason {
        Some(EndReason::Failed(m)) => format!("failed: {m}"),
        Some(r) => r.name().to_string(),
        None => "running".to_string(),
    };
    let _ = write!(
        s,
        "{} events at {n_tp} transition points; end: alpha = {alpha}, reason {why}",
        path.events().len()
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
        for &x in &[
            0.28019791259766_f64,
            -0.5,
            1.5,
            0.42934036865234,
            -1.234567890123456e-7,
            6.02214076e23,
        ] {
            let s = fmt_alpha(x);
            let (mant, _) = s.split_once('e').unwrap();
            let digits = mant.chars().filter(char::is_ascii_digit).count();
            assert_eq!(digits, 14, "{s}");
            let back: f64 = s.parse().unwrap();
            assert!((back - x).abs() <= 5e-14 * x.abs(), "{s} vs {x}");
        }
        assert_eq!(fmt_alpha(0.28019791259766), "2.8019791259766e-1");
    }

    #[test]
    fn class_counts_cover_all_classes() {
        let c = [Class::Open, Class::Stick, Class::Open, Class::SlipMinus];
        assert_eq!(class_counts(&c), "2 open, 1 stick, 0 slip+, 1 slip-");
    }

    #[test]
    fn json_numbers_round_trip() {
        for &x in &[0.1 + 0.2, 1.0 / 3.0, -0.28019791259766, 5e-324, f64::MAX] {
            let s = serde_json::to_string(&num(x)).unwrap();
            let back: f64 = serde_json::from_str(&s).unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{s}");
        }
        assert_eq!(num(f64::NAN), Value::Null);
    }
}
