//! Integration tests of the `fricont` binary: the transition table and the JSON of SPEC §8
//! on hand-derived problems and on the sample `tests/data/sample-rect30`, exit status 2 with a
//! one-line message on broken input, and a confirmation of every event of the sample by
//! independent fixed-α solves on both sides of it.

use std::path::{Path as FsPath, PathBuf};
use std::process::{Command, Output};
use std::sync::Arc;

use serde_json::Value;

use fricont::Class;
use fricont::path::{Path, PathOptions};
use fricont_exchange::io::CaseData;

const BIN: &str = env!("CARGO_BIN_EXE_fricont");

fn sample_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/data/sample-rect30")
}

/// A fresh empty directory under the system temp dir, removed on drop.
struct TempDir(PathBuf);
impl TempDir {
    fn new(tag: &str) -> Self {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static K: AtomicUsize = AtomicUsize::new(0);
        let d = std::env::temp_dir().join(format!(
            "fricont-cli-{tag}-{}-{}",
            std::process::id(),
            K.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        TempDir(d)
    }
    fn path(&self) -> &FsPath {
        &self.0
    }
}
impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run fricont")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

// ---------------------------------------------------------------------------------------
// Hand-derived problems: two contact nodes that do not interact.
//
// n = 4 dofs (u1ν, u1t, u2ν, u2t), A = diag(kν1, kt1, kν2, kt2), N = rows e1, e3,
// T = rows e2, e4, F = 0.75 at both nodes, f(α) = f0 + α f1. For one node with stiffnesses
// kν, kt, gap g and load (fν(α), ft(α)), H1 gives kν uν = fν + λν, kt ut = ft + λt:
// - open: λ = 0, uν = fν/kν, ut = ft/kt; it stays open while uν < g, i.e. fν < kν g;
// - in contact: uν = g, λν = kν g − fν (≤ 0 while fν ≥ kν g);
//   slip±: λt = ∓F λν, kt ut = ft ∓ F λν, guard ±ut > 0;
//   stick: ut = 0, λt = −ft, guard |ft| < −F λν = F (fν − kν g).
//
// Case "decoupled": kν1 = 2, kt1 = 3, g1 = 0.25, f1ν = −1 + 2α, f1t = α;
//                   kν2 = 5, kt2 = 4, g2 = 0,    f2ν = −1 + α,  f2t = −α/2.
// Node 1: contact when −1 + 2α = 2·0.25 → α = 0.75, where ut = 0.75/3 > 0: open → slip+.
//   Then kt ut = α + 0.75 (1.5 − 2α) = 1.125 − 0.5 α > 0 until α = 2.25: slip+ → stick
//   (stick guard |α| < 0.75 (2α − 1.5) ⇔ α > 2.25, consistent).
// Node 2: contact at α = 1, where ut = −0.5/4 < 0: open → slip−. Then λν = 1 − α,
//   kt ut = −α/2 + 0.75 (α − 1) = 0.25 α − 0.75 < 0 until α = 3: slip− → stick.
// Window [0, 3.5]: events (0.75, 1, open→slip+), (1, 2, open→slip−),
// (2.25, 1, slip+→stick), (3, 2, slip−→stick); the start at α = 0 is open, open.
//
// Case "mirror": both nodes kν = 2, kt = 3, g = 0, fν = −1 + 2α, f1t = α, f2t = −α.
// Both touch at α = 0.5 (node 1 slip+, node 2 slip−: a degenerate transition, one event
// per node in node order), and both stick when α = 0.75 (2α − 1) ⇔ α = 1.5.
// ---------------------------------------------------------------------------------------

struct Hand {
    a_diag: [f64; 4],
    gap: Option<[f64; 2]>,
    f0: [f64; 4],
    f1: [f64; 4],
    window: (f64, f64),
}

const DECOUPLED: Hand = Hand {
    a_diag: [2.0, 3.0, 5.0, 4.0],
    gap: Some([0.25, 0.0]),
    f0: [-1.0, 0.0, -1.0, 0.0],
    f1: [2.0, 1.0, 1.0, -0.5],
    window: (0.0, 3.5),
};

const MIRROR: Hand = Hand {
    a_diag: [2.0, 3.0, 2.0, 3.0],
    gap: None,
    f0: [-1.0, 0.0, -1.0, 0.0],
    f1: [2.0, 1.0, 2.0, -1.0],
    window: (0.0, 2.0),
};

fn lines(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x}\n")).collect()
}

fn write_hand(h: &Hand, dir: &FsPath) {
    // A as a symmetric Matrix Market file (diagonal only), with a comment and a blank line.
    let mut a =
        String::from("%%MatrixMarket matrix coordinate real symmetric\n% hand-made\n\n4 4 4\n");
    for (i, v) in h.a_diag.iter().enumerate() {
        a.push_str(&format!("{} {} {v}\n", i + 1, i + 1));
    }
    std::fs::write(dir.join("A.mtx"), a).unwrap();
    std::fs::write(
        dir.join("N.mtx"),
        "%%MatrixMarket matrix coordinate real general\n2 4 2\n1 1 1\n2 3 1\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("T.mtx"),
        "%%MatrixMarket matrix coordinate real general\n2 4 2\n1 2 1.0\n2 4 1e0\n",
    )
    .unwrap();
    std::fs::write(dir.join("f0.txt"), lines(&h.f0)).unwrap();
    std::fs::write(dir.join("f1.txt"), lines(&h.f1)).unwrap();
    if let Some(g) = h.gap {
        std::fs::write(dir.join("gap.txt"), lines(&g)).unwrap();
    }
    std::fs::write(
        dir.join("meta.json"),
        format!(
            r#"{{"n": 4, "p": 2, "F": 0.75, "alpha_start": {}, "alpha_end": {}, "note": "hand"}}"#,
            h.window.0, h.window.1
        ),
    )
    .unwrap();
}

/// Traces `dir` with `extra` options, checks status 0 and the JSON schema, returns the JSON
/// and the printed table.
fn trace_json(dir: &FsPath, extra: &[&str]) -> (Value, String) {
    let out_dir = TempDir::new("json");
    let json_path = out_dir.path().join("out.json");
    let mut args = vec!["trace", dir.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.extend_from_slice(&["--json", json_path.to_str().unwrap()]);
    let o = run(&args);
    assert!(
        o.status.success(),
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status,
        stdout(&o),
        stderr(&o)
    );
    let text = std::fs::read_to_string(&json_path).expect("JSON written");
    let v: Value = serde_json::from_str(&text).expect("valid JSON");
    check_schema(&v);
    (v, stdout(&o))
}

fn num(v: &Value, what: &str) -> f64 {
    v.as_f64()
        .unwrap_or_else(|| panic!("{what} is not a number: {v}"))
}

fn int(v: &Value, what: &str) -> u64 {
    v.as_u64()
        .unwrap_or_else(|| panic!("{what} is not a non-negative integer: {v}"))
}

fn classes(v: &Value, p: u64, what: &str) -> Vec<Class> {
    let a = v
        .as_array()
        .unwrap_or_else(|| panic!("{what} is not an array"));
    assert_eq!(a.len() as u64, p, "{what}: length");
    a.iter()
        .map(|c| {
            Class::from_name(c.as_str().unwrap_or_default())
                .unwrap_or_else(|| panic!("{what}: bad class name {c}"))
        })
        .collect()
}

/// SPEC §8: required keys and their types, 1-based indices and nodes, events in path
/// order (α moving along each piece's direction), pieces joined at the events, residuals
/// ≤ 1e-12.
fn check_schema(v: &Value) {
    let n = int(&v["n"], "n");
    let p = int(&v["p"], "p");
    assert!(n >= 1 && p >= 1);
    assert!(num(&v["r"], "r") > 0.0);
    let a0 = num(&v["alpha_start"], "alpha_start");
    let a1 = num(&v["alpha_end"], "alpha_end");
    let (lo, hi) = (a0.min(a1), a0.max(a1));

    let start = &v["start"];
    assert_eq!(num(&start["alpha"], "start.alpha"), a0);
    let start_classes = classes(&start["classes"], p, "start.classes");
    let r0 = num(&start["residual"], "start.residual");
    assert!((0.0..=1e-12).contains(&r0), "start residual {r0}");

    let events = v["events"].as_array().expect("events array");
    let pieces = v["pieces"].as_array().expect("pieces array");
    let mut last_transition = 0u64;
    let mut last_alpha = a0;
    for (k, e) in events.iter().enumerate() {
        assert_eq!(
            int(&e["index"], "index"),
            k as u64 + 1,
            "events are 1-based, in order"
        );
        let node = int(&e["node"], "node");
        assert!(node >= 1 && node <= p, "node {node} not 1-based in 1..={p}");
        let from = Class::from_name(e["from"].as_str().expect("from")).expect("from class");
        let to = Class::from_name(e["to"].as_str().expect("to")).expect("to class");
        assert_ne!(from, to, "event {} changes nothing", k + 1);
        assert!(e["fold"].is_boolean() && e["bifurcation"].is_boolean());
        let res = num(&e["residual"], "residual");
        assert!(
            (0.0..=1e-12).contains(&res),
            "event {}: residual {res}",
            k + 1
        );
        let alpha = num(&e["alpha"], "alpha");
        assert!(
            alpha >= lo && alpha <= hi,
            "event α {alpha} outside the window"
        );
        // Transition points: 1-based, non-decreasing; events of one share α and are in
        // node order.
        let tp = int(&e["transition"], "transition");
        if k > 0 && tp == last_transition {
            let prev = &events[k - 1];
            assert_eq!(
                num(&prev["alpha"], "alpha"),
                alpha,
                "same transition, same α"
            );
            assert!(
                int(&prev["node"], "node") < node,
                "node order in a transition"
            );
        } else {
            assert_eq!(tp, last_transition + 1, "transition numbering");
            // The piece between two transition points runs in its own direction.
            let piece = &pieces[tp as usize - 1];
            let dir = piece["direction"].as_i64().expect("direction");
            let step = alpha - last_alpha;
            assert!(
                step * dir as f64 >= 0.0 && (dir != 0 || step == 0.0),
                "event {}: α moves by {step} on a piece of direction {dir}",
                k + 1
            );
        }
        last_transition = tp;
        last_alpha = alpha;
    }
    // One piece before the first transition point and one after each.
    assert_eq!(
        pieces.len() as u64,
        last_transition + 1,
        "pieces vs transitions"
    );
    let mut tp_alpha = vec![a0];
    let mut tp_seen = 0;
    for e in events {
        let tp = int(&e["transition"], "transition");
        if tp != tp_seen {
            tp_alpha.push(num(&e["alpha"], "alpha"));
            tp_seen = tp;
        }
    }
    let end = &v["end"];
    let end_alpha = num(&end["alpha"], "end.alpha");
    let reason = end["reason"].as_str().expect("end.reason");
    assert!(
        [
            "window",
            "max_steps",
            "closed_loop",
            "bifurcation",
            "failed"
        ]
        .contains(&reason),
        "reason {reason}"
    );
    tp_alpha.push(end_alpha);
    for (j, piece) in pieces.iter().enumerate() {
        let c = classes(&piece["classes"], p, "piece classes");
        if j == 0 {
            assert_eq!(c, start_classes, "first piece has the start classes");
        }
        assert_eq!(num(&piece["alpha_from"], "alpha_from"), tp_alpha[j]);
        assert_eq!(num(&piece["alpha_to"], "alpha_to"), tp_alpha[j + 1]);
    }
    // Each event's from/to match the classes of the pieces around its transition point.
    for e in events {
        let tp = int(&e["transition"], "transition") as usize;
        let node = int(&e["node"], "node") as usize - 1;
        let before = classes(&pieces[tp - 1]["classes"], p, "piece")[node];
        let after = classes(&pieces[tp]["classes"], p, "piece")[node];
        assert_eq!(before.name(), e["from"].as_str().unwrap());
        assert_eq!(after.name(), e["to"].as_str().unwrap());
    }
    if reason == "window" {
        assert!(
            end_alpha == lo || end_alpha == hi,
            "window end at {end_alpha}"
        );
    }
    let t = &v["timing"];
    assert!(num(&t["setup_s"], "setup_s") >= 0.0);
    assert!(num(&t["trace_s"], "trace_s") >= 0.0);
}

/// (α, node 1-based, from, to) of the events.
fn event_list(v: &Value) -> Vec<(f64, u64, String, String)> {
    v["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["alpha"].as_f64().unwrap(),
                e["node"].as_u64().unwrap(),
                e["from"].as_str().unwrap().to_string(),
                e["to"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

fn assert_events(v: &Value, expected: &[(f64, u64, &str, &str)]) {
    let got = event_list(v);
    assert_eq!(got.len(), expected.len(), "events: {got:?}");
    for (g, e) in got.iter().zip(expected) {
        assert!(
            (g.0 - e.0).abs() <= 1e-12 * e.0.abs().max(1.0),
            "α {} vs hand-derived {}",
            g.0,
            e.0
        );
        assert_eq!(
            (g.1, g.2.as_str(), g.3.as_str()),
            (e.1, e.2, e.3),
            "{got:?}"
        );
    }
}

#[test]
fn hand_decoupled_events_match_the_derivation() {
    let d = TempDir::new("dec");
    write_hand(&DECOUPLED, d.path());
    let (v, table) = trace_json(d.path(), &[]);
    assert_events(
        &v,
        &[
            (0.75, 1, "open", "slip+"),
            (1.0, 2, "open", "slip-"),
            (2.25, 1, "slip+", "stick"),
            (3.0, 2, "slip-", "stick"),
        ],
    );
    assert_eq!(v["n"], 4);
    assert_eq!(v["p"], 2);
    assert_eq!(v["end"]["reason"], "window");
    assert_eq!(v["end"]["alpha"], 3.5);
    assert_eq!(v["start"]["classes"], serde_json::json!(["open", "open"]));
    // The table: one row per event, α with 14 significant digits, 1-based nodes.
    assert!(table.contains("0.75000000000000"), "{table}");
    assert!(table.contains(" 2.2500000000000 "), "{table}");
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| l.contains(" -> ") && !l.contains("before"))
        .collect();
    assert_eq!(rows.len(), 4, "{table}");
    let cols: Vec<&str> = rows[1].split_whitespace().collect();
    assert_eq!(cols, ["2", "1.0000000000000", "2", "open", "->", "slip-"]);
    assert!(
        table.contains("setup") && table.contains("trace"),
        "{table}"
    );
    assert!(table.contains("reason window"), "{table}");
}

#[test]
fn hand_decoupled_backwards_and_r_invariance() {
    let d = TempDir::new("back");
    write_hand(&DECOUPLED, d.path());
    let (v, _) = trace_json(d.path(), &["--alpha-start", "3.5", "--alpha-end", "0"]);
    assert_events(
        &v,
        &[
            (3.0, 2, "stick", "slip-"),
            (2.25, 1, "stick", "slip+"),
            (1.0, 2, "slip-", "open"),
            (0.75, 1, "slip+", "open"),
        ],
    );
    assert_eq!(v["alpha_start"], 3.5);
    assert_eq!(v["end"]["alpha"], 0.0);
    let (base, _) = trace_json(d.path(), &[]);
    for r in ["1e-3", "1", "1e3"] {
        let (w, _) = trace_json(d.path(), &["--r", r]);
        assert_eq!(w["r"].as_f64().unwrap(), r.parse::<f64>().unwrap());
        let (a, b) = (event_list(&base), event_list(&w));
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            assert!((x.0 - y.0).abs() <= 1e-12 * x.0.abs().max(1.0), "r = {r}");
            assert_eq!((x.1, &x.2, &x.3), (y.1, &y.2, &y.3));
        }
    }
}

#[test]
fn hand_mirror_degenerate_transition_one_event_per_node() {
    let d = TempDir::new("mirror");
    write_hand(&MIRROR, d.path());
    let (v, table) = trace_json(d.path(), &[]);
    assert_events(
        &v,
        &[
            (0.5, 1, "open", "slip+"),
            (0.5, 2, "open", "slip-"),
            (1.5, 1, "slip+", "stick"),
            (1.5, 2, "slip-", "stick"),
        ],
    );
    let tps: Vec<u64> = v["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["transition"].as_u64().unwrap())
        .collect();
    assert_eq!(tps, [1, 1, 2, 2]);
    assert_eq!(v["pieces"].as_array().unwrap().len(), 3);
    assert!(table.contains("0.50000000000000"), "{table}");
}

#[test]
fn max_steps_stops_the_path() {
    let d = TempDir::new("max");
    write_hand(&DECOUPLED, d.path());
    let (v, _) = trace_json(d.path(), &["--max-steps", "2"]);
    assert_eq!(v["end"]["reason"], "max_steps");
    assert_events(&v, &[(0.75, 1, "open", "slip+"), (1.0, 2, "open", "slip-")]);
}

/// A one-node problem with two non-smooth folds (Klarbring's coupling).
///
/// n = 2, A = [[1, ½], [½, 1]] (det D = ¾), N = [1 0], T = [0 1], g = 0, F = 3,
/// f(α) = (1, α). With B = I, d = A⁻¹(f + λ); write s = fν − ½ ft (so dν = s/D when open).
/// - open: λ = 0, guard dν = s/D < 0 ⇔ α > 2; there dt = (α − ½)/D > 0;
/// - slip+: λt = F λν, dν = 0 ⇒ λν (1 − ½F) = −s ⇒ λν = 2s = 2 − α, guard λν < 0 ⇔ α > 2;
///   dt = (−½(1 + λν) + α + 3 λν)/D = (4.5 − 1.5 α)/D > 0 ⇔ α < 3;
/// - stick: λ = −f = (−1, −α), guard |α| < F·1 = 3;
/// - slip−: λt = −F λν ⇒ λν = −s/(1 + ½F) = −(1 − α/2)/2.5, dt = (0.9 + 0.3 α)/D < 0 ⇔ α < −3.
///
/// Traced from α = 4 toward −4: open (α decreasing) until α = 2 where contact closes with
/// dt > 0 into slip+, which exists only for α ∈ (2, 3): α turns back (fold 1); slip+ → stick
/// at α = 3 where dt reaches 0, and stick exists for α < 3: α turns back again (fold 2);
/// stick → slip− at α = −3 (no fold). For α ∈ (2, 3) there are three solutions.
#[test]
fn hand_two_folds_are_flagged() {
    let d = TempDir::new("fold");
    let dir = d.path();
    std::fs::write(
        dir.join("A.mtx"),
        "%%MatrixMarket matrix coordinate real general\n2 2 4\n1 1 1\n1 2 0.5\n2 1 0.5\n2 2 1\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("N.mtx"),
        "%%MatrixMarket matrix coordinate real general\n1 2 1\n1 1 1\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("T.mtx"),
        "%%MatrixMarket matrix coordinate real general\n1 2 1\n1 2 1\n",
    )
    .unwrap();
    std::fs::write(dir.join("f0.txt"), "1\n0\n").unwrap();
    std::fs::write(dir.join("f1.txt"), "0\n1\n").unwrap();
    std::fs::write(
        dir.join("meta.json"),
        r#"{"n": 2, "p": 1, "F": 3, "alpha_start": 4, "alpha_end": -4}"#,
    )
    .unwrap();
    let (v, table) = trace_json(dir, &[]);
    assert_events(
        &v,
        &[
            (2.0, 1, "open", "slip+"),
            (3.0, 1, "slip+", "stick"),
            (-3.0, 1, "stick", "slip-"),
        ],
    );
    let folds: Vec<bool> = v["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["fold"].as_bool().unwrap())
        .collect();
    assert_eq!(folds, [true, true, false]);
    let dirs: Vec<i64> = v["pieces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["direction"].as_i64().unwrap())
        .collect();
    assert_eq!(dirs, [-1, 1, -1, -1]);
    assert_eq!(v["end"]["alpha"], -4.0);
    let fold_rows = table.lines().filter(|l| l.ends_with("fold")).count();
    assert_eq!(fold_rows, 2, "{table}");
}

// ---------------------------------------------------------------------------------------
// Bad input: exit status 2 and one line on stderr naming the culprit.
// ---------------------------------------------------------------------------------------

/// Runs `trace` on a copy of DECOUPLED with `file` replaced (or removed if `None`); checks
/// status 2, nothing on stdout, one line on stderr containing every `needles` string.
fn expect_input_error(file: &str, content: Option<&str>, needles: &[&str]) {
    let d = TempDir::new("broken");
    write_hand(&DECOUPLED, d.path());
    match content {
        Some(c) => std::fs::write(d.path().join(file), c).unwrap(),
        None => std::fs::remove_file(d.path().join(file)).unwrap(),
    }
    let o = run(&["trace", d.path().to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{file}: stderr {err}");
    assert_eq!(err.lines().count(), 1, "one line expected: {err}");
    assert!(stdout(&o).is_empty(), "nothing on stdout: {}", stdout(&o));
    for n in needles {
        assert!(err.contains(n), "{file}: {err:?} lacks {n:?}");
    }
}

#[test]
fn broken_matrix_market_files() {
    expect_input_error("A.mtx", None, &["A.mtx", "cannot read"]);
    expect_input_error(
        "A.mtx",
        Some("%%MatrixMarket matrix array real general\n4 4\n"),
        &["A.mtx:2:", "only 0 values, expected 16 values"],
    );
    expect_input_error(
        "A.mtx",
        Some("%%MatrixMarket matrix coordinate pattern symmetric\n4 4 4\n1 1\n2 2\n3 3\n4 4\n"),
        &["A.mtx:1:", "\"pattern\" is not supported"],
    );
    expect_input_error(
        "N.mtx",
        Some("%%MatrixMarket matrix coordinate complex general\n2 4 2\n1 1 1 0\n2 3 1 0\n"),
        &["N.mtx:1:", "\"complex\" is not supported"],
    );
    expect_input_error(
        "A.mtx",
        Some(
            "%%MatrixMarket matrix coordinate real hermitian\n4 4 4\n1 1 2\n2 2 3\n3 3 5\n4 4 4\n",
        ),
        &["A.mtx:1:", "\"hermitian\" is not supported"],
    );
    expect_input_error(
        "N.mtx",
        Some("%%MatrixMarket matrix coordinate real general\n2 4 2\n1 1 1\n"),
        &["N.mtx", "only 1 entries, 2 announced"],
    );
    expect_input_error(
        "N.mtx",
        Some("%%MatrixMarket matrix coordinate real general\n2 4 2\n1 1 1\n3 3 1\n"),
        &["N.mtx:4:", "row index 3 out of range"],
    );
    expect_input_error(
        "T.mtx",
        Some("%%MatrixMarket matrix coordinate real general\n2 4 2\n1 2 x\n2 4 1\n"),
        &["T.mtx:3:", "not a number"],
    );
    expect_input_error(
        "A.mtx",
        Some(
            "%%MatrixMarket matrix coordinate real general\n4 4 4\n1 1 2\n2 2 NaN\n3 3 5\n4 4 4\n",
        ),
        &["A.mtx:4:", "NaN"],
    );
    expect_input_error(
        "T.mtx",
        Some("%%MatrixMarket matrix coordinate real general\n2 5 2\n1 2 1\n2 4 1\n"),
        &["T.mtx:2:", "expected 2x4"],
    );
}

#[test]
fn broken_vectors_and_meta() {
    expect_input_error("f0.txt", Some("-1\n0\n-1\n"), &["f0.txt", "expected n = 4"]);
    expect_input_error("f1.txt", Some("2\n1\n1e999\n-0.5\n"), &["f1.txt:3:", "inf"]);
    expect_input_error("gap.txt", Some("0.25\nzero\n"), &["gap.txt:2:", "\"zero\""]);
    expect_input_error("meta.json", None, &["meta.json", "cannot read"]);
    expect_input_error(
        "meta.json",
        Some(r#"{"n": 4, "p": 2, "alpha_start": 0, "alpha_end": 1}"#),
        &["meta.json", "\"F\""],
    );
    expect_input_error(
        "meta.json",
        Some(r#"{"n": 5, "p": 2, "F": 0.5, "alpha_start": 0, "alpha_end": 1}"#),
        &["A.mtx", "expected 5x5"],
    );
    expect_input_error(
        "meta.json",
        Some(r#"{"n": 4, "p": 2, "F": 0.5, "alpha_start": 1, "alpha_end": 1}"#),
        &["window"],
    );
}

#[test]
fn data_rejected_by_the_problem_builder() {
    // A not positive definite: A(2, 2) < 0 on a diagonal A, so the failing pivot is row 2,
    // counted from 1 as in every message of the CLI.
    expect_input_error(
        "A.mtx",
        Some("%%MatrixMarket matrix coordinate real general\n4 4 4\n1 1 2\n2 2 -3\n3 3 5\n4 4 4\n"),
        &["positive definite", "row 2 of A (1-based"],
    );
    // A not symmetric (general file).
    expect_input_error(
        "A.mtx",
        Some(
            "%%MatrixMarket matrix coordinate real general\n4 4 5\n1 1 2\n2 2 3\n3 3 5\n4 4 4\n1 2 1\n",
        ),
        &["symmetric"],
    );
    // B = [N; T] rank-deficient: T's second row equals N's second row.
    expect_input_error(
        "T.mtx",
        Some("%%MatrixMarket matrix coordinate real general\n2 4 2\n1 2 1\n2 3 1\n"),
        &["rank"],
    );
    // Negative friction.
    expect_input_error(
        "meta.json",
        Some(r#"{"n": 4, "p": 2, "F": [0.5, -1], "alpha_start": 0, "alpha_end": 1}"#),
        &["meta.json", ">= 0"],
    );
}

/// A, N and T as `array` and `integer` Matrix Market files (dense, column-major) give the
/// events of the coordinate files, derived by hand.
#[test]
fn array_and_integer_matrix_market_files() {
    let d = TempDir::new("array");
    write_hand(&DECOUPLED, d.path());
    // A = diag(2, 3, 5, 4): symmetric array, lower triangle by columns, integer values.
    let mut a = String::from("%%MatrixMarket matrix array integer symmetric\n4 4\n");
    for j in 0..4 {
        for i in j..4 {
            let v = if i == j {
                DECOUPLED.a_diag[i] as i64
            } else {
                0
            };
            a.push_str(&format!("{v}\n"));
        }
    }
    std::fs::write(d.path().join("A.mtx"), a).unwrap();
    // N = [e1; e3] as a general 2 x 4 array, column by column.
    std::fs::write(
        d.path().join("N.mtx"),
        "%%MatrixMarket matrix array real general\n2 4\n1\n0\n0\n0\n0\n1\n0\n0\n",
    )
    .unwrap();
    // T = [e2; e4] with integer values and a duplicate summing to 1.
    std::fs::write(
        d.path().join("T.mtx"),
        "%%MatrixMarket matrix coordinate integer general\n2 4 3\n1 2 1\n2 4 3\n2 4 -2\n",
    )
    .unwrap();
    let (v, _) = trace_json(d.path(), &[]);
    assert_events(
        &v,
        &[
            (0.75, 1, "open", "slip+"),
            (1.0, 2, "open", "slip-"),
            (2.25, 1, "slip+", "stick"),
            (3.0, 2, "slip-", "stick"),
        ],
    );
}

/// gen-rect's numeric options take negative values: a negative friction gets the
/// generator's own error, a negative gap (an initial overlap) is accepted and traced.
#[test]
fn gen_rect_negative_values() {
    let d = TempDir::new("neg");
    let out = d.path().join("case");
    let o = run(&["gen-rect", out.to_str().unwrap(), "--friction", "-1"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("friction = -1 must be finite and ≥ 0"),
        "{}",
        stderr(&o)
    );
    assert!(!stderr(&o).contains("--"), "a parser tip: {}", stderr(&o));
    let o = run(&[
        "gen-rect",
        out.to_str().unwrap(),
        "--nx",
        "6",
        "--ny",
        "3",
        "--gap",
        "-0.01",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let case = CaseData::read_dir(&out).unwrap();
    assert_eq!(case.gap, Some(vec![-0.01; case.p()]));
    let (v, _) = trace_json(&out, &[]);
    assert_eq!(v["end"]["reason"], "window");
}

/// `--max-steps 0` is refused as the C ABI refuses it; the counts in the table are in good
/// English for one transition point.
#[test]
fn max_steps_zero_and_one() {
    let d = TempDir::new("steps");
    write_hand(&DECOUPLED, d.path());
    let dir = d.path().to_str().unwrap();
    let o = run(&["trace", dir, "--max-steps", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--max-steps 0"), "{}", stderr(&o));
    assert!(stdout(&o).is_empty());
    let o = run(&["trace", dir, "--max-steps", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("1 event at 1 transition point; end:"),
        "{}",
        stdout(&o)
    );
}

/// A `--json` file that cannot be written fails at once (before the problem is read, so
/// even with a missing problem directory the JSON path is named), with status 2; a JSON
/// file is not left behind, or changed, when the run fails before writing it.
#[test]
fn bad_json_path_fails_before_tracing() {
    let d = TempDir::new("jsonbad");
    let missing = d.path().join("no-such-problem");
    for bad in [
        d.path().join("no-such-dir").join("out.json"),
        d.path().to_path_buf(), // a directory
    ] {
        let o = run(&[
            "trace",
            missing.to_str().unwrap(),
            "--json",
            bad.to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains("cannot write the JSON report to") && err.contains(bad.to_str().unwrap()),
            "{err}"
        );
        assert!(stdout(&o).is_empty());
    }
    // A writable path with a broken problem: no JSON file is created ...
    let json = d.path().join("new.json");
    let o = run(&[
        "trace",
        missing.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("meta.json"), "{}", stderr(&o));
    assert!(!json.exists(), "a JSON file was left behind");
    // ... and an existing one keeps its content.
    std::fs::write(&json, "previous report").unwrap();
    let o = run(&[
        "trace",
        missing.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read_to_string(&json).unwrap(), "previous report");
    // A longer previous file is replaced entirely by the report.
    std::fs::write(&json, "x".repeat(1 << 20)).unwrap();
    let h = TempDir::new("jsonok");
    write_hand(&DECOUPLED, h.path());
    let o = run(&[
        "trace",
        h.path().to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    check_schema(&v);
}

/// `--progress` shows the phases and the tracing state on stderr, ending with the number
/// of transition points of the report; without it (stderr is a pipe here, not a terminal)
/// stderr stays empty.
#[test]
fn progress_on_stderr() {
    let out = TempDir::new("progress");
    let json = out.path().join("p.json");
    let sample = sample_dir();
    let o = run(&[
        "trace",
        sample.to_str().unwrap(),
        "--progress",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let n_tp = v["n_transitions"].as_u64().unwrap();
    assert!(n_tp > 1);
    for phase in [
        "reading",
        "set-up: n = 1320, p = 30",
        "start: fixed-alpha solve",
    ] {
        assert!(err.contains(phase), "no {phase:?} in {err}");
    }
    // The tracing state's last line, then the JSON report's phase (its residuals take a
    // while on large meshes).
    let lines: Vec<&str> = err.lines().collect();
    let done = lines[lines.len().saturating_sub(2)];
    assert!(
        done.starts_with("fricont: [")
            && done.contains("] alpha = 1.500000 (100% of [-0.5, 1.5]), ")
            && done.ends_with(&format!("{n_tp} transition points; done")),
        "{err}"
    );
    let n_ev = v["n_events"].as_u64().unwrap();
    assert!(
        lines.last().unwrap_or(&"").ends_with(&format!(
            "] writing the JSON report (the residual of {n_ev} events)"
        )),
        "{err}"
    );
    // the table on stdout is untouched
    assert!(stdout(&o).contains("reason window"));
    let o = run(&["trace", sample.to_str().unwrap()]);
    assert!(o.status.success());
    assert!(
        stderr(&o).is_empty(),
        "progress without --progress: {}",
        stderr(&o)
    );
}

/// docs/json-report.md lists every key the JSON writer emits, and no other: the keys of a
/// real report (the sample, run by the CLI) and of a report holding the keys that only a
/// failed or a bifurcation stop writes are compared with the doc's table, both ways.
#[test]
fn every_key_of_the_json_report_is_documented() {
    use fricont_exchange::report::{BranchReport, PathReport};
    fn keys(v: &Value, prefix: &str, out: &mut std::collections::BTreeSet<String>) {
        match v {
            Value::Object(m) => {
                for (k, x) in m {
                    let key = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    out.insert(key.clone());
                    keys(x, &key, out);
                }
            }
            Value::Array(a) => {
                for x in a {
                    if x.is_object() {
                        keys(x, &format!("{prefix}[]"), out);
                    }
                }
            }
            _ => {}
        }
    }
    let doc_path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/json-report.md");
    let doc = std::fs::read_to_string(&doc_path).unwrap();
    let section = doc
        .split("\n## Keys\n")
        .nth(1)
        .expect("a \"## Keys\" section")
        .split("\n## ")
        .next()
        .unwrap();
    let documented: std::collections::BTreeSet<String> = section
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .map(|l| l.split('`').next().unwrap().to_string())
        .collect();
    assert!(documented.len() > 20, "{documented:?}");

    let mut emitted = std::collections::BTreeSet::new();
    let (v, _) = trace_json(&sample_dir(), &[]);
    keys(&v, "", &mut emitted);
    // The keys only a failure or a bifurcation stop writes, from the writer itself.
    let case = CaseData::read_dir(&sample_dir()).unwrap();
    let problem = Arc::new(case.problem(None).unwrap());
    let mut path = Path::new(
        problem,
        case.load().unwrap(),
        PathOptions::window(case.alpha_start, case.alpha_end),
    )
    .unwrap();
    path.start(case.alpha_start, None).unwrap();
    path.step().unwrap();
    let mut r = PathReport::from_path(&mut path, Default::default());
    r.end.message = Some("a failure".into());
    r.end.branches = Some(vec![BranchReport {
        classes: vec![Class::Open; case.p()],
        direction: 1,
        orientation_preserving: true,
    }]);
    keys(&serde_json::to_value(&r).unwrap(), "", &mut emitted);
    let undocumented: Vec<&String> = emitted.difference(&documented).collect();
    let stale: Vec<&String> = documented.difference(&emitted).collect();
    assert!(
        undocumented.is_empty(),
        "keys missing from docs/json-report.md: {undocumented:?}"
    );
    assert!(
        stale.is_empty(),
        "docs/json-report.md documents keys the writer does not emit: {stale:?}"
    );
}

#[test]
fn bad_options_exit_2() {
    let d = TempDir::new("opts");
    write_hand(&DECOUPLED, d.path());
    let dir = d.path().to_str().unwrap();
    for args in [
        vec!["trace", dir, "--r", "-1"],
        vec!["trace", dir, "--r", "abc"],
        vec!["trace", dir, "--threads", "0"],
        vec!["trace", dir, "--threads", "4096"],
        vec!["trace", dir, "--extended-precision", "maybe"],
        vec!["trace", dir, "--extended-precision", "1"],
        vec!["trace", dir, "--alpha-start", "2", "--alpha-end", "2"],
        vec!["trace"],
        vec!["frobnicate"],
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).is_empty());
    }
}

#[test]
fn broken_copy_of_the_sample() {
    // The sample with a meta.json that disagrees with its matrices.
    let d = TempDir::new("samplebad");
    for f in ["A.mtx", "N.mtx", "T.mtx", "f0.txt", "f1.txt", "gap.txt"] {
        std::fs::copy(sample_dir().join(f), d.path().join(f)).unwrap();
    }
    std::fs::write(
        d.path().join("meta.json"),
        r#"{"n": 1320, "p": 31, "F": 0.3, "alpha_start": -0.5, "alpha_end": 1.5}"#,
    )
    .unwrap();
    let o = run(&["trace", d.path().to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("N.mtx:3:"), "{}", stderr(&o));
    assert!(stderr(&o).contains("expected 31x1320"), "{}", stderr(&o));
}

// ---------------------------------------------------------------------------------------
// The sample.
// ---------------------------------------------------------------------------------------

#[test]
fn sample_runs_through_the_cli() {
    let (v, table) = trace_json(&sample_dir(), &[]);
    assert_eq!(v["n"], 1320);
    assert_eq!(v["p"], 30);
    assert_eq!(v["alpha_start"], -0.5);
    assert_eq!(v["alpha_end"], 1.5);
    assert_eq!(v["end"]["reason"], "window");
    let events = v["events"].as_array().unwrap();
    assert!(!events.is_empty(), "the sample has transition points");
    // The JSON is the library's path, α exactly (serde_json writes round-trip numbers).
    let case = CaseData::read_dir(&sample_dir()).unwrap();
    let problem = Arc::new(case.problem(None).unwrap());
    let opts = PathOptions::window(case.alpha_start, case.alpha_end);
    let mut path = Path::new(problem, case.load().unwrap(), opts).unwrap();
    path.start(case.alpha_start, None).unwrap();
    path.run().unwrap();
    assert_eq!(path.events().len(), events.len());
    for (e, j) in path.events().iter().zip(events) {
        assert_eq!(e.alpha.to_bits(), j["alpha"].as_f64().unwrap().to_bits());
        assert_eq!(e.node as u64 + 1, j["node"].as_u64().unwrap());
        assert_eq!(e.from.name(), j["from"].as_str().unwrap());
        assert_eq!(e.to.name(), j["to"].as_str().unwrap());
    }
    // Extended precision on (the sample's W is well conditioned: auto leaves it off):
    // the same transitions, α to rounding; stderr says so, and only then.
    let out_dir = TempDir::new("ext");
    let json_path = out_dir.path().join("out.json");
    let dir = sample_dir();
    let o = run(&[
        "trace",
        dir.to_str().unwrap(),
        "--extended-precision",
        "on",
        "--json",
        json_path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("extended precision: W (condition estimate"),
        "{}",
        stderr(&o)
    );
    let ext: Value = serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    let (a, b) = (event_list(&v), event_list(&ext));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!(
            (x.0 - y.0).abs() <= 1e-12 * x.0.abs().max(1.0)
                && (x.1, &x.2, &x.3) == (y.1, &y.2, &y.3),
            "{x:?} {y:?}"
        );
    }
    for mode in ["auto", "off"] {
        let o = run(&["trace", dir.to_str().unwrap(), "--extended-precision", mode]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            !stderr(&o).contains("extended precision"),
            "{mode}: {}",
            stderr(&o)
        );
    }
    // The set-up on 2 threads: the same transitions, α to rounding.
    let (t2, _) = trace_json(&sample_dir(), &["--threads", "2"]);
    let (a, b) = (event_list(&v), event_list(&t2));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!(
            (x.0 - y.0).abs() <= 1e-12 * x.0.abs().max(1.0),
            "{x:?} {y:?}"
        );
        assert_eq!((x.1, &x.2, &x.3), (y.1, &y.2, &y.3));
    }
    // Every event has a table row with its 1-based node and its α to 14 digits.
    for e in events {
        let alpha = e["alpha"].as_f64().unwrap();
        let node = e["node"].as_u64().unwrap().to_string();
        assert!(
            table.lines().any(|l| {
                let c: Vec<&str> = l.split_whitespace().collect();
                let fourteen = c.get(1).is_some_and(|a| {
                    let digits: String = a
                        .chars()
                        .take_while(|&ch| ch != 'e')
                        .filter(char::is_ascii_digit)
                        .collect();
                    digits.trim_start_matches('0').len() == 14
                });
                c.len() >= 6
                    && fourteen
                    && c[1]
                        .parse::<f64>()
                        .is_ok_and(|a| (a - alpha).abs() <= 5e-14 * alpha.abs())
                    && c[2] == node
            }),
            "no row for α {alpha}, node {node}:\n{table}"
        );
    }
}

/// Every event of the sample is confirmed by fixed-α solves on fresh paths at α ∓ δ, with
/// δ a quarter of the distance to the neighbouring transition points (capped at 1e-3 of
/// the window): the node's class there is the reported `from` and `to`, and the whole class
/// vector and the contact forces agree with the traced path's own solution at α ∓ δ.
#[test]
fn sample_events_confirmed_by_fixed_alpha_solves() {
    let case = CaseData::read_dir(&sample_dir()).unwrap();
    let problem = Arc::new(case.problem(None).unwrap());
    let opts = PathOptions::window(case.alpha_start, case.alpha_end);
    let mut path = Path::new(Arc::clone(&problem), case.load().unwrap(), opts.clone()).unwrap();
    path.start(case.alpha_start, None).unwrap();
    path.run().unwrap();
    let events = path.events().to_vec();
    let pieces = path.pieces().to_vec();
    assert!(!events.is_empty());
    // α of each transition point, with the window ends as outer neighbours.
    let mut tp_alpha = vec![case.alpha_start];
    for e in &events {
        if e.transition + 1 == tp_alpha.len() {
            tp_alpha.push(e.alpha);
        }
    }
    tp_alpha.push(case.alpha_end);
    let width = (case.alpha_end - case.alpha_start).abs();
    let fresh_classes = |alpha: f64| -> (Vec<Class>, Vec<f64>) {
        let mut p = Path::new(Arc::clone(&problem), case.load().unwrap(), opts.clone()).unwrap();
        p.start(alpha, None)
            .unwrap_or_else(|e| panic!("fixed-α solve at {alpha}: {e}"));
        let s = p.start_state().unwrap();
        assert!(
            s.residual <= 1e-12,
            "fixed-α residual {} at {alpha}",
            s.residual
        );
        (s.classes.clone(), s.lambda_n.clone())
    };
    let mut confirmed = 0;
    for e in &events {
        let t = e.transition + 1; // position in tp_alpha
        let gap = (tp_alpha[t] - tp_alpha[t - 1])
            .abs()
            .min((tp_alpha[t + 1] - tp_alpha[t]).abs());
        assert!(gap > 0.0, "two transition points at the same α {}", e.alpha);
        let delta = (0.25 * gap).min(1e-3 * width);
        let before = &pieces[e.transition];
        let after = &pieces[e.transition + 1];
        assert!(
            before.direction != 0 && after.direction != 0,
            "vertical piece in the sample at α = {}",
            e.alpha
        );
        assert!(
            !e.fold && before.direction == after.direction,
            "fold in the sample at α = {} (F = 0.3: none expected)",
            e.alpha
        );
        let d = f64::from(before.direction);
        let (a_before, a_after) = (e.alpha - d * delta, e.alpha + d * delta);
        let (cb, ln_b) = fresh_classes(a_before);
        let (ca, ln_a) = fresh_classes(a_after);
        assert_eq!(
            cb[e.node],
            e.from,
            "node {} before α = {}",
            e.node + 1,
            e.alpha
        );
        assert_eq!(
            ca[e.node],
            e.to,
            "node {} after α = {}",
            e.node + 1,
            e.alpha
        );
        assert_eq!(cb, before.classes, "classes before α = {}", e.alpha);
        assert_eq!(ca, after.classes, "classes after α = {}", e.alpha);
        // The traced path's own solution at α ∓ δ (one piece solve) agrees.
        for (alpha, ln) in [(a_before, &ln_b), (a_after, &ln_a)] {
            let sols = path.solutions_at(alpha).unwrap();
            assert_eq!(sols.len(), 1, "one solution at {alpha}");
            let scale = ln.iter().fold(1e-300_f64, |m, x| m.max(x.abs()));
            for (x, y) in sols[0].state.lambda_n.iter().zip(ln) {
                assert!((x - y).abs() <= 1e-9 * scale, "λν {x} vs {y} at {alpha}");
            }
        }
        confirmed += 1;
    }
    assert_eq!(confirmed, events.len());
}

/// A bifurcation at the start point is said on stderr, with the pieces that leave it
/// (tests/data/vertex-start: the brute force of tests/common finds the three curves
/// (open, slip+), (slip-, slip+), (stick, slip-) leaving alpha = 0 toward -1), and the
/// table (stdout) is the first branch's.
#[test]
fn start_bifurcation_is_reported() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/data/vertex-start");
    let o = run(&["trace", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("3 pieces leave the start point toward alpha_end")
            && err.contains("node 1 open, node 2 slip+")
            && err.contains("node 1 slip-, node 2 slip+")
            && err.contains("node 1 stick, node 2 slip-"),
        "{err}"
    );
    assert!(
        stdout(&o).contains("1 open, 0 stick, 1 slip+, 0 slip-"),
        "{}",
        stdout(&o)
    );
}

/// An ill-conditioned W traced in double is never silent. A slender strip (59 contact
/// nodes on 6 × 0.1, W's condition estimate about 9e6): with `--extended-precision off`
/// stderr says that W is ill-conditioned and traced in double, and the JSON's `precision`
/// says the same; with `auto` (a small problem: refined) the note is the refinement's and
/// `precision.extended` is true. The double events stay within 50 × condition × 1.1e-16
/// relative to max(1, |α|) of the refined ones (the same nodes and classes): the note and
/// docs/json-report.md say that W's rounding moves the solutions by condition × 1.1e-16
/// and a transition point by that divided by how steeply its guard crosses zero, and this
/// strip's guards cross steeply.
#[test]
fn ill_conditioned_w_in_double_is_reported() {
    let tmp = TempDir::new("illcond");
    let dir = tmp.path().join("strip");
    let o = run(&[
        "gen-rect",
        "--press-shear",
        "--nx",
        "60",
        "--ny",
        "3",
        "--lx",
        "6",
        "--ly",
        "0.1",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let trace = |mode: &str| -> (String, Value) {
        let json = tmp.path().join(format!("{mode}.json"));
        let o = run(&[
            "trace",
            dir.to_str().unwrap(),
            "--extended-precision",
            mode,
            "--json",
            json.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        let v = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        (stderr(&o), v)
    };
    let (err_off, off) = trace("off");
    let (err_auto, auto) = trace("auto");
    let kappa = off["precision"]["w_condition_estimate"].as_f64().unwrap();
    assert!(kappa > 1e6, "condition estimate {kappa:e}");
    assert_eq!(off["precision"]["extended"], Value::Bool(false));
    assert!(
        err_off.contains("W is ill-conditioned (condition estimate") && err_off.contains("double"),
        "{err_off}"
    );
    assert_eq!(auto["precision"]["extended"], Value::Bool(true));
    assert!(
        err_auto.contains("refined beyond double") && !err_auto.contains("ill-conditioned"),
        "{err_auto}"
    );
    let (a, b) = (event_list(&off), event_list(&auto));
    assert!(a.len() > 50, "{} events", a.len());
    assert_eq!(a.len(), b.len());
    let bound = 50.0 * kappa * f64::EPSILON / 2.0;
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.1, &x.2, &x.3), (y.1, &y.2, &y.3));
        assert!(
            (x.0 - y.0).abs() <= bound * x.0.abs().max(1.0),
            "{x:?} {y:?}: beyond {bound:e}"
        );
    }
}

fn data_dir(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data")
        .join(name)
}

/// The class names of a JSON class array.
fn names(v: &Value) -> Vec<String> {
    v.as_array()
        .expect("classes array")
        .iter()
        .map(|c| c.as_str().expect("class name").to_string())
        .collect()
}

/// `--start-branch K` traces the K-th piece leaving the start point. On
/// tests/data/vertex-start the brute force of tests/common finds three curves leaving
/// alpha = 0 toward -1: (open, slip+), (slip-, slip+), (stick, slip-); the three values
/// of K trace one each, in the order of the note. K beyond them, or above 1 where one piece
/// leaves the start, is an input error (exit 2) naming what is there.
#[test]
fn start_branch_option_traces_each_piece_leaving_the_start() {
    let dir = data_dir("vertex-start");
    let mut first = Vec::new();
    for k in ["1", "2", "3"] {
        let (v, table) = trace_json(&dir, &["--start-branch", k]);
        assert_eq!(v["end"]["reason"], "window", "K = {k}");
        first.push(names(&v["pieces"][0]["classes"]));
        assert!(
            table.contains("end: alpha = -1.0000000000000, reason window"),
            "{table}"
        );
    }
    first.sort();
    let want: Vec<Vec<String>> = [["open", "slip+"], ["slip-", "slip+"], ["stick", "slip-"]]
        .iter()
        .map(|c| c.iter().map(|s| s.to_string()).collect())
        .collect();
    assert_eq!(first, want);
    let o = run(&["trace", dir.to_str().unwrap(), "--start-branch", "4"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--start-branch 4: 3 pieces leave the start point toward alpha_end"),
        "{}",
        stderr(&o)
    );
    let sample = sample_dir();
    let o = run(&["trace", sample.to_str().unwrap(), "--start-branch", "2"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--start-branch 2: 1 piece leaves the start point"),
        "{}",
        stderr(&o)
    );
    let o = run(&["trace", sample.to_str().unwrap(), "--start-branch", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// Where the path stops at a bifurcation, stderr lists the pieces that continue it and
/// says how to follow one, and `--branch K` follows the K-th of `end.branches` (the
/// library's candidates, checked against a brute-force enumeration by
/// tests/core_symmetric.rs and, on this very case, python/tests): tests/data/bifurcation-
/// stop, a mirror-symmetric pair, stops near alpha = -0.53 with three candidates. With
/// `--branch K` the events up to the bifurcation are the same, the next piece is
/// candidate K, its events there are flagged `bifurcation`, and the path reaches the
/// window's end. An index beyond the candidates is an input error; a `--branch` left
/// over is said.
#[test]
fn branch_option_continues_a_bifurcation_stop() {
    let dir = data_dir("bifurcation-stop");
    let out_dir = TempDir::new("bif");
    let json_path = out_dir.path().join("stop.json");
    let o = run(&[
        "trace",
        dir.to_str().unwrap(),
        "--json",
        json_path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stop: Value = serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    check_schema(&stop);
    assert_eq!(stop["end"]["reason"], "bifurcation");
    let cands = stop["end"]["branches"].as_array().expect("end.branches");
    assert_eq!(cands.len(), 3);
    let at = fricont_exchange::report::fmt_alpha(num(&stop["end"]["alpha"], "end.alpha"));
    assert!(
        stderr(&o).contains(&format!(
            "the path stops at a bifurcation at alpha = {at}: 3 pieces continue it"
        )) && stderr(&o).contains("--branch K follows piece K"),
        "{}",
        stderr(&o)
    );
    let before = event_list(&stop);
    let npieces = stop["pieces"].as_array().unwrap().len();
    for (k, cand) in cands.iter().enumerate() {
        let kk = (k + 1).to_string();
        let (v, _) = trace_json(&dir, &["--branch", &kk]);
        assert_eq!(v["end"]["reason"], "window", "K = {kk}");
        let events = event_list(&v);
        assert_eq!(&events[..before.len()], &before[..], "K = {kk}");
        let next = &v["pieces"][npieces];
        assert_eq!(names(&next["classes"]), names(&cand["classes"]), "K = {kk}");
        assert_eq!(next["direction"], cand["direction"], "K = {kk}");
        let at_bif: Vec<&Value> = v["events"]
            .as_array()
            .unwrap()
            .iter()
            .skip(before.len())
            .take_while(|e| e["alpha"] == stop["end"]["alpha"])
            .collect();
        assert!(
            !at_bif.is_empty() && at_bif.iter().all(|e| e["bifurcation"] == true),
            "K = {kk}: {at_bif:?}"
        );
    }
    let o = run(&["trace", dir.to_str().unwrap(), "--branch", "4"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--branch 4: 3 pieces continue the path at the bifurcation"),
        "{}",
        stderr(&o)
    );
    let o = run(&[
        "trace",
        dir.to_str().unwrap(),
        "--branch",
        "1",
        "--branch",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("following piece 1 (--branch)")
            && stderr(&o).contains("--branch 2 not used"),
        "{}",
        stderr(&o)
    );
}
