"""``rmt import-scene`` end to end: a MotionBenchMaker cage (its board called "base") imported, planned
in and checked by proof, the obstacle named as the obstacle; a .scene text file with every shape kind;
bad input exits 2 with one line and writes nothing."""
from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest
import yaml

from planning.cell import load_cell
from planning.cell.moveit import load_scene, scene_cell
from studies.cli import main
from tests.planning.cell.moveit.scenes import TEXT_NOETIC


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def cage():
    from studies.benchmarks.mbm import MbmDataError, problem_dir
    try:
        return problem_dir("panda") / "cage_panda"
    except MbmDataError as e:
        pytest.skip(f"MotionBenchMaker data: {e}")


def test_a_motionbenchmaker_cage_planned_in_and_proven(capsys, tmp_path, cage):
    cell = tmp_path / "cage.toml"
    code, out, err = run(capsys, "import-scene", cage / "scene0001.yaml", "--out", cell, "--robot", "franka_panda")
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert lines[0].endswith(f"(PlanningScene YAML): 8 objects → {cell}: 8 obstacles (8 boxes), in m and degrees, "
                             f"in the scene's planning frame")
    assert lines[1] == ("  obstacle 'base' has the name of franka_panda's body base: the cell keeps it; in [allow] "
                        "pairs write 'obstacle:base' for the obstacle, 'body:base' for the body")
    assert cell.read_text() == scene_cell(load_scene(cage / "scene0001.yaml"), str(cell))[0]
    assert [o.name for o in load_cell(cell).obstacles][:2] == ["Cube1", "base"]
    # MotionBenchMaker's problem 1 in it: planned, proven clear, and proven again by check-path
    req = yaml.safe_load((cage / "request0001.yaml").read_text())
    start = [str(x) for x in req["start_state"]["joint_state"]["position"][:7]]
    goal = [str(j["position"]) for j in req["goal_constraints"][0]["joint_constraints"]]
    path = tmp_path / "move.csv"
    code, out, _ = run(capsys, "plan", "franka_panda", "--start", *start, "--goal", *goal, "--cell", cell,
                       "--time-limit", "10", "--out", path, "--json")
    d = json.loads(out)
    assert code == 0 and d["success"] and d["proven"] and d["checks"]["collisions"] == "proven"
    assert d["min_clearance"] > 0
    code, out, _ = run(capsys, "check-path", "franka_panda", path, "--cell", cell, "--json")
    assert code == 0 and json.loads(out)["collision_check"] == "proven"
    # at the goal, link 6 is nearest the cage's floor board: "obstacle 'base'", not the robot's base
    code, out, _ = run(capsys, "clearance", "franka_panda", *goal, "--cell", cell, "--json")
    d = json.loads(out)
    assert code == 0 and d["other"] == "obstacle 'base'" and d["body"] == "link 6 (joint6)"
    base_row = next(r for r in d["per_body"] if r["body"] == "base")
    assert base_row["obstacles"] > 0.3                 # the robot's own base is far from every board


def test_a_scene_text_file_every_kind_placed_and_named(capsys, tmp_path):
    (tmp_path / "lab.scene").write_text(TEXT_NOETIC)
    out_cell = tmp_path / "sub" / "lab.toml"
    code, out, err = run(capsys, "import-scene", tmp_path / "lab.scene", "--out", out_cell, "--robot-xyz", "0.1", "0",
                         "0.8", "--robot-rpy", "0", "0", "90", "--name", "lab cell")
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert lines[0].endswith("(.scene text (object poses: MoveIt ≥ 1.1.10, Noetic)): 4 objects → "
                             f"{out_cell}: 4 obstacles (1 box, 1 cone, 1 cylinder, 1 mesh, 1 sphere; 1 of several "
                             "shapes, as compound obstacles), in m and degrees, in the scene's planning frame")
    assert lines[1].startswith("  cones and meshes are held by shapes that stand out of them by at most 94.9 mm")
    assert lines[2].startswith("  obstacle 'base' has the name of a robot body: the cell keeps it")
    cell = load_cell(out_cell)
    assert cell.name == "lab cell" and [o.kind for o in cell.obstacles] == ["compound", "sphere", "mesh", "cone"]
    np.testing.assert_allclose(cell.base[:3, 3], [0.1, 0, 0.8])
    np.testing.assert_allclose(cell.base[:3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    code, out, _ = run(capsys, "import-scene", tmp_path / "lab.scene", "--out", out_cell, "--robot",
                       "fanuc_lrmate200id", "--json")
    d = json.loads(out)
    assert code == 0 and d["obstacles"] == 4 and d["body_names"] == ["base"] and d["compound"] == 1
    assert d["shapes"] == {"box": 1, "cylinder": 1, "sphere": 1, "mesh": 1, "cone": 1}
    assert d["over_estimate"] == pytest.approx(0.1 * 0.3 / np.hypot(0.1, 0.3), rel=1e-5)
    assert d["robot"] == "fanuc_lrmate200id" and d["units"] == {"length": "m", "angle": "deg"}
    assert tomllib.loads(out_cell.read_text())["robot"] == {"xyz": [0, 0, 0], "rpy": [0, 0, 0]}


@pytest.mark.parametrize("argv, words", [
    (["{d}/lab.scene", "--out", "{d}/x.json"], ["--out '{d}/x.json' must end in .toml"]),
    (["{d}/lab.scene", "--out", "{d}/adir.toml"], ["adir.toml: is a directory"]),
    (["{d}/none.yaml", "--out", "{d}/x.toml"], ["none.yaml: no such scene file"]),
    (["{d}/nan.yaml", "--out", "{d}/x.toml"], ["nan.yaml: object 1 ('b'): primitives[0]: dimensions",
                                                "finite number"]),
    (["{d}/base.yaml", "--out", "{d}/x.toml", "--robot", "no_such_robot"], ["no_such_robot"]),
    (["{d}/lab.scene", "--out", "{d}/x.toml", "--robot-xyz", "0", "nan", "0"], ["nan is outside the allowed range"]),
    (["{d}/lab.scene", "--out", "{d}/x.toml", "--robot-rpy", "0", "0", "400"], ["400 is outside the allowed range"]),
    (["{d}/lab.scene", "--out", "{d}/x.toml", "--name", " "], ["--name ' ' must be 1 to 100 printable characters"]),
    (["{d}/base.yaml", "--out", "{d}/x.toml", "--frame", "a b"], ["--frame 'a b' must be a frame name"]),
    (["{d}/lab.scene", "--out", "{d}/x.toml", "--frame", "world"], ["a .scene file names no frames"]),
])
def test_bad_input_exits_2_with_one_line_and_writes_nothing(capsys, tmp_path, argv, words):
    (tmp_path / "lab.scene").write_text(TEXT_NOETIC)
    (tmp_path / "nan.yaml").write_text("world: {collision_objects: [{id: b, primitives: "
                                       "[{type: box, dimensions: [1, .nan, 1]}]}]}\n")
    (tmp_path / "base.yaml").write_text("world: {collision_objects: [{id: base, primitives: "
                                        "[{type: box, dimensions: [1, 1, 1]}]}]}\n")
    (tmp_path / "adir.toml").mkdir()
    before = sorted(p.name for p in tmp_path.iterdir())
    code, out, err = run(capsys, "import-scene", *(a.format(d=tmp_path) for a in argv))
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("rmt: error: ") and "Traceback" not in err
    for w in words:
        assert w.format(d=tmp_path) in err, (w, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == before
