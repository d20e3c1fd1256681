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
from studies.shape.mapping import body_map


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
