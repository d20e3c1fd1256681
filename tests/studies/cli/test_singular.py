"""End-to-end tests of `rmt singularities`, `rmt windows` and `rmt workspace`."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from studies.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_singularities_json_scara(capsys):
    code, out, _ = run(capsys, "singularities", "scara_rrp", "--json")
    assert code == 0
    d = json.loads(out)
    assert set(d) >= {"factors", "method"}
    [f] = d["factors"]
    # docs/machines.md §2: det of the position Jacobian = 101250 sin θ2 — one singularity, θ2 = 0, stretched arm
    assert f["expr"] == "sin(q2)" and f["kind"] == "boundary" and f["joints"] == [2]
    assert f["solutions"]["values"] == [0.0]
    assert {"expr", "kind", "joints", "meaning", "solutions"} <= set(f)


def test_singularities_text_puma_in_degrees(capsys):
    code, out, _ = run(capsys, "singularities", "puma560")
    assert code == 0
    assert "[wrist] sin(q5)" in out and "[elbow]" in out and "[shoulder]" in out
    # elbow: d4·c3 − a3·s3 = 0 with a3 = −20.32, d4 = 433.07 mm → q3 = 90° + atan(20.32/433.07)
    expected = 90 + math.degrees(math.atan(20.32 / 433.07))
    assert f"q3 ∈ {{{expected:.6g}}} deg" in out


def test_windows_margin_json_and_file(capsys, tmp_path):
    f = tmp_path / "w.json"
    code, out, _ = run(capsys, "windows", "puma560", "--margin", "3", "--json", "--out", str(f))
    assert code == 0
    d = json.loads(out)
    wrist = [w for w in d["windows"] if w["kind"] == "wrist"][0]
    # 3° in the file's degrees = 0.05236 rad around q5 = 0
    np.testing.assert_allclose(wrist["intervals"], [[-math.radians(3), math.radians(3)]], rtol=1e-12)
    saved = json.loads(f.read_text())
    assert saved["windows"][0]["name"] == d["windows"][0]["name"]


def test_windows_learned_sets_the_published_window_beside_ours(capsys):
    # the SCARA's learned window (seeded, so text and JSON give the same width) beside the thesis's ±0.01 rad
    code, out, _ = run(capsys, "windows", "scara_rrp", "--learned", "--json")
    assert code == 0
    [rep] = json.loads(out)["learned"]
    p = rep["published"]
    assert p["joint"] == "q2" and p["interval"] == [-0.01, 0.01] and "thesis" in p["source"]
    assert p["ours_width"] == rep["width"] and p["ours_over_published"] == pytest.approx(rep["width"] / 0.01)
    (lo, hi), = rep["intervals"]
    assert hi == pytest.approx(rep["width"]) and lo == pytest.approx(-rep["width"])
    code, out, _ = run(capsys, "windows", "scara_rrp", "--learned")
    assert code == 0
    line = next(x for x in out.splitlines() if "published" in x)
    assert "θ2 ∈ [−0.01, 0.01] rad" in line and f"q2 half-width {rep['width']:.4g} rad" in line
    assert f"{rep['width'] / 0.01:.1f}× the published 0.01 rad" in line


def test_windows_needs_a_width_source(capsys):
    code, out, err = run(capsys, "windows", "fanuc_m16ib20")
    assert code == 2 and "--margin" in err and out == ""


def test_windows_threshold_too_high_is_exit_2(capsys):
    code, _, err = run(capsys, "windows", "ur5e", "--sigma-min", "0.05")
    assert code == 2 and "choose a smaller threshold" in err and len(err.strip().splitlines()) == 1


def test_workspace_json_and_plot(capsys, tmp_path):
    png = tmp_path / "ws.png"
    code, out, _ = run(capsys, "workspace", "scara_rrp", "--samples", "20000", "--seed", "3", "--plot", str(png),
                       "--json")
    assert code == 0
    d = json.loads(out)
    # docs/machines.md §2: the SCARA is stretched at r = 675 mm; sampled radial reach cannot exceed it
    assert d["radial_reach"] <= 0.675 + 1e-9 and d["radial_reach"] > 0.66
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("argv", [["workspace", "scara_rrp", "--samples", "0"],
                                  ["singularities", "nosuchrobot"],
                                  ["windows", "scara_rrp", "--margin", "-1"]])
def test_bad_input_exit_2(capsys, argv):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == "" and err.startswith("rmt: error:") and len(err.strip().splitlines()) == 1


GENERAL_6R = """name = "general_6r"
convention = "standard"
length_unit = "m"
angle_unit = "rad"
""" + "".join(f'[[joints]]\ntype = "revolute"\na = {a}\nalpha = {al}\nd = {d}\nlimits = [-3, 3]\n'
              for a, al, d in [(0.1, 1.2, 0.3), (0.45, -0.7, 0.05), (0.12, 0.9, 0.2), (0.05, -1.1, 0.35),
                               (0.08, 0.6, 0.1), (0.02, 0.4, 0.15)])


def test_singularities_of_a_general_chain_say_numeric(capsys, tmp_path, monkeypatch):
    from kin.singular import cache
    from planning.windows import WindowSet
    monkeypatch.setattr(cache, "cache_dir", lambda: tmp_path)
    path = tmp_path / "g6r.toml"
    path.write_text(GENERAL_6R)
    code, out, _ = run(capsys, "singularities", str(path), "--json", "--exact-timeout", "1")
    d = json.loads(out)
    assert code == 0 and d["method"] == "numeric" and d["budget"]["exact_timeout"] == 1.0
    assert d["budget"]["exact_status"] == "timeout" and d["factors"][0]["joints"] == [2, 3, 4, 5]
    code, out, _ = run(capsys, "windows", str(path), "--margin", "0.05", "--exact-timeout", "1",
                       "--out", str(tmp_path / "w.json"))
    assert code == 0 and "sampled points" in out
    assert WindowSet.load(tmp_path / "w.json").windows[0].is_point_set
    code, out, err = run(capsys, "windows", str(path), "--learned", "--exact-timeout", "1")
    assert code == 2 and out == "" and err.count("\n") == 1 and "--exact-timeout" in err


@pytest.mark.parametrize("value", ["-1", "nan", "1e9"])
def test_bad_exact_timeout_is_one_line(capsys, value):
    code, out, err = run(capsys, "singularities", "puma560", "--exact-timeout", value)
    assert code == 2 and out == "" and err.count("\n") == 1 and "--exact-timeout" in err


@pytest.mark.parametrize("name", ["kuka_iiwa7", "franka_panda"])
def test_seven_joint_arms_get_their_singular_set_and_windows(name, tmp_path, capsys):
    """Today's redundant arms: the numeric analysis answers within its budget, every component's
    sample points are singular (J·Jᵀ nearly singular, by numpy's SVD), and windows are built."""
    import kin
    assert main(["singularities", name, "--exact-timeout", "2", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["method"] == "numeric" and d["factors"]
    robot = kin.load_robot(name)
    with_points = [np.array(f["solutions"]["samples"]) for f in d["factors"] if f["solutions"].get("samples")]
    assert with_points
    for pts in with_points:
        s = np.linalg.svd(robot.jacobian(pts)[:, list(robot.task_rows)], compute_uv=False)[:, -1]
        assert np.median(s) < 1e-3
    out = tmp_path / "w.json"
    assert main(["windows", name, "--margin", "0.05", "--exact-timeout", "2", "--out", str(out)]) == 0
    from planning.windows import WindowSet
    assert len(WindowSet.load(out).windows) >= 1


def test_windows_text_in_the_robot_file_units(capsys):
    """ur5e is written in degrees: --margin 5 means ±5°, and the windows say so (not 0.0872665 SI)."""
    code, out, _ = run(capsys, "windows", "ur5e", "--margin", "5")
    assert code == 0
    assert "q5 ∈ [-360, -355] ∪ [-185, -175] ∪ [-5, 5] ∪ [175, 185] ∪ [355, 360] deg   (half-width 5°, margin)" in out
    assert "(half-width ≥ 5°, margin)" in out and "SI," not in out
    code, out, _ = run(capsys, "windows", "ur5e", "--margin", "5", "--json")
    w = json.loads(out)["windows"][0]
    assert w["width"] == pytest.approx(math.radians(5), rel=1e-12)       # the file keeps SI
