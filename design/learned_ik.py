"""Learned inverse kinematics and the singularity thesis's error windows, made exact and reproducible.

The thesis trained a small neural network for inverse kinematics (one hidden layer of 55 tanh
units; inputs the 9 rotation entries and the 3 position entries of the tool pose, outputs the joint
values), evaluated it on poses where the arm is singular and called

    q_singular ± max |q_predicted − q_true|

the singular joint's *error window*.  It hard-coded the singular value and gave no seed; its SCARA
window was θ2 ∈ [−0.01, 0.01] rad (ROBOTS.md §2).  Here:

* the singular values come from :func:`kin.singularity.analyse_singularities` (every factor of
  det J, not one chosen by hand);
* the network (:class:`LearnedIK`, scikit-learn's ``MLPRegressor`` with standardised inputs and
  outputs) is trained on forward-kinematics samples of **one IK branch** (see *Branches*), because
  a regression from pose to joints is only well posed where the inverse is single valued;
* it is evaluated on poses of configurations **on the factor's zero set** inside that branch, and
  the window's half-width is the largest joint error seen there (:func:`learned_window`);
* every random draw (training data, network initialisation, held-out data, evaluation poses) is
  derived from one ``seed``: the same seed gives the same window.

The learned error of a 55-unit network is typically far larger than the thesis's ±0.01 rad; that
is the honest result and the reports say so (next to the thesis's value for the SCARA).

Branches
--------
``branch`` is a dict ``{key: sign}`` with ``sign`` = +1 or −1.  A key is

* a **joint index** j (1-based).  Its *pivot* p_j is the singular value of joint j (a root of a
  one-joint factor of det J on that joint, the one nearest the middle of the joint's range), or,
  when joint j has no one-joint factor, 0 (the range's middle when 0 is outside the range).
  ``+1`` keeps q_j ∈ [p_j, next singular value above p_j or the upper limit],
  ``−1`` keeps q_j ∈ [previous singular value below p_j or the lower limit, p_j].
  SCARA: ``{2: +1}`` is the elbow branch q2 ∈ [0, 2.53] rad, ``{2: -1}`` is q2 ∈ [−2.53, 0].
* the **kind** of a multi-joint factor (``"shoulder"``; its expression string when two multi-joint
  factors share a kind): ``s`` keeps s·g(q) ≥ 0 (left/right arm of a 6R shoulder).

``branch=None`` picks the default branch: every joint with a one-joint factor on the side that
keeps the longer part of its range (+1 on a tie), every multi-joint factor on the sign that holds
for most of the remaining configurations (+1 on a tie).  SCARA: ``{2: +1}``; a 6R arm: elbow,
wrist and shoulder fixed, i.e. one of its (up to) eight IK solutions.  An explicit dict imposes
exactly its own restrictions and nothing else.

A revolute joint whose (restricted) range exceeds 2π is cut to a 2π window (centred on the range,
or anchored at the pivot for a restricted joint): q and q + 2π give the same pose, and a
regression cannot learn a two-valued target.  The cut at ±π remains a seam where nearby poses have
joint values 2π apart; errors near it are large, and are reported as they are.

Units are SI (m, rad).  Nothing here prints or writes files; reports are plain dicts (numbers,
lists, strings) apart from the ``"data"`` entry holding arrays and the fitted model — drop it with
:func:`jsonable_report` before serialising.
"""
from __future__ import annotations

import math
import time
import warnings
import zlib
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np
from sklearn.base import BaseEstimator, clone
from sklearn.compose import TransformedTargetRegressor
from sklearn.exceptions import ConvergenceWarning
from sklearn.metrics import r2_score
from sklearn.neural_network import MLPRegressor
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler
from threadpoolctl import threadpool_limits

import kin
from kin.errors import RmtError
from kin.singularity import SingularFactor, SingularityAnalysis, analyse_singularities
from planning.windows import Window, WindowSet, window_for_factor

__all__ = ["LearnedIKError", "LearnedIK", "Branch", "resolve_branch", "learned_window", "learned_windows",
           "jsonable_report", "default_n_train", "pose_features", "THESIS_WINDOWS", "DEFAULT_N_EVAL"]

#: The thesis's published learned-IK windows (ROBOTS.md §2): robot → joint (1-based) and interval (rad).
THESIS_WINDOWS: dict[str, dict[str, Any]] = {
    "scara_rrp": {"joint": 2, "interval": (-0.01, 0.01),
                  "source": "thesis on singularities and reach (ROBOTS.md §2): θ2 ∈ [−0.01, 0.01] rad"},
}
#: Evaluation poses per factor (configurations on its zero set).
DEFAULT_N_EVAL = 2000
#: Training samples: position-only chains (few inputs) and full-pose chains (12 inputs).
DEFAULT_N_TRAIN_POSITION = 20_000
DEFAULT_N_TRAIN_POSE = 40_000
#: BLAS threads while training/predicting: a 55-unit network is far faster on one thread than on
#: two (thread start-up dominates the small matrix products), and one thread is bit-reproducible.
BLAS_THREADS = 1
_ACTIVATIONS = ("identity", "logistic", "tanh", "relu")
_SOLVERS = ("adam", "sgd", "lbfgs")
# seed streams: one independent generator per purpose, all from the user's seed
_STREAM_TRAIN, _STREAM_HELDOUT, _STREAM_EVAL = 1, 2, 3


class LearnedIKError(RmtError, ValueError):
    """A learned-IK request is invalid (sample counts, seed, branch, network settings, poses)."""


# ---- validation helpers ---------------------------------------------------------------------------
def _check_int(name: str, value: Any, minimum: int = 1) -> int:
    ok = not isinstance(value, (bool, np.bool_)) and isinstance(value, (int, np.integer)) and value >= minimum
    if not ok:
        raise LearnedIKError(f"{name} must be an integer ≥ {minimum}; got {value!r}")
    return int(value)


def _check_seed(seed: Any) -> int:
    ok = not isinstance(seed, (bool, np.bool_)) and isinstance(seed, (int, np.integer)) and 0 <= seed < 2 ** 32
    if not ok:
        raise LearnedIKError(f"seed must be an integer in [0, 2**32); got {seed!r}")
    return int(seed)


def _check_float(name: str, value: Any, lo: float, hi: float, lo_open: bool = False, hi_open: bool = False) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if isinstance(value, (bool, np.bool_)) or not math.isfinite(x) or x < lo or x > hi or (lo_open and x == lo) \
            or (hi_open and x == hi):
        interval = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"
        raise LearnedIKError(f"{name} must be a number in {interval}; got {value!r}")
    return x


def _rng(seed: int, stream: int, extra: int = 0) -> np.random.Generator:
    return np.random.default_rng([seed, stream, extra])


def _as_robot(robot) -> kin.Robot:
    return kin.load_robot(robot) if isinstance(robot, str) else robot


# ---- branches -------------------------------------------------------------------------------------
@dataclass
class Branch:
    """One class of configurations (an IK branch): a box of joint ranges plus sign conditions.

    ``spec``: the normalised ``{key: sign}`` it was built from; ``lower``/``upper`` (n,): the
    joint ranges (SI) after the branch's restrictions and the 2π cut; ``conditions``: list of
    (key, sign, g) meaning sign·g(q) ≥ 0 for multi-joint factors g.
    """

    spec: dict
    lower: np.ndarray
    upper: np.ndarray
    conditions: list[tuple[str, int, Callable[[np.ndarray], np.ndarray]]] = field(default_factory=list)
    pivots: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return len(self.lower)

    def contains(self, Q: np.ndarray, tol: float = 1e-9) -> np.ndarray:
        """(N,) bool: configurations (N, n) inside the branch (boundaries included)."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        inside = np.all((Q >= self.lower - tol) & (Q <= self.upper + tol), axis=1)
        for _, s, g in self.conditions:
            inside &= s * g(Q) >= -tol
        return inside

    def sample(self, N: int, rng: np.random.Generator, max_rounds: int = 50) -> np.ndarray:
        """N configurations uniform in the branch (rejection from the box for the sign conditions)."""
        out, have = [], 0
        for _ in range(max_rounds):
            Q = rng.uniform(self.lower, self.upper, size=(max(2 * (N - have), 64), self.n))
            Q = Q[self.contains(Q, tol=0.0)]
            out.append(Q)
            have += len(Q)
            if have >= N:
                return np.concatenate(out)[:N]
        raise LearnedIKError(f"branch {self.spec_text()} holds too few configurations to sample {N} "
                             "(its sign conditions exclude almost all of the joint box); choose another branch")

    def spec_text(self) -> str:
        return "{" + ", ".join(f"{k!r}: {s:+d}" for k, s in self.spec.items()) + "}"

    def to_dict(self) -> dict:
        return {"spec": {str(k): int(s) for k, s in self.spec.items()},
                "ranges": {f"q{j + 1}": [float(self.lower[j]), float(self.upper[j])] for j in range(self.n)},
                "conditions": [f"{s:+d}·({key}) ≥ 0" for key, s, _ in self.conditions],
                "pivots": {f"q{j + 1}": float(p) for j, p in self.pivots.items()}}


def _factor_keys(factors: list[SingularFactor]) -> dict[str, SingularFactor]:
    """Keys of the multi-joint factors: the kind when unique among them, else the expression."""
    multi = [f for f in factors if f.single_joint is None]
    kinds = [f.kind for f in multi]
    return {(f.kind if kinds.count(f.kind) == 1 else f.expr): f for f in multi}


def _roots_by_joint(factors: list[SingularFactor], n: int) -> dict[int, list[float]]:
    roots: dict[int, list[float]] = {}
    for f in factors:
        j = f.single_joint
        if j is not None and f.solutions.get("values"):
            roots.setdefault(j, []).extend(float(v) for v in f.solutions["values"])
    return {j: sorted(set(v)) for j, v in roots.items()}


def _check_branch_spec(branch: Any, n: int, keys: dict[str, SingularFactor]) -> dict:
    allowed = f"joints 1–{n} (1-based)" + (f" or the multi-joint factors {', '.join(map(repr, keys))}" if keys else "")
    if not isinstance(branch, Mapping):
        raise LearnedIKError(f"branch must be a dict {{joint (1-based) or factor kind: sign ±1}}; got {branch!r}")
    spec: dict = {}
    for key, sign in branch.items():
        if isinstance(key, (int, np.integer)) and not isinstance(key, (bool, np.bool_)):
            if not 1 <= key <= n:
                raise LearnedIKError(f"branch: joint {key!r} unknown; allowed: {allowed}")
            key = int(key)
        elif isinstance(key, str):
            if key not in keys:
                raise LearnedIKError(f"branch: key {key!r} unknown; allowed: {allowed}")
        else:
            raise LearnedIKError(f"branch: key {key!r} unknown; allowed: {allowed}")
        if isinstance(sign, (bool, np.bool_)) or not isinstance(sign, (int, float, np.integer, np.floating)) \
                or sign not in (1, -1):
            raise LearnedIKError(f"branch[{key!r}] = {sign!r}: the sign must be +1 or -1")
        spec[key] = int(sign)
    return spec


def _side(lo: float, hi: float, pivot: float, roots: list[float], sign: int) -> tuple[float, float]:
    if sign > 0:
        nxt = [r for r in roots if r > pivot + 1e-12]
        return pivot, min(nxt[0], hi) if nxt else hi
    prv = [r for r in roots if r < pivot - 1e-12]
    return max(prv[-1], lo) if prv else lo, pivot


def resolve_branch(robot, branch: Mapping | None = None, analysis: SingularityAnalysis | None = None) -> Branch:
    """The :class:`Branch` of ``robot`` described by ``branch`` (see the module docstring;
    ``None`` → the default branch).  ``analysis`` defaults to ``analyse_singularities(robot)``."""
    robot = _as_robot(robot)
    chain = robot.chain
    n = chain.n
    analysis = analysis if analysis is not None else analyse_singularities(robot)
    factors = analysis.factors
    keys = _factor_keys(factors)
    roots = _roots_by_joint(factors, n)
    lo0, hi0 = np.array(chain.lower, float), np.array(chain.upper, float)
    revolute = [chain.joints[j].is_revolute for j in range(n)]

    def pivot_of(j: int) -> float:
        rs = roots.get(j)
        mid = 0.5 * (lo0[j] + hi0[j])
        if rs:
            return min(rs, key=lambda r: (abs(r - mid), r))
        return 0.0 if lo0[j] <= 0.0 <= hi0[j] else mid

    if branch is None:
        spec: dict = {}
        for j in sorted(roots):
            p = pivot_of(j)
            up = _side(lo0[j], hi0[j], p, roots[j], +1)
            dn = _side(lo0[j], hi0[j], p, roots[j], -1)
            if up[1] - up[0] <= 0 and dn[1] - dn[0] <= 0:
                continue
            spec[j + 1] = +1 if up[1] - up[0] >= dn[1] - dn[0] else -1
    else:
        spec = _check_branch_spec(branch, n, keys)

    lower, upper = lo0.copy(), hi0.copy()
    pivots: dict[int, float] = {}
    for key, s in spec.items():
        if isinstance(key, str):
            continue
        j = key - 1
        p = pivot_of(j)
        a, b = _side(lo0[j], hi0[j], p, roots.get(j, []), s)
        if not b - a > 1e-9:
            raise LearnedIKError(f"branch[{key}] = {s:+d} leaves joint {key} no range: its pivot {p:.6g} is at the "
                                 f"{'upper' if s > 0 else 'lower'} limit; use {-s:+d}")
        lower[j], upper[j] = a, b
        pivots[j] = p
    for j in range(n):
        if revolute[j] and upper[j] - lower[j] > 2 * math.pi:
            if j in pivots and spec.get(j + 1, 0) > 0:
                upper[j] = lower[j] + 2 * math.pi
            elif j in pivots:
                lower[j] = upper[j] - 2 * math.pi
            else:
                c = 0.5 * (lower[j] + upper[j])
                lower[j], upper[j] = c - math.pi, c + math.pi

    conditions: list = []
    if branch is None:
        # multi-joint factors: the majority sign inside the box (a fixed draw: the default branch is a
        # property of the robot, not of the seed)
        probe = np.random.default_rng(0).uniform(lower, upper, size=(4000, n))
        for key, f in keys.items():
            if len(f.samples) == 0:
                continue
            g = f(probe)
            s = +1 if np.mean(g >= 0) >= 0.5 else -1
            spec[key] = s
            conditions.append((key, s, f.fn))
            probe = probe[s * g >= 0]
            if len(probe) < 100:
                raise LearnedIKError(f"default branch of {robot.name}: the sign conditions leave too few "
                                     "configurations; give branch explicitly")
    else:
        for key, s in spec.items():
            if isinstance(key, str):
                conditions.append((key, s, keys[key].fn))
    return Branch(spec=spec, lower=lower, upper=upper, conditions=conditions, pivots=pivots)


# ---- features -------------------------------------------------------------------------------------
_ENTRY_NAMES = {(i, j): f"R{i + 1}{j + 1}" for i in range(3) for j in range(3)}
_ENTRY_NAMES.update({(0, 3): "x", (1, 3): "y", (2, 3): "z"})


def _feature_entries(robot) -> list[tuple[int, int]]:
    """Pose entries fed to the network: the 9 rotation and 3 position entries when the task has
    rotation rows (6-joint arms: 12 inputs, as in the thesis), else the task's position entries."""
    rows = tuple(robot.task_rows)
    if any(r >= 3 for r in rows):
        return [(i, j) for i in range(3) for j in range(3)] + [(0, 3), (1, 3), (2, 3)]
    return [(r, 3) for r in rows]


def pose_features(T: np.ndarray, entries: list[tuple[int, int]]) -> np.ndarray:
    """(N, 4, 4) poses → (N, len(entries)) network inputs (SI)."""
    T = np.asarray(T, dtype=float)
    return np.stack([T[:, i, j] for i, j in entries], axis=1)


def default_n_train(robot) -> int:
    """Default training-set size: 20 000 for position-only chains, 40 000 with orientation inputs."""
    return DEFAULT_N_TRAIN_POSE if len(_feature_entries(_as_robot(robot))) > 3 else DEFAULT_N_TRAIN_POSITION


# ---- the estimator --------------------------------------------------------------------------------
class LearnedIK(BaseEstimator):
    """Inverse kinematics of one IK branch learned by a multilayer perceptron (scikit-learn).

    Configured in ``__init__`` (network settings, passed to ``MLPRegressor``; defaults: the
    thesis's one hidden layer of 55 tanh units, Adam with early stopping on a 10 % validation
    split, at most ``max_iter`` epochs); trained by :meth:`fit` on forward-kinematics samples of a
    robot.  Inputs (pose entries) and outputs (joint values, SI) are standardised.

    Fitted attributes: ``robot_name_``, ``n_`` (joints), ``branch_`` (:class:`Branch`),
    ``features_`` (input names), ``model_`` (the scikit-learn regressor), ``n_train_``,
    ``n_heldout_``, ``seed_``, ``n_iter_``, ``converged_``, ``fit_seconds_``,
    ``heldout_score_`` (R² on fresh held-out configurations of the branch, averaged over joints),
    ``heldout_score_per_joint_`` (n,), ``heldout_errors_`` (n_heldout, n) = |q_pred − q_true|.
    """

    def __init__(self, hidden_layer_sizes: tuple[int, ...] = (55,), activation: str = "tanh", solver: str = "adam",
                 max_iter: int = 200, early_stopping: bool = True, batch_size: int = 512,
                 learning_rate_init: float = 3e-3, alpha: float = 1e-4, n_iter_no_change: int = 10,
                 tol: float = 1e-4, validation_fraction: float = 0.1):
        self.hidden_layer_sizes = hidden_layer_sizes
        self.activation = activation
        self.solver = solver
        self.max_iter = max_iter
        self.early_stopping = early_stopping
        self.batch_size = batch_size
        self.learning_rate_init = learning_rate_init
        self.alpha = alpha
        self.n_iter_no_change = n_iter_no_change
        self.tol = tol
        self.validation_fraction = validation_fraction

    # -- parameters
    def _validated_params(self) -> dict:
        h = self.hidden_layer_sizes
        h = (h,) if isinstance(h, (int, np.integer)) and not isinstance(h, bool) else h
        try:
            h = tuple(h)
        except TypeError:
            h = None
        if not h or not all(isinstance(k, (int, np.integer)) and not isinstance(k, bool) and k >= 1 for k in h):
            raise LearnedIKError(f"hidden_layer_sizes must be a tuple of positive integers, e.g. (55,); "
                                 f"got {self.hidden_layer_sizes!r}")
        if self.activation not in _ACTIVATIONS:
            raise LearnedIKError(f"activation {self.activation!r} unknown; allowed: {', '.join(_ACTIVATIONS)}")
        if self.solver not in _SOLVERS:
            raise LearnedIKError(f"solver {self.solver!r} unknown; allowed: {', '.join(_SOLVERS)}")
        if not isinstance(self.early_stopping, (bool, np.bool_)):
            raise LearnedIKError(f"early_stopping must be True or False; got {self.early_stopping!r}")
        return dict(hidden_layer_sizes=tuple(int(k) for k in h), activation=self.activation, solver=self.solver,
                    max_iter=_check_int("max_iter", self.max_iter),
                    early_stopping=bool(self.early_stopping),
                    batch_size=_check_int("batch_size", self.batch_size),
                    learning_rate_init=_check_float("learning_rate_init", self.learning_rate_init, 0, math.inf,
                                                    lo_open=True),
                    alpha=_check_float("alpha", self.alpha, 0, math.inf),
                    n_iter_no_change=_check_int("n_iter_no_change", self.n_iter_no_change),
                    tol=_check_float("tol", self.tol, 0, math.inf),
                    validation_fraction=_check_float("validation_fraction", self.validation_fraction, 0, 1,
                                                     lo_open=True, hi_open=True))

    def __sklearn_is_fitted__(self) -> bool:
        return hasattr(self, "model_")

    @property
    def is_fitted(self) -> bool:
        return hasattr(self, "model_")

    def _check_fitted(self) -> None:
        if not self.is_fitted:
            raise LearnedIKError("this LearnedIK is not fitted yet; call fit(robot, ...) first")

    # -- training
    def fit(self, robot, n_samples: int | None = None, seed: int = 0, branch: Mapping | None = None,
            analysis: SingularityAnalysis | None = None, n_heldout: int | None = None) -> "LearnedIK":
        """Train on ``n_samples`` configurations of ``branch`` (see the module docstring) and their poses.

        ``robot``: a :class:`kin.Robot` or a robot name; ``n_samples``: training configurations
        (default :func:`default_n_train`); ``seed``: training data, network initialisation and
        held-out data; ``analysis``: the singularity analysis that defines the branch pivots
        (computed when None); ``n_heldout``: fresh configurations for the held-out score (default
        max(1000, n_samples // 5)).  Returns self.
        """
        params = self._validated_params()
        robot = _as_robot(robot)
        seed = _check_seed(seed)
        N = default_n_train(robot) if n_samples is None else _check_int("n_samples", n_samples)
        if N < 10:
            raise LearnedIKError(f"n_samples must be an integer ≥ 10 (a network needs data to fit); got {N}")
        Nh = max(1000, N // 5) if n_heldout is None else _check_int("n_heldout", n_heldout)
        branch_ = resolve_branch(robot, branch, analysis)
        entries = _feature_entries(robot)
        t0 = time.perf_counter()
        Q = branch_.sample(N, _rng(seed, _STREAM_TRAIN))
        X = pose_features(robot.fk(Q), entries)
        mlp = MLPRegressor(random_state=seed, **params)
        model = TransformedTargetRegressor(regressor=make_pipeline(StandardScaler(), mlp),
                                           transformer=StandardScaler(), check_inverse=False)
        with threadpool_limits(limits=BLAS_THREADS), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ConvergenceWarning)
            model.fit(X, Q)
        self.converged_ = not any(issubclass(w.category, ConvergenceWarning) for w in caught)
        self.fit_seconds_ = time.perf_counter() - t0
        self.model_ = model
        self.robot_name_ = robot.name
        self.n_ = robot.n
        self.branch_ = branch_
        self.entries_ = entries
        self.features_ = [_ENTRY_NAMES[e] for e in entries]
        self.n_train_ = N
        self.seed_ = seed
        self.n_iter_ = int(model.regressor_[-1].n_iter_)
        # held-out configurations of the same branch, never seen in training
        Qh = branch_.sample(Nh, _rng(seed, _STREAM_HELDOUT))
        Ph = self.predict(robot.fk(Qh))
        self.n_heldout_ = Nh
        self.heldout_score_ = float(r2_score(Qh, Ph))
        self.heldout_score_per_joint_ = np.asarray(r2_score(Qh, Ph, multioutput="raw_values"), dtype=float)
        self.heldout_errors_ = np.abs(Ph - Qh)
        return self

    # -- use
    def _inputs(self, T) -> tuple[np.ndarray, bool]:
        self._check_fitted()
        arr = np.asarray(T, dtype=float)
        single = arr.ndim == 2
        if arr.shape[-2:] != (4, 4) or arr.ndim not in (2, 3):
            raise LearnedIKError(f"poses must have shape (4, 4) or (N, 4, 4); got {arr.shape}")
        arr = arr.reshape(-1, 4, 4)
        if not np.all(np.isfinite(arr)):
            bad = int(np.argmax(~np.all(np.isfinite(arr), axis=(1, 2))))
            raise LearnedIKError(f"poses must be finite; pose {bad} holds NaN or infinity")
        return pose_features(arr, self.entries_), single

    def predict(self, T) -> np.ndarray:
        """Joint values (SI) for poses: (4, 4) → (n,), (N, 4, 4) → (N, n)."""
        X, single = self._inputs(T)
        with threadpool_limits(limits=BLAS_THREADS):
            Q = np.asarray(self.model_.predict(X), dtype=float).reshape(len(X), self.n_)
        return Q[0] if single else Q

    def score(self, T, Q) -> float:
        """R² of the predictions for poses T (N, 4, 4) against joint values Q (N, n), averaged over joints."""
        P = self.predict(T)
        Q = np.asarray(Q, dtype=float).reshape(P.shape)
        return float(r2_score(Q, P))

    def sample_configurations(self, N: int, seed: int = 0) -> np.ndarray:
        """N configurations (N, n) uniform in the fitted branch."""
        self._check_fitted()
        return self.branch_.sample(_check_int("N", N), _rng(_check_seed(seed), _STREAM_HELDOUT, 1))

    def summary(self) -> dict:
        """JSON-friendly description of the fitted model."""
        self._check_fitted()
        return {"robot": self.robot_name_, "hidden_layer_sizes": list(self._validated_params()["hidden_layer_sizes"]),
                "activation": self.activation, "solver": self.solver, "inputs": list(self.features_),
                "outputs": [f"q{j + 1}" for j in range(self.n_)], "n_train": self.n_train_,
                "n_heldout": self.n_heldout_, "seed": self.seed_, "n_iter": self.n_iter_,
                "converged": self.converged_, "fit_seconds": round(self.fit_seconds_, 3),
                "heldout_r2": self.heldout_score_,
                "heldout_r2_per_joint": [float(x) for x in self.heldout_score_per_joint_],
                "branch": self.branch_.to_dict()}


# ---- evaluation on the singular set ---------------------------------------------------------------
def _bisect_zero(g: Callable[[np.ndarray], np.ndarray], Q: np.ndarray, j: int, a: np.ndarray, b: np.ndarray,
                 iters: int = 60) -> np.ndarray:
    """Vectorised bisection of g along joint j in [a, b] (sign change assumed) → configurations."""
    Qa = Q.copy()
    Qa[:, j] = a
    ga = g(Qa)
    for _ in range(iters):
        m = 0.5 * (a + b)
        Qm = Q.copy()
        Qm[:, j] = m
        gm = g(Qm)
        left = np.sign(gm) == np.sign(ga)
        a = np.where(left, m, a)
        ga = np.where(left, gm, ga)
        b = np.where(left, b, m)
    out = Q.copy()
    out[:, j] = 0.5 * (a + b)
    return out


def _zero_set_on_joint(factor: SingularFactor, branch: Branch, j: int, N: int, rng: np.random.Generator,
                       grid: int = 256) -> np.ndarray:
    """Configurations of the branch with g = 0, found along joint j (others uniform in the branch box)."""
    lo, hi = branch.lower[j], branch.upper[j]
    xs = np.linspace(lo, hi, grid)
    found, have = [], 0
    for _ in range(6):
        M = max(2 * (N - have), 256)
        Q = rng.uniform(branch.lower, branch.upper, size=(M, branch.n))
        G = np.empty((M, grid))
        for k, x in enumerate(xs):
            Qx = Q.copy()
            Qx[:, j] = x
            G[:, k] = factor(Qx)
        sc = np.signbit(G[:, :-1]) != np.signbit(G[:, 1:])
        cnt = sc.sum(axis=1)
        rows = np.flatnonzero(cnt > 0)
        if len(rows):
            # one of the row's sign changes, chosen uniformly
            pick = np.floor(rng.random(len(rows)) * cnt[rows]).astype(int)
            csum = np.cumsum(sc[rows], axis=1)
            idx = np.argmax(csum > pick[:, None], axis=1)
            Z = _bisect_zero(factor, Q[rows], j, xs[idx], xs[idx + 1])
            Z = Z[branch.contains(Z)]
            found.append(Z)
            have += len(Z)
        if have >= N:
            break
    return np.concatenate(found)[:N] if found else np.zeros((0, branch.n))


def _evaluation_configurations(factor: SingularFactor, branch: Branch, N: int,
                               rng: np.random.Generator) -> tuple[np.ndarray, dict]:
    """Configurations on the factor's zero set inside the branch (its closure), (≤ N, n), and notes."""
    j = factor.single_joint
    n = branch.n
    if j is not None:
        roots = [r for r in factor.solutions.get("values", [])
                 if branch.lower[j] - 1e-9 <= r <= branch.upper[j] + 1e-9]
        if not roots:
            return np.zeros((0, n)), {"roots_in_branch": []}
        parts = []
        per = int(math.ceil(N / len(roots)))
        for r in roots:
            out, have = [], 0
            for _ in range(50):
                Q = rng.uniform(branch.lower, branch.upper, size=(max(2 * (per - have), 64), n))
                Q[:, j] = r
                Q = Q[branch.contains(Q)]
                out.append(Q)
                have += len(Q)
                if have >= per:
                    break
            parts.append(np.concatenate(out)[:per])
        return np.concatenate(parts)[:N], {"roots_in_branch": [float(r) for r in roots]}
    found, have, used = [], 0, []
    for jj in reversed([k - 1 for k in factor.joints]):
        Z = _zero_set_on_joint(factor, branch, jj, N - have, rng)
        if len(Z):
            found.append(Z)
            used.append(jj + 1)
            have += len(Z)
        if have >= N:
            break
    Q = np.concatenate(found)[:N] if found else np.zeros((0, n))
    return Q, {"solved_along": [f"q{k}" for k in used]}


def _error_stats(E: np.ndarray) -> dict:
    return {"max": [float(x) for x in E.max(axis=0)], "p95": [float(x) for x in np.percentile(E, 95, axis=0)],
            "mean": [float(x) for x in E.mean(axis=0)]}


def _factor_out_of_limits(factor: SingularFactor) -> bool:
    if factor.single_joint is not None:
        return not factor.solutions.get("values")
    return len(factor.samples) == 0


def _skipped(factor: SingularFactor, reason: str, seed: int, **extra) -> dict:
    return {"factor": {"kind": factor.kind, "expr": factor.expr, "joints": list(factor.joints)},
            "status": "skipped", "reason": reason, "method": "learned", "seed": seed, **extra}


def learned_window(robot, factor: SingularFactor, model: LearnedIK | None = None, n_train: int | None = None,
                   n_eval: int = DEFAULT_N_EVAL, seed: int = 0, branch: Mapping | None = None,
                   analysis: SingularityAnalysis | None = None) -> tuple[Window | None, dict]:
    """The thesis's learned-IK error window of one singular factor, and a report.

    ``model``: a fitted :class:`LearnedIK` (used as is; ``n_train`` and a different ``branch``
    are then refused), an unfitted one (a clone is fitted here with ``n_train``, ``seed``,
    ``branch``) or None (a default :class:`LearnedIK`).  ``n_eval`` configurations are drawn on
    the factor's zero set inside the model's branch (one-joint factor: the joint at each of its
    singular values in the branch, the others uniform; other factors: solved along one of its
    joints), their poses (``robot.fk``) are fed to the model and the per-joint errors
    |q_pred − q_true| (rad or m) are taken.  Half-width: the singular joint's largest error
    (one-joint factors), the largest error over the factor's joints (others); the window is
    :func:`planning.windows.window_for_factor` with method ``"learned"``, so the width applies
    around every singular value of the factor, also those outside the branch.

    Returns ``(window, report)``; ``window`` is None (and ``report["status"] == "skipped"``,
    with the reason) when the factor's zero set lies outside the joint limits or outside the
    branch.  The report holds: per-joint max/p95/mean errors at the singularity and on held-out
    configurations of the branch, their ratio, sizes, the held-out R², the seed, the branch, the
    thesis's window when it published one for this robot, and ``"data"`` (not JSON): ``q_true``,
    ``q_pred`` (n_eval, n) and the fitted ``model``.
    """
    robot = _as_robot(robot)
    seed = _check_seed(seed)
    n_eval = _check_int("n_eval", n_eval)
    if n_train is not None:
        _check_int("n_train", n_train)
    if not isinstance(factor, SingularFactor):
        raise LearnedIKError(f"factor must be a SingularFactor from analyse_singularities; got {type(factor).__name__}")
    if factor.n != robot.n:
        raise LearnedIKError(f"factor {factor.expr!r} belongs to a {factor.n}-joint chain, robot {robot.name} has "
                             f"{robot.n} joints")
    if model is not None and not isinstance(model, LearnedIK):
        raise LearnedIKError(f"model must be a LearnedIK or None; got {type(model).__name__}")
    t0 = time.perf_counter()
    if model is not None and model.is_fitted:
        if model.robot_name_ != robot.name or model.n_ != robot.n:
            raise LearnedIKError(f"model was fitted on {model.robot_name_!r}, not on {robot.name!r}")
        if n_train is not None:
            raise LearnedIKError("n_train applies only when the model is trained here; the given model is "
                                 "already fitted (pass an unfitted LearnedIK or None)")
        if branch is not None:
            keys = _factor_keys(analysis.factors) if analysis is not None else {
                k: None for k in model.branch_.spec if isinstance(k, str)}
            if _check_branch_spec(branch, robot.n, keys) != model.branch_.spec:
                raise LearnedIKError(f"branch {dict(branch)!r} differs from the fitted model's branch "
                                     f"{model.branch_.spec_text()}")
        est = model
    else:
        if _factor_out_of_limits(factor):
            return None, _skipped(factor, "zero set outside the joint limits: no singular configuration to "
                                          "evaluate", seed)
        est = clone(model) if model is not None else LearnedIK()
        est.fit(robot, n_samples=n_train, seed=seed, branch=branch, analysis=analysis)
    if _factor_out_of_limits(factor):
        return None, _skipped(factor, "zero set outside the joint limits: no singular configuration to evaluate",
                              seed)
    rng = _rng(seed, _STREAM_EVAL, zlib.crc32(factor.expr.encode()))
    Q, notes = _evaluation_configurations(factor, est.branch_, n_eval, rng)
    if len(Q) == 0:
        return None, _skipped(factor, f"zero set not reached inside the training branch "
                                      f"{est.branch_.spec_text()}; train on a branch that touches it", seed,
                              branch=est.branch_.to_dict())
    P = est.predict(robot.fk(Q))
    E = np.abs(P - Q)
    j = factor.single_joint
    width_joints = [j] if j is not None else [k - 1 for k in factor.joints]
    width = float(E[:, width_joints].max())
    sing, held = _error_stats(E), _error_stats(est.heldout_errors_)
    ratio = {stat: [float(a / b) if b > 0 else math.inf for a, b in zip(sing[stat], held[stat])]
             for stat in ("max", "p95", "mean")}
    chain = robot.chain
    units = ["rad" if chain.joints[k].is_revolute else "m" for k in range(robot.n)]
    detail = {"source": "learned IK (design.learned_ik)", "seed": seed, "n_train": est.n_train_,
              "n_eval": int(len(Q)), "heldout_r2": est.heldout_score_,
              "max_error_per_joint": sing["max"], "branch": {str(k): s for k, s in est.branch_.spec.items()}}
    window = window_for_factor(factor, width, "learned", chain.lower, chain.upper, detail)
    report = {
        "factor": {"kind": factor.kind, "expr": factor.expr, "joints": list(factor.joints)},
        "status": "ok", "method": "learned", "seed": seed,
        "width": width, "width_joints": [f"q{k + 1}" for k in width_joints],
        "width_unit": units[width_joints[0]] if len({units[k] for k in width_joints}) == 1 else "mixed",
        "intervals": [list(iv) for iv in window.intervals] if window.is_interval else None,
        "epsilon": window.epsilon,
        "units": units,
        "n_train": est.n_train_, "n_heldout": est.n_heldout_, "n_eval": int(len(Q)),
        "n_eval_requested": n_eval,
        "heldout_r2": est.heldout_score_,
        "heldout_r2_per_joint": [float(x) for x in est.heldout_score_per_joint_],
        "singular_errors": sing, "heldout_errors": held,
        "singular_to_heldout_ratio": ratio,
        "max_abs_factor_at_eval": float(np.abs(factor(Q)).max()),
        "evaluation": notes,
        "branch": est.branch_.to_dict(),
        "model": est.summary(),
        "seconds": round(time.perf_counter() - t0, 3),
    }
    thesis = THESIS_WINDOWS.get(robot.name)
    if thesis is not None and j is not None and j + 1 == thesis["joint"]:
        lo_t, hi_t = thesis["interval"]
        report["thesis"] = {"joint": f"q{thesis['joint']}", "interval": [lo_t, hi_t], "width": 0.5 * (hi_t - lo_t),
                            "source": thesis["source"], "ours_intervals": report["intervals"], "ours_width": width,
                            "ours_over_thesis": width / (0.5 * (hi_t - lo_t))}
    report["data"] = {"q_true": Q, "q_pred": P, "model": est}
    return window, report


def learned_windows(robot, analysis: SingularityAnalysis | None = None, seed: int = 0, model: LearnedIK | None = None,
                    n_train: int | None = None, n_eval: int = DEFAULT_N_EVAL,
                    branch: Mapping | None = None) -> tuple[WindowSet, list[dict]]:
    """Learned windows for every factor of ``robot``'s singular set, with one model for all.

    The model is trained once (unless a fitted one is given) on ``branch`` with ``n_train``
    samples and ``seed``; every factor is then evaluated as in :func:`learned_window`.  Returns the
    :class:`WindowSet` of the factors that got a window and one report per factor, in
    ``analysis.factors`` order (``report["factor_index"]``); factors whose zero set lies outside the
    joint limits or outside the branch are skipped, their report says why.
    """
    robot = _as_robot(robot)
    seed = _check_seed(seed)
    n_eval = _check_int("n_eval", n_eval)
    if n_train is not None:
        _check_int("n_train", n_train)
    if model is not None and not isinstance(model, LearnedIK):
        raise LearnedIKError(f"model must be a LearnedIK or None; got {type(model).__name__}")
    analysis = analysis if analysis is not None else analyse_singularities(robot, seed=seed)
    reachable = [f for f in analysis.factors if not _factor_out_of_limits(f)]
    fitted = None
    if model is not None and model.is_fitted:
        fitted = model
        if n_train is not None:
            raise LearnedIKError("n_train applies only when the model is trained here; the given model is already "
                                 "fitted")
    elif reachable:
        fitted = (clone(model) if model is not None else LearnedIK()).fit(
            robot, n_samples=n_train, seed=seed, branch=branch, analysis=analysis)
    windows, reports = [], []
    for i, f in enumerate(analysis.factors):
        if _factor_out_of_limits(f):
            w, rep = None, _skipped(f, "zero set outside the joint limits: no singular configuration to evaluate",
                                    seed)
        else:
            w, rep = learned_window(robot, f, model=fitted, n_eval=n_eval, seed=seed,
                                    branch=branch if fitted is model else None, analysis=analysis)
        rep["factor_index"] = i
        reports.append(rep)
        if w is not None:
            windows.append(w)
    return WindowSet(robot=robot.name, n=robot.n, windows=windows), reports


def jsonable_report(report: dict) -> dict:
    """A copy of a report without its ``"data"`` entry (arrays and the model), ready for JSON."""
    return {k: v for k, v in report.items() if k != "data"}
