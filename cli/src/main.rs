//! `fricont`: the command-line front end.
//!
//! ```text
//! fricont trace DIR [--alpha-start A] [--alpha-end B] [--r R] [--max-steps K] [--threads N]
//!                   [--extended-precision auto|on|off] [--json FILE] [--progress]
//! ```
//!
//! reads a problem directory in the exchange format (`docs/exchange-format.md`), traces
//! the path, prints the transition table (α with 14 significant digits, 1-based nodes) and
//! the set-up/trace times, and writes the JSON report of `docs/json-report.md`. While it
//! works it shows its progress on stderr (the phase, then α's position in the window,
//! the transition points so far and the elapsed time, a few updates a second; then the
//! JSON report's phase, whose residuals take a back-solve per transition point) when
//! stderr is a terminal or `--progress` is given.
//!
//! Exit status: 0 when the path was traced (whatever its end reason except `failed`);
//! 2 for bad input (unreadable or malformed files, data the problem builder rejects,
//! an invalid window or option, a `--json` file that cannot be written — checked before
//! anything is read; the message is one line on stderr); 1 for a failure at run time
//! (the start solve or a step failed, the JSON could not be written at the end). On a
//! failure during tracing, what was traced is still printed and written.

use std::io::{IsTerminal as _, Write as _};
use std::path::{Path as FsPath, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand};

use fricont::path::{Path, PathOptions, StepOutcome};
use fricont_exchange::io::CaseData;
use fricont_exchange::report::{self, Timing};

/// Exact path-following of discrete 2D contact problems with Coulomb friction.
#[derive(Parser, Debug)]
#[command(name = "fricont", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Trace the solution path of a problem directory.
    ///
    /// The directory format (files, Matrix Market variants, duplicates, gzip, meta.json) is
    /// specified in docs/exchange-format.md, every key of the JSON report (--json) in
    /// docs/json-report.md.
    Trace(TraceArgs),
    /// Write a rectangle problem (Q1 plane strain, left side clamped, bottom on a rigid
    /// foundation) in the exchange format. Defaults: the case study (31 × 22 nodes).
    GenRect(GenRectArgs),
    /// Run the founding paper's case study: transition table, figures, path as CSV/JSON.
    CaseStudy(CaseStudyArgs),
}

#[derive(clap::Args, Debug)]
struct GenRectArgs {
    /// Output problem directory (created).
    dir: PathBuf,
    /// Start from the sample's "press-shear" load instead of the case study's load.
    #[arg(long)]
    press_shear: bool,
    /// Nodes along x (the bottom side has nx − 1 contact nodes).
    #[arg(long)]
    nx: Option<usize>,
    /// Nodes along y.
    #[arg(long)]
    ny: Option<usize>,
    /// Side length along x.
    #[arg(long, allow_negative_numbers = true)]
    lx: Option<f64>,
    /// Side length along y.
    #[arg(long, allow_negative_numbers = true)]
    ly: Option<f64>,
    /// Young's modulus.
    #[arg(long, allow_negative_numbers = true)]
    e: Option<f64>,
    /// Poisson's ratio.
    #[arg(long, allow_negative_numbers = true)]
    nu: Option<f64>,
    /// Friction coefficient of every contact node.
    #[arg(long, allow_negative_numbers = true)]
    friction: Option<f64>,
    /// Uniform initial gap (length units; negative: an initial overlap, which the
    /// problem allows).
    #[arg(long, allow_negative_numbers = true)]
    gap: Option<f64>,
    /// Tractions of f0, repeatable: SIDE:TX,TY or SIDE:TX,TY:TX2,TY2 (replaces the default).
    #[arg(long, allow_negative_numbers = true)]
    load0: Vec<String>,
    /// Tractions of f1 (per unit α), same form (replaces the default).
    #[arg(long, allow_negative_numbers = true)]
    load1: Vec<String>,
    /// Start of the α window written to meta.json.
    #[arg(long, allow_negative_numbers = true)]
    alpha_start: Option<f64>,
    /// End of the α window written to meta.json.
    #[arg(long, allow_negative_numbers = true)]
    alpha_end: Option<f64>,
}

#[derive(clap::Args, Debug)]
struct CaseStudyArgs {
    /// Output directory (created): table, figures (SVG), path (CSV, JSON), problem files.
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

#[derive(clap::Args, Debug)]
struct TraceArgs {
    /// Problem directory: A.mtx, N.mtx, T.mtx, f0.txt, f1.txt, [gap.txt], meta.json (each
    /// may be gzip-compressed as NAME.gz); see docs/exchange-format.md.
    dir: PathBuf,
    /// Start of the α window (default: `alpha_start` of meta.json).
    #[arg(long, allow_negative_numbers = true)]
    alpha_start: Option<f64>,
    /// End of the α window, traced toward first (default: `alpha_end` of meta.json).
    #[arg(long, allow_negative_numbers = true)]
    alpha_end: Option<f64>,
    /// Augmentation parameter r > 0 (default: 2p / trace W). Does not change the path.
    #[arg(long, allow_negative_numbers = true)]
    r: Option<f64>,
    /// Stop after this many transition points (at least 1; default 10000).
    #[arg(long)]
    max_steps: Option<usize>,
    /// Threads of the set-up (factorisation of A, forming W) and, where 2p ≥ 2048, of the
    /// trace's dense passes (LU factorisations, solves, products with W), 1..=1024.
    /// Results agree with one thread to rounding.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Carry W and the condensed loads beyond double precision (mixed-precision
    /// refinement with the factor of A, for slender bodies whose W is ill-conditioned):
    /// auto where the refinement is cheap (at most 6e9 flops, about 0.3 s: small problems,
    /// whatever W's condition), where the condition estimate of W exceeds 1e6 and the cost
    /// is at most max(20 x the factorisation of A, 1e11 flops), or, whatever it costs, where
    /// the estimate exceeds 1e8.
    #[arg(long, value_enum, default_value_t = Extended::Auto)]
    extended_precision: Extended,
    /// Write the JSON report to this file (every key: docs/json-report.md). The file is
    /// checked to be writable before anything is read or traced.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Show progress on stderr (the phase, α's position in the window, transition points
    /// so far, elapsed time) even when stderr is not a terminal; on a terminal it is shown
    /// anyway.
    #[arg(long)]
    progress: bool,
    /// Where several pieces leave the start point toward alpha_end (a bifurcation at the
    /// start, listed in a note on stderr), trace piece K (1-based; default 1).
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u64).range(1..))]
    start_branch: Option<u64>,
    /// Where the path stops at a bifurcation (several pieces continue it and none is
    /// singled out by the orientation; they are listed in a note on stderr), continue
    /// along piece K (1-based). Repeat the option for the bifurcations met after it, in
    /// order.
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u64).range(1..))]
    branch: Vec<u64>,
}

/// `--extended-precision`.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum Extended {
    Auto,
    On,
    Off,
}

/// A failure with its exit status.
struct Failure {
    status: u8,
    message: String,
}

fn input(msg: impl std::fmt::Display) -> Failure {
    Failure {
        status: 2,
        message: msg.to_string(),
    }
}

fn runtime(msg: impl std::fmt::Display) -> Failure {
    Failure {
        status: 1,
        message: msg.to_string(),
    }
}

/// The file of the JSON report, opened for writing before anything is traced (so a bad
/// path fails at once). Created here if it did not exist, and removed again when the run
/// ends without writing it; an existing file is left as it was until the report replaces
/// it.
struct JsonOut {
    path: PathBuf,
    file: std::fs::File,
    created: bool,
    written: bool,
}

impl JsonOut {
    fn open(path: &FsPath) -> Result<JsonOut, Failure> {
        let existed = path.exists();
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(|e| {
                input(format!(
                    "cannot write the JSON report to {}: {e}",
                    path.display()
                ))
            })?;
        Ok(JsonOut {
            path: path.to_path_buf(),
            file,
            created: !existed,
            written: false,
        })
    }

    fn write(mut self, text: &str) -> Result<(), Failure> {
        self.written = true;
        self.file
            .set_len(0)
            .and_then(|()| self.file.write_all(text.as_bytes()))
            .and_then(|()| self.file.flush())
            .map_err(|e| runtime(format!("cannot write {}: {e}", self.path.display())))
    }
}

impl Drop for JsonOut {
    fn drop(&mut self) {
        if self.created && !self.written {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Progress on stderr: phases as lines, then the tracing state (α's position in the
/// window, transition points so far, elapsed time), at most every 0.25 s on a terminal
/// (one line rewritten in place) and every second otherwise (one line each), and a final
/// line. Silent unless stderr is a terminal or `--progress` was given.
struct Progress {
    enabled: bool,
    tty: bool,
    t0: Instant,
    last: Option<Instant>,
    /// A line is open on the terminal (written with `\r`, not yet ended).
    open: bool,
}

impl Progress {
    fn new(asked: bool) -> Progress {
        let tty = std::io::stderr().is_terminal();
        Progress {
            enabled: asked || tty,
            tty,
            t0: Instant::now(),
            last: None,
            open: false,
        }
    }

    fn line(&mut self, text: &str) {
        if !self.enabled {
            return;
        }
        let mut err = std::io::stderr().lock();
        if self.open {
            let _ = write!(err, "\r\x1b[K");
            self.open = false;
        }
        let _ = writeln!(err, "fricont: {text}");
    }

    fn phase(&mut self, text: &str) {
        let t = self.t0.elapsed().as_secs_f64();
        self.line(&format!("[{t:.1} s] {text}"));
    }

    /// `[12.5 s] alpha = -0.422888 (4% of [-0.5, 1.5]), 1 transition point`: short
    /// enough for one line of an 80-column terminal (α to 6 decimals here; the table and
    /// the report give it to 14 significant digits).
    fn state(&self, alpha: f64, transitions: usize, window: (f64, f64)) -> String {
        let frac = (alpha - window.0) / (window.1 - window.0);
        format!(
            "[{:.1} s] alpha = {alpha:.6} ({:.0}% of [{}, {}]), {}",
            self.t0.elapsed().as_secs_f64(),
            100.0 * frac,
            window.0,
            window.1,
            report::plural(transitions, "transition point")
        )
    }

    /// After a step: shown when the last update is old enough.
    fn update(&mut self, alpha: f64, transitions: usize, window: (f64, f64)) {
        if !self.enabled {
            return;
        }
        let every = Duration::from_millis(if self.tty { 250 } else { 1000 });
        let now = Instant::now();
        if self.last.is_some_and(|t| now.duration_since(t) < every) {
            return;
        }
        self.last = Some(now);
        let text = self.state(alpha, transitions, window);
        let mut err = std::io::stderr().lock();
        if self.tty {
            let _ = write!(err, "\r\x1b[Kfricont: {text}");
            let _ = err.flush();
            self.open = true;
        } else {
            let _ = writeln!(err, "fricont: {text}");
        }
    }
}

fn trace(args: &TraceArgs) -> Result<(), Failure> {
    if args.max_steps == Some(0) {
        return Err(input(
            "--max-steps 0: at least one transition point must be allowed (the default is 10000)",
        ));
    }
    let json = args.json.as_deref().map(JsonOut::open).transpose()?;
    let mut progress = Progress::new(args.progress);
    progress.phase(&format!("reading {}", args.dir.display()));
    let case = CaseData::read_dir(&args.dir).map_err(input)?;
    let alpha_start = args.alpha_start.unwrap_or(case.alpha_start);
    let alpha_end = args.alpha_end.unwrap_or(case.alpha_end);
    let mut opts = PathOptions::window(alpha_start, alpha_end);
    if let Some(k) = args.max_steps {
        opts.max_steps = k;
    }

    progress.phase(&format!(
        "set-up: n = {}, p = {}, Cholesky of A and W = B A^-1 B^T",
        case.n(),
        case.p()
    ));
    let t0 = Instant::now();
    let mut builder =
        case.builder()
            .threads(args.threads)
            .extended_precision(match args.extended_precision {
                Extended::Auto => fricont::ExtendedPrecision::Auto,
                Extended::On => fricont::ExtendedPrecision::On,
                Extended::Off => fricont::ExtendedPrecision::Off,
            });
    if let Some(r) = args.r {
        builder = builder.r(r);
    }
    let problem = builder
        .build()
        .map_err(|e| input(format!("{}: {e}", args.dir.display())))?;
    // A note where the refinement is for W's condition (a slender body) or was asked
    // for; small problems are refined as a matter of course, without one.
    if problem.extended_precision()
        && (matches!(args.extended_precision, Extended::On)
            || problem.w_condition_estimate() > fricont::problem::AUTO_CONDITION)
    {
        eprintln!(
            "fricont: note: extended precision: W (condition estimate {:.1e}) refined beyond double in {:.2} s",
            problem.w_condition_estimate(),
            problem.delassus().setup_times().w_lo_s
        );
    } else if !problem.extended_precision()
        && problem.w_condition_estimate() > fricont::problem::AUTO_CONDITION
    {
        // An ill-conditioned W traced in double: say so, with what it costs in accuracy.
        let kappa = problem.w_condition_estimate();
        eprintln!(
            "fricont: note: W is ill-conditioned (condition estimate {kappa:.1e}) and traced in double{}: its rounding moves the solutions by about {:.0e} (condition x 1.1e-16) relative, and a transition point by that divided by how steeply its guard crosses zero (measured: up to 48 times that on a rectangle of estimate 1.6e6, 610 times on a strip of estimate 6.4e10); --extended-precision on refines it",
            if matches!(args.extended_precision, Extended::Auto) {
                " (auto refines only where that costs at most max(20 x the factorisation of A, 1e11) operations, or where the estimate exceeds 1e8)"
            } else {
                ""
            },
            kappa * f64::EPSILON / 2.0
        );
    }
    let load = case
        .load()
        .map_err(|e| input(format!("{}: {e}", args.dir.display())))?;
    let mut path = Path::new(Arc::new(problem), load, opts).map_err(input)?;
    let setup_s = t0.elapsed().as_secs_f64();

    progress.phase(&format!(
        "start: fixed-alpha solve at alpha = {alpha_start}"
    ));
    let t1 = Instant::now();
    path.start(alpha_start, None)
        .map_err(|e| runtime(format!("start at alpha = {alpha_start}: {e}")))?;
    // Where the solver failed and a fallback found the start: say which (where the
    // problem has several solutions at alpha_start, that decides which one is traced).
    let how = match path.start_route() {
        Some(fricont::StartRoute::Nearby) => Some("the path from a nearby alpha"),
        Some(fricont::StartRoute::ZeroLoad) => {
            Some("the path of tau f(alpha_start) from zero load (tau = 0 to 1)")
        }
        Some(fricont::StartRoute::Open) => Some("the path from a load that holds every node open"),
        Some(fricont::StartRoute::Solved) | None => None,
    };
    if let Some(how) = how {
        eprintln!(
            "fricont: note: the fixed-alpha solver failed at alpha = {alpha_start}; the start was reached by {how}"
        );
    }
    let offered = path.branches().len();
    let start_branch = args.start_branch.unwrap_or(1);
    if start_branch as usize > offered.max(1) {
        return Err(input(format!(
            "--start-branch {start_branch}: {} piece{} the start point toward alpha_end{}",
            offered.max(1),
            if offered > 1 { "s leave" } else { " leaves" },
            if offered > 1 {
                format!(" ({})", describe_branches(path.branches()))
            } else {
                String::new()
            }
        )));
    }
    if offered > 0 {
        eprintln!(
            "fricont: note: {offered} pieces leave the start point toward alpha_end (a bifurcation): {}; tracing piece {start_branch}{}",
            describe_branches(path.branches()),
            if args.start_branch.is_none() {
                " (--start-branch K takes another)"
            } else {
                ""
            }
        );
    }
    if start_branch > 1 {
        path.choose_branch(start_branch as usize - 1)
            .map_err(|e| runtime(format!("--start-branch {start_branch}: {e}")))?;
    }
    progress.phase(&format!(
        "tracing from alpha = {alpha_start} toward {alpha_end}"
    ));
    let window = (alpha_start, alpha_end);
    let mut last = (alpha_start, 0usize);
    let mut choices = args.branch.iter();
    let run = loop {
        match path.step() {
            Ok(StepOutcome::End(fricont::EndReason::Bifurcation)) => {
                let branches = path.branches();
                let at =
                    report::fmt_alpha(path.pieces().last().map_or(alpha_start, |p| p.alpha_to));
                let listed = describe_branches(branches);
                let Some(&k) = choices.next() else {
                    eprintln!(
                        "fricont: note: the path stops at a bifurcation at alpha = {at}: {} pieces continue it ({listed}); --branch K follows piece K",
                        branches.len()
                    );
                    break Ok(fricont::EndReason::Bifurcation);
                };
                if k as usize > branches.len() {
                    return Err(input(format!(
                        "--branch {k}: {} pieces continue the path at the bifurcation at alpha = {at} ({listed})",
                        branches.len()
                    )));
                }
                eprintln!(
                    "fricont: note: bifurcation at alpha = {at} ({listed}): following piece {k} (--branch)"
                );
                if let Err(e) = path.choose_branch(k as usize - 1) {
                    break Err(e);
                }
            }
            Ok(StepOutcome::End(r)) => break Ok(r),
            Ok(StepOutcome::Transition { events, .. }) => {
                if let Some(e) = path.events().get(events.end.wrapping_sub(1)) {
                    last = (e.alpha, e.transition + 1);
                    progress.update(last.0, last.1, window);
                }
            }
            Err(e) => break Err(e),
        }
    };
    let unused: Vec<String> = choices.map(|k| k.to_string()).collect();
    if !unused.is_empty() {
        eprintln!(
            "fricont: note: --branch {} not used: the path did not stop at that many bifurcations",
            unused.join(", ")
        );
    }
    let trace_s = t1.elapsed().as_secs_f64();
    let timing = Timing { setup_s, trace_s };
    if progress.enabled {
        let end_alpha = match &run {
            Ok(fricont::EndReason::Window) => alpha_end,
            _ => last.0,
        };
        let text = progress.state(end_alpha, last.1, window);
        progress.line(&format!("{text}; done"));
    }

    print!("{}", report::table(&mut path, Some(timing)));
    if let Some(out) = json {
        // Each transition point's residual is a back-solve with A's factor: on large
        // meshes with thousands of events this takes a while after the table.
        progress.phase(&format!(
            "writing the JSON report (the residual of {})",
            report::plural(path.events().len(), "event")
        ));
        let text = report::PathReport::from_path(&mut path, timing).to_json_string();
        out.write(&text)?;
    }
    match run {
        Ok(fricont::EndReason::Failed(m)) => Err(runtime(format!("path failed: {m}"))),
        Ok(_) => Ok(()),
        Err(e) => Err(runtime(format!("path failed: {e}"))),
    }
}

/// Candidate pieces for a note: `K: node i class, …` (1-based), by the nodes where they
/// differ, and the way each goes in α.
fn describe_branches(branches: &[fricont::path::Branch]) -> String {
    let Some(first) = branches.first() else {
        return String::new();
    };
    let differ: Vec<usize> = (0..first.classes.len())
        .filter(|&i| branches.iter().any(|b| b.classes[i] != first.classes[i]))
        .collect();
    branches
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let nodes: Vec<String> = differ
                .iter()
                .map(|&i| format!("node {} {}", i + 1, b.classes[i].name()))
                .collect();
            let way = match b.direction {
                1 => "alpha increasing",
                -1 => "alpha decreasing",
                _ => "vertical",
            };
            format!("{}: {} ({way})", k + 1, nodes.join(", "))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // A panic is a bug in fricont, never the user's fault: report it as one line (exit 1)
    // instead of a backtrace. The hook keeps the message and place for that line.
    let panic_msg = Arc::new(std::sync::Mutex::new(String::new()));
    {
        let slot = Arc::clone(&panic_msg);
        std::panic::set_hook(Box::new(move |info| {
            let what = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            let place = info
                .location()
                .map(|l| format!(" at {}:{}", l.file(), l.line()))
                .unwrap_or_default();
            if let Ok(mut m) = slot.lock() {
                *m = format!("{what}{place}");
            }
        }));
    }
    let result = std::panic::catch_unwind(|| match &cli.command {
        Command::Trace(a) => trace(a),
        Command::GenRect(a) => gen_rect(a),
        Command::CaseStudy(a) => case_study(a),
    })
    .unwrap_or_else(|_| {
        let m = panic_msg.lock().map(|m| m.clone()).unwrap_or_default();
        Err(runtime(format!(
            "internal error (a bug in fricont, please report): {m}"
        )))
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            // One line: collapse any newline a message might carry.
            let msg = f.message.replace('\n', " ");
            eprintln!("fricont: error: {msg}");
            ExitCode::from(f.status)
        }
    }
}

fn gen_rect(a: &GenRectArgs) -> Result<(), Failure> {
    use fricont_exchange::generator::{RectSpec, Traction};
    let mut spec = if a.press_shear {
        RectSpec::press_shear()
    } else {
        RectSpec::default()
    };
    macro_rules! set {
        ($($f:ident),*) => { $(if let Some(v) = a.$f { spec.$f = v; })* };
    }
    set!(nx, ny, lx, ly, e, nu, friction, gap, alpha_start, alpha_end);
    let parse = |v: &[String]| -> Result<Vec<Traction>, Failure> {
        v.iter()
            .map(|t| t.parse::<Traction>().map_err(input))
            .collect()
    };
    if !a.load0.is_empty() {
        spec.load0 = parse(&a.load0)?;
        spec.load_name = "custom".into();
    }
    if !a.load1.is_empty() {
        spec.load1 = parse(&a.load1)?;
        spec.load_name = "custom".into();
    }
    let data = fricont_exchange::generator::generate(&spec).map_err(input)?;
    data.write_dir(&a.dir).map_err(input)?;
    println!(
        "wrote {} ({}: n = {}, p = {}, F = {})",
        a.dir.display(),
        spec.mesh_description(),
        spec.n(),
        spec.p(),
        spec.friction
    );
    Ok(())
}

fn case_study(a: &CaseStudyArgs) -> Result<(), Failure> {
    let opts = fricont_cli::casestudy::CaseStudyOptions::new(a.out.clone());
    let report = fricont_cli::casestudy::run(&opts).map_err(runtime)?;
    print!("{}", report.text());
    Ok(())
}
