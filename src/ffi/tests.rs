//! Tests of the boundary machinery and of the exports on a problem solved by hand.
//!
//! The hand-solved problem ("block on a foundation"): two dofs, A = diag(2, 1), one contact
//! node with N = [1, 0], T = [0, 1], F = 1/2, load f(α) = (1, 0) + α (0, 1). Then
//! u = A⁻¹(f + Nᵀλν + Tᵀλt) gives u₁ = (1 + λν)/2, u₂ = α + λt. In contact u₁ = 0, so
//! λν = −1. Stick (u₂ = 0) gives λt = −α, admissible while |α| ≤ F|λν| = 1/2; at α = 1/2
//! λt reaches F λν = −1/2 and the node slips in +t (u₂ = α − 1/2 > 0). So: start at α = 0
//! in stick with λ = (−1, 0); one event at α = 1/2, stick → slip+; at α = 2, u = (0, 3/2).

use std::ffi::CStr;
use std::ptr::{null, null_mut};

use super::boundary::{self, ErrorSlot, Failure, write_message};
use super::path::*;
use super::problem::*;
use super::status::*;

#[test]
fn a_panic_is_caught_recorded_and_poisons_the_handle() {
    let slot = ErrorSlot::default();
    let st = boundary::run(Some(&slot), || panic!("boom {}", 42));
    assert_eq!(st, fricont_status::FRICONT_ERR_PANIC);
    assert!(slot.is_poisoned());
    let msg = slot.message();
    assert!(msg.contains("boom 42"), "{msg}");
    assert!(msg.contains("tests.rs"), "location missing: {msg}");
    assert_eq!(boundary::last_error(), msg);
    // Every later call is refused without running the body.
    let mut ran = false;
    let st = boundary::run(Some(&slot), || {
        ran = true;
        Ok(fricont_status::FRICONT_OK)
    });
    assert_eq!(st, fricont_status::FRICONT_ERR_POISONED);
    assert!(!ran);
}

#[test]
fn a_failure_sets_both_messages_and_keeps_the_callback_code() {
    let slot = ErrorSlot::default();
    let st = boundary::run(Some(&slot), || {
        Err(Failure::from(crate::Error::Load {
            alpha: 0.5,
            code: 17,
            message: "x".into(),
        }))
    });
    assert_eq!(st, fricont_status::FRICONT_ERR_CALLBACK);
    assert_eq!(slot.callback_code(), 17);
    assert!(slot.message().contains("code 17"));
    assert!(!slot.is_poisoned());
}

#[test]
fn messages_are_written_with_snprintf_semantics() {
    let msg = "λν ≤ 0";
    let mut buf = [0x55 as std::ffi::c_char; 16];
    let n = unsafe { write_message(msg, buf.as_mut_ptr(), buf.len()) };
    assert_eq!(n, msg.len());
    let s = unsafe { CStr::from_ptr(buf.as_ptr()) };
    assert_eq!(s.to_str().unwrap(), msg);
    // Room for 3 bytes and the NUL: "λν" needs 4, so the text is cut after "λ" (2 bytes).
    let mut small = [0x55 as std::ffi::c_char; 4];
    let n = unsafe { write_message(msg, small.as_mut_ptr(), small.len()) };
    assert_eq!(n, msg.len());
    let s = unsafe { CStr::from_ptr(small.as_ptr()) };
    assert_eq!(s.to_str().unwrap(), "λ");
    // NULL buffer or zero length: only the length.
    assert_eq!(unsafe { write_message(msg, null_mut(), 0) }, msg.len());
    let n = unsafe { write_message(msg, small.as_mut_ptr(), 0) };
    assert_eq!(n, msg.len());
}

fn csr(nrows: i64, ncols: i64, rp: &[i64], ci: &[i64], v: &[f64], base: i64) -> fricont_csr {
    fricont_csr {
        nrows,
        ncols,
        nnz: v.len() as i64,
        row_ptr: rp.as_ptr(),
        col_idx: ci.as_ptr(),
        values: v.as_ptr(),
        index_base: base,
    }
}

/// The block on a foundation, 1-based CSR (Fortran style), lower storage of A.
fn block_problem() -> *mut fricont_problem {
    let (arp, aci, av) = ([1i64, 2, 3], [1i64, 2], [2.0, 1.0]);
    let (nrp, nci, nv) = ([1i64, 2], [1i64], [1.0]);
    let (trp, tci, tv) = ([1i64, 2], [2i64], [1.0]);
    let a = csr(2, 2, &arp, &aci, &av, 1);
    let n = csr(1, 2, &nrp, &nci, &nv, 1);
    let t = csr(1, 2, &trp, &tci, &tv, 1);
    let mut prob = null_mut();
    let st = unsafe {
        fricont_problem_new(
            &a,
            fricont_storage::FRICONT_STORAGE_LOWER as i32,
            &n,
            &t,
            &mut prob,
        )
    };
    assert_eq!(st, fricont_status::FRICONT_OK);
    assert_eq!(
        unsafe { fricont_problem_set_friction(prob, 0.5) },
        fricont_status::FRICONT_OK
    );
    prob
}

#[test]
fn problem_errors_carry_specific_messages() {
    let prob = block_problem();
    let st = unsafe { fricont_problem_set_friction(prob, -1.0) };
    assert_eq!(st, fricont_status::FRICONT_ERR_RANGE);
    let mut buf = [0 as std::ffi::c_char; 200];
    let n = unsafe { fricont_problem_error_message(prob, buf.as_mut_ptr(), buf.len()) };
    let s = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_str().unwrap();
    assert_eq!(n, s.len());
    assert!(s.contains("F = -1"), "{s}");
    let st = unsafe { fricont_problem_set_r(prob, 0.0) };
    assert_eq!(st, fricont_status::FRICONT_ERR_RANGE);
    let st = unsafe { fricont_problem_set_gap(prob, [0.0, 0.0].as_ptr(), 2) };
    assert_eq!(st, fricont_status::FRICONT_ERR_LENGTH);
    let st = unsafe { fricont_problem_build(null_mut()) };
    assert_eq!(st, fricont_status::FRICONT_ERR_NULL);
    let (mut n, mut p) = (0i64, 0i64);
    assert_eq!(
        unsafe { fricont_problem_dims(prob, &mut n, &mut p) },
        fricont_status::FRICONT_OK
    );
    assert_eq!((n, p), (2, 1));
    // default r = 2p / trace(W); W = B A⁻¹ Bᵀ = diag(1/2, 1) here: r = 2 / 1.5.
    let (mut r, mut r0) = (0.0, 0.0);
    assert_eq!(
        unsafe { fricont_problem_r(prob, &mut r, &mut r0) },
        fricont_status::FRICONT_OK
    );
    assert!((r0 - 2.0 / 1.5).abs() < 1e-15 && r == r0, "{r} {r0}");
    unsafe { fricont_problem_free(prob) };
}

#[test]
fn block_on_a_foundation_matches_the_hand_solution() {
    let prob = block_problem();
    let (f0, f1) = ([1.0, 0.0], [0.0, 1.0]);
    let mut path = null_mut();
    let st = unsafe { fricont_path_new_affine(prob, f0.as_ptr(), f1.as_ptr(), 2, &mut path) };
    assert_eq!(st, fricont_status::FRICONT_OK);
    unsafe { fricont_problem_free(prob) }; // the path keeps the problem alive
    let mut count = -1i64;
    assert_eq!(
        unsafe { fricont_path_event_count(path, &mut count) },
        fricont_status::FRICONT_ERR_ORDER
    );
    assert_eq!(
        unsafe { fricont_path_start(path, 0.0, null(), 0) },
        fricont_status::FRICONT_ERR_ORDER,
        "no window yet"
    );
    let mut route = -1;
    assert_eq!(
        unsafe { fricont_path_start_route(path, &mut route) },
        fricont_status::FRICONT_ERR_ORDER,
        "not started"
    );
    assert_eq!(
        unsafe { fricont_path_set_window(path, 0.0, 2.0) },
        fricont_status::FRICONT_OK
    );
    assert_eq!(
        unsafe { fricont_path_start(path, 0.0, null(), 0) },
        fricont_status::FRICONT_OK
    );
    let mut u = [9.0; 2];
    let mut ln = [9.0; 1];
    let mut lt = [9.0; 1];
    let mut cl = [9i32; 1];
    let mut state = fricont_state {
        alpha: f64::NAN,
        residual: f64::NAN,
        u: u.as_mut_ptr(),
        u_len: 2,
        lambda_n: ln.as_mut_ptr(),
        lambda_n_len: 1,
        lambda_t: lt.as_mut_ptr(),
        lambda_t_len: 1,
        classes: cl.as_mut_ptr(),
        classes_len: 1,
    };
    assert_eq!(
        unsafe { fricont_path_start_state(path, &mut state) },
        fricont_status::FRICONT_OK
    );
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * (1.0 + b.abs());
    assert!(close(state.alpha, 0.0));
    assert!(close(ln[0], -1.0) && close(lt[0], 0.0), "{ln:?} {lt:?}");
    assert!(close(u[0], 0.0) && close(u[1], 0.0), "{u:?}");
    assert_eq!(cl[0], fricont_class::FRICONT_STICK as i32);
    // (the solver's start: the one node pressed, λν = −1, no fallback)
    assert_eq!(
        unsafe { fricont_path_start_route(path, &mut route) },
        fricont_status::FRICONT_OK
    );
    assert_eq!(route, fricont_start_route::FRICONT_START_SOLVED as i32);
    assert_eq!(
        unsafe { fricont_path_start_route(path, null_mut()) },
        fricont_status::FRICONT_ERR_NULL
    );

    let st = unsafe { fricont_path_run(path) };
    assert_eq!(st, fricont_status::FRICONT_END);
    let mut reason = -1;
    unsafe { fricont_path_end_reason(path, &mut reason) };
    assert_eq!(reason, fricont_end_reason::FRICONT_END_WINDOW as i32);
    assert_eq!(
        unsafe { fricont_path_event_count(path, &mut count) },
        fricont_status::FRICONT_OK
    );
    assert_eq!(count, 1);
    let mut ev = std::mem::MaybeUninit::<fricont_event>::uninit();
    assert_eq!(
        unsafe { fricont_path_event(path, 0, ev.as_mut_ptr()) },
        fricont_status::FRICONT_OK
    );
    let ev = unsafe { ev.assume_init() };
    assert!(close(ev.alpha, 0.5), "{}", ev.alpha);
    assert_eq!((ev.node, ev.from, ev.to), (0, 1, 2));
    assert!(!ev.fold && !ev.bifurcation);
    assert_eq!(
        unsafe { fricont_path_event(path, 1, &mut ev.clone()) },
        fricont_status::FRICONT_ERR_RANGE
    );
    // A buffer too short is refused and nothing is written.
    state.u_len = 1;
    u = [7.0; 2];
    assert_eq!(
        unsafe { fricont_path_current(path, &mut state) },
        fricont_status::FRICONT_ERR_LENGTH
    );
    assert_eq!(u, [7.0; 2]);
    state.u_len = 2;
    assert_eq!(
        unsafe { fricont_path_current(path, &mut state) },
        fricont_status::FRICONT_OK
    );
    assert!(close(state.alpha, 2.0));
    assert!(close(u[0], 0.0) && close(u[1], 1.5), "{u:?}");
    assert!(close(ln[0], -1.0) && close(lt[0], -0.5));
    assert_eq!(cl[0], fricont_class::FRICONT_SLIP_PLUS as i32);

    let mut nsol = -1;
    assert_eq!(
        unsafe { fricont_path_solutions_at(path, 0.25, &mut nsol) },
        fricont_status::FRICONT_OK
    );
    assert_eq!(nsol, 1);
    let mut info = fricont_solution {
        piece: -1,
        continuum: true,
    };
    assert_eq!(
        unsafe { fricont_path_solution(path, 0, &mut info, &mut state) },
        fricont_status::FRICONT_OK
    );
    assert_eq!((info.piece, info.continuum), (0, false));
    assert!(close(lt[0], -0.25) && close(ln[0], -1.0));
    unsafe { fricont_path_free(path) };
}
