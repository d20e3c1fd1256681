"""The reach study against closed forms: the planar 2R's annulus (l1 = 1.0, l2 = 0.8), its elbow
angle for the joint-limit and window reasons, its Jacobian for the score, and a box in a cell for
the collision reason."""
import dataclasses
import math

import numpy as np
import pytest

import kin
from design.reach import REASONS, ReachSettings, ScoreWeights, halton_configurations, reach_study
from design.task.model import Targets, TaskError
from design.task.targets import ring_points
from kin.geometry import Obstacle, Shape
from planning.cell import Cell

L1, L2 = 1.0, 0.8
C = np.array([0.5, 0.3, 0.0])
FAST = ReachSettings(starts=4, samples=1024, spins=4)


@pytest.fixture(scope="module")
def r2():
    return kin.load_robot("planar_2r")


def _ring(n=(8, 16, 1), lo=0.05, hi=2.0):
    return Targets(ring_points(C, lo, hi, n), tolerance=1e-6)


def _elbow(r):
    """|q2| (rad) that puts the 2R's tip at distance r from its base (NaN outside the annulus)."""
    c = (r ** 2 - L1 ** 2 - L2 ** 2) / (2 * L1 * L2)
    return np.where(np.abs(c) <= 1, np.arccos(np.clip(c, -1, 1)), np.nan)


def _sigma_min(q):
    """σ_min of the 2R's 2×2 position Jacobian, in numpy."""
    q1, q2 = q[:, 0], q[:, 1]
    J = np.stack([np.stack([-L1 * np.sin(q1) - L2 * np.sin(q1 + q2), -L2 * np.sin(q1 + q2)], -1),
                  np.stack([L1 * np.cos(q1) + L2 * np.cos(q1 + q2), L2 * np.cos(q1 + q2)], -1)], -2)
    return np.linalg.svd(J, compute_uv=False)[:, -1]


@pytest.mark.parametrize("base", [(0.5, 0.3), (0.0, 0.0), (1.1, -0.4)])
def test_verdicts_equal_the_annulus(r2, base):
    t = _ring()
    s = reach_study(r2, t, placement=[*base, 0, 0, 0, 0], settings=FAST)
    d = np.linalg.norm(t.positions[:, :2] - np.array(base), axis=1)
    closed = (d >= L1 - L2) & (d <= L1 + L2)
    clear = np.abs(d - (L1 - L2)) > 1e-4
    clear &= np.abs(d - (L1 + L2)) > 1e-4
    assert np.array_equal(s.reached[clear], closed[clear])
    assert set(s.reason[~s.reached]) <= {"out_of_reach"}
    # the solutions reach their targets (placement applied): independent FK in numpy
    q = s.q[s.reached]
    tip = np.column_stack([L1 * np.cos(q[:, 0]) + L2 * np.cos(q.sum(1)), L1 * np.sin(q[:, 0]) + L2 * np.sin(q.sum(1))])
    assert np.allclose(tip + np.array(base), t.positions[s.reached, :2], atol=1e-6)


def test_same_inputs_same_verdicts(r2):
    t = _ring()
    a = reach_study(r2, t, placement=[0.2, 0.1, 0, 0, 0, 0], settings=FAST)
    b = reach_study(r2, t, placement=[0.2, 0.1, 0, 0, 0, 0], settings=FAST)
    assert np.array_equal(a.reached, b.reached) and np.array_equal(a.score, b.score)
    assert np.array_equal(halton_configurations(r2, 64), halton_configurations(r2, 64))


def test_score_is_the_documented_weighted_mean(r2):
    t = _ring(lo=0.3, hi=1.7)
    w = ScoreWeights(dexterity=0.5, clearance=0.25, limits=0.25)
    s = reach_study(r2, t, placement=[*C[:2], 0, 0, 0, 0], weights=w, settings=FAST)
    ref = _sigma_min(halton_configurations(r2, FAST.samples)).max()
    assert s.dexterity_ref == pytest.approx(ref, rel=1e-9)
    q = s.q[s.reached]
    sig = _sigma_min(q)
    margin = np.clip(np.minimum(q + math.pi, math.pi - q).min(axis=1) / math.pi, 0, 1)
    expect = (0.5 * np.minimum(sig / ref, 1) + 0.25 * margin) / 0.75      # no cell: no clearance term
    assert np.allclose(s.score[s.reached], expect, atol=1e-9)
    assert np.all(s.score[~s.reached] == 0)


def test_joint_limit_reason(r2):
    joints = list(r2.chain.joints)
    joints[1] = dataclasses.replace(joints[1], limits=(0.5, 1.0))
    r = kin.Robot(dataclasses.replace(r2.chain, joints=tuple(joints)))
    t = _ring(n=(24, 6, 1), lo=0.1, hi=1.9)
    s = reach_study(r, t, placement=[*C[:2], 0, 0, 0, 0], settings=FAST)
    d = np.linalg.norm(t.positions[:, :2] - C[:2], axis=1)
    q2 = _elbow(d)
    inside = (q2 >= 0.5 + 1e-3) & (q2 <= 1.0 - 1e-3)
    beyond = np.isfinite(q2) & ((q2 < 0.5 - 1e-3) | (q2 > 1.0 + 1e-3))
    assert np.all(s.reached[inside])
    assert np.all(s.reason[beyond] == "joint_limits")
    assert np.all(s.reason[np.isnan(q2)] == "out_of_reach")


def test_window_reason(r2):
    from planning.windows import build_windows
    W = build_windows(r2, margin=0.4)
    t = _ring(n=(30, 4, 1), lo=0.21, hi=1.79)
    s = reach_study(r2, t, placement=[*C[:2], 0, 0, 0, 0], windows=W, settings=FAST)
    q2 = _elbow(np.linalg.norm(t.positions[:, :2] - C[:2], axis=1))
    near = (q2 < 0.4 - 1e-3) | (q2 > math.pi - 0.4 + 1e-3)
    far = (q2 > 0.4 + 1e-3) & (q2 < math.pi - 0.4 - 1e-3)
    assert near.any() and far.any()
    assert np.all(s.reason[near] == "window")
    assert np.all(s.reached[far])


def test_collision_reason_names_the_obstacle():
    ur = kin.load_robot("ur5e")
    P = np.array([[0.5, 0.0, 0.2], [0.5, 0.05, 0.25], [0.0, 0.5, 0.3]])
    box = Obstacle("crate", (Shape("box", (0.15, 0.15, 0.15), np.array(
        [[1, 0, 0, 0.5], [0, 1, 0, 0], [0, 0, 1, 0.2], [0, 0, 0, 1.0]])),))
    cell = Cell("test cell", obstacles=(box,))
    t = Targets(P, tolerance=1e-5)
    s = reach_study(ur, t, cell=cell, settings=FAST)
    assert list(s.reason[:2]) == ["collision", "collision"]
    assert list(s.obstacle[:2]) == ["crate", "crate"] and "crate" in s.detail[0]
    assert s.reached[2] and s.clearance[2] > 0
    assert s.obstacle_counts() == {"crate": 2}
    # the clearance term is in the score now: recompute the reached target's score
    w = s.weights
    expect = (w.dexterity * min(s.dexterity[2] / s.dexterity_ref, 1) + w.clearance * min(s.clearance[2] / 0.05, 1)
              + w.limits * s.limit_margin[2]) / (w.dexterity + w.clearance + w.limits)
    assert s.score[2] == pytest.approx(expect, rel=1e-12)


def test_json_round_trip_and_reasons_listed(r2):
    import json

    from design.reach import ReachStudy
    s = reach_study(r2, _ring(n=(4, 4, 1)), settings=FAST)
    back = ReachStudy.from_dict(json.loads(json.dumps(s.to_dict())))
    assert np.array_equal(back.reached, s.reached) and np.allclose(back.placement, s.placement)
    assert set(s.reason) <= set(REASONS) | {"reached"}
    bad = s.to_dict()
    bad["per_target"][0]["score"] = 2.0
    with pytest.raises(TaskError, match=r"per_target\[0\]"):
        ReachStudy.from_dict(bad, "b.json")


@pytest.mark.parametrize("kw", [dict(starts=0), dict(starts=65), dict(spins=0), dict(samples=8),
                                dict(max_iter=True), dict(starts=8, samples=4)])
def test_hostile_settings(kw):
    with pytest.raises(TaskError):
        ReachSettings(**kw)


@pytest.mark.parametrize("kw", [dict(dexterity=-1), dict(dexterity=float("nan")),
                                dict(dexterity=0, clearance=0, limits=0),
                                dict(measure="kappa"), dict(dexterity_ref=0), dict(clearance_ref=-0.1),
                                dict(limits="1")])
def test_hostile_weights(kw):
    with pytest.raises(TaskError):
        ScoreWeights(**kw)


def test_hostile_placement_and_hint(r2):
    t = _ring(n=(2, 2, 1))
    for bad in ([0, 0, 0], [0, 0, 0, 0, 0, float("nan")], np.eye(4) * 2, "origin"):
        with pytest.raises(TaskError, match="placement"):
            reach_study(r2, t, placement=bad, settings=FAST)
    with pytest.raises(TaskError, match="hint"):
        reach_study(r2, t, settings=FAST, hint=np.zeros((3, 2)))
