"""Certified convex distances (kin.geometry.convex) against coal's GJK/EPA on the same solids, and
against closed forms (sphere–sphere, box–point)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from kin.geometry.convex import (
    CYLINDER_SIDES,
    box_solid,
    convex_distance,
    convex_distance_numpy,
    cylinder_solid,
    points_solid,
)
from kin.transforms import make_transform, rpy_to_matrix
from tests.coal_ref import hull, placed_distance

coal = pytest.importorskip("coal")


def _pose(rng, spread):
    return make_transform(rpy_to_matrix(rng.uniform(-math.pi, math.pi, 3)), rng.uniform(-spread, spread, 3))


@pytest.mark.parametrize("seed", range(20))
def test_hull_hull_and_hull_box_match_coal(seed):
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(40, 3)) * [0.2, 0.05, 0.08]
    Q = rng.normal(size=(30, 3)) * [0.06, 0.1, 0.03]
    T1, T2 = _pose(rng, 0.3), _pose(rng, 0.3)
    P1, Q2 = P @ T1[:3, :3].T + T1[:3, 3], Q @ T2[:3, :3].T + T2[:3, 3]
    ref = placed_distance(hull(P), T1, hull(Q), T2)
    got = convex_distance(points_solid(P1), points_solid(Q2))
    assert got <= ref + 1e-9 if ref > 0 else got <= 0.0    # a lower bound; never clear when touching
    if ref > 1e-6:
        assert got == pytest.approx(ref, abs=1e-7)        # and tight when apart
    half = rng.uniform(0.02, 0.2, 3)
    ref = placed_distance(hull(P), T1, coal.Box(*(2 * half)), T2)
    got = convex_distance(points_solid(P1), box_solid(half, T2))
    assert got <= ref + 1e-9 if ref > 0 else got <= 0.0
    if ref > 1e-6:
        assert got == pytest.approx(ref, abs=1e-7)


@pytest.mark.parametrize("seed", range(10))
def test_capsule_and_cylinder_match_coal(seed):
    rng = np.random.default_rng(100 + seed)
    P = rng.normal(size=(25, 3)) * 0.1
    T1 = _pose(rng, 0.05)
    P1 = P @ T1[:3, :3].T + T1[:3, 3]
    T2 = _pose(rng, 0.5)
    r, hl = 0.04, 0.15
    a, b = T2[:3, 3] - hl * T2[:3, 2], T2[:3, 3] + hl * T2[:3, 2]
    ref = placed_distance(hull(P), T1, coal.Capsule(r, 2 * hl), T2)
    got = convex_distance(points_solid(P1), points_solid([a, b], r))
    assert got <= ref + 1e-9 if ref > 0 else got <= 0.0
    if ref > 1e-6:
        assert got == pytest.approx(ref, abs=1e-7)
    ref = placed_distance(hull(P), T1, coal.Cylinder(r, 2 * hl), T2)
    got = convex_distance(points_solid(P1), cylinder_solid(r, hl, T2))
    assert got <= ref + 1e-9 if ref > 0 else got <= 0.0
    if ref > 1e-6:                   # the prism around the cylinder stands out by at most this
        assert got >= ref - r * (1 / math.cos(math.pi / CYLINDER_SIDES) - 1) - 1e-9


def test_closed_forms():
    s1, s2 = points_solid([[0, 0, 0]], 0.1), points_solid([[0.5, 0.2, 0.1]], 0.2)
    assert convex_distance(s1, s2) == pytest.approx(math.sqrt(0.25 + 0.04 + 0.01) - 0.3, abs=1e-12)
    box = box_solid([0.1, 0.2, 0.3], np.eye(4))
    assert convex_distance(points_solid([[0.4, 0.0, 0.0]]), box) == pytest.approx(0.3, abs=1e-12)
    assert convex_distance(points_solid([[0.4, 0.5, 0.0]]), box) == pytest.approx(math.hypot(0.3, 0.3), abs=1e-12)
    # overlapping solids: not certified clear
    assert convex_distance(points_solid([[0.05, 0, 0], [0.5, 0, 0]]), box) <= 0.0


@pytest.mark.parametrize("seed", range(10))
def test_placed_solids_and_the_numpy_search_agree(seed):
    """A solid placed by a pose is the same as its points moved; the C search and numpy agree."""
    rng = np.random.default_rng(200 + seed)
    P, Q = rng.normal(size=(30, 3)) * 0.1, rng.normal(size=(20, 3)) * 0.05
    T1, T2 = _pose(rng, 0.4), _pose(rng, 0.4)
    placed = convex_distance(points_solid(P, 0.01, T1), points_solid(Q, 0.02, T2))
    moved = convex_distance(points_solid(P @ T1[:3, :3].T + T1[:3, 3], 0.01),
                            points_solid(Q @ T2[:3, :3].T + T2[:3, 3], 0.02))
    numpy = convex_distance_numpy(points_solid(P, 0.01, T1), points_solid(Q, 0.02, T2))
    assert placed == pytest.approx(moved, abs=1e-9) and placed == pytest.approx(numpy, abs=1e-9)
