"""The values ``rmt view`` shows, against independent ones: the tool pose by plain numpy FK, σ_min by the
closed-form Jacobian of the planar 2R, the nearest obstacle and self pair by coal, the windows by their
closed form (|q2| ≤ margin), the tool handle's IK by FK of its answer; the path and trajectory readers,
the reach targets, and the refusals of the command (busy port, bad host, viser missing)."""
from __future__ import annotations

import contextlib
import io
import re
import socket
import sys

import numpy as np
import pytest

import kin
from planning.collision import collision_world
from studies.cli import main
from studies.view.handle import solve_handle
from studies.view.playback import TrajectoryFileError, path_timeline, trajectory_timeline
from studies.view.plot import window_runs
from studies.view.readouts import LiveModel
from studies.view.scene import body_poses, capsule_parts, nearest_to_ray, slider_spec
from tests.coal_ref import capsule, distance

coal = pytest.importorskip("coal")

CELL = """name = "two blocks"
length_unit = "m"
angle_unit = "deg"
[robot]
xyz = [0.2, -0.1, 0.05]
rpy = [0, 0, 30]
[[obstacle]]
name = "near block"
type = "box"
size = [0.1, 0.1, 0.1]
xyz = [1.6, 1.1, 0]
[[obstacle]]
name = "far block"
type = "box"
size = [0.2, 0.2, 0.2]
xyz = [-0.9, -1.2, 0]
[[tool]]
name = "gripper"
type = "capsule"
a = [0, 0, 0]
b = [0.15, 0, 0]
radius = 0.03
"""
BOXES = {"near block": ((1.6, 1.1, 0.0), (0.1, 0.1, 0.1)), "far block": ((-0.9, -1.2, 0.0), (0.2, 0.2, 0.2))}
YAW = np.radians(30)
PLACE = np.array([[np.cos(YAW), -np.sin(YAW), 0, 0.2], [np.sin(YAW), np.cos(YAW), 0, -0.1], [0, 0, 1, 0.05],
                  [0, 0, 0, 1.0]])


def frames(q) -> list[np.ndarray]:
    """Bodies 0 … 3 of the planar 2R (a1 = 1, a2 = 0.8; tool = frame 2) in the cell, plain numpy."""
    def A(t, a):
        return np.array([[np.cos(t), -np.sin(t), 0, a * np.cos(t)], [np.sin(t), np.cos(t), 0, a * np.sin(t)],
                         [0, 0, 1, 0], [0, 0, 0, 1.0]])
    F1 = PLACE @ A(q[0], 1.0)
    F2 = F1 @ A(q[1], 0.8)
    return [PLACE, F1, F2, F2]


def coal_capsule(c, F):
    """Capsule ``c`` placed by its body's frame ``F``, as a coal object."""
    return capsule((F @ [*c.a, 1])[:3], (F @ [*c.b, 1])[:3], c.radius)


@pytest.fixture(scope="module")
def planar(tmp_path_factory):
    d = tmp_path_factory.mktemp("view")
    (d / "cell.toml").write_text(CELL)
    robot = kin.load_robot("planar_2r")
    world = collision_world(robot, d / "cell.toml")
    from planning.windows import build_windows
    ws = build_windows(robot, margin=0.1)
    return robot, world, LiveModel(robot, world, ws, 1e-3, "1e-3 (test)", "cell frame"), d


@pytest.mark.parametrize("q", [(0.3, 0.9), (0.62, 0.05), (-2.0, 1.4), (0.64, 0.0)])
def test_readout_matches_numpy_fk_closed_form_sigma_and_coal(planar, q):
    robot, world, model, _ = planar
    q = np.array(q)
    r = model.readout(q)
    F = frames(q)
    assert np.allclose(r.pose, F[3], atol=1e-12)
    # σ_min of the planar 2R's position Jacobian (task rows x, y), closed form
    s1, c1, s12, c12 = np.sin(q[0]), np.cos(q[0]), np.sin(q.sum()), np.cos(q.sum())
    J = np.array([[-s1 - 0.8 * s12, -0.8 * s12], [c1 + 0.8 * c12, 0.8 * c12]])
    assert r.sigma_min == pytest.approx(np.linalg.svd(J, compute_uv=False).min(), abs=1e-12)
    # the nearest obstacle by coal: every capsule against every box (none is ignored in this cell)
    caps = world.geometry.capsules
    boxes = {k: coal.CollisionObject(coal.Box(*size), coal.Transform3s(np.eye(3), np.array(c)))
             for k, (c, size) in BOXES.items()}
    d = {(cp.body, k): distance(coal_capsule(cp, F[cp.body]), b) for cp in caps for k, b in boxes.items()}
    (body, name), dmin = min(d.items(), key=lambda kv: kv[1])
    assert r.obstacle is not None and r.obstacle.other == name and r.obstacle.distance == pytest.approx(dmin, abs=1e-7)
    # the self pairs the world checks, by coal
    pairs = [(a, b) for a, b in world.pairs]
    ds = [distance(coal_capsule(ca, F[ca.body]), coal_capsule(cb, F[cb.body]))
          for a, b in pairs for ca in caps if ca.body == a for cb in caps if cb.body == b]
    if ds:
        assert r.self_pair is not None and r.self_pair.distance == pytest.approx(min(ds), abs=1e-7)
    assert r.clearance == pytest.approx(min([dmin] + ds), abs=1e-7)
    assert r.in_collision == (min([dmin] + ds) <= 0)
    # windows: the singular set of the 2R is q2 ∈ {0, ±π}; margin 0.1 rad
    inside = min(abs(q[1]), abs(abs(q[1]) - np.pi)) <= 0.1
    assert bool(r.windows) == inside
    assert r.alarm == (inside or r.in_collision or r.sigma_min < 1e-3)
    text = "\n".join(model.lines(r))
    assert f"x {r.pose[0, 3]:.6g}" in text and "σ_min" in text and ("IN WINDOW" in text) == inside


def test_body_poses_and_capsules_are_placed_in_their_bodies(planar):
    robot, world, model, _ = planar
    q = np.array([0.4, -1.1])
    P = body_poses(model, q)
    for k, F in enumerate(frames(q)):
        assert np.allclose(P[k], F, atol=1e-12)
    for part in capsule_parts(world):                    # every vertex on its capsule's surface (body frame)
        caps = [c for c in world.geometry.capsules if c.body == part.body]
        V = part.vertices
        dist = np.full(len(V), np.inf)
        for c in caps:
            a, b = np.array(c.a), np.array(c.b)
            ab = b - a
            t = np.clip(((V - a) @ ab) / max(ab @ ab, 1e-300), 0, 1) if ab @ ab > 0 else np.zeros(len(V))
            dist = np.minimum(dist, np.abs(np.linalg.norm(V - (a + t[:, None] * ab), axis=1) - c.radius))
        assert dist.max() < 1e-9


def test_sliders_are_in_robot_file_units():
    c = kin.load_robot("fanuc_lrmate200id").chain
    spec = slider_spec(c)
    assert [s["label"] for s in spec] == [f"J{i} [deg]" for i in range(1, 7)]
    assert spec[0]["min"] == pytest.approx(-170) and spec[0]["max"] == pytest.approx(170)
    assert spec[5]["min"] == pytest.approx(-360) and spec[0]["step"] == 0.01


def test_tool_handle_picks_the_nearest_valid_branch():
    from kin.geometry import body_frames
    robot = kin.load_robot("fanuc_lrmate200id")
    world = collision_world(robot, None)
    model = LiveModel(robot, world)
    q_now = np.radians([10, 20, -15, 30, -60, 40])
    q_goal = q_now + np.radians([4, -3, 5, -6, 4, 3])
    target = body_frames(robot.chain, q_goal[None])[0, -1]              # plain numpy DH, not robot.fk
    ans = solve_handle(model, target, q_now)
    assert ans.valid and ans.candidates > 1
    assert np.abs(body_frames(robot.chain, ans.q[None])[0, -1] - target).max() < 1e-9
    assert np.allclose(ans.q, q_goal, atol=1e-7)                        # the branch the drag started on
    far = target.copy()
    far[:3, 3] += [5.0, 0, 0]
    out = solve_handle(model, far, q_now)
    assert out.q is None and "out of reach" in out.text


def test_tool_handle_of_a_chain_without_closed_form_follows_the_drag(planar):
    robot, world, model, _ = planar
    q_now = np.array([0.3, 0.9])
    target = frames(np.array([0.35, 0.85]))[3]
    ans = solve_handle(model, target, q_now)
    assert ans.q is not None and np.allclose(frames(ans.q)[3][:2, 3], target[:2, 3], atol=1e-6)
    assert np.allclose(ans.q, [0.35, 0.85], atol=1e-5)


def test_path_timeline_and_trajectory_reader(planar, tmp_path):
    robot, world, model, _ = planar
    (tmp_path / "p.csv").write_text("q1,q2\n0,0.5\n0,0.5\n1,0.5\n1,1.5\n")
    tl = path_timeline(robot, tmp_path / "p.csv")
    assert not tl.timed and np.allclose(tl.t, [0, 0.5, 1]) and np.allclose(tl.at(0.25), [0.5, 0.5])
    trace = tl.tool_trace(model, 50)
    assert np.allclose(trace[0], frames([0, 0.5])[3][:3, 3]) and np.allclose(trace[-1], frames([1, 1.5])[3][:3, 3])
    (tmp_path / "t.csv").write_text(H + "0,0,0.5,0,0,0,0\n0.5,0.2,0.6,0,0,0,0\n2,1,1,0,0,0,0\n")
    tt = trajectory_timeline(robot, tmp_path / "t.csv")
    assert tt.timed and tt.duration == 2 and tt.playback_speed() == 1.0
    assert np.allclose(tt.at(1.25), [0.6, 0.8])


#: the header of a planar_2r trajectory file (what rmt time --out writes; studies.export.trajectory reads it)
H = "t,q1,q2,qd1,qd2,qdd1,qdd2\n"


@pytest.mark.parametrize("text, words", [
    (H + "0,0,nan,0,0,0,0\n1,0,0,0,0,0,0\n", "line 2: column q2 is nan"),
    (H + "0,0,0,0,0,0,0\n", "1 sample(s)"),
    ("t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3\n0,0,0,0,0,0,0,0,0,0\n1,0,0,0,0,0,0,0,0,0\n",
     "3 joint position columns"),                                   # another robot's trajectory
    (H + "0,0,0,0,0,0,0\n0,1,1,0,0,0,0\n", "times must increase"),
    (H + "0,0,x,0,0,0,0\n1,0,0,0,0,0,0\n", "'x' is not a number"),
    ("", "no header row"),
    (H + "0,0,9,0,0,0,0\n1,0,0,0,0,0,0\n", "outside its limits"),
])
def test_hostile_trajectories_get_one_line(planar, tmp_path, text, words):
    robot = planar[0]
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(TrajectoryFileError, match=re.escape(words)):
        trajectory_timeline(robot, f)


def test_window_runs_and_the_click_ray():
    s = np.linspace(0, 1, 11)
    inside = np.array([0, 1, 1, 0, 0, 0, 1, 0, 0, 1, 1], bool)
    assert np.allclose(window_runs(s, inside), [(0.1, 0.2), (0.6, 0.6), (0.9, 1.0)])
    P = np.array([[0, 0, 5], [1, 0, 5], [0, 1, 0]], float)
    assert nearest_to_ray(P, [0.9, 0.1, 10], [0, 0, -1]) == 1
    assert nearest_to_ray(P, [0, 0, 10], [0, 0, 1]) == 0          # behind the camera: the ray's start counts


def run(argv) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(argv)
    return code, err.getvalue()


def test_busy_port_bad_host_and_default_host_are_refused_or_local():
    from studies.cli.main import build_parser
    args = build_parser().parse_args(["view", "planar_2r"])
    assert args.host == "127.0.0.1" and args.port == 8080
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        port = s.getsockname()[1]
        code, err = run(["view", "planar_2r", "--port", str(port), "--no-browser"])
    assert code == 2 and f"--port {port}" in err and "in use" in err and len(err.strip().splitlines()) == 1
    code, err = run(["view", "planar_2r", "--host", "no-such-host.invalid", "--port", "8080", "--no-browser"])
    assert code == 2 and "--host no-such-host.invalid" in err and len(err.strip().splitlines()) == 1
    code, err = run(["view", "planar_2r", "--host", "192.0.2.1", "--port", "8080", "--no-browser"])   # TEST-NET-1
    assert code == 2 and "--host 192.0.2.1: not an address of this machine" in err
    code, err = run(["view", "planar_2r", "--port", "70000"])
    assert code == 2 and "--port" in err


def test_hostile_files_are_refused_before_serving(planar, tmp_path):
    (tmp_path / "bad.csv").write_text(H + "0,0,nan,0,0,0,0\n1,0,0,0,0,0,0\n")
    code, err = run(["view", "planar_2r", "--trajectory", str(tmp_path / "bad.csv"), "--port", "0", "--no-browser"])
    assert code == 2 and "is nan" in err and len(err.strip().splitlines()) == 1
    code, err = run(["view", "planar_2r", "--path", str(tmp_path / "none.csv"), "--port", "0", "--no-browser"])
    assert code == 2 and "none.csv" in err
    code, err = run(["view", "planar_2r", "--reach", str(tmp_path), "--port", "0", "--no-browser"])
    assert code == 2 and "--reach" in err and "reach.json" in err


def test_without_viser_one_line_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "viser", None)
    code, err = run(["view", "planar_2r", "--no-browser"])
    assert code == 2 and "pip install 'rmtkit[view]'" in err and len(err.strip().splitlines()) == 1
