"""The flagship study fanuc_singularities in quick mode, checked against independent values: the DH
table and the q = 0 pose of docs/machines.md §3, a numpy DH product and geometric Jacobian (σ_min by
numpy's SVD), the closed forms of the three singular factors, the weld seam's geometry, strict JSON
and the report's contents."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.dh_numpy import dh_standard
from tests.studies.bundled.common import assert_report_renders, quick_run

#: docs/machines.md §3: rows (a, α, d) in m and rad, and the joint limits
DH = [(0.150, -math.pi / 2, 0.525), (0.770, 0.0, 0.0), (0.100, math.pi / 2, 0.0),
      (0.0, -math.pi / 2, 0.740), (0.0, math.pi / 2, 0.0), (0.0, 0.0, 0.100)]
LOWER = np.array([-2.97, -1.57, -2.97, -3.49, -2.44, -7.85])
UPPER = np.array([2.97, 2.79, 5.06, 3.49, 2.44, 7.85])
A1, A2, A3, D4 = 0.150, 0.770, 0.100, 0.740
#: the elbow factor a3 sin q3 − d4 cos q3 vanishes at atan(d4/a3) + kπ
ELBOW_ROOTS = [math.atan(D4 / A3) + k * math.pi for k in (-1, 0, 1)]
#: the move of studies/default_study.toml
START = [0.0, -0.8, 0.7, 0.3, 0.8, 0.0]
GOAL = [0.5, -0.5, -1.6, -0.3, 0.9, 0.4]



@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return quick_run("fanuc_singularities", tmp_path_factory)


def _frames(q) -> list[np.ndarray]:
    T, out = np.eye(4), [np.eye(4)]
    for (a, alpha, d), th in zip(DH, q):
        T = T @ dh_standard(th, d, a, alpha)
        out.append(T)
    return out


def _jacobian(q) -> np.ndarray:
    F = _frames(q)
    p = F[-1][:3, 3]
    return np.stack([np.concatenate([np.cross(T[:3, 2], p - T[:3, 3]), T[:3, 2]]) for T in F[:-1]], axis=1)


def _sigma_min(q) -> float:
    return float(np.linalg.svd(_jacobian(q), compute_uv=False).min())


def _shoulder(Q: np.ndarray) -> np.ndarray:
    """The shoulder factor a1 + a2 cos q2 + a3 cos(q2+q3) + d4 sin(q2+q3) (m)."""
    q2, q3 = Q[..., 1], Q[..., 2]
    return A1 + A2 * np.cos(q2) + A3 * np.cos(q2 + q3) + D4 * np.sin(q2 + q3)


def _windows(d: dict, key: str) -> dict:
    return {w["kind"]: w for w in d["windows"][key]["windows"]}


def _inside(windows: dict, Q: np.ndarray) -> np.ndarray:
    """Membership in the wrist (q5), elbow (q3) and shoulder (|g| ≤ ε) windows, evaluated here."""
    inside = np.zeros(len(Q), bool)
    for kind, j in (("wrist", 4), ("elbow", 2)):
        for lo, hi in windows[kind]["intervals"]:
            inside |= (Q[:, j] >= lo) & (Q[:, j] <= hi)
    return inside | (np.abs(_shoulder(Q)) <= windows["shoulder"]["epsilon"])


def test_study_ran_ok_and_json_isstrict_json(run):
    report, d = run.report, run.results
    assert run.copied.returncode == 0 and d["ok"] is True
    assert d["quick"] is True and d["study"] == "fanuc_singularities"
    assert len(d["findings"]) == 5 and all(f["ok"] for f in d["findings"])
    for png in ("plan.png", "sigma_across_windows.png", "weld_seam.png", "workspace.png"):
        assert (report.parent / png).stat().st_size > 10_000, png
    assert "plan.csv" in d["meta"]["files"]


def test_dh_table_is_the_documents(run):
    rows = run.results["robot"]["dh"]
    assert np.allclose([(r["a"], r["alpha"], r["d"]) for r in rows], DH, atol=1e-12)
    assert np.allclose([r["limits"] for r in rows], np.stack([LOWER, UPPER], 1))


def test_fk_at_zero_and_at_the_listed_configurations(run):
    d = run.results
    zero = d["configurations"][0]
    assert zero["position"] == pytest.approx([1.02, 0.0, 1.365], abs=1e-12)
    assert zero["deviation"] == pytest.approx(0.0, abs=1e-12) and zero["matches_reference"] is True
    assert d["fk_check"]["q_zero"]["rotation_deviation_from_identity"] < 1e-12
    assert np.allclose(_frames(np.zeros(6))[-1][:3, :3], np.eye(3))        # the reference value itself
    for c in d["configurations"]:
        assert c["position"] == pytest.approx(_frames(c["q"])[-1][:3, 3].tolist(), abs=1e-12), c["label"]
        assert c["sigma_min"] == pytest.approx(_sigma_min(c["q"]), abs=1e-9), c["label"]
    assert d["fk_check"]["numpy_dh"]["max_position_deviation"] < 1e-12


def test_three_factors_wrist_elbow_shoulder(run):
    d = run.results
    factors = {f["kind"]: f for f in d["singularities"]["factors"]}
    assert len(d["singularities"]["factors"]) == 3 and set(factors) == {"wrist", "elbow", "shoulder"}
    assert factors["wrist"]["joints"] == [5] and factors["wrist"]["solutions"]["values"] == pytest.approx([0.0])
    assert factors["elbow"]["joints"] == [3]
    assert factors["elbow"]["solutions"]["values"] == pytest.approx(ELBOW_ROOTS, abs=1e-9)
    assert factors["shoulder"]["joints"] == [2, 3]
    # det J = −a2 · sin q5 · (a3 sin q3 − d4 cos q3) · shoulder, checked here with numpy at random configurations
    rng = np.random.default_rng(5)
    for q in rng.uniform(LOWER, UPPER, size=(50, 6)):
        prod = math.sin(q[4]) * (A3 * math.sin(q[2]) - D4 * math.cos(q[2])) * _shoulder(q)
        assert np.linalg.det(_jacobian(q)) == pytest.approx(-A2 * prod, abs=1e-12)
    assert d["det_check"]["det_over_factors"] == pytest.approx([-A2, -A2], abs=1e-9)


def test_window_widths_and_the_margin_window_of_q5(run):
    d = run.results
    for key in ("margin", "sigma_min", "learned"):
        ws = _windows(d, key)
        assert set(ws) == {"wrist", "elbow", "shoulder"}, key
        assert all(w["width"] > 0 for w in ws.values()), key
    margin = _windows(d, "margin")
    assert margin["wrist"]["intervals"] == [[-0.05, 0.05]]
    assert np.allclose(margin["elbow"]["intervals"], [[r - 0.05, r + 0.05] for r in ELBOW_ROOTS], atol=1e-9)
    comp = d["window_comparison"]
    assert comp["wrist"]["margin"] == 0.05 and comp["wrist"]["sigma_min"] == _windows(d, "sigma_min")["wrist"]["width"]
    assert comp["wrist"]["learned"] == _windows(d, "learned")["wrist"]["width"]
    assert d["learned"]["n_train"] == 10_000 and len(d["learned_training"]) == 2


def test_sigma_windows_bound_sigma_min(run):
    d = run.results
    threshold = d["sigma_requirement"]["threshold"]
    assert threshold == pytest.approx(0.1 / 5.0)
    Q = np.random.default_rng(11).uniform(LOWER, UPPER, size=(4000, 6))
    sig = np.array([_sigma_min(q) for q in Q])
    out = ~_inside(_windows(d, "sigma_min"), Q)
    assert out.sum() > 1000
    assert sig[out].min() >= threshold
    # the check can fail: outside the narrower margin windows σ_min does drop below the threshold
    out_margin = ~_inside(_windows(d, "margin"), Q)
    assert sig[out_margin].min() < threshold
    assert d["sigma_window_check"]["kept"] is True and d["sigma_window_check"]["min_sigma_outside"] >= threshold


def test_plan_succeeds_proven_and_the_straight_line_is_blocked(run):
    d = run.results
    plan = d["plan"]
    assert plan["success"] is True and plan["proven"] is True and plan["straight_line_valid"] is False
    P = np.array(plan["path"])
    assert P[0] == pytest.approx(START) and P[-1] == pytest.approx(GOAL)
    margin = _windows(d, "margin")
    # densely along the path (numpy): outside every margin window and above the σ_min floor
    dense = np.concatenate([a + np.linspace(0, 1, 200)[:, None] * (b - a) for a, b in zip(P[:-1], P[1:])])
    assert not _inside(margin, dense).any()
    assert min(_sigma_min(q) for q in dense[::5]) >= d["sigma_requirement"]["threshold"]
    # the straight line dips into the shoulder window: |g| falls below ε on it
    line = np.array(START) + np.linspace(0, 1, 2001)[:, None] * (np.array(GOAL) - np.array(START))
    assert np.abs(_shoulder(line)).min() < margin["shoulder"]["epsilon"]
    assert d["straight_line"]["inside_margin_windows"]["shoulder"] > 0


def test_weld_seam_valid(run):
    w = run.results["weld_seam"]
    assert w["valid"] is True and w["verdict"].startswith("VALID") and w["same_branch"] is True
    # 380 mm, a quarter circle of 20 mm radius, 280 mm; 10 mm/s
    length = 0.38 + math.pi * 0.02 / 2 + 0.28
    assert w["length"] == pytest.approx(length, abs=1e-9) and w["duration"] == pytest.approx(length / 0.01)
    assert w["min_sigma"] >= 0.02 and w["waypoints_in_windows"] == 0
    # the first configuration puts the flange at the seam's start, the torch down with a 15° push angle
    T = _frames(w["start_q"])[-1]
    assert T[:3, 3] == pytest.approx([1.05, -0.25, 0.35], abs=1e-6)
    s15, c15 = math.sin(math.radians(15)), math.cos(math.radians(15))
    assert T[:3, 2] == pytest.approx([0.0, s15, -c15], abs=1e-6)


def test_report_holds_the_key_numbers(run):
    d, html = run.results, run.report.read_text(encoding="utf-8")
    for text in ("1.02", "1.365", "wrist", "elbow", "shoulder", "the thesis found 1", "proven clear",
                 f"VALID: all {d['weld_seam']['waypoints']} waypoints", "Which windows to trust",
                 "fanuc_weld_seam.toml"):
        assert text in html, text
    for kind, w in _windows(d, "sigma_min").items():
        assert f"{w['width']:.3g}" in html, kind
    assert f"{_windows(d, 'learned')['wrist']['width']:.3g}" in html
    for view in ("workspace_3d", "weld_seam_3d"):             # the two interactive views
        assert f'class="plot3d" data-name="{view}"' in html, view


def test_report_renders_in_a_browser(run, report_browser):
    report, d = run.report, run.results
    ws = _windows(d, "sigma_min")
    assert_report_renders(report_browser, report, d,
                          numbers=("(1.02, 0, 1.365) m", f"±{ws['wrist']['width']:.3g}",
                                   f"VALID: all {d['weld_seam']['waypoints']} waypoints"))
