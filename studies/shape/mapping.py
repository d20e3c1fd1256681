"""The constant transforms that carry a URDF's bodies onto a robot file's bodies of the same machine.

A URDF imported with :func:`kin.urdf.chain_from_serial` has DH frames of its own; a bundled robot
file describing the same arm (same joints, senses up to ±1, zeros up to multiples of 90°) has
others.  Body k's two frames are both fixed in link k, so X_k = F_file,k(q)⁻¹ · W · F_imported,k(q)
is one constant transform — checked at random configurations (W turns the URDF's base link into
the file's base frame, a multiple of 90° about z).  Used to put a URDF's meshes on a bundled arm
(:mod:`studies.shape.meshes`) and to fit the bundled arms' capsules (tests/kin/geometry/bundled_fit.py).
"""
from __future__ import annotations

import math

import numpy as np

from kin.geometry import body_frames

__all__ = ["body_map", "MappingError"]


class MappingError(ValueError):
    """The URDF's kinematics are not the robot file's (no constant X_k), or not uniquely so."""


def _rz(k: int) -> np.ndarray:
    c, s = round(math.cos(k * math.pi / 2)), round(math.sin(k * math.pi / 2))
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


def _axes_frame(chain, q, k: int) -> np.ndarray:
    """A frame fixed in body k (1 ≤ k < n, standard DH) from its two joint axes: origin the foot of
    their common normal on axis k + 1 (frame k's origin), z along axis k + 1 towards frame k + 1's
    origin, x along the normal towards axis k — in body k's frame."""
    F = body_frames(chain, np.asarray(q, dtype=float))[0]
    inv = np.linalg.inv(F[k])
    nxt = (inv @ F[k + 1])[:3, 3]
    z = nxt / np.linalg.norm(nxt)
    prev = inv @ F[k - 1]
    o, u = prev[:3, 3], prev[:3, 2]
    e = o - (o @ u) * u                          # the foot of the normal from the origin onto axis k
    x = e - (e @ z) * z
    x /= np.linalg.norm(x)
    G = np.eye(4)
    G[:3, 0], G[:3, 1], G[:3, 2] = x, np.cross(z, x), z
    return G


def body_map(bundled, imported, n_q: int = 8, seed: int = 0, tol: float = 1e-4,
             mirror: int | None = None, zeros=None) -> list[np.ndarray]:
    """X_k (imported DH frame k → bundled DH frame k) for bodies 0 … n + 1, constant in q.

    The URDF's joint k may turn the other way or from another zero than the bundled file's: q_urdf =
    s_k·q + o_k with s_k = ±1 and o_k a multiple of 90°; W, the turn of the base (a multiple of 90°
    about z), trades with o_1, so joint 1's zero is taken as the same (o_1 = 0), as is the flange's
    (o_n = 0: a joint's zero shows only in the bodies after it).  Searched body by body, every
    choice that keeps X_k constant (within ``tol``: a URDF's 1.5708 for π/2) followed to the end; of
    the solutions (a spherical wrist has two: θ4 + π, −θ5, θ6 + π is the same flange) the one with the
    fewest offsets and turned joints, then the one whose two frames of each link lie closest.
    With ``mirror`` = m (the robot file's arm is a mirror image of the URDF's from link m on: its
    elbow offset on the other side of the forearm), body m is placed by its joint axes instead
    (:func:`_axes_frame`: turned about its distal axis until its proximal axis lies where the file
    has it) and the bodies after it relative to body m; joint m − 1's zero then shows in no body and
    must be given: ``zeros`` maps joint numbers to their o_k.  :class:`MappingError` when no such
    X_k exist (another machine) or two equally simple solutions place the bodies differently.
    ``body_map.last`` holds (W's quarter turns, s, o) of the solution."""
    if bundled.n != imported.n:
        raise MappingError(f"the URDF's chain has {imported.n} joints, the robot file's {bundled.n}")
    rng = np.random.default_rng(seed)
    Q = rng.uniform(np.maximum(bundled.lower, -3), np.minimum(bundled.upper, 3), size=(n_q, bundled.n))
    Fb = body_frames(bundled, Q)
    n = bundled.n
    quarter = (0.0, math.pi / 2, math.pi, -math.pi / 2)

    def frames(kz, sign, offset, k):
        Fi = body_frames(imported, Q * sign + offset)
        if mirror is not None and k == mirror:
            X = np.array([_axes_frame(bundled, q, k) @ np.linalg.inv(_axes_frame(imported, qi, k))
                          for q, qi in zip(Q, Q * sign + offset)])
        elif mirror is not None and k > mirror:
            Xm = frames(kz, sign, offset, mirror)[1]
            X = np.linalg.inv(np.linalg.inv(Fb[:, mirror]) @ Fb[:, k]) @ Xm @ np.linalg.inv(Fi[:, mirror]) @ Fi[:, k]
        else:
            X = np.linalg.inv(Fb[:, k]) @ _rz(kz) @ Fi[:, k]
        return float(np.abs(X - X[:1]).max()), X[0]

    solutions = []

    def search(k, kz, sign, offset):
        if k > n + 1:
            X = [frames(kz, sign, offset, j)[1] for j in range(n + 2)]
            cost = int(np.count_nonzero(offset)) + int(np.count_nonzero(sign < 0)) + (kz != 0)
            shift = round(sum(float(np.linalg.norm(x[:3, 3])) for x in X), 6)   # frames of a link lie close
            solutions.append(((cost, shift), X, kz, sign, offset))
            return
        if k == n + 1:
            options = [(kz, sign, offset)]
        elif k == 1:
            options = [(0, np.r_[s1, sign[1:]], offset) for s1 in (1.0, -1.0)]
        elif k == 2:
            options = [(z, np.r_[sign[:1], s2, sign[2:]], offset) for z in range(4) for s2 in (1.0, -1.0)]
        else:
            options = []
            for o in quarter:
                if zeros and k - 1 in zeros and o != zeros[k - 1]:
                    continue
                for s_k in (1.0, -1.0):
                    sg, of = sign.copy(), offset.copy()
                    sg[k - 1], of[k - 2] = s_k, o
                    options.append((kz, sg, of))
        for z, sg, of in options:
            if frames(z, sg, of, k)[0] < tol:
                search(k + 1, z, sg, of)

    search(1, 0, np.ones(n), np.zeros(n))
    if not solutions:
        raise MappingError("the URDF's kinematics are not the robot file's (no constant transform between "
                           "their body frames)")
    solutions.sort(key=lambda s: s[0])
    for other in solutions[1:]:                 # equally simple solutions must place the bodies alike
        if other[0] == solutions[0][0] and not all(np.allclose(a, b, atol=1e-6)
                                                   for a, b in zip(solutions[0][1], other[1])):
            raise MappingError("the URDF's bodies map onto the robot file's in two ways")
    body_map.last = solutions[0][2:]
    return solutions[0][1]
