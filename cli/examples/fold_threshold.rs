//! For the case-study rectangle: the friction above which a single slipping contact node
//! (all others open) has a singular piece, F_i = W_νν,ii / |W_νt,ii| (SPEC §4: the sign
//! of det of the piece changes there). Exploration tool for docs/case-study.md.
use fricont_exchange::generator::{RectSpec, generate};

fn main() {
    let nu: f64 = std::env::args().nth(1).map_or(0.3, |s| s.parse().unwrap());
    let spec = RectSpec {
        nu,
        ..RectSpec::default()
    };
    let case = generate(&spec).unwrap();
    let problem = case.problem(None).unwrap();
    let w = problem.delassus().w();
    let p = problem.p();
    let mut best = (f64::INFINITY, 0);
    for i in 0..p {
        let f = w[(i, i)] / w[(i, p + i)].abs();
        if f < best.0 {
            best = (f, i);
        }
        if i < 3 || i + 3 >= p || i == p / 2 {
            println!(
                "node {:2}: W_nn {:.4e} W_nt {:+.4e} F_i {:.4}",
                i + 1,
                w[(i, i)],
                w[(i, p + i)],
                f
            );
        }
    }
    println!(
        "nu = {nu}: smallest F_i = {:.4} at node {}",
        best.0,
        best.1 + 1
    );
}
