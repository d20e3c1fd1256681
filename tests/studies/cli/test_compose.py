"""``rmt compose``: the least-cost assembly of the small test catalogue for a part (the same as the
brute-force enumeration of tests/design/compose finds), its accounting and verification printed, the
robot file and compose.json written (the robot's FK is the modules' product); exit 1 when nothing
serves the part, 2 on bad input with one line."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from kin.modules import Assembly, module_frames
from studies.cli import main
from tests.design.compose import compose_helpers as h

NEAR = [[10, 60, 60], [-60, 90, -45], [120, -70, -30], [-150, 45, 90]]
FAST = ["--joints", "3", "--links-per-joint", "0", "--starts", "4", "--samples", "1024"]


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _part(tmp_path, points_m, name="bracket", extra=""):
    rows = "\n".join(",".join(f"{1000 * v:.6f}" for v in p) for p in points_m)
    (tmp_path / f"{name}.csv").write_text("x,y,z\n" + rows + "\n")
    path = tmp_path / f"{name}.toml"
    path.write_text(f'name = "{name}"\nlength_unit = "mm"\nangle_unit = "deg"\n{extra}'
                    f'[target]\nshape = "points"\nfile = "{name}.csv"\ntolerance = 0.01\n')
    return path


@pytest.fixture(scope="module")
def cat():
    return h.catalogue()


def test_compose_prints_the_least_cost_assembly(capsys, tmp_path, cat):
    part = _part(tmp_path, h.targets_of(cat, "B Rz Ry Ry", NEAR).positions)
    out_dir = tmp_path / "out"
    code, out, err = run(capsys, "compose", h.CATALOGUE, part, *FAST, "--out", out_dir)
    assert code == 0, err
    lines = out.splitlines()
    assert "least cost: 3500 EUR, 3 joints: B Rz Ry Rw" in lines
    assert "  part bracket: reached 4/4" in lines
    assert any(x.startswith("space 9 assemblies (64 module sequences") for x in lines)
    assert any(x.startswith("exhaustive: every assembly cheaper than the answer") for x in lines)
    assert any(x.startswith("verified: part bracket: reached 4/4 with 8 starts among 4096 samples") for x in lines)
    assert err.startswith("compose: batch 1 (exhaustive)")
    # the robot file: its FK is the modules' product
    robot = kin.load_robot(out_dir / "compose_test_composed.toml")
    a = Assembly.parse("B Rz Ry Rw", cat)
    for q in np.radians([[10, 20, 30], [-100, 50, -70]]):
        assert np.allclose(robot.fk(q), module_frames(cat, a, q)[-1][1], atol=1e-12)
    report = json.loads((out_dir / "compose.json").read_text())
    assert report["best"] == "B Rz Ry Rw" and report["cost"] == 3500 and report["exhaustive"]
    assert report["files"]["robot"].endswith("compose_test_composed.toml")


def test_compose_json(capsys, tmp_path, cat):
    part = _part(tmp_path, h.targets_of(cat, "B Rz Ry Ry", NEAR).positions)
    code, out, _ = run(capsys, "compose", h.CATALOGUE, part, *FAST, "--json")
    assert code == 0
    d = json.loads(out)
    c = d["counts"]
    assert d["best"] == "B Rz Ry Rw" and c["total"] == 9
    assert sum(c[k] for k in ("dof", "reach_bound", "holding", "evaluated", "not_cheaper", "not_judged")) == 9
    assert d["assemblies"][0]["verdicts"]["bracket"]["stage"] == "ok"
    assert d["verification"][0]["ok"]


def test_nothing_serves_the_part_exits_1(capsys, tmp_path):
    part = _part(tmp_path, [[3.0, 0.0, 0.5]], name="far")
    code, out, _ = run(capsys, "compose", h.CATALOGUE, part, *FAST)
    assert code == 1 and "no feasible assembly in the space" in out


@pytest.mark.parametrize("args, message", [
    (["--joints", "0-3"], "--joints: 0-3 must satisfy 1 ≤ LO ≤ HI ≤ 8"),
    (["--joints", "three"], "--joints: 'three' is not N or LO-HI"),
    (["--tool", "hammer"], "tools: 'hammer' is not a tool module"),
    (["--base", "Rz"], "bases: 'Rz' is not a base module"),
    (["--budget", "0"], "--budget"),
    (["--starts", "32", "--samples", "16"], "samples = 16 must be ≥ starts = 32"),
])
def test_bad_options_exit_2_with_one_line(capsys, tmp_path, cat, args, message):
    part = _part(tmp_path, h.targets_of(cat, "B Rz Ry Ry", NEAR).positions)
    code, out, err = run(capsys, "compose", h.CATALOGUE, part, *args)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err


def test_bad_files_exit_2_with_one_line(capsys, tmp_path, cat):
    part = _part(tmp_path, h.targets_of(cat, "B Rz Ry Ry", NEAR).positions)
    with_robot = tmp_path / "robot.toml"
    with_robot.write_text(part.read_text().replace('name = "bracket"', 'name = "r"\nrobot = "ur5e"'))
    for argv, message in (([h.CATALOGUE, tmp_path / "none.toml"], "no such part file"),
                          ([tmp_path / "cat.toml", part], "cat.toml"),
                          ([h.CATALOGUE, with_robot], "robot.toml: robot: a part file names no robot"),
                          ([h.CATALOGUE, part, part], "two part files are named 'bracket'")):
        code, _, err = run(capsys, "compose", *argv)
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
