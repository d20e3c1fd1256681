"""`rmt follow`: a bundled tool path followed on the UR3-like pen arm and on the SCARA, by the OSQP
follower and the naive resolved-rate method, checked against independent values — the reached
poses by a numpy DH product against the path's own numbers (the CSV rows read here, the drawing's
geometry of docs/machines.md §6), joint speeds by finite differences of the joint path, the numbers
the ur3_drawing study's tests know for the same drawing, and the SCARA's reach in closed form — and
bad input refused with one line (exit 2)."""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

import kin
from studies.cli import main
from studies.toolpaths import TOOLPATH_DIR
from tests.dh_numpy import fk_numpy

PEN_Q = ["0", "0", repr(math.pi / 2), repr(-math.pi / 2), "0", "0"]     # the drawing's singular start (rad)
MARGIN = repr(math.radians(5.0))                                          # ±5° windows, as the study's
N = 5001                                                                  # 5 segments × 1000 points + the start
START_TIP = np.array([-0.2173, -0.3878, 1.03611])                         # docs/machines.md §6
SCARA_REACH_MM = 675.0                                                    # docs/machines.md §2: 3 × 225 mm


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def pen():
    return kin.load_robot("ur3_homework_pen")


@pytest.fixture(scope="module")
def drawing():
    """`rmt follow ur3_homework_pen ur3_drawing --start <singular> --margin 5° --naive --json --waypoints`."""
    import contextlib
    import io
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["follow", "ur3_homework_pen", "ur3_drawing", "--start", *PEN_Q, "--margin", MARGIN, "--naive",
                     "--json", "--waypoints"])
    return code, json.loads(out.getvalue()), err.getvalue()


def _drawing_tips() -> np.ndarray:
    """The pen tip's targets (N, 3) m by the drawing's geometry (docs/machines.md §6): in the plane
    x = x0, counter-clockwise seen from +x, 1000 points per segment at constant speed — a quarter
    circle (R = 50 mm, centre start − (0, 0, R)) to the left, 50 mm down, 100 mm along +y, 50 mm up,
    the other quarter circle back."""
    x0, y0, z0 = START_TIP
    R, u, h = 0.05, np.arange(1, 1001) / 1000, math.pi / 2
    c = np.array([y0, z0 - R])
    yz = np.vstack([[y0, z0],
                    c + R * np.c_[np.cos(h + u * h), np.sin(h + u * h)],
                    np.c_[np.full(1000, y0 - R), z0 - R - u * R],
                    np.c_[y0 - R + 2 * R * u, np.full(1000, z0 - 2 * R)],
                    np.c_[np.full(1000, y0 + R), z0 - 2 * R + u * R],
                    c + R * np.c_[np.cos(u * h), np.sin(u * h)]])
    return np.c_[np.full(len(yz), x0), yz]


def test_drawing_forces_the_wrist_window_and_stays_within_tolerance(drawing):
    code, d, err = drawing
    assert code == 0 and err == "" and d["ok"] is True
    assert d["mode"] == "pose" and d["waypoints"] == N and d["duration"] == pytest.approx(20.0)
    assert d["start"] == {"q": [0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0, 0.0], "from": "--start"}
    qp = d["methods"]["qp"]
    # the ur3_drawing study's numbers for the same drawing: the whole path in the wrist window, every
    # step forced (with the pen axis held, θ5 = 0 at every waypoint)
    assert qp["within_tolerance"] is True and qp["waypoints_in_window"] == N and qp["share_in_window"] == 1.0
    assert [(w["name"], w["ranges"]) for w in qp["windows_entered"]] == [("wrist: sin(q5)", [[0, N - 1]])]
    assert qp["forced_steps"] == N - 1
    q = np.array(qp["per_waypoint"]["q"])
    assert np.abs(q[:, 4]).max() < 1e-6 and np.abs(q[:, 0]).max() < 1e-6      # θ5 = 0 and θ1 = 0 throughout


def test_the_followers_reached_poses_by_numpy_fk(drawing, pen):
    # every 10th waypoint: the pen tip by a numpy DH product against the drawing's geometry, and the
    # pen axis against the held one (−x)
    _, d, _ = drawing
    target = _drawing_tips()[::10]
    for key in ("qp", "naive"):
        m = d["methods"][key]
        F = np.array([fk_numpy(pen.chain, q) for q in np.array(m["per_waypoint"]["q"])[::10]])
        err = np.linalg.norm(F[:, :3, 3] - target, axis=1)
        np.testing.assert_allclose(err, np.array(m["per_waypoint"]["position_error"])[::10], atol=1e-9)
        assert err.max() <= m["max_position_error"] + 1e-12 and m["max_position_error"] <= 1e-3
        assert np.degrees(np.arccos(np.clip(-F[:, 0, 2], -1, 1))).max() <= 1.0


def test_the_naive_method_as_the_study_measured_it(drawing):
    # tests/studies/bundled/test_ur3_drawing.py and the study: with the correct Jacobian the naive
    # method survives this path — J exactly singular at the start (pinv there only), ~17 µm of
    # open-loop drift, a peak joint speed within 20 % of the follower's (0.0546 and 0.0569 rad/s)
    _, d, _ = drawing
    nv, qp = d["methods"]["naive"], d["methods"]["qp"]
    assert nv["within_tolerance"] is True and nv["first_pinv_steps"] == [0] and nv["pinv_steps"] == 1
    assert 1e-6 < nv["max_position_error"] < 1e-4 and nv["max_position_error"] > 100 * qp["max_position_error"]
    assert nv["peak_joint_speed"] == pytest.approx(qp["peak_joint_speed"], rel=0.2)
    assert qp["peak_joint_speed"] == pytest.approx(0.0569, abs=5e-4) and nv["peak_joint_speed"] == pytest.approx(
        0.0546, abs=5e-4)
    assert nv["waypoints_in_window"] == N and nv["diverged_at"] is None
    # joint speeds by finite differences of each joint path (Δt = 4 ms)
    for m in (nv, qp):
        q = np.array(m["per_waypoint"]["q"])
        v = np.abs(np.diff(q, axis=0)).max(axis=0) / 0.004
        np.testing.assert_allclose(m["max_joint_speed"], v, rtol=1e-6, atol=1e-12)
        assert m["peak_joint"] == 3 and m["max_speed_ratio"] == pytest.approx(v.max() / math.pi, rel=1e-6)


def test_drawing_text_and_plot(capsys, tmp_path, drawing):
    png = tmp_path / "follow.png"
    code, out, err = run(capsys, "follow", "ur3_homework_pen", "ur3_drawing", "--start", *PEN_Q, "--margin", MARGIN,
                         "--plot", png)
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert lines[0] == ("ur3_homework_pen following ur3_drawing.toml (5001 waypoints, 0.3571 m, 20 s), pose mode: "
                        "the QP follower stays within tolerance")
    assert "  start      q = (0, 0, 1.5708, -1.5708, 0, 0) rad (--start)" in lines
    assert any(x.startswith("  in a singular window   5001/5001 waypoints (100 %)") for x in lines)
    assert "  QP follower: wrist: sin(q5) at waypoints 0–5000; 5000 of 5000 steps forced into a window (no " \
           "configuration outside it met the next waypoint)" in lines
    assert "naive" not in out and lines[-1] == f"wrote {png}"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000


def _csv_rows(path: Path) -> np.ndarray:
    with open(path) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    head = rows[0]
    return np.array([[float(r[head.index(c)]) for c in ("x", "y", "z")] for r in rows[1:]])


def test_scara_line_position_mode_in_millimetres(capsys):
    scara = kin.load_robot("scara_rrp")
    target = _csv_rows(TOOLPATH_DIR / "scara_line.csv")                 # mm, read here
    code, out, err = run(capsys, "follow", "scara_rrp", "scara_line", "--naive", "--tol-position", "5", "--json",
                         "--waypoints")
    assert code == 0 and err == ""
    d = json.loads(out)
    assert d["mode"] == "position" and d["units"]["length"] == "mm" and d["tolerance"]["position"] == 5.0
    assert d["start"]["from"] == "IK of waypoint 0" and d["start"]["success"] is True
    for key in ("qp", "naive"):
        m = d["methods"][key]
        q = np.array(m["per_waypoint"]["q"]) * [1.0, 1.0, 1e-3]        # rad, rad, mm → SI
        tips = np.array([fk_numpy(scara.chain, x)[:3, 3] for x in q]) * 1e3
        err_mm = np.linalg.norm(tips - target, axis=1)
        assert m["max_position_error"] == pytest.approx(err_mm.max(), abs=1e-9)
        assert m["max_orientation_error"] is None and m["within_tolerance"] == (err_mm.max() <= 5.0)
    np.testing.assert_allclose(tips[0], target[0], atol=1e-6)           # IK of waypoint 0
    qp, nv = d["methods"]["qp"], d["methods"]["naive"]
    # 24 mm between waypoints: the follower's feedback keeps it within 5 mm, the open-loop method drifts
    assert qp["within_tolerance"] is True and 1.0 < qp["max_position_error"] < 5.0
    assert nv["within_tolerance"] is False and nv["max_position_error"] > 10.0
    # with the default 1 mm tolerance the follower is not within it: exit 1, and the text says so
    code, out, _ = run(capsys, "follow", "scara_rrp", "scara_line")
    assert code == 1 and "the QP follower leaves the tolerance (1 mm)" in out.splitlines()[0]
    assert "q = (2.20834 rad, -1.94026 rad, -152 mm) (IK of waypoint 0" in out


def test_scara_beyond_its_reach(capsys, tmp_path):
    # a radial line at y = 100 mm out to x = 674 mm: up to 681 mm from the base axis, 6 mm beyond the
    # reach; no joint path gets closer than that, and only the follower keeps the joints' speeds
    xs = np.r_[np.arange(450.0, 674.0, 2.0), 674.0, np.arange(672.0, 449.0, -2.0)]
    path = tmp_path / "reach.csv"
    path.write_text("x,y,z,feed\n" + "".join(f"{x:g},100,-150,50\n" for x in xs))
    code, out, err = run(capsys, "follow", "scara_rrp", path, "--margin", "0.05", "--naive", "--json")
    assert code == 1 and err == ""
    d = json.loads(out)
    beyond = math.hypot(674.0, 100.0) - SCARA_REACH_MM
    qp, nv = d["methods"]["qp"], d["methods"]["naive"]
    for m in (qp, nv):
        assert m["within_tolerance"] is False and m["max_position_error"] >= beyond - 1e-9
    assert qp["max_speed_ratio"] <= 1 + 1e-9 < nv["max_speed_ratio"]
    assert qp["waypoints_in_window"] > 0 and qp["windows_entered"][0]["name"] == "boundary: sin(q2)"


@pytest.mark.parametrize("argv, words", [
    (["scara_rrp", "scara_line", "--mode", "pose"], ["--mode pose", "positions only"]),
    (["ur3_homework_pen", "ur3_drawing", "--start", "0", "0"], ["--start", "6 joints"]),
    (["ur3_homework_pen", "ur3_drawing", "--start", "0", "0", "9", "0", "0", "0"], ["joint 3 = 9 rad", "limits"]),
    (["ur3_homework_pen", "ur3_drawing", "--start", "0", "0", "x", "0", "0", "0"], ["--start", "'x' is not a number"]),
    (["ur3_homework_pen", "ur3_drawing", "--margin", "-1"], ["--margin", "outside the allowed range"]),
    (["ur3_homework_pen", "ur3_drawing", "--margin", "200"], ["--margin 200 rad is too wide"]),
    (["ur3_homework_pen", "ur3_drawing", "--margin", "0.1", "--sigma-min", "0.1"], ["not allowed with"]),
    (["scara_rrp", "scara_line", "--mode", "joint"], ["--mode", "invalid choice"]),
    (["scara_rrp", "scara_line", "--tol-position", "0"], ["--tol-position", "outside the allowed range"]),
    (["scara_rrp", "scara_line", "--tol-orientation", "nan"], ["--tol-orientation", "outside the allowed range"]),
    (["scara_rrp", "no_such_path"], ["no such tool-path file", "bundled:", "scara_line"]),
    (["scara_rrp", "{tmp}/untimed.csv"], ["no times"]),
    (["scara_rrp", "{tmp}/one.csv"], ["one.csv: 1 waypoint; a path to follow needs at least 2"]),
    (["scara_rrp", "scara_line", "--plot", "/dev/null"], ["character device"]),
    (["no_robot", "scara_line"], ["unknown robot"]),
    (["ur3_homework_pen"], ["the following arguments are required: TOOLPATH"]),
])
def test_bad_input_is_one_line_exit_2(capsys, tmp_path, argv, words):
    (tmp_path / "untimed.csv").write_text("x,y,z\n400,0,-150\n410,0,-150\n")
    (tmp_path / "one.csv").write_text("x,y,z,feed\n400,0,-150,50\n")
    code, out, err = run(capsys, "follow", *[a.format(tmp=tmp_path) for a in argv])
    assert code == 2 and out == "", (out, err)
    assert err.startswith("rmt: error: ") and err.count("\n") == 1 and "Traceback" not in err
    for w in words:
        assert w in err, err
