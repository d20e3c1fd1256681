"""``rmt place`` against a closed form: the planar 2R (l1 = 1.0 m, l2 = 0.8 m) reaches exactly the
annulus 0.2 ≤ |p − base| ≤ 1.8 m around its base.  Targets filling that ring around c = (0.5, 0.3),
with 36 points exactly on each boundary circle, are all reached from c and from no other placement
(a base moved by d leaves the boundary point opposite d, or the one along d, out of reach), so the
answer must be c, to the IK tolerance.  The reach study's per-target verdicts are checked against the
closed form at c and off it; bad input is one line and exit 2."""
from __future__ import annotations

import contextlib
import io
import json
import math

import numpy as np
import pytest

import kin
from design.reach import reach_study
from design.task.model import Targets
from studies.cli import main

C = np.array([0.5, 0.3, 0.0])
L1, L2 = 1.0, 0.8
R_IN, R_OUT = abs(L1 - L2), L1 + L2
TOL = 1e-6
#: (radius, points): both boundary circles with 36 points, interior rings between them
RINGS = ((R_IN, 36), (0.6, 24), (1.0, 24), (1.4, 24), (R_OUT, 36))


def ring_points() -> np.ndarray:
    pts = []
    for r, n in RINGS:
        th = 2 * np.pi * np.arange(n) / n
        pts.append(np.column_stack([C[0] + r * np.cos(th), C[1] + r * np.sin(th), np.zeros(n)]))
    return np.vstack(pts)


def write_task(d, name: str, unit: str = "m", placement: bool = True):
    """A points task (CSV in ``unit``) of the ring targets; with ``[placement]`` x, y in [-1, 2] m, z and yaw 0."""
    s = {"m": 1.0, "mm": 1e3}[unit]
    P = ring_points() * s
    (d / f"{name}.csv").write_text("x,y,z\n" + "".join(f"{x!r},{y!r},{z!r}\n" for x, y, z in P.tolist()))
    text = (f'name = "{name}"\nrobot = "planar_2r"\nlength_unit = "{unit}"\nangle_unit = "deg"\n'
            f'[target]\nshape = "points"\nfile = "{name}.csv"\ntolerance = {TOL * s!r}\n')
    if placement:
        text += f"[placement]\nx = [{-1 * s:g}, {2 * s:g}]\ny = [{-1 * s:g}, {2 * s:g}]\nz = [0, 0]\nyaw = [0, 0]\n"
    path = d / f"{name}.toml"
    path.write_text(text)
    return path


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def run(argv: list[str], tty: bool = False) -> tuple[int, str, str]:
    out, err = io.StringIO(), (_Terminal() if tty else io.StringIO())
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("place")
    return {"task": write_task(d, "ring"), "bare_mm": write_task(d, "ring_mm", "mm", placement=False), "dir": d}


@pytest.fixture(scope="module")
def answer(files):
    """`rmt place planar_2r ring.toml --json --grid 12 --de-iterations 5 --out DIR`, run once."""
    out_dir = files["dir"] / "out"
    rc, out, err = run(["place", "planar_2r", str(files["task"]), "--json", "--grid", "12", "--de-iterations", "5",
                        "--out", str(out_dir)])
    return rc, json.loads(out), err, out_dir / "ring"


def closed_form(P: np.ndarray, base: np.ndarray) -> np.ndarray:
    r = np.linalg.norm(P[:, :2] - base[:2], axis=1)
    return (r >= R_IN - TOL) & (r <= R_OUT + TOL)


def test_the_answer_is_the_centre_and_reaches_every_target(answer):
    rc, out, err, _ = answer
    assert rc == 0, err
    assert np.linalg.norm(np.array(out["placement"]["xyz"]) - C) < 1e-3
    assert out["placement"]["rpy"] == pytest.approx([0, 0, 0], abs=1e-12)
    assert out["coverage_percent"] == 100.0
    assert out["length_unit"] == "m" and out["units"] == "SI (m, rad)" and out["task"] == "ring"
    assert out["region"]["free"] == ["x", "y"] and out["region"]["x"] == [-1.0, 2.0]
    # every method verified; the grid (step 3/11 m, c not on it) cannot reach both boundary circles
    assert set(out["methods"]) == {"current", "ipopt", "differential_evolution", "grid"}
    assert out["methods"]["grid"]["coverage_percent"] < 100.0
    assert out["method"] == "ipopt" and out["methods"]["ipopt"]["coverage_percent"] == 100.0
    n = len(ring_points())
    assert out["study"]["targets"] == n and out["study"]["reached"] == n
    assert out["targets_gained"] == n - out["before"]["reached"] and out["targets_lost"] == 0


def test_out_writes_placement_json_and_the_reach_csv(answer):
    _, out, _, d = answer
    assert json.loads((d / "placement.json").read_text()) == out
    lines = (d / "reach.csv").read_text().splitlines()
    assert lines[0].split(",")[:5] == ["target", "x", "y", "z", "reached"] and lines[0].endswith("q1,q2")
    assert len(lines) == 1 + len(ring_points())
    assert all(row.split(",")[4] == "True" for row in lines[1:])


@pytest.mark.parametrize("base", [C, C + [0.05, 0.0, 0.0], np.zeros(3)], ids=["centre", "off_5cm", "origin"])
def test_reach_study_verdicts_match_the_annulus(base):
    P = ring_points()
    study = reach_study(kin.load_robot("planar_2r"), Targets(P, tolerance=TOL), placement=[*base, 0, 0, 0])
    expect = closed_form(P, base)
    r = np.linalg.norm(P[:, :2] - base[:2], axis=1)
    on_edge = (np.abs(r - R_IN) < 1e-5) | (np.abs(r - R_OUT) < 1e-5)
    centre = np.array_equal(base, C)
    check = np.ones(len(P), bool) if centre else ~on_edge
    assert check.sum() >= 100
    assert np.array_equal(study.reached[check], expect[check]), np.flatnonzero(study.reached != expect)
    if not centre:
        assert not expect.all()                       # off the centre some targets are truly out of reach
    assert set(study.reason[~study.reached]) <= {"out_of_reach"}


def test_command_line_region_in_task_units_with_the_summary(files):
    """A mm task without [placement]: --region and --yaw (mm, deg) give the region; the summary is in mm,
    progress lines go to a terminal's stderr."""
    rc, out, err = run(["place", "planar_2r", str(files["bare_mm"]), "--region", "-1000", "2000", "-1000", "2000",
                        "0", "0", "--yaw", "0", "0", "--starts", "2", "--candidates", "16"], tty=True)
    assert rc == 0, err
    assert err.startswith("… screening 16 candidate placements and the current one\n") and "… IPOPT start 2/2" in err
    lines = out.splitlines()
    assert lines[0].startswith("planar_2r: task ring_mm, 144 targets, no cell; lengths in mm, angles in deg")
    assert lines[1].startswith("region: x [-1000, 2000], y [-1000, 2000], z 0, yaw 0, tilt ≤ 0; free: x, y")
    ipopt = next(ln for ln in lines if ln.strip().startswith("ipopt"))
    assert "100.0 %" in ipopt and ipopt.endswith("← answer")
    ans = next(ln for ln in lines if ln.startswith("answer (ipopt): xyz "))
    x, y, z = (float(v) for v in ans.split("xyz ")[1].split(" mm")[0].split())
    assert math.hypot(x - 500, y - 300) < 1.0 and z == 0
    assert any(ln.startswith("after: coverage 100.0 %") and "0 lost" in ln for ln in lines)


def test_quiet_prints_nothing(files):
    rc, out, err = run(["place", "planar_2r", str(files["task"]), "--quiet", "--starts", "1", "--candidates", "4",
                        "--max-time", "30"])
    assert rc in (0, 1) and out == "" and err == ""


def test_weights_and_measure_reach_the_score(files):
    rc, out, err = run(["place", "planar_2r", str(files["task"]), "--json", "--weights", "1", "0", "0",
                        "--measure", "manipulability", "--starts", "1", "--candidates", "4"])
    assert rc in (0, 1), err
    w = json.loads(out)["study"]["weights"]
    assert (w["dexterity"], w["clearance"], w["limits"], w["measure"]) == (1.0, 0.0, 0.0, "manipulability")


def test_measures_are_the_reach_studys():
    from design.reach import MEASURES as REACH_MEASURES
    from studies.cli.place import MEASURES
    assert tuple(MEASURES) == tuple(REACH_MEASURES)


HOSTILE = {
    "region_low_above_high": (["--region", "1", "0", "0", "1"], "--region XMIN XMAX"),
    "region_three_numbers": (["--region", "0", "1", "0"], "--region"),
    "region_nan": (["--region", "nan", "1", "0", "1"], "--region"),
    "region_not_a_number": (["--region", "0", "1", "0", "x"], "--region"),
    "yaw_low_above_high": (["--yaw", "10", "-10"], "--yaw"),
    "tilt_100_degrees": (["--tilt", "100"], "--tilt"),
    "keep_out_covers_region": (["--keep-out", "-5", "5", "-5", "5"], "--keep-out"),
    "keep_out_empty": (["--keep-out", "1", "1", "0", "1"], "--keep-out"),
    "keep_out_three_numbers": (["--keep-out", "0", "1", "0"], "--keep-out"),
    "starts_0": (["--starts", "0"], "--starts"),
    "starts_not_integer": (["--starts", "1.5"], "--starts"),
    "candidates_0": (["--candidates", "0"], "--candidates"),
    "grid_negative": (["--grid", "-1"], "--grid"),
    "grid_too_large": (["--grid", "1000", "--yaw", "-10", "10"], "--grid 1000"),
    "de_negative": (["--de-iterations", "-2"], "--de-iterations"),
    "max_time_0": (["--max-time", "0"], "--max-time"),
    "max_time_inf": (["--max-time", "inf"], "--max-time"),
    "seed_negative": (["--seed", "-1"], "--seed"),
    "weights_all_zero": (["--weights", "0", "0", "0"], "--weights"),
    "weights_negative": (["--weights", "-1", "0", "1"], "--weights"),
    "measure_unknown": (["--measure", "volume"], "--measure"),
    "clearance_without_cell": (["--clearance", "5"], "--clearance"),
    "no_such_cell": (["--cell", "no_such_cell"], "no_such_cell"),
}


@pytest.mark.parametrize("case", HOSTILE)
def test_hostile_options_one_line_exit_2(files, case):
    extra, needle = HOSTILE[case]
    rc, out, err = run(["place", "planar_2r", str(files["task"]), *extra])
    assert rc == 2, (case, out, err)
    assert out == "" and err.count("\n") == 1 and err.startswith("rmt: error: "), err
    assert needle in err and "Traceback" not in err, err


@pytest.mark.parametrize("edit,needle", [
    (("x = [-1, 2]", "x = [2, -1]"), "placement.x"),
    (("yaw = [0, 0]", "yaw = [0, 0]\ntilt = 95"), "placement.tilt"),
    (("yaw = [0, 0]", "yaw = [0, 0]\nkeep_out = [[0, 1, 2]]"), "placement.keep_out[0]"),
    (("yaw = [0, 0]", "yaw = [0, 0]\nwidth = 3"), "placement.width"),
    (('file = "ring.csv"', 'file = "nowhere.csv"'), "target.file"),
])
def test_bad_task_file_one_line_exit_2(files, edit, needle):
    bad = files["dir"] / "bad.toml"
    bad.write_text(files["task"].read_text().replace(*edit))
    rc, out, err = run(["place", "planar_2r", str(bad)])
    assert rc == 2 and out == "" and err.count("\n") == 1, err
    assert str(bad) in err and needle in err and "Traceback" not in err, err


def test_no_such_task_and_an_unwritable_out(files):
    rc, _, err = run(["place", "planar_2r", "no_such_task"])
    assert rc == 2 and err.count("\n") == 1 and "no such task file" in err
    (files["dir"] / "plain_file").write_text("x")
    rc, _, err = run(["place", "planar_2r", str(files["task"]), "--out", str(files["dir"] / "plain_file")])
    assert rc == 2 and err.count("\n") == 1 and "not a directory" in err, err


def test_current_placement_already_best_is_said(tmp_path):
    """Eight targets at the 2R's most dexterous reach (0.8 m: σ_min of its Jacobian, by numpy over q2)
    around the robot where it stands (no cell: the origin), scored by dexterity alone: no placement
    scores higher, and the text and JSON say the current one is already the best found."""
    q2 = np.linspace(1e-3, np.pi - 1e-3, 100_001)
    J = np.stack([np.stack([-L2 * np.sin(q2), -L2 * np.sin(q2)], -1),
                  np.stack([L1 + L2 * np.cos(q2), L2 * np.cos(q2)], -1)], -2)
    q = q2[np.argmax(np.linalg.svd(J, compute_uv=False)[:, -1])]
    r = math.sqrt(L1 ** 2 + L2 ** 2 + 2 * L1 * L2 * math.cos(q))
    th = 2 * np.pi * np.arange(8) / 8
    (tmp_path / "dex.csv").write_text("x,y,z\n" + "".join(f"{r * math.cos(t)!r},{r * math.sin(t)!r},0\n" for t in th))
    task = tmp_path / "dex.toml"
    task.write_text('name = "dex"\nrobot = "planar_2r"\nlength_unit = "m"\nangle_unit = "deg"\n[target]\n'
                    'shape = "points"\nfile = "dex.csv"\ntolerance = 1e-6\n')
    args = ["place", "planar_2r", str(task), "--region", "-0.4", "0.4", "-0.4", "0.4", "--yaw", "0", "0",
            "--weights", "1", "0", "0", "--starts", "2", "--candidates", "8", "--grid", "5", "--de-iterations", "2"]
    rc, out, err = run(args)
    assert rc == 0, err
    assert "the current placement is already the best found (coverage 100.0 %, mean score" in out
    assert "answer (current): xyz 0 0 0 m" in out
    assert next(ln for ln in out.splitlines() if ln.strip().startswith("current")).endswith("← answer")
    rc, out, err = run(args + ["--json"])
    d = json.loads(out)
    assert d["current_is_best"] is True and d["method"] == "current"
    assert d["placement"]["xyz"] == [0.0, 0.0, 0.0] and d["current"]["candidate"] is True
    assert all(m["value"] <= d["methods"]["current"]["value"] for m in d["methods"].values())
