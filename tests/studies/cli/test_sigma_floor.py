"""The default σ_min floor of ``rmt plan``, ``check-path`` and ``validate-toolpath`` (issue 29, finding 3):
without options a path through a singularity is flagged (exit 1); ``--no-singularity-check`` and
``--sigma-floor S`` (0 allowed) change it; the output says which floor was used and where it came
from.  σ_min is recomputed here from a plain-numpy Jacobian (tests/dh_numpy.py)."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from studies.cli import main
from tests.dh_numpy import fk_numpy, jacobian_numpy

#: a CNC configuration family: q2 = 0 is its singularity (det J ∝ sin q2, docs/machines.md §4)
CNC_Q = np.array([0.2, 0.0, 0.3, 0.1, 0.05, -0.1])
UR_HOME = ["0", "-90", "90", "-90", "-90", "0"]
UR_ACROSS = ["30", "-80", "80", "-90", "90", "0"]      # q5 from −90° to 90°: through the wrist singularity q5 = 0


def _cli(argv, capsys):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def _sigma(chain, Q) -> np.ndarray:
    return np.array([np.linalg.svd(jacobian_numpy(chain, q), compute_uv=False).min() for q in np.atleast_2d(Q)])


def _rpy(R) -> list[float]:
    """Fixed-axis roll, pitch, yaw of R = Rz(yaw)·Ry(pitch)·Rx(roll) (away from pitch ±90°)."""
    return [float(np.arctan2(R[2, 1], R[2, 2])), float(-np.arcsin(R[2, 0])), float(np.arctan2(R[1, 0], R[0, 0]))]


@pytest.fixture(scope="module")
def contour_cross(tmp_path_factory):
    """A CNC tool path (poses by numpy FK) whose middle waypoint is the singular q2 = 0."""
    chain = kin.load_chain("cnc_rrrppp")
    lines = ["x,y,z,roll,pitch,yaw"]
    for q2 in np.linspace(-0.3, 0.3, 13):
        T = fk_numpy(chain, CNC_Q + [0, q2, 0, 0, 0, 0])
        lines.append(",".join(f"{v:.12f}" for v in [*T[:3, 3], *_rpy(T[:3, :3])]))
    assert _sigma(chain, CNC_Q)[0] < 1e-12
    path = tmp_path_factory.mktemp("floor") / "contour_cross.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_validate_toolpath_flags_a_singular_path_by_default(capsys, contour_cross):
    rc, out, _ = _cli(["validate-toolpath", "cnc_rrrppp", str(contour_cross)], capsys)
    assert rc == 1 and out.startswith("INVALID: first problem at waypoint 6 of 13")
    assert "sigma_min — σ_min = " in out and "< 0.001 (SI)" in out
    assert "σ_min floor         default floor of cnc_rrrppp, 0.001 (SI)" in out
    rc, out, _ = _cli(["validate-toolpath", "cnc_rrrppp", str(contour_cross), "--json"], capsys)
    d = json.loads(out)
    assert rc == 1 and not d["valid"] and d["first_problem"]["kind"] == "sigma_min"
    assert d["sigma_floor"] == {"value": 0.001, "source": "rule", "text": "default floor of cnc_rrrppp, 0.001 (SI)",
                                "unit": "SI"}
    # σ_min at the flagged waypoint is the numpy Jacobian's, below the floor
    assert d["min_sigma"] < 1e-3 and d["min_sigma_index"] == 6


@pytest.mark.parametrize("extra, text", [(["--no-singularity-check"], "off (--no-singularity-check)"),
                                         (["--sigma-floor", "0"], "--sigma-floor 0 (SI)")])
def test_validate_toolpath_floor_off_or_zero(capsys, contour_cross, extra, text):
    rc, out, _ = _cli(["validate-toolpath", "cnc_rrrppp", str(contour_cross), *extra], capsys)
    assert rc == 0 and out.startswith("VALID"), out
    assert f"σ_min floor         {text}" in out


def test_validate_toolpath_explicit_floor(capsys, contour_cross):
    """--sigma-floor 0.5: above σ_min at waypoints away from q2 = 0 too (numpy σ_min of the first one)."""
    chain = kin.load_chain("cnc_rrrppp")
    s0 = _sigma(chain, CNC_Q + [0, -0.3, 0, 0, 0, 0])[0]
    floor = 1.01 * s0
    rc, out, _ = _cli(["validate-toolpath", "cnc_rrrppp", str(contour_cross), "--sigma-floor", f"{floor}", "--json"],
                      capsys)
    d = json.loads(out)
    assert rc == 1 and d["first_problem"]["index"] == 0 and d["sigma_floor"]["source"] == "--sigma-floor"


def test_check_path_flags_the_wrist_singularity_by_default(capsys, tmp_path):
    path = tmp_path / "across.csv"
    path.write_text(",".join(UR_HOME) + "\n" + ",".join(UR_ACROSS) + "\n")
    chain = kin.load_chain("ur5e")
    Q = np.radians([[float(x) for x in UR_HOME], [float(x) for x in UR_ACROSS]])
    t = np.linspace(0, 1, 2001)[:, None]
    assert _sigma(chain, Q[0] + t * (Q[1] - Q[0])).min() < 1e-6         # the straight line passes σ_min ≈ 0
    rc, out, _ = _cli(["check-path", "ur5e", str(path)], capsys)
    assert rc == 1 and out.startswith("INVALID at row 0: sigma_min — σ_min = ")
    assert "σ_min floor: default floor of ur5e, 0.001 (SI)" in out
    rc, out, _ = _cli(["check-path", "ur5e", str(path), "--json"], capsys)
    d = json.loads(out)
    assert rc == 1 and d["first_violation"]["kind"] == "sigma_min" and d["sigma_check"] == "proven"
    assert d["sigma_floor"]["source"] == "rule" and d["sigma_floor"]["value"] == 1e-3
    rc, out, _ = _cli(["check-path", "ur5e", str(path), "--no-singularity-check"], capsys)
    assert rc == 0 and out.startswith("valid:") and "σ_min floor: off (--no-singularity-check)" in out


def test_check_path_takes_the_robot_files_floor(capsys, tmp_path):
    text = kin.dumps_robot(kin.load_chain("ur5e")).replace('angle_unit = "deg"\n',
                                                          'angle_unit = "deg"\nsigma_floor = 0\n')
    robot = tmp_path / "ur5e_nofloor.toml"
    robot.write_text(text)
    path = tmp_path / "across.csv"
    path.write_text(",".join(UR_HOME) + "\n" + ",".join(UR_ACROSS) + "\n")
    rc, out, _ = _cli(["check-path", str(robot), str(path)], capsys)
    assert rc == 0 and "σ_min floor: sigma_floor of the robot file of ur5e, 0 (SI)" in out


def test_plan_keeps_the_default_floor(capsys):
    """Across q5 = 0 no path keeps σ_min ≥ 10⁻³ (every path from q5 = −90° to 90° crosses 0): exit 1 by
    default, with that reason (the wrist factor's sign); --no-singularity-check takes the straight line
    through the singularity."""
    argv = ["plan", "ur5e", "--start", *UR_HOME, "--goal", *UR_ACROSS, "--time-limit", "0.3"]
    rc, out, _ = _cli(argv, capsys)
    assert rc == 1 and "no joint path exists: the wrist factor sin(q5)" in out
    assert "σ_min floor: default floor of ur5e, 0.001 (SI)" in out
    rc, out, _ = _cli([*argv, "--no-singularity-check", "--json"], capsys)
    d = json.loads(out)
    assert rc == 0 and d["success"] and d["sigma_floor"]["source"] == "off"
    P = np.radians(d["path"])
    t = np.linspace(0, 1, 201)[:, None]
    dense = np.vstack([a + t * (b - a) for a, b in zip(P[:-1], P[1:])])
    assert _sigma(kin.load_chain("ur5e"), dense).min() < 1e-4


def test_plan_proves_the_default_floor_along_its_path(capsys):
    rc, out, _ = _cli(["plan", "fanuc_m16ib20", "--start", "0", "-0.8", "0.7", "0.3", "0.8", "0", "--goal", "0.5",
                       "-0.5", "-1.6", "-0.3", "0.9", "0.4", "--margin", "0.05", "--json"], capsys)
    d = json.loads(out)
    assert rc == 0 and d["success"] and d["checks"]["sigma_min"] == "proven"
    assert d["sigma_floor"] == {"value": 0.001, "source": "rule", "unit": "SI",
                                "text": "default floor of fanuc_m16ib20, 0.001 (SI)"}
    P = np.array(d["path"])
    t = np.linspace(0, 1, 401)[:, None]
    dense = np.vstack([a + t * (b - a) for a, b in zip(P[:-1], P[1:])])
    assert _sigma(kin.load_chain("fanuc_m16ib20"), dense).min() >= 1e-3


def test_plan_refuses_a_singular_start_naming_the_floor(capsys):
    rc, _, err = _cli(["plan", "ur5e", "--start", "0", "-90", "90", "-90", "0", "0", "--goal", *UR_HOME], capsys)
    assert rc == 2 and len(err.strip().splitlines()) == 1
    assert "--start: σ_min = " in err and "(default floor of ur5e, 0.001 (SI))" in err
    assert "--no-singularity-check" in err and "Traceback" not in err


@pytest.mark.parametrize("cmd", [["check-path", "ur5e", "x.csv"], ["validate-toolpath", "scara_rrp", "scara_line"],
                                 ["plan", "ur5e", "--start", *UR_HOME, "--goal", *UR_HOME]])
@pytest.mark.parametrize("bad", [["--sigma-floor", "-1"], ["--sigma-floor", "nan"], ["--sigma-floor", "1e9"],
                                 ["--sigma-floor", "0.1", "--no-singularity-check"]])
def test_bad_floor_options_exit_2(capsys, cmd, bad):
    rc, _, err = _cli([*cmd, *bad], capsys)
    assert rc == 2 and "Traceback" not in err
    assert "--sigma-floor" in err or "--no-singularity-check" in err
