"""Issue 30: every robot file ``rmt import-urdf`` writes is one its own reader loads — written to a hidden
sibling, read back with :func:`kin.load_chain`, then renamed; a refusal is one line naming the URDF and
the field, exit 2, and leaves nothing behind.  ``--out`` makes missing parent directories, as every
command's does (:func:`kin.output.write_output`)."""
from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

import kin
import kin.robotfile
from studies.cli import main
from tests.dh_numpy import fk_numpy
from tests.kin.urdf.reference import YourdfpyFk
from tests.kin.urdf.synthetic import serial, urdf_text, write_urdf

ARM = [("revolute", (0, 0, 0.1), (0, 0, 0), (0, 0, 1)), ("revolute", (0, 0, 0.3), (1.2, 0, 0), (0, 0, 1)),
       ("fixed", (0, 0.1, 0.1), (0, 0, 0), (0, 0, 1))]


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def files_under(d):
    return sorted(str(p.relative_to(d)) for p in d.rglob("*"))


def test_out_into_missing_directories_makes_them(capsys, tmp_path):
    urdf = write_urdf(tmp_path, serial(ARM), "arm")
    out = tmp_path / "new" / "deeper" / "arm.toml"
    code, text, err = run(capsys, "import-urdf", urdf, "--no-collision", "--out", out)
    assert code == 0 and err == "" and f"written to {out}" in text
    chain = kin.load_chain(out)
    q = [0.4, -1.1]
    ref = YourdfpyFk(urdf, "l0", "l3")(chain.joint_names(), q)
    np.testing.assert_allclose(fk_numpy(chain, q), ref, atol=1e-12)
    assert files_under(tmp_path) == ["arm.urdf", "new", "new/deeper", "new/deeper/arm.toml"]


def test_a_file_the_reader_refuses_is_never_kept(capsys, tmp_path, monkeypatch):
    """The text written is read back from the file: a writer that emitted a unit the reader does not know
    (simulated) is one line naming the URDF and the field; no file, no hidden sibling, no directory made."""
    urdf = write_urdf(tmp_path, serial(ARM), "arm")
    real = kin.robotfile.dumps_robot
    monkeypatch.setattr(kin.robotfile, "dumps_robot",
                        lambda chain, *a: real(chain, *a).replace('length_unit = "m"', 'length_unit = "furlong"'))
    before = files_under(tmp_path)
    code, text, err = run(capsys, "import-urdf", urdf, "--no-collision", "--out", tmp_path / "made" / "arm.toml")
    lines = err.strip().splitlines()
    assert code == 2 and text == "" and len(lines) == 1, err
    assert lines[0].startswith(f"rmt: error: {urdf}: the robot file made of it is refused by the robot-file reader "
                               "(length_unit: "), lines[0]
    assert files_under(tmp_path) == before


def _mesh_urdf(tmp_path, extent: float):
    box = trimesh.creation.box()
    with np.errstate(all="ignore"):
        trimesh.Trimesh(vertices=np.sign(box.vertices) * extent, faces=box.faces, process=False).export(
            tmp_path / "huge.stl")
    text = urdf_text(serial(ARM), "hugemesh").replace(
        '<link name="l1"/>', '<link name="l1"><collision><geometry><mesh filename="huge.stl"/></geometry>'
                             '</collision></link>')
    (tmp_path / "hugemesh.urdf").write_text(text)
    return tmp_path / "hugemesh.urdf"


def _sphere_urdf(tmp_path, radius: float):
    text = urdf_text(serial(ARM), "ball").replace(
        '<link name="l2"/>', f'<link name="l2"><collision><geometry><sphere radius="{radius!r}"/></geometry>'
                             '</collision></link>')
    (tmp_path / "ball.urdf").write_text(text)
    return tmp_path / "ball.urdf"


def _velocity_urdf(tmp_path, v: float):
    joints = serial(ARM)
    joints[1]["velocity"] = v
    return write_urdf(tmp_path, joints, "fast")


@pytest.mark.parametrize("make, where, allowed", [
    (lambda d: write_urdf(d, serial([("revolute", (0, 0, 1e300), (0, 0, 0), (0, 0, 1))] + ARM[1:]), "far"),
     "joint 'j1'", "allowed: at most 10000 m (10 km)"),
    (lambda d: _mesh_urdf(d, 3e38), "link 'l1' collision 0 mesh 'huge.stl'", "allowed: at most 10000 m (10 km)"),
    (lambda d: _sphere_urdf(d, 4e37), "link 'l2' collision 0", "allowed: 1e-09 to 10000 m"),
    (lambda d: _velocity_urdf(d, -1.0), "joint 'j2'", "<limit> velocity = -1; allowed: a finite number ≥ 0"),
])
def test_values_no_robot_file_holds_are_one_line(capsys, tmp_path, make, where, allowed):
    urdf = make(tmp_path)
    before = files_under(tmp_path)
    code, text, err = run(capsys, "import-urdf", urdf, "--out", tmp_path / "out" / "x.toml")
    lines = err.strip().splitlines()
    assert code == 2 and text == "" and len(lines) == 1, err
    assert lines[0].startswith(f"rmt: error: {urdf}: {where}: ") and allowed in lines[0], lines[0]
    assert files_under(tmp_path) == before


def test_rounding_noise_of_the_urdf_is_written_as_zero(capsys, tmp_path):
    """π/2 written to 11 digits (robowflex's Panda) makes d = −1.5e-12 m, which no robot file holds: written
    as 0, and the file loads with FK equal to the URDF's within that."""
    q = 1.57079632679
    urdf = write_urdf(tmp_path, serial([("revolute", (0, 0, 0.333), (0, 0, 0), (0, 0, 1)),
                                        ("revolute", (0, 0, 0), (-q, 0, 0), (0, 0, 1)),
                                        ("revolute", (0, -0.316, 0), (q, 0, 0), (0, 0, 1)),
                                        ("revolute", (0.0825, 0, 0), (q, 0, 0), (0, 0, 1)),
                                        ("fixed", (0, 0, 0.1), (0, 0, 0), (0, 0, 1))]), "rounded")
    out = tmp_path / "rounded.toml"
    code, text, err = run(capsys, "import-urdf", urdf, "--no-collision", "--out", out)
    assert code == 0 and err == ""
    chain = kin.load_chain(out)
    table = chain.dh_table()[:, [0, 2]].ravel()
    assert all(v == 0.0 or abs(v) >= 1e-9 for v in table)
    qs = [0.3, -0.7, 1.1, 0.2]
    noise = (math.pi / 2 - q) * 0.316
    np.testing.assert_allclose(fk_numpy(chain, qs), YourdfpyFk(urdf, "l0", "l5")(chain.joint_names(), qs),
                               atol=10 * noise)
