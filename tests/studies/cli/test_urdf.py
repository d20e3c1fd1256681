"""``rmt import-urdf`` and ``rmt export-urdf`` end to end: files written, the imported robot's FK
against yourdfpy's model of the same URDF, warnings as ``rmt: warning:`` lines, exit code 2 and one
line on bad input."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from studies.cli import main
from tests.dh_numpy import fk_numpy
from tests.kin.urdf.reference import YourdfpyFk, erd_urdf, mbm_urdf


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
    (["export-urdf", "puma560", "--out", "{tmp}/bad.urdf/dir.urdf"], "{tmp}/bad.urdf is not a directory"),
    (["import-urdf", "{tmp}/far.urdf", "--out", "{tmp}/bad.urdf/x.toml"], "{tmp}/bad.urdf is not a directory"),
    (["export-urdf", "no_such_robot", "--out", "{tmp}/x.urdf"], "unknown robot 'no_such_robot'"),
    (["import-urdf", "{tmp}/bad.urdf", "--convention", "craig", "--out", "{tmp}/x.toml"], "invalid choice: 'craig'"),
    (["import-urdf", "{tmp}/bad.urdf", "--package", "pkg", "--out", "{tmp}/x.toml"],
     "--package 'pkg' must be NAME=DIR"),
    (["import-urdf", "{tmp}/bad.urdf", "--package", "pkg={tmp}/none", "--out", "{tmp}/x.toml"],
     "--package 'pkg={tmp}/none': directory '{tmp}/none' does not exist"),
    (["import-urdf", "{tmp}/mesh.urdf", "--out", "{tmp}/x.toml"],
     "mesh.urdf: link 'b' collision 0 mesh 'package://pkg/m.stl': package 'pkg' is neither a directory above"),
    (["import-urdf", "{tmp}/far.urdf", "--out", "{tmp}/x.toml"],
     "far.urdf: joint 'j': its <origin> xyz [1e+300, 0.0, 0.0] reaches 1e+300 m; allowed: at most 10000 m (10 km)"),
    (["import-urdf", "{tmp}/slow.urdf", "--out", "{tmp}/x.toml"],
     "slow.urdf: joint 'j': <limit> velocity = -1; allowed: a finite number ≥ 0 (rad/s; 0: unknown)"),
])
def test_bad_input_exits_2_with_one_line(capsys, tmp_path, argv, message):
    (tmp_path / "bad.urdf").write_text("<robot")
    for name, origin, velocity in (("far", "1e300 0 0", "1"), ("slow", "0 0 0", "-1")):
        (tmp_path / f"{name}.urdf").write_text(
            f'<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute"><parent link="a"/>'
            f'<child link="b"/><origin xyz="{origin}"/><limit lower="-1" upper="1" effort="1" velocity="{velocity}"/>'
            '</joint></robot>')
    (tmp_path / "mesh.urdf").write_text(
        '<robot name="m"><link name="a"/><link name="b"><collision><geometry><mesh filename="package://pkg/m.stl"/>'
        '</geometry></collision></link><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    code, out, err = run(capsys, *[a.format(tmp=tmp_path) for a in argv])
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and message.format(tmp=tmp_path) in err, err


def test_robowflex_panda_imports_with_a_warning_per_placeholder(capsys, tmp_path):
    """MotionBenchMaker's Panda: two massless links with placeholder tensors are warned about (one line each,
    naming the link), the tip defaults to the hand every leaf hangs from, and the file loads."""
    urdf = mbm_urdf("panda")
    out = tmp_path / "panda.toml"
    code, text, err = run(capsys, "import-urdf", urdf, "--out", out)
    assert code == 0
    lines = err.splitlines()
    # its visual mesh files are not shipped with it: one line for them all (the bodies drawn as capsules)
    lines, visual = [ln for ln in lines if "visual meshes left out" not in ln], \
        [ln for ln in lines if "visual meshes left out" in ln]
    assert len(visual) == 1 and "drawn as the bodies' capsules" in visual[0]
    assert len(lines) == 2 and all(line.startswith(f"rmt: warning: {urdf}: link '") for line in lines)
    assert "'panda_link8' inertial: mass 0" in lines[0] and "'panda_grasptarget' inertial: mass 0" in lines[1]
    assert "tip 'panda_hand': the link that all 3 leaves hang from" in text
    code, shown, _ = run(capsys, "show", out)
    assert code == 0
    assert "placeholder inertials (mass 0 with a tensor) left out: panda_link8, panda_grasptarget" in shown


def test_thorough_search_encloses_the_mesh(capsys, tmp_path):
    """--thorough (every cut scored exactly) on an L-shaped bar: the capsules hold all of its corners."""
    import trimesh
    from shapely.geometry import Polygon
    bar = trimesh.creation.extrude_polygon(Polygon([(0, 0), (0.3, 0), (0.3, 0.06), (0.06, 0.06), (0.06, 0.3),
                                                    (0, 0.3)]), 0.06)
    bar.export(str(tmp_path / "bar.stl"))
    (tmp_path / "bar.urdf").write_text(
        '<robot name="bar"><link name="a"/><link name="b"><collision><geometry><mesh filename="bar.stl"/></geometry>'
        '</collision></link><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<origin xyz="0 0 0.1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    code, text, err = run(capsys, "import-urdf", tmp_path / "bar.urdf", "--thorough", "--out", tmp_path / "bar.toml",
                          "--json")
    assert code == 0 and err == "" and json.loads(text)["capsules"] >= 2
    chain = kin.load_chain(tmp_path / "bar.toml")
    from kin.geometry import body_frames
    from kin.geometry.enclose import segment_distance
    F = body_frames(chain, [0.0])[0][1]
    P = np.asarray(bar.vertices) + [0, 0, 0.1]
    inside = np.min([segment_distance(P, F[:3, :3] @ c.a + F[:3, 3], F[:3, :3] @ c.b + F[:3, 3]) - c.radius
                     for c in chain.geometry.capsules], axis=0)
    assert inside.max() <= 1e-9
