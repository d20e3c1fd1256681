"""The placement study in quick mode, checked independently: the seam typed in from the cell file, the
torch tip at each reached weld pose by a numpy DH product at the placement found, every clearance of
those poses by coal (the cell's boxes and column moved into the robot's old frame), the placement
inside the table's region and out of the fixture's keep-out — then strict JSON and the report in
headless Chromium."""
from __future__ import annotations

import math

import coal
import numpy as np
import pytest

import kin
from kin.transforms import make_transform, rpy_to_matrix
from planning.cell import load_cell
from planning.collision import collision_world
from tests.studies.bundled.common import assert_report_holds, assert_report_renders, quick_run
from tests.studies.bundled.test_fanuc_weld_cell import (
    BASE,
    CELL_FILE,
    OBSTACLES,
    SEAM_C,
    SEAM_R,
    TIP,
    capsules,
    distance,
    frames,
    sphere_clearance,
)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return quick_run("fanuc_weld_placement", tmp_path_factory)


@pytest.fixture(scope="module")
def world():
    return collision_world(kin.load_robot("fanuc_lrmate200id"), load_cell(CELL_FILE))


def placement(run) -> np.ndarray:
    p = run.results["placement"]["answer"]["placement"]
    return make_transform(rpy_to_matrix(p["rpy"]), p["xyz"])


def test_study_ran_ok_and_the_placement_is_on_the_table(run):
    assert run.results["ok"]
    P = placement(run)
    x, y, z = P[:3, 3]
    assert -0.25 - 1e-9 <= x <= 1.05 + 1e-9 and -0.4 - 1e-9 <= y <= 0.4 + 1e-9 and z == pytest.approx(0.8)
    assert not (0.28 < x < 0.82 and -0.22 < y < 0.22)               # the fixture's keep-out
    assert np.allclose(P[2, :3], [0, 0, 1])                          # level
    before, after = run.results["before"], run.results["after"]
    assert after["coverage_percent"] >= before["coverage_percent"]
    m = run.results["placement"]["answer"]["methods"]
    assert {"ipopt", "differential_evolution", "grid"} <= set(m)
    best = max(v["value"] for v in m.values())
    assert run.results["placement"]["answer"]["method"] in [k for k, v in m.items() if v["value"] == best]


def test_reached_weld_poses_put_the_tip_on_the_seam_clear_of_the_cell(run, world):
    rows = run.results["after"]["per_target"]
    P = placement(run)
    move = BASE @ np.linalg.inv(P)          # the cell seen from the robot's old frame, where frames() works
    part = world.obstacles[2].spheres.copy()
    part[:, :3] = part[:, :3] @ move[:3, :3].T + move[:3, 3]
    obstacles = [(name, g, coal.Transform3s(move[:3, :3] @ t.getRotation(), move[:3, :3] @ t.getTranslation()
                                            + move[:3, 3]), ignore) for name, g, t, ignore in OBSTACLES]
    clearance = run.results["task"]["clearance_m"]
    reached = [r for r in rows if r["reached"]]
    assert reached
    for r in rows:
        p = np.array([r["x"], r["y"], r["z"]])
        phi = math.atan2(p[2] - SEAM_C[2], p[0] - SEAM_C[0])
        assert math.hypot(p[0] - SEAM_C[0], p[2] - SEAM_C[2]) == pytest.approx(SEAM_R, abs=1e-12)
        assert p[1] == pytest.approx(SEAM_C[1]) and -1e-9 <= phi <= math.pi + 1e-9      # the upper half
    for r in reached:
        q = np.array(r["q"])
        F = P @ np.linalg.inv(BASE) @ frames(q)[-1]
        p = np.array([r["x"], r["y"], r["z"]])
        np.testing.assert_allclose(F[:3, :3] @ TIP + F[:3, 3], p, atol=1.1e-4)
        radial = np.array([p[0] - SEAM_C[0], 0.0, p[2] - SEAM_C[2]]) / SEAM_R
        axis = F[:3, :3] @ (TIP - [0, 0, 0.2]) / np.linalg.norm(TIP - [0, 0, 0.2])
        np.testing.assert_allclose(axis, (np.array([0, 1.0, 0]) - radial) / math.sqrt(2), atol=1e-4)
        caps = capsules(world, q)
        for body, g, t, a, b, rad in caps:
            for name, og, ot, ignore in obstacles:
                if body not in ignore:
                    assert distance(g, t, og, ot) >= clearance - 1e-6, (r["target"], body, name)
            if body != 7:
                assert sphere_clearance(a, b, rad, part) >= clearance - 1e-6
        for i, j in world.pairs:
            d = min(distance(gi, ti, gj, tj) for bi, gi, ti, *_ in caps for bj, gj, tj, *_ in caps
                    if (bi, bj) == (i, j))
            assert d >= clearance - 1e-6


def test_report_holds_the_figures(run):
    assert_report_holds(run.report, run.results, texts=["placement_3d", "The LR Mate at its new place"],
                        pngs=["placement_map.png", "seam_heat_map.png"])


def test_report_renders_in_a_browser(run, report_browser):
    a = run.results["after"]
    assert_report_renders(report_browser, run.report, run.results,
                          numbers=(f"{a['coverage_percent']:.0f} % reached", "Before and after"))
