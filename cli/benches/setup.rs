//! Benchmark (not a test): the set-up on large generated cases, phase by phase.
//!
//! ```text
//! cargo bench --bench setup                 # generated: 481 × 321 rectangle, 1201 × 4 strip
//! cargo bench --bench setup -- DIR [DIR…]   # problem directories in the exchange format
//! FRICONT_BENCH_EXTENDED=on cargo bench --bench setup -- DIR   # extended precision on|off (default auto)
//! ```
//!
//! For each case it prints the time to read the files, the symbolic analysis (fill-reducing
//! ordering with the contact dofs last), the numeric Cholesky factorisation of A, forming
//! W (from the trailing block of the factor, or by 2p solves for wide rows), the estimate
//! of its condition number and whether it was refined (extended precision), the condensed
//! load vectors q (one solve each), nnz(L), and the peak resident memory of the process
//! (VmHWM). `benches-c/cholmod_setup_time.c` times CHOLMOD on the same A.mtx for
//! comparison (README, Benchmarks).

use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use fricont::ExtendedPrecision;
use fricont::path::{Path, PathOptions};
use fricont_exchange::generator::{RectSpec, generate};
use fricont_exchange::io::CaseData;

/// Peak resident memory of this process in MiB (Linux), if known.
fn peak_mib() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn generated(dir: &FsPath, nx: usize, ny: usize, lx: f64, ly: f64) -> PathBuf {
    let d = dir.join(format!("rect-{nx}x{ny}"));
    if !d.join("A.mtx").exists() {
        let spec = RectSpec {
            nx,
            ny,
            lx,
            ly,
            ..RectSpec::press_shear()
        };
        let case = generate(&spec).unwrap_or_else(|e| panic!("generate {nx}x{ny}: {e}"));
        case.write_dir(&d)
            .unwrap_or_else(|e| panic!("write {}: {e}", d.display()));
    }
    d
}

fn bench(dir: &FsPath) {
    let t = Instant::now();
    let case = match CaseData::read_dir(dir) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("bench setup: {e}");
            std::process::exit(2);
        }
    };
    let read_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mode = match std::env::var("FRICONT_BENCH_EXTENDED").as_deref() {
        Ok("on") => ExtendedPrecision::On,
        Ok("off") => ExtendedPrecision::Off,
        _ => ExtendedPrecision::Auto,
    };
    let problem = match case.builder().extended_precision(mode).build() {
        Ok(p) => Arc::new(p),
        Err(e) => {
            eprintln!("bench setup: {}: {e}", dir.display());
            std::process::exit(1);
        }
    };
    let build_s = t.elapsed().as_secs_f64();
    let times = problem.delassus().setup_times();
    let t = Instant::now();
    let load = case.load().expect("load");
    let path = Path::new(
        problem.clone(),
        load,
        PathOptions::window(case.alpha_start, case.alpha_end),
    )
    .expect("path");
    let q_s = t.elapsed().as_secs_f64();
    drop(path);
    println!(
        "{}: n = {}, p = {}, nnz(A) = {}, nnz(L) = {}, W by {}",
        dir.display(),
        problem.n(),
        problem.p(),
        case.a.nnz(),
        times.nnz_l,
        if problem.delassus().w_from_trailing_block() {
            "the trailing block"
        } else {
            "solves"
        }
    );
    println!(
        "  read {read_s:.3} s | analyse {:.3} s, factorise {:.3} s, W {:.3} s (set-up {build_s:.3} s incl. validation) | q {q_s:.3} s | peak {:.0} MiB",
        times.analyse_s,
        times.factorise_s,
        times.w_s,
        peak_mib().unwrap_or(f64::NAN)
    );
    println!(
        "  W: condition estimate {:.3e}, extended precision {}{}",
        problem.w_condition_estimate(),
        if problem.extended_precision() {
            "on"
        } else {
            "off"
        },
        if problem.delassus().w_lo().is_some() {
            format!(" (W_lo by refinement {:.3} s)", times.w_lo_s)
        } else {
            String::new()
        }
    );
}

fn main() {
    let dirs: Vec<PathBuf> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .map(PathBuf::from)
        .collect();
    if !dirs.is_empty() {
        for d in &dirs {
            bench(d);
        }
        return;
    }
    let tmp = std::env::temp_dir().join("fricont-bench-setup");
    // The size of the GetFEM mesh of the set-up issue (n = 308,160, p = 480), and a thin
    // strip with p = 1,200 contact nodes.
    let big = generated(&tmp, 481, 321, 3.0, 2.1);
    let strip = generated(&tmp, 1201, 4, 30.0, 0.1);
    bench(&big);
    bench(&strip);
}
