"""``rmt export-trajectory``: the ROS YAML parsed back gives the file's samples, the URScript servoj
stream parsed gives planning.timing's own trajectory at 2 ms, movej goes through the stops at the
planned times, a limit breach is refused naming the joint and the time (exit 1), hostile input is one
line (exit 2), and the files `rmt time --out` and `rmt plan --time --trajectory-out` write export."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest
import yaml

import kin
from planning.timing import time_parameterize
from studies.cli import main
from studies.export.trajectory import trajectory_csv_text

P_DEG = np.array([[0, -90, 0, 0, 0, 0], [30, -60, 60, -90, -90, 0], [60, -80, 40, -60, -45, 30]], float)
V, A = np.pi / 2, 3.0                                    # SI, within ur5e's 180 deg/s


def _timed(tmp_path, blend, name="traj.csv"):
    """A ur5e trajectory timed by planning.timing (its object and its trajectory file)."""
    robot = kin.load_robot("ur5e")
    tm = time_parameterize(np.radians(P_DEG), V, A, blend=blend)
    f = tmp_path / name
    f.write_text(trajectory_csv_text(robot, tm.t, tm.q, tm.qd, tm.qdd))
    return tm, f


def _run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_ros_yaml_parses_back_to_the_samples(tmp_path, capsys):
    tm, f = _timed(tmp_path, 0.05)
    out = tmp_path / "t.yaml"
    rc, text, err = _run(capsys, "export-trajectory", "ur5e", str(f), "--format", "ros", "--out", str(out))
    assert rc == 0, err
    assert text.startswith(f"wrote {out}: ROS 2 trajectory_msgs/msg/JointTrajectory, 6 joints, {len(tm.t)} samples")
    raw = out.read_text()
    assert "joints in this order" in raw and "positions rad" in raw    # units and joint order stated
    msg = yaml.safe_load(raw)
    assert msg["joint_names"] == ["base", "shoulder", "elbow", "wrist1", "wrist2", "wrist3"]
    assert msg["header"]["frame_id"] == "base_link"
    pts = msg["points"]
    assert len(pts) == len(tm.t)
    for key, ref in (("positions", tm.q), ("velocities", tm.qd), ("accelerations", tm.qdd)):
        assert np.abs(np.array([p[key] for p in pts]) - ref).max() < 1e-12
    t = np.array([p["time_from_start"]["sec"] + 1e-9 * p["time_from_start"]["nanosec"] for p in pts])
    assert np.abs(t - tm.t).max() <= 0.5e-9 + 1e-15
    assert all(0 <= p["time_from_start"]["nanosec"] < 10 ** 9 for p in pts)
    # JSON: the same message
    rc, text, err = _run(capsys, "export-trajectory", "ur5e", str(f), "--format", "ros-json", "--joint-names",
                         *[f"j{k}" for k in range(6)], "--frame-id", "world")
    assert rc == 0, err
    m2 = json.loads(text)
    assert m2["points"] == pts and m2["joint_names"] == [f"j{k}" for k in range(6)]
    assert m2["header"]["frame_id"] == "world"


def _servoj(text):
    rows = re.findall(r"^  servoj\(\[([^\]]*)\], 0, 0, ([0-9.]+), ([0-9.]+), ([0-9.]+)\)$", text, re.M)
    return np.array([[float(x) for x in r[0].split(",")] for r in rows]), rows


@pytest.mark.parametrize("blend", [0.0, 0.05])
def test_servoj_stream_is_the_trajectory_at_2_ms(tmp_path, capsys, blend):
    tm, f = _timed(tmp_path, blend)
    rc, text, err = _run(capsys, "export-trajectory", "ur5e", str(f), "--format", "urscript")
    assert rc == 0, err
    Q, rows = _servoj(text)
    assert {r[1:] for r in rows} == {("0.002000000000", "0.1", "300")}
    times = np.minimum(np.arange(1, len(Q) + 1) * 0.002, tm.duration)
    assert times[-2] < tm.duration <= times[-1] + 1e-12 and len(Q) == int(np.ceil(tm.duration / 0.002 - 1e-9))
    assert np.abs(Q - tm.sample(times)[0]).max() < 1e-9        # planning.timing's own evaluation
    start = re.search(r"^  start = \[([^\]]*)\]$", text, re.M).group(1)
    assert np.allclose([float(x) for x in start.split(",")], np.radians(P_DEG[0]), atol=1e-12)
    assert text.rstrip().endswith("rmt_trajectory()") and "halt" in text
    rc, text, err = _run(capsys, "export-trajectory", "ur5e", str(f), "--format", "urscript", "--rate", "125",
                         "--lookahead", "0.05", "--gain", "500")
    Q125, rows = _servoj(text)
    assert rc == 0 and rows[0][1:] == ("0.008000000000", "0.05", "500")
    assert np.abs(Q125[:-1] - Q[3:-1:4][:len(Q125) - 1]).max() < 1e-11


def test_movej_goes_through_the_stops_at_the_planned_times(tmp_path, capsys):
    tm, f = _timed(tmp_path, 0.0)
    rc, text, err = _run(capsys, "export-trajectory", "ur5e", str(f), "--format", "urscript", "--urscript-mode",
                         "movej")
    assert rc == 0, err
    moves = re.findall(r"^  movej\(\[([^\]]*)\], a=1.4, v=1.05, t=([0-9.]+), r=0\)$", text, re.M)
    assert len(moves) == len(P_DEG) - 1
    Q = np.array([[float(x) for x in m[0].split(",")] for m in moves])
    assert np.abs(Q - np.radians(P_DEG[1:])).max() < 1e-12
    stop_times = tm.t[tm.sd == 0]                          # planning.timing's stops: at every waypoint
    assert len(stop_times) == len(P_DEG)
    assert np.allclose([float(m[1]) for m in moves], np.diff(stop_times), atol=1e-12)
    # a blended trajectory curves between its stops: movej would not follow it
    _, fb = _timed(tmp_path, 0.05, "blended.csv")
    rc, out, err = _run(capsys, "export-trajectory", "ur5e", str(fb), "--format", "urscript", "--urscript-mode",
                        "movej")
    assert rc == 2 and out == "" and err.count("\n") == 1 and "--blend 0" in err, err


def test_a_dwell_is_a_sleep(tmp_path, capsys):
    robot = kin.load_robot("ur5e")
    q0, q1 = np.radians(P_DEG[0]), np.radians(P_DEG[1])
    t = np.array([0.0, 1.0, 1.5, 2.5])                   # a stop at q1, held 0.5 s, and back
    q = np.array([q0, q1, q1, q0])
    f = tmp_path / "dwell.csv"
    qd = np.zeros((4, 6))
    qdd = np.zeros((4, 6))
    f.write_text(trajectory_csv_text(robot, t, q, qd, qdd))
    rc, text, err = _run(capsys, "export-trajectory", "ur5e", str(f), "--format", "urscript", "--urscript-mode",
                         "movej")
    assert rc == 0, err
    body = [ln.strip() for ln in text.splitlines() if ln.startswith("  movej") or ln.startswith("  sleep")]
    assert body[1] == "sleep(0.500000000000)" and body[0].startswith("movej(") and "t=1.000000000000" in body[0]


def test_csv_is_the_trajectory_in_si(tmp_path, capsys):
    tm, f = _timed(tmp_path, 0.05)
    rc, text, err = _run(capsys, "export-trajectory", "ur5e", str(f), "--format", "csv")
    assert rc == 0, err
    lines = text.splitlines()
    assert "# angle_unit: rad" in lines and "# robot: ur5e" in lines
    X = np.array([ln.split(",") for ln in lines if ln[0].isdigit()], float)
    assert np.array_equal(X[:, 0], tm.t) and np.abs(X[:, 1:7] - tm.q).max() < 1e-15
    rc, text, err = _run(capsys, "export-trajectory", "ur5e", str(f), "--format", "csv", "--rate", "100")
    X = np.array([ln.split(",") for ln in text.splitlines() if ln[0].isdigit()], float)
    assert rc == 0 and np.allclose(np.diff(X[:-1, 0]), 0.01)
    assert np.abs(X[:, 1:7] - tm.sample(X[:, 0])[0]).max() < 1e-12


@pytest.mark.parametrize("what", ["velocity", "position", "jump"])
def test_a_limit_breach_is_refused_naming_the_joint_and_time(tmp_path, capsys, what):
    robot = kin.load_robot("ur5e")
    if what == "velocity":                                # timed at 200 deg/s against ur5e's 180
        tm = time_parameterize(np.radians(P_DEG), np.radians(200.0), 30.0, blend=0.0)
        t, q, qd, qdd = tm.t, tm.q, tm.qd, tm.qdd
    else:                                                 # elbow: 400 deg (limits ±360) in 10 s, or 190 deg in 1 s
        t = np.array([0.0, 10.0 if what == "position" else 1.0])
        q = np.radians([[0, -90, 0, 0, 0, 0], [0, -90, 400 if what == "position" else 190, 0, 0, 0]])
        qd = qdd = np.zeros((2, 6))
    f = tmp_path / "fast.csv"
    f.write_text(trajectory_csv_text(robot, t, q, qd, qdd))
    out = tmp_path / "never.yaml"
    rc, text, err = _run(capsys, "export-trajectory", "ur5e", str(f), "--format", "ros", "--out", str(out))
    assert rc == 1 and text == "" and err.count("\n") == 1 and not out.exists(), err
    assert err.startswith(f"{f}: joint ") and "(ur5e)" in err
    if what == "velocity":
        fast = np.abs(np.degrees(tm.qd)) > 180 * (1 + 1e-6)
        k = int(np.flatnonzero(fast.any(1))[0])           # the first sample beyond 180 deg/s
        j = int(np.flatnonzero(fast[k])[0])
        m = re.search(r"joint (\w+) (mean )?velocity [-0-9.]+ deg/s (at|between) t = ([0-9.e+-]+) s", err)
        assert m and m.group(1) == robot.chain.joint_names()[j], err
        assert float(m.group(4)) == pytest.approx(tm.t[k if not m.group(2) else k - 1], rel=1e-5)
        assert "beyond its max_velocity 180 deg/s" in err
    elif what == "position":
        assert "joint elbow position 400 deg at t = 10 s is beyond its limits [-360, 360] deg" in err
    else:                                                 # q̇ says 0 but q jumps: the mean speed gives it away
        assert "joint elbow mean velocity 190 deg/s between t = 0 s and the next sample" in err


HEADER = "t," + ",".join(f"{k}{j}" for k in ("q", "qd", "qdd") for j in range(1, 7))
ROW0 = "0," + ",".join(["0"] * 18)


@pytest.mark.parametrize("text, argv, what", [
    (f"{HEADER}\n{ROW0}\n0.5,nan" + ",0" * 17 + "\n", [], "column q1 is nan"),
    (f"{HEADER}\n{ROW0}\n", [], "a trajectory needs at least two"),
    ("t," + ",".join(f"{k}{j}" for k in ("q", "qd", "qdd") for j in range(1, 8)) + "\n", [], "has 6 joints"),
    (f"{HEADER}\n{ROW0}\n0," + ",".join(["0"] * 18) + "\n", [], "times must increase strictly"),
    (None, [], "a trajectory file may have at most"),
    (f"{HEADER}\n{ROW0}\n", ["--rate", "0"], "--rate"),
    (f"{HEADER}\n{ROW0}\n", ["--rate", "600", "--format", "urscript"], "500 Hz at most"),
    (f"{HEADER}\n{ROW0}\n", ["--lookahead", "0.5", "--format", "urscript"], "allowed range [0.03, 0.2]"),
    (f"{HEADER}\n{ROW0}\n", ["--gain", "300"], "--gain applies to --format urscript only"),
    (f"{HEADER}\n{ROW0}\n", ["--json"], "--json needs --out"),
    (f"{HEADER}\n{ROW0}\n", ["--joint-names", "a", "b"], "got 2 names; ur5e has 6"),
    (f"{HEADER}\n{ROW0}\n", ["--joint-names", *"aabcde"], "a name is given twice"),
    (f"{HEADER}\n{ROW0}\n", ["--frame-id", "a\nb"], "--frame-id"),
    (f"{HEADER}\n{ROW0}\n", ["--format", "urscript", "--urscript-mode", "movej", "--rate", "100"], "servoj only"),
])
def test_hostile_input_is_one_line_exit_2(tmp_path, capsys, text, argv, what):
    f = tmp_path / "bad.csv"
    if text is None:
        with open(f, "wb") as fh:                         # sparse 101 MB: refused before it is read
            fh.truncate(101_000_000)
    else:
        f.write_text(text)
    fmt = [] if "--format" in argv else ["--format", "ros"]
    rc, out, err = _run(capsys, "export-trajectory", "ur5e", str(f), *fmt, *argv)
    assert rc == 2 and out == "" and err.count("\n") == 1 and what in err, err


def test_urscript_needs_six_revolute_joints(tmp_path, capsys):
    robot = kin.load_robot("franka_panda")
    f = tmp_path / "panda.csv"
    z = np.zeros((2, 7))
    f.write_text(trajectory_csv_text(robot, np.array([0.0, 1.0]), z, z, z))
    rc, out, err = _run(capsys, "export-trajectory", "franka_panda", str(f), "--format", "urscript")
    assert rc == 2 and "six revolute joints; franka_panda has 7" in err


def test_time_and_plan_write_files_that_export(tmp_path, capsys):
    path = tmp_path / "p.csv"
    rc, out, err = _run(capsys, "plan", "ur5e", "--start", "home", "--goal", "30", "-60", "60", "-90", "-90", "0",
                        "--no-singularity-check", "--out", str(path), "--trajectory-out", str(tmp_path / "plan.csv"),
                        "--a-max", "150")
    assert rc == 0, err
    assert "timed rest to rest, stopping at every waypoint:" in out
    rc, out, err = _run(capsys, "time", "ur5e", str(path), "--a-max", "150", "--blend", "0", "--out",
                        str(tmp_path / "time.csv"))
    assert rc == 0, err
    # plan --time is rmt time --blend 0 of the planned path
    assert (tmp_path / "plan.csv").read_bytes() == (tmp_path / "time.csv").read_bytes()
    for fmt in ("ros", "urscript", "csv"):
        rc, out, err = _run(capsys, "export-trajectory", "ur5e", str(tmp_path / "time.csv"), "--format", fmt,
                            "--out", str(tmp_path / f"x.{fmt}"), "--json")
        assert rc == 0, err
        R = json.loads(out)
        assert R["format"] == fmt and R["robot"] == "ur5e" and (tmp_path / f"x.{fmt}").exists()
    rc, out, err = _run(capsys, "plan", "ur5e", "--start", "home", "--goal", "home", "--a-max", "1")
    assert rc == 2 and "--a-max applies with --time or --trajectory-out only" in err


def test_the_pages_excerpts_are_what_the_commands_write(tmp_path, capsys, monkeypatch):
    """docs/export.md shows the trajectory file and a limit breach as text (not run by the doc examples):
    made by its own commands."""
    from pathlib import Path
    page = (Path(__file__).resolve().parents[3] / "docs" / "export.md").read_text()
    monkeypatch.chdir(tmp_path)
    assert main(["plan", "ur5e", "--start", "0", "-90", "90", "-90", "-90", "0", "--goal", "45", "-60", "80", "-110",
                 "-90", "45", "--a-max", "150", "--out", "path.csv", "--trajectory-out", "traj.csv"]) == 0
    assert main(["time", "ur5e", "path.csv", "--v-max", "250", "--a-max", "1000", "--out", "fast.csv"]) == 0
    capsys.readouterr()
    assert main(["export-trajectory", "ur5e", "fast.csv", "--format", "ros"]) == 1
    err = capsys.readouterr().err.strip()
    assert f"```text\n{err}\n```" in page
    block = re.search(r"```text\n(# rmtkit trajectory 1\n.*?)```", page, re.S).group(1).splitlines()
    written = Path("traj.csv").read_text().splitlines()
    assert block[:-1] == written[:len(block) - 1]
    assert block[-1].endswith(",...") and written[len(block) - 1].startswith(block[-1][:-3])
