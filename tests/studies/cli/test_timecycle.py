"""``rmt time ROBOT CYCLE.toml``: the cycle's total is the sum of what ``rmt time`` gives for each move
alone plus the dwells; the written trajectory is continuous, at rest during the dwells, and within
the limits; hostile cycle files are one line naming the file and the field (exit 2)."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import kin
from studies.cli import main

A_MAX = "200"      # deg/s², all joints (UR publishes no acceleration limits)
HOME = [0, -90, 90, -90, -90, 0]
PICK = [45, -60, 80, -110, -90, 45]


def _write_csv(path, rows):
    path.write_text("q1,q2,q3,q4,q5,q6\n" + "\n".join(",".join(repr(float(x)) for x in r) for r in rows) + "\n")
    return path


def _cycle(tmp_path, text):
    p = tmp_path / "cycle.toml"
    p.write_text(text)
    return p


def _time_alone(capsys, path) -> float:
    assert main(["time", "ur5e", str(path), "--a-max", A_MAX, "--json"]) == 0
    return json.loads(capsys.readouterr().out)["duration_s"]


def test_the_cycle_is_the_sum_of_its_moves_and_dwells(tmp_path, capsys):
    a = _write_csv(tmp_path / "a.csv", [HOME, [30, -80, 100, -100, -90, 20], PICK])
    cyc = _cycle(tmp_path, f"""
[[move]]
name = "to pick"
path = "a.csv"
dwell = 0.5

[[move]]
waypoints = [{PICK}, "test_configuration"]
dwell = 1.25

[[move]]
waypoints = ["test_configuration", {HOME}]
""")
    out = tmp_path / "traj.csv"
    assert main(["time", "ur5e", str(cyc), "--a-max", A_MAX, "--out", str(out), "--json"]) == 0
    R = json.loads(capsys.readouterr().out)
    # each move alone, through rmt time on its own CSV (the state's numbers typed out)
    tc = np.degrees(kin.load_chain("ur5e").states["test_configuration"])
    alone = [_time_alone(capsys, a), _time_alone(capsys, _write_csv(tmp_path / "b.csv", [PICK, tc])),
             _time_alone(capsys, _write_csv(tmp_path / "c.csv", [tc, HOME]))]
    assert [m["duration_s"] for m in R["moves"]] == pytest.approx(alone, rel=1e-9)
    assert R["total_s"] == pytest.approx(sum(alone) + 0.5 + 1.25, rel=1e-9)
    assert [m["name"] for m in R["moves"]] == ["to pick", "move 2", "move 3"]
    assert [m["dwell_s"] for m in R["moves"]] == [0.5, 1.25, 0.0]
    # the written trajectory: from HOME to HOME, continuous, within the limits, at rest while dwelling
    rows = [r for r in csv.reader(out.open()) if not r[0].startswith("#")]        # the trajectory file's notes
    X = np.array(rows[1:], float)
    t, q, qd, qdd = X[:, 0], X[:, 1:7], X[:, 7:13], X[:, 13:19]
    assert rows[0][:2] == ["t", "q1"] and t[0] == 0 and t[-1] == pytest.approx(R["total_s"], rel=1e-12)
    assert np.all(np.diff(t) > 0)
    assert np.allclose(q[0], HOME, atol=1e-9) and np.allclose(q[-1], HOME, atol=1e-9)
    v = np.array(R["v_max"])
    dq = np.abs(np.diff(q, axis=0))
    assert np.all(dq <= v * np.diff(t)[:, None] * (1 + 1e-6) + 1e-9)          # no jump anywhere
    assert np.all(np.abs(qd) <= v * (1 + 1e-6)) and np.all(np.abs(qdd) <= float(A_MAX) * (1 + 1e-6))
    for m in R["moves"][:2]:                                                    # the dwells: held at rest
        i = int(np.argmin(np.abs(t - (m["start_s"] + m["duration_s"]))))
        assert t[i + 1] - t[i] == pytest.approx(m["dwell_s"], rel=1e-9)
        assert np.allclose(q[i], q[i + 1], atol=1e-9) and not qd[i].any() and not qd[i + 1].any()
    # the text report
    assert main(["time", "ur5e", str(cyc), "--a-max", A_MAX]) == 0
    text = capsys.readouterr().out
    assert text.startswith("cycle ") and "3 move(s), total" in text and "to pick" in text


MOVE = "[[move]]\nwaypoints = [[0,-90,90,-90,-90,0], [10,-90,90,-90,-90,0]]"


@pytest.mark.parametrize("body, words", [
    (MOVE + "\ndwell = -1", "move 1.dwell: -1 s is outside"),
    (MOVE + "\ndwell = nan", "move 1.dwell: must be a finite"),
    (MOVE + "\ndwell = 86401", "one day"),
    (MOVE + "\n[[move]]\n"
     "waypoints = [[11,-90,90,-90,-90,0], [0,-90,90,-90,-90,0]]",
     "move 2: starts at joint 1 = 11 deg, not where move 1 ends (10 deg)"),
    ("speed = 2\n" + MOVE, "speed: unknown field; allowed: move"),
    (MOVE + "\nwait = 1", "move 1.wait: unknown field"),
    ("[[move]]\npath = 'a.csv'\nwaypoints = [[0,-90,90,-90,-90,0], [1,-90,90,-90,-90,0]]", "give either path"),
    ("[[move]]\ndwell = 1", "give either path"),
    ("[[move]]\nwaypoints = ['home', 'hom']", "move 1.waypoints, configuration 2: ur5e has no state named 'hom'"),
    ("[[move]]\nwaypoints = [[0,-90,90,-90,-90], [1,-90,90,-90,-90,0]]", "configuration 1: must be a list of 6"),
    ("[[move]]\nwaypoints = ['up', 'up']", "move 1: does not move"),
    ("[[move]]\nwaypoints = ['up']", "move 1.waypoints: must be a list of 2"),
    ("[[move]]\npath = 'none.csv'", "none.csv: no such joint-path file"),
    ("", "move: needs 1 to 1000 [[move]] tables"),
    ("[[move", "not valid TOML"),
])
def test_hostile_cycle_files_are_one_line(tmp_path, capsys, body, words):
    cyc = _cycle(tmp_path, body)
    assert main(["time", "ur5e", str(cyc), "--a-max", A_MAX]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and words in err, err


def test_a_cycle_without_accelerations_names_the_option_and_plot_is_refused(tmp_path, capsys):
    cyc = _cycle(tmp_path, "[[move]]\nwaypoints = ['home', 'up']\n")
    assert main(["time", "ur5e", str(cyc)]) == 2
    assert "give --a-max A (deg/s²" in capsys.readouterr().err
    assert main(["time", "ur5e", str(cyc), "--a-max", A_MAX, "--plot", str(tmp_path / "p.png")]) == 2
    assert "--plot applies to one path" in capsys.readouterr().err
    assert main(["time", "ur5e", str(tmp_path / "missing.toml"), "--a-max", A_MAX]) == 2
    assert "no such cycle file" in capsys.readouterr().err


@pytest.mark.parametrize("name, label", [(None, "move 1"), ("reach", "move 1 (reach)")])
def test_limit_breach_names_the_move_once_on_stdout_and_stderr(tmp_path, capsys, name, label):
    """A spline through a configuration at joint 4's upper limit overshoots it (franka_panda, rad):
    the move is named once ("move 1", or "move 1 (its name)"), on stdout and as the error line."""
    robot = kin.load_robot("franka_panda")
    mid = robot.chain.lower + 0.5 * (robot.chain.upper - robot.chain.lower)
    rows = np.tile(mid, (4, 1))
    rows[:, 3] = [-1.5, -0.08, -0.08, -1.5]
    rows[:, 0] = [0.0, 0.01, 0.02, 0.03]
    wp = ", ".join("[" + ", ".join(repr(float(x)) for x in r) + "]" for r in rows)
    text = "[[move]]\n" + (f"name = '{name}'\n" if name else "") + f"waypoints = [{wp}]\n"
    rc = main(["time", "franka_panda", str(_cycle(tmp_path, text)), "--a-max", "10", "--shape", "spline"])
    out, err = capsys.readouterr()
    line = [x for x in out.splitlines() if "leaves joint" in x]
    assert rc == 1 and len(line) == 1 and line[0].startswith(f"{label}: the spline path leaves joint joint4's limits")
    assert err.strip() == line[0]
    assert "move 1 (move 1)" not in out + err
