"""``rmt time`` refuses joint values outside the robot's limits and limits outside the one documented
range it shares with a task's ``[cycle]`` table (planning.timing.limits.LIMIT_RANGE) — issue 30 — and
its default grid times a zig-zag of 199 short moves within 1 % of the closed form."""
from __future__ import annotations

import json
import math

import pytest

from design.task import TaskError, loads_task
from planning.timing.limits import LIMIT_RANGE
from studies.cli import main
from tests.design.test_cycle import TASK

OK = ["--v-max", "10", "--a-max", "1"]


def _csv(tmp_path, rows, name="p.csv"):
    p = tmp_path / name
    p.write_text("".join(f"{a!r},{b!r}\n" for a, b in rows))
    return p


def _one_error_line(capsys, *words):
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err and "Warning" not in err, err
    for w in words:
        assert w in err, err
    return err


@pytest.mark.parametrize("row", [(1e300, 0.0), (0.0, -3.2), (math.pi + 1e-6, 0.0)])
def test_a_joint_value_outside_the_limits_is_refused(tmp_path, capsys, row):
    p = _csv(tmp_path, [(0.0, 0.0), (0.1, 0.1), row])
    assert main(["time", "planar_2r", str(p), *OK]) == 2          # was exit 0, "duration 0.0" for 1e300
    j = "J1" if row[0] != 0.0 else "J2"
    _one_error_line(capsys, str(p), "data row 3", f"joint {j}", "[-3.141592654, 3.141592654] rad")


def test_a_cycle_waypoint_outside_the_limits_is_refused(tmp_path, capsys):
    cyc = tmp_path / "c.toml"
    cyc.write_text("[[move]]\nwaypoints = [[0, 0], [0.5, 4]]\n")
    assert main(["time", "planar_2r", str(cyc), *OK]) == 2
    _one_error_line(capsys, str(cyc), "move 1.waypoints, configuration 2", "joint J2", "outside its limits")


def test_a_cycle_path_outside_the_limits_is_refused(tmp_path, capsys):
    _csv(tmp_path, [(0.0, 0.0), (4.0, 0.0)], "m.csv")
    cyc = tmp_path / "c.toml"
    cyc.write_text('[[move]]\npath = "m.csv"\n')
    assert main(["time", "planar_2r", str(cyc), *OK]) == 2
    _one_error_line(capsys, "m.csv", "move 1.path", "data row 2", "joint J1")


@pytest.mark.parametrize("opts, option", [
    (["--v-max", "1e-300", "--a-max", "1e-300"], "--v-max"),     # v² underflowed: the speed limit vanished
    (["--v-max", "1e308", "--a-max", "1"], "--v-max"),
    (["--v-max", "1", "--a-max", "1e-7"], "--a-max"),
    (["--v-max", "1", "2", "--a-max", "2e7", "1"], "--a-max"),
    (["--v-max", "1", "--a-max", "1", "--j-max", "1e308"], "--j-max"),
])
def test_a_limit_outside_the_shared_range_is_refused(tmp_path, capsys, opts, option):
    p = _csv(tmp_path, [(0.0, 0.0), (0.5, 0.0)])
    assert main(["time", "planar_2r", str(p), *opts]) == 2
    lo, hi = LIMIT_RANGE
    _one_error_line(capsys, option, f"[{lo:g}, {hi:g}]")


def test_the_range_ends_are_accepted(tmp_path, capsys):
    p = _csv(tmp_path, [(0.0, 0.0), (0.5, 0.0)])
    lo, hi = LIMIT_RANGE
    assert main(["time", "planar_2r", str(p), "--v-max", repr(hi), "--a-max", repr(lo), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["duration_s"] == pytest.approx(2 * math.sqrt(0.5 / lo), rel=1e-6)   # never reaches v


@pytest.mark.parametrize("old, new", [("v_max = [300, 500, 1000]", "v_max = [300, 1e-300, 1000]"),
                                      ("a_max = [1500, 3000, 10000]", "a_max = [1500, 1e308, 10000]"),
                                      ("tau_max = [32, 15, 100]", "tau_max = 1e-9")])
def test_the_cycle_table_uses_the_same_range(old, new):
    with pytest.raises(TaskError) as e:
        loads_task(TASK.replace(old, new), "c.toml")
    lo, hi = LIMIT_RANGE
    assert f"[{lo:g}, {hi:g}]" in str(e.value) and "\n" not in str(e.value)


def test_the_default_grid_times_a_zigzag_of_short_moves(tmp_path, capsys):
    square = [(0.0, 0.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5)]
    p = _csv(tmp_path, [square[i % 4] for i in range(200)])
    exact = 199 * 2 * math.sqrt(0.5 / 1.0)                   # 199 rest-to-rest moves, never at 10 rad/s
    assert main(["time", "planar_2r", str(p), *OK, "--blend", "0", "--json"]) == 0
    stop = json.loads(capsys.readouterr().out)["duration_s"]
    assert exact <= stop <= 1.01 * exact                      # was 317.4 s
    assert main(["time", "planar_2r", str(p), *OK, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["duration_s"] <= exact    # was 399.9 s
