//! The generator against the sample case shipped with the project brief (a copy is in
//! `tests/data/sample-rect30`), produced by an independent code: same stiffness, same
//! contact matrices, same loads (trapezoidal nodal forces, which is what the sample uses).

use fricont_exchange::generator::{ForceRule, RectSpec, generate};

fn sample_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/sample-rect30")
}

/// Minimal Matrix Market coordinate reader (general), 1-based → dense map.
fn read_mtx(path: &std::path::Path) -> (usize, usize, Vec<(usize, usize, f64)>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('%'));
    let head: Vec<usize> = lines
        .next()
        .unwrap()
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    let mut t = Vec::new();
    for l in lines {
        let w: Vec<&str> = l.split_whitespace().collect();
        if w.len() == 3 {
            t.push((
                w[0].parse::<usize>().unwrap() - 1,
                w[1].parse::<usize>().unwrap() - 1,
                w[2].parse::<f64>().unwrap(),
            ));
        }
    }
    (head[0], head[1], t)
}

fn read_vec(path: &std::path::Path) -> Vec<f64> {
    std::fs::read_to_string(path)
        .unwrap()
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect()
}

#[test]
fn generator_reproduces_the_sample_case() {
    let dir = sample_dir();
    let spec = RectSpec {
        rule: ForceRule::Trapezoid,
        ..RectSpec::press_shear()
    };
    let c = generate(&spec).unwrap();
    for (name, m) in [("A", &c.a), ("N", &c.n_mat), ("T", &c.t_mat)] {
        let (nr, nc, t) = read_mtx(&dir.join(format!("{name}.mtx")));
        assert_eq!((nr, nc), (m.nrows(), m.ncols()), "{name}");
        let mut dense = std::collections::HashMap::new();
        for (i, j, v) in t {
            *dense.entry((i, j)).or_insert(0.0) += v;
        }
        let scale = m.max_abs();
        let mut seen = 0;
        for i in 0..m.nrows() {
            for (j, v) in m.row(i) {
                let w = dense.get(&(i, j)).copied().unwrap_or(0.0);
                assert!(
                    (v - w).abs() <= 1e-12 * scale,
                    "{name}({i},{j}): {v} vs {w}"
                );
                seen += usize::from(dense.contains_key(&(i, j)));
            }
        }
        let nonzero = dense.values().filter(|v| v.abs() > 1e-12 * scale).count();
        assert!(
            seen >= nonzero,
            "{name}: sample has entries outside the pattern"
        );
    }
    for (name, f) in [("f0", &c.f0), ("f1", &c.f1)] {
        let s = read_vec(&dir.join(format!("{name}.txt")));
        assert_eq!(s.len(), f.len());
        for (k, (a, b)) in f.iter().zip(&s).enumerate() {
            assert!((a - b).abs() <= 1e-15, "{name}[{k}]: {a} vs {b}");
        }
    }
}
