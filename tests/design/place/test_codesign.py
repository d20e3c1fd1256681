"""Co-design through the sweep machinery (placement = true) and two robots sharing a task."""
import sqlite3

import numpy as np
import pytest

import kin
from design.place import PlacementRegion
from design.place.codesign import pareto_front
from design.place.pair import place_pair, robot_robot_clearance
from design.reach import ReachSettings
from design.sweep import load_sweep, run_sweep
from design.sweep.file import SweepError
from design.sweep.store import read_rows
from design.task.model import Targets
from design.task.targets import box_points

TASK = """
name = "ring_off"
robot = "{robot}"
length_unit = "m"
angle_unit = "deg"
objective = "coverage"
[target]
shape = "ring"
center = [0.5, 0.3, 0]
r_inner = 0.3
r_outer = 1.2
count = [3, 8, 1]
[constraints]
min_coverage = 0.0
"""
SWEEP = """
name = "ring_codesign"
task = "task.toml"
placement = {flag}
[sampling]
method = "grid"
[parameters.L1]
values = [0.3, 0.75]
[parameters.L2]
values = [0.3, 0.75]
"""


def _files(tmp_path, flag="true"):
    from importlib.resources import files
    robot = files("studies") / "tasks" / "robots" / "planar_2r_design.toml"
    (tmp_path / "task.toml").write_text(TASK.format(robot=str(robot)))
    (tmp_path / "sweep.toml").write_text(SWEEP.format(flag=flag))
    return tmp_path / "sweep.toml"


def test_placed_sweep_rows(tmp_path):
    sweep = load_sweep(_files(tmp_path))
    assert sweep.placement
    rep = run_sweep(sweep, tmp_path / "s.sqlite")
    assert rep.counts["done"] == 4
    rows = read_rows(sqlite3.connect(tmp_path / "s.sqlite"))
    flat = {(r["params"]["L1"], r["params"]["L2"]): r["metrics"] for r in rows}
    # L1 = L2 = 0.75: the annulus [0, 1.5] holds the ring [0.3, 1.2] from its centre: everything
    best = flat[(0.75, 0.75)]
    assert best["coverage"] == 1.0
    assert np.hypot(best["placement_x"] - 0.5, best["placement_y"] - 0.3) <= 0.3 + 1e-9
    # L1 = L2 = 0.3: annulus [0, 0.6] — at most the ring's share inside radius 0.6 of a centre
    assert flat[(0.3, 0.3)]["coverage"] < 0.6
    assert flat[(0.3, 0.3)]["structural_length"] == pytest.approx(0.6)
    front = pareto_front(list(flat.values()))
    assert list(flat.values()).index(best) in front


def test_placement_flag_must_be_boolean(tmp_path):
    with pytest.raises(SweepError, match="placement"):
        load_sweep(_files(tmp_path, flag='"yes"'))


def test_two_robots_split_a_long_task():
    ur = kin.load_robot("ur5e")
    P = box_points([0.6, -1.2, 0.0], [0.9, 1.2, 0.2], (2, 7, 2))
    t = Targets(P, "axis", axes=np.tile([0, 0, -1.0], (len(P), 1)), tolerance=1e-5)
    regs = (PlacementRegion((0, 0.5), (-1.5, 0), (0, 0)), PlacementRegion((0, 0.5), (0, 1.5), (0, 0)))
    res = place_pair((ur, ur), t, regions=regs, clearance=0.02, settings=ReachSettings(starts=4, samples=1024, spins=4),
                     starts=2, candidates=12)
    a, b = res.assignment == 0, res.assignment == 1
    assert res.coverage > max(res.studies[0].coverage, res.studies[1].coverage)
    assert np.all(res.studies[0].reached[a]) and np.all(res.studies[1].reached[b])
    assert not res.conflicts
    # recompute the robot–robot clearance of the assigned configurations independently of place_pair
    from design.place import placement_transform
    from planning.collision import collision_world
    wa, wb = collision_world(ur, None), collision_world(ur, None)
    wa.move_base(placement_transform(res.u[0]))
    wb.move_base(placement_transform(res.u[1]))
    C = robot_robot_clearance(wa, res.studies[0].q[a], wb, res.studies[1].q[b])
    assert C.min() > 0.02 and C.min() == pytest.approx(res.robot_clearance)
