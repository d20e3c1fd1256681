"""Reachable and functional workspace of a chain, estimated by sampling joint space.

The workspace is sampled and made measurable: sample the joint space (a per-joint grid, or a
scrambled Sobol / uniform random sequence with a seed), map every sample through forward
kinematics, and keep the tool positions (N, 3) together with one dexterity measure per sample.
Samples whose measure falls below a threshold are *near-singular*; the others form the sampled
*functional workspace*, where the arm keeps the dexterity the threshold asks for.

Volume is estimated by voxel occupancy.  The positions are binned into cubes of side ``voxel``
anchored at the lower corner of the cloud's bounding box, and

    V ≈ (number of occupied voxels) · voxel³.

This estimate has two biases that go opposite ways: voxels cut by the boundary count in full
(overestimate, about ½·surface·voxel), and voxels inside the workspace that happen to hold no
sample are missed (underestimate, small when there are many samples per voxel).  State the voxel
size with the number; :class:`Workspace` carries it.  The functional volume counts the voxels
holding at least one sample that is *not* near-singular.

A workspace that is planar (an axis of the bounding box with extent < 1e-9 m, e.g. the planar 2R
arm, z ≡ 0) has volume 0 by nature; its *area* is reported instead: occupied pixels · voxel², with
the same cell side (then a pixel size).

Everything is SI (m, rad).  Nothing here prints or writes files; see :mod:`studies.plots` for the
figure.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

import kin
from kin.compiled import WANT_MANIP, WANT_SIGMA, WANT_T
from kin.errors import RmtError

__all__ = ["WorkspaceError", "Workspace", "sample_joint_space", "compute_workspace", "voxel_occupancy",
           "METHODS", "MEASURES", "DEFAULT_RELATIVE_THRESHOLD", "DEFAULT_VOXELS_ALONG_LONGEST",
           "DEGENERATE_EXTENT"]

METHODS = ("sobol", "random", "grid")
#: Dexterity measures: name → (column of ``robot.evaluate(...)["measures"]``, want bits).
MEASURES = {
    "sigma_min": (1, WANT_SIGMA),          # smallest singular value of the task Jacobian
    "manipulability": (0, WANT_MANIP),     # √det(Jt·Jtᵀ)
    "inverse_condition": (2, WANT_SIGMA),  # σ_min/σ_max ∈ [0, 1], unit-free between its columns
}
#: Default near-singular threshold: this fraction of the median of the measure over the samples.
DEFAULT_RELATIVE_THRESHOLD = 0.05
#: Default voxel: the longest side of the cloud's bounding box divided by this number.
DEFAULT_VOXELS_ALONG_LONGEST = 64
#: the voxel count has converged when every other sample already occupies this share of the voxels
CONVERGED_HALF_RATIO = 0.95
#: An axis of the bounding box shorter than this (m) is degenerate (planar or linear workspace).
DEGENERATE_EXTENT = 1e-9
CHUNK = 1 << 16   # rows per evaluation call: T is kept per chunk only, J is never formed in Python
_MAX_CELLS = 1 << 62


class WorkspaceError(RmtError, ValueError):
    """A workspace request is invalid (sample count, method, measure, threshold, voxel)."""


# ---- sampling ------------------------------------------------------------------------------------
def _check_n_samples(n_samples: Any) -> int:
    if isinstance(n_samples, (bool, np.bool_)):
        raise WorkspaceError(f"n_samples must be a positive integer (>= 1); got {n_samples!r}")
    try:
        value = float(n_samples)
    except (TypeError, ValueError):
        raise WorkspaceError(f"n_samples must be a positive integer (>= 1); got {n_samples!r}") from None
    if not math.isfinite(value) or value != int(value) or value < 1:
        raise WorkspaceError(f"n_samples must be a positive integer (>= 1); got {n_samples!r}")
    return int(value)


def _check_method(method: Any) -> str:
    if method not in METHODS:
        raise WorkspaceError(f"method {method!r} unknown; allowed: {', '.join(repr(m) for m in METHODS)}")
    return method


def _check_seed(seed: Any) -> int:
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise WorkspaceError(f"seed must be a non-negative integer; got {seed!r}")
    return int(seed)


def grid_points_per_joint(n_samples: int, n: int) -> int:
    """Points per joint of the per-joint grid: the smallest k with k**n >= n_samples (k >= 2)."""
    k = max(1, int(round(n_samples ** (1.0 / n))))
    while k ** n < n_samples:          # integer correction of the floating-point root
        k += 1
    while k > 1 and (k - 1) ** n >= n_samples:
        k -= 1
    return max(k, 2)  # a one-point "grid" would not span the joint range; endpoints are included


def sample_joint_space(robot: kin.Robot, n_samples: int, method: Literal["sobol", "random", "grid"] = "sobol",
                       seed: int = 0) -> np.ndarray:
    """Configurations covering the joint limits, shape (N, n), SI (rad, m).

    ``method``:
      - ``"sobol"``: scrambled Sobol sequence (``scipy.stats.qmc.Sobol``, scrambled with ``seed``);
        2^m ≥ ``n_samples`` points are drawn with ``random_base2`` and the first ``n_samples`` kept.
      - ``"random"``: independent uniform samples, ``numpy.random.default_rng(seed)``.
      - ``"grid"``: a per-joint grid, k = ⌈n_samples^(1/n)⌉ points per joint with both
        limits included (k ≥ 2), all kⁿ combinations.  N = kⁿ ≥ ``n_samples``: the count actually
        returned is ``len(result)``, not the request.  ``seed`` is not used.

    Every row lies within ``robot.chain.lower`` … ``robot.chain.upper``.
    """
    N = _check_n_samples(n_samples)
    method = _check_method(method)
    seed = _check_seed(seed)
    lo = np.asarray(robot.chain.lower, dtype=float)
    hi = np.asarray(robot.chain.upper, dtype=float)
    n = lo.size
    if method == "grid":
        k = grid_points_per_joint(N, n)
        axes = [np.linspace(lo[i], hi[i], k) for i in range(n)]
        mesh = np.meshgrid(*axes, indexing="ij")
        return np.stack([m.ravel() for m in mesh], axis=1)
    if method == "random":
        U = np.random.default_rng(seed).random((N, n))
    else:
        from scipy.stats import qmc
        try:
            engine = qmc.Sobol(d=n, scramble=True, rng=seed)
        except TypeError:  # SciPy < 1.15 names it ``seed``
            engine = qmc.Sobol(d=n, scramble=True, seed=seed)
        m = max(0, math.ceil(math.log2(N)))
        U = engine.random_base2(m)[:N]
    return lo + U * (hi - lo)


# ---- voxels --------------------------------------------------------------------------------------
def voxel_occupancy(positions: np.ndarray, voxel: float, origin: np.ndarray,
                    axes: tuple[int, ...] = (0, 1, 2)) -> np.ndarray:
    """Sorted unique packed cell keys (int64) of the cells of side ``voxel`` (m) holding a position.

    Cells are anchored at ``origin`` (3,); only the coordinates in ``axes`` are binned (the others
    are degenerate), so the keys count voxels in 3-D, pixels in 2-D.
    """
    P = np.asarray(positions, dtype=float)
    if P.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    key = np.zeros(P.shape[0], dtype=np.int64)
    stride = 1
    for ax in axes:
        idx = np.floor((P[:, ax] - origin[ax]) / voxel).astype(np.int64)
        key += idx * stride
        stride *= int(idx.max()) + 1 if idx.size else 1
    return np.unique(key)


# ---- result --------------------------------------------------------------------------------------
@dataclass
class Workspace:
    """Sampled workspace of a chain.  Lengths in m, volumes m³, areas m².

    Arrays (one row per sample, same order as the samples):
      ``positions`` (N, 3) tool positions in the world frame (base placement included),
      ``measure`` (N,) the dexterity measure ``measure_name``,
      ``near_singular`` (N,) bool: ``measure < threshold`` (NaN counts as near-singular).
    """

    robot_name: str
    length_unit: str            # the robot file's length unit (for reports)
    length_scale: float         # metres per file length unit
    method: str
    seed: int
    n_requested: int
    n_samples: int              # actually evaluated (the grid may exceed the request)
    points_per_joint: int | None  # grid only
    positions: np.ndarray = field(repr=False)
    measure_name: str
    measure: np.ndarray = field(repr=False)
    threshold: float
    threshold_rule: str
    near_singular: np.ndarray = field(repr=False)
    n_near_singular: int
    voxel: float  # cell side, m (a pixel side when the workspace is planar)
    voxel_rule: str
    dimension: int  # non-degenerate axes of the cloud (3, or 2 for a planar workspace)
    degenerate_axes: tuple[str, ...]
    occupied: int  # occupied voxels (pixels when dimension == 2)
    functional_occupied: int
    #: voxels occupied by every other sample: the convergence check of the count (see ``converged``)
    occupied_half: int
    volume: float  # occupied · voxel³ (m³); 0 when dimension < 3
    functional_volume: float
    area: float | None  # occupied · voxel² (m²) when dimension == 2; 0 when < 2; None in 3-D
    functional_area: float | None
    bbox_min: np.ndarray
    bbox_max: np.ndarray
    reach: float  # max distance of a position from the base origin, m
    radial_reach: float  # max distance from the base z axis (the first joint axis in std DH), m
    elapsed: float  # seconds: sampling, evaluation and voxelisation

    @property
    def half_ratio(self) -> float:
        """Occupied voxels of every other sample ÷ those of all samples (1 when the count has converged)."""
        return self.occupied_half / self.occupied if self.occupied else 1.0

    @property
    def converged(self) -> bool:
        """Whether half the samples already fill ≥ 95 % of the voxels.  When not, the volume (area)
        is a lower bound that grows with the sample count: sample more, or give a larger ``voxel``."""
        return self.half_ratio >= CONVERGED_HALF_RATIO

    @property
    def n_dexterous(self) -> int:
        return self.n_samples - self.n_near_singular

    @property
    def near_singular_fraction(self) -> float:
        return self.n_near_singular / self.n_samples if self.n_samples else 0.0

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (SI units; no per-sample arrays)."""
        def f(x):
            return None if x is None else float(x)
        return {
            "robot": self.robot_name,
            "units": {"length": "m", "volume": "m^3", "area": "m^2", "file_length_unit": self.length_unit},
            "sampling": {"method": self.method, "seed": self.seed, "n_requested": self.n_requested,
                         "n_samples": self.n_samples, "points_per_joint": self.points_per_joint},
            "measure": {"name": self.measure_name, "threshold": f(self.threshold), "rule": self.threshold_rule,
                        "min": f(np.nanmin(self.measure)) if self.n_samples else None,
                        "median": f(np.nanmedian(self.measure)) if self.n_samples else None,
                        "max": f(np.nanmax(self.measure)) if self.n_samples else None},
            "counts": {"samples": self.n_samples, "near_singular": self.n_near_singular,
                       "dexterous": self.n_dexterous, "near_singular_fraction": self.near_singular_fraction},
            "voxel": {"size": f(self.voxel), "rule": self.voxel_rule, "dimension": self.dimension,
                      "degenerate_axes": list(self.degenerate_axes), "occupied": self.occupied,
                      "functional_occupied": self.functional_occupied, "occupied_half": self.occupied_half,
                      "half_ratio": self.half_ratio, "converged": self.converged},
            "volume": f(self.volume), "functional_volume": f(self.functional_volume),
            "area": f(self.area), "functional_area": f(self.functional_area),
            "bbox": {"min": [float(x) for x in self.bbox_min], "max": [float(x) for x in self.bbox_max]},
            "reach": f(self.reach), "radial_reach": f(self.radial_reach),
            "elapsed_s": f(self.elapsed),
        }


# ---- computation ---------------------------------------------------------------------------------
def _check_measure(measure: Any) -> str:
    if measure not in MEASURES:
        raise WorkspaceError(f"measure {measure!r} unknown; allowed: {', '.join(repr(m) for m in MEASURES)}")
    return measure


def _check_positive(name: str, value: Any, allow_none: bool = True) -> float | None:
    if value is None and allow_none:
        return None
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    if isinstance(value, (bool, np.bool_)) or not math.isfinite(v) or v <= 0:
        raise WorkspaceError(f"{name} must be a finite number > 0 (or None for the default); got {value!r}")
    return v


def compute_workspace(robot: kin.Robot | str, n_samples: int = 100_000,
                      method: Literal["sobol", "random", "grid"] = "sobol", seed: int = 0,
                      measure: Literal["sigma_min", "manipulability", "inverse_condition"] = "sigma_min",
                      threshold: float | None = None, voxel: float | None = None, *,
                      relative_threshold: float = DEFAULT_RELATIVE_THRESHOLD, params=None) -> Workspace:
    """Sample the joint space, evaluate FK and one dexterity measure, and estimate the volume.

    ``robot``: a :class:`kin.Robot` (or a bundled name / robot-file path).  ``n_samples``,
    ``method``, ``seed``: see :func:`sample_joint_space`.

    ``measure``: ``"sigma_min"`` (smallest singular value of the task Jacobian), ``"manipulability"``
    or ``"inverse_condition"`` (σ_min/σ_max).  A sample is near-singular when its measure is below
    ``threshold`` (absolute, in the measure's SI unit).  By default the threshold is
    ``relative_threshold`` (5 %) of the median of the measure over the samples: relative because
    σ_min of a Jacobian that mixes m/rad columns has no universal scale, and the median because it
    is robust to the few huge values near the limits.

    ``voxel``: cell side in m; by default the longest side of the cloud's bounding box / 64.
    ``params``: design-parameter values (see :meth:`kin.Robot.evaluate`); None uses the nominal ones.

    The evaluation runs in chunks of 2^16 rows; only positions and the measure are kept.
    """
    t0 = time.perf_counter()
    if isinstance(robot, str):
        robot = kin.load_robot(robot)
    measure = _check_measure(measure)
    threshold = _check_positive("threshold", threshold) if threshold is not None else None
    relative_threshold = _check_positive("relative_threshold", relative_threshold, allow_none=False)
    voxel = _check_positive("voxel", voxel)
    N_req = _check_n_samples(n_samples)
    Q = sample_joint_space(robot, N_req, method, seed)
    N = len(Q)

    col, bits = MEASURES[measure]
    want = WANT_T | bits
    P = np.empty((N, 3))
    M = np.empty(N)
    for s in range(0, N, CHUNK):
        res, _ = robot.evaluate(Q[s:s + CHUNK], want, params)
        P[s:s + CHUNK] = res["T"][:, :3, 3]
        M[s:s + CHUNK] = res["measures"][:, col]
    if measure == "inverse_condition":
        with np.errstate(divide="ignore"):
            M = 1.0 / M  # the column is σ_max/σ_min (inf when singular → 0)
    del Q

    if threshold is None:
        med = float(np.nanmedian(M))
        threshold = relative_threshold * med
        rule = f"{relative_threshold:g} x median of {measure} over the samples ({med:.6g})"
    else:
        rule = f"absolute {measure} < {threshold:.6g} (given)"
    # ~(M >= thr) makes NaN near-singular; an exactly singular sample (measure 0) always is.
    near = ~(M >= threshold) | (M <= 0.0)

    lo, hi = P.min(axis=0), P.max(axis=0)
    ext = hi - lo
    axes = tuple(i for i in range(3) if ext[i] >= DEGENERATE_EXTENT)
    dim = len(axes)
    if voxel is None:
        longest = float(ext.max())
        if longest >= DEGENERATE_EXTENT:
            voxel = longest / DEFAULT_VOXELS_ALONG_LONGEST
            vrule = f"longest bounding-box side ({longest:.6g} m) / {DEFAULT_VOXELS_ALONG_LONGEST}"
        else:
            voxel, vrule = 1e-3, "1 mm (the cloud is a single point)"
    else:
        vrule = "given"
    cells = 1.0
    for ax in axes:
        cells *= math.floor(ext[ax] / voxel) + 1
    if cells >= _MAX_CELLS:
        raise WorkspaceError(f"voxel {voxel:g} m is too small for a bounding box of {ext.max():.6g} m "
                             f"({cells:.3g} cells; at most 2^62); allowed: voxel >= {ext.max() / 2e6:.3g} m")
    occ = voxel_occupancy(P, voxel, lo, axes).size
    focc = voxel_occupancy(P[~near], voxel, lo, axes).size
    occ_half = voxel_occupancy(P[::2], voxel, lo, axes).size

    base = robot.chain.base.matrix
    d = P - base[:3, 3]
    reach = float(np.sqrt(np.max(np.einsum("ij,ij->i", d, d)))) if N else 0.0
    along = d @ base[:3, 2]
    radial = float(np.sqrt(max(0.0, np.max(np.einsum("ij,ij->i", d, d) - along ** 2)))) if N else 0.0

    if dim == 3:
        volume, fvolume, area, farea = occ * voxel ** 3, focc * voxel ** 3, None, None
    elif dim == 2:
        volume, fvolume, area, farea = 0.0, 0.0, occ * voxel ** 2, focc * voxel ** 2
    else:
        volume, fvolume, area, farea = 0.0, 0.0, 0.0, 0.0

    return Workspace(
        robot_name=robot.name, length_unit=robot.chain.length_unit, length_scale=float(robot.chain.length_scale),
        method=method, seed=int(seed), n_requested=N_req, n_samples=N,
        points_per_joint=grid_points_per_joint(N_req, robot.n) if method == "grid" else None,
        positions=P, measure_name=measure, measure=M, threshold=float(threshold), threshold_rule=rule,
        near_singular=near, n_near_singular=int(near.sum()), voxel=float(voxel), voxel_rule=vrule,
        dimension=dim, degenerate_axes=tuple("xyz"[i] for i in range(3) if i not in axes),
        occupied=int(occ), functional_occupied=int(focc), occupied_half=int(occ_half), volume=float(volume),
        functional_volume=float(fvolume),
        area=None if area is None else float(area), functional_area=None if farea is None else float(farea),
        bbox_min=lo, bbox_max=hi, reach=reach, radial_reach=radial, elapsed=time.perf_counter() - t0)
