//! Extended precision (`ProblemBuilder::extended_precision`): W and the condensed loads
//! carried as `hi + lo` beyond double, by mixed-precision refinement with fricont's
//! Cholesky factor of A, against the independent double-double condensation of
//! `tests/common/reference.rs` (its own envelope Cholesky and refined solves).
//!
//! fricont's W is that of the equilibrated rows: row k of B divided by
//! `Problem::row_scale()[k]` (a power of two, so the reference's W and q divided by the
//! scales are exact).

#[path = "../../tests/common/mod.rs"]
mod common;

use common::reference::{Condensed, SparseRows};
use fricont::condense::HostSolve;
use fricont::{CsrMatrix, Error, ExtendedPrecision, Problem, ProblemBuilder, Storage};
use fricont_exchange::generator::{RectSpec, generate};
use fricont_exchange::io::CaseData;

/// The slender beam of `tests/slender.rs`: 121 × 2 nodes on (0, 48) × (0, 1), p = 120.
fn beam() -> CaseData {
    generate(&RectSpec {
        nx: 121,
        ny: 2,
        lx: 48.0,
        ly: 1.0,
        friction: 0.3,
        ..RectSpec::press_shear()
    })
    .expect("generate")
}

fn reference(case: &CaseData) -> Condensed {
    let p = case.p();
    Condensed::from_sparse(
        &SparseRows::from_csr(&case.a),
        &SparseRows::from_csr(&case.n_mat),
        &SparseRows::from_csr(&case.t_mat),
        &case.f0,
        &case.f1,
        vec![0.0; p],
        vec![0.3; p],
    )
}

fn build(case: &CaseData, mode: ExtendedPrecision) -> Problem {
    case.builder()
        .extended_precision(mode)
        .build()
        .expect("problem")
}

/// Largest `|(x_ref + x_ref_lo) − (x + x_lo)|` over the entries, the reference's entry
/// divided by `scale` (exact: a power of two). `x_ref − x` is exact where the two are
/// within a factor of two of each other (Sterbenz), so the difference keeps the low parts.
fn dd_err(x_ref: f64, x_ref_lo: f64, scale: f64, x: f64, x_lo: f64) -> f64 {
    (((x_ref / scale - x) + x_ref_lo / scale) - x_lo).abs()
}

/// W_hi + W_lo and q_hi + q_lo agree with the reference's double-double W and q to 1e-20
/// of max|W| (max|q|), where the unrefined W and q differ by far more (so the test fails
/// without the refinement); W_hi is then W correctly rounded to double.
#[test]
fn refined_w_and_q_match_the_double_double_reference_on_a_slender_beam() {
    let case = beam();
    let cref = reference(&case);
    let on = build(&case, ExtendedPrecision::On);
    let off = build(&case, ExtendedPrecision::Off);
    assert!(on.extended_precision() && !off.extended_precision());
    let del = on.delassus();
    let (w, w_lo) = (del.w(), del.w_lo().expect("W refined"));
    assert!(off.delassus().w_lo().is_none());
    let w_off = off.delassus().w();
    let s = on.row_scale();
    let p = on.p();
    let sc = |k: usize| s[k];
    let (mut err_hi, mut err, mut big) = (0.0f64, 0.0f64, 0.0f64);
    for j in 0..2 * p {
        for i in 0..2 * p {
            let sij = sc(i) * sc(j);
            let (r, rl) = (cref.w[(i, j)], cref.w_lo[(i, j)]);
            big = big.max(w[(i, j)].abs());
            err_hi = err_hi.max(dd_err(r, rl, sij, w_off[(i, j)], 0.0));
            err = err.max(dd_err(r, rl, sij, w[(i, j)], w_lo[(i, j)]));
            // W_hi is W correctly rounded: its low part is at most half an ulp.
            assert!(
                w_lo[(i, j)].abs() <= 0.5 * f64::EPSILON * w[(i, j)].abs() * (1.0 + 1e-12),
                "W_lo({i}, {j}) = {:e} for W_hi = {:e}",
                w_lo[(i, j)],
                w[(i, j)]
            );
        }
    }
    let (err_hi, err) = (err_hi / big, err / big);
    eprintln!(
        "W: |W unrefined - W_ref| = {err_hi:e}, |W_hi + W_lo - W_ref| = {err:e} (relative to max|W|), kappa estimate {:e}, refinement {:.3} s",
        on.w_condition_estimate(),
        del.setup_times().w_lo_s
    );
    assert!(
        err <= 1e-20,
        "W_hi + W_lo differs from the reference by {err:e}"
    );
    assert!(
        err_hi >= 1e-14,
        "the unrefined W is already within {err_hi:e} of the reference: the test does not test the refinement"
    );
    // The condensed loads, computed as BoundLoad computes them.
    for (name, f, q_ref, q_ref_lo) in [
        ("q0", &case.f0, &cref.q0, &cref.q0_lo),
        ("q1", &case.f1, &cref.q1, &cref.q1_lo),
    ] {
        let q = del.condense(f).expect("condense");
        let q_lo = del
            .condense_lo(&[f.as_slice()], &[q.as_slice()])
            .expect("condense_lo")
            .expect("refined")
            .remove(0);
        let qbig = q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let (mut e_hi, mut e) = (0.0f64, 0.0f64);
        for k in 0..2 * p {
            e_hi = e_hi.max(dd_err(q_ref[k], q_ref_lo[k], sc(k), q[k], 0.0));
            e = e.max(dd_err(q_ref[k], q_ref_lo[k], sc(k), q[k], q_lo[k]));
        }
        let (e_hi, e) = (e_hi / qbig, e / qbig);
        eprintln!("{name}: |q_hi - q_ref| = {e_hi:e}, |q_hi + q_lo - q_ref| = {e:e}");
        assert!(e <= 1e-20, "{name}: q_hi + q_lo differs by {e:e}");
        assert!(e_hi >= 100.0 * e, "{name}: q_hi alone within {e_hi:e}");
    }
    // Without refinement there are no low parts.
    let q = off.delassus().condense(&case.f0).unwrap();
    assert!(
        off.delassus()
            .condense_lo(&[case.f0.as_slice()], &[q.as_slice()])
            .unwrap()
            .is_none()
    );
}

/// Auto refines the slender beam (W ill-conditioned, the refinement affordable) and the
/// sample (W well conditioned, but the refinement below `AUTO_SMALL_FLOPS`), and not a
/// well-conditioned problem too large for that (a 121 × 81 rectangle, p = 120).
#[test]
fn auto_refines_the_slender_beam_and_small_problems() {
    let beam = build(&beam(), ExtendedPrecision::Auto);
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/sample-rect30");
    let sample = CaseData::read_dir(&dir)
        .expect("sample")
        .problem(None)
        .expect("problem");
    eprintln!(
        "kappa estimates: beam {:e}, sample {:e}",
        beam.w_condition_estimate(),
        sample.w_condition_estimate()
    );
    assert!(beam.w_condition_estimate() > fricont::problem::AUTO_CONDITION);
    assert!(beam.extended_precision() && beam.delassus().w_lo().is_some());
    assert!(beam.delassus().setup_times().w_lo_s > 0.0);
    assert!(sample.w_condition_estimate() < fricont::problem::AUTO_CONDITION);
    assert!(sample.extended_precision() && sample.delassus().w_lo().is_some());
    let rect = generate(&RectSpec {
        nx: 121,
        ny: 81,
        ..RectSpec::press_shear()
    })
    .expect("generate");
    let rect = build(&rect, ExtendedPrecision::Auto);
    assert!(rect.w_condition_estimate() < fricont::problem::AUTO_CONDITION);
    assert!(!rect.extended_precision() && rect.delassus().w_lo().is_none());
    assert_eq!(rect.delassus().setup_times().w_lo_s, 0.0);
}

/// The condition estimate against the eigenvalues of W (nalgebra's symmetric
/// eigensolver): a lower bound within 10 % on the beam and the sample.
#[test]
fn condition_estimate_matches_the_eigenvalues() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/sample-rect30");
    let sample = CaseData::read_dir(&dir).unwrap().problem(None).unwrap();
    for (name, pb) in [
        ("beam", build(&beam(), ExtendedPrecision::Off)),
        ("sample", sample),
    ] {
        let w = pb.delassus().w();
        let m = w.nrows();
        let wn = nalgebra::DMatrix::from_fn(m, m, |i, j| w[(i, j)]);
        let ev = wn.symmetric_eigenvalues();
        let (lo, hi) = ev
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
        let kappa = hi / lo;
        let est = pb.w_condition_estimate();
        eprintln!("{name}: kappa {kappa:e}, estimate {est:e}");
        assert!(
            est <= kappa * 1.000001 && est >= 0.9 * kappa,
            "{name}: estimate {est:e} against {kappa:e}"
        );
    }
}

/// One node, two dofs: A = diag(2, 1) (the crate's example).
fn tiny() -> (CsrMatrix, CsrMatrix, CsrMatrix) {
    (
        CsrMatrix::from_dense(2, 2, &[2.0, 0.0, 0.0, 1.0]).unwrap(),
        CsrMatrix::from_dense(1, 2, &[1.0, 0.0]).unwrap(),
        CsrMatrix::from_dense(1, 2, &[0.0, 1.0]).unwrap(),
    )
}

/// A host's solve cannot be refined (no A): On is a clean error, Auto and Off build an
/// unrefined problem. Condensed input: On makes the problem extended (its W is the
/// caller's exact data, no low part).
#[test]
fn host_solve_and_condensed_input() {
    let (a, n, t) = tiny();
    let host = || {
        HostSolve::new(
            Box::new(|mut x| {
                for c in 0..x.ncols() {
                    x[(0, c)] /= 2.0;
                }
                Ok(())
            }),
            4,
        )
    };
    let e = ProblemBuilder::with_solve(2, host(), n.clone(), t.clone())
        .extended_precision(ExtendedPrecision::On)
        .build()
        .unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter(m) if m.contains("host")),
        "{e:?}"
    );
    for mode in [ExtendedPrecision::Auto, ExtendedPrecision::Off] {
        let pb = ProblemBuilder::with_solve(2, host(), n.clone(), t.clone())
            .extended_precision(mode)
            .build()
            .unwrap();
        assert!(!pb.extended_precision() && pb.delassus().w_lo().is_none());
    }
    // fricont's own factor: On refines even a well-conditioned W. W = diag(1/2, 1)
    // exactly; W_hi comes from Z = L_SS⁻¹ Bᵀ with L_SS = diag(√2, 1), so W_hi(1, 1) may
    // be off by an ulp, and W_hi + W_lo is 1/2 to double-double accuracy.
    let pb = ProblemBuilder::new(a, Storage::Full, n, t)
        .extended_precision(ExtendedPrecision::On)
        .build()
        .unwrap();
    assert!(pb.extended_precision());
    let (w, lo) = (pb.delassus().w(), pb.delassus().w_lo().unwrap());
    for (i, j, exact) in [(0, 0, 0.5), (1, 1, 1.0), (0, 1, 0.0), (1, 0, 0.0)] {
        let e = ((w[(i, j)] - exact) + lo[(i, j)]).abs();
        assert!(
            e <= 1e-30,
            "W({i}, {j}): {} + {} against {exact}",
            w[(i, j)],
            lo[(i, j)]
        );
    }
    assert!((pb.w_condition_estimate() - 2.0).abs() < 1e-9);
    let w = fricont::faer::Mat::from_fn(2, 2, |i, j| if i == j { 0.5 + i as f64 } else { 0.0 });
    for (mode, ext) in [
        (ExtendedPrecision::On, true),
        (ExtendedPrecision::Auto, false),
        (ExtendedPrecision::Off, false),
    ] {
        let pb = ProblemBuilder::condensed(w.clone())
            .extended_precision(mode)
            .build()
            .unwrap();
        assert_eq!(pb.extended_precision(), ext, "{mode:?}");
        assert!(pb.delassus().w_lo().is_none());
    }
}
