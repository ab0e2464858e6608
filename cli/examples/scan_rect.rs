//! Scans loads of the form f0 = lift on the right side (0.01 up) + top traction (s, -b0),
//! f1 = top pressure -b1, and scores them against the features the paper reports:
//! 14 transition points, #6 node 13 open -> slip at 0.28, #7 node 3 slip -> stick at 0.43,
//! #8 node 14 open -> slip at 0.60. Exploration tool for docs/case-study.md.
use std::sync::Arc;

use fricont::Class;
use fricont::load::Load;
use fricont::path::{Path, PathOptions};
use fricont_exchange::generator::{RectSpec, Side, Traction, generate, load_vector};

fn main() {
    let base = RectSpec::default();
    let case = generate(&base).unwrap();
    let problem = Arc::new(case.problem(None).unwrap());
    let lift = load_vector(&base, &[Traction::uniform(Side::Right, [0.0, 0.01])]);
    let shear = load_vector(&base, &[Traction::uniform(Side::Top, [1.0, 0.0])]);
    let slope: f64 = std::env::var("SLOPE")
        .ok()
        .map_or(0.0, |v| v.parse().unwrap());
    let press = load_vector(
        &base,
        &[Traction::linear(
            Side::Top,
            [0.0, -(1.0 - slope)],
            [0.0, -(1.0 + slope)],
        )],
    );
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    let (s_lo, s_hi, b0_lo, b0_hi, b1_lo, b1_hi, steps) = (
        args[0],
        args[1],
        args[2],
        args[3],
        args[4],
        args[5],
        args[6] as usize,
    );
    let lin = |lo: f64, hi: f64, k: usize| lo + (hi - lo) * k as f64 / (steps.max(2) - 1) as f64;
    let mut best: Vec<(f64, String)> = Vec::new();
    for i in 0..steps {
        for j in 0..steps {
            for k in 0..steps {
                let (s, b0, b1) = (
                    lin(s_lo, s_hi, i),
                    lin(b0_lo, b0_hi, j),
                    lin(b1_lo, b1_hi, k),
                );
                let f0: Vec<f64> = (0..lift.len())
                    .map(|d| lift[d] + s * shear[d] + b0 * press[d])
                    .collect();
                let f1: Vec<f64> = press.iter().map(|v| b1 * v).collect();
                let mut path = Path::new(
                    problem.clone(),
                    Load::affine(f0, f1).unwrap(),
                    PathOptions::window(-0.5, 1.5),
                )
                .unwrap();
                if path.start(-0.5, None).is_err() {
                    continue;
                }
                if path.run().is_err() {
                    continue;
                }
                let ev = path.events();
                let ntp = ev.last().map_or(0, |e| e.transition + 1);
                let tp = |t: usize| ev.iter().find(|e| e.transition + 1 == t);
                let mut score = (ntp as f64 - 14.0).abs();
                let want = [
                    (6, 13, Class::Open, true, 0.28019791259766),
                    (7, 3, Class::SlipPlus, false, 0.42934036865234),
                    (8, 14, Class::Open, true, 0.60403706054688),
                ];
                for (t, node, from, opening, a) in want {
                    match tp(t) {
                        Some(e) => {
                            let ok_kind = if opening {
                                e.from == Class::Open && e.to.in_contact() && e.to != Class::Stick
                            } else {
                                matches!(e.from, Class::SlipPlus | Class::SlipMinus)
                                    && e.to == Class::Stick
                            };
                            let _ = from;
                            if e.node + 1 != node {
                                score += 3.0;
                            }
                            if !ok_kind {
                                score += 3.0;
                            }
                            score += 5.0 * (e.alpha - a).abs();
                        }
                        None => score += 10.0,
                    }
                }
                let kinds: std::collections::BTreeSet<String> = ev
                    .iter()
                    .map(|e| format!("{}>{}", e.from.name(), e.to.name()))
                    .collect();
                score -= 0.3 * kinds.len() as f64;
                best.push((
                    score,
                    format!("s={s:.5} b0={b0:.5} b1={b1:.5}: {ntp} tp, kinds {kinds:?}"),
                ));
            }
        }
    }
    best.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (sc, d) in best.iter().take(12) {
        println!("{sc:.3}  {d}");
    }
}
