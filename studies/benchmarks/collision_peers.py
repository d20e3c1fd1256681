"""Peer models for the collision benchmark: a robot in its work cell in pinocchio + coal.

:mod:`studies.benchmarks.bench_collision` compares rmtkit's clearance kernel with pinocchio's
``computeDistances`` / ``computeCollisions`` (coal underneath) on the same robot and cell, built here
from a :class:`planning.collision.CollisionWorld` (the robot's capsules, the cell's obstacles, the
checked body pairs):

* :func:`urdf_mesh_scene` — the way a pinocchio user would: a URDF's model and its collision meshes
  (``pin.buildGeomFromUrdf``), only the links the rmtkit robot models (:data:`PANDA_LINKS`: the
  Panda's link0 … link7; the bundled ``franka_panda`` ends at the flange, without the hand);
* :func:`capsule_scene` — like for like: the chain rebuilt joint by joint from its DH table
  (:func:`studies.benchmarks.peers.pinocchio_model`) carrying rmtkit's own capsules as
  ``coal.Capsule`` (``coal.Sphere`` where a capsule has no length).

In both the cell's obstacles are coal primitives (``coal.Box``, ``Cylinder``, ``Capsule``,
``Sphere``; a sphere set as one ``coal.Sphere`` per sphere) on the universe joint, and the collision
pairs are exactly the world's: every robot geometry against every obstacle whose ``ignore`` does not
hold its body, and the robot geometries of the checked self pairs (:attr:`CollisionWorld.pairs`).
The pinocchio world frame is the robot's root (where the cell's ``[robot]`` puts it); obstacles are
moved into it.  pinocchio and coal are imported only inside the functions that need them.
"""
from __future__ import annotations

import importlib.metadata
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: example-robot-data's robots, inside its distribution
ERD_SHARE = "cmeel.prefix/share"
PANDA_URDF = "example-robot-data/robots/panda_description/urdf/panda.urdf"
#: the Panda URDF's links with collision meshes that the bundled franka_panda models, by body
PANDA_LINKS = {f"panda_link{k}": k for k in range(8)}


def erd_share() -> Path | None:
    """The ``share`` directory of the installed example-robot-data (package root of its URDFs'
    ``package://`` paths), or None when it is not installed."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    path = Path(dist.locate_file(ERD_SHARE))
    return path if (path / PANDA_URDF).is_file() else None


def failed(d: np.ndarray) -> np.ndarray:
    """Where coal's distance is not a distance: not finite, or −DBL_MAX (its answer when GJK/EPA
    did not converge)."""
    return ~np.isfinite(d) | (d < -1e300)


def _z_to(d: np.ndarray) -> np.ndarray:
    """A rotation taking the z axis to the unit vector ``d``."""
    z = d / np.linalg.norm(d)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def coal_shape(kind: str, size) -> object:
    """A coal geometry of a :class:`kin.geometry.Shape` kind and size (half sizes → coal's full ones)."""
    import coal

    r, h, z = (float(v) for v in size)
    if kind == "sphere":
        return coal.Sphere(r)
    if kind == "capsule":
        return coal.Capsule(r, 2 * h)
    if kind == "box":
        return coal.Box(2 * r, 2 * h, 2 * z)
    if kind == "cylinder":
        return coal.Cylinder(r, 2 * h)
    raise ValueError(f"shape kind {kind!r} unknown")


def capsule_shape(a, b, radius: float) -> tuple[object, np.ndarray]:
    """A coal geometry of the capsule a–b of ``radius`` and its placement (4×4) in the capsule's frame."""
    import coal

    a, b = np.asarray(a, float), np.asarray(b, float)
    T = np.eye(4)
    T[:3, 3] = 0.5 * (a + b)
    length = float(np.linalg.norm(b - a))
    if length < 1e-12:
        return coal.Sphere(float(radius)), T
    T[:3, :3] = _z_to(b - a)
    return coal.Capsule(float(radius), length), T


def obstacle_shapes(world) -> list[tuple[str, int, object, np.ndarray]]:
    """(name, obstacle index, coal geometry, pose in the robot root's frame) of every primitive and
    sphere of the world's obstacles."""
    to_root = np.linalg.inv(world.base)
    out = []
    for oi, ob in enumerate(world.obstacles):
        for k, sh in enumerate(ob.shapes):
            out.append((f"{ob.name} {k}", oi, coal_shape(sh.kind, sh.size), to_root @ np.asarray(sh.pose)))
        if ob.spheres is not None:
            for k, (x, y, z, r) in enumerate(ob.spheres):
                T = np.eye(4)
                T[:3, 3] = x, y, z
                out.append((f"{ob.name} sphere {k}", oi, coal_shape("sphere", (r, 0, 0)), to_root @ T))
    return out


@dataclass
class PinScene:
    """A pinocchio model and GeometryModel of a robot in a cell, with the pairs' bookkeeping:
    ``pair_body[i]`` (the robot body of pair i's first geometry), ``pair_other[i]`` (obstacle index
    ≥ 0, or −1 − body for a self pair).  ``q(x)`` pads a configuration to ``model.nq``."""

    model: object
    data: object
    gmodel: object
    gdata: object
    n: int
    pair_body: np.ndarray
    pair_other: np.ndarray
    robot_geoms: int
    label: str
    notes: list[str] = field(default_factory=list)

    def q(self, x) -> np.ndarray:
        out = np.zeros(self.model.nq)
        out[:self.n] = x
        return out

    def pad(self, Q: np.ndarray) -> np.ndarray:
        out = np.zeros((len(Q), self.model.nq))
        out[:, :self.n] = Q
        return np.ascontiguousarray(out)

    @property
    def obstacle_pairs(self) -> np.ndarray:
        return self.pair_other >= 0

    def distances(self, x) -> np.ndarray:
        """Every pair's distance (coal's ``min_distance``, m) at configuration ``x``; NaN where coal
        failed (:func:`failed`)."""
        import pinocchio as pin

        pin.computeDistances(self.model, self.data, self.gmodel, self.gdata, self.q(x))
        d = np.array([r.min_distance for r in self.gdata.distanceResults])
        return np.where(failed(d), np.nan, d)

    def collisions(self, x) -> np.ndarray:
        """Every pair's collision flag (coal's exact test) at configuration ``x``."""
        import pinocchio as pin

        pin.computeCollisions(self.model, self.data, self.gmodel, self.gdata, self.q(x), False)
        return np.array([r.isCollision() for r in self.gdata.collisionResults])


def _finish(model, gmodel, robot: list[tuple[str, int, int, object, np.ndarray]], world, label: str,
            n: int, notes: list[str]) -> PinScene:
    """Add the robot geometries (name, body, joint, coal geometry, placement in the joint), the
    world's obstacles and the world's pairs to ``gmodel``."""
    import pinocchio as pin

    ids = []
    for name, body, joint, geom, T in robot:
        ids.append((gmodel.addGeometryObject(pin.GeometryObject(name, joint, pin.SE3(T), geom)), body))
    obs = [(gmodel.addGeometryObject(pin.GeometryObject(name, 0, pin.SE3(T), geom)), oi)
           for name, oi, geom, T in obstacle_shapes(world)]
    pair_body, pair_other = [], []
    for gi, body in ids:
        for go, oi in obs:
            if body not in world.obstacles[oi].ignore:
                gmodel.addCollisionPair(pin.CollisionPair(gi, go))
                pair_body.append(body)
                pair_other.append(oi)
    checked = set(world.pairs)
    for a, (gi, bi) in enumerate(ids):
        for gj, bj in ids[a + 1:]:
            if (min(bi, bj), max(bi, bj)) in checked:
                gmodel.addCollisionPair(pin.CollisionPair(gi, gj))
                pair_body.append(bi)
                pair_other.append(-1 - bj)
    return PinScene(model, model.createData(), gmodel, pin.GeometryData(gmodel), n, np.array(pair_body, int),
                    np.array(pair_other, int), len(ids), label, notes)


def capsule_scene(world) -> PinScene:
    """pinocchio + coal with rmtkit's capsules (``world.geometry``) and the world's obstacles and pairs:
    the chain from its DH table, every capsule on its body's joint."""
    import pinocchio as pin

    from studies.benchmarks.peers import _segments, pinocchio_model

    chain = world.chain
    model, _ = pinocchio_model(chain)
    posts = [post for _, _, post in _segments(chain)]
    n = chain.n
    robot = []
    for k, c in enumerate(world.geometry.capsules):
        geom, T = capsule_shape(c.a, c.b, c.radius)
        if c.body == 0:                       # DH frame 0 = the chain's base, on the universe
            joint, M = 0, chain.base.matrix
        elif c.body <= n:                     # DH frame k = joint k's frame · post_k
            joint, M = c.body, posts[c.body - 1]
        else:                                 # the tool frame = frame n · tool
            joint, M = n, posts[n - 1] @ chain.tool.matrix
        robot.append((f"capsule {k} ({c.name or c.body})", c.body, joint, geom, M @ T))
    gmodel = pin.GeometryModel()
    return _finish(model, gmodel, robot, world, "pinocchio + coal, rmtkit's capsules", n,
                   [f"{len(robot)} capsules as coal.Capsule / coal.Sphere"])


def urdf_mesh_scene(world, urdf: str | Path, package_dir: str | Path, link_bodies: dict[str, int]) -> PinScene:
    """pinocchio + coal the usual way: the URDF's model and collision meshes (``pin.buildGeomFromUrdf``),
    keeping the geometries of the links in ``link_bodies`` (URDF link name → rmtkit body), with the
    world's obstacles and pairs.  The URDF's first joints must be the chain's joints, in order."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf))
    full = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION, package_dirs=[str(package_dir)])
    robot, skipped, tris = [], [], 0
    for g in full.geometryObjects:
        link = model.frames[g.parentFrame].name
        if link not in link_bodies:
            skipped.append(g.name)
            continue
        tris += int(getattr(g.geometry, "num_tris", 0) or 0)
        robot.append((g.name, link_bodies[link], g.parentJoint, g.geometry, g.placement.homogeneous))
    notes = [f"{len(robot)} collision meshes ({tris} triangles) of links {', '.join(sorted(link_bodies))}"]
    if skipped:
        notes.append(f"left out: {', '.join(skipped)} (not part of the rmtkit robot)")
    return _finish(model, pin.GeometryModel(), robot, world, "pinocchio + coal, the URDF's collision meshes",
                   world.chain.n, notes)


def one_obstacle(world, name: str):
    """A view of ``world`` with only its obstacle ``name`` and no self pairs (what
    :func:`urdf_mesh_scene` reads: chain, obstacles, pairs, base) — the set-up of a robot against
    one box."""
    from types import SimpleNamespace

    (ob,) = [o for o in world.obstacles if o.name == name]
    return SimpleNamespace(chain=world.chain, obstacles=(ob,), pairs=(), base=world.base)


def tighten(scene: PinScene, tolerance: float = 1e-10) -> PinScene:
    """Tighten coal's GJK and EPA tolerances of every pair (default 1e-6) so that its distances can
    serve as the reference of an agreement check (not for timing: a user keeps the defaults).  At
    1e-12 GJK sometimes fails to converge and coal reports −DBL_MAX (:func:`failed`)."""
    for req in scene.gdata.distanceRequests:
        req.gjk_tolerance = tolerance
        req.epa_tolerance = tolerance
    return scene


def body_frames_pin(scene: PinScene, chain, x) -> np.ndarray:
    """DH frames 1 … n (n, 4, 4) of the capsule scene's model at ``x`` (the placement of each
    capsule-carrying joint times post_k), for checking the rebuild against rmtkit's frames."""
    import pinocchio as pin

    from studies.benchmarks.peers import _segments

    pin.forwardKinematics(scene.model, scene.data, scene.q(x))
    posts = [post for _, _, post in _segments(chain)]
    return np.array([scene.data.oMi[k + 1].homogeneous @ posts[k] for k in range(chain.n)])
