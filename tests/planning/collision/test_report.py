"""The nearest obstacle and the nearest self pair named apart, against coal: the planar 2R in a cell
with two boxes and a tool capsule, its frames by plain numpy FK (Rz(q)·Tx(a) per joint), every
capsule–box and capsule–capsule distance by coal; `rmt clearance` and `rmt check-path` report them."""
from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest

import kin
from planning.collision import ClearanceTally, collision_world, nearest_obstacle_per_body
from planning.validate import densify
from studies.cli import main
from tests.coal_ref import capsule, distance

coal = pytest.importorskip("coal")

CELL = """name = "two blocks"
length_unit = "m"
angle_unit = "deg"
[[obstacle]]
name = "near block"
type = "box"
size = [0.1, 0.1, 0.1]
xyz = [1.6, 1.1, 0]
[[obstacle]]
name = "far block"
type = "box"
size = [0.2, 0.2, 0.2]
xyz = [-0.9, -1.2, 0]
[[tool]]
name = "gripper"
type = "capsule"
a = [0, 0, 0]
b = [0.15, 0, 0]
radius = 0.03
"""
BOXES = {"near block": ((1.6, 1.1, 0.0), (0.1, 0.1, 0.1)), "far block": ((-0.9, -1.2, 0.0), (0.2, 0.2, 0.2))}
NAMES = ["base", "link 1 (J1)", "link 2 (J2)", "tool"]


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    d = tmp_path_factory.mktemp("report")
    (d / "cell.toml").write_text(CELL)
    robot = kin.load_robot("planar_2r")
    return robot, d / "cell.toml", collision_world(robot, d / "cell.toml")


def _frames(q) -> list[np.ndarray]:
    """Bodies 0 … 3 of the planar 2R (a1 = 1, a2 = 0.8; tool = frame 2), plain numpy."""
    def A(t, a):
        return np.array([[np.cos(t), -np.sin(t), 0, a * np.cos(t)], [np.sin(t), np.cos(t), 0, a * np.sin(t)],
                         [0, 0, 1, 0], [0, 0, 0, 1.0]])
    F1 = A(q[0], 1.0)
    F2 = F1 @ A(q[1], 0.8)
    return [np.eye(4), F1, F2, F2]


def _capsule(c, F):
    """Capsule ``c`` placed by its body's frame ``F``, as a coal object."""
    return capsule((F @ [*c.a, 1])[:3], (F @ [*c.b, 1])[:3], c.radius)


def _by_coal(world, q):
    """Every capsule–box distance {(body, obstacle): d} and self-pair distance {(i, j): d} (minimum over a
    body's capsules), by coal; and the nearest of each: (d, body, obstacle) and (d, i, j)."""
    F = _frames(q)
    caps = [(c.body, _capsule(c, F[c.body])) for c in world.geometry.capsules]
    boxes = {n: coal.CollisionObject(coal.Box(*s), coal.Transform3s(np.eye(3), np.array(p))) for n, (p, s) in
             BOXES.items()}
    obs, slf = {}, {}
    for b, o in caps:
        for n in boxes:
            obs[b, n] = min(obs.get((b, n), np.inf), distance(o, boxes[n]))
        for b2, o2 in caps:
            if (b, b2) in world.pairs:
                slf[b, b2] = min(slf.get((b, b2), np.inf), distance(o, o2))
    return obs, slf, min((d, *k) for k, d in obs.items()), min((d, *k) for k, d in slf.items())


def test_checked_pairs_are_the_non_adjacent_ones(setup):
    _, _, world = setup
    # base–link 2, base–tool, link 1–tool: not adjacent (the tool is adjacent to link 2 only)
    assert set(world.pairs) == {(0, 2), (0, 3), (1, 3)}


@pytest.mark.parametrize("q", [(0.3, 1.2), (0.9, 0.4), (-2.0, 2.6), (1.0, 2.7)])
def test_tally_names_both_as_coal_measures(setup, q):
    _, _, world = setup
    t = ClearanceTally(world)
    t.add(np.array([q]))
    obs, slf, (d_o, _, _), (d_s, _, _) = _by_coal(world, q)
    # the distance is the smallest, and the pair named is at that distance (equal pairs may tie)
    assert t.obstacle.distance == pytest.approx(d_o, abs=1e-6)
    assert obs[NAMES.index(t.obstacle.body), t.obstacle.other] == pytest.approx(d_o, abs=1e-6)
    assert t.self_pair.distance == pytest.approx(d_s, abs=1e-6)
    i, j = sorted((NAMES.index(t.self_pair.body), NAMES.index(t.self_pair.other)))
    assert slf[i, j] == pytest.approx(d_s, abs=1e-6)
    named = nearest_obstacle_per_body(world, q)
    for b in range(4):                      # beyond the cap (1 m) nothing is named
        d = min(v for (bb, _), v in obs.items() if bb == b)
        if d >= world.cap:
            assert named[b] is None
        else:
            assert named[b][1] == pytest.approx(d, abs=1e-6) and obs[b, named[b][0]] == pytest.approx(d, abs=1e-6)
    # witness points lie |distance| apart
    p, o = (np.array(v) for v in t.obstacle.points)
    assert np.linalg.norm(p - o) == pytest.approx(abs(t.obstacle.distance), abs=1e-6)


def run(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, out.getvalue(), err.getvalue()


def test_rmt_clearance_reports_both_apart(setup):
    _, cell, world = setup
    q = (1.0, 2.7)             # folded: link 2 near the base
    obs, _, (d_o, b_o, n_o), (d_s, b1, b2) = _by_coal(world, q)
    assert d_s < d_o            # the self pair is nearer: it must not hide the obstacle
    rc, out, err = run(["clearance", "planar_2r", *map(str, q), "--cell", str(cell), "--json"])
    assert rc == 0, err
    d = json.loads(out)
    assert d["clearance"] == pytest.approx(d_s, abs=1e-6)
    # links 1 and 2 tie here (the elbow is the nearest point of both): either may be named
    tied = {NAMES[b] for (b, n), v in obs.items() if n == n_o and abs(v - d_o) < 1e-9}
    assert d["nearest_obstacle"]["obstacle"] == n_o and d["nearest_obstacle"]["body"] in tied
    b_o = NAMES.index(d["nearest_obstacle"]["body"])
    assert d["nearest_obstacle"]["distance"] == pytest.approx(d_o, abs=1e-6)
    assert {d["nearest_self"]["body"], d["nearest_self"]["other_body"]} == {NAMES[b1], NAMES[b2]}
    assert d["nearest_self"]["distance"] == pytest.approx(d_s, abs=1e-6)
    rows = {r["body"]: r for r in d["per_body"]}
    assert rows[NAMES[b_o]]["nearest_obstacle"] == n_o
    rc, out, _ = run(["clearance", "planar_2r", *map(str, q), "--cell", str(cell)])
    head = out.splitlines()[0]
    assert any(head.startswith(f"clear: nearest obstacle '{n_o}' to {name}: {d_o * 1e3:.4g} mm; nearest self pair ")
               for name in tied)
    assert f"{d_s * 1e3:.4g} mm" in head
    assert "nearest obstacle" in out.splitlines()[1]     # the per-body table names each body's obstacle


def test_check_path_reports_both_over_the_dense_states(setup, tmp_path):
    robot, cell, world = setup
    P = np.array([[0.3, 1.2], [0.9, 0.4]])
    path = tmp_path / "p.csv"
    path.write_text("q1,q2\n" + "".join(f"{a!r},{b!r}\n" for a, b in P.tolist()))
    rc, out, err = run(["check-path", "planar_2r", str(path), "--cell", str(cell), "--json"])
    assert rc == 0, err
    d = json.loads(out)
    Q, seg, _ = densify(P, robot.chain.revolute_mask)       # the default step, as check-path
    best_o = min(_by_coal(world, q)[2] for q in Q)
    best_s = min(_by_coal(world, q)[3] for q in Q)
    assert d["nearest_obstacle"]["distance"] == pytest.approx(best_o[0], abs=1e-6)
    assert d["nearest_obstacle"]["obstacle"] == best_o[2]
    assert d["nearest_self"]["distance"] == pytest.approx(best_s[0], abs=1e-6)
    assert d["min_clearance"] == pytest.approx(min(best_o[0], best_s[0]), abs=1e-6)
    rc, out, _ = run(["check-path", "planar_2r", str(path), "--cell", str(cell)])
    assert f"nearest obstacle '{best_o[2]}'" in out and "nearest self pair" in out


@pytest.mark.parametrize("robot_name, cell", [("fanuc_lrmate200id", "fanuc_weld_cell"), ("ur5e", "ur5e_shelf_cell"),
                                              ("ur5e", None)])
def test_the_tally_gives_the_worlds_clearance(robot_name, cell):
    """check_path takes each state's clearance from the tally (its two kinds' models): exactly the
    world's own, the same pairs in one model."""
    from studies.cli.common import cell_file
    robot = kin.load_robot(robot_name)
    world = collision_world(robot, None if cell is None else cell_file(cell), 0.0)
    Q = robot.random_configurations(3000, seed=3)
    c = ClearanceTally(world).add(Q)
    assert np.array_equal(c, world.clearance(Q))
    assert (c < world.cap).any()              # pairs within the cap: the comparison is not of two constants
