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
from kin.compiled import MEASURE_NAMES, WANT_J, WANT_MANIP, WANT_SIGMA, WANT_T, check_out, make_evaluator
from kin.errors import ConfigurationError, OutBufferError, ParameterError
from kin.robotfile import load_chain
from kin.symbolic import SymbolicChain
from kin.validation import real_array

MAX_RANDOM = 100_000_000  # random_configurations: at most this many rows (0.8·n GB)


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

    @cached_property
    def geometry(self):
        """The collision capsules (:class:`kin.geometry.RobotGeometry`): the chain's own, else the
        default along its DH offsets (:func:`kin.geometry.default_geometry`)."""
        from kin.geometry import default_geometry
        return self.chain.geometry if self.chain.geometry is not None else default_geometry(self.chain)

    @property
    def task_rows(self) -> tuple[int, ...]:
        """Jacobian rows the dexterity measures use (0..5 = x y z rx ry rz)."""
        return self.symbolic.task_rows

    # ---- core evaluation ----------------------------------------------------------------------
    @cached_property
    def _fast(self):
        """The compiled single-configuration functions (``evaluator.single``), or None."""
        return getattr(self.evaluator, "single", None)

    def _params(self, params, N: int) -> np.ndarray:
        if params is None:
            return self.chain.parameter_values
        if isinstance(params, Mapping):
            for k, v in params.items():
                if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
                    raise ParameterError(f"design parameter {k!r} = {v!r} is not a real number")
            return self.chain.parameter_vector(params)
        P = self.chain.parameter_vector(real_array(params, "params", ParameterError))
        if P.ndim == 2 and P.shape[0] != N:
            raise ParameterError(f"parameter batch has {P.shape[0]} rows for {N} configurations")
        if P.ndim > 2:
            raise ParameterError(f"parameter array has shape {P.shape}; expected (n_p,) or (N, n_p)")
        return P

    def _batch(self, q) -> tuple[np.ndarray, bool]:
        return self.chain.as_batch(real_array(q, "q", ConfigurationError))

    def evaluate(self, q, want: int, params=None, out: dict | None = None) -> tuple[dict[str, np.ndarray], bool]:
        """Low-level: evaluate the ``want`` bit-set (see :mod:`kin.compiled`) → (results, single).

        ``out``: arrays to fill, keyed as in :mod:`kin.compiled.evaluator` (batch shapes).
        """
        Q, single = self._batch(q)
        return self.evaluator.evaluate(Q, self._params(params, len(Q)), want, out), single

    def _one(self, q, name: str, want: int):
        """Fast path for one configuration with nominal parameters (``name``: fk, jacobian,
        fk_jacobian, measures); None when it does not apply and the validating batch path must run.

        The compiled library's extension functions take q as it comes (anything but a float64 (n,)
        array of finite values, prismatic ones within ±:data:`kin.chain.MAX_PRISMATIC`, gives None);
        without them, the library's buffers are used through ctypes.
        """
        f = self._fast
        if f is not None:
            p = self.evaluator.p_nominal
            return f.measures(q, p, want) if name == "measures" else getattr(f, name)(q, p)
        ev = self.evaluator
        if not ev.single_call or type(q) is not np.ndarray or q.shape != (self.n,) \
                or q.dtype.kind not in "fiu":
            return None
        with ev.lock:
            if ev.one(q, want):
                self.chain.as_batch(q)  # raises the ConfigurationError naming the joint
            if name == "fk":
                return ev.T1.copy()
            if name == "jacobian":
                return ev.J1.copy()
            if name == "fk_jacobian":
                return ev.T1.copy(), ev.J1.copy()
            return ev.m1.copy()

    def _into(self, q, want: int, params, out: dict, shapes: dict[str, tuple[int, ...]]):
        """Evaluate into the caller's ``out`` arrays; a single configuration's arrays have no batch axis."""
        Q, single = self._batch(q)
        view = {}
        for k, arr in out.items():
            shape = shapes[k] if single else (len(Q), *shapes[k])
            check_out(arr, shape, k)
            view[k] = arr.reshape(1, *shapes[k]) if single else arr
        self.evaluator.evaluate(Q, self._params(params, len(Q)), want, view)

    def fk(self, q, params=None, out: np.ndarray | None = None) -> np.ndarray:
        """Tool pose in the base frame: (4, 4) for q of shape (n,), (N, 4, 4) for a batch.

        ``out``: a float64 C-contiguous array of the result's shape to write into (returned).
        """
        if params is None and out is None and (T := self._one(q, "fk", WANT_T)) is not None:
            return T
        if out is not None:
            self._into(q, WANT_T, params, {"T": out}, {"T": (4, 4)})
            return out
        res, single = self.evaluate(q, WANT_T, params)
        return res["T"][0] if single else res["T"]

    def jacobian(self, q, params=None, out: np.ndarray | None = None) -> np.ndarray:
        """Geometric Jacobian (base frame, tool point; rows vx vy vz wx wy wz): (6, n) or (N, 6, n).

        ``out``: as in :meth:`fk`.
        """
        if params is None and out is None and (J := self._one(q, "jacobian", WANT_J)) is not None:
            return J
        if out is not None:
            self._into(q, WANT_J, params, {"J": out}, {"J": (6, self.n)})
            return out
        res, single = self.evaluate(q, WANT_J, params)
        return res["J"][0] if single else res["J"]

    def fk_jacobian(self, q, params=None, out: tuple[np.ndarray, np.ndarray] | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
        """(T, J) in one evaluation; shapes as :meth:`fk` and :meth:`jacobian`; ``out`` a pair of arrays."""
        if params is None and out is None and (TJ := self._one(q, "fk_jacobian", WANT_T | WANT_J)) is not None:
            return TJ
        if out is not None:
            if not isinstance(out, tuple) or len(out) != 2:
                raise OutBufferError("out must be a pair (T, J) of arrays")
            self._into(q, WANT_T | WANT_J, params, {"T": out[0], "J": out[1]}, {"T": (4, 4), "J": (6, self.n)})
            return out
        res, single = self.evaluate(q, WANT_T | WANT_J, params)
        return (res["T"][0], res["J"][0]) if single else (res["T"], res["J"])

    def position_jacobian(self, q, params=None) -> np.ndarray:
        """The three position rows of :meth:`jacobian`: (3, n) or (N, 3, n)."""
        return self.jacobian(q, params)[..., :3, :]

    def measures(self, q, params=None, out: np.ndarray | None = None) -> Measures:
        """Manipulability, σ_min, condition number and det of the task Jacobian.

        ``out``: a float64 (N, 4) array for a batch (columns in :class:`Measures` order), filled and
        viewed by the returned arrays.
        """
        want = WANT_MANIP | WANT_SIGMA
        if params is None and out is None and (m := self._one(q, "measures", want)) is not None:
            return Measures(*(float(x) for x in m))
        if out is not None:
            self._into(q, want, params, {"measures": out}, {"measures": (4,)})
            return Measures(*(float(x) for x in out)) if out.ndim == 1 else Measures(*out.T)
        res, single = self.evaluate(q, want, params)
        M = res["measures"]
        return Measures(*(float(x) for x in M[0])) if single else Measures(*M.T.copy())

    def _measure(self, q, params, col: int, want: int, out):
        if params is None and out is None and (m := self._one(q, "measures", want)) is not None:
            return float(m[col])
        name = MEASURE_NAMES[col]
        if out is not None:
            self._into(q, want, params, {name: out}, {name: ()})
            return float(out) if out.ndim == 0 else out
        res, single = self.evaluate(q, want, params)
        m = res["measures"][:, col]
        return float(m[0]) if single else m

    def manipulability(self, q, params=None, out: np.ndarray | None = None):
        """Yoshikawa manipulability √det(Jt·Jtᵀ) of the task Jacobian: float or (N,); ``out`` (N,) to fill."""
        return self._measure(q, params, 0, WANT_MANIP, out)

    def sigma_min(self, q, params=None, out: np.ndarray | None = None):
        """Smallest singular value of the task Jacobian: float or (N,); ``out`` (N,) to fill."""
        return self._measure(q, params, 1, WANT_SIGMA, out)

    def condition(self, q, params=None, out: np.ndarray | None = None):
        """Condition number σ_max/σ_min of the task Jacobian (inf when singular): float or (N,)."""
        return self._measure(q, params, 2, WANT_SIGMA, out)

    def det(self, q, params=None, out: np.ndarray | None = None):
        """det of the task Jacobian when it is square (NaN otherwise): float or (N,)."""
        return self._measure(q, params, 3, WANT_MANIP, out)

    # ---- inverse dynamics ------------------------------------------------------------------------
    @cached_property
    def dynamics(self):
        """The Newton–Euler model (:class:`kin.dynamics.rnea.InverseDynamics`, built on first use);
        :class:`~kin.errors.DynamicsError` when no body has inertial data."""
        from kin.dynamics.rnea import InverseDynamics
        return InverseDynamics(self.chain)

    @cached_property
    def dynamics_evaluator(self):
        """The inverse-dynamics evaluator (:mod:`kin.dynamics.evaluator`): compiled on first use (or
        loaded from the cache), CasADi's VM with ``backend="vm"`` or when no compiler works.  Its
        ``single`` (None for the VM) is the lowest-overhead entry for one configuration:
        ``single.tau(q, qd, qdd, p)`` etc. with float64 (n,) arrays and p = ``p_nominal``."""
        from kin.dynamics.evaluator import make_dynamics_evaluator
        return make_dynamics_evaluator(self.dynamics, self.backend_request)

    @cached_property
    def _dyn_one(self):
        """(extension module, nominal parameters) of the compiled single-call path, or None."""
        ev = self.dynamics_evaluator
        return None if ev.single is None else (ev.single, ev.p_nominal)

    def _dyn(self, name: str, arrays: list[tuple[str, object]], params, shape: tuple[int, ...]):
        """Validate q (and q̇, q̈: the same shape as q) and params, evaluate ``name`` in batch."""
        batches = []
        for k, (what, x) in enumerate(arrays):
            Q, single = self.chain.as_batch(real_array(x, what, ConfigurationError), what, bounded=k == 0)
            if k and np.shape(x) != np.shape(arrays[0][1]):
                raise ConfigurationError(f"{what} has shape {np.shape(x)}; it must match q's {np.shape(arrays[0][1])}")
            batches.append(Q)
        ev = self.dynamics_evaluator
        res = ev.evaluate(name, batches, self._params(params, len(batches[0]))).reshape(len(batches[0]), *shape)
        return res[0] if single else res

    # The single-configuration fast lane: the extension checks that every array is exactly a float64
    # (n,) ndarray of finite values (q's prismatic joints within ±MAX_PRISMATIC) and answers None
    # otherwise, so anything else takes the validating path above.
    def inverse_dynamics(self, q, qd, qdd, params=None) -> np.ndarray:
        """Joint torques/forces τ = M(q)q̈ + c(q, q̇) + g(q) + friction (N·m or N): (n,) for one
        configuration, (N, n) for a batch; q̇, q̈ have q's shape.  Coulomb friction uses sign(q̇),
        so τ jumps at q̇ = 0 (:mod:`kin.dynamics.rnea`)."""
        if params is None and (one := self._dyn_one) is not None and (r := one[0].tau(q, qd, qdd, one[1])) is not None:
            return r
        return self._dyn("tau", [("q", q), ("qd", qd), ("qdd", qdd)], params, (self.n,))

    def mass_matrix(self, q, params=None) -> np.ndarray:
        """Joint-space mass matrix M(q), motor inertias included: (n, n) or (N, n, n)."""
        if params is None and (one := self._dyn_one) is not None and (r := one[0].mass_matrix(q, one[1])) is not None:
            return r
        return self._dyn("mass_matrix", [("q", q)], params, (self.n, self.n))

    def gravity(self, q, params=None) -> np.ndarray:
        """Gravity torques/forces g(q) (τ at rest): (n,) or (N, n)."""
        if params is None and (one := self._dyn_one) is not None and (r := one[0].gravity(q, one[1])) is not None:
            return r
        return self._dyn("gravity", [("q", q)], params, (self.n,))

    def coriolis(self, q, qd, params=None) -> np.ndarray:
        """Coriolis and centrifugal torques c(q, q̇) (no friction): (n,) or (N, n)."""
        if params is None and (one := self._dyn_one) is not None and (r := one[0].coriolis(q, qd, one[1])) is not None:
            return r
        return self._dyn("coriolis", [("q", q), ("qd", qd)], params, (self.n,))

    def path_torque_coefficients(self, q, d1, d2, params=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Torque along a path q(s) traversed forwards: τ = A·s̈ + B·ṡ² + C + viscous·q′·ṡ, with q′ = ``d1``,
        q″ = ``d2`` the path derivatives at q (same shape as q).  Returns A, B, C, each (n,) or (N, n):
        A = M·q′, B = M·q″ + c(q, q′), C = g(q) + coulomb·sign(q′) (:mod:`kin.dynamics.rnea`)."""
        res = None
        if params is None and (one := self._dyn_one) is not None:
            res = one[0].path_coefficients(q, d1, d2, one[1])
        if res is None:
            res = self._dyn("path_coefficients", [("q", q), ("d1", d1), ("d2", d2)], params, (self.n, 3))
        return res[..., 0], res[..., 1], res[..., 2]

    # ---- limits -------------------------------------------------------------------------------
    def within_limits(self, q, tol: float = 0.0):
        """True where q is inside the joint limits: bool or (N,) bool."""
        return self.chain.within_limits(real_array(q, "q", ConfigurationError), tol)

    def check_limits(self, q) -> None:
        """Raise :class:`~kin.errors.JointLimitError` naming the first joint out of its limits."""
        self.chain.check_limits(real_array(q, "q", ConfigurationError))

    def random_configurations(self, N: int, seed: int = 0) -> np.ndarray:
        """N configurations uniform within the joint limits, shape (N, n); N in 0..1e8, seed ≥ 0."""
        for name, v, hi in (("N", N, MAX_RANDOM), ("seed", seed, 2**63 - 1)):
            if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or not 0 <= v <= hi:
                raise ConfigurationError(f"random_configurations: {name} = {v!r}; allowed: an integer 0..{hi}")
        rng = np.random.default_rng(seed)
        return rng.uniform(self.chain.lower, self.chain.upper, size=(int(N), self.n))

    # ---- inverse kinematics -------------------------------------------------------------------
    def ik(self, T, seed: int = 0, **options):
        """Inverse kinematics of a target pose (4, 4) or batch (N, 4, 4); see :func:`kin.ik.solve_ik`."""
        from kin.ik import solve_ik
        return solve_ik(self, T, seed=seed, **options)


def load_robot(name_or_path: str | Path, backend: str = "auto") -> Robot:
    """Load a bundled robot by name (``rmt robots`` lists them) or a robot file by path."""
    return Robot(load_chain(name_or_path), backend=backend)
