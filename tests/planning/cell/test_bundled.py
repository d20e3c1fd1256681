"""The bundled FANUC LR Mate 200iD weld cell (studies/cells/): it reads, it ties to the robot, its part
is the mesh the file describes, the robot stands clear of everything it is checked against at home
and at a welding pose (an independent numpy check), and docs/cells.md shows it as it is."""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
import trimesh

import kin
from kin.geometry import body_frames
from planning.cell import load_cell, parse_cell

ROOT = Path(__file__).resolve().parents[3]
CELL = ROOT / "studies" / "cells" / "fanuc_weld_cell.toml"


@pytest.fixture(scope="module")
def robot():
    return kin.load_robot("fanuc_lrmate200id")


@pytest.fixture(scope="module")
def resolved(robot):
    return load_cell(CELL).resolve(robot)


def weld_part() -> trimesh.Trimesh:
    """How studies/cells/weld_part.stl was made (mm): a pipe r 40/50 × 250 along z, a flange r 50/90 × 12
    at its −z end."""
    pipe = trimesh.creation.annulus(40, 50, 250, sections=32)
    flange = trimesh.creation.annulus(50, 90, 12, sections=32)
    flange.apply_translation([0, 0, -119])
    return trimesh.util.concatenate([pipe, flange])


def test_the_part_is_the_mesh_described():
    shipped = trimesh.load_mesh(CELL.parent / "weld_part.stl")
    made = weld_part()
    assert len(shipped.faces) == len(made.faces) == 512
    assert shipped.bounds == pytest.approx(made.bounds, abs=1e-4)
    assert shipped.area == pytest.approx(made.area, rel=1e-6) and shipped.volume == pytest.approx(made.volume, rel=1e-6)


def test_the_cell_reads_and_ties_to_the_robot(resolved, robot):
    cell = resolved.cell
    assert cell.name == "FANUC LR Mate 200iD weld cell" and cell.base[:3, 3] == pytest.approx([0, 0, 0.8])
    assert [o.name for o in cell.obstacles] == ["table", "fixture", "part", "wire feeder column", "rear fence",
                                                "floor"]
    part = resolved.obstacles[2]
    assert part.kind == "mesh" and part.ignore == {robot.n + 1} and part.over_estimate <= 0.0101
    assert len(part.spheres) <= 3000
    assert resolved.obstacles[0].ignore == {0, 1}
    assert (5, robot.n + 1) in resolved.geometry.allowed
    # the pipe lies on the fixture, along y: its spheres span the part's extent, give or take the over-estimate
    lo = (part.spheres[:, :3] - part.spheres[:, 3:]).min(0)
    hi = (part.spheres[:, :3] + part.spheres[:, 3:]).max(0)
    assert lo == pytest.approx([0.46, -0.125, 0.86], abs=0.011) and hi == pytest.approx([0.64, 0.125, 1.04], abs=0.011)


# ---- an independent clearance check: capsule samples against the primitives, in numpy ---------------
def _shape_distance(shape, P: np.ndarray) -> np.ndarray:
    L = (P - shape.pose[:3, 3]) @ shape.pose[:3, :3]          # points in the shape's frame
    a, b, c = shape.size
    if shape.kind == "box":
        q = np.abs(L) - [a, b, c]
        return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)
    if shape.kind == "cylinder":
        q = np.column_stack([np.hypot(L[:, 0], L[:, 1]) - a, np.abs(L[:, 2]) - b])
        return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)
    raise AssertionError(shape.kind)


def _clearances(resolved, robot, q) -> dict[tuple[str, str], float]:
    F = body_frames(robot.chain, q, base=resolved.base)[0]
    names = resolved.body_names
    out = {}
    for cap in resolved.geometry.capsules:
        t = np.linspace(0, 1, max(2, int(cap.length / 0.002) + 1))[:, None]
        local = np.asarray(cap.a) * (1 - t) + np.asarray(cap.b) * t
        P = local @ F[cap.body][:3, :3].T + F[cap.body][:3, 3]
        for ob in resolved.obstacles:
            if cap.body in ob.ignore:
                continue
            if ob.spheres is not None:
                d = np.linalg.norm(P[:, None] - ob.spheres[None, :, :3], axis=2) - ob.spheres[None, :, 3]
                d = d.min(axis=1)
            else:
                d = np.min([_shape_distance(s, P) for s in ob.shapes], axis=0)
            key = (names[cap.body], ob.name)
            out[key] = min(out.get(key, np.inf), float(d.min()) - cap.radius)
    return out


def _weld_pose(robot, resolved):
    """The torch's neck end 5 mm above the top of the pipe, the torch pointing down."""
    tip = np.array([0, 0.040, 0.310])
    R = np.diag([1.0, -1.0, -1.0])
    target = np.array([0.55, 0.0, 1.005])
    T = np.linalg.inv(resolved.base) @ np.block([[R, (target - R @ tip)[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]])
    sol = robot.ik(T)
    assert sol.success
    return sol.q


def test_the_robot_is_clear_at_home_and_welding(resolved, robot):
    for q in (np.zeros(robot.n), _weld_pose(robot, resolved)):
        clear = _clearances(resolved, robot, q)
        worst = min(clear, key=clear.get)
        assert clear[worst] > 0.005, (q, worst, clear[worst])
    # welding, the torch is where the part is: a few mm from its spheres
    F = body_frames(robot.chain, _weld_pose(robot, resolved), base=resolved.base)[0]
    tip = F[-1][:3, :3] @ [0, 0.040, 0.310] + F[-1][:3, 3]
    S = resolved.obstacles[2].spheres
    assert (np.linalg.norm(S[:, :3] - tip, axis=1) - S[:, 3]).min() < 0.005


def test_the_docs_show_the_bundled_cell():
    page = (ROOT / "docs" / "cells.md").read_text()
    blocks = re.findall(r"^```toml\n(.*?)^```", page, re.M | re.S)
    assert CELL.read_text() in blocks, "docs/cells.md shows studies/cells/fanuc_weld_cell.toml as it is"
    parse_cell(CELL.read_text(), "docs", CELL.parent)


def test_the_cell_is_packaged():
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["studies"]
    assert "cells/*.toml" in data and "cells/*.stl" in data
