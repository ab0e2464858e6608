//! `fricont`: the command-line front end.
//!
//! ```text
//! fricont trace DIR [--alpha-start A] [--alpha-end B] [--r R] [--max-steps K] [--json FILE]
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

use fricont::io::CaseData;
use fricont::path::{Path, PathOptions};
use fricont::report::{self, Timing};

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
    // --- Subcommands of the case study (issue 4), wired by the lead at merge time: ---
    // GenRect(GenRectArgs)      -> fricont::generator::generate(&RectSpec)?.write_dir(&dir)
    //                              (the module is `generator`: `gen` is a keyword in 2024)
    // CaseStudy(CaseStudyArgs)  -> fricont::casestudy::run(&CaseStudyOptions::new(out))
    // Add the variants here and their arms in `main` below (marked likewise). Map a bad
    // spec or output directory to `input(..)` (exit 2), other failures to `runtime(..)`.
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
    let problem = case
        .problem(args.r)
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
        // --- case-study subcommands (issue 4): arms go here. ---
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
