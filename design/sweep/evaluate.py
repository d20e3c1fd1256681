"""Evaluating sweep designs, in whatever process runs them.

A :class:`SweepJob` is what travels to a worker (pickled): the task with its robot replaced by the
plain chain (the CasADi graph does not pickle), the IK budget and the metrics.  A worker builds its
robots once per architecture (:func:`job_robot`); their compiled evaluators are loaded from the
on-disk cache, which the driver fills before any worker starts (:func:`warm_cache`).

Each design is evaluated **alone** (one :func:`design.optimise.evaluate_designs` call per design):
the IK's random restarts are drawn per batch, so a design's metrics would otherwise depend on which
designs share its batch — and then a resumed sweep, or one run with another number of workers,
would not give the same rows.  A design that raises becomes a failed :class:`Outcome` with its
error; the chunk goes on.
"""
from __future__ import annotations

import os
import socket
import time
import traceback
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

import kin
from design.metrics import converged_volume, structural_length
from design.optimise import VerifySettings, evaluate_designs
from design.sweep.file import Sweep
from design.sweep.space import Design
from design.task import Task

__all__ = ["SweepJob", "Outcome", "make_job", "evaluate_design", "evaluate_chunk", "job_robot", "warm_cache",
           "job_fingerprint"]


@dataclass(frozen=True)
class SweepJob:
    """Everything a worker needs (picklable).  ``task.robot`` is a :class:`kin.Chain` here.
    ``evaluate`` is the per-design function (module-level, so it pickles by name)."""

    task: Task
    seeds: int
    samples: int
    seed: int
    metrics: tuple[str, ...]
    evaluate: Callable[["SweepJob", kin.Robot, Design], dict] | None = None

    def run_chunk(self, designs: list[Design]) -> list[Outcome]:
        """What a worker does with a chunk (the executors call this; other jobs, such as the
        composition's verdicts, bring their own)."""
        return evaluate_chunk(self, designs)


@dataclass
class Outcome:
    """The result of one design: ``metrics`` (name → number) when ``ok``, else ``error`` (one line);
    ``time_s`` the evaluation's wall time; ``worker`` host:pid of the process that ran it."""

    key: str
    ok: bool
    metrics: dict | None
    error: str | None
    time_s: float
    worker: str


def make_job(sweep: Sweep, evaluate: Callable | None = None) -> SweepJob:
    """The picklable job of a sweep."""
    return SweepJob(replace(sweep.task, robot=sweep.task.robot.chain), sweep.seeds, sweep.samples, sweep.eval_seed,
                    sweep.metrics, evaluate)


#: robots built in this process: (id of the job's chain, architecture) → (chain, robot); the chain is
#: kept so that its id cannot be reused by another object
_ROBOTS: dict[tuple[int, str], tuple[kin.Chain, kin.Robot]] = {}


def job_robot(job: SweepJob, architecture: str) -> kin.Robot:
    """The robot of an architecture ("" = the task's own), built once per process."""
    base = job.task.robot
    key = (id(base), architecture)
    if key not in _ROBOTS:
        chain = base
        if architecture and "".join("R" if j.is_revolute else "P" for j in chain.joints) != architecture:
            from design.architecture import with_joint_types
            chain = with_joint_types(chain, architecture)
        if len(_ROBOTS) > 256:
            _ROBOTS.clear()
        _ROBOTS[key] = (base, kin.Robot(chain))
    return _ROBOTS[key][1]


def warm_cache(job: SweepJob, architectures) -> None:
    """Compile (or load) every architecture's evaluator once, so workers only load from the cache."""
    for a in architectures:
        r = job_robot(job, a)
        r.fk((r.chain.lower + r.chain.upper) / 2)


def evaluate_design(job: SweepJob, robot: kin.Robot, design: Design) -> dict:
    """The metrics of one design (SI): objective (the task's, in its own sense), score (minimised;
    infeasible designs above every feasible one), feasible, and the job's metrics."""
    chain = robot.chain
    lo = np.array([p.bounds[0] for p in chain.parameters.values()])
    hi = np.array([p.bounds[1] for p in chain.parameters.values()])
    p = np.clip(design.vector(), lo, hi)       # normalisation may move a bound value by 1e-12
    task = replace(job.task, robot=robot, architectures=())
    ev = evaluate_designs(task, p[None], VerifySettings(seeds=job.seeds, samples=job.samples, seed=job.seed))
    cov = ev.coverage[0]
    out = {"objective": float(ev.value[0]), "score": float(ev.score[0]), "feasible": bool(ev.feasible[0])}
    length = structural_length(chain, p)
    simple = {"coverage": cov.fraction, "reach": cov.reach_fraction, "flips": cov.flips, "gci": cov.gci,
              "structural_length": length}
    out.update({m: simple[m] for m in job.metrics if m in simple})
    if ev.cycles is not None and any(m in job.metrics for m in ("cycle_time", "peak_torque", "torque_ratio")):
        cyc = ev.cycles[0].metrics()          # cycle_time s, peak_torque N·m, torque_ratio, peak_torque_JOINT
        out.update({k: v for k, v in cyc.items() if k in job.metrics or
                    (k.startswith("peak_torque_") and "peak_torque" in job.metrics)})
    if "volume" in job.metrics or "length_index" in job.metrics:
        cv = converged_volume(robot, p, start=job.samples, seed=job.seed)
        out["volume"] = cv.volume
        if "length_index" in job.metrics:
            root = cv.volume ** (1 / 3) if cv.dimension == 3 else cv.volume ** 0.5
            out["length_index"] = length / root if root > 0 else None
    return out


def _worker_name() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def evaluate_chunk(job: SweepJob, designs: list[Design]) -> list[Outcome]:
    """Evaluate designs one by one; a design that raises is a failed outcome with its error."""
    fn = job.evaluate or evaluate_design
    name = _worker_name()
    out = []
    for d in designs:
        t0 = time.perf_counter()
        try:
            robot = job_robot(job, d.architecture)
            m = fn(job, robot, d)
            out.append(Outcome(d.key, True, m, None, time.perf_counter() - t0, name))
        except Exception as e:           # any failure of one design is stored, the sweep goes on
            last = traceback.extract_tb(e.__traceback__)[-1] if e.__traceback__ else None
            where = f" ({os.path.basename(last.filename)}:{last.lineno})" if last else ""
            msg = (str(e).splitlines() or [""])[0]
            out.append(Outcome(d.key, False, None, f"{type(e).__name__}: {msg}{where}", time.perf_counter() - t0, name))
    return out


def _cell_fingerprint(cell) -> str:
    """Everything of a work cell that decides collisions, as text (``""`` without a cell)."""
    if cell is None:
        return ""
    parts = [np.asarray(cell.base, float).tobytes().hex(), repr(cell.tool), repr(cell.body_pairs),
             repr(cell.obstacle_pairs)]
    for ob in cell.obstacles:
        parts.append(repr((ob.name, sorted(ob.ignore), [(s.kind, s.size, s.pose.tobytes().hex()) for s in ob.shapes])))
        if ob.spheres is not None:
            parts.append(ob.spheres.tobytes().hex())
    return "|".join(parts)


def _cycle_fingerprint(cycle) -> str:
    """The motion cycle's every value (numpy arrays in full), or "-" without one."""
    if cycle is None:
        return "-"
    from dataclasses import fields
    return repr([(f.name, np.asarray(v).tolist() if isinstance(v := getattr(cycle, f.name), np.ndarray) else v)
                 for f in fields(cycle)])


def job_fingerprint(job: SweepJob) -> str:
    """SHA-256 of everything that decides a design's metrics: the chain, the targets, the dexterity,
    objective and constraints, the IK budget and the metrics (a store refuses another job's rows)."""
    import hashlib
    t = job.task
    h = hashlib.sha256()
    for part in (repr(t.robot), t.targets.orientation, repr(t.targets.cone_half_angle), repr(t.targets.tolerance),
                 repr(t.dexterity), t.objective, repr(t.min_coverage), repr(t.total_length),
                 repr((job.seeds, job.samples, job.seed, tuple(job.metrics))),
                 getattr(job.evaluate, "__qualname__", "default"),
                 _cell_fingerprint(t.cell), repr(t.clearance), repr(t.region),
                 _cycle_fingerprint(t.cycle)):
        h.update(part.encode())
        h.update(b"\0")
    for arr in (t.targets.positions, t.targets.axes, t.targets.rotations):
        h.update(b"-" if arr is None else np.ascontiguousarray(arr, float).tobytes())
    return h.hexdigest()
