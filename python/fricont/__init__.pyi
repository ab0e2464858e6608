"""Type hints of the fricont package (see the docstrings in __init__.py)."""

from dataclasses import dataclass
from typing import Any, Callable, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str
CLASSES: Tuple[str, str, str, str]

class Error(Exception): ...
class NotPositiveDefinite(Error, ValueError): ...
class SolveError(Error): ...
class LoadError(Error): ...
class NumericalError(Error): ...
class UsageError(Error): ...
class PrecisionWarning(UserWarning): ...

@dataclass(frozen=True)
class Event:
    index: int
    alpha: float
    node: int
    from_class: str
    to_class: str
    fold: bool
    bifurcation: bool
    lambda_n: npt.NDArray[np.float64]
    lambda_t: npt.NDArray[np.float64]
    transition: int

@dataclass(frozen=True)
class Piece:
    alpha_from: float
    alpha_to: float
    classes: Tuple[str, ...]
    direction: int
    orientation: int
    det_sign: int
    lambda_from: npt.NDArray[np.float64]
    lambda_to: npt.NDArray[np.float64]

@dataclass(frozen=True)
class Solution:
    piece: int
    alpha: float
    u: npt.NDArray[np.float64]
    lambda_n: npt.NDArray[np.float64]
    lambda_t: npt.NDArray[np.float64]
    classes: Tuple[str, ...]
    residual: float
    continuum: bool

class Branch:
    classes: Tuple[str, ...]
    direction: int
    orientation_preserving: bool

class Path:
    events: list[Event]
    pieces: list[Piece]
    end_reason: str
    end_message: Optional[str]
    start_route: str
    branches: list[Branch]
    start_branches: list[Branch]
    @property
    def start(self) -> Optional[dict[str, Any]]: ...
    def resume(
        self, monitor: Optional[Callable[[float, int, Tuple[int, int]], Any]] = None
    ) -> Path: ...
    def choose_branch(
        self, k: int, monitor: Optional[Callable[[float, int, Tuple[int, int]], Any]] = None
    ) -> Path: ...
    def event_state(self, k: int) -> dict[str, Any]: ...
    def solutions_at(self, alpha: float) -> list[Solution]: ...
    def to_dict(self) -> dict[str, Any]: ...

class Problem:
    def __init__(
        self,
        A: Any,
        N: Any,
        T: Any,
        friction: float | Sequence[float] | npt.ArrayLike = 0.3,
        gap: Optional[npt.ArrayLike] = None,
        r: Optional[float] = None,
        storage: str = "full",
        threads: int = 1,
        extended_precision: str = "auto",
    ) -> None: ...
    @property
    def n(self) -> int: ...
    @property
    def p(self) -> int: ...
    @property
    def r(self) -> float: ...
    @property
    def extended_precision(self) -> bool: ...
    @property
    def w_condition_estimate(self) -> float: ...
    def trace(
        self,
        f0: Optional[npt.ArrayLike] = None,
        f1: Optional[npt.ArrayLike] = None,
        window: Sequence[float] = (0.0, 1.0),
        alpha_start: Optional[float] = None,
        max_steps: Optional[int] = None,
        *,
        load: Optional[Callable[[float], npt.ArrayLike]] = None,
        dload: Optional[Callable[[float], npt.ArrayLike]] = None,
        n: Optional[int] = None,
        monitor: Optional[Callable[[float, int, Tuple[int, int]], Any]] = None,
        max_alpha_step: Optional[float] = None,
        guess: Optional[npt.ArrayLike] = None,
        branch: Optional[int] = None,
        basis: Optional[Sequence[npt.ArrayLike]] = None,
        weights: Optional[Callable[[float], Tuple[npt.ArrayLike, npt.ArrayLike]]] = None,
        zero_tol: Optional[float] = None,
    ) -> Path: ...

def read_case(directory: Any) -> dict[str, Any]: ...
