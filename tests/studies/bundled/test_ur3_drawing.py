"""The ur3_drawing study in quick mode, checked against independent values: a numpy DH product of the
homework arm (docs/machines.md §6 table, with the pen d6 = 0.1218 m), the closed form of the drawing's
two shoulder solutions (θ1 = 0, or tan(θ1/2) = y/d4, with |sin θ5| = |sin θ1|, for a pen held along −x
with its wrist point at x = d4), the forced-window statement with its share (all waypoints in pose
and pen-axis mode), the homework Jacobian's blow-up, strict JSON, the report's numbers and figures."""
from __future__ import annotations

import math

import numpy as np
import pytest

from studies.study.drawing import pen_robot, wrist_branches
from tests.studies.bundled.common import assert_report_holds, assert_report_renders, quick_run

H = math.pi / 2
# docs/machines.md §6, with the pen: rows (θ offset, α, a, d)
DH = [(H, H, 0.0, 0.1833), (H, 0.0, 0.73731, 0.0), (0.0, 0.0, 0.3878, 0.0), (H, H, 0.0, -0.0955),
      (0.0, H, 0.0, 0.1155), (0.0, 0.0, 0.0, 0.1218)]
D4 = -0.0955
START_TIP = (-0.2173, -0.3878, 1.03611)        # docs/machines.md §6
N = 5001                                       # 5 segments × 1000 points + the start



def _frames(q) -> list[np.ndarray]:
    """T_0 … T_6 by A_i = Rz(θ)·Tz(d)·Tx(a)·Rx(α), in numpy."""
    T = np.eye(4)
    out = [T]
    for (off, al, a, d), qi in zip(DH, q):
        th = off + qi
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
        T = T @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d],
                          [0, 0, 0, 1.0]])
        out.append(T)
    return out


def _jacobian(q) -> np.ndarray:
    F = _frames(q)
    on = F[-1][:3, 3]
    return np.column_stack([np.r_[np.cross(F[i][:3, 2], on - F[i][:3, 3]), F[i][:3, 2]] for i in range(6)])


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return quick_run("ur3_drawing", tmp_path_factory)


def test_study_ran_ok_and_json_isstrict_json(run):
    d = run.results
    assert run.copied.returncode == 0 and d["ok"] is True
    assert d["quick"] is True and d["study"] == "ur3_drawing"
    assert all(f["ok"] for f in d["findings"]) and len(d["findings"]) == 8


def test_start_pose_and_the_singular_family_in_numpy():
    # the pen tip of docs/machines.md §6, and the family θ1 = θ5 = 0: pen along −x, tip at x = d4 − d6,
    # J singular — whatever θ2, θ3, θ4, θ6 (so every point of a drawing in that plane can lie on it)
    T = _frames([0, 0, H, -H, 0, 0])[-1]
    np.testing.assert_allclose(T[:3, 3], START_TIP, atol=1e-5)
    rng = np.random.default_rng(0)
    for _ in range(20):
        q = [0.0, *rng.uniform(-3, 3, 3), 0.0, rng.uniform(-3, 3)]
        T = _frames(q)[-1]
        np.testing.assert_allclose(T[:3, 2], [-1, 0, 0], atol=1e-12)
        assert T[0, 3] == pytest.approx(D4 - 0.1218, abs=1e-12)
        assert np.linalg.svd(_jacobian(q), compute_uv=False)[-1] < 1e-12


def test_wrist_branches_closed_form_against_numpy_fk():
    # for random configurations, the closed form recovers q1 as one of its two θ1 and |sin q5| on it
    robot = pen_robot()
    rng = np.random.default_rng(1)
    Q = rng.uniform(-3, 3, (50, 6))
    poses = np.array([_frames(q)[-1] for q in Q])
    for q, T in zip(Q, poses):
        res = wrist_branches(robot, T[None], math.radians(5), theta1_start=q[0])
        assert math.remainder(res["start_branch"]["theta1_rad"][0] - q[0], 2 * math.pi) == pytest.approx(0, abs=1e-9)
        assert res["start_branch"]["abs_sin_theta5"][0] == pytest.approx(abs(math.sin(q[4])), abs=1e-9)


def test_the_path_forces_the_wrist_window_on_every_waypoint(run):
    d = run.results
    fb = d["forced_by_path"]
    assert fb["forced"] is True and fb["waypoints"] == N
    sb, ob = fb["start_branch"], fb["other_branch"]
    assert sb["waypoints_in_window"] == N and sb["share_in_window"] == 1.0
    assert max(abs(x) for x in sb["theta1_rad"]) < 1e-12 and sb["abs_sin_theta5"][1] < 1e-12
    # the other shoulder solution: tan(θ1/2) = y/d4 over y ∈ [y0 − R, y0 + R], |sin θ5| = |sin θ1|
    y = np.array([START_TIP[1] + 0.05, START_TIP[1] - 0.05])
    th = 2 * np.arctan(y / D4)
    assert ob["theta1_rad"] == pytest.approx(sorted(th), abs=1e-9)
    assert ob["abs_sin_theta5"] == pytest.approx(sorted(np.abs(np.sin(th))), abs=1e-9)
    assert ob["waypoints_in_window"] == 0
    # the follower's own probe agrees: no way out at any of the 5000 steps, pose and pen-axis mode
    assert fb["follower_forced_steps"] == {"pose": N - 1, "axis": N - 1}
    m = d["methods"]
    for key in ("naive", "qp_pose", "qp_axis"):
        assert m[key]["waypoints_in_window"] == N and m[key]["share_in_window"] == 1.0, key
        assert m[key]["forced_by_path"] is True and "forced by the path" in m[key]["verdict"], key
        assert m[key]["within_tolerance"] is True
    assert m["qp_position"]["forced_by_path"] is False and "not forced" in m["qp_position"]["verdict"]
    assert 0 < m["qp_position"]["share_in_window"] < 0.1
    assert m["qp_position"]["windows_entered"][0]["ranges"][0][0] == 0


def test_naive_method_with_the_homework_jacobian_blows_up(run):
    m = run.results["methods"]
    hw, qp = m["naive_homework"], m["qp_pose"]
    assert hw["max_position_error_m"] > 0.1 and hw["within_tolerance"] is False
    assert hw["peak_joint_speed_rad_s"] > 1e6 * qp["peak_joint_speed_rad_s"]
    assert hw["forced_by_path"] is None and hw["verdict"].startswith("fails")
    # the tolerated methods: ≤ 1 mm, and the follower's joint speeds stay below π rad/s
    for key in ("naive", "qp_pose", "qp_axis", "qp_position"):
        assert m[key]["max_position_error_m"] <= 1e-3
    assert qp["peak_joint_speed_rad_s"] < math.pi
    assert qp["median_sigma"] < 1e-6 < m["qp_position"]["median_sigma"]


def test_window_width_does_not_change_what_the_path_forces(run):
    d = run.results
    sweep = d["window_width_sweep"]
    assert {r["half_width_deg"] for r in sweep} == {2.0, 20.0}
    for r in sweep:
        if r["mode"] == "pose":
            assert r["share_in_window"] == 1.0 and r["forced_steps"] == N - 1
        assert r["within_tolerance"] and r["max_position_error_m"] <= 1e-3
    pos = {r["half_width_deg"]: r for r in sweep if r["mode"] == "position"}
    # a narrow window: out within the first second, never forced
    assert pos[2.0]["last_waypoint_in_window"] < 250 and pos[2.0]["forced_steps"] == 0
    # a wide one: the one-step test finds no way out, the follower stays in — said in a finding
    assert pos[20.0]["share_in_window"] == 1.0 and pos[20.0]["forced_steps"] == N - 1
    assert any("±20° window the follower in position mode stays in" in f["text"] for f in d["findings"])


def test_report_holds_the_numbers_and_the_plots(run):
    report, d = run.report, run.results
    m = d["methods"]
    assert_report_holds(report, d, (f"{N}/{N} waypoints", "forced by the path", "not forced",
                                    "θ5 = 0 at all 5001 waypoints",
                                    f"{m['naive_homework']['peak_joint_speed_rad_s']:.3g}", "ur3_homework_pen.toml"),
                        ("theta5_along_drawing.png", "drawn.png", "speeds_and_errors.png"))


def test_report_renders_in_a_browser(run, report_browser):
    report, results = run.report, run.results
    assert_report_renders(report_browser, report, results, numbers=(f"{N}/{N}", "forced by the path"))
