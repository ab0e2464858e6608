//! Runs the founding paper's case study: `cargo run --release --example case_study -- OUT`
//! (the CLI's `fricont case-study --out OUT` does the same).
fn main() {
    let out = std::env::args().nth(1).unwrap_or_else(|| "out".into());
    let opts = fricont::casestudy::CaseStudyOptions::new(out);
    match fricont::casestudy::run(&opts) {
        Ok(r) => {
            print!("{}", r.table);
            if let Some(f) = &r.fold {
                println!("\nhigh-friction variant:\n{}", f.table);
            }
            println!(
                "set-up {:.3} s, trace {:.3} s; {} files written",
                r.setup_s,
                r.trace_s,
                r.files.len()
            );
        }
        Err(e) => {
            eprintln!("case study failed: {e}");
            std::process::exit(1);
        }
    }
}
