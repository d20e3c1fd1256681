"""The cnc_rrrppp study in quick mode, checked against a numpy DH re-implementation of both chains
(the table of docs/machines.md §4, and the same with the fixed θ of joints 4–6 as ∓90, ±90 rad):
FK of both at every compared configuration, the constant rotation between them, det J / sin θ2 of a
numpy geometric Jacobian, strict JSON and the report."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.studies.bundled.common import assert_report_holds, assert_report_renders, quick_run

H = math.pi / 2
# docs/machines.md §4: (a, α, d, θ) per joint; None marks the joint variable
A = [0.6, 0.5, 0.5, 0.4, 0.5, 0.5]
ALPHA = [-H, H, -H, -H, -H, -H]
D = [0.5, 0.5, 0.5, None, None, None]
THETA = {"correct": [None, None, None, -H, H, -H], "slipped": [None, None, None, -90.0, 90.0, -90.0]}



def _frames(q, model: str) -> list[np.ndarray]:
    """T_0, T_1, …, T_6 by the standard DH product A_i = Rz(θ)·Tz(d)·Tx(a)·Rx(α), in numpy."""
    T = np.eye(4)
    out = [T]
    for i in range(6):
        th = q[i] if THETA[model][i] is None else THETA[model][i]
        d = q[i] if D[i] is None else D[i]
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(ALPHA[i]), math.sin(ALPHA[i])
        Ai = np.array([[ct, -st * ca, st * sa, A[i] * ct],
                       [st, ct * ca, -ct * sa, A[i] * st],
                       [0.0, sa, ca, d],
                       [0.0, 0.0, 0.0, 1.0]])
        T = T @ Ai
        out.append(T)
    return out


def _jacobian(q, model: str) -> np.ndarray:
    """The geometric Jacobian (rows v, ω) from the numpy frames: revolute [z × (o_n − o); z], prismatic [z; 0]."""
    F = _frames(q, model)
    on = F[-1][:3, 3]
    J = np.zeros((6, 6))
    for i in range(6):
        z, o = F[i][:3, 2], F[i][:3, 3]
        J[:, i] = np.r_[np.cross(z, on - o), z] if i < 3 else np.r_[z, np.zeros(3)]
    return J


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return quick_run("cnc_rrrppp", tmp_path_factory)


def test_study_ran_ok_and_json_isstrict_json(run):
    d = run.results
    assert run.copied.returncode == 0 and d["ok"] is True
    assert d["quick"] is True and d["study"] == "cnc_rrrppp"
    assert all(f["ok"] for f in d["findings"]) and len(d["findings"]) == 3


def test_both_models_match_a_numpy_dh_product(run):
    configs = run.results["slip"]["configurations"]
    assert len(configs) >= 4
    for c in configs:
        for model in ("correct", "slipped"):
            np.testing.assert_allclose(c[f"T_{model}"], _frames(c["q"], model)[-1], atol=1e-12, err_msg=c["label"])
        Tc, Ts = _frames(c["q"], "correct")[-1], _frames(c["q"], "slipped")[-1]
        assert c["position_difference_m"] == pytest.approx(np.linalg.norm(Tc[:3, 3] - Ts[:3, 3]), abs=1e-12)
    home = next(c for c in configs if c["label"] == "home")
    np.testing.assert_allclose(np.array(home["T_correct"])[:3, 3], [2.1, 0.0, 1.4], atol=1e-12)
    # the slip is not a small change: the tool lands tens of centimetres away everywhere
    assert min(c["position_difference_m"] for c in configs) > 0.1


def test_rotation_between_the_models_is_the_fixed_rotation_of_the_linear_axes(run):
    d = run.results["slip"]
    # R = R_03(q)·R_fixed, so R_correctᵀ·R_slipped = R_fixed,correctᵀ·R_fixed,slipped for every q
    q0 = [0.3, -0.4, 0.9, 0.0, 0.0, 0.0]
    Fc, Fs = _frames(q0, "correct"), _frames(q0, "slipped")
    Rfc = np.linalg.inv(Fc[3][:3, :3]) @ Fc[6][:3, :3]
    Rfs = np.linalg.inv(Fs[3][:3, :3]) @ Fs[6][:3, :3]
    angle = math.degrees(math.acos(np.clip((np.trace(Rfc.T @ Rfs) - 1) / 2, -1, 1)))
    lo, med, hi = d["random"]["rotation_difference_deg"]
    assert lo == pytest.approx(angle, abs=1e-6) and hi == pytest.approx(angle, abs=1e-6)
    for c in d["configurations"]:
        assert c["rotation_difference_deg"] == pytest.approx(angle, abs=1e-6)
    plo, pmed, phi = d["random"]["position_difference_m"]
    assert 0 < plo <= pmed <= phi


def test_singularity_survives_the_slip(run):
    sing = run.results["singularity"]
    assert sing["correct"]["factors"] == ["sin(q2)"] and sing["slipped"]["factors"] == ["sin(q2)"]
    assert [f["expr"] for f in run.results["singularities"]["factors"]] == ["sin(q2)"]
    rng = np.random.default_rng(3)
    for model in ("correct", "slipped"):
        ratios = []
        for _ in range(20):
            q = rng.uniform([-1.74, -1.74, -1.74, -0.4, -0.3, -0.4], [1.74, 1.74, 1.74, 0.4, 0.3, 0.4])
            ratios.append(np.linalg.det(_jacobian(q, model)) / math.sin(q[1]))
        k = float(np.mean(ratios))
        assert np.ptp(ratios) < 1e-9
        lo, hi = sing[model]["det_over_sin_q2"]
        assert lo == pytest.approx(k, abs=1e-9) and hi == pytest.approx(k, abs=1e-9)
        # det Z of the linear axes works out to sin(θ of joint 5)
        assert sing[model]["det_Z"] == pytest.approx(math.sin(THETA[model][4]), abs=1e-9)
    assert sing["correct"]["det_over_sin_q2"][0] == pytest.approx(1.0, abs=1e-9)
    assert sing["slipped"]["det_over_sin_q2"][0] == pytest.approx(math.sin(90.0), abs=1e-9)


def test_slipped_file_is_refused_and_workspaces_are_reported(run):
    d = run.results
    assert "joints[3].theta" in d["slipped_file_refused"] and "-90" in d["slipped_file_refused"]
    ws, wss = d["workspace"], d["workspace_slipped"]
    assert ws["counts"]["samples"] == wss["counts"]["samples"] > 0
    # reach: no tool point beyond the sum of every offset and the longest strokes
    bound = sum(A) + 1.5 + 0.4 + 0.3 + 0.4
    assert 0 < ws["reach"] < bound and 0 < wss["reach"] < bound and ws["reach"] != pytest.approx(wss["reach"])
    assert d["workspace_shift_m"] > 0


def test_report_holds_the_numbers_and_the_plots(run):
    report, d = run.report, run.results
    lo, _, hi = d["slip"]["random"]["position_difference_m"]
    angle = d["slip"]["random"]["rotation_difference_deg"][1]
    assert_report_holds(report, d, (f"{lo:.2f}–{hi:.2f} m", "sin(q2)", "0.894", f"{angle:.2f}°", "exceeds ±25.1327"),
                        ("det_across_q2.png", "workspace.png", "workspace_slipped.png"))


def test_report_renders_in_a_browser(run, report_browser):
    report, results = run.report, run.results
    assert_report_renders(report_browser, report, results)
