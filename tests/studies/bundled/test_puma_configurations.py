"""The puma_configurations study in quick mode, checked against independent values: a numpy DH product
of the thesis's test chain for k = 1 … 5 (correct, and with every angle's degrees read as radians), the
row sums, docs/machines.md §1's five-joint rotation, the PUMA 560's ranges from docs/machines.md §1 (only
joint 5 out), and for the joint-type architectures a numpy re-implementation of the skeleton (rank of
the position Jacobian, GCI on the same uniform samples), the wrist centre's closed-form reach and the
PPP rectangle's area; strict JSON, the report's numbers and figures."""
from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from tests.studies.bundled.common import assert_report_holds, assert_report_renders, quick_run

THETA = (90.0, 30.0, 90.0, 60.0, 180.0)           # docs/machines.md §1, degrees
ALPHA = (-90.0, 60.0, 90.0, 90.0, 0.0)
R5 = [[0.866, 0.0, -0.5], [-0.25, -0.866, -0.433], [-0.433, 0.5, -0.75]]
PUMA_RANGES = [(-160, 160), (-225, 45), (-45, 225), (-110, 170), (-100, 100), (-266, 266)]   # degrees
# the PUMA arm (docs/machines.md §1, metres): rows (α, a, d) of joints 1–3, the forearm d4 as tool offset
ARM = [(-math.pi / 2, 0.0, 0.0), (0.0, 0.4318, 0.14909), (math.pi / 2, -0.02032, 0.0)]
D4 = 0.43307
L = 0.4318



def _A(theta, d, a, alpha):
    """Standard DH A_i = Rz(θ)·Tz(d)·Tx(a)·Rx(α), batched over the leading axis of theta/d."""
    theta, d = np.broadcast_arrays(np.asarray(theta, float), np.asarray(d, float))
    ct, st, ca, sa = np.cos(theta), np.sin(theta), math.cos(alpha), math.sin(alpha)
    A = np.zeros(theta.shape + (4, 4))
    A[..., 0, 0], A[..., 0, 1], A[..., 0, 2], A[..., 0, 3] = ct, -st * ca, st * sa, a * ct
    A[..., 1, 0], A[..., 1, 1], A[..., 1, 2], A[..., 1, 3] = st, ct * ca, -ct * sa, a * st
    A[..., 2, 1], A[..., 2, 2], A[..., 2, 3] = sa, ca, d
    A[..., 3, 3] = 1.0
    return A


def _test_chain(k: int, slipped: bool) -> np.ndarray:
    T = np.eye(4)
    for th, al in zip(THETA[:k], ALPHA[:k]):
        T = T @ (_A(th, 0.0, 0.0, al) if slipped else _A(math.radians(th), 0.0, 0.0, math.radians(al)))
    return T


def _arm_jacobian(types: str, Q: np.ndarray) -> np.ndarray:
    """Position Jacobian (N, 3, 3) of the skeleton with joint types ``types`` (tool point: wrist centre)."""
    N = len(Q)
    T = np.broadcast_to(np.eye(4), (N, 4, 4))
    frames = [T]
    for (al, a, d), t, q in zip(ARM, types, Q.T):
        T = T @ (_A(q, d, a, al) if t == "R" else _A(np.zeros(N), d + q, a, al))
        frames.append(T)
    p = (T @ np.array([0, 0, D4, 1.0]))[:, :3]
    cols = []
    for F, t in zip(frames[:3], types):
        z = F[:, :3, 2]
        cols.append(np.cross(z, p - F[:, :3, 3]) if t == "R" else z)
    return np.stack(cols, axis=2)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return quick_run("puma_configurations", tmp_path_factory)


def test_study_ran_ok_and_json_isstrict_json(run):
    d = run.results
    assert run.copied.returncode == 0 and d["ok"] is True
    assert d["quick"] is True and d["study"] == "puma_configurations"
    assert all(f["ok"] for f in d["findings"]) and len(d["findings"]) == 4


def test_configurations_against_a_numpy_dh_product(run):
    rows = run.results["configurations"]
    assert [r["k"] for r in rows] == [1, 2, 3, 4, 5]
    for r in rows:
        T, Ts = _test_chain(r["k"], False), _test_chain(r["k"], True)
        np.testing.assert_allclose(r["R_correct"], T[:3, :3], atol=1e-12)
        np.testing.assert_allclose(r["position_correct"], [0, 0, 0], atol=1e-15)   # a = d = 0
        np.testing.assert_allclose(r["R_thesis"], Ts[:3, :3], atol=1e-12)
        # the thesis's "position": the rotation's row sums
        np.testing.assert_allclose(r["position_thesis"], Ts[:3, :3].sum(axis=1), atol=1e-12)
        np.testing.assert_allclose(r["row_sums_correct"], T[:3, :3].sum(axis=1), atol=1e-12)
        c = (np.trace(T[:3, :3].T @ Ts[:3, :3]) - 1) / 2
        assert r["angle_deg"] == pytest.approx(math.degrees(math.acos(np.clip(c, -1, 1))), abs=1e-9)
    # docs/machines.md §1: the five-joint rotation, printed to three decimals
    np.testing.assert_allclose(rows[-1]["R_correct"], R5, atol=5e-4)
    assert run.results["reference_R5_deviation"] < 5e-4
    # one joint: Rz(90°)·Rx(−90°), by hand
    np.testing.assert_allclose(rows[0]["R_correct"], [[0, 0, -1], [1, 0, 0], [0, -1, 0]], atol=1e-12)


def test_joint_limit_check_flags_joint_5_only(run):
    lc = run.results["limit_check"]
    outside = [i + 1 for i, (v, (lo, hi)) in enumerate(zip([*THETA, 0.0], PUMA_RANGES)) if not lo <= v <= hi]
    assert outside == [5]
    assert [v["joint"] for v in lc["violations"]] == outside
    assert lc["violations"][0]["value_deg"] == pytest.approx(180.0)
    assert "joint 5" in lc["message"] and "1.74533" in lc["message"]


def test_architectures_against_a_numpy_skeleton(run):
    d = run.results
    rows = {r["architecture"]: r for r in d["architectures"]}
    assert list(rows) == ["".join(t) for t in itertools.product("RP", repeat=3)]
    n_dex = d["meta"]["inputs"]["architectures: dexterity samples (uniform random)"]
    seed = d["meta"]["inputs"]["seed"]
    for a, r in rows.items():
        lo = [math.radians(PUMA_RANGES[i][0]) if t == "R" else 0.0 for i, t in enumerate(a)]
        hi = [math.radians(PUMA_RANGES[i][1]) if t == "R" else L for i, t in enumerate(a)]
        Q = np.random.default_rng(seed).uniform(lo, hi, size=(n_dex, 3))    # = Robot.random_configurations
        J = _arm_jacobian(a, Q)
        J[:, :, [t == "R" for t in a]] /= L
        sv = np.linalg.svd(J, compute_uv=False)
        ik = sv[:, -1] / sv[:, 0]
        ik[ik < 1e-12] = 0.0
        assert r["gci"] == pytest.approx(ik.mean(), abs=1e-9), a
        rank2 = bool(np.all(sv[:, -1] < 1e-9 * sv[:, 0]))
        assert (r["dimension"] == 2) == rank2 == (a in ("RPP", "PRR", "PPP")), a
        assert (r["volume_m3"] == 0) == rank2
    # RRR: the wrist centre's largest distance from the base, arm stretched: √(d2² + (a2 + √(a3² + d4²))²)
    reach = math.hypot(0.14909, 0.4318 + math.hypot(0.02032, D4))
    assert reach - 5e-3 < rows["RRR"]["reach_m"] <= reach + 1e-9
    # PPP: a rectangle, stroke L along z0 by 2L along the parallel z1, z2; the voxel estimate exceeds it by
    # at most the cells along its boundary
    area, vox = L * 2 * L, rows["PPP"]["voxel_m"]
    assert area <= rows["PPP"]["area_m2"] <= area + 2 * (L + 2 * L) * vox + 4 * vox ** 2
    assert rows["RRR"]["volume_m3"] == max(r["volume_m3"] for r in rows.values())


def test_stroke_sweep_volumes_grow_with_the_stroke(run):
    sweep = run.results["stroke_sweep"]
    for a in ("RRP", "RPR", "PRP", "PPR"):
        vols = [x["volume_m3"] for x in sorted((x for x in sweep if x["architecture"] == a),
                                               key=lambda x: x["stroke_factor"])]
        assert len(vols) == 3 and vols[0] < vols[1] < vols[2], a


def test_report_holds_the_numbers_and_the_plots(run):
    report, d = run.report, run.results
    assert_report_holds(report, d, ("0.8660", "−0.4330", "row sums", "degrees read as radians, row sums as position",
                 "θ5 = 180° is outside the PUMA 560's range −100…100°", "joint 5 = 3.14159 rad", "RPP, PRR, PPP",
                 f"{d['configurations'][-1]['position_thesis'][0]:.4f}"),
                        ("frames.png", "architectures.png", "architecture_workspaces.png"))


def test_report_renders_in_a_browser(run, report_browser):
    report, results = run.report, run.results
    assert_report_renders(report_browser, report, results, numbers=("0.8660", "row sums"))
