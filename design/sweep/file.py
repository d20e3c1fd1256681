"""Sweep files (TOML): a design task plus the design space, the sampling and the metrics.

Every bad field raises :class:`SweepError` naming the file and the field; nothing is evaluated.
Parameter ranges and values are in the robot file's units (as ``rmt coverage --param``) and must
lie inside the parameter's bounds.  Schema: docs/design.md, "Sweep files".
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from design.task import Task, TaskError, load_task
from design.task.file import _architectures as _task_architectures
from design.task.file import _Reader

__all__ = ["SweepError", "Sweep", "ParameterSpace", "load_sweep", "loads_sweep", "SAMPLINGS", "METRICS"]

#: sampling of the continuous parameters: full grid, Latin hypercube, scrambled Sobol (scipy.stats.qmc)
SAMPLINGS = ("grid", "lhs", "sobol")
#: metrics a sweep may store per design (objective, score and feasible are always stored)
METRICS = ("coverage", "reach", "flips", "gci", "structural_length", "length_index", "volume", "cycle_time",
           "peak_torque", "torque_ratio")
#: the metrics of the task's motion cycle (they need its [cycle] table, :mod:`design.cycle`)
CYCLE_METRICS = ("cycle_time", "peak_torque", "torque_ratio")
DEFAULT_METRICS = ("coverage", "reach", "flips", "gci", "structural_length")
_TOP = ("name", "title", "task", "metrics", "architecture", "sampling", "evaluation", "parameters", "placement")
#: at most this many designs from the sampling (a larger sweep is several files, or --resume extends)
MAX_DESIGNS = 1_000_000


class SweepError(TaskError):
    """A sweep file, store or run is invalid; the message names the file and the field."""


@dataclass(frozen=True)
class ParameterSpace:
    """One swept design parameter, SI: ``values`` an explicit list, else ``low``..``high`` with
    ``count`` grid points (the count is unused by LHS and Sobol, which sample the range)."""

    name: str
    low: float = 0.0
    high: float = 0.0
    count: int = 0
    values: tuple[float, ...] = ()

    @property
    def is_list(self) -> bool:
        return bool(self.values)


@dataclass(frozen=True)
class Sweep:
    """A sweep: the task, the swept parameters (in the robot's parameter order), the architectures
    ("" = the robot's own joint types), the sampling and its seed, the IK budget of the evaluation
    (``seeds`` per target, ``samples`` for the seed index, ``eval_seed``), the metrics to store."""

    name: str
    task: Task
    parameters: tuple[ParameterSpace, ...]
    architectures: tuple[str, ...] = ("",)
    sampling: str = "grid"
    count: int = 0
    seed: int = 0
    seeds: int = 4
    samples: int = 5000
    eval_seed: int = 0
    metrics: tuple[str, ...] = DEFAULT_METRICS
    title: str = ""
    source: str = ""
    #: co-design: place every design at its best (:func:`design.place.codesign.evaluate_placed_design`)
    placement: bool = False


class _SweepReader(_Reader):
    """The task-file field reader, failing with :class:`SweepError`."""

    def fail(self, field: str | None, msg: str) -> SweepError:
        return SweepError(msg, self.path, field)


def load_sweep(path: str | Path) -> Sweep:
    """Read a sweep file; its ``task`` is a path relative to the sweep file's folder."""
    from design.task.file import MAX_TASK_BYTES
    from kin.files import read_text
    p = Path(path)
    text = read_text(p, "sweep file", MAX_TASK_BYTES, error=SweepError)
    return loads_sweep(text, str(p), p.parent)


def loads_sweep(text: str, path: str | None = None, base: Path | None = None, task: Task | None = None) -> Sweep:
    """Parse sweep-file text (see :func:`load_sweep`); ``task`` overrides the file's ``task`` entry."""
    r = _SweepReader(path)
    base = Path(".") if base is None else base
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise SweepError(f"not valid TOML: {e}", path) from None
    r.table(raw, "", _TOP)
    for key in ("name", "task", "parameters"):
        if key not in raw:
            raise r.fail(key, "missing (required)")
    name = r.string(raw["name"], "name")
    if not name or not all(c.isalnum() or c in "_-" for c in name):
        raise r.fail("name", f"{name!r} must be letters, digits, '_' or '-'")
    if task is None:
        tp = r.file(raw["task"], "task", base)
        try:
            task = load_task(tp)
        except TaskError as e:
            raise r.fail("task", str(e)) from None
    chain = task.robot.chain
    params = _parameters(r, raw["parameters"], chain)
    samp = r.table(raw.get("sampling", {}), "sampling", ("method", "count", "seed"))
    method = r.string(samp.get("method", "grid"), "sampling.method", SAMPLINGS)
    seed = r.integer(samp.get("seed", 0), "sampling.seed", 0, 2 ** 31 - 1)
    count = 0
    if method == "grid":
        if "count" in samp:
            raise r.fail("sampling.count", "only for lhs and sobol (a grid's size is the product of the counts)")
        for ps in params:
            if not ps.is_list and ps.count < 1:
                raise r.fail(f"parameters.{ps.name}.count", "missing (required for a grid with a range)")
    else:
        if "count" not in samp:
            raise r.fail("sampling.count", f"missing (required for {method})")
        count = r.integer(samp["count"], "sampling.count", 1, MAX_DESIGNS)
        if method == "sobol" and count & (count - 1):
            raise r.fail("sampling.count", f"{count} must be a power of two for sobol (balance of the sequence)")
        if all(ps.is_list for ps in params):
            raise r.fail("sampling.method", f"{method} needs at least one parameter with a range")
    ev = r.table(raw.get("evaluation", {}), "evaluation", ("seeds", "samples", "seed"))
    seeds = r.integer(ev.get("seeds", 4), "evaluation.seeds", 1, 64)
    samples = r.integer(ev.get("samples", 5000), "evaluation.samples", max(seeds, 100), 5_000_000)
    eval_seed = r.integer(ev.get("seed", task.seed), "evaluation.seed", 0, 2 ** 31 - 1)
    metrics = DEFAULT_METRICS
    if "metrics" in raw:
        m = raw["metrics"]
        if not isinstance(m, list) or not m:
            raise r.fail("metrics", f"must be a non-empty list; allowed: {', '.join(METRICS)}")
        metrics = tuple(dict.fromkeys(r.string(x, f"metrics[{i}]", METRICS) for i, x in enumerate(m)))
        for i, x in enumerate(m):
            if x in CYCLE_METRICS and task.cycle is None:
                raise r.fail(f"metrics[{i}]", f"{x!r} needs a motion cycle: the task has no [cycle] table")
    archs = _architectures(r, raw.get("architecture"), task)
    size = math.prod(len(ps.values) if ps.is_list else (ps.count if method == "grid" else 1) for ps in params)
    size *= (count or 1) * len(archs)
    if size > MAX_DESIGNS:
        raise r.fail("parameters", f"{size} designs; at most {MAX_DESIGNS} per sweep file")
    title = r.string(raw.get("title", ""), "title")
    placement = raw.get("placement", False)
    if not isinstance(placement, bool):
        raise r.fail("placement", f"must be true or false, got {placement!r}")
    return Sweep(placement=placement, name=name, task=task, parameters=params, architectures=archs,
                 sampling=method, count=count,
                 seed=seed, seeds=seeds, samples=samples, eval_seed=eval_seed, metrics=metrics, title=title,
                 source=path or "")


def _parameters(r: _Reader, raw: Any, chain) -> tuple[ParameterSpace, ...]:
    r.table(raw, "parameters", tuple(chain.parameters))
    if not raw:
        raise r.fail("parameters", f"empty; {chain.name} has design parameters {', '.join(chain.parameters) or 'none'}")
    out = []
    for name in chain.parameters:                    # the robot's order, so design vectors line up
        if name not in raw:
            continue
        f = f"parameters.{name}"
        tab = r.table(raw[name], f, ("range", "count", "values"))
        par = chain.parameters[name]
        scale = chain.length_scale if par.kind == "length" else chain.angle_scale
        lo_b, hi_b = par.bounds

        def inside(x: float, fld: str) -> float:
            v = x * scale
            if not lo_b - 1e-12 * max(1.0, abs(lo_b)) <= v <= hi_b + 1e-12 * max(1.0, abs(hi_b)):
                raise r.fail(fld, f"{x:g} is outside the parameter's bounds [{lo_b / scale:g}, {hi_b / scale:g}]")
            return min(max(v, lo_b), hi_b)
        if "values" in tab:
            if "range" in tab or "count" in tab:
                raise r.fail(f, "give values, or range (with count for a grid), not both")
            vals = tab["values"]
            if not isinstance(vals, list) or not vals or len(vals) > 100_000:
                raise r.fail(f"{f}.values", "must be a non-empty list of numbers")
            si = [inside(r.number(x, f"{f}.values[{i}]"), f"{f}.values[{i}]") for i, x in enumerate(vals)]
            out.append(ParameterSpace(name, min(si), max(si), len(si), tuple(dict.fromkeys(si))))
            continue
        if "range" not in tab:
            raise r.fail(f"{f}.range", "missing (give range = [low, high] or values = [...])")
        lo, hi = r.vector(tab["range"], f"{f}.range", 2)
        if not lo < hi:
            raise r.fail(f"{f}.range", f"[{lo:g}, {hi:g}] must have low < high")
        count = r.integer(tab["count"], f"{f}.count", 1, 100_000) if "count" in tab else 0
        out.append(ParameterSpace(name, inside(lo, f"{f}.range"), inside(hi, f"{f}.range"), count))
    return tuple(out)


def _architectures(r: _Reader, raw: Any, task: Task) -> tuple[str, ...]:
    """The task-file reader's joint-type strings ("" = the robot's own), less those pruned because
    the task's orientation requirement needs more revolute joints."""
    from design.architecture import required_revolute
    archs = _task_architectures(r, raw, task.robot.n) if raw is not None else tuple(task.architectures)
    archs = archs or ("",)
    need = required_revolute(task)
    kept = tuple(a for a in archs if a == "" or a.count("R") >= need)
    if not kept:
        raise r.fail("architecture", f"every architecture has fewer than the {need} revolute joints the task's "
                                     f"{task.targets.orientation} orientation requirement needs")
    return kept
