"""Mesh enclosure (kin/geometry/meshfit.py) against independent numbers: slabs against trimesh's own
slicing of the mesh, surface samples against trimesh's random surface points, proxies and fits
holding every point (plain numpy distances), the floor of the over-estimate against sampled distances
(trimesh's closest points), and the fast search against the exhaustive one."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull, cKDTree

from kin.geometry.enclose import over_bounds, point_triangle_distance, segment_distance, union_volume
from kin.geometry.meshfit import Surface, _proxy_capsules, fit_mesh
from tests.kin.geometry.test_enclose import check_mesh, inside, l_shape, union_surface


def meshes():
    return {"L": l_shape(), "annulus": trimesh.creation.annulus(0.03, 0.08, 0.05, sections=32),
            "sphere": trimesh.creation.icosphere(2, 0.1), "capsule": trimesh.creation.capsule(0.3, 0.05)}


@pytest.mark.parametrize("name", ["L", "annulus", "capsule"])
def test_slab_points_span_the_slab_of_the_solid(name):
    """The convex hull of a slab's points (corners between the planes and edge crossings) is the hull of
    the part of the solid between them, which trimesh slices off with capped planes."""
    mesh = meshes()[name]
    surface = Surface(np.asarray(mesh.vertices)[mesh.faces])
    rng = np.random.default_rng(5)
    for _ in range(6):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        s = surface.V @ n
        lo, hi = np.sort(rng.uniform(s.min(), s.max(), 2))
        P = surface.slab(s, lo, hi, lambda o: surface.crossings(s, o))
        part = trimesh.intersections.slice_mesh_plane(mesh, n, lo * n, cap=True)
        part = trimesh.intersections.slice_mesh_plane(part, -n, hi * n, cap=True)
        assert ConvexHull(P).volume == pytest.approx(ConvexHull(part.vertices).volume, rel=1e-9)


@pytest.mark.parametrize("name", ["sphere", "L", "annulus"])
def test_samples_cover_the_surface(name):
    """Every point of the surface lies within max(spacing, longest edge / 16) of a sample, and each sample
    lies on the triangle it names (the distance function measures it against that triangle)."""
    mesh = meshes()[name]
    tris = np.asarray(mesh.vertices)[mesh.faces]
    spacing = float(np.linalg.norm(mesh.extents)) / 100
    pts, ids = Surface(tris).samples(spacing)
    assert point_triangle_distance(pts, tris[ids]).max() < 1e-12
    probe, _ = trimesh.sample.sample_surface(mesh, 20000, seed=3)
    reach = max(spacing, float(mesh.edges_unique_length.max()) / 16)
    assert cKDTree(pts).query(probe)[0].max() <= reach * (1 + 1e-9)


def test_proxy_capsules_hold_their_points():
    rng = np.random.default_rng(1)
    P = rng.normal(size=(400, 3)) * [0.3, 0.1, 0.05]
    M = rng.uniform(size=(12, 400)) < 0.4
    A, B, R = _proxy_capsules(P, M)
    for a, b, r, m in zip(A, B, R, M):
        assert (segment_distance(P[m], a, b) <= r * (1 + 1e-6)).all()


def test_the_floor_bounds_the_over_estimate_from_below():
    """Without a floor the upper bound is at least every sampled distance and the lower bound (a distance
    found on the surface) is within the tolerance of the largest sampled one; a floor above the largest
    distance is what comes back (nothing needs refining), one below changes nothing but the work."""
    mesh = l_shape()
    fit = fit_mesh(mesh.vertices, mesh.faces)
    S = union_surface(fit.capsules, 20_000)
    sampled = float(np.abs(trimesh.proximity.closest_point(mesh, S)[1]).max())
    upper, lower = over_bounds(fit.capsules, fit.distance, fit.size, tol=fit.size / 500)
    assert sampled - fit.size / 500 <= lower <= upper and sampled <= upper + 1e-9
    assert over_bounds(fit.capsules, fit.distance, fit.size, tol=fit.size / 500, floor=2 * upper)[0] == 2 * upper
    assert over_bounds(fit.capsules, fit.distance, fit.size, tol=fit.size / 500, floor=lower / 2)[0] == upper


@pytest.mark.parametrize("name", ["L", "annulus"])
def test_fast_and_exhaustive_searches_both_hold_and_agree(name):
    """Both searches hold the solid with a true over-estimate (tests/kin/geometry/test_enclose.py's
    check); the fast one's union is within 5 % of the exhaustive one's."""
    mesh = meshes()[name]
    fits = {s: fit_mesh(mesh.vertices, mesh.faces, search=s) for s in ("fast", "exhaustive")}
    for fit in fits.values():
        from kin.geometry.enclose import Enclosure
        check_mesh(mesh, Enclosure(fit.capsules, fit.over_estimate()))
        assert inside(mesh.vertices, fit.capsules, tol=1e-12).all()
    fast, exhaustive = (union_volume(fits[s].capsules, 200_000) for s in ("fast", "exhaustive"))
    assert fast <= 1.05 * exhaustive


def test_unknown_search_is_refused():
    mesh = l_shape()
    with pytest.raises(ValueError, match="search 'quick' unknown; allowed: fast, exhaustive"):
        fit_mesh(mesh.vertices, mesh.faces, search="quick")
