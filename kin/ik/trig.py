"""The small pieces the closed-form IK solvers share (:mod:`kin.ik.analytic`, :mod:`kin.ik.parallel`):
elementary homogeneous transforms and the solutions of a·cos x + b·sin x = c."""
from __future__ import annotations

import math

import numpy as np

from kin.transforms import make_transform, rot_x, rot_z

__all__ = ["EPS", "rx", "rz", "trans", "two_angles"]

#: below this, a length or an amplitude counts as zero
EPS = 1e-12


def rx(a: float) -> np.ndarray:
    """4×4 rotation by ``a`` about x."""
    return make_transform(rot_x(a))


def rz(t: float) -> np.ndarray:
    """4×4 rotation by ``t`` about z."""
    return make_transform(rot_z(t))


def trans(x: float = 0.0, z: float = 0.0) -> np.ndarray:
    """4×4 translation by ``x`` along x and ``z`` along z."""
    T = np.eye(4)
    T[0, 3], T[2, 3] = x, z
    return T


def two_angles(a: float, b: float, c: float) -> list[float]:
    """Solutions of a·cos x + b·sin x = c: none when |c| > √(a² + b²) beyond rounding, the tangent one
    when |c| equals it within rounding, else two."""
    rho = math.hypot(a, b)
    if rho < EPS:
        return []
    ratio = c / rho
    if abs(ratio) > 1 + 1e-9:
        return []
    phi = math.atan2(b, a)
    delta = math.acos(max(-1.0, min(1.0, ratio)))
    return [phi + delta, phi - delta] if delta > 1e-12 else [phi]
