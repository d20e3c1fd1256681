"""Learned inverse kinematics and the learned-IK error windows, made exact and reproducible.

The learned-IK window method trains a small neural network for inverse kinematics (one hidden
layer of 55 tanh units; inputs the 9 rotation entries and the 3 position entries of the tool pose,
outputs the joint values), evaluates it on poses where the arm is singular and calls

    q_singular ± max |q_predicted − q_true|

the singular joint's *error window*.  Done by hand, the method is not repeatable: the singular
value is chosen by hand and the random draws are unseeded.  Here:

* the singular values come from :func:`kin.singular.analyse_singularities` (every factor of
  det J, not one chosen by hand);
* the network (:class:`LearnedIK`, scikit-learn's ``MLPRegressor`` with standardised inputs and
  outputs) is trained on forward-kinematics samples of **one IK branch** (see *Branches*), because
  a regression from pose to joints is only well posed where the inverse is single valued;
* it is evaluated on poses of configurations **on the factor's zero set** inside that branch, and
  the window's half-width is the largest joint error seen there (:func:`learned_window`);
* every random draw (training data, network initialisation, held-out data, evaluation poses) is
  derived from one ``seed``: the same seed gives the same window.

The window measures the network as much as the arm: its size, its training poses and its seed set
the width (a bigger or better-trained network gives a narrower one), and the reports give the
held-out errors beside it so that a reader can tell.

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
from typing import Mapping

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.compose import TransformedTargetRegressor
from sklearn.exceptions import ConvergenceWarning
from sklearn.metrics import r2_score
from sklearn.neural_network import MLPRegressor
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler
from threadpoolctl import threadpool_limits

from design.learned.branch import (
    _STREAM_HELDOUT,
    _STREAM_TRAIN,
    Branch,
    LearnedIKError,
    _as_robot,
    _check_float,
    _check_int,
    _check_seed,
    _rng,
    resolve_branch,
)
from kin.singular import SingularityAnalysis

__all__ = ["LearnedIKError", "LearnedIK", "Branch", "resolve_branch", "default_n_train", "pose_features",
           "DEFAULT_N_EVAL"]

#: scikit-learn's MLP stochastic solvers catch Ctrl-C and only warn with this message.
_SKLEARN_INTERRUPTED = "Training interrupted by user."

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


# ---- features -------------------------------------------------------------------------------------
_ENTRY_NAMES = {(i, j): f"R{i + 1}{j + 1}" for i in range(3) for j in range(3)}
_ENTRY_NAMES.update({(0, 3): "x", (1, 3): "y", (2, 3): "z"})


def _feature_entries(robot) -> list[tuple[int, int]]:
    """Pose entries fed to the network: the 9 rotation and 3 position entries when the task has
    rotation rows (6-joint arms: 12 inputs), else the task's position entries."""
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
    method's one hidden layer of 55 tanh units, Adam with early stopping on a 10 % validation
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
            warnings.simplefilter("always")
            model.fit(X, Q)
        # scikit-learn's stochastic solvers catch Ctrl-C, warn and return a half-trained network;
        # a user who pressed Ctrl-C wants to stop, not a window from that network
        if any(str(w.message) == _SKLEARN_INTERRUPTED for w in caught):
            raise KeyboardInterrupt
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


