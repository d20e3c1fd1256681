"""The task objective of designs, from the independent (IK-verified) metrics — shared by the
IPOPT re-verification, the brute-force grid and differential evolution.

``score`` is what the optimisers minimise: the structural length (m) for "length", the
structural length index for "length_index", −coverage for "coverage", −GCI for "gci", the cycle time
(s) for "cycle_time" and the largest peak torque over its limit for "torque_ratio"; a design whose
verified coverage is below ``min_coverage`` gets a penalty above every feasible score.

A task with a motion cycle (``task.cycle``, :mod:`design.cycle`) has every design's cycle evaluated
too: a feasible design also reaches every stop of the cycle and keeps every peak motor torque within
its limit (``tau_max``, where known); the penalty of one that does not grows with the excess.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from design.coverage import Coverage, coverage_of_designs
from design.metrics import length_index, structural_length
from design.task.model import Task

__all__ = ["Evaluation", "evaluate_designs", "VerifySettings"]


@dataclass(frozen=True)
class VerifySettings:
    """Budget of the verification: IK seeds per target, sampled configurations, seed; samples and
    tolerance of the converged volume (for the length index)."""

    seeds: int = 4
    samples: int = 20_000
    seed: int = 0
    volume_tolerance: float = 0.02


@dataclass
class Evaluation:
    """Verified evaluation of D designs: ``value`` (D,) the objective in its own sense (m, or a
    fraction), ``score`` (D,) what is minimised, ``feasible`` (D,), ``coverage`` one per design,
    ``cycles`` one :class:`design.cycle.CycleResult` per design when the task has a cycle, else None."""

    value: np.ndarray
    score: np.ndarray
    feasible: np.ndarray
    coverage: list[Coverage]
    cycles: list | None = None


def evaluate_designs(task: Task, P: np.ndarray, settings: VerifySettings = VerifySettings()) -> Evaluation:
    """Verify designs P (D, n_p) (SI) against the task and score them."""
    P = np.atleast_2d(np.asarray(P, float))
    covs = coverage_of_designs(task.robot, task.targets, task.dexterity, P, settings.seeds, settings.samples,
                               settings.seed, cell=task.cell, clearance=task.clearance)
    frac = np.array([c.fraction for c in covs])
    chain = task.robot.chain
    length = np.array([structural_length(chain, p) for p in P])
    feasible = frac >= task.min_coverage - 1e-12
    if task.total_length is not None:
        feasible &= np.abs(length - task.total_length) <= 1e-6 * max(task.total_length, 1.0)
    if task.objective == "length":
        value = score = length
    elif task.objective == "length_index":
        value = score = np.array([length_index(task.robot, p, settings.samples, settings.seed,
                                               settings.volume_tolerance) for p in P])
    elif task.objective == "coverage":
        value, score = frac, -frac
    elif task.objective == "gci":
        value = np.array([c.gci for c in covs])
        score = -value
    cycles, excess = None, np.zeros(len(P))
    if task.cycle is not None:
        from design.cycle import evaluate_cycle
        cycles = [evaluate_cycle(task.robot, task.cycle, task.targets, p, settings.seed) for p in P]
        excess = np.array([0.0 if c.within_torque else 1.0 if not c.ok else c.torque_ratio - 1.0 for c in cycles])
        feasible &= excess == 0
        if task.objective == "cycle_time":
            value = score = np.array([c.cycle_time for c in cycles])
        elif task.objective == "torque_ratio":
            value = score = np.array([c.torque_ratio if c.ok else np.inf for c in cycles])
    # infeasible designs rank after every feasible one, ordered by how much coverage (and torque) they miss
    finite = score[np.isfinite(score)]
    top = (np.abs(finite).max() if finite.size else 1.0) + 1.0
    score = np.where(feasible, score, top * (2 + np.maximum(task.min_coverage - frac, 0) + np.minimum(excess, 1e3)))
    return Evaluation(value=value, score=score, feasible=feasible, coverage=covs, cycles=cycles)
