//! Benchmark (not a test): time per transition on thin strips as p grows.
//!
//! ```text
//! cargo bench --bench strips                  # p = 240, 480, 960, 1920
//! cargo bench --bench strips -- 240 480       # chosen sizes
//! FRICONT_BENCH_FRESH=480 cargo bench --bench strips   # also fresh factorisations up to p = 480
//! FRICONT_BENCH_EXTENDED=on cargo bench --bench strips -- 1920   # extended precision on|off (default auto)
//! FRICONT_BENCH_THREADS=2 cargo bench --bench strips -- 1920       # the problem's threads (default 1)
//! FRICONT_BENCH_REPS=3 cargo bench --bench strips -- 480 1920      # each strip traced 3 times
//! ```
//!
//! Each strip is the rectangle generator's press-shear case with `p + 1 × 4` nodes on
//! `(0, p/40) × (0, 0.1)` (n = 8p dofs, p contact nodes along the bottom). The trace starts
//! at the window's start and runs to the end of the path; printed: transitions, end
//! reason, set-up time, the start solve's time, the trace time (start included), the time
//! per transition (start excluded), fresh factorisations of a base
//! piece matrix, the peak resident memory of the process so far, and whether the problem
//! was carried in extended precision (`ext`: W refined and transition points polished in
//! double-double; the set-up time includes the refinement). With
//! `FRICONT_BENCH_FRESH=P`, strips with p ≤ P are traced a second time with a fresh
//! factorisation of every piece (the reference tracer) for the ratio. With
//! `FRICONT_BENCH_REPS=N` each strip is set up and traced N times (a row each), and a
//! summary gives each size's least and median time per transition and their ratios to the
//! first size's: on this shared machine a short trace (p = 480: 2 s) varies by up to
//! 1.7× from run to run, a long one (p = 1920: 200 s) by a few percent, so a growth taken
//! from single traces says as much about the moment as about the code.

use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use fricont::ExtendedPrecision;
use fricont::path::{Path, PathOptions};
use fricont_exchange::generator::{RectSpec, generate};
use fricont_exchange::io::CaseData;

fn peak_mib() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn strip(dir: &FsPath, p: usize) -> PathBuf {
    let d = dir.join(format!("strip-p{p}"));
    if !d.join("A.mtx").exists() {
        let spec = RectSpec {
            nx: p + 1,
            ny: 4,
            lx: p as f64 / 40.0,
            ly: 0.1,
            ..RectSpec::press_shear()
        };
        let case = generate(&spec).unwrap_or_else(|e| panic!("generate p = {p}: {e}"));
        case.write_dir(&d)
            .unwrap_or_else(|e| panic!("write {}: {e}", d.display()));
    }
    d
}

fn trace(case: &CaseData, fresh: bool) -> (usize, String, f64, f64, f64, usize, bool) {
    let t = Instant::now();
    let mode = match std::env::var("FRICONT_BENCH_EXTENDED").as_deref() {
        Ok("on") => ExtendedPrecision::On,
        Ok("off") => ExtendedPrecision::Off,
        _ => ExtendedPrecision::Auto,
    };
    let threads: usize = std::env::var("FRICONT_BENCH_THREADS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let problem = Arc::new(
        case.builder()
            .extended_precision(mode)
            .threads(threads)
            .build()
            .expect("problem"),
    );
    let ext = problem.extended_precision();
    let mut opts = PathOptions::window(case.alpha_start, case.alpha_end);
    opts.fresh_factorisations = fresh;
    let mut path = Path::new(problem, case.load().expect("load"), opts).expect("path");
    let setup = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let started = path.start(case.alpha_start, None);
    let start = t.elapsed().as_secs_f64();
    let end = match started.and_then(|_| path.run()) {
        Ok(_) => path
            .end_reason()
            .map_or("none".to_string(), |r| r.name().to_string()),
        Err(e) => format!("failed: {e}"),
    };
    let secs = t.elapsed().as_secs_f64();
    let transitions = path.events().last().map_or(0, |e| e.transition + 1);
    (
        transitions,
        end,
        setup,
        start,
        secs,
        path.refactorisations(),
        ext,
    )
}

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if sizes.is_empty() {
        vec![240, 480, 960, 1920]
    } else {
        sizes
    };
    let fresh_up_to: usize = std::env::var("FRICONT_BENCH_FRESH")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let reps: usize = std::env::var("FRICONT_BENCH_REPS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1)
        .max(1);
    let tmp = std::env::temp_dir().join("fricont-bench-strips");
    println!(
        "{:>6} {:>7} {:>11} {:>9} {:>9} {:>9} {:>12} {:>8} {:>9} {:>4}  end",
        "p",
        "n",
        "transitions",
        "setup s",
        "start s",
        "trace s",
        "ms/transit.",
        "refact.",
        "peak MiB",
        "ext"
    );
    // (p, least and median ms per transition of the updated tracer over the repetitions)
    let mut summary: Vec<(usize, f64, f64)> = Vec::new();
    for &p in &sizes {
        let dir = strip(&tmp, p);
        let case = CaseData::read_dir(&dir).expect("read");
        let mut runs = vec![("updated", false)];
        if p <= fresh_up_to {
            runs.push(("fresh", true));
        }
        for (name, fresh) in runs {
            let mut per: Vec<f64> = Vec::new();
            for _ in 0..reps {
                let (tr, end, setup, start, secs, refact, ext) = trace(&case, fresh);
                let ms = 1e3 * (secs - start) / tr.max(1) as f64;
                per.push(ms);
                println!(
                    "{p:>6} {:>7} {tr:>11} {setup:>9.2} {start:>9.2} {secs:>9.2} {ms:>12.2} {refact:>8} {:>9.0} {:>4}  {end} ({name})",
                    case.a.nrows(),
                    peak_mib().unwrap_or(f64::NAN),
                    if ext { "yes" } else { "no" }
                );
            }
            if !fresh {
                per.sort_by(f64::total_cmp);
                summary.push((p, per[0], per[per.len() / 2]));
            }
        }
    }
    if reps > 1 {
        let (p0, least0, median0) = summary[0];
        println!("ms per transition over {reps} traces each (least, median; ratio to p = {p0}):");
        for &(p, least, median) in &summary {
            println!(
                "{p:>6} {least:>9.2} {median:>9.2}  ({:.1}x, {:.1}x)",
                least / least0,
                median / median0
            );
        }
    }
}
