//! Traces a rectangle case given as RectSpec JSON (fields default to the case study) and
//! prints a summary: `cargo run --release --example explore_rect -- '{"friction":1.0}'`.
use std::collections::BTreeMap;
use std::sync::Arc;

use fricont::path::{Path, PathOptions};
use fricont_cli::casestudy::seed_words;
use fricont_exchange::generator::{RectSpec, generate};
use fricont_exchange::report::transition_rows;

fn main() {
    let arg = std::env::args().nth(1).unwrap_or_else(|| "{}".into());
    let verbose = std::env::args().nth(2).is_some();
    let spec: RectSpec = serde_json::from_str(&arg).expect("spec JSON");
    let case = generate(&spec).expect("generate");
    let problem = Arc::new(case.problem(None).expect("problem"));
    let mut path = Path::new(
        problem,
        case.load().unwrap(),
        PathOptions::window(spec.alpha_start, spec.alpha_end),
    )
    .unwrap();
    path.start(spec.alpha_start, None).expect("start");
    let end = path.run().expect("run");
    let rows = transition_rows(&path);
    let mut kinds: BTreeMap<String, usize> = BTreeMap::new();
    for r in &rows {
        *kinds
            .entry(format!("{} -> {}", r.from.name(), r.to.name()))
            .or_default() += 1;
    }
    let st = path.start_state().unwrap();
    let start: String = st
        .classes
        .iter()
        .map(|c| match c.name() {
            "open" => 'o',
            "stick" => 's',
            "slip+" => '+',
            _ => '-',
        })
        .collect();
    let cur = path.current().unwrap();
    let endc: String = cur
        .classes
        .iter()
        .map(|c| match c.name() {
            "open" => 'o',
            "stick" => 's',
            "slip+" => '+',
            _ => '-',
        })
        .collect();
    println!(
        "end {} at {:.4}; {} transition points, {} folds, {} bifurcations; start [{start}] end [{endc}]",
        end.name(),
        cur.alpha,
        rows.last().map_or(0, |r| r.transition),
        rows.iter().filter(|r| r.fold).count(),
        rows.iter().filter(|r| r.bifurcation).count(),
    );
    println!("kinds: {kinds:?}");
    if verbose {
        print!("{}", seed_words(&rows));
    }
}
