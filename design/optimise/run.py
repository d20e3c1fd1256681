"""``optimise(task, method=...)``: IPOPT multi-start (:mod:`design.optimise.nlp`) or differential
evolution (:mod:`design.optimise.de`), every answer re-verified by the independent coverage metric."""
from __future__ import annotations

import time
from dataclasses import replace
from typing import Callable

import numpy as np

from design.coverage import seed_configurations
from design.optimise.objective import VerifySettings, evaluate_designs
from design.optimise.result import DesignResult
from design.task.model import Task, TaskError

__all__ = ["optimise", "METHODS"]

METHODS = ("ipopt", "de")


def _bounds(task: Task) -> np.ndarray:
    pars = task.robot.chain.parameters
    if not pars:
        raise TaskError(f"{task.robot.name} has no design parameters to optimise")
    return np.array([p.bounds for p in pars.values()], float)


def start_points(task: Task, starts: int, seed: int, settings: VerifySettings, screen: int = 8):
    """Initial designs (starts, n_p) and their verified coverage: the nominal design first, then the
    best ``starts − 1`` (by verified score) of ``screen × (starts − 1)`` designs uniform within the
    bounds — a random start where the arm reaches nothing leaves IPOPT without a feasible branch."""
    b = _bounds(task)
    rng = np.random.default_rng(seed)
    nominal = np.clip(task.robot.chain.parameter_values, b[:, 0], b[:, 1])[None]
    cand = rng.uniform(b[:, 0], b[:, 1], size=(max(screen, 1) * (starts - 1), len(b)))
    ev = evaluate_designs(task, np.vstack([nominal, cand]), settings)
    order = 1 + np.argsort(ev.score[1:], kind="stable")[:starts - 1]
    pick = np.concatenate([[0], order])
    return np.vstack([nominal, cand])[pick], [ev.coverage[i] for i in pick]


def _poses(targets) -> np.ndarray:
    T = np.tile(np.eye(4), (len(targets), 1, 1))
    T[:, :3, :3], T[:, :3, 3] = targets.rotations, targets.positions
    return T


def _polish(task: Task, run, Qs, rng, t0: float, max_time: float, rounds: int, nlp):
    """Re-solve from the run's design with each target's configuration replaced by the nearest
    sampled one at that design when that is closer to the target; keep improvements."""
    robot = task.robot
    for _ in range(rounds):
        left = max_time - (time.perf_counter() - t0)
        if left <= 0 or run.q is None:
            break
        p = np.clip(run.p, *_bounds(task).T)
        t = task.targets
        if t.orientation in ("free", "pose"):     # best-effort IK at the new design, from fresh starts too
            goal = t.positions if t.orientation == "free" else _poses(t)
            # without q0, IK prefers the solution nearest the home configuration: away from the limits,
            # where a configuration pinned at a joint limit blocks the design from moving
            cand = robot.ik(goal, seed=int(rng.integers(2 ** 31)), restarts=4, rounds=1, params=p,
                            mode="position" if t.orientation == "free" else "pose").q
        else:
            cand = seed_configurations(robot, t, p, 1, Qs)[:, 0]
        cur = np.clip(run.q, robot.chain.lower, robot.chain.upper)
        d_cur = np.linalg.norm(robot.fk(cur, params=p)[:, :3, 3] - task.targets.positions, axis=1)
        d_new = np.linalg.norm(robot.fk(cand, params=p)[:, :3, 3] - task.targets.positions, axis=1)
        q0 = np.where((d_new < np.maximum(d_cur, t.tolerance) - 1e-12)[:, None], cand, cur)
        q0 = q0 + rng.normal(0.0, 0.01, q0.shape) * (robot.chain.upper - robot.chain.lower) / (2 * np.pi)
        nxt = nlp.solve(p, q0)
        better = nxt.success and nxt.objective < run.objective - 1e-12 * max(1.0, abs(run.objective))
        merged = replace(nxt if better else run, p0=run.p0, iterations=run.iterations + nxt.iterations,
                         time_s=run.time_s + nxt.time_s, history=run.history + nxt.history,
                         constraint_violation=run.constraint_violation + nxt.constraint_violation)
        run = merged
        if not better:
            break
    return run


def optimise(task: Task, method: str = "ipopt", starts: int = 4, seed: int = 0,
             settings: VerifySettings | None = None, max_time: float = 300.0,
             progress: Callable[[str], None] | None = None, polish: int = 2, screen: int = 8,
             **options) -> DesignResult:
    """Optimise the task's design parameters (SI) and verify the answer independently.

    ``starts``: IPOPT starts (the nominal design, then the best verified of ``screen`` random designs
    per further start, from ``seed``); ``settings``: the
    verification budget; ``polish``: re-solves per start with the per-target configurations
    re-seeded at the new design (a target whose configuration sits on another IK branch, or on a
    stationary point such as a folded arm, is re-seeded from the nearest-neighbour index); ``max_time``:
    wall-time budget (s) for the solver; ``progress`` receives
    one line per start/generation.  ``options`` go to the method (``margin``, ``max_iter`` for
    IPOPT; ``popsize``, ``maxiter`` for DE).
    """
    if method not in METHODS:
        raise TaskError(f"method {method!r} unknown; allowed: {', '.join(METHODS)}")
    if not 1 <= starts <= 1000:
        raise TaskError(f"starts {starts} must be in [1, 1000]")
    settings = settings or VerifySettings(seed=task.seed)
    if method == "de":
        from design.optimise.de import optimise_de
        return optimise_de(task, seed=seed, settings=settings, max_time=max_time, progress=progress, **options)
    from design.optimise.nlp import DesignNlp
    t0 = time.perf_counter()
    robot, b = task.robot, _bounds(task)
    P0, covs0 = start_points(task, starts, seed, settings, screen)
    rng = np.random.default_rng(seed + 1)
    Qs = robot.random_configurations(max(settings.samples, 1000), seed=seed)
    nlp = DesignNlp(task, max_time=max_time, **options)
    runs = []
    for i, p0 in enumerate(P0):
        left = max_time - (time.perf_counter() - t0)
        if left <= 0:
            break
        # per target: the verified IK solution at the start design where there is one, else the nearest
        # sample with a small seeded jitter (keeps it off stationary points: a stretched or folded arm)
        nn = seed_configurations(robot, task.targets, p0, 1, Qs)[:, 0]
        nn = nn + rng.normal(0.0, 0.05, nn.shape) * (robot.chain.upper - robot.chain.lower) / (2 * np.pi)
        q0 = np.where(covs0[i].reached[:, None], covs0[i].q, nn)
        run = nlp.solve(p0, q0)
        run = _polish(task, run, Qs, rng, t0, max_time, polish, nlp)
        runs.append(run)
        if progress:
            progress(f"start {i + 1}/{starts}: {run.status}, objective {run.objective:.6g}, "
                     f"{run.iterations} iterations, {run.time_s:.2f} s")
    P = np.clip(np.array([r.p for r in runs]), b[:, 0], b[:, 1])
    ev = evaluate_designs(task, P, settings)
    # the verified score decides; the NLP's own objective breaks ties (e.g. equal coverage fractions)
    best = int(np.lexsort((np.array([r.objective for r in runs]), ev.score))[0])
    names = list(robot.chain.parameters)
    solver = {"name": "ipopt", "starts": [{"p0": dict(zip(names, r.p0)), "p": dict(zip(names, r.p)),
                                           "objective": r.objective, "success": r.success, "status": r.status,
                                           "iterations": r.iterations, "time_s": r.time_s,
                                           "verified_coverage": ev.coverage[i].fraction,
                                           "verified_score": float(ev.score[i])}
                                          for i, r in enumerate(runs)],
              "best_start": best, "time_s": sum(r.time_s for r in runs),
              "verification": {"seeds": settings.seeds, "samples": settings.samples, "seed": settings.seed}}
    return DesignResult(task=task.name, method="ipopt", robot=robot, params=dict(zip(names, P[best].tolist())),
                        objective_name=task.objective, objective=float(ev.value[best]),
                        feasible=bool(ev.feasible[best]),
                        verification=ev.coverage[best], solver=solver, history=[r.history for r in runs],
                        time_s=time.perf_counter() - t0, length_unit=task.length_unit,
                        architecture="".join("R" if j.is_revolute else "P" for j in robot.chain.joints),
                        cycle=None if ev.cycles is None else ev.cycles[best])
