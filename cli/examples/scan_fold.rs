//! Random search for loads on the case-study rectangle whose path has a non-smooth fold
//! at moderate friction: f0, f1 = combinations of top pressure/shear and right-side
//! normal/shear tractions. Exploration tool for docs/case-study.md.
use std::sync::Arc;

use fricont::Storage;
use fricont::load::Load;
use fricont::path::{Path, PathOptions};
use fricont::problem::ProblemBuilder;
use fricont_exchange::generator::{RectSpec, Side, Traction, generate, load_vector};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let friction: f64 = args[1].parse().unwrap();
    let trials: usize = args[2].parse().unwrap();
    let mut seed: u64 = args.get(3).map_or(1, |s| s.parse().unwrap());
    let base = RectSpec::default();
    let case = generate(&base).unwrap();
    let problem = Arc::new(
        ProblemBuilder::new(
            case.a.clone(),
            Storage::Full,
            case.n_mat.clone(),
            case.t_mat.clone(),
        )
        .friction_uniform(friction)
        .build()
        .unwrap(),
    );
    let basis = [
        ("top pressure", Traction::uniform(Side::Top, [0.0, -0.01])),
        ("top shear +x", Traction::uniform(Side::Top, [0.01, 0.0])),
        (
            "right push -x",
            Traction::uniform(Side::Right, [-0.01, 0.0]),
        ),
        (
            "right shear +y",
            Traction::uniform(Side::Right, [0.0, 0.01]),
        ),
    ];
    let vecs: Vec<Vec<f64>> = basis.iter().map(|b| load_vector(&base, &[b.1])).collect();
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    for trial in 0..trials {
        let c0: Vec<f64> = (0..4).map(|_| rnd()).collect();
        let c1: Vec<f64> = (0..4).map(|_| rnd()).collect();
        // keep the body pressed at the start
        let c0 = {
            let mut c = c0;
            c[0] = c[0].abs() + 0.2;
            c
        };
        let comb = |c: &[f64]| -> Vec<f64> {
            (0..vecs[0].len())
                .map(|d| (0..4).map(|k| c[k] * vecs[k][d]).sum())
                .collect()
        };
        let mut path = match Path::new(
            problem.clone(),
            Load::affine(comb(&c0), comb(&c1)).unwrap(),
            PathOptions::window(-0.5, 1.5),
        ) {
            Ok(p) => p,
            Err(_) => continue,
        };
        if path.start(-0.5, None).is_err() {
            continue;
        }
        let end = match path.run() {
            Ok(e) => e,
            Err(e) => {
                println!("trial {trial}: error {e}");
                continue;
            }
        };
        let ev = path.events();
        let folds: Vec<usize> = (0..ev.len()).filter(|&k| ev[k].fold).collect();
        if folds.is_empty() {
            continue;
        }
        // fold width: distance in alpha to the neighbouring transition points
        let k = folds[0];
        let a = ev[k].alpha;
        let w_prev = ev[..k]
            .iter()
            .rev()
            .find(|e| e.alpha != a)
            .map_or(0.0, |e| (e.alpha - a).abs());
        let w_next = ev[k + 1..]
            .iter()
            .find(|e| e.alpha != a)
            .map_or(0.0, |e| (e.alpha - a).abs());
        println!(
            "trial {trial}: {} folds, end {}, first fold at {a:.4} node {} width {:.4}; c0 {:?} c1 {:?}",
            folds.len(),
            end.name(),
            ev[k].node + 1,
            w_prev.min(w_next),
            c0.iter()
                .map(|x| (x * 1000.0).round() / 1000.0)
                .collect::<Vec<_>>(),
            c1.iter()
                .map(|x| (x * 1000.0).round() / 1000.0)
                .collect::<Vec<_>>()
        );
    }
}
