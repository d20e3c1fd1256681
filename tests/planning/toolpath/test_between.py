"""The joint motions between tool-path waypoints (``planning.toolpath.between``): a tool line of the
CNC machine cnc_rrrppp (det J ∝ sin q2) whose IK crosses q2 = 0 between two waypoints, built from
the numpy DH forward kinematics, is INVALID at that segment — the sign change of sin q2 is a proof,
and the windows / σ_min floor along the joint segment are proven by check_path."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kin
from planning.toolpath import load_toolpath
from planning.toolpath.check import validate_toolpath
from planning.windows import build_windows
from studies.cli import main
from tests.dh_numpy import fk_numpy

QA = np.array([0.3, -0.2, 0.4, 0.1, 0.1, 0.1])


@pytest.fixture(scope="module")
def cnc():
    return kin.load_robot("cnc_rrrppp")


def line_file(tmp_path, cnc, q2_from: float, q2_to: float, points: int = 3):
    """A straight tool line from the pose at QA with q2 = q2_from to the pose with q2 = q2_to; the
    orientation turns (slerp) about the fixed axis q2 turns about, so the IK's q2 moves linearly:
    waypoint k of points + 1 has q2 = q2_from + k / points · (q2_to − q2_from)."""
    qa, qb = QA.copy(), QA.copy()
    qa[1], qb[1] = q2_from, q2_to
    Ta, Tb = (fk_numpy(cnc.chain, q) for q in (qa, qb))
    rpy = [Rotation.from_matrix(T[:3, :3]).as_euler("xyz") for T in (Ta, Tb)]
    fmt = lambda v: "[" + ", ".join(f"{x:.15g}" for x in v) + "]"   # noqa: E731
    p = tmp_path / "line.toml"
    p.write_text(f'length_unit = "m"\nangle_unit = "rad"\nfeed = 0.05\n\n[start]\nxyz = {fmt(Ta[:3, 3])}\n'
                 f'rpy = {fmt(rpy[0])}\n\n[[segments]]\ntype = "line"\nto = {fmt(Tb[:3, 3])}\nrpy = {fmt(rpy[1])}\n'
                 f'points = {points}\n', encoding="utf-8")
    return p, qa


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_crossing_between_two_waypoints_is_invalid(capsys, tmp_path, cnc):
    path, qa = line_file(tmp_path, cnc, -0.2, 0.2)          # q2: -0.2, -0.0667, +0.0667, +0.2
    for extra in ([], ["--margin", "0.05"]):
        code, out, err = run(capsys, "validate-toolpath", "cnc_rrrppp", path, "--start", *qa, *extra)
        assert code == 1, out + err
        assert out.startswith("INVALID: first problem at the segment from waypoint 1 to 2 of 4"), out
        assert "singular_crossing" in out and "sin(q2)" in out and "proven" in out
        code, out, err = run(capsys, "validate-toolpath", "cnc_rrrppp", path, "--start", *qa, "--json", "--waypoints",
                             *extra)
        d = json.loads(out)
        assert code == 1 and d["valid"] is False
        assert d["first_problem"]["segment"] == [1, 2] and d["first_problem"]["kind"] == "singular_crossing"
        assert d["segment_counts"]["singular_crossing"] == 1
        q2 = np.array(d["per_waypoint"]["q"])[:, 1]
        assert np.allclose(q2, np.linspace(-0.2, 0.2, 4), atol=1e-6)    # the IK the line was built from
        assert not any(d["counts"].values())            # every waypoint is fine on its own


def test_no_crossing_stays_valid(capsys, tmp_path, cnc):
    path, qa = line_file(tmp_path, cnc, 0.2, 0.6)
    code, out, _ = run(capsys, "validate-toolpath", "cnc_rrrppp", path, "--start", *qa, "--margin", "0.05")
    assert code == 0, out
    assert "between waypoints   none (joint motions checked: windows and floor proven" in out


def test_windows_and_floor_proven_along_the_segment(tmp_path, cnc):
    """Without the factors' signs the dense check / proofs of check_path find the same segment."""
    path, qa = line_file(tmp_path, cnc, -0.2, 0.2)
    tp = load_toolpath(path, cnc)
    rep = validate_toolpath(cnc, tp, start_q=qa, sigma_min=1e-3, factors=())
    p = rep.first_problem
    assert p is not None and p.segment and p.index == 1 and p.kind == "sigma_min", rep.verdict()
    at = float(p.detail.split("(at ")[1].split(" of")[0])
    assert "between waypoints 1 and 2" in p.detail and abs(at - 0.5) < 0.01, p.detail     # q2 = 0 mid-way
    ws = build_windows(cnc, margin=0.05)
    rep = validate_toolpath(cnc, tp, windows=ws, start_q=qa, factors=())
    p = rep.first_problem
    assert p is not None and p.segment and p.index == 1 and p.kind == "window", rep.verdict()
    # entering the window |q2| ≤ 0.05 from q2 = -0.0667 towards +0.0667: at (0.0667 − 0.05) / 0.1333 = 0.125
    at = float(p.detail.split("(at ")[1].split(" of")[0])
    assert "between waypoints 1 and 2" in p.detail and 0.125 <= at < 0.14, p.detail
    assert math.isclose(rep.s[1], p.s) and math.isclose(rep.s[2], p.s_end)


def test_no_singularity_check_skips_the_segments(tmp_path, cnc):
    path, qa = line_file(tmp_path, cnc, -0.2, 0.2)
    rep = validate_toolpath(cnc, load_toolpath(path, cnc), start_q=qa)
    assert rep.ok and rep.segments_check is None
