"""Joint-type architectures: the 2ⁿ R/P choices of an n-joint skeleton (the architectural styles of
a reconfigurable machine), each optimised and verified, then ranked.

A skeleton is the task's robot: its DH rows (α, fixed θ, parameterised a and d) stay; changing a
joint's type changes which DH value is the joint variable.  A joint that becomes revolute gets
limits ±π with its old θ as the offset; one that becomes prismatic gets its old d as the offset
and the stroke of the skeleton's first prismatic joint (or ``stroke``).  A string is pruned
before optimisation when it has fewer revolute joints than the task's orientation requirement
needs (an axis needs two, a full pose three; a PPP chain cannot turn the tool).
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field, replace
from typing import Callable

import kin
from design.optimise import DesignResult, VerifySettings, optimise
from design.task.model import Task, TaskError

__all__ = ["all_architectures", "with_joint_types", "required_revolute", "ArchitectureRanking",
           "optimise_architectures"]


def all_architectures(n: int) -> list[str]:
    """The 2ⁿ joint-type strings of n joints, "RR…R" first."""
    if not 1 <= n <= 12:
        raise TaskError(f"{n} joints: architectures are enumerated for 1 to 12 joints")
    return ["".join(t) for t in itertools.product("RP", repeat=n)]


def required_revolute(task: Task) -> int:
    """Revolute joints the task's orientation requirement needs at least."""
    return {"free": 0, "axis": 2, "cone": 2, "pose": 3}[task.targets.orientation]


def with_joint_types(chain: kin.Chain, types: str, stroke: tuple[float, float] | None = None) -> kin.Chain:
    """The skeleton ``chain`` with joint types from ``types`` ("R"/"P" per joint); SI limits."""
    if len(types) != chain.n or set(types) - {"R", "P"}:
        raise TaskError(f"architecture {types!r} must be {chain.n} letters R or P")
    if stroke is None:
        pris = [j.limits for j in chain.joints if not j.is_revolute]
        stroke = pris[0] if pris else (0.0, 1.0)
    joints = []
    for j, t in zip(chain.joints, types):
        if (t == "R") == j.is_revolute:
            joints.append(j)
        elif t == "R":
            joints.append(replace(j, type="revolute", limits=(-math.pi, math.pi), max_velocity=None,
                                  max_acceleration=None, max_torque=None))
        else:
            joints.append(replace(j, type="prismatic", limits=tuple(stroke), max_velocity=None,
                                  max_acceleration=None, max_torque=None))
    name = f"{chain.name}_{types.lower()}"
    return replace(chain, name=name, joints=tuple(joints), title=f"{chain.title} as {types}")


@dataclass
class ArchitectureRanking:
    """Architectures ranked: feasible first, then by the verified objective.  ``results`` holds the
    optimised design per evaluated string; ``pruned`` the strings skipped with the reason;
    ``errors`` the strings whose optimisation failed with the message."""

    objective: str
    order: list[str]
    results: dict[str, DesignResult]
    pruned: dict[str, str] = field(default_factory=dict)
    errors: dict[str, str] = field(default_factory=dict)

    @property
    def names(self) -> list[str]:
        return list(self.order)

    @property
    def objectives(self) -> list[float]:
        return [self.results[a].objective for a in self.order]

    @property
    def coverages(self) -> list[float]:
        return [self.results[a].verification.fraction for a in self.order]

    @property
    def feasible(self) -> list[bool]:
        return [self.results[a].feasible for a in self.order]

    def table(self) -> str:
        """The ranking as text, one line per architecture."""
        lines = [f"{'rank':>4}  {'arch':<6} {'feasible':<8} {'coverage %':>10}  {self.objective}"]
        for i, a in enumerate(self.order, 1):
            r = self.results[a]
            lines.append(f"{i:>4}  {a:<6} {'yes' if r.feasible else 'no':<8} {100 * r.verification.fraction:>10.1f}  "
                         f"{r.objective:.6g}")
        lines += [f"   -  {a:<6} pruned: {why}" for a, why in self.pruned.items()]
        lines += [f"   -  {a:<6} failed: {msg}" for a, msg in self.errors.items()]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {"objective": self.objective,
                "ranking": [self.results[a].to_dict() | {"rank": i} for i, a in enumerate(self.order, 1)],
                "pruned": self.pruned, "errors": self.errors}


def optimise_architectures(task: Task, architectures: list[str] | None = None, method: str = "ipopt",
                           starts: int = 2, seed: int = 0, settings: VerifySettings | None = None,
                           max_time: float = 600.0, progress: Callable[[str], None] | None = None,
                           **options) -> ArchitectureRanking:
    """Optimise every architecture (default: the task's list, else all 2ⁿ) and rank them."""
    archs = list(architectures or task.architectures or all_architectures(task.robot.n))
    need = required_revolute(task)
    results, pruned, errors = {}, {}, {}
    budget = max_time / max(len(archs), 1)
    for a in archs:
        if a.count("R") < need:
            pruned[a] = (f"{a.count('R')} revolute joint(s); the {task.targets.orientation} orientation "
                         f"requirement needs {need}")
            continue
        robot = kin.Robot(with_joint_types(task.robot.chain, a))
        sub = replace(task, robot=robot, architectures=())
        try:
            results[a] = optimise(sub, method=method, starts=starts, seed=seed, settings=settings,
                                  max_time=budget, **options)
            results[a].architecture = a
        except (kin.RmtError, RuntimeError) as e:
            errors[a] = str(e).splitlines()[0] if str(e) else type(e).__name__
        if progress:
            r = results.get(a)
            progress(f"{a}: " + (f"coverage {100 * r.verification.fraction:.1f} %, {task.objective} "
                                 f"{r.objective:.6g}" if r else f"failed: {errors[a]}"))
    sign = -1.0 if task.objective in ("coverage", "gci") else 1.0
    order = sorted(results, key=lambda a: (not results[a].feasible, -results[a].verification.fraction
                                           if not results[a].feasible else 0.0, sign * results[a].objective))
    return ArchitectureRanking(task.objective, order, results, pruned, errors)
