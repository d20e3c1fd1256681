"""planning.testing: a failing path gives the expected message, a valid one passes."""
import math
from pathlib import Path

import numpy as np
import pytest

import kin
from planning.ompl import KeepOutBox, plan
from planning.testing import assert_path_valid, assert_toolpath_valid
from planning.toolpath import load_toolpath
from planning.windows import build_windows

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def fanuc():
    robot = kin.load_robot("fanuc_m16ib20")
    return robot, build_windows(robot, margin=0.05)


def test_a_planned_path_passes(fanuc):
    robot, ws = fanuc
    start = np.array([0.0, -0.8, 0.7, 0.3, 0.8, 0.0])
    goal = np.array([0.5, -0.5, -1.6, -0.3, 0.9, 0.4])
    res = plan(robot, start, goal, ws, time_limit=2.0, seed=0)
    assert res.success
    assert_path_valid(robot, res.path, windows=ws, sigma_floor=0.01)


def test_a_path_through_the_shoulder_window_names_it(fanuc):
    robot, ws = fanuc
    P = np.array([[0, -0.8, 0.7, 0.3, 0.8, 0.0], [0.5, -0.5, -1.6, -0.3, 0.9, 0.4]])
    with pytest.raises(AssertionError) as e:
        assert_path_valid(robot, P, windows=ws)
    msg = str(e.value)
    w = next(w for w in ws.windows if w.kind == "shoulder")
    assert "segment 0 → 1" in msg and "shoulder window" in msg and w.expr in msg and "(proven)" in msg
    # the configuration named is on the segment and on the window's edge
    q = np.array([float(x) for x in msg.split("q = [")[1].split("]")[0].split(",")])
    d = P[1] - P[0]
    t = float(np.dot(q - P[0], d) / np.dot(d, d))
    assert np.allclose(P[0] + t * d, q, atol=1e-5)
    assert abs(abs(w.g(q[None])[0]) - w.epsilon) < 1e-4


def test_messages_are_in_file_units():
    robot = kin.load_robot("puma560")                      # degrees
    ws = build_windows(robot, margin=math.radians(3))
    a = np.radians([0, -45, 45, 0, -40, 0])
    b = np.radians([0, -45, 45, 0, 40, 0])
    with pytest.raises(AssertionError) as e:
        assert_path_valid(robot, np.array([a, b]), windows=ws)
    msg = str(e.value)
    assert "(deg)" in msg and "wrist window on joint 5" in msg
    q5 = float(msg.split("q = [")[1].split("]")[0].split(",")[4])
    assert q5 == pytest.approx(-3.0, abs=1e-6)             # enters the ±3° window at −3°


def test_limits_sigma_floor_and_keep_out(fanuc):
    robot, ws = fanuc
    P = np.array([[0, -0.8, 0.7, 0.3, 0.8, 0.0], [0, -0.8, 0.7, 0.3, 3.0, 0.0]])
    with pytest.raises(AssertionError, match=r"row 1.*joint 5 is outside its limits \[-2.44, 2.44\]"):
        assert_path_valid(robot, P)
    P = np.array([[0, -0.8, 0.7, 0.3, 0.8, 0.0], [0, -0.8, 0.7, 0.3, 0.2, 0.0]])
    sig = robot.sigma_min(np.array([P[0] + t * (P[1] - P[0]) for t in np.linspace(0, 1, 2001)]))
    floor = float(sig.min() + 0.5 * (sig.max() - sig.min()))
    with pytest.raises(AssertionError, match=r"σ_min = .* below the floor .*\(proven\)"):
        assert_path_valid(robot, P, sigma_floor=floor)
    assert_path_valid(robot, P, sigma_floor=float(sig.min()) * 0.99)
    tool = robot.fk(P[0])[:3, 3]
    box = KeepOutBox(tuple(tool - 0.01), tuple(tool + 0.01))
    with pytest.raises(AssertionError, match=r"row 0.*tool point inside keep-out box 0"):
        assert_path_valid(robot, P, keep_out=[box])


def test_bad_input_fails_clearly(fanuc):
    robot, _ = fanuc
    with pytest.raises(AssertionError, match="expected"):
        assert_path_valid(robot, np.zeros((2, 5)))
    with pytest.raises(AssertionError, match="NaN"):
        assert_path_valid(robot, np.full((2, 6), np.nan))


@pytest.mark.parametrize("floor", [float("nan"), float("inf"), -0.01, "0.01", True])
def test_a_bad_sigma_floor_is_refused_not_ignored(fanuc, floor):
    """A NaN floor once passed silently a path through the wrist singularity (σ_min ≈ 1e-17)."""
    robot, _ = fanuc
    through = np.array([[0.0, -0.3, 0.4, 0.2, 0.8, 0.0], [0.0, -0.3, 0.4, 0.2, -0.8, 0.0]])
    with pytest.raises(kin.ConfigurationError, match="sigma_floor"):
        assert_path_valid(robot, through, sigma_floor=floor)
    with pytest.raises(AssertionError, match="σ_min"):
        assert_path_valid(robot, through, sigma_floor=0.01)


def test_windows_of_another_robot_are_refused(fanuc):
    _, ws = fanuc
    puma = kin.load_robot("puma560")
    from planning.errors import WindowError
    with pytest.raises(WindowError, match="another robot"):
        assert_path_valid(puma, np.zeros((2, 6)), windows=ws)


def test_toolpaths():
    scara = kin.load_robot("scara_rrp")
    assert_toolpath_valid(scara, load_toolpath(ROOT / "studies/toolpaths/scara_line.csv", scara))
    pen = kin.load_robot("ur3_homework_pen")
    path = load_toolpath(ROOT / "studies/toolpaths/ur3_drawing.toml", pen)
    ws = build_windows(pen, margin=0.05)
    start = pen.chain.to_si([0, 0, 1.5708, -1.5708, 0, 0])
    with pytest.raises(AssertionError, match=r"waypoint 0 .*window"):
        assert_toolpath_valid(pen, path, windows=ws, start_q=start)
