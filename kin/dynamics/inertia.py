"""The inertial model of a link: mass, centre of mass, inertia tensor, motor inertia and friction.

A :class:`LinkInertia` belongs to a body of the chain: joint k's link is body k and carries DH frame k
(the frame that moves with joint k, :mod:`kin.chain`); the payload sits in the tool frame.  Values are
SI: mass kg, centre of mass m in the body's frame, the inertia tensor kg·m² about the centre of mass
in the axes of the body's frame, given as (ixx, iyy, izz, ixy, ixz, iyz) with
I = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]].  ``motor_inertia`` (kg·m² for a revolute
joint, kg for a prismatic one) is the rotor's inertia reflected through the gearbox, added to the
joint's diagonal of the mass matrix; ``viscous`` (N·m·s/rad or N·s/m) and ``coulomb`` (N·m or N)
friction act on the joint.

A physical rigid body has m ≥ 0 and an inertia tensor that is symmetric positive semi-definite
with principal moments obeying the triangle inequality (each ≤ the sum of the other two); anything
else is refused with one line naming the body and the value (:class:`InertiaError`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kin.errors import RmtError

__all__ = ["LinkInertia", "InertiaError", "MAX_MASS"]

#: the largest mass (kg) a body may have: far beyond any machine tool's link
MAX_MASS = 1e6


class InertiaError(RmtError, ValueError):
    """An inertial value is not physical (negative mass, an inertia that is not positive semi-definite
    or violates the triangle inequality, NaN); the message names the body and the value."""


def _finite(v, what: str, n: int | None = None) -> tuple[float, ...] | float:
    try:
        arr = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise InertiaError(f"{what} = {v!r} must be {'a number' if n is None else f'{n} numbers'}") from None
    if isinstance(v, bool) or (n is None and arr.shape != ()) or (n is not None and arr.shape != (n,)):
        raise InertiaError(f"{what} = {v!r} must be {'a number' if n is None else f'{n} numbers'}")
    if not np.all(np.isfinite(arr)):
        raise InertiaError(f"{what} = {v!r} holds NaN or infinite values")
    return float(arr) if n is None else tuple(float(x) for x in arr)


@dataclass(frozen=True)
class LinkInertia:
    """One body's inertial parameters (SI; see the module text).  ``body`` names it in messages."""

    mass: float
    com: tuple[float, float, float] = (0.0, 0.0, 0.0)
    inertia: tuple[float, float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    motor_inertia: float = 0.0
    viscous: float = 0.0
    coulomb: float = 0.0
    body: str = ""

    def __post_init__(self):
        who = f"{self.body}: " if self.body else ""
        m = _finite(self.mass, f"{who}mass (kg)")
        if not 0.0 <= m <= MAX_MASS:
            raise InertiaError(f"{who}mass = {m:g} kg must be in [0, {MAX_MASS:g}] kg")
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "com", _finite(self.com, f"{who}centre of mass (m)", 3))
        object.__setattr__(self, "inertia", _finite(self.inertia, f"{who}inertia (kg·m²)", 6))
        for name in ("motor_inertia", "viscous", "coulomb"):
            v = _finite(getattr(self, name), f"{who}{name}")
            if v < 0:
                raise InertiaError(f"{who}{name} = {v:g} must be ≥ 0")
            object.__setattr__(self, name, v)
        w = np.linalg.eigvalsh(self.tensor)
        scale = max(float(np.abs(w).max()), 1e-300)
        tol = 1e-9 * scale
        if w[0] < -tol:
            raise InertiaError(f"{who}inertia tensor {self.inertia} is not positive semi-definite (smallest "
                               f"principal moment {w[0]:.6g} kg·m²)")
        if w[2] > w[0] + w[1] + tol:
            raise InertiaError(f"{who}inertia tensor {self.inertia} violates the triangle inequality: principal "
                               f"moment {w[2]:.6g} > {w[0]:.6g} + {w[1]:.6g} kg·m² (no rigid body has it)")
        if m == 0.0 and scale > 1e-300 and float(np.abs(w).max()) > 0:
            raise InertiaError(f"{who}a massless body cannot have an inertia tensor {self.inertia}")

    @property
    def tensor(self) -> np.ndarray:
        """The 3×3 inertia tensor about the centre of mass (kg·m²)."""
        ixx, iyy, izz, ixy, ixz, iyz = self.inertia
        return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])

    def about_origin(self) -> np.ndarray:
        """The 3×3 inertia tensor about the body frame's origin (parallel-axis theorem, kg·m²)."""
        c = np.asarray(self.com)
        return self.tensor + self.mass * (float(c @ c) * np.eye(3) - np.outer(c, c))

    def scaled(self, length_scale: float) -> "LinkInertia":
        """The same body with lengths given in a unit of ``length_scale`` m: com × s, inertia × s²."""
        s = float(length_scale)
        return LinkInertia(self.mass, tuple(x * s for x in self.com), tuple(x * s * s for x in self.inertia),
                           self.motor_inertia, self.viscous, self.coulomb, self.body)

    def transformed(self, T) -> "LinkInertia":
        """The same body described in another frame: ``T`` (4×4, rigid) maps this frame's points into
        the new frame's; the centre of mass moves, the tensor turns (R·I·Rᵀ)."""
        T = np.asarray(T, dtype=float)
        R, p = T[:3, :3], T[:3, 3]
        c = R @ np.asarray(self.com) + p
        M = R @ self.tensor @ R.T
        M = (M + M.T) / 2
        return LinkInertia(self.mass, tuple(float(x) for x in c),
                           (float(M[0, 0]), float(M[1, 1]), float(M[2, 2]), float(M[0, 1]), float(M[0, 2]),
                            float(M[1, 2])), self.motor_inertia, self.viscous, self.coulomb, self.body)

    @staticmethod
    def combined(parts, body: str = "") -> "LinkInertia":
        """One rigid body made of ``parts`` (LinkInertia in one frame): masses add, the centre of mass
        is the mass-weighted mean, the tensors meet at it by the parallel-axis theorem.  Motor
        inertia and friction add too (they belong to the joint; at most one part should carry them)."""
        parts = list(parts)
        if not parts:
            raise InertiaError(f"{body + ': ' if body else ''}no parts to combine")
        m = sum(p.mass for p in parts)
        if m == 0.0:
            c = np.zeros(3)
        else:
            c = sum(p.mass * np.asarray(p.com) for p in parts) / m
        M = np.zeros((3, 3))
        for p in parts:
            d = np.asarray(p.com) - c
            M += p.tensor + p.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
        M = (M + M.T) / 2
        return LinkInertia(m, tuple(float(x) for x in c),
                           (float(M[0, 0]), float(M[1, 1]), float(M[2, 2]), float(M[0, 1]), float(M[0, 2]),
                            float(M[1, 2])), sum(p.motor_inertia for p in parts), sum(p.viscous for p in parts),
                           sum(p.coulomb for p in parts), body)

    @staticmethod
    def is_close(a: "LinkInertia | None", b: "LinkInertia | None", tol: float = 1e-12) -> bool:
        if a is None or b is None:
            return a is b
        return (math.isclose(a.mass, b.mass, rel_tol=tol, abs_tol=tol)
                and np.allclose(a.com, b.com, rtol=tol, atol=tol) and np.allclose(a.inertia, b.inertia, rtol=tol,
                                                                                     atol=tol))
