"""The link mass model of a design whose link lengths vary: every link a uniform thin tube, a motor
at every joint it carries, a payload at the tool — its inertias follow each design's actual DH
lengths (:class:`LinkMasses`, :func:`chain_with_masses`).

A sweep or an optimiser changes the link lengths, so fixed inertias (a robot file's
``[joints.inertial]``) would describe another machine; this model rebuilds the inertial data of
each design from a few numbers instead (SI: kg, kg/m, kg·m²):

* **links**: body k (joint k's link, DH frame k of the standard convention, :mod:`kin.dynamics`) is
  a thin uniform tube of ``mass_per_length[k]`` kg/m along its DH offsets — a rod of length |d_k|
  along joint k's axis, then a rod of length |a_k| along x_k to the origin of frame k.  A thin rod
  of mass m and length L has its centre of mass at its middle and m L²/12 about any axis across it
  through there (none about its own axis).  The moving part of a **prismatic** joint is instead a rod
  of the joint's stroke (upper − lower limit) along its axis, from the end of the d offset back
  toward the joint's housing (its position along the axis changes no torque about that axis);
* **motors**: ``motor_mass[k]`` kg is joint k's motor, a point mass on joint k's axis at the origin
  of DH frame k − 1 (the distal end of link k − 1, which carries it); joint 1's motor stands on
  the base and moves with nothing (it is accepted and ignored);
* **rotors**: ``rotor_inertia[k]`` is joint k's rotor inertia reflected through its gearbox
  (kg·m², kg for a prismatic joint), added to the joint's diagonal of the mass matrix;
* **payload**: ``payload`` kg, a point mass at the tool frame's origin (the gripped part).

A modified-DH chain is converted to standard DH first (:meth:`kin.Chain.to_standard`; the joint
values keep their meaning).  The model replaces any inertial data of the robot file.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

import kin
from design.task.model import TaskError
from kin.dynamics import LinkInertia

__all__ = ["LinkMasses", "chain_with_masses", "chain_own_masses", "rod", "MAX_MASS_PER_LENGTH", "MAX_PART_MASS"]

#: the largest tube mass per metre accepted (kg/m): a solid steel bar of 0.4 m diameter
MAX_MASS_PER_LENGTH = 1000.0
#: the largest motor or payload mass accepted (kg)
MAX_PART_MASS = 10_000.0


def rod(mass: float, A, B) -> LinkInertia:
    """A thin uniform rod of ``mass`` kg from point A to point B (m, one frame): centre of mass at its
    middle, m L²/12 (I − u uᵀ) about it (u the rod's direction)."""
    A, B = np.asarray(A, float), np.asarray(B, float)
    d = B - A
    L = float(np.linalg.norm(d))
    c = tuple(float(x) for x in (A + B) / 2)
    if L == 0.0 or mass == 0.0:
        return LinkInertia(float(mass), c)
    u = d / L
    M = mass * L * L / 12.0 * (np.eye(3) - np.outer(u, u))
    return LinkInertia(float(mass), c, (M[0, 0], M[1, 1], M[2, 2], M[0, 1], M[0, 2], M[1, 2]))


def _per_joint(v, n: int, name: str, hi: float) -> tuple[float, ...]:
    arr = np.asarray(v, dtype=float) if not isinstance(v, bool) else np.array(np.nan)
    vals = np.full(n, float(arr)) if arr.ndim == 0 else arr
    if vals.shape != (n,) or not np.all(np.isfinite(vals)) or np.any(vals < 0) or np.any(vals > hi):
        raise TaskError(f"{name} = {v!r} must be a number or {n} numbers (one per joint) in [0, {hi:g}]")
    return tuple(float(x) for x in vals)


@dataclass(frozen=True)
class LinkMasses:
    """The mass model of the module text, SI: ``mass_per_length`` (n,) kg/m of each link's tube,
    ``motor_mass`` (n,) kg of each joint's motor, ``rotor_inertia`` (n,) kg·m² (kg) reflected,
    ``payload`` kg at the tool.  Scalars are broadcast to every joint by :meth:`make`."""

    mass_per_length: tuple[float, ...]
    motor_mass: tuple[float, ...]
    rotor_inertia: tuple[float, ...]
    payload: float = 0.0

    @staticmethod
    def make(n: int, mass_per_length=0.0, motor_mass=0.0, rotor_inertia=0.0, payload: float = 0.0) -> "LinkMasses":
        """The model for an n-joint chain; every value validated (one line naming it)."""
        mpl = _per_joint(mass_per_length, n, "mass_per_length (kg/m)", MAX_MASS_PER_LENGTH)
        mm = _per_joint(motor_mass, n, "motor_mass (kg)", MAX_PART_MASS)
        ri = _per_joint(rotor_inertia, n, "rotor_inertia (kg·m² or kg)", MAX_PART_MASS)
        if isinstance(payload, bool) or not (isinstance(payload, (int, float, np.number)) and math.isfinite(payload)
                                             and 0 <= payload <= MAX_PART_MASS):
            raise TaskError(f"payload = {payload!r} must be a mass in [0, {MAX_PART_MASS:g}] kg")
        if not any(mpl) and not any(mm[1:]) and not payload:
            raise TaskError("the mass model has no mass that moves: give mass_per_length, a motor_mass beyond "
                            "joint 1's or a payload")
        return LinkMasses(mpl, mm, ri, float(payload))

    @property
    def n(self) -> int:
        return len(self.mass_per_length)

    def bodies(self, chain: kin.Chain) -> tuple[list[LinkInertia], LinkInertia]:
        """(the inertia of every body in its DH frame, the payload in the tool frame) for a chain in
        standard DH without design parameters (SI)."""
        if chain.convention != "standard" or chain.parameters:
            raise TaskError("LinkMasses.bodies needs a standard-DH chain with its parameters resolved "
                            "(chain_with_masses does that)")
        if chain.n != self.n:
            raise TaskError(f"the mass model has {self.n} joints; {chain.name} has {chain.n}")
        out = []
        tab = chain.dh_table()
        for k, (j, (a, alpha, d, _)) in enumerate(zip(chain.joints, tab)):
            axis = np.array([0.0, math.sin(alpha), math.cos(alpha)])        # z_{k-1} seen in frame k
            P1 = np.array([-a, 0.0, 0.0])                                  # end of the d offset
            parts = [rod(self.mass_per_length[k] * abs(a), P1, np.zeros(3))]
            if j.is_revolute:
                parts.append(rod(self.mass_per_length[k] * abs(d), P1 - d * axis, P1))
            else:
                lo, hi = j.limits
                stroke = hi - lo
                mid = d + 0.5 * (lo + hi)                                  # d offset + mid stroke
                back = -axis if mid >= 0 else axis                         # from the end toward the housing
                parts.append(rod(self.mass_per_length[k] * stroke, P1, P1 + stroke * back))
            if k + 1 < self.n and self.motor_mass[k + 1] > 0:              # the next joint's motor, on its axis
                parts.append(LinkInertia(self.motor_mass[k + 1], (0.0, 0.0, 0.0)))
            parts.append(LinkInertia(0.0, motor_inertia=self.rotor_inertia[k]))
            out.append(LinkInertia.combined(parts, body=j.name or f"link {k + 1}"))
        return out, LinkInertia(self.payload, body="payload")

    def total_moving_mass(self, chain: kin.Chain) -> float:
        """The mass that moves (kg): every body and the payload (joint 1's motor excluded)."""
        bodies, pay = self.bodies(chain)
        return float(sum(b.mass for b in bodies) + pay.mass)


def chain_with_masses(chain: kin.Chain, params, masses: LinkMasses) -> kin.Chain:
    """The chain at design ``params`` (SI vector, or None: nominal) with its parameters resolved, in
    standard DH, carrying the inertias of ``masses`` (:class:`LinkMasses`) for its actual lengths."""
    p = chain.parameter_vector(params) if chain.parameters else None
    fz = chain.frozen(p)
    if fz.convention != "standard":
        fz = fz.to_standard()
    bodies, pay = masses.bodies(fz)
    joints = tuple(replace(j, inertia=b) for j, b in zip(fz.joints, bodies))
    return replace(fz, joints=joints, payload=pay)


def chain_own_masses(chain: kin.Chain, params=None) -> kin.Chain:
    """The chain at design ``params`` (as :func:`chain_with_masses`) keeping its own inertial data —
    an assembly of catalogue modules (:func:`kin.modules.assemble`) carries the modules' masses; a
    body without inertial data is massless."""
    p = chain.parameter_vector(params) if chain.parameters else None
    fz = chain.frozen(p)
    return fz if fz.convention == "standard" else fz.to_standard()
