"""Issue acceptance, end to end through the CLI: on the FANUC LR Mate 200iD a box stands where the
straight joint move sweeps the forearm (not the tool point) through it; `rmt plan --cell` returns a
path that `rmt check-path --cell` proves clear, and coal's exact distance between the URDF written
by `rmt export-urdf` (its collision elements, placed by the URDF's own forward kinematics in
yourdfpy) and the box stays positive along the densely interpolated path."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from studies.cli import main

coal = pytest.importorskip("coal")
yourdfpy = pytest.importorskip("yourdfpy")

CELL = """length_unit = "mm"
name = "forearm box"
[[obstacle]]
name = "box"
type = "box"
size = [60, 60, 200]
xyz = [300, 0, 700]
"""
BOX_LO, BOX_HI = np.array([0.27, -0.03, 0.6]), np.array([0.33, 0.03, 0.8])
START, GOAL = ["-60", "15", "0", "0", "-70", "0"], ["60", "15", "0", "0", "-70", "0"]


def _run(argv, capsys):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def _urdf_collision_objects(path):
    """(link name, coal shape, 4×4 origin in the link) for every collision element of a URDF."""
    robot = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False, load_collision_meshes=False)
    out = []
    for link in robot.robot.links:
        for col in link.collisions:
            g = col.geometry
            if g.box is not None:
                shape = coal.Box(*np.asarray(g.box.size, float))
            elif g.cylinder is not None:
                shape = coal.Cylinder(float(g.cylinder.radius), float(g.cylinder.length))
            elif g.sphere is not None:
                shape = coal.Sphere(float(g.sphere.radius))
            else:
                raise AssertionError(f"{link.name}: unexpected collision geometry {g}")
            origin = np.eye(4) if col.origin is None else np.asarray(col.origin, float)
            out.append((link.name, shape, origin))
    return robot, out


def test_forearm_box_plan_is_proven_and_coal_agrees(tmp_path, capsys):
    robot = kin.load_robot("fanuc_lrmate200id")
    cell = tmp_path / "cell.toml"
    cell.write_text(CELL)
    s, g = robot.chain.to_si(np.array([float(x) for x in START])), robot.chain.to_si(np.array([float(x) for x in GOAL]))
    t = np.linspace(0, 1, 501)
    line = s + t[:, None] * (g - s)
    tool = robot.fk(line)[:, :3, 3]
    assert not np.all((tool >= BOX_LO) & (tool <= BOX_HI), axis=1).any(), "the tool point must miss the box"
    # the straight line collides, by the forearm
    path_csv = tmp_path / "line.csv"
    path_csv.write_text("\n".join(",".join(x) for x in (START, GOAL)) + "\n")
    rc, out, _ = _run(["check-path", "fanuc_lrmate200id", str(path_csv), "--cell", str(cell), "--json"], capsys)
    d = json.loads(out)
    assert rc == 1 and d["first_violation"]["kind"] == "collision"
    assert ("link 3" in d["first_violation"]["detail"] or "link 4" in d["first_violation"]["detail"])
    assert "'box'" in d["first_violation"]["detail"]
    # the cell-aware plan is proven clear, and check-path proves it again
    planned = tmp_path / "move.csv"
    rc, out, _ = _run(["plan", "fanuc_lrmate200id", "--start", *START, "--goal", *GOAL, "--margin", "0.05",
                       "--cell", str(cell), "--out", str(planned), "--json"], capsys)
    d = json.loads(out)
    assert rc == 0 and d["success"] and d["proven"] and d["checks"]["collisions"] == "proven"
    assert d["min_clearance"] > 0 and d["clearance_bound"] > 0
    rc, out, _ = _run(["check-path", "fanuc_lrmate200id", str(planned), "--margin", "0.05", "--cell", str(cell),
                       "--json"], capsys)
    c = json.loads(out)
    assert rc == 0 and c["valid"] and c["collision_check"] == "proven" and c["windows_check"] == "proven"
    # coal, on the exported URDF's collision geometry, placed by yourdfpy's forward kinematics
    urdf = tmp_path / "fanuc.urdf"
    assert _run(["export-urdf", "fanuc_lrmate200id", "--out", str(urdf)], capsys)[0] == 0
    model, objects = _urdf_collision_objects(urdf)
    assert objects, "the exported URDF has collision geometry"
    box = coal.CollisionObject(coal.Box(*(BOX_HI - BOX_LO)), coal.Transform3s(np.eye(3), 0.5 * (BOX_LO + BOX_HI)))
    P = robot.chain.to_si(np.loadtxt(planned, delimiter=",", comments="#", ndmin=2, skiprows=1))
    joints = model.actuated_joint_names
    worst = np.inf
    for a, b in zip(P[:-1], P[1:]):
        for q in a + np.linspace(0, 1, 400)[:, None] * (b - a):
            model.update_cfg(dict(zip(joints, q)))
            for link, shape, origin in objects:
                T = model.get_transform(link) @ origin
                obj = coal.CollisionObject(shape, coal.Transform3s(T[:3, :3], T[:3, 3]))
                res = coal.DistanceResult()
                coal.distance(obj, box, coal.DistanceRequest(), res)
                worst = min(worst, res.min_distance)
    assert worst > 0, f"coal finds the exported robot {worst} m from the box"
    assert worst == pytest.approx(c["min_clearance"], abs=2e-3)


def test_a_wrist_folded_into_the_base_names_both_links(capsys):
    """`rmt clearance` on a configuration that folds the wrist down into the base: exit 1 and one line
    naming the two bodies; coal agrees that those two bodies' capsules overlap."""
    from kin.geometry import body_frames
    q = ["-29", "108", "-41", "64", "-24", "-169"]
    rc, out, _ = _run(["clearance", "fanuc_lrmate200id", *q, "--json"], capsys)
    d = json.loads(out)
    assert rc == 1 and not d["clear"] and d["clearance"] < 0
    assert {d["body"], d["other"]} == {"base", "link 5 (J5)"}
    robot = kin.load_robot("fanuc_lrmate200id")
    F = body_frames(robot.chain, robot.chain.to_si(np.array([float(x) for x in q]))[None])[0]

    def objects(body):
        out = []
        for c in robot.geometry.capsules:
            if c.body == body:
                a, b = (F[body] @ [*c.a, 1])[:3], (F[body] @ [*c.b, 1])[:3]
                L = float(np.linalg.norm(b - a))
                z = (b - a) / L if L > 0 else np.array([0.0, 0.0, 1.0])
                x = np.cross(z, [1.0, 0, 0]) if abs(z[0]) < 0.9 else np.cross(z, [0, 1.0, 0])
                x /= np.linalg.norm(x)
                R = np.column_stack([x, np.cross(z, x), z])
                out.append(coal.CollisionObject(coal.Capsule(c.radius, L), coal.Transform3s(R, 0.5 * (a + b))))
        return out

    deepest = min(_coal_distance(a, b) for a in objects(0) for b in objects(5))
    assert deepest < 0 and deepest == pytest.approx(d["clearance"], abs=1e-4)


def _coal_distance(a, b) -> float:
    req = coal.DistanceRequest()
    req.enable_signed_distance = True
    res = coal.DistanceResult()
    coal.distance(a, b, req, res)
    return res.min_distance
