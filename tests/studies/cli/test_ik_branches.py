"""rmt ik with a closed form (issue 29 finding 1): every branch, nearest to --near (default zero) first,
each reaching the pose by the numpy FK; the cell frame with --cell; bad frame/reference input exits 2."""
from __future__ import annotations

import json

import numpy as np

import kin
from kin.transforms import make_transform, rpy_to_matrix
from planning.collision import collision_world
from studies.cli import main
from studies.cli.common import cell_file
from tests.dh_numpy import fk_numpy

ARGS = ["ik", "ur5e", "--xyz", "0.45", "-0.2", "0.2", "--rpy", "180", "0", "0"]


def _json(capsys, argv):
    rc = main(argv + ["--json"])
    out, _ = capsys.readouterr()
    return rc, json.loads(out)


def test_every_branch_ranked_from_zero(capsys):
    c = kin.load_chain("ur5e")
    target = make_transform(rpy_to_matrix(np.radians([180, 0, 0])), np.array([0.45, -0.2, 0.2]))
    rc, d = _json(capsys, ARGS)
    assert rc == 0 and d["method"] == "closed form" and len(d["solutions"]) == 8
    Q = np.array([s["q"] for s in d["solutions"]])
    for q in Q:
        assert np.abs(fk_numpy(c, c.to_si(q)) - target).max() < 1e-9
    dist = np.linalg.norm(np.radians(Q), axis=1)
    assert np.all(np.diff(dist) >= -1e-9) and d["q"] == d["solutions"][0]["q"]
    # the absurd answer of the issue is no longer first; every joint of the first is within ±180°
    assert not np.allclose(Q[0], [-8.3, -208.2, 87.7, -329.5, 270, -278.3], atol=0.2)
    assert np.abs(Q[0]).max() <= 180 + 1e-6


def test_near_puts_the_reference_branch_first(capsys):
    near = [-8.25708, 151.81, 87.6707, 30.5188, -90, 81.7429]
    rc, d = _json(capsys, ARGS + ["--near", *map(str, near)])
    assert rc == 0 and np.allclose(d["q"], near, atol=1e-3)
    rc, many = _json(capsys, ARGS + ["--all-turns", "--near", *map(str, near)])
    assert len(many["solutions"]) > 8 and np.allclose(many["q"], near, atol=1e-3)
    main(ARGS)
    text, _ = capsys.readouterr()
    assert text.startswith("8 solution(s) by the closed form (base frame), nearest to the zero configuration")


def test_cell_frame_and_collisions(capsys):
    robot = kin.load_robot("ur5e")
    world = collision_world(robot, cell_file("ur5e_shelf_cell"))
    target = make_transform(rpy_to_matrix(np.radians([180, 0, 0])), np.array([0.45, -0.2, 0.95]))
    argv = ["ik", "ur5e", "--xyz", "0.45", "-0.2", "0.95", "--rpy", "180", "0", "0", "--cell", "ur5e_shelf_cell"]
    rc, d = _json(capsys, argv)
    assert rc == 0 and d["frame"] == "cell"
    for s in d["solutions"]:
        q = robot.chain.to_si(s["q"])
        assert np.abs(world.base @ fk_numpy(robot.chain, q) - target).max() < 1e-9
        assert (s["collision"] is None) == bool(world.clearance(q) > 0)
    assert any(s["collision"] for s in d["solutions"]) and any(s["collision"] is None for s in d["solutions"])
    rc, b = _json(capsys, argv + ["--frame", "base"])
    assert b["frame"] == "base" and b["solutions"] != d["solutions"]


def test_bad_frame_and_reference_exit_2(capsys):
    assert main(ARGS + ["--frame", "cell"]) == 2
    assert "--frame cell" in capsys.readouterr().err
    assert main(ARGS + ["--near", "0", "0", "0", "0", "0", "0", "--q0", "0", "0", "0", "0", "0", "0"]) == 2
    assert main(["ik", "ur5e", "--xyz", "0.4", "0", "0.2", "--all-turns"]) == 2
    assert main(["ik", "ur5e", "--xyz", "3", "0", "0", "--rpy", "180", "0", "0"]) == 1
    assert "NO solution (base frame): out of reach" in capsys.readouterr().out
