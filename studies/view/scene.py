"""What ``rmt view`` draws, as plain arrays (no viser): the robot's parts fixed in its bodies — its real
shape where :func:`studies.shape.meshes.visual_meshes` knows it, its collision capsules (the cell's tool
among them, body n + 1) — the cell's obstacles in the world, the bodies' poses at a configuration, the
joint sliders' ranges in robot file units, and the target nearest a click ray.  :mod:`studies.view.server`
puts them into viser."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Part", "capsule_parts", "mesh_parts", "obstacle_parts", "body_poses", "slider_spec",
           "nearest_to_ray", "initial_configuration", "CAPSULE_RGB", "ALARM_RGB", "TOOL_RGB"]

CAPSULE_RGB = (224, 168, 0)
TOOL_RGB = (77, 77, 77)
ALARM_RGB = (214, 39, 40)


@dataclass(frozen=True)
class Part:
    """A triangle mesh: ``vertices`` (k, 3; m) in body ``body``'s frame (None: in the world), ``faces``
    (m, 3), ``rgb`` (0 … 255), ``opacity``, ``name`` (unique in the scene), ``kind`` ("mesh", "capsules",
    "tool", "obstacle")."""

    name: str
    kind: str
    body: int | None
    vertices: np.ndarray
    faces: np.ndarray
    rgb: tuple[int, int, int]
    opacity: float = 1.0


def capsule_parts(world) -> list[Part]:
    """The capsules of every body of ``world`` (a :class:`planning.collision.CollisionWorld`: the robot's
    and the cell's tool), one part per body, in the body's own frame."""
    from studies.report.cell_view import _join, capsule_mesh
    n = world.chain.n
    out = []
    for b in sorted({c.body for c in world.geometry.capsules}):
        V, F = _join([capsule_mesh(c.a, c.b, c.radius) for c in world.geometry.capsules if c.body == b])
        tool = b == n + 1
        out.append(Part(f"b{b}_capsules", "tool" if tool else "capsules", b, V, F, TOOL_RGB if tool else CAPSULE_RGB,
                        1.0 if tool else 0.85))
    return out


def mesh_parts(robot) -> tuple[list[Part], str]:
    """The robot's real shape as parts (empty when unknown) and one line saying what is drawn."""
    try:
        from studies.shape.meshes import visual_meshes
    except ImportError:                   # the module of the real shapes is optional
        return [], "robot drawn as its collision capsules (no mesh support installed)"
    import kin
    try:
        meshes = visual_meshes(robot)
    except (kin.RmtError, OSError, ValueError) as e:
        return [], f"robot drawn as its collision capsules: its meshes could not be read ({e})"
    if not meshes:
        return [], f"no real shape known for {robot.name}: drawn as its collision capsules"
    out = []
    for i, m in enumerate(meshes):
        rgba = tuple(float(x) for x in m.rgba)
        rgb = tuple(int(round(255 * min(max(x, 0.0), 1.0))) for x in rgba[:3])
        out.append(Part(f"b{m.body}_mesh{i}", "mesh", int(m.body), np.asarray(m.vertices, float),
                        np.asarray(m.faces, np.int64), rgb, rgba[3] if len(rgba) > 3 else 1.0))
    bodies = len({p.body for p in out})
    return out, f"real shape: {len(out)} mesh(es) on {bodies} bodies (capsules: the checkbox)"


def obstacle_parts(world, meshes=None) -> list[Part]:
    """The obstacles of ``world`` in the world frame: their shapes, a mesh obstacle as its original
    triangles (``meshes``: ``cell.meshes``) where known (:func:`studies.report.cell_view.obstacle_mesh`)."""
    from studies.report.cell_view import OBSTACLE_COLOURS, obstacle_mesh
    out = []
    for k, ob in enumerate(world.obstacles):
        V, F, _ = obstacle_mesh(ob, (meshes or {}).get(ob.name))
        if not len(V):
            continue
        h = OBSTACLE_COLOURS[k % len(OBSTACLE_COLOURS)]
        rgb = tuple(int(h[i:i + 2], 16) for i in (1, 3, 5))
        out.append(Part(f"o{k}", "obstacle", None, V, F, rgb, 0.55 if ob.spheres is None else 0.85))
    return out


def body_poses(model, q) -> np.ndarray:
    """The poses (n + 2, 4, 4; world, m) of bodies 0 … n + 1 at ``q`` (SI): :func:`kin.geometry.body_frames`
    with the robot's placement."""
    from kin.geometry import body_frames
    return body_frames(model.chain, np.asarray(q, float)[None], model.base)[0]


def slider_spec(chain) -> list[dict]:
    """Per joint: label ("J1 [deg]"), min, max (the limits in robot file units) and a step of about a
    twenty-thousandth of the range, a power of ten."""
    from studies.units import joint_units
    lo, hi = chain.from_si(chain.lower), chain.from_si(chain.upper)
    out = []
    for name, u, a, b in zip(chain.joint_names(), joint_units(chain), lo, hi):
        span = float(b - a) if math.isfinite(b - a) and b > a else 1.0
        step = 10.0 ** math.floor(math.log10(span / 20000))
        out.append({"label": f"{name} [{u}]", "min": float(a), "max": float(b), "step": step})
    return out


def initial_configuration(robot, given=None) -> np.ndarray:
    """Where the sliders start (SI): ``given``, else the robot's state ``home``, else zero clipped into
    the limits."""
    c = robot.chain
    if given is not None:
        return np.asarray(given, float)
    if "home" in c.states:
        return np.asarray(c.states["home"], float)
    return np.clip(np.zeros(c.n), c.lower, c.upper)


def nearest_to_ray(points: np.ndarray, origin, direction) -> int:
    """The index of the point (K, 3) nearest the ray ``origin`` + t·``direction`` (t ≥ 0): what a click
    on the targets picked."""
    P = np.asarray(points, float).reshape(-1, 3)
    o, d = np.asarray(origin, float), np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    t = np.clip((P - o) @ d, 0.0, None)
    return int(np.argmin(np.linalg.norm(P - (o + t[:, None] * d), axis=1)))
