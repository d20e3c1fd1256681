"""An independent re-check of MotionBenchMaker paths: the URDF's own spheres against the scene's exact
primitives, densely — sharing nothing with rmtkit's planner or proofs.

* the robot: the URDF as yourdfpy reads it, its kinematic tree evaluated here in numpy from the joints'
  origins and axes (not from rmtkit's DH rows, not from its clearance kernel), every ``<collision>``
  sphere of every link placed in the world;
* the scene: the ``moveit_msgs/PlanningScene`` YAML read here (not through rmtkit's cell reader), each box,
  cylinder and sphere at its pose (quaternion x y z w turned by scipy's ``Rotation``);
* the check: the signed distance of every sphere from every primitive (closed forms: a point against a
  box, a cylinder, a sphere), and between the spheres of link pairs the SRDF does not disable and that
  are more than one moving joint apart (links next to each other always touch in these models; rmtkit
  does not check neighbouring bodies either), at states no more than ``step`` apart in every joint.

A state is in collision when a distance is below zero.  The verdict is reported with the smallest
distance found, per kind.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["UrdfSpheres", "SceneSolids", "Recheck", "recheck_path", "disabled_pairs"]

#: the largest joint step between re-checked states (rad)
STEP = math.radians(0.2)


def _rot(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotations (N, 3, 3) about unit ``axis`` by ``angle`` (N,) (Rodrigues)."""
    k = axis / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3)[None] + s * K[None] + (1 - c) * (K @ K)[None]


def disabled_pairs(srdf: str | Path | None) -> set[frozenset[str]]:
    """The link pairs an SRDF's ``<disable_collisions>`` elements name (read with the standard library's
    XML parser, entities refused)."""
    if srdf is None:
        return set()
    import xml.etree.ElementTree as ET
    text = Path(srdf).read_text()
    if "<!ENTITY" in text:
        raise ValueError(f"{srdf}: entity declarations are not read")
    root = ET.fromstring(text)
    return {frozenset((e.get("link1"), e.get("link2"))) for e in root.iter("disable_collisions")}


class UrdfSpheres:
    """A URDF's collision spheres, placed by its own kinematic tree (numpy, batch).

    ``joints``: the names of the actuated joints, in the order configurations are given."""

    def __init__(self, urdf: str | Path, joints: list[str], srdf: str | Path | None = None):
        import yourdfpy
        self.urdf = yourdfpy.URDF.load(str(urdf), build_scene_graph=False, load_meshes=False,
                                       build_collision_scene_graph=False, load_collision_meshes=False)
        self.joints = list(joints)
        robot = self.urdf.robot
        child_links = {j.child for j in robot.joints}
        roots = [link.name for link in robot.links if link.name not in child_links]
        if len(roots) != 1:
            raise ValueError(f"{urdf}: {len(roots)} root links; a tree has one")
        self.root = roots[0]
        children: dict[str, list] = {}
        for j in robot.joints:
            children.setdefault(j.parent, []).append(j)
        # the tree in parent-first order
        self.order = []
        stack = [self.root]
        while stack:
            link = stack.pop()
            for j in children.get(link, []):
                self.order.append(j)
                stack.append(j.child)
        for name in self.joints:
            if not any(j.name == name for j in self.order):
                raise ValueError(f"{urdf}: no joint {name!r}")
        self.spheres: list[tuple[str, np.ndarray, float]] = []      # link, centre in the link frame, radius
        for link in robot.links:
            for c in link.collisions:
                g = c.geometry
                if g.sphere is None:
                    continue
                T = np.eye(4) if c.origin is None else np.asarray(c.origin, float)
                self.spheres.append((link.name, T[:3, 3].copy(), float(g.sphere.radius)))
        self.sphere_link = np.array([s[0] for s in self.spheres])
        # which links move together (joined by fixed joints): a link's rigid group is its nearest
        # ancestor below a moving joint
        depth = {self.root: 0}                   # moving joints between the root and each link
        for j in self.order:
            depth[j.child] = depth[j.parent] + (0 if j.type == "fixed" else 1)
        self.depth = depth
        disabled = disabled_pairs(srdf)
        links = sorted({s[0] for s in self.spheres})
        self.self_pairs = [(a, b) for i, a in enumerate(links) for b in links[i + 1:]
                           if abs(depth[a] - depth[b]) > 1 and frozenset((a, b)) not in disabled]

    def centres(self, Q: np.ndarray) -> np.ndarray:
        """Sphere centres (N, S, 3) in the root frame at configurations Q (N, len(joints))."""
        Q = np.atleast_2d(np.asarray(Q, float))
        N = len(Q)
        T = {self.root: np.tile(np.eye(4), (N, 1, 1))}
        col = {name: k for k, name in enumerate(self.joints)}
        for j in self.order:
            Tj = np.eye(4) if j.origin is None else np.asarray(j.origin, float)
            M = T[j.parent] @ Tj
            if j.type in ("revolute", "continuous", "prismatic") and j.name in col:
                q = Q[:, col[j.name]]
                axis = np.asarray(j.axis, float)
                L = np.tile(np.eye(4), (N, 1, 1))
                if j.type == "prismatic":
                    L[:, :3, 3] = q[:, None] * axis / np.linalg.norm(axis)
                else:
                    L[:, :3, :3] = _rot(axis, q)
                M = M @ L
            T[j.child] = M
        out = np.empty((N, len(self.spheres), 3))
        for k, (link, c, _) in enumerate(self.spheres):
            out[:, k] = (T[link][:, :3, :3] @ c) + T[link][:, :3, 3]
        return out

    @property
    def radii(self) -> np.ndarray:
        return np.array([s[2] for s in self.spheres])


@dataclass(frozen=True)
class SceneSolids:
    """A planning scene's primitives in the root frame: boxes (poses (B, 4, 4), half sizes (B, 3)),
    cylinders (poses, radius, half length), spheres (centres, radii), and their names."""

    box_T: np.ndarray
    box_half: np.ndarray
    cyl_T: np.ndarray
    cyl_r: np.ndarray
    cyl_h: np.ndarray
    sph_c: np.ndarray
    sph_r: np.ndarray
    names: tuple[str, ...]

    @staticmethod
    def from_yaml(path: str | Path) -> "SceneSolids":
        import yaml
        from scipy.spatial.transform import Rotation
        d = yaml.safe_load(Path(path).read_text())
        boxes, cyls, sphs, names = [], [], [], []
        for co in d["world"]["collision_objects"]:
            base = np.eye(4)
            if co.get("pose"):
                base[:3, :3] = Rotation.from_quat(co["pose"]["orientation"]).as_matrix()
                base[:3, 3] = co["pose"]["position"]
            for prim, pose in zip(co.get("primitives", []), co.get("primitive_poses", [])):
                T = np.eye(4)
                T[:3, :3] = Rotation.from_quat(pose["orientation"]).as_matrix()
                T[:3, 3] = pose["position"]
                T = base @ T
                dims = [float(x) for x in prim["dimensions"]]
                names.append(co["id"])
                if prim["type"] == "box":
                    boxes.append((T, 0.5 * np.array(dims)))
                elif prim["type"] == "cylinder":
                    cyls.append((T, dims[1], 0.5 * dims[0]))
                elif prim["type"] == "sphere":
                    sphs.append((T[:3, 3], dims[0]))
                else:
                    raise ValueError(f"{path}: primitive {prim['type']!r} is not re-checked")
        z4 = np.zeros((0, 4, 4))
        return SceneSolids(np.array([b[0] for b in boxes]) if boxes else z4,
                           np.array([b[1] for b in boxes]).reshape(-1, 3),
                           np.array([c[0] for c in cyls]) if cyls else z4, np.array([c[1] for c in cyls]),
                           np.array([c[2] for c in cyls]), np.array([s[0] for s in sphs]).reshape(-1, 3),
                           np.array([s[1] for s in sphs]), tuple(names))

    def distances(self, P: np.ndarray, r: np.ndarray) -> np.ndarray:
        """The least signed distance (N,) of spheres (N, S, 3) of radii r (S,) from every solid."""
        best = np.full(P.shape[0], np.inf)
        for T, h in zip(self.box_T, self.box_half):
            L = (P - T[:3, 3]) @ T[:3, :3]                      # sphere centres in the box's frame
            q = np.abs(L) - h
            out = np.linalg.norm(np.maximum(q, 0.0), axis=-1)
            inside = np.minimum(q.max(axis=-1), 0.0)
            best = np.minimum(best, (out + inside - r).min(axis=1))
        for T, R, H in zip(self.cyl_T, self.cyl_r, self.cyl_h):
            L = (P - T[:3, 3]) @ T[:3, :3]
            dr = np.hypot(L[..., 0], L[..., 1]) - R
            dz = np.abs(L[..., 2]) - H
            out = np.hypot(np.maximum(dr, 0.0), np.maximum(dz, 0.0))
            inside = np.minimum(np.maximum(dr, dz), 0.0)
            best = np.minimum(best, (out + inside - r).min(axis=1))
        for c, R in zip(self.sph_c, self.sph_r):
            best = np.minimum(best, (np.linalg.norm(P - c, axis=-1) - r - R).min(axis=1))
        return best


@dataclass(frozen=True)
class Recheck:
    """``collides`` — some re-checked state is in collision; ``min_obstacle``, ``min_self``: the least
    signed distances found (m); ``states``: how many were checked."""

    collides: bool
    min_obstacle: float
    min_self: float
    states: int


def recheck_path(robot: UrdfSpheres, scene: SceneSolids, path: np.ndarray, step: float = STEP,
                 chunk: int = 2000) -> Recheck:
    """Re-check ``path`` (M, len(robot.joints)), rad, at states no more than ``step`` apart per joint."""
    P = np.atleast_2d(np.asarray(path, float))
    if len(P) > 1:
        k = np.maximum(np.ceil(np.abs(np.diff(P, axis=0)).max(axis=1) / step), 1).astype(int)
        Q = np.vstack([P[i] + np.linspace(0, 1, k[i], endpoint=False)[:, None] * (P[i + 1] - P[i])
                       for i in range(len(P) - 1)] + [P[-1:]])
    else:
        Q = P
    r = robot.radii
    link_of = robot.sphere_link
    pairs = [(np.flatnonzero(link_of == a), np.flatnonzero(link_of == b)) for a, b in robot.self_pairs]
    min_obs, min_self = math.inf, math.inf
    for s in range(0, len(Q), chunk):
        C = robot.centres(Q[s:s + chunk])
        min_obs = min(min_obs, float(scene.distances(C, r).min()))
        for ia, ib in pairs:
            d = np.linalg.norm(C[:, ia, None, :] - C[:, None, ib, :], axis=-1) - r[ia][:, None] - r[ib][None, :]
            min_self = min(min_self, float(d.min()))
    return Recheck(min_obs < 0 or min_self < 0, min_obs, min_self, len(Q))
