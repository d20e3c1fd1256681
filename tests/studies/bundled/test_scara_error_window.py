"""The scara_error_window study in quick mode, checked against independent values: the FK numbers
and the closed form det Jv = 101250·sin θ2 of docs/machines.md §2, σ_min of a numpy planar
Jacobian at the window edges, the workspace's closed-form radii, strict JSON and the report."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.studies.bundled.common import assert_report_holds, assert_report_renders, quick_run

A = 225.0            # every link's a (mm), docs/machines.md §2
FOREARM = 2 * A      # a2 + a3: the prismatic joint's link carries the tool another 225 mm
Q2_LIMIT = 2.53      # rad



@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return quick_run("scara_error_window", tmp_path_factory)


def _sigma_min_planar_m(q2: float) -> float:
    """σ_min (m/rad) of the SCARA's planar position Jacobian (θ1 = 0) in numpy; the prismatic column is
    (0, 0, 1) and decoupled, so this is σ_min of the whole position Jacobian."""
    a, L = A * 1e-3, FOREARM * 1e-3
    J = np.array([[-L * math.sin(q2), -L * math.sin(q2)], [a + L * math.cos(q2), L * math.cos(q2)]])
    return float(np.linalg.svd(J, compute_uv=False).min())


def test_study_ran_ok_and_json_isstrict_json(run):
    d = run.results
    assert run.copied.returncode == 0 and d["ok"] is True
    assert d["quick"] is True and d["study"] == "scara_error_window"
    assert all(f["ok"] for f in d["findings"]) and len(d["findings"]) == 5


def test_fk_matches_machines_md(run):
    d = run.results
    got = {c["label"]: c["position"] for c in d["configurations"]}
    assert got["FK(0, 0, −197)"] == pytest.approx([675.0, 0.0, -195.0], abs=0.01)
    assert got["FK(0.5, 1.0, −150)"] == pytest.approx([229.29, 556.74, -148.0], abs=0.01)
    # and the closed form of the planar arm: r = a1·(c1, s1) + (a2 + a3)·(c12, s12), z = d1 + d2 + d3
    q1, q2, d3 = 0.5, 1.0, -150.0
    closed = [A * math.cos(q1) + FOREARM * math.cos(q1 + q2), A * math.sin(q1) + FOREARM * math.sin(q1 + q2), 2 + d3]
    assert got["FK(0.5, 1.0, −150)"] == pytest.approx(closed, abs=1e-9)


def test_one_factor_matching_the_closed_form(run):
    d = run.results
    factors = d["singularities"]["factors"]
    assert len(factors) == 1
    f = factors[0]
    assert f["joints"] == [2] and f["solutions"]["values"] == [0.0]
    chk = d["det_check"]
    # det Jv / factor is the closed form's constant 101250 mm² (factor sin q2), to rounding
    lo, hi = chk["det_over_factor_mm2"]
    assert lo == pytest.approx(101250.0, rel=1e-9) and hi == pytest.approx(101250.0, rel=1e-9)
    assert chk["max_abs_difference_mm2"] < 1e-6 and chk["samples"] > 0


def test_windows_against_the_thesis_and_numpy_sigma_min(run):
    d = run.results
    w = d["window_widths_rad"]
    assert w["thesis"] == 0.01
    learned = d["learned"]
    assert learned["status"] == "ok" and learned["width_joints"] == ["q2"]
    (lo, hi), = learned["intervals"]
    assert lo < 0 < hi and hi == pytest.approx(-lo) and hi == pytest.approx(w["learned"]) and w["learned"] > 0
    # the thesis's published window beside ours (studies.published, not the core)
    published = learned["published"]
    assert published["interval"] == [-0.01, 0.01] and published["joint"] == "q2" and published["width"] == 0.01
    assert "thesis" in published["source"] and published["ours_width"] == w["learned"]
    assert published["ours_over_published"] == pytest.approx(w["learned"] / 0.01)
    # the learned width is the largest joint-2 error at the singular poses: at least their p95
    assert w["learned"] >= learned["singular_errors"]["p95"][1]
    lo_t, hi_t = w["learned_range_over_training"]
    assert lo_t <= w["learned"] <= hi_t
    # the σ_min window: σ_min (numpy) at its edge is at least the threshold, well inside it is below
    t = w["sigma_min_threshold"]
    assert t == pytest.approx(0.1 / 5.0)
    (slo, shi), = d["windows"]["sigma_min"]["windows"][0]["intervals"]
    assert slo < 0 < shi and shi == pytest.approx(w["sigma_min"])
    assert _sigma_min_planar_m(shi) >= t
    assert _sigma_min_planar_m(shi / 1.5) < t
    assert w["sigma_min_at_thesis_edge"] == pytest.approx(_sigma_min_planar_m(0.01), rel=1e-9)
    assert d["windows"]["learned"]["windows"][0]["method"] == "learned"


def test_workspace_is_the_annulus_times_the_stroke(run):
    b = run.results["workspace_bounds_mm"]
    inner = math.sqrt(A**2 + FOREARM**2 + 2 * A * FOREARM * math.cos(Q2_LIMIT))
    assert b["outer_radius"]["closed_form"] == pytest.approx(675.0)
    assert b["inner_radius"]["closed_form"] == pytest.approx(inner)
    assert inner - 1e-6 <= b["inner_radius"]["sampled"] < inner + 5.0
    assert 670.0 < b["outer_radius"]["sampled"] <= 675.0 + 1e-6
    assert b["z"]["closed_form"] == pytest.approx([-295.0, -95.0])
    zlo, zhi = b["z"]["sampled"]
    assert -295.0 - 1e-6 <= zlo < -290.0 and -100.0 < zhi <= -95.0 + 1e-6
    assert run.results["workspace"]["radial_reach"] == pytest.approx(0.675, abs=5e-3)


def test_report_holds_the_numbers_and_the_plots(run):
    report, d = run.report, run.results
    w = d["window_widths_rad"]
    assert_report_holds(report, d, ("101250", "675", "229.29", "556.74", "±0.01 rad", "[−0.01, 0.01]",
                 f"±{w['learned']:.3g} rad", f"±{w['sigma_min']:.3g} rad", "sin(q2)"),
                        ("sigma_min_across_window.png", "learned_error_across_branch.png", "workspace.png"))


def test_report_renders_in_a_browser(run, report_browser):
    report, results = run.report, run.results
    assert_report_renders(report_browser, report, results)
