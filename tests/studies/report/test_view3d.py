"""The 3-D view draws what the kinematics computes: its frame origins against a plain numpy DH
product, its tool point against FK, its animation frames against the path's waypoints."""
from __future__ import annotations

import numpy as np

import kin
from studies.jointpath import densify
from studies.report.view3d import MAX_ANIMATION_FRAMES, MAX_CLOUD_POINTS, frame_origins, robot_view


def _dh(a, alpha, d, theta):
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]])


# docs/machines.md §3 (FANUC M-16iB/20, standard DH, m and rad): (a, alpha, d)
FANUC = [(0.150, -np.pi / 2, 0.525), (0.770, 0, 0), (0.100, np.pi / 2, 0), (0, -np.pi / 2, 0.740),
         (0, np.pi / 2, 0), (0, 0, 0.100)]


def _origins_numpy(q):
    T = np.eye(4)
    out = [T[:3, 3].copy()]
    for (a, al, d), qi in zip(FANUC, q):
        T = T @ _dh(a, al, d, qi)
        out.append(T[:3, 3].copy())
    return np.array(out)


def test_frame_origins_match_a_numpy_dh_product():
    robot = kin.load_robot("fanuc_m16ib20")
    for q in np.random.default_rng(3).uniform(-1.5, 1.5, (5, 6)):
        P = frame_origins(robot, q)
        assert P.shape == (8, 3)                       # base, 6 joint frames, tool
        np.testing.assert_allclose(P[:7], _origins_numpy(q), atol=1e-12)
        np.testing.assert_allclose(P[-1], robot.fk(q)[:3, 3], atol=1e-12)


def test_file_units_are_shown():
    robot = kin.load_robot("scara_rrp")                # millimetres
    q = np.array([0.0, 0.0, -0.197])
    P = frame_origins(robot, q)
    np.testing.assert_allclose(P[-1], [675, 0, -195], atol=1e-9)    # docs/machines.md §2
    fig = robot_view(robot, q)
    assert fig.layout.scene.xaxis.title.text == "x (mm)"


def test_animation_follows_the_path():
    robot = kin.load_robot("fanuc_m16ib20")
    Q = np.linspace([0, -0.5, 0.3, 0, 0.8, 0], [0.6, 0.2, -0.4, 0.5, 1.2, 0.3], 200)
    fig = robot_view(robot, Q[0], path=Q)
    assert len(fig.frames) == MAX_ANIMATION_FRAMES
    assert fig.frames[0].name == "0" and fig.frames[-1].name == "100"
    first = fig.frames[0].data[0]
    np.testing.assert_allclose(np.c_[first.x, first.y, first.z], frame_origins(robot, Q[0]), atol=1e-12)
    links = fig.frames[-1].data[0]
    np.testing.assert_allclose(np.c_[links.x, links.y, links.z], frame_origins(robot, Q[-1]), atol=1e-12)
    [slider] = fig.layout.sliders
    assert [st.label for st in slider.steps] == [f.name for f in fig.frames]
    tool = next(t for t in fig.data if t.name == "planned tool path")
    np.testing.assert_allclose([tool.x[-1], tool.y[-1], tool.z[-1]], robot.fk(Q[-1])[:3, 3], atol=1e-12)


def test_cloud_is_subsampled_with_near_singular_in_red():
    robot = kin.load_robot("fanuc_m16ib20")
    rng = np.random.default_rng(0)
    small = rng.normal(size=(500, 3))
    near = np.arange(500) % 5 == 0
    fig = robot_view(robot, np.zeros(6), cloud=small, near_singular=near)
    red = next(t for t in fig.data if t.name.startswith("near-singular"))
    grey = next(t for t in fig.data if t.name.startswith("workspace"))
    assert len(red.x) == 100 and len(grey.x) == 400 and red.marker.color == "#d62728"
    np.testing.assert_allclose(np.c_[red.x, red.y, red.z], small[near])
    big = rng.normal(size=(3 * MAX_CLOUD_POINTS, 3))
    fig = robot_view(robot, np.zeros(6), cloud=big, near_singular=np.zeros(len(big), bool))
    assert sum(len(t.x) for t in fig.data if t.name.split()[0] in ("workspace", "near-singular")) == MAX_CLOUD_POINTS


def test_a_short_path_is_interpolated_through_its_waypoints():
    Q = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 3.0]])          # arc lengths 0, 1, 4
    D = densify(Q, 9)                                            # every 0.5 along the polyline
    np.testing.assert_allclose(D[[0, 2, 8]], Q)
    np.testing.assert_allclose(D[1], [0.5, 0.0])
    np.testing.assert_allclose(np.linalg.norm(np.diff(D, axis=0), axis=1), 0.5)
    robot = kin.load_robot("fanuc_m16ib20")
    P = np.array([[0, -0.8, 0.7, 0.3, 0.8, 0], [0.3, -0.6, 0.1, 0, 0.9, 0.2], [0.5, -0.5, -1.6, -0.3, 0.9, 0.4]])
    fig = robot_view(robot, P[0], path=P)
    assert len(fig.frames) == MAX_ANIMATION_FRAMES
    last = fig.frames[-1].data[0]
    np.testing.assert_allclose(np.c_[last.x, last.y, last.z], frame_origins(robot, P[-1]), atol=1e-12)
    tool = next(t for t in fig.data if t.name == "planned tool path")
    assert len(tool.x) > 100                                     # the curve the tool takes, not chords
    mid = densify(P, len(tool.x))[len(tool.x) // 2]
    np.testing.assert_allclose([tool.x[len(tool.x) // 2], tool.y[len(tool.x) // 2], tool.z[len(tool.x) // 2]],
                               robot.fk(mid)[:3, 3], atol=1e-12)


def test_targets_are_drawn_in_file_units():
    robot = kin.load_robot("scara_rrp")                          # millimetres
    T = np.array([[0.4, 0.1, -0.2], [0.3, -0.2, -0.15]])         # metres
    fig = robot_view(robot, np.array([0.0, 0.5, -0.2]), targets=T)
    tr = next(t for t in fig.data if t.name.startswith("task targets"))
    np.testing.assert_allclose(np.c_[tr.x, tr.y, tr.z], 1000 * T)
