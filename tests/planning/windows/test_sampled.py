"""Point-set windows (planning.windows.sampled) against brute-force numpy distances, their JSON
round trip and validation, and windows built from a numeric analysis."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from kin.singular import analyse_singularities
from planning.errors import WindowError
from planning.windows import PointSetWindow, WindowSet, build_windows


def _window(normals=False, n=4):
    rng = np.random.default_rng(0)
    P = rng.uniform(-1, 1, size=(300, 2))
    kw = {}
    if normals:
        N = rng.normal(size=(300, 2))
        kw = {"normals": N / np.linalg.norm(N, axis=1, keepdims=True), "radius": rng.uniform(0, 0.1, 300)}
    return PointSetWindow("w", "other", "sigma_min(J; q2, q4)", (2, 4), 0.05, "margin", n, points=P, **kw)


def test_contains_is_distance_to_the_nearest_point_over_its_joints():
    w = _window()
    Q = np.random.default_rng(1).uniform(-1.2, 1.2, size=(2000, 4))
    d = np.sqrt(((Q[:, None, [1, 3]] - w.points[None]) ** 2).sum(-1)).min(1)     # brute force
    assert np.allclose(w.distance(Q), d)
    assert np.array_equal(w.contains(Q), d <= 0.05)
    assert w.contains(Q[0]) == bool(d[0] <= 0.05)


def test_disc_distance_matches_brute_force_over_all_discs():
    w = _window(normals=True)
    Q = np.random.default_rng(2).uniform(-1, 1, size=(500, 4))
    X = Q[:, [1, 3]]
    D = X[:, None, :] - w.points[None]
    h = np.einsum("nkd,kd->nk", D, w.normals)
    t = np.sqrt(np.maximum((D ** 2).sum(-1) - h ** 2, 0))
    brute = np.sqrt(h ** 2 + np.maximum(t - w.radius[None], 0) ** 2).min(1)
    # the window looks at the 16 nearest discs only: never nearer than the true minimum, equal almost always
    got = w.distance(Q)
    assert np.all(got >= brute - 1e-12) and np.mean(np.isclose(got, brute)) > 0.97


@pytest.mark.parametrize("normals", [False, True])
def test_json_round_trip(tmp_path, normals):
    ws = WindowSet("r", 4, [_window(normals)])
    ws.save(tmp_path / "w.json")
    back = WindowSet.load(tmp_path / "w.json")
    Q = np.random.default_rng(3).uniform(-1, 1, size=(1000, 4))
    assert isinstance(back.windows[0], PointSetWindow)
    assert np.array_equal(back.contains(Q), ws.contains(Q)) and np.array_equal(back.which(Q), ws.which(Q))


@pytest.mark.parametrize("edit", [
    lambda d: d.update(points=[[0.0, float("nan")]]),
    lambda d: d.update(points=[[0.0, "1"]]),
    lambda d: d.update(points=[[0.0]]),
    lambda d: d.update(width=-1.0),
    lambda d: d.update(width=True),
    lambda d: d.update(joints=[2, 9]),
    lambda d: d.update(radius=[0.1]),
    lambda d: d.update(normals=[[1.0, 1.0]] * 300),
    lambda d: d.pop("points"),
])
def test_malformed_entries_are_refused(tmp_path, edit):
    d = WindowSet("r", 4, [_window(True)]).to_dict()
    edit(d["windows"][0])
    (tmp_path / "w.json").write_text(json.dumps(d))
    with pytest.raises(WindowError):
        WindowSet.load(tmp_path / "w.json")


def test_wrong_shape_is_refused():
    with pytest.raises(WindowError, match="shape"):
        _window().contains(np.zeros((4, 3)))


@pytest.fixture(scope="module")
def puma_numeric(tmp_path_factory):
    robot = kin.load_robot("puma560")
    return robot, analyse_singularities(robot, exact_timeout=0.0, use_cache=False)


def test_windows_from_a_numeric_analysis(puma_numeric):
    robot, a = puma_numeric
    exact = analyse_singularities(robot)
    ws = build_windows(robot, margin=0.05, analysis=a)
    we = build_windows(robot, margin=0.05, analysis=exact)
    for w in ws.windows:
        if w.is_interval:      # one-joint components: the same intervals as the exact windows
            match = [x for x in we.windows if x.is_interval and x.joint == w.joint]
            assert np.allclose(match[0].intervals, w.intervals, atol=1e-6)
        else:
            assert isinstance(w, PointSetWindow) and w.kind == "shoulder"
    # configurations on the exact shoulder set, moved less than the width minus the
    # sampling resolution, are inside the numeric window
    f = exact.by_kind("shoulder")[0]
    S = f.samples
    inside = ws.contains(S + 0.02 * f.gradient(S) / np.linalg.norm(f.gradient(S), axis=1, keepdims=True))
    assert inside.mean() > 0.95


def test_sigma_min_windows_from_a_numeric_analysis(puma_numeric):
    robot, a = puma_numeric
    ws = build_windows(robot, sigma_min=0.01, analysis=a)
    Q = robot.random_configurations(20000, seed=11)
    out = ~ws.contains(Q)
    rows = list(robot.task_rows)
    s = np.linalg.svd(robot.jacobian(Q[out])[:, rows], compute_uv=False)[:, -1]
    assert s.min() >= 0.01 * 0.99


def test_margin_gradient_is_the_direction_from_the_nearest_point():
    w = _window()
    rng = np.random.default_rng(5)
    for q in rng.uniform(-1, 1, size=(20, 4)):
        x = q[[1, 3]]
        k = np.argmin(np.linalg.norm(w.points - x, axis=1))
        d = np.linalg.norm(w.points[k] - x)
        m, g = w.margin_and_gradient(q)
        assert abs(m - (d - 0.05)) < 1e-12 and np.allclose(g, (x - w.points[k]) / d, atol=1e-5)


def test_planning_and_checking_use_numeric_windows(puma_numeric):
    from planning.ompl import plan
    from planning.ompl.validity import JointSpaceChecker
    from planning.validate import check_path
    robot, a = puma_numeric
    ws = build_windows(robot, margin=0.05, analysis=a)
    checker = JointSpaceChecker(robot, ws)
    Q = robot.random_configurations(3000, seed=8)
    inside = ws.contains(Q)
    assert inside.any() and not inside.all()
    assert [checker.state_valid(list(q)) for q in Q] == list(~inside)
    assert np.array_equal(checker.batch_valid(Q), ~inside)
    # start and goal on the same side of every exact factor (the windows split the joint space)
    free = Q[~inside]
    side = np.sign(analyse_singularities(robot).values(free))
    same = free[np.all(side == side[0], axis=1)]
    d = np.linalg.norm(same - same[0], axis=1)
    start, goal = same[0], same[np.argsort(d)[len(d) // 2]]
    res = plan(robot, start, goal, ws, planner="RRTConnect", time_limit=5.0, seed=0)
    assert res.success
    report = check_path(robot, res.path, ws)
    assert report.valid
    # a straight line through the shoulder set is refused by check_path, naming the window
    f = [w for w in ws.windows if isinstance(w, PointSetWindow)][0]
    p = np.zeros(6)
    p[[j - 1 for j in f.joints]] = f.points[len(f.points) // 2]
    p[4] = 0.8                                      # away from the wrist window
    line = np.linspace(p - 0.2 * np.eye(6)[1], p + 0.2 * np.eye(6)[1], 50)
    bad = check_path(robot, line, ws)
    assert not bad.valid and bad.first_violation.kind == "window"


def test_sigma_min_windows_of_a_general_chain():
    """A 6R without spherical wrist: the exact path is cut, the numeric component's window keeps
    σ_min ≥ the threshold outside it on fresh samples (numpy SVD), all but a sampling remainder."""
    from tests.kin.singular.test_numeric import GENERAL_6R, chain_robot
    robot = chain_robot("general_6r", GENERAL_6R)
    a = analyse_singularities(robot, exact_timeout=1.0, numeric_time=20.0)
    assert a.method == "numeric"
    ws = build_windows(robot, sigma_min=0.002, analysis=a)
    assert [type(w) for w in ws.windows] == [PointSetWindow]
    Q = robot.random_configurations(20000, seed=21)
    out = ~ws.contains(Q)
    s = np.linalg.svd(robot.jacobian(Q[out]), compute_uv=False)[:, -1]
    assert out.mean() > 0.5                         # the window is a neighbourhood, not the whole space
    assert np.mean(s < 0.002) < 5e-4
