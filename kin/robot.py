"""`Robot`: a chain plus its symbolic model and fast evaluators — the main entry point of ``kin``.

Every method takes one configuration q (n,) or a batch (N, n), SI units (rad, m), and answers
with the matching shape.  ``params`` overrides design parameters (a mapping name → SI value, a
vector (n_p,), or one vector per configuration (N, n_p)); ``None`` uses their nominal values.
"""
from __future__ import annotations

from functools import cached_property
from pathlib import Path
from typing import Mapping, NamedTuple

import numpy as np

from kin.chain import Chain
from kin.compiled import WANT_J, WANT_MANIP, WANT_SIGMA, WANT_T, CompiledEvaluator, make_evaluator
from kin.errors import ParameterError
from kin.robotfile import load_chain
from kin.symbolic import SymbolicChain


class Measures(NamedTuple):
    """Dexterity of the task Jacobian; each a float or an (N,) array."""

    manipulability: np.ndarray | float   # √det(Jt·Jtᵀ)
    sigma_min: np.ndarray | float        # smallest singular value
    condition: np.ndarray | float        # σ_max / σ_min (inf at a singularity)
    det: np.ndarray | float              # det Jt, NaN when Jt is not square


class Robot:
    """A chain with its CasADi model and evaluators.

    ``backend``: ``"auto"`` (compiled C, cached; CasADi VM when no compiler works), ``"compiled"``
    or ``"vm"``.  Compilation happens on first use, not at construction.
    """

    def __init__(self, chain: Chain, backend: str = "auto"):
        self.chain = chain
        self.backend_request = backend

    def __repr__(self) -> str:
        return f"Robot({self.chain.name!r}, n={self.n}, {self.chain.convention} DH)"

    @property
    def name(self) -> str:
        return self.chain.name

    @property
    def n(self) -> int:
        return self.chain.n

    @cached_property
    def symbolic(self) -> SymbolicChain:
        """The CasADi model (built on first use)."""
        return SymbolicChain(self.chain)

    @cached_property
    def evaluator(self):
        """The fast evaluator (compiled on first use, or loaded from the cache)."""
        return make_evaluator(self.symbolic, self.backend_request)

    @property
    def backend(self) -> str:
        """``"compiled"`` or ``"vm"``: what actually evaluates."""
        return self.evaluator.backend

    @property
    def task_rows(self) -> tuple[int, ...]:
        """Jacobian rows the dexterity measures use (0..5 = x y z rx ry rz)."""
        return self.symbolic.task_rows

    # ---- core evaluation ----------------------------------------------------------------------
    def _params(self, params, N: int) -> np.ndarray:
        if params is None:
            return self.chain.parameter_values
        if isinstance(params, Mapping):
            return self.chain.parameter_vector(params)
        P = self.chain.parameter_vector(params)
        if P.ndim == 2 and P.shape[0] != N:
            raise ParameterError(f"parameter batch has {P.shape[0]} rows for {N} configurations")
        if P.ndim > 2:
            raise ParameterError(f"parameter array has shape {P.shape}; expected (n_p,) or (N, n_p)")
        return P

    def evaluate(self, q, want: int, params=None) -> tuple[dict[str, np.ndarray], bool]:
        """Low-level: evaluate the ``want`` bit-set (see :mod:`kin.compiled`) → (results, single)."""
        Q, single = self.chain.as_batch(q)
        return self.evaluator.evaluate(Q, self._params(params, len(Q)), want), single

    def _single(self, q, want: int, outputs: str):
        """Fast path for one configuration with nominal parameters; None when it does not apply."""
        ev = self.evaluator
        if type(ev) is not CompiledEvaluator:
            return None
        arr = np.asarray(q, dtype=float)
        if arr.shape != (self.n,):
            return None
        with ev.lock:
            if ev.one(arr, want):
                self.chain.as_batch(arr)  # raises the ConfigurationError naming the joint
            if outputs == "T":
                return ev.T1.copy()
            if outputs == "J":
                return ev.J1.copy()
            if outputs == "TJ":
                return ev.T1.copy(), ev.J1.copy()
            return ev.m1.copy()

    def fk(self, q, params=None) -> np.ndarray:
        """Tool pose in the base frame: (4, 4) for q of shape (n,), (N, 4, 4) for a batch."""
        if params is None and (out := self._single(q, WANT_T, "T")) is not None:
            return out
        res, single = self.evaluate(q, WANT_T, params)
        return res["T"][0] if single else res["T"]

    def jacobian(self, q, params=None) -> np.ndarray:
        """Geometric Jacobian (base frame, tool point; rows vx vy vz wx wy wz): (6, n) or (N, 6, n)."""
        if params is None and (out := self._single(q, WANT_J, "J")) is not None:
            return out
        res, single = self.evaluate(q, WANT_J, params)
        return res["J"][0] if single else res["J"]

    def fk_jacobian(self, q, params=None) -> tuple[np.ndarray, np.ndarray]:
        """(T, J) in one evaluation; shapes as :meth:`fk` and :meth:`jacobian`."""
        if params is None and (out := self._single(q, WANT_T | WANT_J, "TJ")) is not None:
            return out
        res, single = self.evaluate(q, WANT_T | WANT_J, params)
        return (res["T"][0], res["J"][0]) if single else (res["T"], res["J"])

    def position_jacobian(self, q, params=None) -> np.ndarray:
        """The three position rows of :meth:`jacobian`: (3, n) or (N, 3, n)."""
        return self.jacobian(q, params)[..., :3, :]

    def measures(self, q, params=None) -> Measures:
        """Manipulability, σ_min, condition number and det of the task Jacobian."""
        if params is None and (m := self._single(q, WANT_MANIP | WANT_SIGMA, "m")) is not None:
            return Measures(*(float(x) for x in m))
        res, single = self.evaluate(q, WANT_MANIP | WANT_SIGMA, params)
        M = res["measures"]
        return Measures(*(float(x) for x in M[0])) if single else Measures(*M.T.copy())

    def _measure(self, q, params, col: int, want: int):
        if params is None and (m := self._single(q, want, "m")) is not None:
            return float(m[col])
        res, single = self.evaluate(q, want, params)
        m = res["measures"][:, col]
        return float(m[0]) if single else m

    def manipulability(self, q, params=None):
        """Yoshikawa manipulability √det(Jt·Jtᵀ) of the task Jacobian: float or (N,)."""
        return self._measure(q, params, 0, WANT_MANIP)

    def sigma_min(self, q, params=None):
        """Smallest singular value of the task Jacobian: float or (N,)."""
        return self._measure(q, params, 1, WANT_SIGMA)

    def condition(self, q, params=None):
        """Condition number σ_max/σ_min of the task Jacobian (inf when singular): float or (N,)."""
        return self._measure(q, params, 2, WANT_SIGMA)

    def det(self, q, params=None):
        """det of the task Jacobian when it is square (NaN otherwise): float or (N,)."""
        return self._measure(q, params, 3, WANT_MANIP)

    # ---- limits -------------------------------------------------------------------------------
    def within_limits(self, q, tol: float = 0.0):
        """True where q is inside the joint limits: bool or (N,) bool."""
        return self.chain.within_limits(q, tol)

    def check_limits(self, q) -> None:
        """Raise :class:`~kin.errors.JointLimitError` naming the first joint out of its limits."""
        self.chain.check_limits(q)

    def random_configurations(self, N: int, seed: int = 0) -> np.ndarray:
        """N configurations uniform within the joint limits, shape (N, n)."""
        rng = np.random.default_rng(seed)
        return rng.uniform(self.chain.lower, self.chain.upper, size=(N, self.n))

    # ---- inverse kinematics -------------------------------------------------------------------
    def ik(self, T, seed: int = 0, **options):
        """Inverse kinematics of a target pose (4, 4) or batch (N, 4, 4); see :func:`kin.ik.solve_ik`."""
        from kin.ik import solve_ik
        return solve_ik(self, T, seed=seed, **options)


def load_robot(name_or_path: str | Path, backend: str = "auto") -> Robot:
    """Load a bundled robot by name (``rmt robots`` lists them) or a robot file by path."""
    return Robot(load_chain(name_or_path), backend=backend)
