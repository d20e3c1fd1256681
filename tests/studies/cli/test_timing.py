"""``rmt time``: end to end on the Panda (the CSV's torques are the inverse dynamics of its own q, q̇,
q̈; the JSON's peaks are the CSV's; the plot is written) and hostile inputs (one line, exit 2)."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import kin
from studies.cli import main

A_MAX = ["15", "7.5", "10", "12.5", "15", "20", "20"]
TAU = ["52", "52", "52", "52", "7", "7", "7"]


def _path_file(tmp_path, rows=None, name="path.csv"):
    lim = kin.load_chain("franka_panda").limits
    rng = np.random.default_rng(1)
    P = rows if rows is not None else lim.mean(1) + 0.4 * (lim[:, 1] - lim[:, 0]) / 2 * rng.uniform(-1, 1, (5, 7))
    f = tmp_path / name
    f.write_text("q1,q2,q3,q4,q5,q6,q7\n" + "\n".join(",".join(repr(float(x)) for x in r) for r in P) + "\n")
    return f


def test_panda_end_to_end(tmp_path, capsys):
    path = _path_file(tmp_path)
    out_csv, png = tmp_path / "traj.csv", tmp_path / "traj.png"
    rc = main(["time", "franka_panda", str(path), "--a-max", *A_MAX, "--tau-max", *TAU, "--csv", str(out_csv),
               "--plot", str(png), "--json"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    R = json.loads(out)
    rows = [r for r in csv.reader(out_csv.open()) if not r[0].startswith("#")]    # the trajectory file's notes
    assert rows[0][:2] == ["t", "q1"] and rows[0][-1] == "tau7"
    X = np.array(rows[1:], float)
    t, q, qd, qdd, tau = X[:, 0], X[:, 1:8], X[:, 8:15], X[:, 15:22], X[:, 22:29]
    robot = kin.load_robot("franka_panda")
    assert np.allclose(tau, robot.inverse_dynamics(q, qd, qdd), rtol=1e-9, atol=1e-9)
    assert R["duration_s"] == pytest.approx(t[-1]) and R["samples"] == len(t)
    tmax = np.array(TAU, float)
    assert [j["tau_max"] for j in R["joints"]] == tmax.tolist()
    assert np.allclose([j["peak_torque"] for j in R["joints"]], np.abs(tau).max(0))
    assert max(j["peak_torque_ratio"] for j in R["joints"]) <= 1 + 1e-6
    assert R["max_torque_ratio"] <= 1 + 1e-6
    assert np.allclose([j["peak_velocity_ratio"] for j in R["joints"]],
                       np.abs(qd).max(0) / np.array([2.175] * 4 + [2.61] * 3))
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the text report names every joint and the dense re-check
    assert main(["time", "franka_panda", str(path), "--a-max", "10", "--tau-max", *TAU]) == 0
    text = capsys.readouterr().out
    assert text.startswith("duration ") and "joint7" in text and "max |τ|/τ_max" in text


@pytest.mark.parametrize("extra, what", [
    (["--a-max", "1", "2"], "--a-max: got 2 values"),
    (["--a-max", "-1"], "outside the allowed range [1e-06, 1e+07]"),
    (["--a-max", "x"], "not a number"),
    (["--a-max", "10", "--v-max", "nan"], "not a finite number"),
    (["--a-max", "10", "--ds", "0"], "--ds"),
    (["--a-max", "10", "--blend", "-1"], "--blend"),
    (["--a-max", "10", "--tau-max", "5"], "cannot hold the path at rest"),
    (["--a-max", "10", "--tau-max", "0"], "outside the allowed range [1e-06, 1e+07]"),
])
def test_hostile_inputs_are_one_line(tmp_path, capsys, extra, what):
    rc = main(["time", "franka_panda", str(_path_file(tmp_path)), *extra])
    out, err = capsys.readouterr()
    assert rc == 2 and out == "" and err.count("\n") == 1 and what in err, err


def test_bad_files_and_robots_are_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("1,2,3\n")
    cases = [["time", "franka_panda", str(tmp_path / "missing.csv"), "--a-max", "1"],
             ["time", "franka_panda", str(bad), "--a-max", "1"],
             ["time", "fanuc_m16ib20", str(_path_file(tmp_path, np.zeros((2, 6)) + [[0] * 6, [1] * 6], "fanuc.csv")),
              "--a-max", "100", "--v-max", "100", "--tau-max", "100"],
             ["time", "franka_panda", str(_path_file(tmp_path)), "--a-max", "1", "--csv", str(tmp_path)]]
    for argv, what in zip(cases, ["no such joint-path file", "3 values", "no body has inertial data", "bad"]):
        assert main(argv) == 2, argv
        out, err = capsys.readouterr()
        assert out == "" and err.count("\n") == 1, err
        assert what in err or what == "bad", err


def test_spline_shape_path_out_and_joint_limits(tmp_path, capsys):
    """--shape spline is faster through many close waypoints; --path-out holds every waypoint (a knot of
    the spline, hence a polyline vertex) and `rmt check-path` reads it; a spline that overshoots a joint
    limit between waypoints exits 1 naming the joint (q4 = −1.5, −0.08, −0.08, −1.5 at equal steps: the
    not-a-knot cubic through them is the parabola peaking at +0.0975 rad, above the Panda's −0.0698)."""
    lim = kin.load_chain("franka_panda").limits
    u = np.linspace(0, 1, 25)[:, None]
    rows = lim.mean(1) + 0.3 * (lim[:, 1] - lim[:, 0]) / 2 * np.sin(2 * np.pi * (u + np.arange(7) / 7))
    path = _path_file(tmp_path, rows)
    runs = {}
    for shape in ("blend", "spline"):
        out = tmp_path / f"{shape}.csv"
        rc = main(["time", "franka_panda", str(path), "--a-max", *A_MAX, "--shape", shape, "--path-out", str(out),
                   "--json"])
        runs[shape] = json.loads(capsys.readouterr().out)
        assert rc == 0 and runs[shape]["shape"] == shape and runs[shape]["joints_leaving_limits"] == []
    assert runs["spline"]["duration_s"] < runs["blend"]["duration_s"]
    dense = np.array(list(csv.reader((tmp_path / "spline.csv").open()))[1:], float)
    assert len(dense) > 10 * len(rows)
    for w in rows:
        assert np.min(np.linalg.norm(dense - w, axis=1)) < 1e-9
    assert main(["check-path", "franka_panda", str(tmp_path / "spline.csv")]) == 0
    capsys.readouterr()
    bad = np.tile(lim.mean(1), (4, 1))
    bad[:, 3] = [-1.5, -0.08, -0.08, -1.5]
    bad[:, 0] = [0.0, 0.01, 0.02, 0.03]                # distinct rows (joint 1 barely moves)
    rc = main(["time", "franka_panda", str(_path_file(tmp_path, bad, "bad.csv")), "--a-max", *A_MAX,
               "--shape", "spline"])
    err = capsys.readouterr().err
    assert rc == 1 and "leaves joint joint4's limits" in err and "0.0975" in err


def test_the_cli_offers_exactly_the_shapes_of_the_timing():
    import planning.timing.parameterize as timing
    import studies.cli.timing as cli
    assert cli.SHAPES == timing.SHAPES



def test_published_accelerations_are_the_default_and_missing_ones_name_the_option(tmp_path, capsys):
    """The Panda's file carries Franka's ddq_max: without --a-max the timing is the one with those values
    typed out; the UR5e's maker publishes none: one line naming --a-max and its unit."""
    path = _path_file(tmp_path)
    assert main(["time", "franka_panda", str(path), "--json"]) == 0
    default = json.loads(capsys.readouterr().out)
    assert main(["time", "franka_panda", str(path), "--a-max", *A_MAX, "--json"]) == 0
    typed = json.loads(capsys.readouterr().out)
    assert default["duration_s"] == typed["duration_s"] and default["a_max"] == [float(a) for a in A_MAX]
    assert default["limits_from"] == {"v_max": "robot file", "a_max": "robot file"}
    assert typed["limits_from"]["a_max"] == "--a-max"
    ur = tmp_path / "ur.csv"
    ur.write_text("0,0,0,0,0,0\n10,20,30,40,50,60\n")
    assert main(["time", "ur5e", str(ur)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "ur5e has no published accelerations" in err and "give --a-max A (deg/s²" in err
    assert main(["time", "ur3_homework", str(ur), "--a-max", "1"]) == 2
    assert "give --v-max V (rad/s" in capsys.readouterr().err
