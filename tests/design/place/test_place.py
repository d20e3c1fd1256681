"""Placement: the planar 2R's ring (only its centre reaches every target), keep-out rectangles, the
region's validation, grids; co-design's Pareto front; two robots' capsule clearance by hand."""
import math

import numpy as np
import pytest

import kin
from design.place import PlacementRegion, grid_placements, halton_placements, place, placement_transform
from design.place.codesign import pareto_front
from design.place.pair import robot_robot_clearance
from design.reach import ReachSettings
from design.task.model import Targets, TaskError
from design.task.targets import ring_points

C = np.array([0.5, 0.3, 0.0])
FAST = ReachSettings(starts=4, samples=1024, spins=4)


def _ring_with_edges():
    th = np.linspace(0, 2 * np.pi, 36, endpoint=False)
    circ = lambda R: C + R * np.column_stack([np.cos(th), np.sin(th), 0 * th])
    return Targets(np.vstack([circ(0.2), ring_points(C, 0.2, 1.8, (6, 18, 1)), circ(1.8)]), tolerance=1e-6)


@pytest.fixture(scope="module")
def r2():
    return kin.load_robot("planar_2r")


def test_ring_centre_is_found(r2):
    t = _ring_with_edges()
    reg = PlacementRegion((-1, 2), (-1, 2), (0, 0), yaw=(0, 0))
    res = place(r2, t, region=reg, settings=FAST, starts=2, candidates=16)
    assert np.linalg.norm(res.u[:3] - C) < 1e-3
    assert res.study.coverage == 1.0
    # the reach study there agrees with the annulus (closed form)
    d = np.linalg.norm(t.positions[:, :2] - res.u[:2], axis=1)
    assert np.array_equal(res.study.reached, (d >= 0.2 - 1e-6) & (d <= 1.8 + 1e-6))
    # the configurations IPOPT returns put the tip on the targets (numpy FK, placement applied)
    q = res.ipopt[0].q
    tip = np.column_stack([np.cos(q[:, 0]) + 0.8 * np.cos(q.sum(1)), np.sin(q[:, 0]) + 0.8 * np.sin(q.sum(1))])
    assert np.abs(tip + res.ipopt[0].u[:2] - t.positions[:, :2]).max() < 1e-5
    assert res.to_dict()["placement"]["xyz"] == pytest.approx(list(res.u[:3]))


def test_keep_out_is_respected(r2):
    t = _ring_with_edges()
    reg = PlacementRegion((-1, 2), (-1, 2), (0, 0), yaw=(0, 0), keep_out=((0.4, 0.6, 0.2, 0.4),))
    res = place(r2, t, region=reg, settings=FAST, starts=2, candidates=16, grid=8)
    for m in res.methods.values():
        x, y = m["placement"][:2]
        assert not (0.4 < x < 0.6 and 0.2 < y < 0.4)
    assert res.study.coverage < 1.0        # only the centre reaches every target, and it is kept out
    assert all(not (0.4 < u[0] < 0.6 and 0.2 < u[1] < 0.4) for u in grid_placements(reg, 8))


def test_grid_and_halton_placements():
    reg = PlacementRegion((0, 1), (0, 2), (0.5, 0.5), yaw=(-math.pi, math.pi))
    G = grid_placements(reg, 5)
    assert G.shape == (125, 6)
    assert np.allclose(np.unique(G[:, 0]), np.linspace(0, 1, 5))
    assert len(np.unique(G[:, 5])) == 5 and G[:, 5].max() < math.pi     # a full turn has no duplicate end
    assert np.all(G[:, 2] == 0.5)
    H = halton_placements(reg, 40)
    assert H.shape == (40, 6) and np.array_equal(H, halton_placements(reg, 40))
    assert np.all((H[:, 0] >= 0) & (H[:, 0] <= 1) & (H[:, 1] >= 0) & (H[:, 1] <= 2))
    T = placement_transform([1, 2, 3, 0, 0, math.pi / 2])
    assert np.allclose(T[:3, 0], [0, 1, 0]) and np.allclose(T[:3, 3], [1, 2, 3])


@pytest.mark.parametrize("kw", [dict(x=(1, 0), y=(0, 1)), dict(x=(0, 1), y=(0, float("nan"))),
                                dict(x=(0, 1, 2), y=(0, 1)),
                                dict(x=(0, 0), y=(0, 0), yaw=(0, 0)), dict(x=(0, 1), y=(0, 1), tilt=2.0),
                                dict(x=(0, 1), y=(0, 1), keep_out=((0, 1, 0),)),
                                dict(x=(0, 1), y=(0, 1), keep_out=((1, 0, 0, 1),)),
                                dict(x=(0, 1), y=(0, 1), tilt=True)])
def test_hostile_region(kw):
    with pytest.raises(TaskError):
        PlacementRegion(**kw)


def test_hostile_place_arguments(r2):
    t = _ring_with_edges()
    reg = PlacementRegion((0, 1), (0, 1), (0, 0), yaw=(0, 0), keep_out=((-1, 2, -1, 2),))
    with pytest.raises(TaskError, match="keep-out"):
        place(r2, t, region=reg, settings=FAST)
    for kw in (dict(starts=0), dict(grid=-1), dict(candidates=True), dict(de_iterations=1.5), dict(polish="2"),
               dict(max_time=float("nan")), dict(max_time=0), dict(seed=-1)):
        with pytest.raises(TaskError):
            place(r2, t, settings=FAST, **kw)


def test_pareto_front_by_brute_force():
    rng = np.random.default_rng(3)
    rows = [{"coverage": float(c), "mean_score": float(s), "structural_length": float(length)}
            for c, s, length in rng.uniform(size=(60, 3))]
    rows.append({"coverage": 0.5})             # missing metrics: left out
    front = set(pareto_front(rows))
    for i, a in enumerate(rows[:-1]):
        beaten = any(b["coverage"] >= a["coverage"] and b["mean_score"] >= a["mean_score"]
                     and b["structural_length"] <= a["structural_length"] and b != a for b in rows[:-1])
        assert (i in front) == (not beaten)
    assert 60 not in front


def test_robot_robot_clearance_by_hand(r2):
    from planning.collision import collision_world
    wa, wb = collision_world(r2), collision_world(r2)
    wb.move_base(placement_transform([4.0, 0, 0, 0, 0, math.pi]))     # facing robot A, 4 m away
    caps = r2.geometry.capsules
    # both stretched along the line between them: the tips' capsules are the nearest
    reach = max(np.hypot(*c.b[:2]) for c in caps if c.body == 2) + 1.0       # tip end in the world (frame 2 at x = 1)
    radius = max(c.radius for c in caps if c.body == 2)
    got = robot_robot_clearance(wa, np.zeros((1, 2)), wb, np.zeros((1, 2)))[0, 0]
    tip_gap = 4.0 - 2 * max(1.8, reach)
    assert got == pytest.approx(tip_gap - 2 * radius, abs=1e-9)
    # folded back (q2 = π), robot A's elbow (x = 1) is its point nearest B's tip (x = 4 − 1.8)
    far = robot_robot_clearance(wa, np.array([[0.0, math.pi]]), wb, np.zeros((1, 2)))[0, 0]
    r1 = max(c.radius for c in caps if c.body == 1)
    assert far == pytest.approx((4.0 - 1.8 - 1.0) - r1 - radius, abs=1e-9)
