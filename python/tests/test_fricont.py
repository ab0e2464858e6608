"""Tests of the Python package against independent sources: the CLI's JSON on the same
case, a hand derivation, other input kinds of the same matrices, and a single-threaded run.
"""

import json
import os
import pathlib
import subprocess
import sys
import threading

import numpy as np
import pytest
import scipy.sparse as sp

import fricont

ROOT = pathlib.Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "tests" / "data" / "sample-rect30"
VERTEX_START = ROOT / "tests" / "data" / "vertex-start"
BIFURCATION = ROOT / "tests" / "data" / "bifurcation-stop"
CLI = pathlib.Path(os.environ.get("FRICONT_CLI", ROOT / "target" / "release" / "fricont"))
EXAMPLES = ROOT / "python" / "examples"


def cli_events(directory, tmp_path):
    out = tmp_path / "cli.json"
    subprocess.run([str(CLI), "trace", str(directory), "--json", str(out)], check=True,
                   stdout=subprocess.DEVNULL)
    return json.loads(out.read_text())


def assert_same_events(py_events, cli_json, rel=1e-12):
    ev = cli_json["events"]
    assert len(py_events) == len(ev) > 0
    for e, j in zip(py_events, ev):
        assert e.node + 1 == j["node"]
        assert (e.from_class, e.to_class) == (j["from"], j["to"])
        assert (e.fold, e.bifurcation) == (j["fold"], j["bifurcation"])
        assert abs(e.alpha - j["alpha"]) <= rel * max(abs(j["alpha"]), 1.0), (e.alpha, j["alpha"])


def signature(path):
    return [(e.node, e.from_class, e.to_class, e.fold) for e in path.events]


def same_path(a, b, rel=1e-12):
    """Same events: nodes, classes and flags, alpha to `rel` relative."""
    return signature(a) == signature(b) and all(
        abs(x.alpha - y.alpha) <= rel * max(abs(y.alpha), 1.0) for x, y in zip(a.events, b.events))


@pytest.fixture(scope="module")
def sample():
    return fricont.read_case(SAMPLE)


def trace_sample(case, **kw):
    prob = fricont.Problem(case["A"], case["N"], case["T"], friction=case["friction"], **kw)
    return prob.trace(case["f0"], case["f1"], window=(case["alpha_start"], case["alpha_end"]))


def test_one_node_sticks_then_slips_at_the_hand_derived_alpha():
    # A = diag(2, 1), N = [1, 0], T = [0, 1], F = 0.5, f = (1, alpha): the node is pressed
    # with lambda_n = -1 and sheared by lambda_t = -alpha; it sticks while alpha <= 0.5.
    A = sp.diags([2.0, 1.0]).tocsr()
    prob = fricont.Problem(A, [[1.0, 0.0]], [[0.0, 1.0]], friction=0.5)
    path = prob.trace(f0=[1.0, 0.0], f1=[0.0, 1.0], window=(0.0, 2.0))
    assert len(path.events) == 1 and path.end_reason == "window"
    assert path.start_route == "solved"
    e = path.events[0]
    assert (e.node, e.from_class, e.to_class) == (0, "stick", "slip+")
    assert abs(e.alpha - 0.5) <= 1e-14
    assert e.lambda_n[0] == pytest.approx(-1.0, abs=1e-14)
    st = path.event_state(0)
    assert st["residual"] <= 1e-14
    # At alpha = 1 the node slips: lambda_t = F lambda_n = -0.5, u_t = (alpha - 0.5) / 1.
    (sol,) = path.solutions_at(1.0)
    assert sol.lambda_t[0] == pytest.approx(-0.5, abs=1e-14)
    assert sol.u[1] == pytest.approx(0.5, abs=1e-14)
    assert sol.classes == ("slip+",)
    for bad in (float("nan"), float("inf")):
        with pytest.raises(ValueError, match="not finite"):
            path.solutions_at(bad)
    # W = B A^-1 B^T = diag(1/2, 1) (rows of norm 1: no equilibration): condition 2 (its
    # estimate by 20 power iterations, a lower bound, to about 4^-20); a problem this small
    # is always refined, and the report says both.
    assert prob.w_condition_estimate == pytest.approx(2.0, rel=1e-9)
    assert prob.extended_precision is True
    assert path.to_dict()["precision"] == {
        "extended": True, "w_condition_estimate": prob.w_condition_estimate}
    # ... unless told not to; either way the same event.
    off = fricont.Problem(A, [[1.0, 0.0]], [[0.0, 1.0]], friction=0.5, extended_precision="off")
    assert off.extended_precision is False
    e_off = off.trace(f0=[1.0, 0.0], f1=[0.0, 1.0], window=(0.0, 2.0)).events[0]
    assert abs(e_off.alpha - 0.5) <= 1e-14
    with pytest.raises(ValueError, match="extended_precision"):
        fricont.Problem(A, [[1.0, 0.0]], [[0.0, 1.0]], extended_precision="yes")


def test_sample_events_equal_the_cli(sample, tmp_path):
    path = trace_sample(sample)
    assert_same_events(path.events, cli_events(SAMPLE, tmp_path))
    d = path.to_dict()
    assert d["n"] == 1320 and d["p"] == 30 and d["end"]["reason"] == "window"
    assert [e["node"] for e in d["events"]] == [e.node + 1 for e in path.events]


def test_every_input_kind_gives_the_same_events(sample):
    ref = trace_sample(sample)
    A, N, T = sample["A"], sample["N"], sample["T"]
    kinds = {
        "csc": (sp.csc_array(A), sp.csc_array(N), sp.csc_array(T), "full"),
        "coo": (sp.coo_array(A), sp.coo_array(N), sp.coo_array(T), "full"),
        "csr_matrix": (sp.csr_matrix(A), sp.csr_matrix(N), sp.csr_matrix(T), "full"),
        "dense": (A.toarray(), N.toarray(), T.toarray(), "full"),
        "lower": (sp.tril(A, format="csr"), N, T, "lower"),
        "upper": (sp.triu(A, format="csc"), N, T, "upper"),
    }
    i32 = sp.csr_array(A)
    i32.indices = i32.indices.astype(np.int32)
    i32.indptr = i32.indptr.astype(np.int32)
    i64 = sp.csr_array(A)
    i64.indices = i64.indices.astype(np.int64)
    i64.indptr = i64.indptr.astype(np.int64)
    kinds["int32"] = (i32, N, T, "full")
    kinds["int64"] = (i64, N, T, "full")
    for name, (a, n, t, storage) in kinds.items():
        prob = fricont.Problem(a, n, t, friction=sample["friction"], storage=storage)
        path = prob.trace(sample["f0"], sample["f1"], window=(-0.5, 1.5))
        # A dense or triangular input changes the stored pattern (explicit zeros dropped)
        # and so the fill-reducing ordering and the rounding of the factor; the sample's
        # third event is a shallow crossing that moves by ~1e-12 under such 1-ulp changes
        # (its condition number), hence 1e-11 here, 1e-12 where the input is the same.
        assert same_path(path, ref, rel=1e-11), name


def test_a_general_load_equal_to_the_affine_one_gives_the_same_events(sample):
    ref = trace_sample(sample)
    prob = fricont.Problem(sample["A"], sample["N"], sample["T"], friction=sample["friction"])
    f0, f1 = sample["f0"], sample["f1"]
    path = prob.trace(load=lambda a: f0 + a * f1, dload=lambda a: f1, window=(-0.5, 1.5))
    assert len(path.events) == len(ref.events)
    for e, r in zip(path.events, ref.events):
        assert (e.node, e.from_class, e.to_class) == (r.node, r.from_class, r.to_class)
        assert abs(e.alpha - r.alpha) <= 1e-10


def test_a_basis_load_reparametrised_by_sinh_has_the_events_at_asinh(sample):
    # f(s) = f0 + sinh(s) f1 is the affine load at alpha = sinh(s): the events of the basis
    # load are at s = asinh(alpha_k) of the affine ones (a reparametrisation, metamorphic).
    ref = trace_sample(sample)
    prob = fricont.Problem(sample["A"], sample["N"], sample["T"], friction=sample["friction"])
    f0, f1 = sample["f0"], sample["f1"]
    path = prob.trace(basis=[f0, f1], weights=lambda s: ([1.0, np.sinh(s)], [0.0, np.cosh(s)]),
                      window=(np.arcsinh(-0.5), np.arcsinh(1.5)))
    assert path.end_reason == "window" and len(path.events) == len(ref.events)
    for e, r in zip(path.events, ref.events):
        assert (e.node, e.from_class, e.to_class, e.fold) == (r.node, r.from_class, r.to_class, r.fold)
        assert abs(np.sinh(e.alpha) - r.alpha) <= 1e-10 * max(1.0, abs(r.alpha))


def test_basis_load_errors(sample):
    prob = fricont.Problem(sample["A"], sample["N"], sample["T"], friction=sample["friction"])
    f0, f1 = sample["f0"], sample["f1"]
    win = (-0.5, 1.5)
    with pytest.raises(ValueError, match="one load"):
        prob.trace(f0, f1, window=win, basis=[f0], weights=lambda a: ([1.0], [0.0]))
    with pytest.raises(ValueError, match="weights"):
        prob.trace(window=win, basis=[f0, f1])
    with pytest.raises(ValueError, match="expected k = 2"):
        prob.trace(window=win, basis=[f0, f1], weights=lambda a: ([1.0], [0.0]))
    with pytest.raises(ValueError, match="pair"):
        prob.trace(window=win, basis=[f0, f1], weights=lambda a: np.array([1.0, a]))
    with pytest.raises(ValueError, match="basis"):
        prob.trace(window=win, basis=[f0, f1[:-1]], weights=lambda a: ([1.0, a], [0.0, 1.0]))

    def weights(a):
        if a > 0.5:
            raise RuntimeError("no weights beyond alpha = 0.5")
        return [1.0, a], [0.0, 1.0]

    with pytest.raises(RuntimeError, match="beyond") as info:
        prob.trace(window=win, basis=[f0, f1], weights=weights)
    kept = info.value.path
    assert kept.end_reason == "failed" and len(kept.events) > 0
    assert all(e.alpha <= 0.5 + 1e-12 for e in kept.events)


def test_a_load_that_raises_keeps_the_traced_part(sample):
    ref = trace_sample(sample)
    cut = 0.5
    prob = fricont.Problem(sample["A"], sample["N"], sample["T"], friction=sample["friction"])
    f0, f1 = sample["f0"], sample["f1"]

    def load(a):
        if a > cut:
            raise RuntimeError("no load beyond alpha = 0.5")
        return f0 + a * f1

    with pytest.raises(RuntimeError, match="beyond") as info:
        prob.trace(load=load, dload=lambda a: f1, window=(-0.5, 1.5))
    kept = info.value.path
    assert isinstance(kept, fricont.Path) and kept.end_reason == "failed"
    expected = [e for e in ref.events if e.alpha < cut - 1e-9]
    assert len(expected) > 0
    assert [(e.node, e.to_class) for e in kept.events[: len(expected)]] == [
        (e.node, e.to_class) for e in expected
    ]
    assert all(e.alpha <= cut + 1e-12 for e in kept.events)


def test_the_monitor_stops_the_path_after_three_transition_points_and_resume_ends_it(sample):
    # Reference: the same path traced without a monitor (the same arithmetic: equal bits).
    ref = trace_sample(sample)
    seen = []

    def monitor(alpha, transitions, events):
        seen.append((alpha, transitions, events))
        return transitions >= 3

    prob = fricont.Problem(sample["A"], sample["N"], sample["T"], friction=sample["friction"])
    path = prob.trace(sample["f0"], sample["f1"], window=(-0.5, 1.5), monitor=monitor)
    assert path.end_reason == "stopped" and path.end_message is None
    assert path.to_dict()["end"]["reason"] == "stopped"
    assert [t for _, t, _ in seen] == [1, 2, 3]
    # each call: alpha of the new events, which follow those of the previous call
    assert seen[0][2][0] == 0
    for (a, t, (first, end)), prev in zip(seen, [None] + seen[:-1]):
        assert prev is None or first == prev[2][1]
        assert end > first
        assert all(ref.events[k].alpha == a and ref.events[k].transition == t - 1
                   for k in range(first, end))
    n_stop = seen[-1][2][1]
    assert len(path.events) == n_stop < len(ref.events)
    assert [(e.alpha, e.node, e.to_class) for e in path.events] == [
        (e.alpha, e.node, e.to_class) for e in ref.events[:n_stop]]
    # resume: from the stop to the reference's end, with the reference's events
    more = []
    assert path.resume(monitor=lambda a, t, ev: more.append(t)) is path
    assert path.end_reason == ref.end_reason == "window"
    assert path.to_dict()["end"]["reason"] == "window"
    assert [(e.alpha, e.node, e.from_class, e.to_class, e.transition) for e in path.events] == [
        (e.alpha, e.node, e.from_class, e.to_class, e.transition) for e in ref.events]
    assert more == list(range(4, ref.events[-1].transition + 2))
    assert len(path.pieces) == len(ref.pieces)
    # resuming a path that ended changes nothing
    path.resume()
    assert path.end_reason == "window" and len(path.events) == len(ref.events)


def test_an_exception_in_the_monitor_stops_the_path_and_is_raised_with_it(sample):
    ref = trace_sample(sample)

    class GiveUp(Exception):
        pass

    def monitor(alpha, transitions, events):
        if transitions == 2:
            raise GiveUp("enough at 2")
        return False

    prob = fricont.Problem(sample["A"], sample["N"], sample["T"], friction=sample["friction"])
    with pytest.raises(GiveUp, match="enough at 2") as info:
        prob.trace(sample["f0"], sample["f1"], window=(-0.5, 1.5), monitor=monitor)
    kept = info.value.path
    assert kept.end_reason == "stopped"
    upto = [e for e in ref.events if e.transition <= 1]
    assert [(e.alpha, e.node) for e in kept.events] == [(e.alpha, e.node) for e in upto]
    # the path stays usable; a monitor that reads the path from inside its own run is
    # refused (UsageError, raised like any exception of the monitor), not a deadlock
    with pytest.raises(fricont.UsageError, match="monitor") as info:
        kept.resume(monitor=lambda a, t, ev: kept.event_state(ev[0]))
    assert info.value.path is kept and kept.end_reason == "stopped"
    upto = [e for e in ref.events if e.transition <= 2]
    assert [(e.alpha, e.node) for e in kept.events] == [(e.alpha, e.node) for e in upto]
    kept.resume()
    assert kept.end_reason == "window"
    assert [(e.alpha, e.node) for e in kept.events] == [(e.alpha, e.node) for e in ref.events]


def test_max_alpha_step_finds_a_narrow_bump_at_the_analytic_alpha():
    # One node, A = I, N = [1, 0], T = [0, 1] under the normal load
    # c(alpha) = 0.5 - 0.6 exp(-((alpha - ab)/w)^2) (tests/core_oscillating.rs): the node
    # opens where the exponential exceeds 5/6, i.e. for |alpha - ab| < w sqrt(ln 1.2).
    # The default steps (up to 1/8 of the window) never evaluate the load on the bump;
    # steps of at most 1e-3 find both transitions.
    ab, w = 21.5 / 64, 2e-3
    half = w * np.sqrt(np.log(1.2))
    prob = fricont.Problem(sp.identity(2, format="csr"), [[1.0, 0.0]], [[0.0, 1.0]], friction=0.3)

    def load(a):
        return np.array([0.5 - 0.6 * np.exp(-(((a - ab) / w) ** 2)), 0.0])

    path = prob.trace(load=load, window=(-1.0, 1.0), max_alpha_step=1e-3)
    assert path.end_reason == "window"
    assert [(e.from_class, e.to_class) for e in path.events] == [("stick", "open"), ("open", "stick")]
    assert abs(path.events[0].alpha - (ab - half)) <= 1e-10
    assert abs(path.events[1].alpha - (ab + half)) <= 1e-10
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="max_alpha_step"):
            prob.trace(load=load, window=(-1.0, 1.0), max_alpha_step=bad)
        with pytest.raises(ValueError, match="max_alpha_step"):
            prob.trace([0.5, 0.0], [0.0, 0.0], window=(-1.0, 1.0), max_alpha_step=bad)


def test_two_threads_trace_at_once_with_the_results_of_one(sample):
    ref = trace_sample(sample)
    results = [None, None]

    def work(k):
        results[k] = trace_sample(sample)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    # Identical to the last bit: the same arithmetic on each thread.
    for r in results:
        assert [(e.alpha, e.node, e.to_class) for e in r.events] == [
            (e.alpha, e.node, e.to_class) for e in ref.events]


def test_the_threads_option_gives_the_events_of_one_thread(sample):
    # The set-up on a private pool of 2 threads (the sample's 2p = 60 is below the order
    # from which the trace's passes use them): W, and so the events, to rounding.
    ref = trace_sample(sample)
    two = trace_sample(sample, threads=2)
    assert same_path(two, ref, rel=1e-12)


def test_bad_inputs_raise_the_documented_exceptions(sample):
    A, N, T = sample["A"], sample["N"], sample["T"]
    with pytest.raises(ValueError, match="symmetric"):
        B = sp.csr_array(A.toarray() + np.triu(np.ones(A.shape), 1) * 1e-3)
        fricont.Problem(B, N, T)
    with pytest.raises(fricont.NotPositiveDefinite) as info:
        fricont.Problem(-A, N, T)
    assert isinstance(info.value, ValueError) and isinstance(info.value, fricont.Error)
    with pytest.raises(ValueError):
        fricont.Problem(A, N[:, :-1], T)
    with pytest.raises(ValueError, match="non-finite|NaN"):
        a = sp.csr_array(A, copy=True)
        a.data[0] = np.nan
        fricont.Problem(a, N, T)
    with pytest.raises(ValueError, match="friction|F"):
        fricont.Problem(A, N, T, friction=-1.0)
    with pytest.raises(ValueError, match="storage"):
        fricont.Problem(A, N, T, storage="both")
    for threads in (0, 1025, 1.5, True):
        with pytest.raises(ValueError, match="threads"):
            fricont.Problem(A, N, T, threads=threads)
    prob = fricont.Problem(A, N, T)
    with pytest.raises(ValueError):
        prob.trace(sample["f0"][:-1], sample["f1"], window=(0, 1))
    with pytest.raises(ValueError, match="window"):
        prob.trace(sample["f0"], sample["f1"], window=(1.0, 1.0))
    with pytest.raises(ValueError):
        prob.trace(sample["f0"], sample["f1"], window=(0, 1), max_steps=0)
    with pytest.raises(OSError, match="meta.json"):
        fricont.read_case(SAMPLE / "missing")


def test_vectors_and_event_indices_are_taken_as_meant(sample):
    # A (nodes, 2) table is not a vector: which dof each entry is belongs to the caller.
    # A column, and a list index counted from the end, are what they say.
    prob = fricont.Problem(sample["A"], sample["N"], sample["T"], friction=sample["friction"])
    f0, f1, win = sample["f0"], sample["f1"], (sample["alpha_start"], sample["alpha_end"])
    ref = prob.trace(f0, f1, window=win)
    assert len(ref.events) >= 2
    with pytest.raises(ValueError, match=r"f0: expected a vector, got an array of shape \(660, 2\)"):
        prob.trace(f0.reshape(-1, 2), f1, window=win)
    with pytest.raises(ValueError, match="shape"):
        prob.trace(load=lambda a: (f0 + a * f1).reshape(-1, 2), window=win)
    with pytest.raises(ValueError, match="friction: expected a vector"):
        fricont.Problem(sample["A"], sample["N"], sample["T"], friction=np.full((2, 15), 0.3))
    assert same_path(prob.trace(f0.reshape(-1, 1), f1.reshape(1, -1), window=win), ref)
    count = len(ref.events)
    last = ref.event_state(count - 1)
    for k in (-1, np.int64(-1)):
        st = ref.event_state(k)
        assert st["alpha"] == last["alpha"] and np.array_equal(st["u"], last["u"])
    assert ref.event_state(-count)["alpha"] == ref.event_state(0)["alpha"]
    for k in (count, -count - 1):
        with pytest.raises(fricont.UsageError, match="does not exist"):
            ref.event_state(k)
    for k in (1.0, True, "0"):
        with pytest.raises(ValueError, match="event index"):
            ref.event_state(k)


def test_the_skfem_example_agrees_with_the_cli(tmp_path):
    proc = subprocess.run([sys.executable, str(EXAMPLES / "skfem_block.py"), str(tmp_path), "--export"],
                          check=True, capture_output=True, text=True)
    assert (tmp_path / "skfem_block.png").stat().st_size > 10_000
    case = fricont.read_case(tmp_path / "problem")
    path = fricont.Problem(case["A"], case["N"], case["T"], friction=case["friction"]).trace(
        case["f0"], case["f1"], window=(case["alpha_start"], case["alpha_end"]))
    assert_same_events(path.events, cli_events(tmp_path / "problem", tmp_path))
    assert f"{len(path.events)} events" in proc.stdout


def test_complex_input_is_refused_unless_it_is_real():
    # numpy drops an imaginary part with a warning only: fricont refuses it, and takes the
    # real part of complex values whose imaginary parts are all zero.
    A = sp.diags([2.0, 1.0]).tocsr()
    N, T = [[1.0, 0.0]], [[0.0, 1.0]]
    ref = fricont.Problem(A, N, T, friction=0.5).trace(
        f0=[1.0, 0.0], f1=[0.0, 1.0], window=(0.0, 2.0)
    )
    with pytest.raises(ValueError, match="imaginary"):
        fricont.Problem(A.astype(complex) * (1 + 1e-3j), N, T, friction=0.5)
    with pytest.raises(ValueError, match="imaginary"):
        fricont.Problem(np.diag([2.0, 1.0 + 1e-9j]), N, T, friction=0.5)
    with pytest.raises(ValueError, match="imaginary"):
        fricont.Problem(A, N, T, friction=0.5 + 0.1j)
    prob = fricont.Problem(A.astype(complex), np.array(N, dtype=complex), T, friction=0.5 + 0j)
    with pytest.raises(ValueError, match="imaginary"):
        prob.trace(f0=[1.0, 1j], f1=[0.0, 1.0], window=(0.0, 2.0))
    with pytest.raises(ValueError, match="imaginary"):
        prob.trace(load=lambda a: np.array([1.0, a + 1e-6j]), window=(0.0, 2.0))
    for path in (
        prob.trace(f0=np.array([1.0, 0.0], dtype=complex), f1=[0.0, 1.0], window=(0.0, 2.0)),
        prob.trace(load=lambda a: np.array([1.0, a], dtype=complex), window=(0.0, 2.0)),
    ):
        assert [(e.node, e.from_class, e.to_class) for e in path.events] == [
            (e.node, e.from_class, e.to_class) for e in ref.events
        ]
        assert abs(path.events[0].alpha - 0.5) <= 1e-14


CLASSES = ("open", "stick", "slip+", "slip-")


def brute_pieces(case):
    """Every piece of a small problem (all 4^p class vectors), independently of fricont
    (dense numpy, SPEC section 3): W = B A^-1 B^T, q = B A^-1 f, d = q + W lambda - (g, 0);
    open: lambda = 0, guard -d_n > 0; stick: d = 0, guards -lambda_n > 0 and
    |lambda_t| < -F lambda_n; slip s: d_n = 0, lambda_t = s F lambda_n, guards
    -lambda_n > 0 and s d_t > 0. Returns (classes, l0, l1, lo, hi): lambda = l0 + alpha l1
    on the open interval (lo, hi), for the nonempty ones."""
    A = case["A"].toarray()
    B = np.vstack([case["N"].toarray(), case["T"].toarray()])
    p = B.shape[0] // 2
    W = B @ np.linalg.solve(A, B.T)
    W = (W + W.T) / 2
    q0, q1 = B @ np.linalg.solve(A, case["f0"]), B @ np.linalg.solve(A, case["f1"])
    gap = np.zeros(p) if case["gap"] is None else np.asarray(case["gap"])
    F = np.broadcast_to(np.asarray(case["friction"], dtype=float), (p,))
    out = []
    for code in range(4**p):
        cl = tuple(CLASSES[(code >> (2 * i)) & 3] for i in range(p))
        M, r0, r1 = np.zeros((2 * p, 2 * p)), np.zeros(2 * p), np.zeros(2 * p)
        for i, c in enumerate(cl):
            if c == "open":
                M[i, i] = M[p + i, p + i] = 1.0
                continue
            M[i], r0[i], r1[i] = W[i], gap[i] - q0[i], -q1[i]
            if c == "stick":
                M[p + i], r0[p + i], r1[p + i] = W[p + i], -q0[p + i], -q1[p + i]
            else:
                M[p + i, p + i], M[p + i, i] = 1.0, -(1.0 if c == "slip+" else -1.0) * F[i]
        if np.linalg.cond(M) > 1e11:
            continue
        l0, l1 = np.linalg.solve(M, r0), np.linalg.solve(M, r1)
        d0, d1 = q0 + W @ l0 - np.concatenate([gap, np.zeros(p)]), q1 + W @ l1
        guards = []
        for i, c in enumerate(cl):
            n, t = i, p + i
            if c == "open":
                guards.append((-d0[n], -d1[n]))
            elif c == "stick":
                guards += [(-l0[n], -l1[n]), (l0[t] - F[i] * l0[n], l1[t] - F[i] * l1[n]),
                           (-F[i] * l0[n] - l0[t], -F[i] * l1[n] - l1[t])]
            else:
                s = 1.0 if c == "slip+" else -1.0
                guards += [(-l0[n], -l1[n]), (s * d0[t], s * d1[t])]
        lo, hi = -np.inf, np.inf
        for g0, g1 in guards:
            if g1 > 0:
                lo = max(lo, -g0 / g1)
            elif g1 < 0:
                hi = min(hi, -g0 / g1)
            elif g0 <= 0:
                hi = -np.inf
        if lo < hi:
            out.append((cl, l0, l1, lo, hi))
    return out


def incident(pieces, alpha, lam, tol=1e-8):
    """The pieces whose closure holds the point (alpha, lambda), as {classes: the end at
    alpha, "lo" or "hi"}."""
    out = {}
    for cl, l0, l1, lo, hi in pieces:
        for end, a in (("lo", lo), ("hi", hi)):
            if abs(a - alpha) <= tol * max(1.0, abs(alpha)) and np.allclose(
                    l0 + a * l1, lam, rtol=0, atol=tol * max(1.0, np.abs(lam).max())):
                out[cl] = end
    return out


def test_choose_branch_follows_each_continuation_of_a_bifurcation_the_path_stopped_at():
    case = fricont.read_case(BIFURCATION)
    prob = fricont.Problem(case["A"], case["N"], case["T"], friction=case["friction"])
    window = (case["alpha_start"], case["alpha_end"])

    def traced():
        return prob.trace(case["f0"], case["f1"], window=window)

    path = traced()
    assert path.end_reason == "bifurcation" and path.start_branches == []
    last = path.pieces[-1]
    alpha, lam = last.alpha_to, last.lambda_to
    # The brute force's pieces through the point, less the one the path came by, are the
    # continuations: the path offers exactly those.
    pieces = brute_pieces(case)
    through = incident(pieces, alpha, lam)
    assert last.classes in through
    want = {cl: end for cl, end in through.items() if cl != last.classes}
    assert len(want) >= 2
    assert {b.classes for b in path.branches} == set(want)
    # alpha_end < alpha_start: a piece leaving the point at its "hi" end goes down in alpha.
    for b in path.branches:
        assert b.direction == (-1 if want[b.classes] == "hi" else 1)
    kept = [(e.alpha, e.node, e.from_class, e.to_class) for e in path.events]
    for k, b in enumerate(path.branches):
        other = traced()
        assert other.choose_branch(k) is other
        assert [(e.alpha, e.node, e.from_class, e.to_class) for e in other.events[:len(kept)]] == kept
        after = [pc.classes for pc in other.pieces]
        assert after[len(path.pieces)] == b.classes
        assert other.end_reason == "window" and other.branches == []
        # The chosen piece's next transition (or the window's end) where the brute force's
        # piece ends.
        (cl, l0, l1, lo, hi), = [pc for pc in pieces if pc[0] == b.classes]
        nxt = other.pieces[len(path.pieces)]
        end = max(lo, min(window)) if b.direction < 0 else min(hi, max(window))
        assert nxt.alpha_to == pytest.approx(end, rel=1e-10, abs=1e-10)
        np.testing.assert_allclose(nxt.lambda_to, l0 + end * l1, rtol=0, atol=1e-10)
    # Choosing again after the path moved on, or an index out of range, is a usage error
    # that carries the path.
    with pytest.raises(fricont.UsageError) as err:
        other.choose_branch(0)
    assert err.value.path is other
    with pytest.raises(fricont.UsageError):
        traced().choose_branch(len(want))
    with pytest.raises(ValueError):
        traced().choose_branch(-1)


def test_branch_starts_on_each_piece_leaving_a_zero_force_vertex():
    # tests/data/vertex-start: the brute force (tests/core_vertex_start.rs, c-tests/
    # start_branches.c) finds three solution curves leaving the start point toward
    # alpha_end: (open, slip+), (slip-, slip+), (stick, slip-). Here they are checked
    # against this file's own enumeration as well.
    case = fricont.read_case(VERTEX_START)
    prob = fricont.Problem(case["A"], case["N"], case["T"], friction=case["friction"])
    window = (case["alpha_start"], case["alpha_end"])
    path = prob.trace(case["f0"], case["f1"], window=window)
    offered = [b.classes for b in path.start_branches]
    assert set(offered) == {("open", "slip+"), ("slip-", "slip+"), ("stick", "slip-")}
    # (the vertex: lambda = 0 at alpha_start; each curve leaves it toward alpha_end < 0)
    through = incident(brute_pieces(case), window[0], np.zeros(4))
    assert {cl for cl, end in through.items() if end == "hi"} == set(offered)
    assert all(b.direction == -1 for b in path.start_branches)
    assert path.pieces[0].classes == offered[0]
    for k, cl in enumerate(offered):
        other = prob.trace(case["f0"], case["f1"], window=window, branch=k)
        assert other.pieces[0].classes == cl and other.end_reason == "window"
        assert [b.classes for b in other.start_branches] == offered
    with pytest.raises(fricont.UsageError, match="3 pieces leave the start point") as err:
        prob.trace(case["f0"], case["f1"], window=window, branch=3)
    assert err.value.path.pieces[0].classes == offered[0]
    # (one piece leaves the sample's start: branch 0 is it, branch 1 an error)
    sample = fricont.read_case(SAMPLE)
    sp = fricont.Problem(sample["A"], sample["N"], sample["T"], friction=sample["friction"])
    sw = (sample["alpha_start"], sample["alpha_end"])
    assert same_path(sp.trace(sample["f0"], sample["f1"], window=sw, branch=0),
                     sp.trace(sample["f0"], sample["f1"], window=sw))
    with pytest.raises(fricont.UsageError, match="1 piece leaves the start point"):
        sp.trace(sample["f0"], sample["f1"], window=sw, branch=1)
    with pytest.raises(ValueError, match="branch"):
        prob.trace(case["f0"], case["f1"], window=window, branch=-1)


def test_a_guess_that_solves_the_problem_starts_the_path_there():
    # The hand-derived fold problem of tests/core_hand.rs (two_folds_three_solutions):
    # A = diag(1, 1, 4), N = (1, 0, 0), T = (-1, 1, 0), F = 2, f = f0 + alpha f1. At
    # alpha = -1 it has three solutions: open lambda = (0, 0), slip+ (-1, -2) (on
    # (-2, 0)) and stick (-1.5, -2.5) (on (-2, 1.2), then slip- from alpha = 1.2 on).
    A = sp.diags([1.0, 1.0, 4.0]).tocsr()
    prob = fricont.Problem(A, [[1.0, 0.0, 0.0]], [[-1.0, 1.0, 0.0]], friction=2.0)
    f0, f1 = [0.0, 1.0, 0.7], [1.0, -1.5, -0.3]
    expect = {
        # guess: (start class, events (alpha, from, to, fold), end alpha)
        (0.0, 0.0): ("open", [(0.0, "open", "slip+", True)], -1.0),
        (-1.0, -2.0): ("slip+", [(0.0, "slip+", "open", True)], -1.0),
        (-1.5, -2.5): ("stick", [(1.2, "stick", "slip-", False)], 3.0),
    }
    for guess, (cls, events, end) in expect.items():
        path = prob.trace(f0, f1, window=(-1.0, 3.0), guess=list(guess))
        st = path.start
        assert st["classes"] == [cls]
        np.testing.assert_allclose([st["lambda_n"][0], st["lambda_t"][0]], guess, atol=1e-14)
        got = [(e.alpha, e.from_class, e.to_class, e.fold) for e in path.events]
        assert len(got) == len(events)
        for (a, fc, tc, fold), (wa, wfc, wtc, wfold) in zip(got, events):
            assert (fc, tc, fold) == (wfc, wtc, wfold) and a == pytest.approx(wa, abs=1e-13)
        assert path.end_reason == "window"
        assert path.pieces[-1].alpha_to == pytest.approx(end, abs=1e-13)
    for bad, match in (([0.0], "2p"), ([0.0, float("nan")], "finite")):
        with pytest.raises(ValueError, match=match):
            prob.trace(f0, f1, window=(-1.0, 3.0), guess=bad)


def test_zero_tol_decides_which_nearby_switches_are_one_transition_point():
    # Two decoupled nodes (A = I, N = (u1, u3), T = (u2, u4), F = 1/2) pushed by
    # f_n = alpha - 1/2 and alpha - 1/2 - d, sheared by +-0.1: by hand, node 1 closes at
    # alpha = 1/2 (slip, since F |lambda_n| = (alpha - 1/2)/2 < 0.1) and sticks at 0.7,
    # node 2 likewise d later. d = 1e-10 is above the default zero_tol (1e-11): four
    # transition points; with zero_tol = 1e-9 the pairs are one point each.
    A = sp.identity(4, format="csr")
    prob = fricont.Problem(A, [[1, 0, 0, 0], [0, 0, 1, 0]], [[0, 1, 0, 0], [0, 0, 0, 1]],
                           friction=0.5)
    d = 1e-10
    f0, f1 = [-0.5, 0.1, -0.5 - d, -0.1], [1.0, 0.0, 1.0, 0.0]
    want = [(0.5, 0, "open", "slip+"), (0.5 + d, 1, "open", "slip-"),
            (0.7, 0, "slip+", "stick"), (0.7 + d, 1, "slip-", "stick")]
    apart = prob.trace(f0, f1, window=(0.0, 1.0))
    assert [(e.node, e.from_class, e.to_class) for e in apart.events] == [w[1:] for w in want]
    assert [e.transition for e in apart.events] == [0, 1, 2, 3]
    assert all(abs(e.alpha - w[0]) <= 1e-14 for e, w in zip(apart.events, want))
    together = prob.trace(f0, f1, window=(0.0, 1.0), zero_tol=1e-9)
    assert [(e.node, e.from_class, e.to_class) for e in together.events] == [w[1:] for w in want]
    assert [e.transition for e in together.events] == [0, 0, 1, 1]
    assert all(abs(e.alpha - w[0]) <= 2 * d for e, w in zip(together.events, want))
    for bad in (0.0, -1e-11, 1e-2, float("nan")):
        with pytest.raises(ValueError, match="zero_tol"):
            prob.trace(f0, f1, window=(0.0, 1.0), zero_tol=bad)
