"""``rmt reach`` and ``rmt reach-compare`` against closed forms: the planar 2R (l1 = 1.0, l2 = 0.8 m)
reaches exactly the annulus 0.2 ≤ |p − base| ≤ 1.8 m; targets inside the weld cell's fixture box are
reached only through a collision with it; units of the task file; bad input one line and exit 2."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from tests.studies.cli.test_place_cli import ring_points, run, write_task

C = np.array([0.5, 0.3, 0.0])
FAST = ["--starts", "4", "--samples", "1024", "--spins", "4"]


def closed_form(P, base):
    r = np.linalg.norm(P[:, :2] - np.asarray(base)[:2], axis=1)
    return (r >= 0.2 - 1e-6) & (r <= 1.8 + 1e-6), np.minimum(np.abs(r - 0.2), np.abs(r - 1.8)) > 1e-5


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("reach")
    fixture = d / "fixture.toml"       # the weld cell's fixture box: centre (550, 0, 850) mm, 300 × 200 × 100 mm
    pts = [(520, -40, 850), (580, 40, 830), (600, 0, 880)]
    (d / "fixture.csv").write_text("".join(f"{x},{y},{z}\n" for x, y, z in pts))
    fixture.write_text('name = "in_fixture"\nrobot = "fanuc_lrmate200id"\nlength_unit = "mm"\nangle_unit = "deg"\n'
                       'cell = "' + str(_cell()) + '"\n[target]\nshape = "points"\nfile = "fixture.csv"\n'
                       'tolerance = 0.01\n')
    return {"ring": write_task(d, "ring"), "ring_mm": write_task(d, "ring_mm", "mm", placement=False),
            "fixture": fixture, "dir": d}


def _cell():
    from studies.cli.common import cell_file
    return cell_file("fanuc_weld_cell")


@pytest.mark.parametrize("base", [(0.5, 0.3), (0.0, 0.0), (0.55, 0.3)])
def test_verdicts_are_the_annulus(files, base):
    rc, out, err = run(["reach", "planar_2r", str(files["ring"]), "--placement", str(base[0]), str(base[1]), "0",
                        "0", "0", "0", "--json", *FAST])
    d = json.loads(out)
    P = ring_points()
    expect, clear = closed_form(P, base)
    got = np.array([r["reached"] for r in d["per_target"]])
    assert np.array_equal(got[clear], expect[clear])
    assert rc == (0 if got.all() else 1) and err == ""
    assert d["coverage_percent"] == pytest.approx(100 * got.mean())
    assert d["placement"]["xyz"] == pytest.approx([base[0], base[1], 0.0])
    if base == (0.5, 0.3):
        assert d["coverage_percent"] == 100.0


def test_task_units_for_placement_csv_and_plot(files):
    d = files["dir"]
    rc, out, _ = run(["reach", "planar_2r", str(files["ring_mm"]), "--placement", "500", "300", "0", "0", "0", "0",
                      "--csv", str(d / "r.csv"), "--plot", str(d / "r.png"), *FAST])
    assert rc == 0 and "placement: xyz 500 300 0 mm" in out
    rows = list(csv.DictReader((d / "r.csv").open()))
    P = ring_points()
    assert len(rows) == len(P)
    assert np.allclose([[float(r[k]) for k in "xyz"] for r in rows], 1000 * P)          # in the task's mm
    assert all(r["reached"] == "True" for r in rows)
    assert (d / "r.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_targets_inside_the_fixture_collide_with_it(files):
    rc, out, _ = run(["reach", "fanuc_lrmate200id", str(files["fixture"]), "--json", *FAST])
    d = json.loads(out)
    assert rc == 1 and d["coverage_percent"] == 0
    reasons = [r["reason"] for r in d["per_target"]]
    assert set(reasons) <= {"collision", "out_of_reach"} and "collision" in reasons
    for r in d["per_target"]:
        if r["reason"] == "collision":
            assert r["obstacle"] == "fixture" and "fixture" in r["detail"]
    assert d["collisions_by_object"] == {"fixture": reasons.count("collision")}


def test_compare_two_placements(files):
    d = files["dir"]
    a, b = d / "a.json", d / "b.json"
    for path, base in ((a, "0.5"), (b, "0")):
        rc, out, _ = run(["reach", "planar_2r", str(files["ring"]), "--placement", base, base if base == "0" else "0.3",
                          "0", "0", "0", "0", "--json", *FAST])
        path.write_text(out)
    rc, out, err = run(["reach-compare", str(a), str(b), "--labels", "centre", "origin", "--json", "--out",
                        str(d / "cmp")])
    c = json.loads(out)
    P = ring_points()
    at_c, _ = closed_form(P, (0.5, 0.3))
    at_o, clear = closed_form(P, (0.0, 0.0))
    lost = np.zeros(len(P), bool)
    lost[c["lost"]] = True
    assert np.array_equal(lost[clear], (at_c & ~at_o)[clear]) and c["gained"] == []
    assert rc == 0 and c["coverage_percent"]["centre"] == 100.0
    html = (d / "cmp" / "reach_compare.html").read_text()
    assert "centre" in html and "origin" in html and "reach_compare_3d" in html
    # studies of other targets do not compare
    (d / "few.csv").write_text("0.5,0.3,0\n1.0,0.3,0\n")
    (d / "few.toml").write_text('name = "few"\nrobot = "planar_2r"\nlength_unit = "m"\nangle_unit = "deg"\n'
                                '[target]\nshape = "points"\nfile = "few.csv"\n')
    rc, out, _ = run(["reach", "planar_2r", str(d / "few.toml"), "--json", *FAST])
    (d / "other.json").write_text(out)
    rc, out, err = run(["reach-compare", str(a), str(d / "other.json")])
    assert rc == 2 and "different targets" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("extra", [
    ["--placement", "0", "0", "0", "0", "0"], ["--placement", "0", "0", "nan", "0", "0", "0"],
    ["--placement", "0", "0", "x", "0", "0", "0"], ["--weights", "-1", "0", "0"], ["--weights", "0", "0", "0"],
    ["--starts", "0"], ["--spins", "1000"], ["--samples", "2"], ["--cell", "no_such_cell"], ["--clearance", "5"],
    ["--clearance-ref", "0"], ["--margin", "-1"], ["--csv", "/"], ["--out", "/dev/null"],
])
def test_hostile_options(files, extra):
    rc, out, err = run(["reach", "planar_2r", str(files["ring"]), *extra])
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_hostile_files(files, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("name = [")
    nonjson = tmp_path / "x.json"
    nonjson.write_text("{")
    broken = tmp_path / "y.json"
    broken.write_text(json.dumps({"per_target": [{"x": 0}], "placement": {"xyz": [0, 0, 0], "rpy": [0, 0, 0]}}))
    for argv in (["reach", "planar_2r", str(tmp_path / "missing.toml")], ["reach", "planar_2r", str(bad)],
                 ["reach-compare", str(nonjson), str(nonjson)], ["reach-compare", str(broken), str(broken)],
                 ["reach-compare", str(tmp_path / "none.json"), str(broken)]):
        rc, out, err = run(argv)
        assert rc == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, (argv, err)
