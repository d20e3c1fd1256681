"""Issue 32: ``rmt assemble`` writes the robot of an assembly of catalogue modules and says what it is
(the assembly, its cost, the DH table, its mass, whether every joint holds the rest of the chain at rest);
``rmt export-urdf`` of that file works; a joint that provably cannot hold a heavy tool exits 1 and
writes nothing, unless ``--no-holding-check``.  ``rmt modules`` lists a catalogue's connectors and
modules with their key numbers.  Checked against the catalogue's plain numbers (tomllib) and the
plain product of the modules' transforms (tests/kin/modules/plain.py)."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from studies.cli import main
from tests.dh_numpy import fk_numpy
from tests.kin.modules.plain import FIXTURE, Plain

ARM = "stand R80 L200@90 E80 L300b@180 P80 A80_63 R63@180 grip63"
HEAVY = "wall A80_63 R63 L63 heavy"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def plain():
    return Plain(FIXTURE)


def _all_parts_mass(plain, names):
    return sum(plain.mod[n].get(k, {}).get("mass", 0.0) for n in names for k in ("inertial", "distal_inertial"))


def test_assemble_writes_the_robot_and_says_what_it_is(capsys, tmp_path, plain):
    out = tmp_path / "cells" / "My-Arm.toml"          # parents made; the name from the file's
    code, text, err = run(capsys, "assemble", FIXTURE, "--modules", *ARM.split(), "--out", out)
    assert code == 0 and err == "", err
    names = plain.parse(ARM.split())[0]
    cost = sum(plain.mod[n]["cost"] for n in names)
    lines = text.splitlines()
    assert lines[0] == f"my_arm: {ARM} (catalogue fixture_modules)"
    assert lines[1] == f"cost: {cost:g} EUR"
    assert lines[2] == "4 joints (RRPR), standard DH, lengths in mm, angles in deg:"
    assert f"mass: {_all_parts_mass(plain, names):.6g} kg in all" in text
    assert [ln.split()[3] for ln in lines if ln.startswith("  joint ")] == ["holds"] * 4
    assert "[0, 300] mm" in text and "1500 N" in text and "[-170, 170] deg" in text
    assert lines[-1] == f"written to {out}; see it with: rmt show {out}"
    chain = kin.load_chain(out)
    assert chain.name == "my_arm" and (chain.length_unit, chain.angle_unit) == ("mm", "deg")
    rng = np.random.default_rng(3)
    lim = plain.limits(ARM.split())
    for qf in rng.uniform(lim[:, 0], lim[:, 1], size=(5, 4)):
        np.testing.assert_allclose(fk_numpy(chain, chain.to_si(qf)), plain.tip(ARM.split(), qf), atol=1e-12)
    # the DH table printed is the file's
    rows = [ln.split() for ln in lines[4:8]]
    np.testing.assert_allclose([float(r[4]) for r in rows], [j.d / 1e-3 for j in chain.joints], rtol=1e-5, atol=1e-4)


def test_export_urdf_of_an_assembled_robot_has_its_kinematics(capsys, tmp_path, plain):
    """The URDF read back by rmtkit's own URDF import has the modules' FK."""
    from kin.urdf import import_urdf
    robot_file, urdf = tmp_path / "arm.toml", tmp_path / "arm.urdf"
    assert run(capsys, "assemble", FIXTURE, "--modules", *ARM.split(), "--out", robot_file)[0] == 0
    code, text, err = run(capsys, "export-urdf", robot_file, "--out", urdf)
    assert code == 0 and err == "" and "4 joints written to" in text
    chain = import_urdf(str(urdf), collision=False)
    lim = plain.limits(ARM.split())
    for qf in np.random.default_rng(4).uniform(lim[:, 0], lim[:, 1], size=(5, 4)):
        scale = np.array([np.pi / 180, np.pi / 180, 1e-3, np.pi / 180])
        np.testing.assert_allclose(fk_numpy(chain, qf * scale), plain.tip(ARM.split(), qf), atol=1e-12)


def test_assemble_json(capsys, tmp_path, plain):
    code, text, err = run(capsys, "assemble", FIXTURE, "--modules", *ARM.split(), "--out", tmp_path / "a.toml",
                          "--name", "cell_arm", "--json")
    assert code == 0 and err == ""
    d = json.loads(text)
    names = plain.parse(ARM.split())[0]
    assert d["written"] is True and d["refused"] is None and d["name"] == "cell_arm"
    assert d["assembly"] == ARM and d["modules"] == names and d["currency"] == "EUR"
    assert d["cost"] == sum(plain.mod[n]["cost"] for n in names)
    assert d["mass_kg"]["total"] == pytest.approx(_all_parts_mass(plain, names))
    assert d["mass_kg"]["tool"] == plain.mod["grip63"]["inertial"]["mass"]
    assert [h["verdict"] for h in d["holding"]] == ["holds"] * 4
    assert [h["max_torque"] for h in d["holding"]] == [m["max_torque"] for m in plain.joints(ARM.split())]
    np.testing.assert_allclose([r["limits"] for r in d["joints"]], plain.limits(ARM.split()), rtol=1e-14)
    assert all(h["bound"] + 1e-12 >= h["witness"] >= 0 for h in d["holding"])     # to rounding of a 0 torque
    assert kin.load_chain(tmp_path / "a.toml").name == "cell_arm"


def test_a_joint_that_cannot_hold_the_tool_is_refused_in_one_line(capsys, tmp_path):
    out = tmp_path / "h.toml"
    code, text, err = run(capsys, "assemble", FIXTURE, "--modules", *HEAVY.split(), "--out", out)
    assert code == 1 and text == "" and err.count("\n") == 1, err
    assert err.startswith("rmt assemble: joint 1 (j1_r63) cannot hold the rest of the chain at rest") and "8 N·m" in err
    assert not out.exists()
    code, text, err = run(capsys, "assemble", FIXTURE, "--modules", *HEAVY.split(), "--out", out, "--json")
    d = json.loads(text)
    assert code == 1 and d["written"] is False and "j1_r63" in d["refused"] and not out.exists()
    assert d["holding"][0]["verdict"] == "fails" and d["holding"][0]["witness"] > d["holding"][0]["max_torque"]


def test_no_holding_check_writes_it_and_says_the_failure(capsys, tmp_path):
    out = tmp_path / "h.toml"
    code, text, err = run(capsys, "assemble", FIXTURE, "--modules", *HEAVY.split(), "--out", out,
                          "--no-holding-check")
    assert code == 0 and out.exists()
    assert "joint 1 (j1_r63): fails" in text
    assert err.count("\n") == 1 and "warning" in err and "j1_r63" in err and "--no-holding-check" in err
    assert kin.load_chain(out).payload.mass == 20


@pytest.mark.parametrize("argv, words", [
    (["--out", "arm.urdf"], "--out 'arm.urdf' must end in .toml"),
    (["--out", "d.toml"], "d.toml: is a directory"),
    (["--out", "a.toml", "--name", "Bad Name"], "--name 'Bad Name' must match [a-z0-9_]+"),
])
def test_bad_options_are_one_line(capsys, tmp_path, monkeypatch, argv, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "d.toml").mkdir()
    code, text, err = run(capsys, "assemble", FIXTURE, "--modules", "stand", "R80", *argv)
    assert code == 2 and text == "" and err.count("\n") == 1 and words in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]


def test_modules_lists_connectors_and_modules_per_kind(capsys, plain):
    code, text, err = run(capsys, "modules", FIXTURE)
    assert code == 0 and err == ""
    lines = text.splitlines()
    assert "  F63       twists 0, 180" in lines and "  F80_tool  twists 0, 90, 180, 270  (meets as F80)" in lines
    heads = [ln for ln in lines if ln in ("bases:", "joints:", "links:", "tools:")]
    assert heads == ["bases:", "joints:", "links:", "tools:"]
    for kind, head in (("base", "bases:"), ("joint", "joints:"), ("link", "links:"), ("tool", "tools:")):
        start = lines.index(head) + 1
        block = []
        for ln in lines[start:]:
            if not ln.startswith("  "):
                break
            block.append(ln.split()[0])
        assert block == [m["name"] for m in plain.doc["modules"] if m["kind"] == kind]
    r63 = next(ln for ln in lines if ln.split()[0] == "R63")
    assert "2100" in r63 and "8 N·m" in r63 and "[-180, 180] deg" in r63 and "length 75 mm" in r63


def test_modules_json_has_the_catalogues_numbers(capsys, plain):
    code, text, _ = run(capsys, "modules", FIXTURE, "--json")
    d = json.loads(text)
    assert code == 0 and d["name"] == "fixture_modules" and d["units"] == {"length": "mm", "angle": "deg"}
    assert {c["name"]: c["twists"] for c in d["connectors"]} == {"F80": [0, 90, 180, 270],
                                                                 "F80_tool": [0, 90, 180, 270], "F63": [0, 180]}
    rows = {r["name"]: r for r in d["modules"]}
    assert list(rows) == [m["name"] for m in plain.doc["modules"]]
    for name, m in plain.mod.items():
        r = rows[name]
        assert r["cost"] == m["cost"] and r["kind"] == m["kind"]
        assert r["mass_kg"] == pytest.approx(sum(m.get(k, {}).get("mass", 0.0)
                                                 for k in ("inertial", "distal_inertial")))
        T = plain.frame(m["axis"]) @ plain.frame(m["out"]) if m["kind"] == "joint" else plain.out(m)
        assert r["length"] == pytest.approx(np.linalg.norm(T[:3, 3]) / 1e-3, rel=1e-12)
        if m["kind"] == "joint":
            assert r["limits"] == pytest.approx(m["limits"]) and r["max_torque"] == m["max_torque"]
            assert r["max_velocity"] == pytest.approx(m["max_velocity"])


def test_modules_without_a_catalogue_lists_the_bundled(capsys):
    from kin.modules import bundled_catalogues
    code, text, _ = run(capsys, "modules", "--json")
    assert code == 0 and [c["name"] for c in json.loads(text)["catalogues"]] == bundled_catalogues()
