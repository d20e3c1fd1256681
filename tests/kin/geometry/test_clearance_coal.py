"""kin.geometry.ClearanceModel against coal (the exact collision library of Pinocchio): every pair kind
at random placements, grazing and barely penetrating ones, and whole robots in a cell of ten random
obstacles.

Coal measures separated shapes by GJK, whose witness points lie on the shapes, so its distance is an
upper bound of the truth: the kernel, a lower bound, must never exceed it (beyond 1e-9 m) and stay
within 1e-6 m of it.  For penetrations coal reports minus the depth of the minimum translation that
separates the shapes (EPA); the kernel's signed distance of a capsule and a box or a cylinder is minus
the deepest the capsule reaches into the solid, which is never deeper: there the signs agree and the
kernel is never below coal's (beyond 1e-6 m).  For a capsule against a sphere or a capsule the two
definitions coincide."""
from __future__ import annotations

import numpy as np
import pytest

coal = pytest.importorskip("coal")

import kin  # noqa: E402
from kin.geometry import LinkCapsule, Obstacle, RobotGeometry, Shape  # noqa: E402
from tests.kin.geometry.test_clearance import ONE, ROBOTS, fallback, model, pose, random_cell  # noqa: E402

ABOVE = 1e-9        # m: how far the kernel may exceed coal where the shapes are apart
CLOSE = 1e-6        # m: how far from coal it may be


def _request():
    req = coal.DistanceRequest()
    req.enable_signed_distance = True
    req.gjk_tolerance = 1e-9
    req.epa_tolerance = 1e-9
    return req


REQUEST = _request()


def coal_shape(kind: str, size) -> object:
    if kind == "sphere":
        return coal.Sphere(size[0])
    if kind == "capsule":
        return coal.Capsule(size[0], 2 * size[1])
    if kind == "box":
        return coal.Box(*(2 * np.asarray(size)))
    return coal.Cylinder(size[0], 2 * size[1])


def capsule_pose(a, b) -> tuple[np.ndarray, np.ndarray, float]:
    """Rotation taking z along a → b, the midpoint and the length."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    L = float(np.linalg.norm(b - a))
    z = (b - a) / L if L > 0 else np.array([0.0, 0.0, 1.0])
    x = np.cross(z, [1.0, 0.0, 0.0])
    if np.linalg.norm(x) < 1e-6:
        x = np.cross(z, [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z], axis=1), 0.5 * (a + b), L


def coal_capsule(a, b, r):
    R, c, L = capsule_pose(a, b)
    geom = coal.Sphere(r) if L == 0 else coal.Capsule(r, L)
    return coal.CollisionObject(geom, coal.Transform3s(R, c))


def coal_distance(o1, o2) -> float:
    res = coal.DistanceResult()
    return float(coal.distance(o1, o2, REQUEST, res))


def check(kind: str, v: float, c: float) -> None:
    if not np.isfinite(c) or c < -1e3:                 # EPA gave up: nothing to compare
        return
    if c > CLOSE:
        assert c - CLOSE <= v <= c + ABOVE, (kind, v, c)
    elif c < -CLOSE:
        assert v < 0, (kind, v, c)
        if kind in ("sphere", "capsule"):
            assert abs(v - c) <= CLOSE, (kind, v, c)
        else:
            assert v >= c - CLOSE, (kind, v, c)
    else:
        assert abs(v - c) <= CLOSE, (kind, v, c)


def one_pair(a, b, r, shape: Shape) -> float:
    m = model(ONE, [Obstacle("it", (shape,))], geometry=RobotGeometry((LinkCapsule(0, a, b, r),)), self_pairs=(),
              cap=np.inf)
    return m.clearance(np.zeros(1))


@pytest.mark.parametrize("kind", ["sphere", "capsule", "box", "cylinder"])
def test_random_pairs_against_coal(kind):
    rng = np.random.default_rng(["sphere", "capsule", "box", "cylinder"].index(kind))
    apart = deep = 0
    for _ in range(400):
        size = tuple(float(x) for x in rng.uniform(0.02, 0.3, 3))
        size = {"sphere": (size[0], 0.0, 0.0), "box": size}.get(kind, (size[0], size[1], 0.0))
        T = pose(rng, (0, 0, 0), 0.2)
        a = rng.uniform(-0.5, 0.5, 3)
        b = a + (rng.normal(size=3) * rng.uniform(0, 0.4) if rng.uniform() < 0.85 else 0.0)
        r = float(rng.uniform(0.0, 0.1))
        v = one_pair(a, b, r, Shape(kind, size, T))
        c = coal_distance(coal_capsule(a, b, r), coal.CollisionObject(coal_shape(kind, size),
                                                                       coal.Transform3s(T[:3, :3], T[:3, 3])))
        check(kind, v, c)
        apart += c > CLOSE
        deep += c < -CLOSE
    assert apart > 50 and deep > 20                       # both cases were seen


def test_grazing_pairs_against_coal():
    rng = np.random.default_rng(30)
    for eps in (1e-2, 1e-4, 1e-6, 1e-8, -1e-8, -1e-6, -1e-4):
        for kind in ("sphere", "capsule", "box", "cylinder"):
            T = pose(rng, (0, 0, 0))
            r = 0.03
            # a segment parallel to a face or the side, eps from it (local normal n, tangent u, foot p0)
            size, n, u, p0 = {
                "box": ((0.2, 0.15, 0.1), (0, 0, 1.0), (1.0, 0.3, 0), (0, 0, 0.1)),
                "cylinder": ((0.1, 0.2, 0), (1.0, 0, 0), (0, 0, 1.0), (0.1, 0, 0)),
                "capsule": ((0.05, 0.2, 0), (1.0, 0, 0), (0, 1.0, 0), (0.05, 0, 0)),
                "sphere": ((0.1, 0, 0), (0, 0, 1.0), (1.0, 0, 0), (0, 0, 0.1))}[kind]
            n, u, p0 = np.array(n), np.array(u) / np.linalg.norm(u), np.array(p0)
            mid = p0 + (eps + r) * n
            a_l, b_l = (mid, mid) if kind == "sphere" else (mid - 0.05 * u, mid + 0.05 * u)
            a, b = (T[:3, :3] @ x + T[:3, 3] for x in (a_l, b_l))
            v = one_pair(a, b, r, Shape(kind, size, T))
            c = coal_distance(coal_capsule(a, b, r), coal.CollisionObject(coal_shape(kind, size),
                                                                           coal.Transform3s(T[:3, :3], T[:3, 3])))
            assert abs(c - eps) <= CLOSE                  # the construction, seen by coal
            assert eps - CLOSE <= v <= eps + 1e-12, (kind, eps, v)
            assert (v < 0) == (eps < 0)


def robot_distances_by_coal(robot, cell, Q) -> np.ndarray:
    """min over capsule–obstacle pairs (ignore sets honoured) of coal's signed distance, per configuration."""
    geometry = robot.geometry
    F = kin.geometry.body_frames(robot.chain, Q)
    shapes = [(i, coal.CollisionObject(coal_shape(sh.kind, sh.size), coal.Transform3s(sh.pose[:3, :3],
                                                                                      sh.pose[:3, 3])))
              for i, ob in enumerate(cell) for sh in ob.shapes]
    caps = []
    for cap in geometry.capsules:
        L = float(np.linalg.norm(np.subtract(cap.b, cap.a)))
        caps.append((cap, coal.CollisionObject(coal.Sphere(cap.radius) if L == 0 else coal.Capsule(cap.radius, L))))
    out = np.full(len(Q), np.inf)
    for k in range(len(Q)):
        for cap, obj in caps:
            T = F[k, cap.body]
            a, b = T[:3, :3] @ cap.a + T[:3, 3], T[:3, :3] @ cap.b + T[:3, 3]
            R, c, _ = capsule_pose(a, b)
            obj.setTransform(coal.Transform3s(R, c))
            for i, other in shapes:
                if cap.body not in cell[i].ignore:
                    out[k] = min(out[k], coal_distance(obj, other))
    return out


@pytest.mark.parametrize("name", ROBOTS)
def test_whole_robots_against_coal(name):
    robot = kin.load_robot(name)
    cell = random_cell(40)
    Q = robot.random_configurations(2000, seed=41)
    d = model(robot, cell, self_pairs=(), cap=np.inf).clearance(Q)
    dn = fallback(robot, cell, self_pairs=(), cap=np.inf).clearance(Q)
    assert np.allclose(d, dn, atol=2e-7, rtol=0)
    c = robot_distances_by_coal(robot, cell, Q)
    apart = c > CLOSE
    assert apart.sum() > 200 and (~apart).sum() > 200    # both cases were seen
    assert np.all(d[apart] <= c[apart] + ABOVE), float((d - c)[apart].max())
    assert np.all(d[apart] >= c[apart] - CLOSE), float((c - d)[apart].max())
    touching = np.abs(c) <= CLOSE
    assert np.all(np.abs(d[touching] - c[touching]) <= CLOSE)
    deep = c < -CLOSE
    assert np.all(d[deep] < 0) and np.all(d[deep] >= c[deep] - CLOSE)
