"""Enclosing capsules (kin/geometry/enclose.py) against independent numbers: the least-volume capsule of
a box or a cylinder from its closed-form volume minimised by scipy, every vertex (and every sampled
interior point) inside, and the stated over-estimate against the largest distance from densely
sampled points of the capsules' surface to the solid (closed-form distances for primitives, trimesh's
closest points for meshes)."""
from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from scipy.optimize import minimize_scalar

from kin.geometry.enclose import (
    Capsule,
    capsule_along,
    enclose_box,
    enclose_cylinder,
    enclose_points,
    enclose_sphere,
    segment_distance,
)
from kin.geometry.meshfit import enclose_mesh


def surface(c: Capsule, n: int = 60_000, seed: int = 0) -> np.ndarray:
    """Random points of a capsule's surface: its side, and a hemisphere at each end (random unit
    vectors), independent of the module's grid."""
    rng = np.random.default_rng(seed)
    a, b, R = np.array(c.a), np.array(c.b), c.radius
    L = float(np.linalg.norm(b - a))
    u = (b - a) / L if L > 0 else np.array([0.0, 0.0, 1.0])
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    along = d @ u
    side = rng.uniform(0, 1, size=n)
    radial = d - along[:, None] * u
    radial /= np.maximum(np.linalg.norm(radial, axis=1, keepdims=True), 1e-300)
    pts = np.where((np.arange(n) % 2 == 0)[:, None],
                   a + side[:, None] * (b - a) + R * radial,             # the side
                   np.where((along >= 0)[:, None], b, a) + R * d)        # the ends
    return pts


def inside(points, caps, tol=1e-12) -> np.ndarray:
    d = np.min([segment_distance(points, c.a, c.b) - c.radius for c in caps], axis=0)
    return d <= tol


def union_surface(caps, n=60_000) -> np.ndarray:
    pts = []
    for i, c in enumerate(caps):
        p = surface(c, n, seed=i)
        others = [o for j, o in enumerate(caps) if j != i]
        if others:
            p = p[~inside(p, others, tol=-1e-12)]
        pts.append(p)
    return np.vstack(pts)


def box_distance(P, half):
    return np.linalg.norm(np.maximum(np.abs(P) - half, 0.0), axis=1)


def cylinder_distance(P, rho, h):
    r = np.hypot(P[:, 0], P[:, 1])
    return np.hypot(np.maximum(r - rho, 0), np.maximum(np.abs(P[:, 2]) - h, 0))


def least_volume(h, r):
    """The least-volume capsule along an axis for a cross-section of circumradius r at axial ±h:
    minimise V(R) = πR²·2(h − √(R² − r²))⁺ + 4/3·πR³ over R ≥ r (scipy's bounded scalar minimiser)."""
    def V(R):
        return math.pi * R * R * 2 * max(h - math.sqrt(max(R * R - r * r, 0.0)), 0.0) + 4 / 3 * math.pi * R ** 3
    res = minimize_scalar(V, bounds=(r, math.hypot(h, r)), method="bounded", options={"xatol": 1e-12})
    R = float(res.x)
    return R, max(h - math.sqrt(R * R - r * r), 0.0)


def test_sphere_is_exact():
    e = enclose_sphere((1.0, 2.0, 3.0), 0.5)
    assert e.capsules == (Capsule((1.0, 2.0, 3.0), (1.0, 2.0, 3.0), 0.5),) and e.over_estimate == 0.0


@pytest.mark.parametrize("size", [(0.4, 0.1, 0.05), (1.0, 1.0, 1.0), (0.1, 0.3, 0.02), (0.02, 0.03, 0.5)])
def test_box(size):
    half = np.array(size) / 2
    e = enclose_box(size)
    (c,) = e.capsules
    axis = int(np.argmax(half))
    others = np.delete(half, axis)
    R, L = least_volume(half[axis], float(np.hypot(*others)))
    assert c.radius == pytest.approx(R, rel=1e-6)
    assert c.length / 2 == pytest.approx(L, rel=1e-5, abs=1e-6)
    np.testing.assert_allclose(np.cross(np.subtract(c.b, c.a), np.eye(3)[axis]), 0, atol=1e-12)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    assert inside(corners, [c]).all()
    sampled = box_distance(surface(c), half).max()
    assert sampled <= e.over_estimate + 1e-12
    assert sampled >= e.over_estimate - 1e-3 * np.linalg.norm(size)


def test_box_pose_moves_the_capsule():
    T = np.eye(4)
    T[:3, :3] = trimesh.transformations.rotation_matrix(0.7, [1, 2, 3])[:3, :3]
    T[:3, 3] = (0.1, -0.2, 0.3)
    e0, e = enclose_box((0.3, 0.1, 0.05)), enclose_box((0.3, 0.1, 0.05), T)
    (c0,), (c,) = e0.capsules, e.capsules
    np.testing.assert_allclose(c.a, T[:3, :3] @ c0.a + T[:3, 3], atol=1e-15)
    assert c.radius == c0.radius and e.over_estimate == e0.over_estimate


@pytest.mark.parametrize("rho, length", [(0.05, 0.6), (0.1, 0.02), (0.06, 0.12)])
def test_cylinder(rho, length):
    e = enclose_cylinder(rho, length)
    (c,) = e.capsules
    R, L = least_volume(length / 2, rho)
    assert c.radius == pytest.approx(R, rel=1e-6)
    assert c.length / 2 == pytest.approx(L, rel=1e-5, abs=1e-6)
    ang = np.linspace(0, 2 * np.pi, 2001)
    rims = np.vstack([np.column_stack([rho * np.cos(ang), rho * np.sin(ang), np.full_like(ang, z)])
                      for z in (-length / 2, length / 2)])
    assert inside(rims, [c]).all()
    sampled = cylinder_distance(surface(c), rho, length / 2).max()
    assert sampled <= e.over_estimate + 1e-12
    assert sampled >= e.over_estimate - 1e-3 * math.hypot(2 * rho, length)


def test_long_cylinder_keeps_its_radius():
    (c,) = enclose_cylinder(0.05, 0.6).capsules
    assert 0.05 <= c.radius < 0.0503


def test_capsule_along_holds_points_and_radius_is_the_distance():
    rng = np.random.default_rng(3)
    P = rng.normal(size=(500, 3)) * (0.3, 0.05, 0.02)
    c = capsule_along(P, (1, 0, 0))
    d = segment_distance(P, c.a, c.b)
    assert d.max() == c.radius


def test_point_set():
    rng = np.random.default_rng(5)
    R = trimesh.transformations.rotation_matrix(1.1, [0.3, -1, 0.2])[:3, :3]
    P = (rng.normal(size=(2000, 3)) * (0.25, 0.04, 0.03)) @ R.T + (0.5, 0.1, -0.2)
    e = enclose_points(P)
    (c,) = e.capsules
    assert inside(P, [c]).all()
    # the axis is (close to) the principal axis
    u = np.subtract(c.b, c.a) / c.length
    assert abs(u @ R[:, 0]) > 0.98
    # no larger than the capsule along the exact principal axis through the mean
    naive = capsule_along(P, R[:, 0], point=P.mean(axis=0))
    assert c.volume <= naive.volume * (1 + 1e-9)
    hull = trimesh.convex.convex_hull(P)
    S = surface(c, 20_000)
    sampled = np.abs(trimesh.proximity.closest_point(hull, S)[1]).max()
    assert sampled <= e.over_estimate + 1e-9
    assert sampled >= e.over_estimate - 0.01


def l_shape() -> trimesh.Trimesh:
    """An L-shaped bar (two 0.3 × 0.06 arms, 0.06 thick), watertight."""
    from shapely.geometry import Polygon
    poly = Polygon([(0, 0), (0.3, 0), (0.3, 0.06), (0.06, 0.06), (0.06, 0.3), (0, 0.3)])
    return trimesh.creation.extrude_polygon(poly, 0.06)


def check_mesh(mesh: trimesh.Trimesh, e, n_volume=4000):
    caps = e.capsules
    assert inside(mesh.vertices, caps, tol=1e-12).all()
    interior = trimesh.sample.volume_mesh(mesh, n_volume)     # points inside the solid
    assert len(interior) > n_volume // 10
    assert inside(interior, caps).all()
    S = union_surface(caps, 20_000)
    sampled = np.abs(trimesh.proximity.closest_point(mesh, S)[1]).max()
    assert sampled <= e.over_estimate + 1e-9
    size = float(np.linalg.norm(mesh.extents))
    assert sampled >= e.over_estimate - size / 50


def test_mesh_split_into_pieces_that_hold_the_solid():
    mesh = l_shape()
    one = enclose_mesh(mesh.vertices, mesh.faces, max_capsules=1)
    many = enclose_mesh(mesh.vertices, mesh.faces)
    assert len(one.capsules) == 1 and len(many.capsules) >= 2
    assert many.over_estimate < one.over_estimate
    for e in (one, many):
        check_mesh(mesh, e)


@pytest.mark.parametrize("make", [
    lambda: trimesh.creation.box((0.3, 0.1, 0.05)),
    lambda: trimesh.creation.cylinder(0.05, 0.4, sections=48),
    lambda: trimesh.creation.annulus(0.03, 0.08, 0.05, sections=48),
    lambda: trimesh.creation.icosphere(3, 0.1),
])
def test_mesh_primitives(make):
    mesh = make()
    check_mesh(mesh, enclose_mesh(mesh.vertices, mesh.faces))


def test_bad_meshes_are_refused():
    with pytest.raises(ValueError, match="no triangles"):
        enclose_mesh(np.zeros((3, 3)), np.zeros((0, 3), dtype=int))
    with pytest.raises(ValueError, match="NaN"):
        enclose_mesh(np.array([[0, 0, 0], [1, 0, 0], [0, np.nan, 0]]), [[0, 1, 2]])
