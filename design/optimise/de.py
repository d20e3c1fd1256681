"""Derivative-free design optimisation: scipy's differential evolution on the verified metric
(:func:`design.optimise.objective.evaluate_designs`), every generation verified as one IK batch
(``vectorized=True``).  For non-smooth objectives (Q_L, GCI, and the cycle time and torque ratio, which
the IPOPT NLP cannot differentiate: they pass through IK branch choices and a time-optimal timing) and
as a cross-check of IPOPT.

A total-length equality constraint is met by projection: the parameters are scaled so that
Σ(|a_i| + |d_i|) = L (a design whose projection leaves the bounds is infeasible).
"""
from __future__ import annotations

import time
from typing import Callable

import numpy as np
from scipy.optimize import differential_evolution

from design.metrics import structural_length
from design.optimise.objective import VerifySettings, evaluate_designs
from design.optimise.result import DesignResult
from design.task.model import Task, TaskError

__all__ = ["optimise_de", "project_total_length"]


def project_total_length(task: Task, P: np.ndarray) -> np.ndarray:
    """Designs P (D, n_p) scaled so that their structural length equals ``task.total_length``
    (unchanged when the task has none)."""
    if task.total_length is None:
        return P
    chain = task.robot.chain
    fixed = structural_length(chain, np.zeros(P.shape[1]))
    var = np.array([structural_length(chain, p) for p in P]) - fixed
    if task.total_length <= fixed:
        raise TaskError(f"total_length {task.total_length:g} m is not more than the fixed links' {fixed:g} m")
    return P * ((task.total_length - fixed) / np.where(var > 0, var, 1.0))[:, None]


def optimise_de(task: Task, seed: int = 0, settings: VerifySettings | None = None, max_time: float = 300.0,
                progress: Callable[[str], None] | None = None, popsize: int = 12, maxiter: int = 40,
                tol: float = 1e-3) -> DesignResult:
    """Differential evolution (seeded, one worker, whole generations verified in one batch)."""
    settings = settings or VerifySettings(seed=task.seed)
    chain = task.robot.chain
    if not chain.parameters:
        raise TaskError(f"{task.robot.name} has no design parameters to optimise")
    if not (2 <= popsize <= 200 and 1 <= maxiter <= 10_000):
        raise TaskError(f"popsize {popsize} must be in [2, 200] and maxiter {maxiter} in [1, 10000]")
    b = np.array([p.bounds for p in chain.parameters.values()], float)
    t0 = time.perf_counter()
    history: list[float] = []
    evals = [0]

    def scores(X: np.ndarray) -> np.ndarray:            # X (n_p, S): scipy's vectorised layout
        P = project_total_length(task, np.atleast_2d(X.T))
        inside = np.all((P >= b[:, 0] - 1e-12) & (P <= b[:, 1] + 1e-12), axis=1)
        out = np.full(len(P), np.inf)
        if inside.any():
            out[inside] = evaluate_designs(task, P[inside], settings).score
        finite = out[np.isfinite(out)]
        out[~np.isfinite(out)] = (np.abs(finite).max() + 1.0) * 4 if finite.size else 1e6
        evals[0] += len(P)
        return out

    def callback(intermediate_result):
        history.append(float(intermediate_result.fun))
        if progress:
            progress(f"generation {len(history)}: best score {intermediate_result.fun:.6g}, "
                     f"{evals[0]} designs verified")
        return time.perf_counter() - t0 > max_time

    res = differential_evolution(scores, b, seed=seed, workers=1, vectorized=True, updating="deferred",
                                 popsize=popsize, maxiter=maxiter, tol=tol, polish=False, callback=callback)
    p = project_total_length(task, res.x[None])
    ev = evaluate_designs(task, p, settings)
    names = list(chain.parameters)
    solver = {"name": "differential_evolution", "generations": int(res.nit), "evaluations": evals[0],
              "message": str(res.message), "popsize": popsize, "maxiter": maxiter, "seed": seed,
              "score": float(res.fun), "time_s": time.perf_counter() - t0,
              "verification": {"seeds": settings.seeds, "samples": settings.samples, "seed": settings.seed}}
    return DesignResult(task=task.name, method="de", robot=task.robot, params=dict(zip(names, p[0].tolist())),
                        objective_name=task.objective, objective=float(ev.value[0]), feasible=bool(ev.feasible[0]),
                        verification=ev.coverage[0], solver=solver, history=[history],
                        time_s=time.perf_counter() - t0, length_unit=task.length_unit,
                        architecture="".join("R" if j.is_revolute else "P" for j in chain.joints),
                        cycle=None if ev.cycles is None else ev.cycles[0])
