"""The reach benchmark (studies/benchmarks/bench_reach.py) at tiny sizes: its targets are what it
says, the pinocchio user's loop takes rmtkit's goals in rmtkit's frames (a configuration the reach
study calls reached, given as the start, is reached at once and found clear by coal), and
``bench_reach --json --quick`` reports every figure — the 2R placement within 1 mm of the ring's
centre.  No timing asserted."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
import studies.benchmarks.bench_reach as bench
from design.reach import ReachSettings, ScoreWeights, reach_study
from design.reach.study import ReachProblem
from planning.cell import load_cell
from planning.collision import collision_world

TINY = dict(reach_shape=(2, 2, 2), rm_repeats=1, peer_repeats=1, place_shape=(2, 1, 2), place_grid=3,
            place_repeats=1, ring=(3, 6))


def test_targets_are_the_boxes_and_rings():
    T = bench.box_targets(bench.REACH_BOX, (5, 8, 5))
    assert len(T) == 200 and T.orientation == "axis"
    np.testing.assert_allclose(T.axes, np.tile([0, 0, -1.0], (200, 1)))
    np.testing.assert_allclose(T.positions.min(axis=0), [b[0] for b in bench.REACH_BOX])
    np.testing.assert_allclose(T.positions.max(axis=0), [b[1] for b in bench.REACH_BOX])
    R = bench.ring_targets(3, 6)
    r = np.linalg.norm(R.positions - np.asarray(bench.RING_CENTRE), axis=1)
    assert R.orientation == "free" and len(R) == 18
    np.testing.assert_allclose(sorted(set(np.round(r, 12))), [0.2, 1.0, 1.8])


def test_the_peer_takes_rmtkits_goals_and_solutions():
    pytest.importorskip("pinocchio")
    robot = kin.load_robot(bench.ROBOT)
    cell = load_cell(str(bench.scene_path(bench.CELL)))
    targets = bench.box_targets(bench.REACH_BOX, (2, 2, 2))
    settings = ReachSettings()
    study = reach_study(robot, targets, cell)
    assert study.reached.any()
    pb = ReachProblem(robot, targets, cell, 0.0, None, ScoreWeights(), settings, None)
    goals, starts, mode = pb.goals(pb.default_base)
    assert mode == "pose" and starts.shape == (len(targets), settings.starts, robot.n)
    # rmtkit's own solution as every start: the loop must call it converged and clear, where rmtkit
    # reached the target (the solution is at one of the spins' goals, met to the tolerance)
    mine = np.repeat(study.q[:, None], settings.starts, axis=1)
    run, scene = bench.clik_peer(collision_world(robot, cell), goals, mine, pb.nv, 1e-5, settings.max_iter)
    reached, runs, iters, checks = run()
    assert reached[study.reached].all()
    assert scene.robot_geoms == len(robot.geometry.capsules) and checks >= study.reached.sum()


def test_json_report_holds_every_figure(monkeypatch, capsys):
    monkeypatch.setitem(bench.SIZES, True, TINY)
    assert bench.main(["--json", "--quick"]) == 0
    R = json.loads(capsys.readouterr().out)
    assert R["benchmark"] == "bench_reach" and R["quick"] is True
    S = R["reach_study"]
    assert S["targets"] == 8 and S["rmtkit"]["targets_per_s"] > 0
    assert 0 <= S["rmtkit"]["coverage_percent"] <= 100
    if "skipped" not in S["pinocchio"]:
        assert S["pinocchio"]["targets_per_s"] > 0 and S["ratio_targets_per_s"] > 0
        a = S["agreement"]
        assert a["both_reached"] + a["neither"] + a["rmtkit_only"] + a["pinocchio_only"] == 8
        assert a["disagreements"] == a["rmtkit_only"] + a["pinocchio_only"]
    P = R["placement"]
    assert P["grid"]["placements"] == 27 and P["acceptance"] is False
    for k in ("ipopt", "grid"):
        assert {"coverage_percent", "mean_score", "placement"} <= set(P[k])
    assert P["time_ratio"] > 0
    Q = R["planar_2r"]
    assert Q["distance_mm"] < 1.0 and Q["coverage_percent"] == 100.0
    assert {t["key"] for t in R["targets"]} == set(bench.TARGETS)
    assert {t["status"] for t in R["targets"]} <= {"PASS", "MISS", "n/a"}
    assert "unreliable_sections" in R["environment"]
    text = bench.format_report(R)
    assert "bench_reach" in text and "not the acceptance figure" in text
