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
