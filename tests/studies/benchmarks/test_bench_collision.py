"""The collision benchmark's peers (studies/benchmarks/collision_peers.py) are rmtkit's robot and cell:
the chain rebuilt in pinocchio has rmtkit's frames, its capsules in coal give rmtkit's clearances,
the pairs are exactly the world's, and the Panda URDF's meshes sit on the right bodies; and
``bench_collision --json --quick`` reports every figure.  No timing asserted."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kin
import studies.benchmarks.bench_collision as bench
from kin.geometry import ClearanceModel, body_frames
from studies.benchmarks import collision_peers as cp


@pytest.fixture(scope="module", params=bench.ROBOTS)
def world(request):
    return bench.world_for(kin.load_robot(request.param))


def test_the_cell_resolves_for_both_robots(world):
    assert len(world.obstacles) >= 10
    kinds = {sh.kind for ob in world.obstacles for sh in ob.shapes}
    assert kinds == {"box", "cylinder", "capsule", "sphere"}
    assert world.obstacles[0].name == "table" and world.obstacles[0].ignore == {0, 1}


def test_capsule_scene_is_rmtkits_world(world):
    pytest.importorskip("pinocchio")
    scene = cp.tighten(cp.capsule_scene(world))
    caps = world.geometry.capsules
    expected = sum(1 for c in caps for ob in world.obstacles for _ in ob.shapes if c.body not in ob.ignore)
    assert int(scene.obstacle_pairs.sum()) == expected
    self_bodies = {(min(b, -1 - o), max(b, -1 - o)) for b, o in zip(scene.pair_body, scene.pair_other) if o < 0}
    assert self_bodies == set(world.pairs)
    Q = world.robot.random_configurations(30, seed=4)
    for x in Q[:5]:
        F = body_frames(world.chain, x[None])[0, 1:world.chain.n + 1]
        np.testing.assert_allclose(cp.body_frames_pin(scene, world.chain, x), F, atol=1e-12)
    exact = ClearanceModel(world.chain, world.geometry, world.obstacles, base=world.base, self_pairs=world.pairs,
                           cap=math.inf)
    ob, se = exact.per_body(Q)
    D = np.array([scene.distances(x) for x in Q])
    for ours, mask in ((ob.min(axis=1), scene.obstacle_pairs), (se.min(axis=1), ~scene.obstacle_pairs)):
        theirs = D[:, mask].min(axis=1)
        clear = theirs > 0
        assert ((ours > 0) == clear).all()
        np.testing.assert_allclose(ours[clear], theirs[clear], rtol=0, atol=1e-6)


def test_panda_meshes_sit_on_their_bodies():
    pytest.importorskip("pinocchio")
    share = cp.erd_share()
    if share is None:
        pytest.skip("example-robot-data is not installed")
    world = bench.world_for(kin.load_robot("franka_panda"))
    scene = cp.urdf_mesh_scene(world, share / cp.PANDA_URDF, share, cp.PANDA_LINKS)
    assert scene.robot_geoms == 8 and any("panda_hand" in note for note in scene.notes)
    assert set(scene.pair_body) == set(range(8))
    # the arm folded down into the table: coal's meshes collide with an obstacle
    folded = np.array([0.0, 1.7, 0.0, -0.5, 0.0, 2.0, 0.0])
    assert scene.collisions(folded)[scene.obstacle_pairs].any()


def test_json_report_holds_every_figure(monkeypatch, capsys):
    monkeypatch.setitem(bench.SIZES, True, dict(N=3000, repeats=1, loop=20, mesh_dist=2, mesh_col=20, agree=10,
                                                 enclose=4, single=200))
    assert bench.main(["--json", "--quick"]) == 0
    R = json.loads(capsys.readouterr().out)
    assert [r["robot"] for r in R["robots"]] == list(bench.ROBOTS)
    for r in R["robots"]:
        one = r["rmtkit"]["threads"]["1"]
        assert {"clearance", "per_body", "clearance_exact", "per_body_exact"} <= set(one)
        assert one["clearance"]["median_cfg_per_s"] > 0
        if "skipped" not in r["pinocchio"]:
            assert r["pinocchio"]["capsules"]["pairs"] > 0
            assert r["agreement"]["obstacles"]["max_ours_minus_coal_m"] <= 1e-9
            assert r["ratios"]
    panda = R["robots"][0]
    if panda["enclosure"] is not None:
        assert set(panda["enclosure"]["sets"]) == {"uniform", "near_contact"}
        assert isinstance(panda["enclosure"]["violations"], int)
    assert {t["key"] for t in R["targets"]} == set(bench.TARGETS)
    assert "bench_collision" in bench.format_report(R)


def test_urdf_geometry_needs_collision_geometry_from_the_import():
    robot = None
    try:
        robot = bench.load_robot("franka_panda", "urdf")
    except RuntimeError as e:
        assert "collision geometry" in str(e) or "example-robot-data" in str(e)
    if robot is not None:
        assert robot.geometry.source != "default"
