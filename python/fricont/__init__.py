"""fricont: exact path-following of discrete 2D contact problems with Coulomb friction.

Hand over the stiffness ``A`` (n x n, symmetric positive definite), the contact matrices
``N`` and ``T`` (p x n: row i gives the normal and the tangential displacement of contact
node i), friction coefficients and a load path ``f(alpha)``; fricont traces the solution
curve as ``alpha`` varies and reports every transition point, where a contact node changes
between ``"open"`` (no contact), ``"stick"``, ``"slip+"`` and ``"slip-"``.

Conventions (as the C and Rust APIs):

* ``lambda_n <= 0`` is compressive, ``N u <= g`` is non-penetration (``g`` defaults to 0);
* ``"slip+"`` slips with ``T u > 0`` and carries ``lambda_t = F * lambda_n``;
* forces are in the units of ``A u``; ``r`` (the augmentation parameter) is force per
  length and changes nothing in the solutions (default ``2p / trace(W)``);
* node indices are 0-based in Python (the CLI's reports and ``to_dict()`` count from 1,
  as the founding paper does);
* residuals are ``||H||_inf`` relative to the largest magnitude among the terms of the
  equations (a normwise backward error).

Example::

    import numpy as np, scipy.sparse as sp, fricont
    A = sp.diags([2.0, 1.0]).tocsr()           # one node: normal dof 0, tangential dof 1
    N = sp.csr_array([[1.0, 0.0]]); T = sp.csr_array([[0.0, 1.0]])
    prob = fricont.Problem(A, N, T, friction=0.5)
    path = prob.trace(f0=[1.0, 0.0], f1=[0.0, 1.0], window=(0.0, 2.0))
    e = path.events[0]                          # stick -> slip+ at alpha = 0.5
    print(e.alpha, e.node, e.from_class, e.to_class)

Errors: invalid data raise ``ValueError`` with the library's message; numerical failures
raise a subclass of :class:`fricont.Error` (``NotPositiveDefinite`` is also a
``ValueError``).
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass
from typing import Any, Callable, Optional, Sequence, Tuple

import numpy as np
import scipy.sparse as _sp

from . import _core
from ._core import (
    Error,
    LoadError,
    NumericalError,
    SolveError,
    UsageError,
)


class NotPositiveDefinite(_core.NotPositiveDefinite, ValueError):
    """A is not positive definite, or B = [N; T] is rank-deficient."""


class PrecisionWarning(UserWarning):
    """Issued by :class:`Problem` when ``extended_precision="auto"`` left an
    ill-conditioned W in double (its condition estimate above 1e6, its refinement over the
    cost budget): the rounding of W then moves the solutions by about the estimate times
    1.1e-16 relative, and a transition point by that divided by how steeply its guard
    crosses zero, which has no bound (on a mirror-symmetric pair of strips of estimate
    4.9e6 in double, mirrored nodes switched 4.3e-8 apart in alpha, where they switch
    together, and the path took pieces the refined one does not). Pass
    ``extended_precision="on"`` to refine W (a longer set-up), or ``"off"`` to say that
    double is meant (no warning)."""


__all__ = [
    "Problem",
    "Path",
    "Event",
    "Piece",
    "Solution",
    "Branch",
    "read_case",
    "Error",
    "NotPositiveDefinite",
    "PrecisionWarning",
    "SolveError",
    "LoadError",
    "NumericalError",
    "UsageError",
    "__version__",
]

__version__ = _core.version()

CLASSES = ("open", "stick", "slip+", "slip-")


def _reraise(err: BaseException) -> BaseException:
    """The library's NotPositiveDefinite as the Python-level class (also a ValueError)."""
    if isinstance(err, _core.NotPositiveDefinite) and not isinstance(err, NotPositiveDefinite):
        new = NotPositiveDefinite(*err.args)
        new.__cause__ = None
        return new
    return err


def _float64(name: str, v: Any) -> np.ndarray:
    """``v`` as float64; ValueError for complex values with a nonzero imaginary part (numpy
    would drop it with a warning only), the real part of complex values without one."""
    a = np.asarray(v)
    if np.iscomplexobj(a):
        if np.any(a.imag != 0):
            raise ValueError(
                f"{name}: complex values with a nonzero imaginary part; expected real numbers"
            )
        a = a.real
    return np.asarray(a, dtype=np.float64)


def _csr(name: str, m: Any, shape: Optional[Tuple[int, int]] = None):
    """(shape, indptr int64, indices int64, data float64) of any scipy.sparse matrix or
    array (CSR, CSC, COO, ...; int32 or int64 indices) or dense array-like."""
    if _sp.issparse(m):
        c = _sp.csr_array(m)
    else:
        d = _float64(name, m)
        if d.ndim != 2:
            raise ValueError(f"{name}: expected a 2-D matrix, got an array of shape {d.shape}")
        c = _sp.csr_array(d)
    if c.has_canonical_format is False:
        c = c.copy()
        c.sum_duplicates()
    return (
        (int(c.shape[0]), int(c.shape[1])),
        np.ascontiguousarray(c.indptr, dtype=np.int64),
        np.ascontiguousarray(c.indices, dtype=np.int64),
        np.ascontiguousarray(_float64(name, c.data)),
    )


def _is_int(x: Any) -> bool:
    """Whether ``x`` is an integer (Python or NumPy), and not a bool."""
    return isinstance(x, (int, np.integer)) and not isinstance(x, bool)


def _vector(name: str, v: Any) -> np.ndarray:
    """``v`` as a contiguous 1-D float64 array. A row or column (shape ``(1, n)``, ``(n, 1)``)
    is taken as the vector it is; an array with two or more axes longer than one (a
    ``(nodes, 2)`` table of nodal values, say) is a ValueError: which order its entries take
    in the dofs of A is the caller's to say (``.ravel()`` it in that order)."""
    a = _float64(name, v)
    if sum(1 for d in a.shape if d != 1) > 1:
        raise ValueError(
            f"{name}: expected a vector, got an array of shape {a.shape}; flatten it in the "
            "order of the dofs of A (e.g. .ravel()) if that is what it holds"
        )
    return np.ascontiguousarray(a.ravel())


@dataclass(frozen=True)
class Event:
    """One node changing class at a transition point.

    Attributes: ``alpha`` (the load parameter), ``node`` (0-based contact node),
    ``from_class`` and ``to_class`` (``"open"``, ``"stick"``, ``"slip+"``, ``"slip-"``),
    ``fold`` (alpha turns back here), ``bifurcation`` (more than one neighbouring piece
    continues here), ``lambda_n`` and ``lambda_t`` (all p contact forces at the point,
    force units, ``lambda_n <= 0`` compressive), ``transition`` (0-based transition point,
    shared by the events of a degenerate transition), ``index`` (0-based position in
    ``path.events``).
    """

    index: int
    alpha: float
    node: int
    from_class: str
    to_class: str
    fold: bool
    bifurcation: bool
    lambda_n: np.ndarray
    lambda_t: np.ndarray
    transition: int


@dataclass(frozen=True)
class Piece:
    """A traced smooth piece: the class of every node, the alpha range, the contact forces
    at its ends (``lambda_from``, ``lambda_to``: 2p values, normal then tangential),
    ``direction`` (sign of d alpha / ds, 0 for a vertical piece), the path's
    ``orientation`` and ``det_sign`` (sign of det dH/d lambda)."""

    alpha_from: float
    alpha_to: float
    classes: Tuple[str, ...]
    direction: int
    orientation: int
    det_sign: int
    lambda_from: np.ndarray
    lambda_to: np.ndarray


@dataclass(frozen=True)
class Solution:
    """A solution at a given alpha: ``piece`` (index in ``path.pieces``), the state
    (``u``, ``lambda_n``, ``lambda_t``, ``classes``, ``residual``) and ``continuum`` (the
    piece is vertical at this alpha: every point between its end forces is a solution)."""

    piece: int
    alpha: float
    u: np.ndarray
    lambda_n: np.ndarray
    lambda_t: np.ndarray
    classes: Tuple[str, ...]
    residual: float
    continuum: bool


@dataclass(frozen=True)
class Branch:
    """A piece that continues the path at a bifurcation (or leaves its start point):
    ``classes`` (the class of every node on it), ``direction`` (sign of d alpha / ds
    along it, 0 for a vertical piece) and ``orientation_preserving`` (it keeps the path's
    orientation, SPEC section 4: past a bifurcation the path takes the one branch that
    does, and stops with ``end_reason == "bifurcation"`` when none or several do)."""

    classes: Tuple[str, ...]
    direction: int
    orientation_preserving: bool


class Path:
    """A traced path. Returned by :meth:`Problem.trace`; not created directly.

    ``events``, ``pieces`` and ``end_reason`` describe what was traced; ``event_state(k)``
    gives the full state at event k (one back-solve for u), ``solutions_at(alpha)`` every
    traced solution at alpha, ``to_dict()`` the JSON report of the CLI (1-based numbers),
    ``resume()`` continues a path that its monitor stopped, ``branches`` and
    ``choose_branch(k)`` continue a path along another branch of a bifurcation.
    """

    def __init__(self, core: Any):
        self._core = core
        self._refresh()

    def _refresh(self) -> None:
        """Reads what the core path holds now."""
        core = self._core
        self.events: list = [
            Event(i, a, node, fc, tc, fold, bif, ln, lt, tr)
            for i, (a, node, fc, tc, fold, bif, ln, lt, tr) in enumerate(core.events())
        ]
        self.pieces: list = [
            Piece(
                d["alpha_from"],
                d["alpha_to"],
                tuple(d["classes"]),
                d["direction"],
                d["orientation"],
                d["det_sign"],
                d["lambda_from"],
                d["lambda_to"],
            )
            for d in core.pieces()
        ]
        reason, message = core.end_reason()
        #: Why the path ended: "window", "max_steps", "closed_loop", "bifurcation",
        #: "failed", "stopped" (by the monitor: :meth:`resume` continues), or "none" when
        #: it never started (the start solve failed).
        self.end_reason: str = reason if reason is not None else "none"
        #: The failure message when ``end_reason == "failed"``.
        self.end_message: Optional[str] = message
        #: How the start point was reached: "solved" (the fixed-alpha solver at the
        #: start's alpha), or where it failed, "zero_load" (the path of the load
        #: tau f(alpha) from tau = 0), "open" (the path from a load that holds every node
        #: open) or, where those failed too, "nearby" (a path traced from a nearby alpha);
        #: "none" when the path never started. Every route ends in the same check of the
        #: start point.
        self.start_route: str = core.start_route() or "none"
        #: The candidate continuations (:class:`Branch`) at the last transition point,
        #: 0-based as ``choose_branch`` takes them: empty unless it was a bifurcation
        #: and the path has not moved on since (where it stopped there: ``end_reason ==
        #: "bifurcation"``).
        self.branches: list = [Branch(tuple(c), d, o) for c, d, o in core.branches()]
        #: The pieces that left the start point toward ``window[1]`` when more than one
        #: did (a bifurcation at the start: the path took the first, or the one given
        #: as ``branch=`` to :meth:`Problem.trace`); empty otherwise.
        self.start_branches: list = [
            Branch(tuple(c), d, o) for c, d, o in core.start_branches()
        ]

    @property
    def start(self) -> Optional[dict]:
        """The start point: ``alpha``, ``lambda_n``, ``lambda_t``, ``classes``,
        ``residual`` (no u); None when the path never started. Its residual costs one
        back-solve, done on each access (keep the dict rather than asking again).

        Raises: :class:`NumericalError` when that solve fails (u overflows)."""
        return self._core.start_state()

    def __repr__(self) -> str:
        return f"<fricont.Path: {len(self.events)} events, end {self.end_reason!r}>"

    def resume(self, monitor: Optional[Callable[[float, int, Tuple[int, int]], Any]] = None) -> "Path":
        """Continues a path that its monitor stopped (``end_reason == "stopped"``) from
        where it stopped, until it ends again, and returns it (``events``, ``pieces``,
        ``end_reason`` updated; the events equal those of a run that was never stopped).
        ``monitor`` is called as in :meth:`Problem.trace` (the one given there is not kept:
        pass it again to keep monitoring); the GIL is released meanwhile. A path that ended
        for another reason is left as it is.

        Raises: as :meth:`Problem.trace` (the exception carries this path as ``err.path``);
        :class:`UsageError` when called from inside the path's own monitor.
        """
        self._core.resume(monitor)
        self._refresh()
        _raise_pending(self)
        return self

    def choose_branch(
        self, k: int, monitor: Optional[Callable[[float, int, Tuple[int, int]], Any]] = None
    ) -> "Path":
        """Continues along ``branches[k]`` (0-based) instead of the branch the path took, or
        after it stopped with ``end_reason == "bifurcation"``, and runs it on until it ends
        again (as :meth:`resume`); returns the path. Only directly after the bifurcation
        (``branches`` is not empty: the path stopped there). The chosen branch's events
        follow those traced up to the bifurcation.

        Raises: :class:`UsageError` when no bifurcation is pending (``branches`` is empty)
        or ``k`` is out of range, with this path as ``err.path``; otherwise as
        :meth:`resume`.
        """
        if not _is_int(k) or k < 0:
            raise ValueError(f"k = {k!r}: expected a branch index, an integer >= 0")
        self._core.choose_branch(int(k), monitor)
        self._refresh()
        _raise_pending(self)
        return self

    def event_state(self, k: int) -> dict:
        """The full state at event k (0-based): ``u`` (n), ``lambda_n``, ``lambda_t`` (p),
        ``classes`` (after the event), ``residual``, ``alpha``. One back-solve with the
        Cholesky factor of A; the GIL is released meanwhile. A negative k counts from the
        last event, as a list index does (``-1``: the last). Errors: ValueError when k is not
        an integer; :class:`UsageError` for k out of range."""
        if not _is_int(k):
            raise ValueError(f"k = {k!r}: expected an event index, an integer")
        # A negative k counts from the end of `self.events`; the library checks the range
        # (and refuses a call from inside the path's own monitor, where `self.events` is
        # not yet refreshed).
        i = int(k)
        if i < 0:
            i += len(self.events)
            if i < 0:
                raise UsageError(f"event {int(k)} does not exist ({len(self.events)} events)")
        try:
            return self._core.event_state(i)
        except Exception as err:  # noqa: BLE001
            raise _reraise(err) from None

    def solutions_at(self, alpha: float) -> list:
        """Every traced solution at ``alpha`` (several past a fold), as :class:`Solution`
        objects: one small solve on each stored piece whose alpha range contains it
        (under a nonlinear load refined in double-double where ``extended_precision`` is
        on, as the traced points are), plus a back-solve for u. Empty where the traced path never reached ``alpha``;
        ``ValueError`` when ``alpha`` is not finite."""
        out = []
        for piece, st, continuum in self._core.solutions_at(float(alpha)):
            out.append(
                Solution(
                    piece,
                    st["alpha"],
                    st["u"],
                    st["lambda_n"],
                    st["lambda_t"],
                    tuple(st["classes"]),
                    st["residual"],
                    continuum,
                )
            )
        return out

    def to_dict(self) -> dict:
        """The path in the JSON shape of ``fricont trace --json`` (SPEC §8: nodes, events
        and transition points counted from 1)."""
        return json.loads(self._core.to_json())


class Problem:
    """A contact problem, factorised once (sparse Cholesky of A, Delassus operator
    W = B A^-1 B^T with B = [N; T]); the GIL is released meanwhile.

    Parameters
    ----------
    A : scipy.sparse matrix/array (CSR, CSC, COO, ...; int32 or int64 indices) or dense
        array, n x n symmetric positive definite (Dirichlet dofs eliminated).
    N, T : the same kinds, p x n: normal and tangential displacement of each contact node.
    friction : float or length-p array, F >= 0.
    gap : length-p array or None: initial normal gap g (N u <= g), default 0.
    r : float or None: augmentation parameter (force per length), default 2p / trace(W).
    storage : "full" (symmetry checked to 1e-10 relative), "lower" or "upper" (only that
        triangle of A is read).
    threads : int, 1 to 1024 (default 1: no thread is started): the threads of the
        set-up and, where 2p >= 2048, of the trace's dense passes (LU factorisations,
        solves, products with W), each on a private pool stopped when the call ends. The
        load and monitor callables still run on the calling thread. Results agree with
        one thread's to rounding.
    extended_precision : "auto" (default), "on" or "off": whether W and the condensed
        loads are carried beyond double precision (mixed-precision refinement with the
        Cholesky factor of A; slender bodies, whose W is ill-conditioned). "auto" refines
        where that is cheap (small problems), or where W's condition estimate exceeds 1e6
        and the refinement costs at most about max(20 x the factorisation, 1e11
        operations), or whatever it costs where the estimate exceeds 1e8; see the
        properties ``extended_precision`` and ``w_condition_estimate`` for what was chosen.
        Where "auto" leaves W in double with an estimate above 1e6 (the refinement over its
        budget), a :class:`PrecisionWarning` says so.

    Duplicate entries (a COO matrix, or a CSR matrix without canonical format) are summed,
    as by every fricont interface (C, C++, Fortran, the CLI's Matrix Market files).

    Raises ValueError (invalid data: dimensions, NaN/Inf, complex values with a nonzero
    imaginary part, not symmetric, F < 0, r <= 0, threads outside 1..1024,
    extended_precision not one of the three) and
    NotPositiveDefinite (A not SPD, with the failing pivot; B rank-deficient).
    """

    def __init__(self, A, N, T, friction=0.3, gap=None, r=None, storage="full", threads=1,
                 extended_precision="auto"):
        a = _csr("A", A)
        n = _csr("N", N)
        t = _csr("T", T)
        p = n[0][0]
        fr = _vector("friction", friction)
        if fr.size == 1:
            fr_list = [float(fr[0])]
        else:
            fr_list = [float(x) for x in fr]
            if len(fr_list) != p:
                raise ValueError(f"friction has {len(fr_list)} values, expected 1 or p = {p}")
        g = None if gap is None else [float(x) for x in _vector("gap", gap)]
        try:
            if not _is_int(threads) or threads < 1:
                raise ValueError(f"threads = {threads!r}: expected an integer in 1..1024")
            self._core = _core.Problem(
                a, n, t, fr_list, g, None if r is None else float(r), storage, int(threads),
                str(extended_precision),
            )
        except Exception as err:  # noqa: BLE001
            raise _reraise(err) from None
        kappa = self._core.w_condition_estimate
        if (
            str(extended_precision) == "auto"
            and not self._core.extended_precision
            and kappa > _core.AUTO_CONDITION
        ):
            warnings.warn(
                PrecisionWarning(
                    f"W is ill-conditioned (condition estimate {kappa:.1e}) and auto left it in "
                    f"double (its refinement would cost more than the budget): its rounding "
                    f"moves the solutions by about {kappa * 1.1e-16:.0e} relative, and a "
                    "transition point by that divided by how steeply its guard crosses zero; "
                    'extended_precision="on" refines W, "off" means double (no warning)'
                ),
                stacklevel=2,
            )

    @property
    def n(self) -> int:
        """Number of dofs."""
        return self._core.n

    @property
    def p(self) -> int:
        """Number of contact nodes."""
        return self._core.p

    @property
    def r(self) -> float:
        """The augmentation parameter in use (force per length)."""
        return self._core.r

    @property
    def extended_precision(self) -> bool:
        """Whether W and the condensed loads are carried beyond double precision.

        As the constructor's ``extended_precision`` says: "on" always, "off" never,
        "auto" (the default) small problems always, and problems whose W is
        ill-conditioned (``w_condition_estimate`` above 1e6) where the refinement costs at
        most max(20 times the factorisation of A, 1e11) operations, or whatever it costs
        where the estimate exceeds 1e8. When False, the rounding of W moves the solutions by
        about ``w_condition_estimate`` * 1.1e-16 relative, and a transition point by that
        divided by how steeply its guard crosses zero (measured: up to 610 times that in
        alpha, relative to max(1, abs(alpha)), on a slender strip of estimate 6.4e10).
        """
        return self._core.extended_precision

    @property
    def w_condition_estimate(self) -> float:
        """Estimate of the 2-norm condition number of the equilibrated W (dimensionless,
        usually a lower bound; W's rows are equilibrated by powers of two)."""
        return self._core.w_condition_estimate

    def trace(
        self,
        f0=None,
        f1=None,
        window: Sequence[float] = (0.0, 1.0),
        alpha_start: Optional[float] = None,
        max_steps: Optional[int] = None,
        *,
        load: Optional[Callable[[float], Any]] = None,
        dload: Optional[Callable[[float], Any]] = None,
        n: Optional[int] = None,
        monitor: Optional[Callable[[float, int, Tuple[int, int]], Any]] = None,
        max_alpha_step: Optional[float] = None,
        guess=None,
        branch: Optional[int] = None,
        basis=None,
        weights: Optional[Callable[[float], Any]] = None,
        zero_tol: Optional[float] = None,
    ) -> Path:
        """Traces the solution path over ``window = (alpha_start, alpha_end)``.

        Affine load: ``f(alpha) = f0 + alpha * f1`` (length-n arrays, force units).
        General load: ``load(alpha)`` returns f (length n), ``dload(alpha)`` its derivative
        (central differences when None); ``n`` defaults to the problem's n. Each evaluation
        costs a solve with the current piece's matrix, O(p^2), and condenses f and f' to
        the contact rows: by a solve with A until the evaluations have spanned the load's
        directions (up to 8; a vector within 64 eps of their span is then condensed as a
        combination of those solves, O(k n)).
        Its accuracy: fricont does not see the terms that make up f, so where the load
        passes through (near) zero it takes them as large as the load's change since the
        last transition point (or the start; at most over the window): where the load at a
        transition is far smaller than that (``1e-8 * f0 + phi(alpha) * f1`` just after a
        start at alpha = 1), nearby transitions can be merged or moved without an error. A
        basis load has exact terms: give the load so where it is a sum of fixed vectors.
        On an ill-conditioned body the rounding of each entry of f (eps * |f|, fresh at
        every alpha) moves the solution by up to the piece's conditioning times that, also
        in extended precision: transitions are located to that noise (slender strips with
        F = 5, kappa(W) ~ 1e8: f0 + phi(alpha) f1 as a general load put its events within
        7.4e-13 in phi of the affine load's); a basis load has no such noise.
        Basis load: ``f(alpha) = sum_j phi_j(alpha) basis[j]``, ``basis`` k vectors of
        length n, ``weights(alpha)`` returns ``(phi, dphi)``, the k weights and their
        derivatives. Each vector is condensed once, so an evaluation costs O(k p) instead
        of a piece solve: the way to trace an oscillating or otherwise nonlinear load on
        a large mesh (on a 308,160-dof mesh with p = 480, an oscillating load with 511
        events traced in 0.5 s as a basis load and in 17 s as a general one, same events).

        ``alpha_start`` (default ``window[0]``) is where the fixed-alpha solve starts the
        path; it then goes toward ``window[1]``, through folds, until alpha leaves the
        window. Where W is carried in extended precision, a stage of that solve that
        stalls has its last iterate solved again on its piece in double-double until the
        classes settle. Where that solve fails at ``alpha_start`` (every stage but its long
        Gauss-Seidel run and restarts, which come after the rays), the start is the point at
        tau = 1 of the path of the load tau f(alpha_start) from zero load (tau = 0), or
        where that path cannot leave tau = 0 (every gap zero), from a load that holds every
        node open; where neither gets there, it solves at a nearby alpha (1e-3, 1e-2, 1e-1
        of the window's length away, or of a thousand times the load's own alpha scale
        ||q|| / ||q'|| where that is shorter; inside the window) and the path from there is
        traced back to ``alpha_start``: the point it reaches is the start (SolveError only
        where none leads there). ``path.start_route`` says which of these it was.
        ``max_steps`` bounds the number of transition points (default 10 000).

        ``guess`` (None or 2p values: lambda_n of the p nodes, then lambda_t; force units,
        lambda_n <= 0 compressive) is where the fixed-alpha solve starts instead of zero
        forces. The contact problem at one alpha can have several solutions (large
        friction, a path that folds back over ``alpha_start``); the solve returns one of
        them, and which one can depend on rounding. A guess that solves the problem (to
        1e-12 relative) is kept: the path starts from that solution. Pass a known one
        (``path.start``'s forces, an event's, a :meth:`Path.solutions_at` state's) to
        trace from it. When several
        pieces leave the start point toward ``window[1]`` (``path.start_branches``), the
        path takes the first, or ``branch`` (0-based) when given.

        ``monitor(alpha, transitions, (first_event, end_event))`` is called after each
        transition point with its alpha, the number of transition points so far and the
        range of the new events (0-based indices into ``path.events``). A true return
        value stops the path cleanly: ``end_reason == "stopped"`` (also in ``to_dict()``),
        everything traced is kept, and :meth:`Path.resume` continues from there.

        ``max_alpha_step`` (alpha units; default 1/8 of the window) bounds the steps of the
        step control of a general load: a feature of ``load`` narrower than the steps (a
        bump, a fast oscillation) can be stepped over unseen, a step no longer than the
        narrowest feature cannot miss it. No effect on an affine load (its pieces are
        followed exactly). ValueError when it is not finite or <= 0.

        ``zero_tol`` (default 1e-11, in (0, 1e-3]): the relative tolerance for "a guard is
        at zero" and "two nodes switch at once", relative to the local scales of each point
        (the contact forces there, the terms of a displacement's own row), never to the
        window. ValueError outside that range. A friction coefficient so small that F times
        a node's normal force is within it is not resolved: where such a node's slip
        reverses while pressed, the path stops with an :class:`Error` that names the node
        (give it F = 0, or a smaller ``zero_tol``: F = 1e-10 traces with 1e-12).

        The GIL is released while tracing (re-acquired only to call ``load``, ``dload`` or
        ``monitor``), so threads can trace different problems at once.

        Raises: ValueError for bad arguments (more than one load or none, ``guess`` not 2p
        finite values, ``weights`` returning other than two length-k arrays, ``branch``
        negative); UsageError when ``branch`` is not below the number of pieces leaving the
        start point (``len(start_branches)``, or 1 when it lists none; the message says
        how many; the path, started on the first, is ``err.path``);
        SolveError when the start solve fails; an
        exception raised inside ``load``/``dload``/``weights``/``monitor`` stops the path
        and is re-raised with what was traced kept on it as ``err.path`` (a :class:`Path`;
        after
        an exception of ``monitor`` it is stopped, ``end_reason == "stopped"``, and can be
        resumed); other numerical failures raise NumericalError, also with ``err.path``.
        """
        if len(window) != 2:
            raise ValueError("window must be (alpha_start, alpha_end)")
        win = (float(window[0]), float(window[1]))
        a0 = None if alpha_start is None else float(alpha_start)
        ms = None if max_steps is None else int(max_steps)
        h = None if max_alpha_step is None else float(max_alpha_step)
        zt = None if zero_tol is None else float(zero_tol)
        opts = (win, a0, ms, h, zt)
        g = None if guess is None else _vector("guess", guess)
        if branch is not None and (not _is_int(branch) or branch < 0):
            raise ValueError(f"branch = {branch!r}: expected None or an integer >= 0")
        b = None if branch is None else int(branch)
        if basis is not None or weights is not None:
            if f0 is not None or f1 is not None or load is not None:
                raise ValueError("give one load: f0 and f1, load=, or basis= with weights=")
            if basis is None or weights is None or not callable(weights):
                raise ValueError("a basis load needs basis= (the vectors f_j) and a callable weights=")
            vectors = [_vector(f"basis[{j}]", v) for j, v in enumerate(basis)]

            def pair(a):
                r = weights(a)
                if not isinstance(r, (tuple, list)) or len(r) != 2:
                    raise ValueError("weights(alpha) must return a pair (phi, dphi)")
                return _vector("weights phi", r[0]), _vector("weights dphi", r[1])

            try:
                core = self._core.trace_basis(vectors, pair, opts, monitor, g, b)
            except Exception as err:  # noqa: BLE001
                raise _reraise(err) from None
        elif load is not None:
            if f0 is not None or f1 is not None:
                raise ValueError("give either f0 and f1 (affine load) or load=, not both")
            # (the returned vectors through _vector: a complex f is an error, not its real
            # part with a warning)
            def real(fn, name):
                return None if fn is None else (lambda a: _vector(name, fn(a)))

            core = self._core.trace_general(
                real(load, "load"),
                real(dload, "dload"),
                int(n) if n is not None else self.n,
                opts,
                monitor,
                g,
                b,
            )
        else:
            if f0 is None or f1 is None:
                raise ValueError("an affine load needs f0 and f1 (or give load=)")
            try:
                core = self._core.trace_affine(
                    _vector("f0", f0), _vector("f1", f1), opts, monitor, g, b
                )
            except Exception as err:  # noqa: BLE001
                raise _reraise(err) from None
        path = Path(core)
        _raise_pending(path)
        return path


def _raise_pending(path: Path) -> None:
    """Raises the exception that ended the last run of ``path``, if any, with the path
    attached as ``err.path``."""
    err = path._core.take_error()
    if err is not None:
        err = _reraise(err)
        try:
            err.path = path
        except AttributeError:
            pass
        raise err


def read_case(directory) -> dict:
    """Reads a problem directory in the exchange format (``docs/exchange-format.md``):
    returns a dict with ``A`` (scipy.sparse CSR array, full storage), ``N``, ``T`` (CSR,
    p x n), ``f0``, ``f1`` (numpy, n), ``gap`` (numpy p, or None), ``friction`` (float or
    numpy p), ``alpha_start``, ``alpha_end`` and ``meta`` (the whole meta.json as a dict).

    Raises OSError naming the file and line for unreadable or malformed files, ValueError
    when the files disagree (dimensions, NaN/Inf).
    """
    d = _core.read_case(str(directory))

    def mat(t):
        shape, indptr, indices, data = t
        return _sp.csr_array((data, indices, indptr), shape=shape)

    fr = d["friction"]
    return {
        "A": mat(d["A"]),
        "N": mat(d["N"]),
        "T": mat(d["T"]),
        "f0": d["f0"],
        "f1": d["f1"],
        "gap": d["gap"],
        "friction": float(fr[0]) if len(fr) == 1 else fr,
        "alpha_start": d["alpha_start"],
        "alpha_end": d["alpha_end"],
        "meta": json.loads(d["meta"]),
    }
