"""Learned-IK error windows from a learned IK model (see :mod:`design.learned.ik`):
evaluate the model on poses of configurations on each singular factor's zero set; the window's
half-width is the largest joint error there."""
from __future__ import annotations

import math
import time
import zlib
from typing import Callable, Mapping

import numpy as np
from sklearn.base import clone

from design.learned.branch import (
    _STREAM_EVAL,
    Branch,
    LearnedIKError,
    _as_robot,
    _check_branch_spec,
    _check_int,
    _check_seed,
    _factor_keys,
    _rng,
)
from design.learned.ik import DEFAULT_N_EVAL, LearnedIK
from kin.singular import SingularFactor, SingularityAnalysis, analyse_singularities
from planning.windows import Window, WindowSet, window_for_factor

__all__ = ["learned_window", "learned_windows", "jsonable_report"]


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
    """The learned-IK error window of one singular factor, and a report.

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
    configurations of the branch, their ratio, sizes, the held-out R², the seed, the branch, and
    ``"data"`` (not JSON): ``q_true``, ``q_pred`` (n_eval, n) and the fitted ``model``.
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
    detail = {"source": "learned IK (design.learned.ik)", "seed": seed, "n_train": est.n_train_,
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
    if getattr(analysis, "method", "exact") != "exact":
        raise LearnedIKError(f"learned windows need the exact singular factors; the analysis of {robot.chain.name} "
                             f"is {analysis.method} (the exact one did not finish within its budget)")
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

