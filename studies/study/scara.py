"""The SCARA in closed form: where an arm of two horizontal links A1, A2 (revolute J1, J2 about
vertical axes) and a vertical prismatic J3 reaches a target with a required dexterity — an
independent check of the IK-verified coverage of :mod:`design.coverage`, and the shortest such arm.

The arm reaches a point at horizontal radius r iff |A1 − A2| ≤ r ≤ A1 + A2
(cos q2 = (r² − A1² − A2²)/(2·A1·A2)), on one of the two elbow branches ±q2, with
q1 = atan2(y, x) − atan2(A2·sin q2, A1 + A2·cos q2); both joints must be inside their limits, and the
height z must be inside J3's stroke.  The translational Jacobian is block-diagonal (the planar 2×2
block and J3's unit column), so σ_min = min(σ_min(2×2), 1) with, for the 2×2 block,
σ_min² = (F − √(F² − 4·det²))/2, F = A1² + 2·A2² + 2·A1·A2·cos q2 (its squared Frobenius norm) and
det = A1·A2·sin q2.  Everything SI (m, rad, m/rad); joint limits ``lower``, ``upper`` are the
chain's (J1, J2 in rad, J3 in m).

    from studies.study.scara import scara_covered
    covered = scara_covered([0.25], [0.2], task.targets.positions, chain.lower, chain.upper, 0.08, z0)
"""
from __future__ import annotations

import numpy as np

__all__ = ["scara_sigma", "scara_covered", "closed_form_map", "closed_form_optimum"]


def scara_sigma(l1, l2, xy: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Best σ_min (m/rad) of the translational Jacobian over the elbow branches inside the limits of
    J1, J2, for designs ``l1``, ``l2`` (D,) m and points ``xy`` (N, 2) m: (D, N), NaN where no
    branch reaches the point."""
    l1 = np.atleast_1d(np.asarray(l1, float))[:, None]
    l2 = np.atleast_1d(np.asarray(l2, float))[:, None]
    x, y = xy[:, 0][None], xy[:, 1][None]
    c2 = (x ** 2 + y ** 2 - l1 ** 2 - l2 ** 2) / (2 * l1 * l2)
    reach = np.abs(c2) <= 1.0
    c2 = np.clip(c2, -1.0, 1.0)
    best = np.full(c2.shape, np.nan)
    for sign in (1.0, -1.0):
        q2 = sign * np.arccos(c2)
        q1 = np.arctan2(y, x) - np.arctan2(l2 * np.sin(q2), l1 + l2 * np.cos(q2))
        q1 = (q1 + np.pi) % (2 * np.pi) - np.pi
        inside = reach & (q1 >= lower[0]) & (q1 <= upper[0]) & (q2 >= lower[1]) & (q2 <= upper[1])
        F = l1 ** 2 + 2 * l2 ** 2 + 2 * l1 * l2 * np.cos(q2)
        det = l1 * l2 * np.sin(q2)
        sigma = np.minimum(np.sqrt(np.maximum((F - np.sqrt(np.maximum(F ** 2 - 4 * det ** 2, 0.0))) / 2, 0.0)), 1.0)
        best = np.where(inside & ~(best >= sigma), sigma, best)
    return best


def scara_covered(l1, l2, positions: np.ndarray, lower: np.ndarray, upper: np.ndarray, sigma_min: float,
                  z0: float) -> np.ndarray:
    """(D, N) bool: target ``positions`` (N, 3) m covered by design (l1, l2) with σ_min ≥ ``sigma_min``;
    ``z0`` the tool height at q3 = 0 (the sum of the fixed d's), so q3 = z − z0 must be in J3's stroke."""
    sigma = scara_sigma(l1, l2, positions[:, :2], lower, upper)
    z_ok = (positions[:, 2] - z0 >= lower[2]) & (positions[:, 2] - z0 <= upper[2])
    return (np.nan_to_num(sigma, nan=-1.0) >= sigma_min * (1 - 1e-9)) & z_ok[None]


def closed_form_map(axis: np.ndarray, positions: np.ndarray, lower, upper, sigma_min: float, z0: float) -> np.ndarray:
    """Covered share of the targets (0..1) in closed form over the design plane ``axis`` × ``axis``
    (A1 along the first index, A2 along the second), m."""
    A1, A2 = np.meshgrid(axis, axis, indexing="ij")
    cov = scara_covered(A1.ravel(), A2.ravel(), positions, lower, upper, sigma_min, z0)
    return cov.mean(axis=1).reshape(A1.shape)


def closed_form_optimum(positions, lower, upper, sigma_min: float, z0: float, bounds,
                        coarse: float = 1e-3, steps: tuple[float, ...] = (1e-4, 1e-5), margin: float = 5e-3):
    """The shortest design (A1, A2) m covering every target, in closed form, to the last of ``steps``.

    A ``coarse`` grid over the bounds finds the valley of short covering designs; each refinement then
    searches the band of lengths A1 + A2 just below the best so far (``margin``, then ten steps of the
    previous refinement) over the valley's A1 range, A2 = length − A1, at its step.  None when no
    design of the coarse grid covers every target."""
    def covering(A1, A2):
        keep = (A2 >= bounds[1, 0]) & (A2 <= bounds[1, 1])
        A1, A2 = A1[keep], A2[keep]
        ok = scara_covered(A1, A2, positions, lower, upper, sigma_min, z0).all(axis=1)
        return A1[ok], A2[ok]

    def axis(lo, hi, step):
        return np.linspace(lo, hi, int(round((hi - lo) / step)) + 1)

    A1, A2 = covering(*(g.ravel() for g in np.meshgrid(axis(*bounds[0], coarse), axis(*bounds[1], coarse),
                                                       indexing="ij")))
    if not len(A1):
        return None
    prev, width = coarse, margin
    for step in steps:
        best = (A1 + A2).min()
        valley = A1 + A2 <= best + prev + 1e-12
        a1 = axis(max(A1[valley].min() - 2 * prev, bounds[0, 0]), min(A1[valley].max() + 2 * prev, bounds[0, 1]), step)
        lengths = axis(best - width, best, step)
        N1, N2 = covering(np.repeat(a1, len(lengths)), np.tile(lengths, len(a1)) - np.repeat(a1, len(lengths)))
        if len(N1):
            A1, A2 = N1, N2
        prev, width = step, 10 * step
    i = int(np.argmin(A1 + A2))
    return np.array([A1[i], A2[i]])
