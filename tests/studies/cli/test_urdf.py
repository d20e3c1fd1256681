"""``rmt import-urdf`` and ``rmt export-urdf`` end to end: files written, the imported robot's FK
against yourdfpy's model of the same URDF, exit code 2 and one line on bad input."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from studies.cli import main
from tests.dh_numpy import fk_numpy
from tests.kin.urdf.reference import YourdfpyFk, erd_urdf


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_import_ur5_then_show_and_fk(capsys, tmp_path, convention):
    urdf = erd_urdf("ur_description/urdf/ur5_robot.urdf")
    out = tmp_path / "ur5.toml"
    code, text, err = run(capsys, "import-urdf", urdf, "--tip", "tool0", "--convention", convention,
                          "--capsules-per-mesh", "1", "--out", out, "--json")
    assert code == 0 and err == ""
    info = json.loads(text)
    assert (info["joints"], info["convention"], info["name"]) == (6, convention, "ur5")
    assert info["capsules"] == 8 and 0 < info["over_estimate"] < 0.1          # 7 meshes and a box, one each
    assert kin.load_chain(out).geometry.over_estimate == pytest.approx(info["over_estimate"], rel=1e-12)
    code, text, _ = run(capsys, "fk", out, "0.1", "-0.5", "0.7", "0.2", "1.1", "-0.3", "--json")
    assert code == 0
    ref = YourdfpyFk(urdf, "world", "tool0")
    T = ref(kin.load_chain(out).joint_names(), [0.1, -0.5, 0.7, 0.2, 1.1, -0.3])
    np.testing.assert_allclose(json.loads(text)["T"], T, atol=1e-12)
    assert run(capsys, "show", out)[0] == 0


def test_import_without_collision_geometry(capsys, tmp_path):
    urdf = erd_urdf("ur_description/urdf/ur5_robot.urdf")
    code, text, err = run(capsys, "import-urdf", urdf, "--tip", "tool0", "--no-collision", "--out", tmp_path / "x.toml")
    assert code == 0 and err == "" and "collision geometry" not in text
    assert kin.load_chain(tmp_path / "x.toml").geometry is None


def test_import_without_tip_lists_the_leaves(capsys, tmp_path):
    urdf = erd_urdf("ur_description/urdf/ur5_robot.urdf")
    code, out, err = run(capsys, "import-urdf", urdf, "--out", tmp_path / "x.toml")
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "choose the tip link (--tip) from: ee_link, tool0, base" in err


def test_export_then_import_round_trip(capsys, tmp_path):
    urdf = tmp_path / "fanuc.urdf"
    code, out, err = run(capsys, "export-urdf", "fanuc_m16ib20", "--out", urdf)
    assert code == 0 and err == "" and "6 joints" in out and "collision capsules" in out
    code, _, _ = run(capsys, "import-urdf", urdf, "--tip", "tool", "--out", tmp_path / "back.toml")
    assert code == 0
    chain, back = kin.load_chain("fanuc_m16ib20"), kin.load_chain(tmp_path / "back.toml")
    for q in np.random.default_rng(3).uniform(chain.lower, chain.upper, size=(20, 6)):
        np.testing.assert_allclose(fk_numpy(back, q), fk_numpy(chain, q), atol=1e-12)


@pytest.mark.parametrize("argv, message", [
    (["import-urdf", "{tmp}/none.urdf", "--out", "{tmp}/x.toml"], "none.urdf: no such file"),
    (["import-urdf", "{tmp}/bad.urdf", "--out", "{tmp}/x.toml"], "bad.urdf: robot: not a readable URDF"),
    (["import-urdf", "{tmp}/bad.urdf", "--out", "{tmp}/x.json"], "--out '{tmp}/x.json' must end in .toml"),
    (["export-urdf", "puma560", "--out", "{tmp}/no/dir.urdf"], "directory '{tmp}/no' does not exist"),
    (["export-urdf", "no_such_robot", "--out", "{tmp}/x.urdf"], "unknown robot 'no_such_robot'"),
    (["import-urdf", "{tmp}/bad.urdf", "--convention", "craig", "--out", "{tmp}/x.toml"], "invalid choice: 'craig'"),
    (["import-urdf", "{tmp}/bad.urdf", "--package", "pkg", "--out", "{tmp}/x.toml"],
     "--package 'pkg' must be NAME=DIR"),
    (["import-urdf", "{tmp}/bad.urdf", "--package", "pkg={tmp}/none", "--out", "{tmp}/x.toml"],
     "--package 'pkg={tmp}/none': directory '{tmp}/none' does not exist"),
    (["import-urdf", "{tmp}/mesh.urdf", "--out", "{tmp}/x.toml"],
     "mesh.urdf: link 'b' collision 0 mesh 'package://pkg/m.stl': package 'pkg' is neither a directory above"),
])
def test_bad_input_exits_2_with_one_line(capsys, tmp_path, argv, message):
    (tmp_path / "bad.urdf").write_text("<robot")
    (tmp_path / "mesh.urdf").write_text(
        '<robot name="m"><link name="a"/><link name="b"><collision><geometry><mesh filename="package://pkg/m.stl"/>'
        '</geometry></collision></link><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    code, out, err = run(capsys, *[a.format(tmp=tmp_path) for a in argv])
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and message.format(tmp=tmp_path) in err, err
