"""A stand-in judge for the verdict-cache tests: real work on a real assembly (the chain built from
the modules, its holding check, its reach radius against the part's farthest target), module level so
that worker processes and Dask workers import it, and a call counter (this process only)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from design.task import Targets, Task
from kin.modules import Assembly, assemble, holding, load_catalogue

CATALOGUE = Path(__file__).resolve().parents[2] / "kin" / "modules" / "small_catalogue.toml"
CALLS = [0]


@dataclass(frozen=True)
class StandInVerdict:
    """The fields of design.compose.verdict.Verdict (the contract)."""

    assembly: str
    part: str
    feasible: bool
    stage: str
    reason: str
    reached: int
    targets: int
    cycle_time: float | None
    torque_ratio: float | None
    seconds: float


def stand_in_judge(catalogue, assembly: Assembly, part, settings) -> StandInVerdict:
    CALLS[0] += 1
    chain = assemble(catalogue, assembly, check_holding=False)
    rep = holding(chain)
    radius = sum(abs(j.a) + abs(j.d) for j in chain.joints) + float(np.linalg.norm(chain.tool.matrix[:3, 3]))
    dist = np.linalg.norm(part.targets.positions - chain.base.matrix[:3, 3], axis=1)
    reached = int(np.sum(dist <= radius))
    text = assembly.text(catalogue)
    if rep.fails:
        return StandInVerdict(text, part.name, False, "holding", "a joint cannot hold the chain", 0, len(dist),
                              None, None, 0.0)
    ok = reached == len(dist)
    return StandInVerdict(text, part.name, ok, "ok" if ok else "reach_bound", f"radius {radius:.6f} m", reached,
                          len(dist), None, float(np.max(rep.bound)), 0.0)


def failing_judge(catalogue, assembly, part, settings):
    raise ValueError("no verdict here")


def catalogue():
    return load_catalogue(CATALOGUE)


def part(name: str, points) -> Task:
    return Task(name=name, robot=None, targets=Targets(np.asarray(points, float)), source=f"{name}.toml")


def pairs(cat, parts):
    texts = ["B JS LS JL T", "B JS LL JL T", "B JS LL JS@90 LS JL T", "B JL LE JL T", "B JS LE@180 JS T"]
    return [(Assembly.parse(t, cat), p) for t in texts for p in parts]
