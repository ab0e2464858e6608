//! The Delassus operator by the trailing block of the factor equals W by solves with A,
//! and W by solves equals an independent dense computation B A⁻¹ Bᵀ (nalgebra).

mod common;

use common::read_mtx;
use fricont::{CsrMatrix, ProblemBuilder, Storage};
use nalgebra::DMatrix;

fn max_rel_diff(a: faer::MatRef<'_, f64>, b: faer::MatRef<'_, f64>) -> f64 {
    let scale = (0..a.nrows())
        .flat_map(|i| (0..a.ncols()).map(move |j| (i, j)))
        .fold(0.0f64, |m, (i, j)| m.max(a[(i, j)].abs()));
    (0..a.nrows())
        .flat_map(|i| (0..a.ncols()).map(move |j| (i, j)))
        .fold(0.0f64, |m, (i, j)| m.max((a[(i, j)] - b[(i, j)]).abs()))
        / scale
}

fn sample() -> (CsrMatrix, CsrMatrix, CsrMatrix) {
    let d = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sample-rect30");
    let m = |f: &str| {
        let (r, c, t) = read_mtx(&d.join(f));
        CsrMatrix::from_triplets(f, r, c, &t).unwrap()
    };
    (m("A.mtx"), m("N.mtx"), m("T.mtx"))
}

#[test]
fn trailing_block_w_equals_w_by_solves_on_the_sample() {
    let (a, n, t) = sample();
    // (both in double: the sample is small enough for Auto to refine W)
    let pb = ProblemBuilder::new(a, Storage::Full, n, t)
        .friction_uniform(0.3)
        .extended_precision(fricont::ExtendedPrecision::Off)
        .build()
        .unwrap();
    let del = pb.delassus();
    assert!(del.w_from_trailing_block());
    let d = max_rel_diff(del.w(), del.w_by_solves().unwrap().as_ref());
    assert!(d <= 1e-13, "relative difference {d:e}");
}

/// Contact rows that touch every dof (mortar-like): W comes from the solves, and it equals
/// B A⁻¹ Bᵀ computed densely by nalgebra.
#[test]
fn wide_rows_fall_back_to_solves_and_match_a_dense_reference() {
    let nd = 12;
    let p = 2;
    let mut a = vec![0.0; nd * nd];
    for i in 0..nd {
        a[i * nd + i] = 4.0;
        if i + 1 < nd {
            a[i * nd + i + 1] = -1.0;
            a[(i + 1) * nd + i] = -1.0;
        }
    }
    let row = |k: usize| -> Vec<f64> {
        (0..nd)
            .map(|j| ((k * 7 + j * 3) % 5) as f64 - 1.5)
            .collect()
    };
    let nrows: Vec<f64> = (0..p).flat_map(row).collect();
    let trows: Vec<f64> = (p..2 * p).flat_map(row).collect();
    let pb = ProblemBuilder::new(
        CsrMatrix::from_dense(nd, nd, &a).unwrap(),
        Storage::Full,
        CsrMatrix::from_dense(p, nd, &nrows).unwrap(),
        CsrMatrix::from_dense(p, nd, &trows).unwrap(),
    )
    .build()
    .unwrap();
    let am = DMatrix::from_row_slice(nd, nd, &a);
    // The library equilibrates each row of B by the power of two at or below its 2-norm:
    // so does the reference, from the rows themselves.
    let norm = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut b = DMatrix::zeros(2 * p, nd);
    for i in 0..p {
        let (nr, tr) = (&nrows[i * nd..(i + 1) * nd], &trows[i * nd..(i + 1) * nd]);
        let (sn, st) = (
            2f64.powf(norm(nr).log2().floor()),
            2f64.powf(norm(tr).log2().floor()),
        );
        assert_eq!((pb.row_scale()[i], pb.row_scale()[p + i]), (sn, st));
        for j in 0..nd {
            b[(i, j)] = nr[j] / sn;
            b[(p + i, j)] = tr[j] / st;
        }
    }
    let w_ref = &b * am.lu().solve(&b.transpose()).unwrap();
    assert!(!pb.delassus().w_from_trailing_block());
    let w = pb.delassus().w();
    let mut dmax = 0.0f64;
    for i in 0..2 * p {
        for j in 0..2 * p {
            dmax = dmax.max((w[(i, j)] - w_ref[(i, j)]).abs() / w_ref.amax());
        }
    }
    assert!(dmax <= 1e-13, "relative difference {dmax:e}");
}

/// The set-up on a private pool of 2 or 3 threads gives W and the events of the
/// single-threaded set-up to rounding (1e-14 relative), on a mesh whose supernodes are
/// large enough for faer's parallel kernels; 0 threads is refused.
#[test]
fn threads_give_the_same_w_and_events() {
    let case = common::fe_case(11, 120, 10, 1.0);
    let data = &case.data;
    let build = |threads: usize| data.builder().threads(threads).build();
    let one = std::sync::Arc::new(build(1).unwrap());
    let reference = common::trace(one.clone(), data.affine_load(), case.a0, case.a1);
    assert!(reference.events().len() > 5);
    for threads in [2, 3] {
        let many = std::sync::Arc::new(build(threads).unwrap());
        let d = max_rel_diff(one.delassus().w(), many.delassus().w());
        assert!(d <= 1e-14, "{threads} threads: W differs by {d:e}");
        let path = common::trace(many, data.affine_load(), case.a0, case.a1);
        assert_eq!(path.events().len(), reference.events().len());
        for (x, y) in path.events().iter().zip(reference.events()) {
            assert!((x.alpha - y.alpha).abs() <= 1e-12 * x.alpha.abs().max(1.0));
            assert_eq!((x.node, x.from, x.to), (y.node, y.from, y.to));
        }
    }
    assert!(matches!(build(0), Err(fricont::Error::InvalidParameter(_))));
}
