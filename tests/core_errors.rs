//! Data errors: every `Error` variant reachable from bad
//! data is provoked through `CsrMatrix::from_raw`, `ProblemBuilder`, `Load` and `Path`, and
//! nothing panics (each call runs under `catch_unwind`, so a panic fails with a message
//! naming the case instead of aborting the test).

mod common;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;

use fricont::load::LoadFailure;
use fricont::{
    CsrMatrix, EndReason, Error, Load, Path, PathOptions, Problem, ProblemBuilder, Storage,
};

/// Runs `f`, failing the test with `what` if it panics.
fn no_panic<T>(what: &str, f: impl FnOnce() -> T) -> T {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(v) => v,
        Err(_) => panic!("{what}: panicked instead of returning an error"),
    }
}

fn dense(r: usize, c: usize, v: &[f64]) -> CsrMatrix {
    CsrMatrix::from_dense(r, c, v).unwrap()
}

fn eye(n: usize) -> Vec<f64> {
    let mut a = vec![0.0; n * n];
    for i in 0..n {
        a[i * n + i] = 1.0;
    }
    a
}

/// A valid 1-node problem with n = 3: A = I, N = [1 0 0], T = [0 1 0].
fn good() -> ProblemBuilder {
    ProblemBuilder::new(
        dense(3, 3, &eye(3)),
        Storage::Full,
        dense(1, 3, &[1.0, 0.0, 0.0]),
        dense(1, 3, &[0.0, 1.0, 0.0]),
    )
}

fn build_err(what: &str, b: ProblemBuilder) -> Error {
    match no_panic(what, move || b.build()) {
        Ok(_) => panic!("{what}: accepted bad data"),
        Err(e) => {
            let msg = e.to_string();
            assert!(
                !msg.is_empty() && !msg.contains('\n'),
                "{what}: message {msg:?}"
            );
            e
        }
    }
}

fn raw_err(
    what: &str,
    nr: usize,
    nc: usize,
    rp: &[i64],
    ci: &[i64],
    v: &[f64],
    base: i64,
) -> Error {
    match no_panic(what, || CsrMatrix::from_raw("A", nr, nc, rp, ci, v, base)) {
        Ok(m) => panic!("{what}: accepted {m:?}"),
        Err(e) => e,
    }
}

#[test]
fn good_problem_builds() {
    let p = good().friction_uniform(0.5).build().unwrap();
    assert_eq!((p.n(), p.p()), (3, 1));
    // 1-based CSR of the same A is accepted and equal.
    let a1 =
        CsrMatrix::from_raw("A", 3, 3, &[1, 2, 3, 4], &[1, 2, 3], &[1.0, 1.0, 1.0], 1).unwrap();
    assert_eq!(a1, dense(3, 3, &eye(3)));
    // unsorted columns inside a row are accepted (and sorted)
    let m = CsrMatrix::from_raw("A", 2, 2, &[0, 2, 3], &[1, 0, 1], &[2.0, 1.0, 3.0], 0).unwrap();
    assert_eq!(m.col_idx(), &[0, 1, 1]);
    assert_eq!(m.values(), &[1.0, 2.0, 3.0]);
}

#[test]
fn csr_structure_errors() {
    use Error::Csr;
    let cases: Vec<(&str, Error)> = vec![
        (
            "index base 2",
            raw_err("base", 2, 2, &[2, 3, 4], &[2, 3], &[1.0, 1.0], 2),
        ),
        (
            "row_ptr too short",
            raw_err("rp len", 2, 2, &[0, 1], &[0], &[1.0], 0),
        ),
        (
            "row_ptr too long",
            raw_err("rp len2", 2, 2, &[0, 1, 2, 2], &[0, 1], &[1.0, 1.0], 0),
        ),
        (
            "row_ptr[0] != base",
            raw_err("rp0", 2, 2, &[1, 1, 2], &[0, 1], &[1.0, 1.0], 0),
        ),
        (
            "row_ptr decreases",
            raw_err(
                "rp dec",
                3,
                3,
                &[0, 2, 1, 3],
                &[0, 1, 2],
                &[1.0, 1.0, 1.0],
                0,
            ),
        ),
        (
            "row_ptr end != nnz",
            raw_err("rp end", 2, 2, &[0, 1, 1], &[0, 1], &[1.0, 1.0], 0),
        ),
        (
            "row_ptr beyond nnz",
            raw_err("rp big", 2, 2, &[0, 5, 2], &[0, 1], &[1.0, 1.0], 0),
        ),
        (
            "negative row_ptr",
            raw_err("rp neg", 2, 2, &[0, -1, 2], &[0, 1], &[1.0, 1.0], 0),
        ),
        (
            "column out of range",
            raw_err("col", 2, 2, &[0, 1, 2], &[0, 2], &[1.0, 1.0], 0),
        ),
        (
            "negative column",
            raw_err("col neg", 2, 2, &[0, 1, 2], &[0, -1], &[1.0, 1.0], 0),
        ),
        (
            "column 0 with base 1",
            raw_err("col base", 2, 2, &[1, 2, 3], &[0, 2], &[1.0, 1.0], 1),
        ),
        (
            "col_idx and values lengths",
            raw_err("len", 2, 2, &[0, 1, 2], &[0, 1], &[1.0], 0),
        ),
    ];
    for (what, e) in cases {
        assert!(matches!(e, Csr(_)), "{what}: {e:?}");
    }
    // triplets out of range
    let e = no_panic("triplets", || {
        CsrMatrix::from_triplets("N", 1, 3, &[(0, 3, 1.0)])
    })
    .unwrap_err();
    assert!(matches!(e, Csr(_)), "{e:?}");
    let e = no_panic("triplets row", || {
        CsrMatrix::from_triplets("N", 1, 3, &[(1, 0, 1.0)])
    })
    .unwrap_err();
    assert!(matches!(e, Csr(_)), "{e:?}");
    // dense array of the wrong length
    let e = no_panic("dense", || CsrMatrix::from_dense(2, 2, &[1.0, 2.0, 3.0])).unwrap_err();
    assert!(matches!(e, Error::Dimension(_)), "{e:?}");
}

#[test]
fn non_finite_values() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = raw_err("nan", 2, 2, &[0, 1, 2], &[0, 1], &[1.0, bad], 0);
        assert!(matches!(e, Error::NonFinite(_)), "{e:?}");
        let e = no_panic("triplets", || {
            CsrMatrix::from_triplets("T", 1, 2, &[(0, 0, bad)])
        })
        .unwrap_err();
        assert!(matches!(e, Error::NonFinite(_)), "{e:?}");
        let e = build_err("gap", good().gap(vec![bad]));
        assert!(matches!(e, Error::NonFinite(_)), "gap {bad}: {e:?}");
        let e = no_panic("affine", || Load::affine(vec![0.0, bad, 0.0], vec![0.0; 3])).unwrap_err();
        assert!(matches!(e, Error::NonFinite(_)), "{e:?}");
        let e = no_panic("affine f1", || {
            Load::affine(vec![0.0; 3], vec![bad, 0.0, 0.0])
        })
        .unwrap_err();
        assert!(matches!(e, Error::NonFinite(_)), "{e:?}");
        let e = no_panic("basis", || {
            Load::basis(
                vec![vec![0.0; 3], vec![bad, 0.0, 0.0]],
                Box::new(|_, _, _| Ok(())),
            )
        })
        .unwrap_err();
        assert!(matches!(e, Error::NonFinite(_)), "{e:?}");
        // friction NaN / inf and r NaN / inf are invalid parameters
        let e = build_err("friction", good().friction_uniform(bad));
        assert!(matches!(e, Error::InvalidParameter(_)), "F = {bad}: {e:?}");
        let e = build_err("r", good().r(bad));
        assert!(matches!(e, Error::InvalidParameter(_)), "r = {bad}: {e:?}");
    }
}

#[test]
fn dimension_errors() {
    use Error::Dimension;
    let a = || dense(3, 3, &eye(3));
    let n1 = || dense(1, 3, &[1.0, 0.0, 0.0]);
    let t1 = || dense(1, 3, &[0.0, 1.0, 0.0]);
    let cases = vec![
        (
            "A not square",
            ProblemBuilder::new(dense(3, 2, &[1.0; 6]), Storage::Full, n1(), t1()),
        ),
        (
            "N has wrong n",
            ProblemBuilder::new(a(), Storage::Full, dense(1, 2, &[1.0, 0.0]), t1()),
        ),
        (
            "T has wrong n",
            ProblemBuilder::new(a(), Storage::Full, n1(), dense(1, 4, &[0.0, 1.0, 0.0, 0.0])),
        ),
        (
            "T has wrong p",
            ProblemBuilder::new(
                a(),
                Storage::Full,
                n1(),
                dense(2, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0]),
            ),
        ),
        ("friction length", good().friction(vec![0.1, 0.2])),
        ("gap length", good().gap(vec![0.0, 0.0])),
        ("empty gap", good().gap(vec![])),
    ];
    for (what, b) in cases {
        let e = build_err(what, b);
        assert!(matches!(e, Dimension(_)), "{what}: {e:?}");
    }
    let e = no_panic("affine lengths", || {
        Load::affine(vec![0.0; 3], vec![0.0; 2])
    })
    .unwrap_err();
    assert!(matches!(e, Dimension(_)), "{e:?}");
    let e = no_panic("basis empty", || {
        Load::basis(vec![], Box::new(|_, _, _| Ok(())))
    })
    .unwrap_err();
    assert!(matches!(e, Dimension(_)), "{e:?}");
    let e = no_panic("basis lengths", || {
        Load::basis(vec![vec![0.0; 3], vec![0.0; 2]], Box::new(|_, _, _| Ok(())))
    })
    .unwrap_err();
    assert!(matches!(e, Dimension(_)), "{e:?}");
    // a load of the wrong length for the problem
    let pr = Arc::new(good().build().unwrap());
    let e = no_panic("load length", || {
        Path::new(
            pr.clone(),
            Load::affine(vec![0.0; 2], vec![0.0; 2]).unwrap(),
            PathOptions::window(0.0, 1.0),
        )
    })
    .err()
    .expect("load of wrong length accepted");
    assert!(matches!(e, Dimension(_)), "{e:?}");
    let e = no_panic("general load length", || {
        Path::new(
            pr.clone(),
            Load::general(4, Box::new(|_, _| Ok(())), None),
            PathOptions::window(0.0, 1.0),
        )
    })
    .err()
    .expect("general load of wrong length accepted");
    assert!(matches!(e, Dimension(_)), "{e:?}");
    // a start guess of the wrong length
    let mut path = Path::new(
        pr,
        Load::affine(vec![0.0, 0.0, 0.0], vec![-1.0, 0.0, 0.0]).unwrap(),
        PathOptions::window(0.0, 1.0),
    )
    .unwrap();
    let r = no_panic("guess length", || path.start(0.0, Some(&[0.0; 3])));
    assert!(r.is_err(), "guess of length 3 for 2p = 2 accepted");
    let r = no_panic("guess NaN", || path.start(0.0, Some(&[f64::NAN, 0.0])));
    assert!(r.is_err(), "NaN guess accepted");
}

#[test]
fn symmetry_and_storage() {
    // non-symmetric A in full storage
    let a = dense(3, 3, &[2.0, 1.0, 0.0, 0.5, 2.0, 0.0, 0.0, 0.0, 2.0]);
    let e = build_err(
        "non-symmetric",
        ProblemBuilder::new(
            a,
            Storage::Full,
            dense(1, 3, &[1.0, 0.0, 0.0]),
            dense(1, 3, &[0.0, 1.0, 0.0]),
        ),
    );
    assert!(matches!(e, Error::NotSymmetric(_)), "{e:?}");
    // an entry missing on one side only
    let a = dense(3, 3, &[2.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0]);
    let e = build_err(
        "one-sided entry",
        ProblemBuilder::new(
            a,
            Storage::Full,
            dense(1, 3, &[1.0, 0.0, 0.0]),
            dense(1, 3, &[0.0, 1.0, 0.0]),
        ),
    );
    assert!(matches!(e, Error::NotSymmetric(_)), "{e:?}");
    // lower storage with an entry above the diagonal, and upper with one below
    let a = dense(3, 3, &[2.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 2.0]);
    for s in [Storage::Lower, Storage::Upper] {
        let e = build_err(
            "wrong triangle",
            ProblemBuilder::new(
                a.clone(),
                s,
                dense(1, 3, &[1.0, 0.0, 0.0]),
                dense(1, 3, &[0.0, 1.0, 0.0]),
            ),
        );
        assert!(matches!(e, Error::Csr(_)), "{s:?}: {e:?}");
    }
    // the lower and the upper triangle of the same SPD matrix both build
    let lo = dense(3, 3, &[2.0, 0.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 2.0]);
    let up = dense(3, 3, &[2.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0]);
    let n = || dense(1, 3, &[1.0, 0.0, 0.0]);
    let t = || dense(1, 3, &[0.0, 1.0, 0.0]);
    let pl = ProblemBuilder::new(lo, Storage::Lower, n(), t())
        .build()
        .unwrap();
    let pu = ProblemBuilder::new(up, Storage::Upper, n(), t())
        .build()
        .unwrap();
    let pf = ProblemBuilder::new(a, Storage::Full, n(), t())
        .build()
        .unwrap();
    assert_eq!(pl.a(), pf.a());
    assert_eq!(pu.a(), pf.a());
}

#[test]
fn not_positive_definite_reports_the_pivot() {
    let n = || dense(1, 4, &[1.0, 0.0, 0.0, 0.0]);
    let t = || dense(1, 4, &[0.0, 1.0, 0.0, 0.0]);
    // Diagonal with one negative (or zero) entry at row k: whatever the ordering, the only
    // non-positive pivot is A(k,k), so the reported row must be k (0-based).
    for (k, bad) in [(2, -1.0), (2, 0.0), (3, -1.0), (0, -1.0)] {
        let mut a = eye(4);
        a[k * 4 + k] = bad;
        let a = CsrMatrix::from_triplets(
            "A",
            4,
            4,
            &(0..4).map(|i| (i, i, a[i * 5])).collect::<Vec<_>>(),
        )
        .unwrap();
        let e = build_err(
            &format!("diag with A({k},{k}) = {bad}"),
            ProblemBuilder::new(a, Storage::Full, n(), t()),
        );
        match e {
            Error::NotSpd { row, pivot } => {
                assert_eq!(row, k, "{e}");
                assert!(pivot < 4);
                // the message counts from 1, as every message does
                let m = e.to_string();
                assert!(m.contains(&format!("row {} of A (1-based", k + 1)), "{m}");
            }
            e => panic!("diag({bad}): {e:?}"),
        }
    }
    // Indefinite 2×2 block [[1, 2], [2, 1]] in rows 1, 2 of an otherwise identity matrix:
    // in any elimination order the first pivot of the block is 1 > 0 and the second is
    // 1 − 4 = −3, so the failing row is 1 or 2, and it is the block's second pivot.
    let a = dense(
        4,
        4,
        &[
            1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 0.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ],
    );
    let e = build_err(
        "indefinite",
        ProblemBuilder::new(a, Storage::Full, n(), t()),
    );
    match &e {
        Error::NotSpd { row, pivot } => {
            assert!(*row == 1 || *row == 2, "{e}");
            assert!(*pivot >= 1 && *pivot < 4, "{e}");
        }
        e => panic!("indefinite: {e:?}"),
    }
    assert!(e.to_string().contains("pivot"));

    // 2D Laplacians (5-point, m×m grid) with one diagonal entry made very negative at
    // row k. Whatever the fill-reducing order, every leading principal submatrix that
    // does not contain row k is a principal submatrix of the Laplacian, hence SPD; the
    // first non-positive pivot is therefore row k's own, and the error must name row k.
    // (Sizes cover both of faer's simplicial and supernodal factorisations.)
    for m in [2usize, 3, 10, 30, 60] {
        let nn = m * m;
        let id = |i: usize, j: usize| i * m + j;
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                t.push((id(i, j), id(i, j), 4.0));
                if i + 1 < m {
                    t.push((id(i, j), id(i + 1, j), -1.0));
                    t.push((id(i + 1, j), id(i, j), -1.0));
                }
                if j + 1 < m {
                    t.push((id(i, j), id(i, j + 1), -1.0));
                    t.push((id(i, j + 1), id(i, j), -1.0));
                }
            }
        }
        for k in [0, nn / 2, nn - 1, 1] {
            let mut tk = t.clone();
            tk.push((k, k, -100.0)); // summed: A(k, k) = −96
            let a = CsrMatrix::from_triplets("A", nn, nn, &tk).unwrap();
            let nm = CsrMatrix::from_triplets("N", 1, nn, &[(0, 0, 1.0)]).unwrap();
            let tm = CsrMatrix::from_triplets("T", 1, nn, &[(0, 1, 1.0)]).unwrap();
            let e = build_err(
                &format!("Laplacian {m}x{m} with A({k},{k}) < 0"),
                ProblemBuilder::new(a, Storage::Full, nm, tm),
            );
            match e {
                Error::NotSpd { row, pivot } => {
                    assert_eq!(row, k, "Laplacian {m}x{m}, negative A({k},{k}): {e}");
                    assert!(pivot < nn, "{e}");
                }
                e => panic!("Laplacian {m}x{m}: {e:?}"),
            }
        }
    }
}

#[test]
fn rank_deficient_b() {
    let a = || dense(4, 4, &eye(4));
    let cases = vec![
        // T row equal to N row
        (
            "T = N",
            dense(1, 4, &[1.0, 1.0, 0.0, 0.0]),
            dense(1, 4, &[1.0, 1.0, 0.0, 0.0]),
        ),
        // zero T row
        (
            "zero T row",
            dense(1, 4, &[1.0, 0.0, 0.0, 0.0]),
            CsrMatrix::from_triplets("T", 1, 4, &[]).unwrap(),
        ),
        // T of node 2 a combination of the N rows
        (
            "T2 = N1 + N2",
            dense(2, 4, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
            dense(2, 4, &[0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0]),
        ),
        // 2p > n
        (
            "2p > n",
            dense(
                3,
                4,
                &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            ),
            dense(
                3,
                4,
                &[0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0],
            ),
        ),
        // two equal N rows
        (
            "N1 = N2",
            dense(2, 4, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
            dense(2, 4, &[0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]),
        ),
    ];
    for (what, n, t) in cases {
        let e = build_err(what, ProblemBuilder::new(a(), Storage::Full, n, t));
        if what == "2p > n" {
            // a size error (FRICONT_ERR_LENGTH), found before anything is factorised
            assert!(matches!(e, Error::Dimension(_)), "{what}: {e:?}");
        } else {
            assert!(matches!(e, Error::RankDeficient(_)), "{what}: {e:?}");
        }
    }
    // numerically rank-deficient: T = N (1 + 1e-15)
    let e = build_err(
        "nearly dependent",
        ProblemBuilder::new(
            a(),
            Storage::Full,
            dense(1, 4, &[1.0, 2.0, 0.0, 0.0]),
            dense(1, 4, &[1.0 + 1e-15, 2.0, 0.0, 0.0]),
        ),
    );
    assert!(matches!(e, Error::RankDeficient(_)), "{e:?}");
}

#[test]
fn invalid_parameters() {
    use Error::InvalidParameter;
    for (what, b) in [
        ("F < 0", good().friction_uniform(-0.1)),
        ("F < 0 at a node", good().friction(vec![-1e-300])),
        ("r = 0", good().r(0.0)),
        ("r < 0", good().r(-1.0)),
    ] {
        let e = build_err(what, b);
        assert!(matches!(e, InvalidParameter(_)), "{what}: {e:?}");
    }
    // p = 0
    let e = build_err(
        "p = 0",
        ProblemBuilder::new(
            dense(2, 2, &eye(2)),
            Storage::Full,
            CsrMatrix::from_triplets("N", 0, 2, &[]).unwrap(),
            CsrMatrix::from_triplets("T", 0, 2, &[]).unwrap(),
        ),
    );
    assert!(
        matches!(e, InvalidParameter(_) | Error::Dimension(_)),
        "{e:?}"
    );
    let p = good().build().unwrap();
    for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = no_panic("with_r", || p.with_r(r)).unwrap_err();
        assert!(matches!(e, InvalidParameter(_)), "with_r({r}): {e:?}");
    }
    // windows and tolerances
    let pr = Arc::new(p);
    let load = || Load::affine(vec![0.0; 3], vec![-1.0, 0.0, 0.0]).unwrap();
    for (a0, a1) in [(0.0, 0.0), (f64::NAN, 1.0), (0.0, f64::INFINITY)] {
        let e = no_panic("window", || {
            Path::new(pr.clone(), load(), PathOptions::window(a0, a1))
        })
        .err()
        .expect("bad window accepted");
        assert!(matches!(e, InvalidParameter(_)), "[{a0}, {a1}]: {e:?}");
    }
    for tol in [0.0, -1.0, 0.1, f64::NAN] {
        let mut o = PathOptions::window(0.0, 1.0);
        o.zero_tol = tol;
        let e = no_panic("zero_tol", || Path::new(pr.clone(), load(), o))
            .err()
            .expect("bad zero_tol accepted");
        assert!(matches!(e, InvalidParameter(_)), "zero_tol {tol}: {e:?}");
    }
    // start outside the window
    let mut path = Path::new(pr, load(), PathOptions::window(0.0, 1.0)).unwrap();
    assert!(no_panic("start outside", || path.start(2.0, None)).is_err());
    assert!(no_panic("start NaN", || path.start(f64::NAN, None)).is_err());
}

fn simple_problem() -> Arc<Problem> {
    Arc::new(good().friction_uniform(0.3).build().unwrap())
}

#[test]
fn usage_errors() {
    let mut path = Path::new(
        simple_problem(),
        Load::affine(vec![0.0; 3], vec![-1.0, 0.5, 0.0]).unwrap(),
        PathOptions::window(-1.0, 1.0),
    )
    .unwrap();
    assert!(!path.is_started());
    assert_eq!(path.start_route(), None);
    let e = no_panic("step before start", || path.step()).unwrap_err();
    assert!(matches!(e, Error::Usage(_)), "{e:?}");
    let e = no_panic("current before start", || path.current()).unwrap_err();
    assert!(matches!(e, Error::Usage(_)), "{e:?}");
    assert!(no_panic("solutions_at before start", || path.solutions_at(0.0)).is_err());
    path.start(-1.0, None).unwrap();
    assert!(path.is_started());
    // (one node: the fixed-α solver at α solves it; no fallback)
    assert_eq!(path.start_route(), Some(fricont::StartRoute::Solved));
    let e = no_panic("choose_branch without bifurcation", || {
        path.choose_branch(0)
    })
    .unwrap_err();
    assert!(
        matches!(e, Error::Usage(_) | Error::InvalidParameter(_)),
        "{e:?}"
    );
    path.run().unwrap();
    assert!(path.end_reason().is_some());
    // α must be finite (it used to give an empty list, as for an α never reached)
    for a in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = no_panic("solutions_at a non-finite alpha", || path.solutions_at(a)).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter(_)), "{a}: {e:?}");
    }
    assert!(!path.solutions_at(0.5).unwrap().is_empty());
    // stepping an ended path does not panic
    let _ = no_panic("step after end", || path.step());
}

#[test]
fn load_failures_stop_cleanly() {
    let pr = simple_problem();
    // the closure fails at once: start reports the caller's code
    let load = Load::general(
        3,
        Box::new(|_, _| {
            Err(LoadFailure {
                code: 42,
                message: "no data".into(),
            })
        }),
        None,
    );
    let mut path = Path::new(pr.clone(), load, PathOptions::window(-1.0, 1.0)).unwrap();
    match no_panic("failing load", || path.start(-1.0, None)) {
        Err(Error::Load { code, .. }) => assert_eq!(code, 42),
        r => panic!("{r:?}"),
    }
    // NaN from the closure
    let load = Load::general(
        3,
        Box::new(|_, out: &mut [f64]| {
            out[0] = f64::NAN;
            Ok(())
        }),
        None,
    );
    let mut path = Path::new(pr.clone(), load, PathOptions::window(-1.0, 1.0)).unwrap();
    match no_panic("NaN load", || path.start(-1.0, None)) {
        Err(Error::Load { code, .. }) => assert_eq!(code, 0),
        r => panic!("{r:?}"),
    }
    // basis weights returning NaN
    let load = Load::basis(
        vec![vec![1.0, 0.0, 0.0]],
        Box::new(|_, w: &mut [f64], dw: &mut [f64]| {
            w[0] = f64::NAN;
            dw[0] = 0.0;
            Ok(())
        }),
    )
    .unwrap();
    let mut path = Path::new(pr.clone(), load, PathOptions::window(-1.0, 1.0)).unwrap();
    assert!(matches!(
        no_panic("NaN weights", || path.start(-1.0, None)),
        Err(Error::Load { .. })
    ));

    // A load that fails past α = 0.5 while the path is traced, f = (α, 0.5α + 0.3, 0)
    // until then. Node: A = I, N = e₁, T = e₂, F = 0.3, so W = I and
    // d = (α, 0.5α + 0.3) + λ: open for α < 0, contact closes at α = 0 with dt = 0.3 > 0
    // (slip+), then λν = −α, dt = 0.5α + 0.3 − 0.3α > 0: no other event before 0.5.
    let fail_at = 0.5;
    let f = move |a: f64, out: &mut [f64]| -> Result<(), LoadFailure> {
        if a > fail_at {
            return Err(LoadFailure {
                code: 7,
                message: format!("beyond {fail_at}"),
            });
        }
        out[0] = a;
        out[1] = 0.5 * a + 0.3;
        out[2] = 0.0;
        Ok(())
    };
    let df = |_: f64, out: &mut [f64]| -> Result<(), LoadFailure> {
        out[0] = 1.0;
        out[1] = 0.5;
        out[2] = 0.0;
        Ok(())
    };
    let mut path = Path::new(
        pr,
        Load::general(3, Box::new(f), Some(Box::new(df))),
        PathOptions::window(-1.0, 1.0),
    )
    .unwrap();
    path.start(-1.0, None).unwrap();
    let mut err = None;
    for _ in 0..100 {
        match no_panic("stepping into a failing load", || path.step()) {
            Ok(fricont::StepOutcome::End(r)) => {
                assert!(
                    matches!(r, EndReason::Failed(_)),
                    "path ended with {r:?} although the load fails"
                );
                break;
            }
            Ok(_) => {}
            Err(e) => {
                err = Some(e);
                break;
            }
        }
    }
    if let Some(e) = &err {
        assert!(matches!(e, Error::Load { code: 7, .. }), "{e:?}");
    }
    assert!(
        matches!(path.end_reason(), Some(EndReason::Failed(_))),
        "{:?}",
        path.end_reason()
    );
    // what was traced before the failure is kept: contact closed at α = 0
    let ev = path.events();
    assert!(!ev.is_empty(), "events before the failure were lost");
    assert!(ev[0].alpha.abs() <= 1e-12, "{:?}", ev[0]);
    assert!(ev.iter().all(|e| e.alpha <= fail_at));
}

/// Extreme int64 indices in CSR input are reported as CSR errors, in debug builds too
/// (no arithmetic overflow on the way).
#[test]
fn csr_extreme_indices_are_errors_not_overflows() {
    for base in [0i64, 1] {
        // a row pointer of i64::MIN
        let e = CsrMatrix::from_raw("M", 1, 2, &[base, i64::MIN], &[base], &[1.0], base);
        assert!(matches!(e, Err(Error::Csr(_))), "base {base}: {e:?}");
        // a column index of i64::MIN and of i64::MAX
        for c in [i64::MIN, i64::MAX] {
            let e = CsrMatrix::from_raw("M", 1, 2, &[base, base + 1], &[c], &[1.0], base);
            assert!(
                matches!(e, Err(Error::Csr(_))),
                "base {base}, column {c}: {e:?}"
            );
        }
        // a first row pointer of i64::MAX
        let e = CsrMatrix::from_raw("M", 1, 2, &[i64::MAX, i64::MAX], &[], &[], base);
        assert!(matches!(e, Err(Error::Csr(_))), "base {base}: {e:?}");
        // a row count of usize::MAX (nrows + 1 overflows)
        let e = no_panic("from_raw with usize::MAX rows", || {
            CsrMatrix::from_raw("M", usize::MAX, 2, &[base], &[], &[], base)
        });
        assert!(matches!(e, Err(Error::Csr(_))), "base {base}: {e:?}");
    }
    let e = no_panic("from_triplets with usize::MAX rows", || {
        CsrMatrix::from_triplets("M", usize::MAX, 2, &[])
    });
    assert!(e.is_err(), "{e:?}");
    let e = no_panic("from_dense with usize::MAX x 2", || {
        CsrMatrix::from_dense(usize::MAX, 2, &[])
    });
    assert!(matches!(e, Err(Error::Dimension(_))), "{e:?}");
}

/// Duplicate entries in CSR input are summed, in the order given, with 64-bit and
/// 32-bit indices, unsorted or not; a sum that overflows is a non-finite error.
#[test]
fn csr_duplicates_are_summed() {
    // Row 0: (0, 1) given as 0.25 then 0.5, (0, 0) once; row 1: (1, 1) as 1, 2, 4.
    let expect = dense(2, 2, &[3.0, 0.75, 0.0, 7.0]);
    let m64 = CsrMatrix::from_raw(
        "A",
        2,
        2,
        &[0i64, 3, 6],
        &[1, 0, 1, 1, 1, 1],
        &[0.25, 3.0, 0.5, 1.0, 2.0, 4.0],
        0,
    )
    .unwrap();
    assert_eq!(m64, expect);
    assert_eq!(m64.nnz(), 3);
    let m32 = CsrMatrix::from_raw(
        "A",
        2,
        2,
        &[1i32, 4, 7],
        &[2, 1, 2, 2, 2, 2],
        &[0.25, 3.0, 0.5, 1.0, 2.0, 4.0],
        1,
    )
    .unwrap();
    assert_eq!(m32, expect);
    // Summation order is the caller's: 1 + 1e16 − 1e16 = 0 in that order (1 is absorbed),
    // 1e16 − 1e16 + 1 = 1 in the other.
    let m = CsrMatrix::from_raw("A", 1, 1, &[0, 3], &[0, 0, 0], &[1.0, 1e16, -1e16], 0).unwrap();
    assert_eq!(m.values(), &[0.0]);
    let m = CsrMatrix::from_raw("A", 1, 1, &[0, 3], &[0, 0, 0], &[1e16, -1e16, 1.0], 0).unwrap();
    assert_eq!(m.values(), &[1.0]);
    // Overflow of a sum: an error naming the entry, not an infinity in the matrix.
    let e = CsrMatrix::from_raw("A", 1, 2, &[0, 2], &[1, 1], &[1e308, 1e308], 0).unwrap_err();
    assert!(matches!(e, Error::NonFinite(_)), "{e:?}");
    assert!(e.to_string().contains("(0, 1)"), "{e}");
    let e = CsrMatrix::from_triplets("N", 1, 2, &[(0, 1, -1e308), (0, 1, -1e308)]).unwrap_err();
    assert!(matches!(e, Error::NonFinite(_)), "{e:?}");
}

/// The symmetry check of A in full storage applies to the summed matrix: A(0, 1) given as
/// 0.25 + 0.25 matches A(1, 0) = 0.5, while 0.5 + 0.5 does not.
#[test]
fn symmetry_check_sees_summed_duplicates() {
    let a = |x: f64| {
        CsrMatrix::from_raw(
            "A",
            3,
            3,
            &[0i64, 3, 5, 6],
            &[0, 1, 1, 0, 1, 2],
            &[4.0, x, x, 0.5, 4.0, 4.0],
            0,
        )
        .unwrap()
    };
    let nm = dense(1, 3, &[0.0, 0.0, 1.0]);
    let tm = dense(1, 3, &[1.0, 0.0, 0.0]);
    // summed: A = [[4, 0.5, 0], [0.5, 4, 0], [0, 0, 4]], symmetric, positive definite
    let p = ProblemBuilder::new(a(0.25), Storage::Full, nm.clone(), tm.clone())
        .build()
        .unwrap();
    let same = ProblemBuilder::new(
        dense(3, 3, &[4.0, 0.5, 0.0, 0.5, 4.0, 0.0, 0.0, 0.0, 4.0]),
        Storage::Full,
        nm.clone(),
        tm.clone(),
    )
    .build()
    .unwrap();
    assert_eq!(p.default_r(), same.default_r());
    let e = build_err(
        "A(0,1) summed to 1, A(1,0) = 0.5",
        ProblemBuilder::new(a(0.5), Storage::Full, nm, tm),
    );
    assert!(matches!(e, Error::NotSymmetric(_)), "{e:?}");
}

/// Extreme or negative int32 indices are CSR errors too.
#[test]
fn csr_i32_bad_indices_are_errors() {
    for base in [0i32, 1] {
        let b = i64::from(base);
        let e = CsrMatrix::from_raw("M", 1, 2, &[base, i32::MIN], &[base], &[1.0], b);
        assert!(matches!(e, Err(Error::Csr(_))), "base {base}: {e:?}");
        for c in [i32::MIN, -1, i32::MAX] {
            let e = CsrMatrix::from_raw("M", 1, 2, &[base, base + 1], &[c], &[1.0], b);
            assert!(
                matches!(e, Err(Error::Csr(_))),
                "base {base}, column {c}: {e:?}"
            );
        }
        // a decreasing row pointer
        let e = CsrMatrix::from_raw("M", 2, 2, &[base, base + 1, base], &[base], &[1.0], b);
        assert!(
            matches!(&e, Err(Error::Csr(m)) if m.contains("decreases")),
            "{e:?}"
        );
    }
}

/// r far from the default 2p / trace(W) is refused at the build and by `with_r` (a range
/// error naming the accepted range); r within it is accepted.
#[test]
fn r_outside_its_range_is_refused() {
    let data = common::one_node(0.3, [0.0, -1.0, 0.0], [0.1, 0.0, 0.0]);
    let p = data.problem();
    let r0 = p.default_r();
    for r in [1e300, 1e-300, 2e6 * r0, 5e-7 * r0] {
        let e = data.builder().r(r).build().map(|_| ()).unwrap_err();
        assert!(
            matches!(&e, Error::InvalidParameter(m) if m.contains("outside")),
            "{r:e}: {e:?}"
        );
        let e = p.with_r(r).map(|_| ()).unwrap_err();
        assert!(
            matches!(&e, Error::InvalidParameter(m) if m.contains("outside")),
            "{r:e}: {e:?}"
        );
    }
    for r in [1e-6 * r0, 1e6 * r0, 10.0 * r0] {
        assert_eq!(p.with_r(r).unwrap().r(), r);
    }
}

/// A load that fails from α = 0.7 on, after a transition at α = 0.5 (one node, A = I,
/// f = (0.5 − α, 0): in contact, sticking, while 0.5 − α > 0, open after; a hand
/// derivation), given as a basis load and as a general load: the transition is reported
/// first, and the failure where the path reaches it, not where a step looking ahead
/// first met it. Whichever step sizes the march takes, only α ≤ 0.7 may pass.
#[test]
fn a_load_failing_ahead_is_reached_after_the_transitions_before_it() {
    let problem = || {
        let a = CsrMatrix::from_dense(2, 2, &[1.0, 0.0, 0.0, 1.0]).unwrap();
        let n = CsrMatrix::from_dense(1, 2, &[1.0, 0.0]).unwrap();
        let t = CsrMatrix::from_dense(1, 2, &[0.0, 1.0]).unwrap();
        Arc::new(
            ProblemBuilder::new(a, Storage::Full, n, t)
                .friction_uniform(0.3)
                .build()
                .unwrap(),
        )
    };
    let fail = |alpha: f64| LoadFailure {
        code: 11,
        message: format!("no data at {alpha}"),
    };
    let basis = Load::basis(
        vec![vec![0.5, 0.0], vec![-1.0, 0.0]],
        Box::new(move |al: f64, w: &mut [f64], dw: &mut [f64]| {
            if al > 0.7 {
                return Err(fail(al));
            }
            (w[0], w[1], dw[0], dw[1]) = (1.0, al, 0.0, 1.0);
            Ok(())
        }),
    )
    .unwrap();
    let general = Load::general(
        2,
        Box::new(move |al: f64, out: &mut [f64]| {
            if al > 0.7 {
                return Err(fail(al));
            }
            (out[0], out[1]) = (0.5 - al, 0.0);
            Ok(())
        }),
        None,
    );
    for (name, load) in [("basis", basis), ("general", general)] {
        let mut path = Path::new(problem(), load, PathOptions::window(0.0, 2.0)).unwrap();
        path.start(0.0, None).unwrap();
        let e = no_panic(name, || path.run()).unwrap_err();
        match e {
            Error::Load { alpha, code, .. } => {
                assert_eq!(code, 11, "{name}");
                assert!(
                    alpha > 0.7 && alpha <= 0.7 + 1e-9,
                    "{name}: failed at {alpha}"
                );
            }
            e => panic!("{name}: {e:?}"),
        }
        assert!(
            matches!(path.end_reason(), Some(EndReason::Failed(_))),
            "{name}: {:?}",
            path.end_reason()
        );
        let ev = path.events();
        assert_eq!(ev.len(), 1, "{name}: {ev:?}");
        assert!(
            (ev[0].alpha - 0.5).abs() <= 1e-12,
            "{name}: {}",
            ev[0].alpha
        );
        assert_eq!(
            (ev[0].from, ev[0].to),
            (fricont::Class::Stick, fricont::Class::Open)
        );
    }
}

/// Each row of N and T is equilibrated by its own power of two, and node i's friction
/// coefficient by their ratio (`F s_t / s_ν`): where that leaves the range of normal
/// doubles (rows of 1e-300 and 1e300 at one node, ratio 2^1993; or a tangential row of
/// 1e-320 with F = 0.3) the build is an `InvalidParameter` naming the node; F = 0 and an F
/// small (or large) enough for the ratio are accepted.
#[test]
fn friction_out_of_range_for_the_rows_of_its_node() {
    let apart = |f: f64| {
        ProblemBuilder::new(
            dense(3, 3, &eye(3)),
            Storage::Full,
            dense(1, 3, &[1e-300, 0.0, 0.0]),
            dense(1, 3, &[0.0, 1e300, 0.0]),
        )
        .friction_uniform(f)
    };
    let e = build_err("friction 1 on rows 1e-300, 1e300", apart(1.0));
    assert!(
        matches!(e, Error::InvalidParameter(ref m) if m.contains("node 1") && m.contains("2^1993")),
        "{e}"
    );
    for f in [0.0, 1e-300] {
        let p = no_panic("small friction", || apart(f).build()).unwrap();
        assert_eq!(p.friction(), &[f]);
        let fe = p.friction_equilibrated()[0];
        assert!(fe.is_finite() && (fe > 0.0) == (f > 0.0), "{fe}");
    }
    // A tangential row of 1e-320 (a subnormal number): 0.3 · 2^-1063 is subnormal and
    // keeps only some of 0.3's digits (slipping nodes had |λt| = 1.15 F |λν| in the
    // caller's units), so it is an error too; F = 1e300 gives a normal number, kept.
    let tiny_t = |f: f64| {
        ProblemBuilder::new(
            dense(3, 3, &eye(3)),
            Storage::Full,
            dense(1, 3, &[1.0, 0.0, 0.0]),
            dense(1, 3, &[0.0, 1e-320, 0.0]),
        )
        .friction_uniform(f)
    };
    let e = build_err("friction 0.3 on rows 1, 1e-320", tiny_t(0.3));
    assert!(
        matches!(e, Error::InvalidParameter(ref m) if m.contains("node 1") && m.contains("normal doubles")),
        "{e}"
    );
    let p = no_panic("friction 1e300 on rows 1, 1e-320", || tiny_t(1e300).build()).unwrap();
    let fe = p.friction_equilibrated()[0];
    assert!(fe >= f64::MIN_POSITIVE && fe.is_finite(), "{fe}");
}
