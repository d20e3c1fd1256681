"""How the capsules of the bundled arms were fitted to their makers' collision meshes (a helper, not a
test module; tests/kin/geometry/test_bundled_geometry.py re-derives the Panda's from
example-robot-data, and checks every bundled capsule still holds those meshes).

For an arm with a URDF whose kinematics are the bundled robot file's (same joints, senses and zero
pose), :func:`fit` imports the URDF with its collision meshes (:func:`kin.urdf.import_urdf` with the
exhaustive search of :mod:`kin.geometry.meshfit`, which encloses each mesh by up to three capsules),
and moves every capsule from the imported chain's DH frames into the bundled chain's: body k's
frames are both fixed in link k, so X_k = F_bundled,k(q)⁻¹ · W · F_imported,k(q) is one constant
transform (checked at random configurations; W turns the URDF's base link into the bundled base
frame, a multiple of 90° about z). :func:`rounded` writes the ends to 0.1 mm and grows each radius
to cover the rounding; :func:`toml` prints the [geometry] table. The URDFs of the arms that
example-robot-data does not ship were expanded with xacro from their ROS packages (see each robot
file's [geometry] source)::

    from tests.kin.geometry.bundled_fit import fit, rounded, toml
    caps, over = fit("ur5e", "ur5e.urdf", tip="flange", package_dirs={"ur_description": ".../ur_description"})
    print(toml(kin.load_chain("ur5e"), rounded(caps, 1e-4), over, "source text", allow=[...]))
"""
from __future__ import annotations

import math

import numpy as np

import kin
from kin.geometry import LinkCapsule, body_frames
from kin.robotfile import _str, body_label
from kin.urdf import import_urdf


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
    must be given: ``zeros`` maps joint numbers to their o_k."""
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
    assert solutions, "the URDF's kinematics are not the bundled file's"
    solutions.sort(key=lambda s: s[0])
    for other in solutions[1:]:                 # equally simple solutions must place the bodies alike
        if other[0] == solutions[0][0]:
            assert all(np.allclose(a, b, atol=1e-6) for a, b in zip(solutions[0][1], other[1])), "ambiguous"
    body_map.last = solutions[0][2:]
    return solutions[0][1]


def fit(name: str, urdf: str, tip: str, package_dirs=None, max_capsules: int = 3,
        base: str | None = None, mirror: int | None = None, zeros=None) -> tuple[list[LinkCapsule], float]:
    """The capsules of the URDF's collision meshes in the bundled robot ``name``'s body frames, and
    their over-estimate; links below the tip (a gripper: the tool body) are left out, the bundled
    arms end at their flange."""
    bundled = kin.load_chain(name)
    imported = import_urdf(urdf, base=base, tip=tip, max_capsules=max_capsules, package_dirs=package_dirs,
                           search="exhaustive")
    assert imported.n == bundled.n
    X = body_map(bundled, imported, mirror=mirror, zeros=zeros)
    n = bundled.n
    out = []
    for c in imported.geometry.capsules:
        if c.body == n + 1:
            continue
        M = X[c.body]
        out.append(LinkCapsule(c.body, M[:3, :3] @ np.array(c.a) + M[:3, 3], M[:3, :3] @ np.array(c.b) + M[:3, 3],
                               c.radius, c.name))
    return out, imported.geometry.over_estimate


def rounded(caps, step: float) -> list[LinkCapsule]:
    """Ends rounded to ``step`` (m) and radii grown by the largest end shift, rounded up to ``step``."""
    out = []
    for c in caps:
        a, b = (np.round(np.array(p) / step) * step for p in (c.a, c.b))
        shift = max(np.linalg.norm(a - c.a), np.linalg.norm(b - c.b))
        r = math.ceil((c.radius + shift) / step - 1e-9) * step
        out.append(LinkCapsule(c.body, tuple(a + 0.0), tuple(b + 0.0), r, c.name))
    return out


def toml(chain, caps, over: float, source: str, allow=()) -> str:
    """The [geometry] table of ``chain``'s robot file for these capsules (file units)."""
    s = chain.length_scale
    digits = 1 if chain.length_unit == "mm" else 4

    def num(x):
        v = round(x / s, digits)
        return f"{v + 0.0:.{digits}f}"

    lines = ["[geometry]", f"source = {_str(source)}", f"over_estimate = {num(over)}"]
    if allow:
        lines.append("allow = [" + ", ".join(f'["{body_label(chain, i)}", "{body_label(chain, j)}"]'
                                             for i, j in allow) + "]")
    for c in caps:
        lines += ["", "[[geometry.capsule]]", f'body = "{body_label(chain, c.body)}"',
                  "a = [" + ", ".join(num(x) for x in c.a) + "]", "b = [" + ", ".join(num(x) for x in c.b) + "]",
                  f"radius = {num(c.radius)}", f"name = {_str(c.name)}"]
    return "\n".join(lines) + "\n"


def self_contacts(chain, geometry, q) -> list[tuple[int, int, float]]:
    """Checked body pairs (not adjacent, not allowed) whose capsules overlap at ``q``: (i, j, depth)."""
    F = body_frames(chain, np.asarray(q, dtype=float))[0]
    world = []
    for c in geometry.capsules:
        a = F[c.body, :3, :3] @ np.array(c.a) + F[c.body, :3, 3]
        b = F[c.body, :3, :3] @ np.array(c.b) + F[c.body, :3, 3]
        world.append((c.body, a, b, c.radius))
    out = []
    for i, j in geometry.checked_pairs(chain.n):
        worst = math.inf
        for bi, a1, b1, r1 in world:
            if bi != i:
                continue
            for bj, a2, b2, r2 in world:
                if bj != j:
                    continue
                worst = min(worst, segment_segment(a1, b1, a2, b2) - r1 - r2)
        if worst < 0:
            out.append((i, j, worst))
    return out


def segment_segment(p1, q1, p2, q2) -> float:
    """Distance between segments p1–q1 and p2–q2 (Ericson, Real-Time Collision Detection 5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, f = d1 @ d1, d2 @ d2, d2 @ r
    if a <= 1e-300 and e <= 1e-300:
        return float(np.linalg.norm(r))
    if a <= 1e-300:
        s, t = 0.0, min(max(f / e, 0.0), 1.0)
    else:
        c = d1 @ r
        if e <= 1e-300:
            t, s = 0.0, min(max(-c / a, 0.0), 1.0)
        else:
            b = d1 @ d2
            den = a * e - b * b
            s = min(max((b * f - c * e) / den, 0.0), 1.0) if den > 1e-300 else 0.0
            t = (b * s + f) / e
            if t < 0:
                t, s = 0.0, min(max(-c / a, 0.0), 1.0)
            elif t > 1:
                t, s = 1.0, min(max((b - c) / a, 0.0), 1.0)
    return float(np.linalg.norm(p1 + d1 * s - p2 - d2 * t))
