//! A deterministic mutation test of the exchange-format reader and what follows it (issue
//! 10, item 6): a few thousand mutants of a small generated rectangle and a few hundred of
//! the repository's sample (tests/data/sample-rect30), from a fixed seed — bytes flipped,
//! lines truncated, deleted, duplicated or swapped, numbers replaced by NaN, infinities,
//! huge, tiny, negative or garbage values, wrong headers and size lines, indices out of
//! range, `meta.json` keys changed or removed, files removed. For every mutant:
//!
//! * reading is a clean `Err` or a success, never a panic;
//! * on success the problem is built and a path traced for a few steps (`max_steps` 5):
//!   every call is a clean `Err` or `Ok`, never a panic;
//! * every reported point is certified from the data: the start state's and every
//!   event's residual (`Path::event_state`) is ≤ 1e-10, and every event's forces obey
//!   the contact law of the classes after it (λν ≤ 0, |λt| ≤ F |λν|, λ = 0 when open, to
//!   1e-9 of the path's force scale).
//!
//! A failure names the mutant (its base case, index and mutation) so that it can be
//! replayed alone: `FRICONT_MUTANT=base:index cargo test --release --test mutation`.
//! `FRICONT_MUTATION_SEED=S FRICONT_MUTATION_COUNT=K` explore other seeds (both bases;
//! the sample gets K / 10 mutants).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;

use fricont::{Class, EndReason, Path, PathOptions, StepOutcome};
use fricont_exchange::generator::{RectSpec, generate};
use fricont_exchange::io::CaseData;

/// splitmix64: a tiny, well-mixed generator (Steele, Lea, Flood 2014), fixed seed.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `0..n` (n ≥ 1).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// The files of a problem directory, as bytes.
struct Files(Vec<(String, Vec<u8>)>);

impl Files {
    fn read(dir: &FsPath) -> Files {
        let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                (
                    e.file_name().into_string().unwrap(),
                    std::fs::read(e.path()).unwrap(),
                )
            })
            .collect();
        v.sort();
        Files(v)
    }
}

/// Replacements for a number: non-finite, extreme, negative, malformed.
const NUMBERS: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "Infinity",
    "1e308",
    "-1e308",
    "1e309",
    "1e-320",
    "4.9e-324",
    "0",
    "-0",
    "-1",
    "-1e-300",
    "1e300",
    "3.5",
    "2",
    "0.5",
    "-7",
    "1e20",
    "18446744073709551616",
    "9223372036854775807",
    "-9223372036854775808",
    "garbage",
    "",
    "0x10",
    "1.5D+00",
    "1,5",
    "--1",
    "1e",
    ".",
    "+",
    "1.0.0",
    "99999999999999999999999999",
];

/// Replacement header lines for a Matrix Market file.
const HEADERS: &[&str] = &[
    "%%MatrixMarket matrix coordinate real symmetric",
    "%%MatrixMarket matrix coordinate real general",
    "%%MatrixMarket matrix coordinate integer general",
    "%%MatrixMarket matrix coordinate complex general",
    "%%MatrixMarket matrix array real general",
    "%%MatrixMarket matrix coordinate real skew-symmetric",
    "%%MatrixMarket matrix coordinate real hermitian",
    "%%MatrixMarket matrix coordinate pattern general",
    "%%matrixmarket MATRIX Coordinate REAL General",
    "%MatrixMarket matrix coordinate real general",
    "",
    "% a comment",
    "%%MatrixMarket matrix coordinate real",
];

/// meta.json values for a key.
const META_VALUES: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "3",
    "1e15",
    "1.5",
    "1320.0",
    "null",
    "true",
    "\"5\"",
    "[]",
    "[0.3]",
    "[0.3, 0.3]",
    "{}",
    "1e400",
    "-0.5",
    "0.3",
    "100",
    "1e-300",
    "-1e300",
    "1e300",
    "7",
];

/// One mutant of `base`: the file changed, its new content (`None`: removed) and a
/// description.
fn mutate(base: &Files, rng: &mut SplitMix) -> (usize, Option<Vec<u8>>, String) {
    let fi = rng.below(base.0.len());
    let name = base.0[fi].0.clone();
    let text = base.0[fi].1.clone();
    let lines: Vec<&[u8]> = text.split(|&b| b == b'\n').collect();
    let join = |ls: &[Vec<u8>]| ls.join(&b'\n');
    let owned: Vec<Vec<u8>> = lines.iter().map(|l| l.to_vec()).collect();
    let nl = owned.len();
    let op = rng.below(16);
    let (new, what): (Option<Vec<u8>>, String) = match op {
        0 => {
            // a byte replaced by any byte
            let mut t = text.clone();
            if t.is_empty() {
                (
                    Some(vec![rng.next() as u8]),
                    "a byte into the empty file".into(),
                )
            } else {
                let k = rng.below(t.len());
                let b = rng.next() as u8;
                t[k] = b;
                (Some(t), format!("byte {k} set to {b:#04x}"))
            }
        }
        1 => {
            // truncated anywhere
            let k = rng.below(text.len() + 1);
            (Some(text[..k].to_vec()), format!("truncated to {k} bytes"))
        }
        2 => {
            let k = rng.below(nl);
            let mut ls = owned.clone();
            ls.remove(k);
            (Some(join(&ls)), format!("line {} deleted", k + 1))
        }
        3 => {
            let k = rng.below(nl);
            let mut ls = owned.clone();
            ls.insert(k, owned[k].clone());
            (Some(join(&ls)), format!("line {} duplicated", k + 1))
        }
        4 => {
            let (a, b) = (rng.below(nl), rng.below(nl));
            let mut ls = owned.clone();
            ls.swap(a, b);
            (
                Some(join(&ls)),
                format!("lines {} and {} swapped", a + 1, b + 1),
            )
        }
        5..=7 => {
            // a number (token) replaced
            let k = rng.below(nl);
            let s = String::from_utf8_lossy(&owned[k]).to_string();
            let toks: Vec<&str> = s.split_whitespace().collect();
            if toks.is_empty() {
                (None, "nothing".into())
            } else {
                let t = rng.below(toks.len());
                let v = *rng.pick(NUMBERS);
                let mut nt: Vec<String> = toks.iter().map(|x| x.to_string()).collect();
                nt[t] = v.to_string();
                let mut ls = owned.clone();
                ls[k] = nt.join(" ").into_bytes();
                (
                    Some(join(&ls)),
                    format!("line {} token {} set to {v:?}", k + 1, t + 1),
                )
            }
        }
        8 if name.ends_with(".mtx") => {
            let h = *rng.pick(HEADERS);
            let mut ls = owned.clone();
            ls[0] = h.as_bytes().to_vec();
            (Some(join(&ls)), format!("header set to {h:?}"))
        }
        9 if name.ends_with(".mtx") => {
            // an index of an entry line out of range (or at the edge)
            let first = owned
                .iter()
                .position(|l| !l.is_empty() && l[0] != b'%')
                .unwrap_or(0);
            let k = (first + 1 + rng.below(nl.saturating_sub(first + 1).max(1))).min(nl - 1);
            let s = String::from_utf8_lossy(&owned[k]).to_string();
            let mut toks: Vec<String> = s.split_whitespace().map(|x| x.to_string()).collect();
            if toks.len() < 2 {
                (None, "nothing".into())
            } else {
                let t = rng.below(2);
                let v = rng
                    .pick(&[
                        "0",
                        "-1",
                        "1",
                        "100000",
                        "1321",
                        "31",
                        "30",
                        "2",
                        "4294967297",
                    ])
                    .to_string();
                toks[t] = v.clone();
                let mut ls = owned.clone();
                ls[k] = toks.join(" ").into_bytes();
                (
                    Some(join(&ls)),
                    format!("line {} index {} set to {v}", k + 1, t + 1),
                )
            }
        }
        10 if name == "meta.json" => {
            let key = *rng.pick(&["n", "p", "F", "alpha_start", "alpha_end"]);
            let v = *rng.pick(META_VALUES);
            let mut json: serde_json::Value =
                serde_json::from_slice(&text).expect("base meta.json");
            let obj = json.as_object_mut().unwrap();
            if rng.below(8) == 0 {
                obj.remove(key);
                (
                    Some(serde_json::to_vec(&json).unwrap()),
                    format!("meta key {key} removed"),
                )
            } else {
                // written as raw text (1e400 is not valid for serde_json's writer)
                obj.insert(key.into(), serde_json::Value::String("@@".into()));
                let t = serde_json::to_string(&json).unwrap().replace("\"@@\"", v);
                (Some(t.into_bytes()), format!("meta {key} = {v}"))
            }
        }
        11 | 14 | 15 => {
            // a value multiplied by a finite factor, ordinary or extreme (the file stays
            // readable: these mutants reach the builder and the tracer)
            let k = rng.below(nl);
            let s = String::from_utf8_lossy(&owned[k]).to_string();
            let toks: Vec<&str> = s.split_whitespace().collect();
            match toks.last().and_then(|t| t.parse::<f64>().ok()) {
                Some(x) => {
                    let f = *rng.pick(&[
                        1e300,
                        1e-300,
                        -1.0,
                        1e12,
                        1e-12,
                        0.0,
                        10.0,
                        0.1,
                        1e6,
                        1e-6,
                        2.0,
                        -3.0,
                        1.000_000_01,
                        1e3,
                        1e-3,
                    ]);
                    let mut nt: Vec<String> = toks.iter().map(|x| x.to_string()).collect();
                    *nt.last_mut().unwrap() = format!("{:e}", x * f);
                    let mut ls = owned.clone();
                    ls[k] = nt.join(" ").into_bytes();
                    (Some(join(&ls)), format!("line {} value times {f:e}", k + 1))
                }
                None => (None, "nothing".into()),
            }
        }
        12 => {
            // the file removed, or replaced by an empty one
            if rng.below(2) == 0 {
                return (fi, None, format!("{name} removed"));
            }
            (Some(Vec::new()), "emptied".into())
        }
        _ => {
            // a size-line or sparse-entry count change (mtx), else a byte flip at line start
            let first = owned
                .iter()
                .position(|l| !l.is_empty() && l[0] != b'%')
                .unwrap_or(0);
            let s = String::from_utf8_lossy(&owned[first]).to_string();
            let mut toks: Vec<String> = s.split_whitespace().map(|x| x.to_string()).collect();
            if toks.is_empty() {
                (None, "nothing".into())
            } else {
                let t = rng.below(toks.len());
                let d = *rng.pick(&[-2i64, -1, 1, 2, 1000]);
                let v = toks[t].parse::<i64>().map(|x| x + d).unwrap_or(d);
                toks[t] = v.to_string();
                let mut ls = owned.clone();
                ls[first] = toks.join(" ").into_bytes();
                (
                    Some(join(&ls)),
                    format!("line {} token {} set to {v}", first + 1, t + 1),
                )
            }
        }
    };
    let new = new.unwrap_or(text);
    (fi, Some(new), format!("{name}: {what}"))
}

/// What happened to one mutant.
#[derive(Debug, Default)]
struct Tally {
    read_err: usize,
    build_err: usize,
    trace_err: usize,
    traced: usize,
    events: usize,
}

/// Reads, builds and traces the directory; `Err` with the violated certificate.
fn check(dir: &FsPath, tally: &mut Tally) -> Result<(), String> {
    let Ok(case) = CaseData::read_dir(dir) else {
        tally.read_err += 1;
        return Ok(());
    };
    let (Ok(problem), Ok(load)) = (case.problem(None), case.load()) else {
        tally.build_err += 1;
        return Ok(());
    };
    let friction = problem.friction().to_vec();
    let p = problem.p();
    let mut opts = PathOptions::window(case.alpha_start, case.alpha_end);
    opts.max_steps = 5;
    let Ok(mut path) = Path::new(Arc::new(problem), load, opts) else {
        tally.build_err += 1;
        return Ok(());
    };
    if path.start(case.alpha_start, None).is_err() {
        tally.trace_err += 1;
        return Ok(());
    }
    // u is solved for on request: beyond the range of a double it is a clean error there.
    let start = match path.start_state() {
        Ok(s) => s,
        Err(fricont::Error::Numerical(m)) if m.contains("overflows") => {
            tally.trace_err += 1;
            return Ok(());
        }
        Err(e) => return Err(format!("the start state failed: {e}")),
    };
    if start.residual.is_nan() || start.residual > 1e-10 {
        return Err(format!(
            "the start state at α = {:.14e} has the residual {:e}",
            start.alpha, start.residual
        ));
    }
    let mut failed = false;
    loop {
        match path.step() {
            Ok(StepOutcome::End(_)) => break,
            Ok(StepOutcome::Transition { .. }) => {}
            Err(_) => {
                failed = true;
                break;
            }
        }
    }
    if failed || matches!(path.end_reason(), Some(EndReason::Failed(_))) {
        tally.trace_err += 1;
    } else {
        tally.traced += 1;
    }
    // What was reported, failed or not, must hold, to 1e-9 of the path's force scale:
    // the largest force reported, or the load at the event divided by the largest row of
    // B (λ ~ f / |B_i|; an event where every node is open has forces of rounding size).
    let inf = |v: &mut dyn Iterator<Item = &f64>| v.fold(0.0f64, |m, x| m.max(x.abs()));
    let row_norm = |m: &fricont::CsrMatrix, i: usize| m.row(i).map(|(_, v)| v * v).sum::<f64>();
    let max_row = (0..p)
        .map(|i| {
            row_norm(&case.n_mat, i)
                .max(row_norm(&case.t_mat, i))
                .sqrt()
        })
        .fold(0.0f64, f64::max);
    let path_forces = path
        .events()
        .iter()
        .map(|e| inf(&mut e.lambda_n.iter().chain(&e.lambda_t)))
        .fold(
            inf(&mut start.lambda_n.iter().chain(&start.lambda_t)),
            f64::max,
        );
    for (k, e) in path.events().iter().enumerate() {
        tally.events += 1;
        let load = inf(&mut case
            .f0
            .iter()
            .zip(&case.f1)
            .map(|(a, b)| a + e.alpha * b)
            .collect::<Vec<_>>()
            .iter());
        let scale = path_forces.max(load / max_row);
        let tol = 1e-9 * scale;
        for (i, &f) in friction.iter().enumerate() {
            let (ln, lt) = (e.lambda_n[i], e.lambda_t[i]);
            let ok = ln <= tol
                && lt.abs() <= f * ln.abs() + tol
                && (e.classes[i] != Class::Open || (ln.abs() <= tol && lt.abs() <= tol));
            if !ok {
                return Err(format!(
                    "event {} (α = {:.14e}, node {} {} -> {}): node {} ({}) has λν = {ln:e}, λt = {lt:e}, F = {f} (force scale {scale:e})",
                    k + 1,
                    e.alpha,
                    e.node + 1,
                    e.from,
                    e.to,
                    i + 1,
                    e.classes[i]
                ));
            }
        }
        match path.event_state(k) {
            Ok(s) if s.residual <= 1e-10 => {}
            Ok(s) => {
                return Err(format!(
                    "event {} (α = {:.14e}, node {} {} -> {}) has the residual {:e}",
                    k + 1,
                    e.alpha,
                    e.node + 1,
                    e.from,
                    e.to,
                    s.residual
                ));
            }
            // a clean error (u beyond the range of a double, …) is not a wrong answer
            Err(_) => {}
        }
    }
    Ok(())
}

fn write_files(dir: &FsPath, files: &Files) {
    if dir.exists() {
        std::fs::remove_dir_all(dir).unwrap();
    }
    std::fs::create_dir_all(dir).unwrap();
    for (name, text) in &files.0 {
        std::fs::write(dir.join(name), text).unwrap();
    }
}

/// Writes (or removes, for `None`) one file of the directory. The old file is removed
/// first: truncating and rewriting a file makes ext4 flush it on close (auto_da_alloc),
/// which made this test wait on the disk.
fn put(dir: &FsPath, name: &str, content: Option<&[u8]>) {
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    if let Some(t) = content {
        std::fs::write(path, t).unwrap();
    }
}

/// Runs `count` mutants of `base` (named `label`); returns the failures.
fn run(label: &str, base: &Files, seed: u64, count: usize, only: Option<usize>) -> Vec<String> {
    let dir: PathBuf =
        std::env::temp_dir().join(format!("fricont-mutation-{}-{label}", std::process::id()));
    let mut rng = SplitMix(seed);
    let mut tally = Tally::default();
    let mut failures = Vec::new();
    write_files(&dir, base);
    for index in 0..count {
        let (fi, content, what) = mutate(base, &mut rng);
        if only.is_some_and(|o| o != index) {
            continue;
        }
        let name = &base.0[fi].0;
        put(&dir, name, content.as_deref());
        let outcome = catch_unwind(AssertUnwindSafe(|| check(&dir, &mut tally)));
        put(&dir, name, Some(&base.0[fi].1));
        match outcome {
            Ok(Ok(())) => {}
            Ok(Err(m)) => failures.push(format!("mutant {label}:{index} ({what}): {m}")),
            Err(p) => {
                let m = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                failures.push(format!("mutant {label}:{index} ({what}): PANIC {m}"));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!("{label}: {count} mutants: {tally:?}");
    // The mutants must exercise every stage, not only the reader's errors.
    if only.is_none() {
        assert!(
            tally.read_err > count / 10 && tally.traced > count / 20 && tally.events > 0,
            "{label}: the mutants do not reach every stage: {tally:?}"
        );
    }
    failures
}

/// The seed and number of mutants: the fixed ones, or `FRICONT_MUTATION_SEED` (decimal
/// or 0x-hex; `salt` tells the bases apart) and `FRICONT_MUTATION_COUNT` (`divisor`
/// applied).
fn seed_count(seed: u64, count: usize, salt: u64, divisor: usize) -> (u64, usize) {
    let var = |k: &str| std::env::var(k).ok();
    let seed = var("FRICONT_MUTATION_SEED")
        .and_then(|v| match v.strip_prefix("0x") {
            Some(h) => u64::from_str_radix(&h.replace('_', ""), 16).ok(),
            None => v.parse().ok(),
        })
        .map_or(seed, |s| s ^ salt);
    let count = var("FRICONT_MUTATION_COUNT")
        .and_then(|v| v.parse::<usize>().ok())
        .map_or(count, |c| (c / divisor).max(1));
    (seed, count)
}

/// `FRICONT_MUTANT=base:index` replays one mutant.
fn only(label: &str) -> Option<Option<usize>> {
    match std::env::var("FRICONT_MUTANT") {
        Err(_) => Some(None),
        Ok(v) => {
            let (l, i) = v.split_once(':')?;
            (l == label).then(|| i.parse().ok())
        }
    }
}

#[test]
fn mutants_of_a_small_rectangle() {
    let Some(only) = only("rect") else { return };
    let spec = RectSpec {
        nx: 6,
        ny: 4,
        lx: 3.0,
        ly: 2.0,
        gap: 0.001,
        ..RectSpec::press_shear()
    };
    let dir = std::env::temp_dir().join(format!("fricont-mutation-{}-base", std::process::id()));
    generate(&spec).unwrap().write_dir(&dir).unwrap();
    let base = Files::read(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(base.0.iter().any(|f| f.0 == "gap.txt"));
    let (seed, count) = seed_count(0x5EED_0001, 3000, 1, 1);
    let failures = run("rect", &base, seed, count, only);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn mutants_of_the_sample() {
    let Some(only) = only("sample") else { return };
    let dir = FsPath::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/sample-rect30");
    let base = Files::read(&dir);
    let (seed, count) = seed_count(0x5EED_0002, 250, 2, 10);
    let failures = run("sample", &base, seed, count, only);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
