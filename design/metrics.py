"""Design metrics besides coverage (:mod:`design.coverage`): the structural length Σ(|a_i| + |d_i|),
the converged workspace volume, and the structural length index Q_L = Σ(|a_i| + |d_i|) / ∛V.
The global conditioning index (mean 1/κ over the covered targets) is :attr:`Coverage.gci`.
Everything SI."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import kin

__all__ = ["structural_length", "ConvergedVolume", "converged_volume", "length_index", "design_metrics"]


def structural_length(chain: kin.Chain, params=None) -> float:
    """Σ over the joints of |a_i| + |d_i| (m), design parameters resolved (``params`` SI vector or None).
    A prismatic joint's d is its fixed offset (the stroke is not a link)."""
    tab = chain.dh_table(None if params is None else np.asarray(params, float))
    return float(np.abs(tab[:, 0]).sum() + np.abs(tab[:, 2]).sum())


@dataclass(frozen=True)
class ConvergedVolume:
    """A workspace volume (m³, or area m² for a planar chain) with its convergence: ``history`` the
    (samples, volume) pairs, ``voxel`` the fixed cell side (m), ``converged`` whether the last
    doubling changed the volume by less than ``tolerance`` (relative)."""

    volume: float
    voxel: float
    samples: int
    converged: bool
    tolerance: float
    history: tuple[tuple[int, float], ...]
    dimension: int


def converged_volume(robot: kin.Robot, params=None, start: int = 20_000, tolerance: float = 0.02,
                     max_samples: int = 2_000_000, voxel: float | None = None, seed: int = 0) -> ConvergedVolume:
    """Voxel volume with samples doubled (same seed, same voxel) until it changes by less than
    ``tolerance`` relative, or ``max_samples`` is reached (then ``converged`` is False).

    The voxel is fixed from the first cloud's bounding box (longest side / 64) so that only the
    sampling changes between steps; the volume is stated with it.
    """
    from design.workspace import compute_workspace
    if not (0 < tolerance < 1) or start < 100 or max_samples < start:
        raise kin.RmtError(f"converged_volume: tolerance {tolerance} must be in (0, 1), start ≥ 100, "
                           f"max_samples ≥ start")
    n = start
    hist: list[tuple[int, float]] = []
    while True:
        ws = compute_workspace(robot, n_samples=n, method="random", seed=seed, voxel=voxel, params=params)
        voxel = ws.voxel
        v = ws.volume if ws.dimension == 3 else (ws.area or 0.0)
        hist.append((n, float(v)))
        if len(hist) > 1 and abs(v - hist[-2][1]) <= tolerance * max(abs(v), 1e-300):
            return ConvergedVolume(float(v), float(voxel), n, True, tolerance, tuple(hist), ws.dimension)
        if 2 * n > max_samples:
            return ConvergedVolume(float(v), float(voxel), n, False, tolerance, tuple(hist), ws.dimension)
        n *= 2


def length_index(robot: kin.Robot, params=None, samples: int = 20_000, seed: int = 0,
                 tolerance: float = 0.02) -> float:
    """Structural length index Q_L = Σ(|a_i| + |d_i|) / ∛V (dimensionless; √A for a planar chain),
    V the converged workspace volume."""
    p = robot.chain.parameter_vector(params)
    cv = converged_volume(robot, p, start=samples, tolerance=tolerance, seed=seed)
    root = cv.volume ** (1 / 3) if cv.dimension == 3 else cv.volume ** 0.5
    return structural_length(robot.chain, p) / root if root > 0 else float("inf")


def design_metrics(robot: kin.Robot, params, gci: float, volume: bool = False, samples: int = 50_000,
                   tolerance: float = 0.02, max_samples: int = 2_000_000, seed: int = 0) -> dict:
    """The metrics of one design (SI): structural length, GCI (given, from the coverage), and with
    ``volume`` the converged workspace volume (with its voxel, samples, convergence) and Q_L."""
    p = robot.chain.parameter_vector(params)
    out = {"structural_length_m": structural_length(robot.chain, p), "gci": gci}
    if volume:
        cv = converged_volume(robot, p, start=samples, tolerance=tolerance, max_samples=max_samples, seed=seed)
        root = cv.volume ** (1 / 3) if cv.dimension == 3 else cv.volume ** 0.5
        out["workspace"] = {"volume": cv.volume, "unit": "m^3" if cv.dimension == 3 else "m^2", "voxel_m": cv.voxel,
                            "samples": cv.samples, "converged": cv.converged, "tolerance": cv.tolerance,
                            "history": [list(h) for h in cv.history]}
        out["length_index"] = out["structural_length_m"] / root if root > 0 else None
    return out
