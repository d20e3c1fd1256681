"""Helpers of the composition tests, independent of design.compose's enumeration and bounds: every
assembly of a structure listed by itertools over the catalogue's modules and the twists each pair of
connectors allows (kin.modules), judged directly — the assembled robot must hold itself
(kin.modules.assemble refuses one that provably cannot) and the reach study must reach every target."""
from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

import kin
from design.reach import ReachSettings
from design.reach.score import ScoreWeights
from design.reach.study import ReachProblem
from design.task import Targets
from kin.modules import Assembly, AssemblyError, assemble, load_catalogue

HERE = Path(__file__).resolve().parent
CATALOGUE = HERE / "compose_catalogue.toml"
#: a light reach study: the search and the direct judgement use the same one
LIGHT = ReachSettings(starts=4, samples=1024, spins=4, max_iter=100)


def catalogue():
    return load_catalogue(CATALOGUE)


def every_assembly(cat, joints: tuple[int, int], links_per_joint: int, tools=(None,), bases=None):
    """(Assembly, cost) of every assembly of the structure, by brute force: every module sequence
    base, (joint, up to k links) × n, tool-or-none, every twist each mating allows (none: not formed)."""
    bases = bases or [m.name for m in cat.of_kind("base")]
    jn = [m.name for m in cat.of_kind("joint")]
    ln = [m.name for m in cat.of_kind("link")]
    segs = [(j, *ls) for j in jn for r in range(links_per_joint + 1) for ls in itertools.product(ln, repeat=r)]
    out = []
    for b in bases:
        for n in range(joints[0], joints[1] + 1):
            for chosen in itertools.product(segs, repeat=n):
                for t in tools:
                    names = [b, *itertools.chain.from_iterable(chosen)] + ([t] if t else [])
                    mods = [cat.modules[x] for x in names]
                    options = [cat.twists(p.output, m.input) for p, m in zip(mods, mods[1:])]
                    for tw in itertools.product(*options):
                        a = Assembly(tuple(names), tuple(tw))
                        out.append((a, a.cost(cat)))
    return out


def order_key(cat, a: Assembly, cost: float):
    return cost, len(a.joints(cat)), a.text(cat)


def direct_feasible(cat, a: Assembly, targets: Targets, settings: ReachSettings = LIGHT) -> bool:
    """Holds itself (assemble with the holding check) and reaches every target (no cell, at the origin)."""
    try:
        chain = assemble(cat, a, check_holding=True)
    except AssemblyError:
        return False
    pb = ReachProblem(kin.Robot(chain, backend="vm"), targets, None, 0.0, None, ScoreWeights(dexterity_ref=1.0),
                      settings, None)
    return bool(np.all(pb.run(np.eye(4))["reached"]))


def targets_of(cat, text: str, degrees, tolerance: float = 1e-4) -> Targets:
    """Target points: the tool point of assembly ``text`` at joint values ``degrees`` (one row each),
    by the modules' own product of transforms (kin.modules.module_frames)."""
    from kin.modules import module_frames
    a = Assembly.parse(text, cat)
    P = [module_frames(cat, a, np.radians(q))[-1][1][:3, 3] for q in degrees]
    return Targets(np.array(P), tolerance=tolerance)
