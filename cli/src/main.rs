//! `fricont`: the command-line front end.
//!
//! ```text
//! fricont trace DIR [--alpha-start A] [--alpha-end B] [--r R] [--max-steps K] [--threads N] [--json FILE]
//! ```
//!
//! reads a problem directory in the exchange format (SPEC §7), traces the path, prints the
//! transition table (α with 14 significant digits, 1-based nodes) and the set-up/trace
//! times, and writes the JSON of SPEC §8.
//!
//! Exit status: 0 when the path was traced (whatever its end reason except `failed`);
//! 2 for bad input (unreadable or malformed files, data the problem builder rejects,
//! an invalid window or option; the message is one line on stderr); 1 for a failure at
//! run time (the start solve or a step failed, the JSON could not be written). On a
//! failure during tracing, what was traced is still printed and written.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use clap::{Parser, Subcommand};

use fricont::path::{Path, PathOptions};
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
    /// Trace the solution path of a problem directory (SPEC §7 exchange format).
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
    #[arg(long)]
    lx: Option<f64>,
    /// Side length along y.
    #[arg(long)]
    ly: Option<f64>,
    /// Young's modulus.
    #[arg(long)]
    e: Option<f64>,
    /// Poisson's ratio.
    #[arg(long)]
    nu: Option<f64>,
    /// Friction coefficient of every contact node.
    #[arg(long)]
    friction: Option<f64>,
    /// Uniform initial gap.
    #[arg(long)]
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
    /// Problem directory: A.mtx, N.mtx, T.mtx, f0.txt, f1.txt, [gap.txt], meta.json.
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
    /// Stop after this many transition points.
    #[arg(long)]
    max_steps: Option<usize>,
    /// Threads of the set-up (factorisation of A, forming W), 1..=1024. Results agree
    /// with one thread to rounding; tracing runs on one thread.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Write the JSON report (SPEC §8) to this file.
    #[arg(long)]
    json: Option<PathBuf>,
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

fn trace(args: &TraceArgs) -> Result<(), Failure> {
    let case = CaseData::read_dir(&args.dir).map_err(input)?;
    let alpha_start = args.alpha_start.unwrap_or(case.alpha_start);
    let alpha_end = args.alpha_end.unwrap_or(case.alpha_end);
    let mut opts = PathOptions::window(alpha_start, alpha_end);
    if let Some(k) = args.max_steps {
        opts.max_steps = k;
    }

    let t0 = Instant::now();
    let mut builder = case.builder().threads(args.threads);
    if let Some(r) = args.r {
        builder = builder.r(r);
    }
    let problem = builder
        .build()
        .map_err(|e| input(format!("{}: {e}", args.dir.display())))?;
    let load = case
        .load()
        .map_err(|e| input(format!("{}: {e}", args.dir.display())))?;
    let mut path = Path::new(Arc::new(problem), load, opts).map_err(input)?;
    let setup_s = t0.elapsed().as_secs_f64();

    let t1 = Instant::now();
    path.start(alpha_start, None)
        .map_err(|e| runtime(format!("start at alpha = {alpha_start}: {e}")))?;
    let run = path.run();
    let trace_s = t1.elapsed().as_secs_f64();
    let timing = Timing { setup_s, trace_s };

    print!("{}", report::table(&mut path, Some(timing)));
    if let Some(file) = &args.json {
        let text = report::PathReport::from_path(&mut path, timing).to_json_string();
        std::fs::write(file, text)
            .map_err(|e| runtime(format!("cannot write {}: {e}", file.display())))?;
    }
    match run {
        Ok(fricont::EndReason::Failed(m)) => Err(runtime(format!("path failed: {m}"))),
        Ok(_) => Ok(()),
        Err(e) => Err(runtime(format!("path failed: {e}"))),
    }
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
