"""The design space of a sweep: designs (architecture + every design parameter, SI), their stable
keys, and the sampling of the swept parameters (full grid, Latin hypercube or scrambled Sobol from
``scipy.stats.qmc``, seeded, so the same file gives the same designs).

A design's values are normalised to 12 significant digits before anything else sees them: the
key is the SHA-256 of the normalised design, and the evaluation uses exactly those values, so a
design sampled twice (or proposed again by refinement) is one row of the store.
"""
from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

from design.sweep.file import Sweep

__all__ = ["Design", "normalise", "design_key", "sample_designs", "unit_to_params"]


def normalise(x: float) -> float:
    """A parameter value rounded to 12 significant digits (what keys and evaluations use)."""
    return float(f"{float(x):.12g}")


def design_key(architecture: str, params: dict[str, float]) -> str:
    """SHA-256 (hex) of the normalised design: the architecture and the sorted (name, value) pairs."""
    canon = json.dumps({"a": architecture, "p": sorted((k, normalise(v)) for k, v in params.items())},
                       separators=(",", ":"))
    return hashlib.sha256(canon.encode()).hexdigest()


@dataclass(frozen=True)
class Design:
    """One design: ``architecture`` ("" = the robot's own joint types), ``params`` name → SI value
    (every design parameter of the robot, normalised), ``key`` its stable hash, ``origin``
    ("sample" or "refine")."""

    architecture: str
    params: tuple[tuple[str, float], ...]
    key: str
    origin: str = "sample"

    @classmethod
    def make(cls, architecture: str, params: dict[str, float], origin: str = "sample") -> "Design":
        p = tuple((k, normalise(v)) for k, v in params.items())
        return cls(architecture, p, design_key(architecture, dict(p)), origin)

    @property
    def values(self) -> dict[str, float]:
        return dict(self.params)

    def vector(self) -> np.ndarray:
        """The parameter values in the robot's order (n_p,)."""
        return np.array([v for _, v in self.params])


def unit_to_params(sweep: Sweep, U: np.ndarray) -> np.ndarray:
    """Points U (M, d) of the unit cube → SI values of the ``d`` range parameters (M, d)."""
    rng = [ps for ps in sweep.parameters if not ps.is_list]
    lo = np.array([ps.low for ps in rng])
    hi = np.array([ps.high for ps in rng])
    return lo + np.asarray(U, float) * (hi - lo)


def _range_samples(sweep: Sweep) -> np.ndarray:
    """Samples (M, d) of the range parameters by the sweep's method."""
    rng = [ps for ps in sweep.parameters if not ps.is_list]
    d = len(rng)
    if d == 0:
        return np.zeros((1, 0))
    if sweep.sampling == "grid":
        axes = [np.array([(ps.low + ps.high) / 2]) if ps.count == 1 else np.linspace(ps.low, ps.high, ps.count)
                for ps in rng]
        return np.array(list(itertools.product(*axes))).reshape(-1, d)
    if sweep.sampling == "lhs":
        U = qmc.LatinHypercube(d=d, seed=sweep.seed).random(sweep.count)
    else:
        U = qmc.Sobol(d=d, scramble=True, seed=sweep.seed).random_base2(int(sweep.count).bit_length() - 1)
    return unit_to_params(sweep, U)


def sample_designs(sweep: Sweep) -> list[Design]:
    """Every design of the sweep, in a fixed order: architectures × list-parameter combinations ×
    range samples; parameters not swept keep their nominal values."""
    chain = sweep.task.robot.chain
    nominal = dict(zip(chain.parameters, chain.parameter_values))
    lists = [ps for ps in sweep.parameters if ps.is_list]
    ranged = [ps.name for ps in sweep.parameters if not ps.is_list]
    R = _range_samples(sweep)
    out: list[Design] = []
    seen: set[str] = set()
    for arch in sweep.architectures:
        for combo in itertools.product(*[ps.values for ps in lists]):
            for row in R:
                vals = dict(nominal)
                vals.update(zip((ps.name for ps in lists), combo))
                vals.update(zip(ranged, row))
                d = Design.make(arch, {k: float(v) for k, v in vals.items()})
                if d.key not in seen:
                    seen.add(d.key)
                    out.append(d)
    return out
