"""Brute force: the verified objective on a full grid of designs (the reference the optimisers
are compared with)."""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from design.optimise.objective import VerifySettings, evaluate_designs
from design.task.model import Task, TaskError

__all__ = ["GridResult", "grid_search"]


@dataclass
class GridResult:
    """Every grid design P (D, n_p) SI, its ``score`` and ``feasible`` flag, and the best one."""

    P: np.ndarray
    score: np.ndarray
    feasible: np.ndarray
    best: np.ndarray
    best_score: float
    spacing: np.ndarray


def grid_search(task: Task, counts: int | tuple[int, ...] = 50, settings: VerifySettings | None = None,
                chunk: int = 500) -> GridResult:
    """Evaluate ``counts`` points per parameter (from bound to bound) — every combination — with the
    verified metric, ``chunk`` designs per IK batch."""
    pars = task.robot.chain.parameters
    if not pars:
        raise TaskError(f"{task.robot.name} has no design parameters")
    counts = (counts,) * len(pars) if isinstance(counts, int) else tuple(counts)
    if len(counts) != len(pars) or min(counts) < 2 or np.prod(counts) > 1_000_000:
        raise TaskError(f"grid counts {counts}: one count ≥ 2 per parameter ({len(pars)}), at most 1e6 designs")
    axes = [np.linspace(p.bounds[0], p.bounds[1], c) for p, c in zip(pars.values(), counts)]
    P = np.array(list(itertools.product(*axes)))
    settings = settings or VerifySettings(seed=task.seed)
    score = np.empty(len(P))
    feas = np.empty(len(P), bool)
    for s in range(0, len(P), chunk):
        ev = evaluate_designs(task, P[s:s + chunk], settings)
        score[s:s + chunk], feas[s:s + chunk] = ev.score, ev.feasible
    b = int(np.argmin(score))
    return GridResult(P, score, feas, P[b], float(score[b]), np.array([a[1] - a[0] for a in axes]))
