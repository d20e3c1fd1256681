"""The command line's input contract (issue 8 §4): every bad value is refused with exit 2 and one
line on stderr naming the argument and its allowed range — never a traceback, never a silent answer."""
from __future__ import annotations

import json

import pytest

from studies.cli import main

SCARA_PATH = "q1,q2,q3\n0,0.5,-150\n0.2,0.6,-150\n"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def refused(capsys, *argv, match: str):
    code, out, err = run(capsys, *argv)
    assert code == 2, (argv, out, err)
    assert err.count("\n") == 1 and err.startswith("rmt: error:") and "Traceback" not in err, err
    assert match in err, err
    return err


@pytest.mark.parametrize("argv", [
    ["ik", "puma560", "--xyz", "400", "100", "300"],
    ["singularities", "scara_rrp"],
    ["windows", "scara_rrp", "--margin", "0.1"],
    ["workspace", "scara_rrp", "--samples", "100"],
    ["plan", "scara_rrp", "--start", "0", "0.5", "-150", "--goal", "0.2", "0.6", "-150"],
    ["check-path", "scara_rrp", "p.csv"],
    ["validate-toolpath", "scara_rrp", "scara_line"],
])
def test_negative_seed_in_every_command(capsys, argv):
    refused(capsys, *argv, "--seed", "-1", match="--seed: -1 is outside the allowed range 0 to 4294967295")


@pytest.mark.parametrize("argv,match", [
    (["plan", "scara_rrp", "--start", "0", "0.5", "-150", "--goal", "0.2", "0.6", "-150", "--time-limit", "1e308"],
     "--time-limit: 1e308 is outside the allowed range (0, 3600] s"),
    (["plan", "scara_rrp", "--start", "0", "0.5", "-150", "--goal", "0.2", "0.6", "-150", "--time-limit", "nan"],
     "--time-limit: nan is outside"),
    (["windows", "scara_rrp", "--margin", "200"],
     "--margin 200 rad is too wide for the boundary window; allowed: 0 to 3.14159 rad"),
    (["windows", "puma560", "--margin", "181"], "--margin 181 deg is too wide"),
    (["windows", "scara_rrp", "--margin", "-1"], "--margin: -1 is outside"),
    (["windows", "scara_rrp", "--sigma-min", "0"], "--sigma-min: 0 is outside the allowed range (0, 1000]"),
    (["check-path", "scara_rrp", "p.csv", "--sigma-floor", "-1"],
     "--sigma-floor: -1 is outside the allowed range [0, 1000]"),
    (["check-path", "scara_rrp", "p.csv", "--sigma-floor", "nan"], "--sigma-floor: nan is outside"),
    (["validate-toolpath", "scara_rrp", "scara_line", "--sigma-floor", "nan"], "--sigma-floor: nan is outside"),
    (["check-path", "scara_rrp", "p.csv", "--step", "inf"], "--step: inf is outside the allowed range > 0, finite"),
    (["check-path", "scara_rrp", "p.csv", "--step", "1e308"],
     "--step 1e+308 is outside the allowed range [1e-06, 0.0873] rad"),
    (["check-path", "scara_rrp", "p.csv", "--step", "1e-300"], "--step 1e-300 is outside the allowed range"),
    (["check-path", "scara_rrp", "p.csv", "--step", "0.00005"], "[0.0001, 10] mm for the prismatic joints"),
    (["follow", "scara_rrp", "scara_line", "--tol-position", "inf"],
     "--tol-position: inf is outside the allowed range > 0, finite (file length unit)"),
    (["workspace", "scara_rrp", "--samples", "0"], "--samples: 0 is outside"),
])
def test_values_outside_their_range(capsys, tmp_path, monkeypatch, argv, match):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "p.csv").write_text(SCARA_PATH)
    refused(capsys, *argv, match=match)


def test_check_path_step_within_range_checks_the_closed_form_count(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "p.csv").write_text(SCARA_PATH)
    code, out, _ = run(capsys, "check-path", "scara_rrp", "p.csv", "--step", "0.01", "--json")
    # q1 moves 0.2 rad, q2 0.1 rad, q3 0 mm: ceil(0.2 / 0.01) = 20 sub-steps, plus the last row
    assert code == 0 and json.loads(out)["checked_states"] == 21


def test_out_into_a_missing_directory_and_onto_a_directory(capsys, tmp_path):
    target = tmp_path / "new" / "dir" / "w.json"
    code, out, err = run(capsys, "windows", "scara_rrp", "--margin", "0.05", "--out", target)
    assert code == 0, err
    assert json.loads(target.read_text())["n"] == 3
    refused(capsys, "windows", "scara_rrp", "--margin", "0.05", "--out", tmp_path / "new", match="is a directory")
    (tmp_path / "file").write_text("")
    refused(capsys, "plan", "scara_rrp", "--start", "0", "0.5", "-150", "--goal", "0.2", "0.6", "-150",
            "--out", tmp_path / "file" / "p.csv", match="is not a directory")


def test_out_onto_a_symlink_or_a_device_leaves_it(capsys, tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("keep")
    (tmp_path / "link.json").symlink_to(victim)
    refused(capsys, "windows", "scara_rrp", "--margin", "0.05", "--out", tmp_path / "link.json",
            match="symbolic link")
    assert victim.read_text() == "keep"
    refused(capsys, "workspace", "scara_rrp", "--samples", "100", "--plot", "/dev/null", match="character device")


def test_windows_file_with_a_python_payload_runs_nothing(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    w = {"robot": "scara_rrp", "n": 3, "windows": [
        {"name": "evil", "kind": "boundary", "expr": "__import__('os').system('touch X')", "joints": [2],
         "width": 0.1, "method": "margin", "epsilon": 0.1}]}
    (tmp_path / "w.json").write_text(json.dumps(w))
    err = refused(capsys, "validate-toolpath", "scara_rrp", "scara_line", "--windows", "w.json",
                  match="expr: unexpected character")
    assert "position 12" in err                               # the quote after __import__(
    assert not (tmp_path / "X").exists()
    w["windows"][0]["expr"] = "sin(q2"                         # malformed, not malicious
    (tmp_path / "w.json").write_text(json.dumps(w))
    refused(capsys, "validate-toolpath", "scara_rrp", "scara_line", "--windows", "w.json", match="expected ')'")


DEGENERATE = '''name = "{name}"
convention = "standard"
length_unit = "m"
angle_unit = "rad"
[[joints]]
type = "revolute"
a = {a}
limits = [-3, 3]
[[joints]]
type = "revolute"
a = {a2}
limits = [-3, 3]
'''


@pytest.mark.parametrize("a,a2,match", [
    ("1e308", "1.0", "joints[0].a: 1e+308 is outside the allowed range"),
    ("1e-300", "1.0", "joints[0].a: 1e-300 is outside the allowed range"),
    ("0.0", "0.0", "no task rows to control"),
])
@pytest.mark.parametrize("command", [["jacobian", "R", "0.1", "0.2"], ["singularities", "R"],
                                     ["windows", "R", "--margin", "0.1"], ["workspace", "R", "--samples", "500"]])
def test_degenerate_robots_get_a_clear_error(capsys, tmp_path, a, a2, match, command):
    p = tmp_path / "r.toml"
    p.write_text(DEGENERATE.format(name="deg", a=a, a2=a2))
    refused(capsys, *[str(p) if c == "R" else c for c in command], match=match)


def test_joint_path_file_size_is_bounded(capsys, tmp_path, monkeypatch):
    import studies.jointpath as jp
    monkeypatch.setattr(jp, "MAX_PATH_BYTES", 20)
    (tmp_path / "p.csv").write_text(SCARA_PATH)                # 38 bytes
    refused(capsys, "check-path", "scara_rrp", tmp_path / "p.csv", match="a joint-path file may have at most 20 bytes")
