"""``place``: the robot's base placement that reaches most targets, best — IPOPT from several starts,
cross-checked by differential evolution and by a grid, every answer re-verified by the reach study.

1. *Candidates*: ``candidates`` quasi-random placements (Halton, no seed) are screened by a light
   reach study; the ``starts`` best seed IPOPT with their per-target configurations.
2. *IPOPT* (:class:`design.place.nlp.PlacementNlp`) from each start, re-solved (``polish``) with the
   configurations re-seeded by IK at the placement found while that improves the objective.
3. *Cross-checks*: differential evolution (``de_iterations`` generations, seeded) and a grid of
   ``grid`` values per free coordinate, both scoring placements by the light reach study.
4. *Verification*: every method's best placement gets the full reach study (the collisions of the
   cell, the windows); the placement with the best verified value (reached targets, then mean
   score) is the answer, and the result says which method found it and how the others compare.

The *current* placement (the cell's, identity without a cell) is a candidate of every search when it
lies in the region: screened with the quasi-random candidates, a member of differential evolution's
first population, a point of the grid, and verified by the full study like the others.  Another
placement is the answer only when its verified value beats the current one's; otherwise the answer is
the current placement and the result says so (``current_is_best``): a search never recommends a
worse spot than where the robot stands.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from design.place.nlp import NlpRun, PlacementNlp
from design.place.region import PlacementRegion, placement_transform
from design.place.search import (
    Evaluated,
    SearchResult,
    de_search,
    evaluate_placements,
    grid_placements,
    halton_placements,
)
from design.reach.score import ScoreWeights
from design.reach.study import ReachProblem, ReachSettings, ReachStudy
from design.task.model import Dexterity, Targets, TaskError
from kin.transforms import matrix_to_rpy

__all__ = ["place", "PlacementResult", "SCREEN", "MAX_GRID", "CURRENT_TIE", "CURRENT_BEST"]

#: the light reach study that scores many placements (the verification uses the full settings)
SCREEN = ReachSettings(starts=2, samples=2048, spins=4, max_iter=100)
#: the most placements the grid cross-check may hold (``grid`` to the power of the free coordinates)
MAX_GRID = 1_000_000
#: another placement replaces the current one only when its verified value is higher by more than this
#: share of max(1, |value|) (two studies of equal placements may differ in the last digits)
CURRENT_TIE = 1e-9
#: how a note says that no search beat the current placement (the command line words its own line)
CURRENT_BEST = "the current placement is already the best found"


@dataclass
class PlacementResult:
    """The answer of :func:`place` (SI).  ``u`` the placement (x, y, z, roll, pitch, yaw);
    ``study`` the full reach study there; ``before`` the study at the starting placement (the cell's);
    ``method`` which search found ``u`` (``"current"``: the starting placement is the best found);
    ``methods``: per method its best placement, verified value, coverage, mean score and time;
    ``ipopt`` the runs; ``current``: the starting placement (SI, yaw in the region's range) and
    ``current_reason`` why it was not a candidate (None: it was)."""

    robot: str
    region: PlacementRegion
    u: np.ndarray
    study: ReachStudy
    before: ReachStudy | None
    method: str
    methods: dict = field(default_factory=dict)
    ipopt: list[NlpRun] = field(default_factory=list)
    time_s: float = 0.0
    notes: list[str] = field(default_factory=list)
    #: the grid cross-check's placements and light-study values (None without a grid)
    grid: Evaluated | None = None
    current: np.ndarray | None = None
    current_reason: str | None = None

    @property
    def current_is_best(self) -> bool:
        """Whether the starting placement is the answer (no search found a better verified one)."""
        return self.method == "current"

    @property
    def matrix(self) -> np.ndarray:
        return placement_transform(self.u)

    def to_dict(self) -> dict:
        out = {"robot": self.robot, "coverage_percent": 100 * self.study.coverage, "mean_score": self.study.mean_score,
               "placement": {"xyz": [float(v) for v in self.u[:3]],
                             "rpy": [float(v) for v in matrix_to_rpy(self.matrix[:3, :3])]},
               "method": self.method, "region": self.region.to_dict(), "methods": self.methods,
               "ipopt_runs": [{"u0": r.u0.tolist(), "u": r.u.tolist(), "objective": r.objective,
                               "success": r.success, "status": r.status, "iterations": r.iterations,
                               "time_s": r.time_s, "keep_out_sides": list(r.sides)} for r in self.ipopt],
               "time_s": self.time_s, "notes": list(self.notes), "study": self.study.summary(),
               "current_is_best": self.current_is_best,
               "current": None if self.current is None else
               {"placement": [float(v) for v in self.current], "candidate": self.current_reason is None,
                "reason": self.current_reason}}
        if self.before is not None:
            out["before"] = self.before.summary()
        return out


def _verified(name: str, u: np.ndarray, study: ReachStudy, t: float, extra: dict | None = None) -> dict:
    return {"placement": [float(v) for v in u], "value": study.value, "coverage_percent": 100 * study.coverage,
            "mean_score": study.mean_score, "time_s": t, **(extra or {})}


def place(robot, targets: Targets, cell=None, region: PlacementRegion | None = None, clearance: float = 0.0,
          windows=None, weights: ScoreWeights | None = None, settings: ReachSettings | None = None,
          dexterity: Dexterity | None = None, starts: int = 4, candidates: int = 32, grid: int = 0,
          de_iterations: int = 0, seed: int = 0, max_time: float = 600.0, polish: int = 2,
          progress: Callable[[str], None] | None = None) -> PlacementResult:
    """The best base placement of ``robot`` for ``targets`` (cell frame) in ``cell``, within ``region``
    (default: around the targets, z at the cell's placement, yaw free).  See the module text.

    ``starts`` IPOPT starts (1–64) from ``candidates`` screened placements; ``grid`` values per free
    coordinate of the grid cross-check (0: none); ``de_iterations`` generations of differential
    evolution (0: none), seeded by ``seed``; ``max_time`` (s) bounds the searches (each stops when it
    runs out and the result says so); ``polish``: re-solves per start with every target's configuration
    re-seeded by IK at the placement found (a target left on a poor IK branch, with slack, gets
    another).
    """
    if not isinstance(targets, Targets):
        raise TaskError(f"targets must be design.task.Targets, got {type(targets).__name__}")
    for name, v, lo, hi in (("starts", starts, 1, 64), ("candidates", candidates, 1, 100_000),
                            ("grid", grid, 0, 1000), ("de_iterations", de_iterations, 0, 100_000),
                            ("polish", polish, 0, 100)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= hi:
            raise TaskError(f"{name} = {v!r} must be an integer in [{lo}, {hi}]")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2 ** 32:
        raise TaskError(f"seed = {seed!r} must be an integer in [0, 2³²)")
    if isinstance(max_time, bool) or not isinstance(max_time, (int, float, np.integer, np.floating)) \
            or not 0 < max_time <= 30 * 86_400:
        raise TaskError(f"max_time = {max_time!r} must be a number of seconds in (0, 30 days]")
    t_start = time.perf_counter()
    weights = weights or ScoreWeights()
    settings = settings or ReachSettings()
    say = progress or (lambda s: None)
    base0 = np.array(cell.base) if cell is not None else np.eye(4)
    if region is None:
        region = PlacementRegion.default(robot, targets.positions, z=float(base0[2, 3]))
    # the current placement: a candidate of every search when the region holds it
    u_now, why_not = region.locate(np.concatenate([base0[:3, 3], matrix_to_rpy(base0[:3, :3])]))
    now = u_now[None] if why_not is None else np.empty((0, 6))
    k = int(region.free.sum())
    if grid and grid ** k > MAX_GRID:       # the grid is built whole: 1000 values on 3 coordinates would be 10⁹
        raise TaskError(f"grid = {grid} values on each of the {k} free coordinates ({', '.join(region.names())}) "
                        f"is {grid ** k:.3g} placements; at most {MAX_GRID}")
    full = ReachProblem(robot, targets, cell, clearance, windows, weights, settings, dexterity)
    light = ReachProblem(robot, targets, cell, clearance, windows,
                         dataclasses.replace(weights, dexterity_ref=full.dex_ref), SCREEN, dexterity)
    deadline = t_start + max_time
    full.deadline = light.deadline = deadline     # every study stops early past it (after one start), and says so
    cut: list[str] = []
    methods: dict = {}
    verified: list[tuple[str, np.ndarray, ReachStudy]] = []

    def verify(name: str, u: np.ndarray, t: float, extra: dict | None = None) -> ReachStudy:
        s = full.study(placement_transform(u))
        cut.extend(f"{name} verification: {c}" for c in full.cut)
        verified.append((name, u, s))
        methods[name] = _verified(name, u, s, t, extra)
        return s

    # 1–2: candidates and IPOPT
    t0 = time.perf_counter()
    C = np.vstack([now, halton_placements(region, candidates)])
    if not len(C):
        raise TaskError("the placement region lies inside the keep-out rectangles: no placement to try")
    say(f"screening {len(C) - len(now)} candidate placements" + (" and the current one" if len(now) else ""))
    ev = evaluate_placements(light, C, region, keep_q=True, deadline=deadline)
    screened = int(np.isfinite(ev.value).sum())
    if screened < len(C):
        cut.append(f"screening: {screened} of {len(C)} candidate placements scored")
    if light.cut:
        cut.append(f"screening: {light.cut[0]}")
    order = np.argsort(-ev.value, kind="stable")[:starts]
    runs = []
    if time.perf_counter() > deadline:      # building the NLP alone takes minutes on 10⁵ targets
        cut.append("ipopt: not run")
        order = order[:0]
    else:
        nlp = PlacementNlp(robot, targets, region, weights, full.dex_ref, cell is not None,
                           max_time=max(1.0, min(60.0, max_time / max(starts, 1))))
    for i, c in enumerate(order):
        if time.perf_counter() > deadline or ev.q[c] is None:
            break
        run = nlp.solve(ev.U[c], ev.q[c])
        for _ in range(polish):       # re-seed each target's configuration by IK at the new placement
            if time.perf_counter() > deadline:
                break
            q = light.run(placement_transform(run.u))["q"]
            nxt = nlp.solve(run.u, q)
            if not (nxt.success and nxt.objective < run.objective - 1e-9 * max(1.0, abs(run.objective))):
                break
            nxt.iterations += run.iterations
            nxt.time_s += run.time_s
            nxt.u0 = run.u0
            run = nxt
        runs.append(run)
        say(f"IPOPT start {i + 1}/{len(order)}: {run.status}, objective {run.objective:.6g}, {run.iterations} "
            f"iterations, {run.time_s:.2f} s")
    if runs:            # each run verified with its own configurations offered as one more IK start
        studies = []
        for r in runs:
            studies.append(full.study(placement_transform(r.u), hint=r.q) if region.allowed(r.u[None])[0] else None)
            cut.extend(f"ipopt verification: {c}" for c in full.cut)
        vals = [s.value if s is not None else -1.0 for s in studies]
        best = int(np.argmax(vals))
        if studies[best] is not None:
            verified.append(("ipopt", runs[best].u, studies[best]))
            methods["ipopt"] = _verified("ipopt", runs[best].u, studies[best], time.perf_counter() - t0,
                                         {"starts": len(runs), "best_start": best, "candidates": len(C)})
    # 3: cross-checks
    if de_iterations and time.perf_counter() < deadline:
        say("differential evolution")
        de: SearchResult = de_search(light, region, seed=seed, maxiter=de_iterations, progress=say,
                                     max_time=max(1.0, deadline - time.perf_counter()),
                                     x0=u_now if why_not is None else None)
        if de.u is not None:
            verify("differential_evolution", de.u, de.time_s,
                   {"evaluations": de.evaluations, "generations": de.generations, "message": de.message})
    eg = None
    if grid and time.perf_counter() < deadline:
        U = np.vstack([grid_placements(region, grid), now])
        say(f"grid: {len(U)} placements")
        t1 = time.perf_counter()
        eg = evaluate_placements(light, U, region, deadline=deadline)
        done = int(np.isfinite(eg.value).sum())
        verify("grid", eg.U[eg.best()], time.perf_counter() - t1,
               {"placements": len(U), "evaluated": done, "per_axis": grid})
    if not verified:      # every search ran out of time: the best screened candidate
        verify("candidates", ev.U[ev.best()], ev.time_s, {"candidates": len(C)})
    name, u, study = max(verified, key=lambda v: v[2].value)
    t1 = time.perf_counter()
    before = full.study(base0)
    cut.extend(f"current placement's study: {c}" for c in full.cut)
    notes = []
    if why_not is None:
        methods["current"] = _verified("current", u_now, before, time.perf_counter() - t1)
        if before.value >= study.value - CURRENT_TIE * max(1.0, abs(before.value)):
            name, u, study = "current", u_now, before
            notes.append(f"{CURRENT_BEST} (coverage {100 * before.coverage:.1f} %, "
                         f"mean score {before.mean_score:.3f}); no search found a better one")
    else:
        notes.append(f"the current placement is not a candidate: {why_not}")
    if time.perf_counter() > deadline:
        skipped = [label for label, key, on in (("differential evolution", "differential_evolution", de_iterations),
                                                ("grid", "grid", grid)) if on and key not in methods]
        notes.append(f"the time budget of {max_time:g} s ran out; the searches stopped early"
                     + (f" ({', '.join(skipped)} not run)" if skipped else "")
                     + "".join(f"; {c}" for c in dict.fromkeys(cut)))
    return PlacementResult(robot=robot.name, region=region, u=np.asarray(u, float), study=study, before=before,
                           method=name, methods=methods, ipopt=runs, time_s=time.perf_counter() - t_start,
                           notes=notes, grid=eg, current=u_now, current_reason=why_not)
