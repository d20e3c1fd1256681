"""Co-design: the robot's placement together with its link parameters and joint types.

Each design of a sweep (link parameters × architecture, :mod:`design.sweep`) is placed by
:func:`design.place.place` (IPOPT from a few screened starts, verified by the reach study) and
stored with its coverage, mean score, structural length and placement: a sweep file with
``placement = true`` evaluates its designs with :func:`evaluate_placed_design`, so co-design
results go to SQLite, resume, and run locally or on Dask like any sweep.  :func:`pareto_front` picks
the designs no other beats on coverage, score and structural length at once.
"""
from __future__ import annotations

import numpy as np

import kin
from design.metrics import structural_length
from design.place.run import place
from design.reach.study import ReachSettings
from design.sweep.export import pareto_rows

__all__ = ["evaluate_placed_design", "pareto_front", "CODESIGN_SETTINGS"]

#: the designs no other beats on coverage, score and structural length at once (rows of a sweep)
pareto_front = pareto_rows

#: the verification effort of a co-design sweep's reach studies (per design)
CODESIGN_SETTINGS = ReachSettings(starts=4, samples=2048, spins=6, max_iter=150)


def evaluate_placed_design(job, robot: kin.Robot, design) -> dict:
    """The metrics of one design placed at its best (SI): coverage (0..1), mean_score, structural
    length, the placement x, y, z, roll, pitch, yaw, the method that found it; objective, score
    (minimised; designs below the task's ``min_coverage`` above every other) and feasible, as every
    sweep row has.  Picklable by name (module level), so Dask workers run it."""
    chain = robot.chain
    lo = np.array([p.bounds[0] for p in chain.parameters.values()])
    hi = np.array([p.bounds[1] for p in chain.parameters.values()])
    p = np.clip(design.vector(), lo, hi)
    names = list(chain.parameters)
    placed = kin.Robot(chain.with_parameters(dict(zip(names, p))).frozen()) if names else robot
    t = job.task
    res = place(placed, t.targets, cell=t.cell, region=t.region, clearance=t.clearance,
                dexterity=t.dexterity if t.dexterity.kind in ("sigma_min", "manipulability") else None,
                settings=CODESIGN_SETTINGS, starts=2, candidates=16, seed=job.seed, max_time=120.0, polish=1)
    s = res.study
    length = structural_length(chain, p)
    feasible = s.coverage >= t.min_coverage - 1e-12
    objective = length if t.objective in ("length", "length_index") else s.coverage
    score = (length if t.objective in ("length", "length_index") else -s.coverage) - 1e-3 * s.mean_score
    out = {"objective": float(objective), "score": float(score if feasible else 1e3 + (1 - s.coverage)),
           "feasible": bool(feasible), "coverage": s.coverage, "mean_score": s.mean_score,
           "structural_length": length, "placement_method": res.method}
    out.update({f"placement_{c}": float(v) for c, v in zip(("x", "y", "z", "roll", "pitch", "yaw"), res.u)})
    return out
