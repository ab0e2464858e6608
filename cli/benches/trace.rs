//! Benchmark (not a test): set-up against trace time on a problem directory.
//!
//! ```text
//! cargo bench --bench trace                 # tests/data/sample-rect30
//! cargo bench --bench trace -- DIR          # another problem directory
//! FRICONT_BENCH_CASE=DIR FRICONT_BENCH_REPS=15 cargo bench --bench trace
//! FRICONT_BENCH_LOAD=basis-sine cargo bench --bench trace -- DIR
//! FRICONT_BENCH_THREADS=2 cargo bench --bench trace -- DIR
//! FRICONT_BENCH_REPS=1 FRICONT_BENCH_TRACES=20 cargo bench --bench trace -- DIR  # to profile
//! FRICONT_BENCH_LOAD=general-sine FRICONT_BENCH_AMP=0.05 cargo bench --bench trace -- DIR
//! ```
//!
//! `FRICONT_BENCH_THREADS` (default 1) is the problem's `threads`: the set-up's, and the
//! trace's dense passes where 2p ≥ `fricont::PARALLEL_MIN_ORDER`.
//!
//! `FRICONT_BENCH_LOAD` chooses the load: `affine` (default: the directory's f0 + α f1),
//! or the oscillating `f0 + φ(α) f1`, `φ(α) = α + A sin(2π·10 (α − α_start)/L)` with
//! L the window's length and A = L/100 (ten periods over the window; `FRICONT_BENCH_AMP=a`
//! sets A = a L: from a = 1/(20π) ≈ 0.016 on, φ is not monotone and every guard turns
//! where φ does), given as a basis
//! load (`basis-sine`: vectors f0, f1 and the weights) or as a general load
//! (`general-sine`: f itself, condensed at every α).
//!
//! Set-up = building the problem (validation, sparse Cholesky of A, W = B A⁻¹ Bᵀ) and
//! binding the load (condensed load vectors). Trace = the start solve plus every step to
//! the end of the window, on a fresh path over the same problem. Reading the files is
//! timed apart and counted in neither. Each is repeated (default 7 times) and the median
//! and minimum are printed (`FRICONT_BENCH_TRACES=k`: k traces after each set-up, all
//! counted in the trace's median), with the ratio trace/set-up of the medians (SPEC §6 wants it
//! below 1 for the sample).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use fricont::load::{Load, LoadFailure};
use fricont::path::{Path, PathOptions};
use fricont_exchange::io::CaseData;

fn median_min(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let med = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    (med, v[0])
}

fn main() {
    // cargo passes `--bench` (and maybe other flags) to harness-less benches: skip flags.
    let arg_dir = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let dir = arg_dir
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("FRICONT_BENCH_CASE").map(PathBuf::from))
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/data/sample-rect30")
        });
    let reps: usize = std::env::var("FRICONT_BENCH_REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|&k| k > 0)
        .unwrap_or(7);

    let t = Instant::now();
    let case = match CaseData::read_dir(&dir) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("bench trace: {e}");
            std::process::exit(2);
        }
    };
    let read_s = t.elapsed().as_secs_f64();
    let opts = PathOptions::window(case.alpha_start, case.alpha_end);
    let kind = std::env::var("FRICONT_BENCH_LOAD").unwrap_or_else(|_| "affine".into());
    let (a_start, len) = (case.alpha_start, case.alpha_end - case.alpha_start);
    let amp_frac: f64 = std::env::var("FRICONT_BENCH_AMP")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.01);
    let (amp, omega) = (amp_frac * len, 2.0 * std::f64::consts::PI * 10.0 / len);
    let load = || -> Load {
        let (f0, f1) = (case.f0.clone(), case.f1.clone());
        match kind.as_str() {
            "basis-sine" => Load::basis(
                vec![f0, f1],
                Box::new(move |a: f64, w: &mut [f64], dw: &mut [f64]| {
                    let x = omega * (a - a_start);
                    w[0] = 1.0;
                    w[1] = a + amp * x.sin();
                    dw[0] = 0.0;
                    dw[1] = 1.0 + amp * omega * x.cos();
                    Ok::<(), LoadFailure>(())
                }),
            )
            .expect("load"),
            "general-sine" => Load::general(
                f0.len(),
                Box::new(move |a: f64, out: &mut [f64]| {
                    let s = a + amp * (omega * (a - a_start)).sin();
                    for ((o, x), y) in out.iter_mut().zip(&f0).zip(&f1) {
                        *o = x + s * y;
                    }
                    Ok::<(), LoadFailure>(())
                }),
                None,
            ),
            "affine" => case.load().expect("load"),
            other => {
                eprintln!(
                    "bench trace: FRICONT_BENCH_LOAD={other}: affine, basis-sine or general-sine"
                );
                std::process::exit(2);
            }
        }
    };

    let threads: usize = std::env::var("FRICONT_BENCH_THREADS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    // Traces per set-up (default 1); more make a profile of the trace alone.
    let traces: usize = std::env::var("FRICONT_BENCH_TRACES")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|&k| k > 0)
        .unwrap_or(1);
    let mut setup = Vec::with_capacity(reps);
    let mut trace = Vec::with_capacity(reps);
    let mut start = Vec::with_capacity(reps);
    let mut summary = String::new();
    for _ in 0..reps {
        let t = Instant::now();
        let problem = Arc::new(case.builder().threads(threads).build().expect("problem"));
        let path = Path::new(Arc::clone(&problem), load(), opts.clone()).expect("path");
        setup.push(t.elapsed().as_secs_f64());
        drop(path);

        for _ in 0..traces {
            // A fresh path on the same problem: binding the load is set-up, not trace.
            let mut path = Path::new(Arc::clone(&problem), load(), opts.clone()).expect("path");
            let t = Instant::now();
            path.start(opts.alpha_start, None).expect("start");
            start.push(t.elapsed().as_secs_f64());
            let end = path.run().expect("run");
            trace.push(t.elapsed().as_secs_f64());
            std::hint::black_box(path.events().len());
            summary = format!(
                "{} events, {} pieces, {} refactorisations, end: {}",
                path.events().len(),
                path.pieces().len(),
                path.refactorisations(),
                end.name()
            );
        }
    }
    let (s_med, s_min) = median_min(&mut setup);
    let (t_med, t_min) = median_min(&mut trace);
    let (st_med, st_min) = median_min(&mut start);
    println!(
        "case {} (n = {}, p = {}), load {kind}, {threads} thread(s), {reps} repetitions; {summary}",
        dir.display(),
        case.n(),
        case.p()
    );
    println!("read    {:>12.6} ms (once, not counted)", read_s * 1e3);
    println!(
        "set-up  median {:>12.6} ms   min {:>12.6} ms   (Cholesky of A, W, condensed load)",
        s_med * 1e3,
        s_min * 1e3
    );
    println!(
        "trace   median {:>12.6} ms   min {:>12.6} ms   (start solve + all steps)",
        t_med * 1e3,
        t_min * 1e3
    );
    println!(
        "  of which start solve: median {:>12.6} ms   min {:>12.6} ms",
        st_med * 1e3,
        st_min * 1e3
    );
    println!(
        "ratio trace/set-up: median {:.4}, min {:.4}",
        t_med / s_med,
        t_min / s_min
    );
}
