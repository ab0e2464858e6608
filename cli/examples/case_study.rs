//! Runs the founding paper's case study: `cargo run --release --example case_study -- OUT`
//! (the CLI's `fricont case-study --out OUT` does the same).
fn main() {
    let out = std::env::args().nth(1).unwrap_or_else(|| "out".into());
    let opts = fricont_cli::casestudy::CaseStudyOptions::new(out);
    match fricont_cli::casestudy::run(&opts) {
        Ok(r) => print!("{}", r.text()),
        Err(e) => {
            eprintln!("case study failed: {e}");
            std::process::exit(1);
        }
    }
}
