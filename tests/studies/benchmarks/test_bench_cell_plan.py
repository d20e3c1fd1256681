"""The cell-planning benchmark (studies/benchmarks/bench_cell_plan.py): its scenes are cell files both
robots resolve, its queries are what it says (valid, not separated, the goal's tool in the scene's
region pointing its way), its re-check catches a path through an obstacle, and ``--json --quick``
reports every figure.  No timing asserted."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
import studies.benchmarks.bench_cell_plan as bench
from planning.cell import load_cell
from planning.certify import free_cells
from planning.ompl.validity import JointSpaceChecker
from planning.windows import build_windows
from studies.benchmarks.bench_collision import scene_path


@pytest.mark.parametrize("scene", list(bench.SCENES))
@pytest.mark.parametrize("robot", bench.ROBOTS)
def test_scenes_are_cells_both_robots_resolve(scene, robot):
    cell = load_cell(scene_path(f"{scene}.toml"))
    assert cell.name == scene and cell.obstacles[0].name == "table"
    resolved = cell.resolve(kin.load_robot(robot))
    assert resolved.obstacles[0].ignore == {0, 1}
    assert all(ob.shapes for ob in resolved.obstacles)


@pytest.fixture(scope="module")
def ur5e_box():
    robot = kin.load_robot("ur5e")
    windows = build_windows(robot, margin=bench.MARGIN)
    world = bench.world_for(robot, "box.toml")
    queries, tally = bench.draw_queries(robot, world, windows, 6, seed=3, region=bench.SCENES["box"], poses=600)
    return robot, windows, world, queries, tally


def test_queries_are_valid_and_in_the_region(ur5e_box):
    robot, windows, world, queries, tally = ur5e_box
    assert len(queries) == 6 and tally["pairs"] >= 6
    checker = JointSpaceChecker(robot, windows, world=world)
    cells = free_cells(robot.chain.lower, robot.chain.upper, windows)
    region = bench.SCENES["box"]
    for q in queries:
        a, b = q["start"], q["goal"]
        assert checker.reason(list(a)) is None and checker.reason(list(b)) is None
        assert cells.separation(a, b) is None
        assert (bench.aspect(windows, a[None]) == bench.aspect(windows, b[None])).all()
        assert (bench.slab_cells(windows, a[None]) == bench.slab_cells(windows, b[None])).all()
        T = world.base @ robot.fk(b)
        assert np.all(T[:3, 3] >= np.array(region.lo) - 1e-6) and np.all(T[:3, 3] <= np.array(region.hi) + 1e-6)
        np.testing.assert_allclose(T[:3, 2], region.approach, atol=1e-6)
        facts = bench.straight_line(robot, world, windows, a, b)
        assert (q["straight_collides"], q["straight_crosses_window"]) == facts
    # colliding straight lines come first
    flags = [q["straight_collides"] for q in queries]
    assert flags == sorted(flags, reverse=True)


def test_slab_cells_number_the_gaps_between_intervals():
    robot = kin.load_robot("ur5e")
    windows = build_windows(robot, margin=bench.MARGIN)
    Q = np.zeros((3, 6))
    Q[:, 2] = [-2.0, 1.0, 2.0]           # the elbow q3 on both sides of its window about 0 (1 and 2: one gap)
    cells = bench.slab_cells(windows, Q)
    elbow = [w.name for w in windows.windows if w.is_interval].index("elbow: sin(q3)")
    assert cells[0, elbow] != cells[1, elbow] and cells[1, elbow] == cells[2, elbow]


def test_recheck_catches_a_path_through_an_obstacle(ur5e_box):
    robot, windows, world, queries, _ = ur5e_box
    blocked = [q for q in queries if q["straight_collides"]]
    assert blocked
    q = blocked[0]
    bad = bench.recheck(robot, world, windows, np.array([q["start"], q["goal"]]), q["start"], q["goal"])
    assert not bad["valid"] and not bad["check_path_valid"] and not bad["dense_valid"]
    same = np.array([q["start"], q["start"]])
    ok = bench.recheck(robot, world, windows, same, q["start"], q["start"])
    assert ok["valid"] and ok["collision_check"] == "proven"
    wrong_end = bench.recheck(robot, world, windows, same, q["start"], q["goal"])
    assert not wrong_end["valid"] and not wrong_end["ends"]


def test_json_report_holds_every_figure(monkeypatch, capsys):
    monkeypatch.setattr(bench, "ROBOTS", ("franka_panda",))     # capsules only: the quickest of the two
    monkeypatch.setattr(bench, "SCENES", {"box": bench.SCENES["box"]})
    monkeypatch.setattr(bench, "QUICK_QUERIES", 2)
    monkeypatch.setattr(bench, "CANDIDATE_POSES", 400)
    monkeypatch.setattr(bench, "TIME_LIMIT", 0.5)
    assert bench.main(["--json", "--quick", "--profile"]) == 0
    R = json.loads(capsys.readouterr().out)
    (r,) = R["robots"]
    (S,) = r["scenes"]
    s = S["summary"]
    assert s["queries"] == 2 and len(S["runs"]) == 2
    for run in S["runs"]:
        assert run["time_s"] > 0
        if run["success"]:
            assert run["recheck"]["valid"]          # plan() never returns an invalid path
    assert {t["key"] for t in R["targets"]} == set(bench.TARGETS)
    assert "tottime" in R["profile"] and "plan" in R["profile"]["cumulative"]
    text = bench.format_report(R)
    assert "bench_cell_plan" in text and "VAMP" in text
