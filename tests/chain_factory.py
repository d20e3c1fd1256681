"""Random chains and independent numerical references for the kin tests (a helper, not a test module).

* :func:`random_chain` builds a :class:`kin.Chain` from random DH values: mixed revolute/prismatic
  joints, either convention, optional random base/tool, optional design parameters.
* :func:`fd_jacobian` is a central finite-difference geometric Jacobian of any FK callable:
  position rows from the difference of positions, angular rows from
  ω_i = vee(log(R(q + h e_i)·R(q − h e_i)ᵀ)) / (2h), the logarithm taken by SciPy (independent of
  ``kin.transforms``).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from kin.chain import Chain, Joint, Parameter, Placement

HALF_PI = math.pi / 2


def _angle(rng: np.random.Generator) -> float:
    """A DH angle: often one of the exact 0/±90°/180° twists of real tables, else random."""
    u = rng.uniform()
    if u < 0.4:
        return float(rng.choice([0.0, HALF_PI, -HALF_PI, math.pi]))
    return float(rng.uniform(-math.pi, math.pi))


def random_placement(rng: np.random.Generator, as_matrix: bool = False) -> Placement:
    xyz = tuple(float(v) for v in rng.uniform(-0.3, 0.3, 3))
    rpy = tuple(float(v) for v in rng.uniform(-math.pi, math.pi, 3))
    if as_matrix:
        T = np.eye(4)
        T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
        T[:3, 3] = xyz
        return Placement.from_matrix(T)
    return Placement(xyz=xyz, rpy=rpy)  # type: ignore[arg-type]


def random_chain(seed: int, n: int | None = None, convention: str = "standard", placements: bool = True,
                 params: bool = False, name: str = "random_chain", types: tuple[str, ...] | None = None) -> Chain:
    """A random chain (SI units).  With ``params`` some DH entries become design parameters."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 8)) if n is None else n
    joints = []
    parameters: dict[str, Parameter] = {}
    for i in range(n):
        jtype = types[i] if types is not None else ("prismatic" if rng.uniform() < 0.3 else "revolute")
        a = float(rng.uniform(-0.6, 0.6)) if rng.uniform() < 0.75 else 0.0
        d = float(rng.uniform(-0.6, 0.6)) if rng.uniform() < 0.75 else 0.0
        values: dict[str, float | str] = {"a": a, "alpha": _angle(rng), "d": d, "theta": _angle(rng)}
        if params:
            for f in ("a", "alpha", "d", "theta"):
                if rng.uniform() < 0.25:
                    pname = f"p{i}_{f}"
                    v = float(values[f])
                    kind = "length" if f in ("a", "d") else "angle"
                    parameters[pname] = Parameter(v, (v - 1.0, v + 1.0), kind)  # type: ignore[arg-type]
                    values[f] = pname
        if jtype == "revolute":
            lo = float(rng.uniform(-math.pi, -0.5))
            limits = (lo, float(rng.uniform(0.5, math.pi)))
        else:
            lo = float(rng.uniform(-0.5, 0.0))
            limits = (lo, lo + float(rng.uniform(0.2, 0.8)))
        joints.append(Joint(jtype, limits=limits, name=f"j{i + 1}", **values))  # type: ignore[arg-type]
    if params and not parameters:  # make sure there is at least one parameter
        j0 = joints[0]
        parameters["p0_a"] = Parameter(float(j0.a), (float(j0.a) - 1.0, float(j0.a) + 1.0), "length")
        joints[0] = Joint(j0.type, a="p0_a", alpha=j0.alpha, d=j0.d, theta=j0.theta, limits=j0.limits, name=j0.name)
    base = random_placement(rng, as_matrix=bool(rng.uniform() < 0.5)) if placements else Placement()
    tool = random_placement(rng, as_matrix=bool(rng.uniform() < 0.5)) if placements else Placement()
    return Chain(name=name, joints=tuple(joints), convention=convention,  # type: ignore[arg-type]
                 base=base, tool=tool, parameters=parameters)


def random_q(chain: Chain, N: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(chain.lower, chain.upper, size=(N, chain.n))


def rotvec(R: np.ndarray) -> np.ndarray:
    """vee(log R) by SciPy."""
    return Rotation.from_matrix(R).as_rotvec()


def fd_jacobian(fk, q, h: float = 1e-6) -> np.ndarray:
    """Central-difference geometric Jacobian (6×n) of ``fk(q) -> 4×4`` (base frame, tool point)."""
    q = np.asarray(q, dtype=float)
    J = np.zeros((6, len(q)))
    for i in range(len(q)):
        e = np.zeros(len(q))
        e[i] = h
        Tp, Tm = np.asarray(fk(q + e)), np.asarray(fk(q - e))
        J[:3, i] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        J[3:, i] = rotvec(Tp[:3, :3] @ Tm[:3, :3].T) / (2 * h)
    return J

