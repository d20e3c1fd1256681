"""The scara_design study in quick mode, against values computed here independently of the study,
of the IK-verified metric and of the optimisers: the SCARA's reach in closed form, re-derived with
an explicit Jacobian and numpy's SVD.

The machine (docs/machines.md §2, the SCARA of the singularities thesis): revolute J1, J2 with limits
±2.22 and ±2.53 rad and d = 1 mm each, prismatic J3 with stroke −297 … −97 mm; in the design robot
(studies/tasks/robots/scara_design.toml) the arms A1, A2 are the design parameters, 100 … 400 mm.
The task (studies/tasks/scara_box.toml): a 5 × 5 grid on x 150 … 350 mm, y −150 … 150 mm at
z = −150 mm, every target with σ_min ≥ 0.08 m/rad of the translational Jacobian.
"""
from __future__ import annotations

import csv
import json
import sqlite3

import numpy as np
import pytest

from tests.studies.bundled.common import assert_report_holds, assert_report_renders, quick_run

# ------------------------------------------------------------------ the machine and the task, in mm
LIM1, LIM2 = 2.22, 2.53            # |q1|, |q2| limits (rad)
STROKE = (-297.0, -97.0)           # q3 (mm)
Z0 = 2.0                           # d1 + d2 (mm): the tool height at q3 = 0
SIGMA = 0.08                       # m/rad
XS, YS, Z = np.linspace(150, 350, 5), np.linspace(-150, 150, 5), -150.0
TARGETS = np.array([(x, y) for x in XS for y in YS])


def sigma_at(l1: float, l2: float, x: float, y: float) -> float:
    """Best σ_min (m/rad) over the elbow branches within the limits at target (x, y) mm, by an
    explicit IK and the SVD of the 3 × 3 translational Jacobian (m/rad and m/m); −1 when unreachable."""
    c2 = (x * x + y * y - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    if abs(c2) > 1 or not STROKE[0] <= Z - Z0 <= STROKE[1]:
        return -1.0
    best = -1.0
    for q2 in (np.arccos(c2), -np.arccos(c2)):
        q1 = np.arctan2(y, x) - np.arctan2(l2 * np.sin(q2), l1 + l2 * np.cos(q2))
        q1 = (q1 + np.pi) % (2 * np.pi) - np.pi
        if abs(q1) > LIM1 or abs(q2) > LIM2:
            continue
        a, b = l1 / 1e3, l2 / 1e3
        J = np.array([[-a * np.sin(q1) - b * np.sin(q1 + q2), -b * np.sin(q1 + q2), 0.0],
                      [a * np.cos(q1) + b * np.cos(q1 + q2), b * np.cos(q1 + q2), 0.0],
                      [0.0, 0.0, 1.0]])
        # the configuration reaches the target (a check of the IK above)
        assert np.hypot(l1 * np.cos(q1) + l2 * np.cos(q1 + q2) - x, l1 * np.sin(q1) + l2 * np.sin(q1 + q2) - y) < 1e-6
        best = max(best, float(np.linalg.svd(J, compute_uv=False)[-1]))
    return best


def covered_count(l1: float, l2: float) -> int:
    return sum(sigma_at(l1, l2, x, y) >= SIGMA * (1 - 1e-6) for x, y in TARGETS)


def covered_count_vec(l1: np.ndarray, l2: np.ndarray) -> np.ndarray:
    """Targets covered (count) for many designs (D,) mm at once: the same closed form, with σ_min of the
    block-diagonal Jacobian as the smallest eigenvalue of the 2 × 2 block's JᵀJ (numpy eigvalsh)."""
    l1, l2 = np.asarray(l1, float)[:, None], np.asarray(l2, float)[:, None]
    x, y = TARGETS[:, 0][None], TARGETS[:, 1][None]
    c2 = (x ** 2 + y ** 2 - l1 ** 2 - l2 ** 2) / (2 * l1 * l2)
    ok = np.zeros(np.broadcast_shapes(c2.shape), bool)
    for sign in (1, -1):
        q2 = sign * np.arccos(np.clip(c2, -1, 1))
        q1 = np.arctan2(y, x) - np.arctan2(l2 * np.sin(q2), l1 + l2 * np.cos(q2))
        q1 = (q1 + np.pi) % (2 * np.pi) - np.pi
        a, b = l1 / 1e3, l2 / 1e3
        J = np.empty(q1.shape + (2, 2))
        J[..., 0, 0] = -a * np.sin(q1) - b * np.sin(q1 + q2)
        J[..., 0, 1] = -b * np.sin(q1 + q2)
        J[..., 1, 0] = a * np.cos(q1) + b * np.cos(q1 + q2)
        J[..., 1, 1] = b * np.cos(q1 + q2)
        smin = np.sqrt(np.maximum(np.linalg.eigvalsh(np.swapaxes(J, -1, -2) @ J)[..., 0], 0))
        inside = (np.abs(c2) <= 1) & (np.abs(q1) <= LIM1) & (np.abs(q2) <= LIM2)
        ok |= inside & (np.minimum(smin, 1) >= SIGMA * (1 - 1e-6))
    z_ok = STROKE[0] <= Z - Z0 <= STROKE[1]
    return (ok & z_ok).sum(axis=1)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    q = quick_run("scara_design", tmp_path_factory)
    return q.copied, q.results, q.report.parent


def test_results_json_is_strict_and_the_study_passed(run):
    copied, _, d = run
    def no_constant(x):
        raise ValueError(f"non-strict JSON constant {x}")
    on_disk = json.loads((d / "results.json").read_text(), parse_constant=no_constant)
    assert copied.returncode == 0 and on_disk["ok"] is True and on_disk["quick"] is True
    assert [f["ok"] for f in on_disk["findings"]] == [True, True, True]


def test_the_closed_form_here_matches_the_machine():
    # the nominal 225/225 mm arm at r = 225·√2 mm (elbow at 90°): the 2R block's JᵀJ has trace
    # F = 3·0.225² and determinant det² = (0.225²)², so σ_min² = (F − √(F² − 4 det²))/2; stretched, σ_min → 0
    r = np.hypot(225, 225)
    F, det = (0.225 ** 2 + 2 * 0.225 ** 2), 0.225 ** 2
    assert sigma_at(225, 225, r, 0) == pytest.approx(np.sqrt((F - np.sqrt(F * F - 4 * det * det)) / 2), rel=1e-9)
    assert sigma_at(225, 225, 449.999999, 0) < 1e-3 and sigma_at(225, 225, 460, 0) == -1.0
    for l1, l2 in ((225, 225), (245.8, 173.8), (120, 390), (300, 110)):
        assert covered_count_vec([l1], [l2])[0] == covered_count(l1, l2)


def test_nominal_design_covers_every_target(run):
    _, results, _ = run
    assert covered_count(225, 225) == 25
    assert results["nominal"]["coverage_percent"] == 100.0 and results["nominal"]["length_mm"] == pytest.approx(452.0)


def test_ipopt_optimum_covers_every_target_in_closed_form(run):
    _, results, _ = run
    ip = results["ipopt"]
    assert ip["feasible"] is True and ip["coverage_percent"] == 100.0
    assert covered_count(ip["A1_mm"], ip["A2_mm"]) == 25
    assert ip["length_mm"] == pytest.approx(ip["A1_mm"] + ip["A2_mm"] + Z0, abs=1e-9)
    # the least dexterous target sits at the threshold: the dexterity constraint is active at the optimum
    worst = min(sigma_at(ip["A1_mm"], ip["A2_mm"], x, y) for x, y in TARGETS)
    assert SIGMA <= worst < 1.01 * SIGMA
    # 0.3 % shorter arms (same split) no longer cover everything: the optimum is tight
    assert covered_count(0.997 * ip["A1_mm"], 0.997 * ip["A2_mm"]) < 25


def test_ipopt_optimum_is_the_shortest_in_closed_form(run):
    """Every design covering the farthest target has A1 + A2 ≥ its radius (380.8 mm); on a 0.5 mm
    grid of the band from there to IPOPT's length, the shortest covering design is within 1 mm
    of IPOPT's, and none is more than 0.1 mm shorter."""
    _, results, _ = run
    L_ip = results["ipopt"]["length_mm"] - Z0
    r_max = np.hypot(350, 150)
    a1 = np.arange(100, 400.001, 0.5)
    lengths = np.arange(np.floor(r_max), L_ip + 1.0, 0.5)
    A1, S = np.repeat(a1, len(lengths)), np.tile(lengths, len(a1))
    A2 = S - A1
    keep = (A2 >= 100) & (A2 <= 400)
    A1, A2 = A1[keep], A2[keep]
    counts = np.concatenate([covered_count_vec(A1[i:i + 20000], A2[i:i + 20000]) for i in range(0, len(A1), 20000)])
    full = counts == 25
    assert full.any()
    shortest = (A1 + A2)[full].min()
    assert shortest - 1.0 <= L_ip <= shortest + 0.1
    cf = results["closed_form"]
    assert cf["length_mm"] - Z0 == pytest.approx(shortest, abs=0.6) and cf["covered_at_ipopt"] == 25


def test_ipopt_against_the_grid(run):
    _, results, _ = run
    ip, g, cmp = results["ipopt"], results["grid"], results["ipopt_vs_grid"]
    n = g["n"]
    assert g["designs"] == n * n and g["spacing_mm"] == pytest.approx(300 / (n - 1))
    # the grid's best by the IK metric is the closed form's best on the same grid
    axis = np.linspace(100, 400, n)
    A1, A2 = np.repeat(axis, n), np.tile(axis, n)
    full = covered_count_vec(A1, A2) == 25
    assert abs(int(full.sum()) - g["feasible_designs"]) <= 2
    assert g["length_mm"] == pytest.approx((A1 + A2)[full].min() + Z0, abs=1e-6)
    # IPOPT is no longer than the grid's best, and shorter by less than one grid step per parameter
    assert ip["length_mm"] <= g["length_mm"] + 1e-6
    assert g["length_mm"] - ip["length_mm"] <= 2 * g["spacing_mm"]
    assert cmp["gap_percent"] == pytest.approx(100 * (ip["length_mm"] - g["length_mm"]) / g["length_mm"])
    assert -100 * 2 * g["spacing_mm"] / g["length_mm"] <= cmp["gap_percent"] <= 0.0
    assert cmp["time_ratio"] > 0


def test_differential_evolution_cross_check(run):
    _, results, _ = run
    de = results["de"]
    assert de["feasible"] is True and covered_count(de["A1_mm"], de["A2_mm"]) == 25
    # DE cannot beat the closed-form optimum (IPOPT's length less the 0.1 mm tolerance above)
    assert de["length_mm"] >= results["ipopt"]["length_mm"] - 1.0
    assert de["gap_to_ipopt_percent"] == pytest.approx(
        100 * (de["length_mm"] - results["ipopt"]["length_mm"]) / results["ipopt"]["length_mm"])


def _sweep_rows(d):
    with open(d / "sweep.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return rows


def test_sweep_store_and_table(run):
    _, results, d = run
    sw = results["sweep"]
    n = sw["n"]
    rows = _sweep_rows(d)
    assert len(rows) == sw["designs"] == n * n and sw["done"] == n * n and sw["failed"] == 0
    assert {r["status"] for r in rows} == {"done"}
    con = sqlite3.connect(f"file:{d / 'sweep.sqlite'}?mode=ro", uri=True)
    try:
        assert con.execute("SELECT COUNT(*) FROM designs WHERE status = 'done'").fetchone()[0] == n * n
    finally:
        con.close()
    axis = np.linspace(100, 400, n)
    A1 = np.array([float(r["A1_mm"]) for r in rows])
    A2 = np.array([float(r["A2_mm"]) for r in rows])
    assert sorted(set(np.round(A1, 6))) == pytest.approx(axis) and sorted(set(np.round(A2, 6))) == pytest.approx(axis)
    # the IK-verified coverage never exceeds the closed form's, and agrees with it on nearly every design
    ik = np.rint(25 * np.array([float(r["coverage"]) for r in rows])).astype(int)
    cf = covered_count_vec(A1, A2)
    assert np.all(ik <= cf)
    assert np.mean(ik == cf) >= 0.9
    L = np.array([float(r["structural_length"]) for r in rows])
    assert L == pytest.approx((A1 + A2 + Z0) / 1e3)


def test_pareto_rows_are_the_non_dominated_designs(run):
    _, results, d = run
    rows = _sweep_rows(d)
    L = np.array([1e3 * float(r["structural_length"]) for r in rows])
    C = np.array([float(r["coverage"]) for r in rows])
    front = results["sweep"]["pareto"]
    assert results["sweep"]["pareto_size"] == len(front) >= 2
    pts = {(round(p["length_mm"], 6), round(p["coverage"], 9)) for p in front}
    # brute force: a design is on the front iff no other is as short with as much coverage, one strictly
    expected = set()
    for i in range(len(rows)):
        dominated = np.any((L <= L[i]) & (C >= C[i]) & ((L < L[i]) | (C > C[i])))
        if not dominated:
            expected.add((round(L[i], 6), round(C[i], 9)))
    assert pts == expected
    # sorted by length, coverage rising; the full-coverage end is no shorter than IPOPT's optimum
    lens = [p["length_mm"] for p in front]
    assert lens == sorted(lens) and [p["coverage"] for p in front] == sorted(p["coverage"] for p in front)
    assert front[-1]["coverage"] == 1.0 and front[-1]["length_mm"] >= results["ipopt"]["length_mm"]
    assert covered_count(front[-1]["A1_mm"], front[-1]["A2_mm"]) == 25


def test_report_holds_the_numbers_and_the_plots(run):
    _, results, d = run
    ip, g = results["ipopt"], results["grid"]
    assert_report_holds(d / "report.html", results,
                        (f"{ip['A1_mm']:.2f}", f"{ip['A2_mm']:.2f}", f"{ip['length_mm']:.2f}", f"{g['length_mm']:.2f}",
                         f"{results['closed_form']['length_mm']:.2f}", f"{results['de']['length_mm']:.2f}",
                         f"{results['sweep']['pareto_size']} designs", "Pareto"),
                        ("task.png", "optimum.png", "design_plane.png", "pareto.png", "ipopt_history.png"))
    assert {"sweep.sqlite", "sweep.csv"} <= set(results["meta"]["files"])


def test_report_renders_in_a_browser(run, report_browser):
    _, results, out_dir = run
    assert_report_renders(report_browser, out_dir / "report.html", results)
