"""End-to-end tests of the ``rmt`` command line: output values, units, exit codes, error lines."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from studies.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_robots_lists_every_bundled_robot(capsys):
    import kin
    code, out, _ = run(capsys, "robots", "--json")
    assert code == 0
    names = [r["name"] for r in json.loads(out)["robots"]]
    assert names == kin.bundled_robots()
    assert {"puma560", "fanuc_m16ib20", "scara_rrp", "ur5e"} <= set(names)


def test_fk_json_in_file_units_puma(capsys):
    # docs/machines.md §1: q = (90, 0, 90, 0, 0, 0) deg -> p = (-149.09, 921.12, 20.32) mm
    code, out, err = run(capsys, "fk", "puma560", "90", "0", "90", "0", "0", "0", "--json")
    assert code == 0 and err == ""
    d = json.loads(out)
    assert d["units"] == {"length": "mm", "angle": "deg"}
    np.testing.assert_allclose(d["position"], [-149.09, 921.12, 20.32], atol=0.005)
    np.testing.assert_allclose(np.array(d["T"])[:3, :3], [[0, -1, 0], [0, 0, 1], [-1, 0, 0]], atol=1e-12)


def test_fk_negative_values_are_joint_values(capsys):
    code, out, _ = run(capsys, "fk", "fanuc_m16ib20", "0", "-0.5", "0", "0", "0.5", "0", "--json")
    assert code == 0
    p = json.loads(out)["position"]
    # closed form (FANUC, q2 = -0.5, q5 = 0.5; planar in x-z): wrist centre + flange along the tool z axis
    q2, q5 = -0.5, 0.5
    a1, a2, a3, d1, d4, d6 = 0.150, 0.770, 0.100, 0.525, 0.740, 0.100
    # standard DH with alpha1 = -90°: joint-2 rotation about the base -y direction
    x = a1 + a2 * math.cos(q2) + a3 * math.cos(q2) + d4 * math.sin(q2)
    z = d1 - a2 * math.sin(q2) - a3 * math.sin(q2) + d4 * math.cos(q2)
    # flange: d6 along the tool z axis, which is the forearm axis rotated by q5 about the joint-5 axis
    ang = q2 + q5
    x += d6 * math.sin(ang)
    z += d6 * math.cos(ang)
    np.testing.assert_allclose(p, [x, 0.0, z], atol=1e-12)


def test_fk_out_of_limits_warns_but_answers(capsys):
    code, out, err = run(capsys, "fk", "puma560", "0", "0", "0", "0", "180", "0")
    assert code == 0
    assert "joint 5 = 180 deg is outside its limits [-100, 100] deg" in err
    assert "position" in out


def run_strict(capsys, *argv):
    """``run`` with every Python warning an error: a numpy RuntimeWarning fails the test even when an
    earlier test already printed the same one (which the default filter would then hide)."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return run(capsys, *argv)


@pytest.mark.parametrize("argv, fragment", [
    (["jacobian", "cnc_rrrppp", "0", "0", "0", "1e308", "1e308", "1e308"], "joint values: joint 4 = 1e+308 m"),
    (["jacobian", "cnc_rrrppp", "0", "0", "0", "-1e308", "-1e308", "-1e308", "--json"], "joint 4 = -1e+308 m"),
    (["fk", "cnc_rrrppp", "0", "0", "0", "0", "0", "1e308"], "joint values: joint 6 = 1e+308 m"),
    (["fk", "scara_rrp", "0", "0", "-1e308"], "joint 3 = -1e+308 mm is beyond ±1e+09 mm"),
    (["jacobian", "scara_rrp", "0", "0", "1000000001"], "joint 3 = 1e+09 mm is beyond ±1e+09 mm"),
    (["ik", "scara_rrp", "--xyz", "100", "100", "0", "--q0", "0", "0", "1e308"], "--q0: joint 3 = 1e+308 mm"),
])
def test_prismatic_values_beyond_the_evaluators_range_exit_2(capsys, argv, fragment):
    """A prismatic joint at ±1e308 printed numpy's "divide by zero in det" and NaN-born measures
    (manipulability 0, σ_min 0); it is refused — one line naming the argument, the joint, the range
    (±1e6 m in the robot file's unit) and the joint's limits, before any limit warning."""
    code, out, err = run_strict(capsys, *argv)
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rmt: error:") and fragment in lines[0], err
    assert "prismatic joint value may take (its limits: [" in lines[0]


@pytest.mark.parametrize("argv", [
    ["jacobian", "cnc_rrrppp", "1e308", "-1e308", "1e308", "0", "0", "0"],
    ["jacobian", "cnc_rrrppp", "1e308", "-1e308", "1e308", "1e6", "-1e6", "999999", "--json"],
    ["fk", "cnc_rrrppp", "-1e308", "1e308", "-1e308", "-1e6", "1e6", "0"],
    ["fk", "scara_rrp", "1e308", "-1e308", "-1e9", "--json"],
    ["jacobian", "puma560", "1e308", "-1e308", "1e308", "-1e308", "1e308", "-1e308", "--json"],
])   # (ik --q0 1e308 …: refused, the reference must lie within the limits ± a turn: tests/studies/cli/test_ik_near.py)
def test_huge_joint_values_in_range_answer_without_warnings(capsys, argv):
    """Revolute joints at any finite angle, prismatic ones within the range: the answer comes with the
    CLI's own limit warnings only (no numpy RuntimeWarning), finite in JSON."""
    code, out, err = run_strict(capsys, *argv)
    assert code in (0, 1), err
    assert "Warning" not in err and "Traceback" not in err, err
    assert all(line.startswith("rmt: warning: joint") for line in err.splitlines()), err
    if "--json" in argv:
        json.loads(out, parse_constant=lambda c: pytest.fail(f"non-finite {c} in JSON"))


def test_jacobian_json_fields_and_units(capsys):
    code, out, _ = run(capsys, "jacobian", "scara_rrp", "0.3", "1.0", "-150", "--json")
    assert code == 0
    d = json.loads(out)
    J = np.array(d["J"])
    assert J.shape == (6, 3)
    # SCARA (mm): det of the position Jacobian = 101250 sin q2 mm² (docs/machines.md §2), rows x y z;
    # the measures are SI (issue 29, finding 6): 0.10125 sin q2 m², σ_min of J with its rows in m
    assert d["task_rows"] == ["x", "y", "z"] and d["units"]["measures"] == "SI"
    assert d["det"] == pytest.approx(101250e-6 * math.sin(1.0), rel=1e-12)
    assert d["manipulability"] == pytest.approx(abs(d["det"]), rel=1e-12)
    J_si = J[:3] * np.array([1e-3, 1e-3, 1.0])          # mm/rad → m/rad (revolute); mm/mm = m/m (prismatic)
    s = np.linalg.svd(J_si, compute_uv=False)
    assert d["sigma_min"] == pytest.approx(s[-1], rel=1e-10)
    assert d["condition"] == pytest.approx(s[0] / s[-1], rel=1e-10)


def test_jacobian_singular_condition_is_null(capsys):
    code, out, _ = run(capsys, "jacobian", "planar_2r", "0.4", "0", "--json")
    d = json.loads(out)
    assert d["det"] == pytest.approx(0.0, abs=1e-15)
    assert d["condition"] is None or d["condition"] > 1e12


def test_ik_success_and_failure_exit_codes(capsys):
    code, out, _ = run(capsys, "ik", "puma560", "--xyz", "411.48", "149.09", "489.32", "--rpy", "0", "0", "0",
                       "--json")
    d = json.loads(out)
    assert code == 0 and d["success"] is True
    assert d["position_error"] < 1e-3 and d["orientation_error"] < 1e-4
    # the solution really reaches the target: check with fk
    code, out, _ = run(capsys, "fk", "puma560", *map(str, d["q"]), "--json")
    np.testing.assert_allclose(json.loads(out)["position"], [411.48, 149.09, 489.32], atol=1e-4)
    code, out, _ = run(capsys, "ik", "puma560", "--xyz", "5000", "0", "0", "--json")
    d = json.loads(out)
    assert code == 1 and d["success"] is False
    # the PUMA's reach is under 1 m, so the residual is at least 4 m
    assert d["position_error"] > 4000


@pytest.mark.parametrize("argv, fragment", [
    (["fk", "nosuchrobot", "0"], "unknown robot 'nosuchrobot'"),
    (["fk", "fanuc_m16ib20", "0", "0"], "got 2 values; fanuc_m16ib20 has 6 joints"),
    (["fk", "fanuc_m16ib20", "0", "0", "x", "0", "0", "0"], "'x' is not a number"),
    (["fk", "fanuc_m16ib20", "0", "0", "inf", "0", "0", "0"], "not a finite number"),
    (["ik", "fanuc_m16ib20", "--xyz", "1", "2"], "--xyz"),
    (["nosuchcommand"], "invalid choice"),
    (["fk", "/nonexistent/robot.toml", "0"], "no such robot file"),
])
def test_bad_input_exit_2_one_line(capsys, argv, fragment):
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rmt: error:")
    assert fragment in lines[0]


def test_broken_robot_file_exit_2(capsys, tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text('name = "bad"\nconvention = "standard"\nlength_unit = "m"\nangle_unit = "rad"\n'
                 '[[joints]]\ntype = "revolute"\nlimits = [-170, 170]\n')
    code, out, err = run(capsys, "fk", str(f), "0")
    assert code == 2
    assert str(f) in err and "joints[0].limits" in err and "degree" in err


def test_study_file_writes_results(tmp_path, capsys):
    from studies.study.kinematics import DEFAULT_STUDY
    code, out, _ = run(capsys, "study", str(DEFAULT_STUDY), "--out", str(tmp_path))
    assert code == 0
    path = tmp_path / "fanuc_m16ib20" / "results.json"
    d = json.loads(path.read_text())
    assert d["robot"]["name"] == "fanuc_m16ib20"
    zero = d["configurations"][0]
    # docs/machines.md §3: q = 0 -> p = (1.02, 0, 1.365), R = I; and q5 = 0 is the wrist singularity
    np.testing.assert_allclose(zero["position"], [1.02, 0, 1.365], atol=1e-12)
    assert zero["sigma_min"] < 1e-12 and zero["det"] == pytest.approx(0.0, abs=1e-12)
    assert str(path.with_name("report.html")) in out


def test_console_script_no_traceback():
    # the real entry point in a subprocess: exit code 2 and no traceback on a bad robot
    proc = subprocess.run([sys.executable, "-m", "studies.cli", "fk", "nosuch", "0"], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and proc.stderr.count("\n") == 1


def test_negative_values_in_exponent_form(capsys):
    code, out, _ = run(capsys, "fk", "fanuc_m16ib20", "-1e-3", "-2.5E-1", "0", "0", "0", "0", "--json")
    assert code == 0
    code2, out2, _ = run(capsys, "fk", "fanuc_m16ib20", "-0.001", "-0.25", "0", "0", "0", "0", "--json")
    assert json.loads(out) == json.loads(out2)


def test_show_lists_link_masses_and_torque_limits(capsys):
    """The UR5e's published masses (UR's DH/dynamics article: 3.761, 8.058, 2.846, 1.37, 1.3, 0.365 kg)
    and torque limits (150 × 3, 28 × 3 N·m) in text and JSON; a file without them says so."""
    code, out, _ = run(capsys, "show", "ur5e", "--json")
    d = json.loads(out)["dynamics"]
    assert [j["mass_kg"] for j in d["joints"]] == [3.761, 8.058, 2.846, 1.37, 1.3, 0.365]
    assert [j["max_torque"] for j in d["joints"]] == [150.0] * 3 + [28.0] * 3
    assert d["gravity"] == [0.0, 0.0, -9.81]
    code, out, _ = run(capsys, "show", "ur5e")
    assert code == 0 and " 2 mass     8.058 kg   max torque      150" in out
    code, out, _ = run(capsys, "show", "scara_rrp")
    assert "no inertial data or torque limits" in out


def test_jacobian_sigma_min_is_si_on_a_degree_robot(capsys):
    """ur5e is written in degrees: σ_min printed is the SI one (numpy Jacobian), not per degree."""
    import kin
    from tests.dh_numpy import jacobian_numpy
    q = [0, -90, 90, -90, -90, 0]
    s = np.linalg.svd(jacobian_numpy(kin.load_chain("ur5e"), np.radians(q)), compute_uv=False)[-1]
    code, out, _ = run(capsys, "jacobian", "ur5e", *map(str, q), "--json")
    assert code == 0 and json.loads(out)["sigma_min"] == pytest.approx(s, rel=1e-9)
    code, out, _ = run(capsys, "jacobian", "ur5e", *map(str, q))
    assert f"sigma_min {s:.6g}" in out and "(SI: J in m/s and rad/s per rad/s or m/s)" in out
