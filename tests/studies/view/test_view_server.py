"""The viser scene of ``rmt view`` driven from Python (no browser): the bodies follow the sliders to the
poses of plain numpy DH frames, the robot turns red in collision and back, dragging the tool handle moves
the sliders to an IK answer that reaches the handle, the timeline plays a path, a reach target clicked
(or picked) jumps to its configuration, the capsules checkbox hides the capsules of bodies with a mesh."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from planning.collision import collision_world
from studies.cli.common import cell_file
from studies.view.readouts import LiveModel
from studies.view.scene import ALARM_RGB

viser = pytest.importorskip("viser")


def dh_tool(chain, q, base):
    """The tool frame by plain numpy DH (standard convention: Rz(θ)·Tz(d)·Tx(a)·Rx(α))."""
    from kin.geometry.frames import dh_rows
    T = base @ chain.base.matrix
    for k, (a, alpha, d, theta, pris) in enumerate(dh_rows(chain)):
        th, dd = theta + (0 if pris else q[k]), d + (q[k] if pris else 0)
        ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(alpha), np.sin(alpha)
        T = T @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, dd],
                          [0, 0, 0, 1.0]])
    return T @ chain.tool.matrix


@pytest.fixture(scope="module")
def view(tmp_path_factory):
    from studies.view.playback import path_timeline
    from studies.view.server import ViewServer
    from studies.view.targets import load_reach
    robot = kin.load_robot("fanuc_lrmate200id")
    assert robot.chain.convention == "standard"
    world = collision_world(robot, cell_file("fanuc_weld_cell"))
    model = LiveModel(robot, world, None, 1e-3, "1e-3", "cell frame")
    d = tmp_path_factory.mktemp("view")
    (d / "p.csv").write_text("q1,q2,q3,q4,q5,q6\n0,0,0,0,-90,0\n40,20,-10,0,-80,0\n")
    Q = np.radians([[0, 0, 0, 0, -90, 0], [20, 10, -5, 10, -70, 5], [-30, 15, 0, 0, -60, 0]])
    P = np.array([(model.tool_pose(q))[:3, 3] for q in Q])
    rows = [{"target": i, "x": p[0], "y": p[1], "z": p[2], "reached": i != 2, "score": [0.9, 0.4, 0.0][i],
             "reason": "reached" if i != 2 else "collision", "q": Q[i].tolist()} for i, p in enumerate(P)]
    (d / "task").mkdir()
    (d / "task" / "reach.json").write_text(json.dumps({
        "robot": robot.name, "placement": {"xyz": world.base[:3, 3].tolist(), "rpy": [0, 0, 0]},
        "per_target": rows}))
    study = load_reach(str(d), robot)
    v = ViewServer(model, Q[0], host="127.0.0.1", port=0, timeline=path_timeline(robot, d / "p.csv"), study=study)
    yield v, robot, world, Q
    v.stop()


def test_sliders_move_the_bodies_and_the_readout(view):
    v, robot, world, _ = view
    q = np.radians([15, 25, -20, 35, -45, 60])
    for s, x in zip(v.sliders, np.degrees(q)):
        s.value = float(x)                      # as the browser does: each slider's update moves the robot
    assert np.allclose(v.q, q, atol=1e-12)
    T = dh_tool(robot.chain, q, world.base)
    tool = v.frames[robot.n + 1]
    R = viser.transforms.SO3(np.asarray(tool.wxyz)).as_matrix()
    assert np.allclose(tool.position, T[:3, 3], atol=1e-9) and np.allclose(R, T[:3, :3], atol=1e-9)
    x, y, z = T[:3, 3] * 1e3
    assert f"x {x:.6g}  y {y:.6g}  z {z:.6g}" in v.last_lines[0]


def test_collision_turns_the_robot_red_and_back(view):
    v, robot, world, Q = view
    hit = np.radians([0, 90, 0, 0, 0, 0])                       # leant forward into the fixture and table
    assert world.clearance(hit[None])[0] <= 0
    v.set_q(hit)
    colours = {tuple(h.color) for h, p in v.robot_nodes if p.kind != "tool"}
    assert colours == {ALARM_RGB} and any("IN COLLISION" in line for line in v.last_lines)
    v.set_q(Q[0])
    assert all(tuple(h.color) == p.rgb for h, p in v.robot_nodes)


def test_dragging_the_tool_handle_moves_the_sliders(view):
    v, robot, world, Q = view
    v.set_q(Q[0])
    goal = Q[0] + np.radians([5, -4, 3, 2, 5, -6])
    T = dh_tool(robot.chain, goal, world.base)
    v.handle.wxyz = viser.transforms.SO3.from_matrix(T[:3, :3]).wxyz
    v.handle.position = T[:3, 3]
    v._on_handle(None)                                           # what a drag in the browser triggers
    assert np.allclose(v.q, goal, atol=1e-7)
    assert np.allclose([s.value for s in v.sliders], np.degrees(goal), atol=1e-5)
    assert any("IK (closed form)" in line for line in v.last_lines)


def test_timeline_and_reach_targets_jump(view):
    v, robot, world, Q = view
    v.time_slider.value = 0.5
    assert np.allclose(v.q, np.radians([20, 10, -5, 0, -85, 0]), atol=1e-9)
    v.jump_to_target(1)
    assert np.allclose(v.q, Q[1], atol=1e-12) and "target 1" in v.last_lines[-1]
    P = np.asarray(v.study.positions)
    from studies.view.scene import nearest_to_ray
    assert nearest_to_ray(P, P[2] + [0, 0, 1.0], [0, 0, -1]) == 2


def test_capsules_checkbox_and_what_is_drawn(view):
    v, robot, _, _ = view
    kinds = {p.kind for _, p in v.robot_nodes}
    assert "tool" in kinds and "capsules" in kinds
    if not v.meshes:                                    # no real shape known: the capsules are the robot
        assert v.capsules.value and all(h.visible for h, _ in v.robot_nodes)
        assert "capsules" in v.notes[0]


def test_play_advances_the_timeline_and_pause_stops_it(view):
    import time
    v = view[0]
    v.time_slider.value = 0.0
    v.toggle_play()
    time.sleep(0.6)
    v.toggle_play()
    s = float(v.time_slider.value)
    time.sleep(0.3)
    assert 0.0 < s < 1.0 and float(v.time_slider.value) == s          # a path plays over 8 s; paused, it stays
    assert np.allclose(v.q, v.timeline.at(s), atol=1e-12)


def test_a_real_shape_is_drawn_and_the_checkbox_shows_the_capsules():
    from studies.shape.meshes import visual_meshes
    from studies.view.server import ViewServer
    robot = kin.load_robot("franka_panda")
    meshes = visual_meshes(robot)
    if not meshes:
        pytest.skip("no real shape of the Panda here (example-robot-data missing)")
    model = LiveModel(robot, collision_world(robot, None))
    v = ViewServer(model, np.clip(np.zeros(robot.n), robot.chain.lower, robot.chain.upper), host="127.0.0.1",
                   port=0)
    try:
        with_mesh = {m.body for m in meshes}
        assert {p.body for p in v.meshes} == with_mesh and not v.capsules.value
        hidden = [h for h, p in v.robot_nodes if p.kind == "capsules" and p.body in with_mesh]
        assert hidden and not any(h.visible for h in hidden)
        assert all(h.visible for h, p in v.robot_nodes if p.kind == "mesh")
        v.capsules.value = True
        assert all(h.visible for h in hidden)
        # the meshes ride on their bodies: the node of body k has body k's pose
        q = np.clip(np.full(robot.n, 0.3), robot.chain.lower, robot.chain.upper)
        v.set_q(q)
        from kin.geometry import body_frames
        F = body_frames(robot.chain, q[None])[0]
        for b in with_mesh:
            assert np.allclose(v.frames[b].position, F[b][:3, 3], atol=1e-9)
    finally:
        v.stop()
