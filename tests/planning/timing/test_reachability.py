"""Tests of planning.timing.reachability: the compiled and the numpy passes give the same profile;
the profile against HiGHS maximising Σ b over the same rows (an independent LP solver); durations
against the OSQP method and against TOPP-RA (when installed)."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sps
from scipy.optimize import linprog

from planning.timing import blend_path, time_parameterize
from planning.timing.jerk import interval_times
from planning.timing.limits import dense_ratios
from planning.timing.native import load_reach
from planning.timing.qp import row_matrix
from planning.timing.reachability import reach, reach_numpy
from planning.timing.stages import build_stages

needs_cc = pytest.mark.skipif(load_reach() is None, reason="no C compiler (RMTKIT_CC=none or none installed)")


def smooth_path(seed: int, m: int = 40, n: int = 6) -> np.ndarray:
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 1.0, m)[:, None]
    return 0.8 * np.sin(2 * np.pi * rng.uniform(0.3, 1.5, n) * u + rng.uniform(0, 6, n))


CASES = [(smooth_path(0), 0.05, 120), (smooth_path(1, 25, 3), 0.2, 200), (smooth_path(2, 12, 4), 0.0, 150),
         (np.array([[0.0], [1.0]]), 0.05, 50)]
V = np.array([2.6, 2.8, 2.8, 5.2, 5.2, 7.8])


def stages(W, blend, K):
    bp = blend_path(W, blend)
    n = bp.n
    return bp, build_stages(bp, K, V[:n], 2 * V[:n])


@needs_cc
@pytest.mark.parametrize("W, blend, K", CASES)
def test_compiled_and_numpy_passes_agree(W, blend, K):
    _, st = stages(W, blend, K)
    hi_c, b_c, used = reach(st, "c")
    hi_n, b_n = reach_numpy(st)
    assert used == "c"
    np.testing.assert_allclose(hi_c, hi_n, rtol=1e-9, atol=1e-12 * hi_n.max())
    np.testing.assert_allclose(b_c, b_n, rtol=1e-9, atol=1e-12 * b_n.max())


@needs_cc
def test_compiled_and_numpy_passes_agree_on_a_coarse_grid_over_many_pieces():
    """Grid intervals spanning dozens of path pieces: stages of hundreds of half-planes (HiGHS in numpy)."""
    _, st = stages(smooth_path(7, 60), 0.05, 4)
    assert np.max(np.bincount(st.iv)) > 64
    hi_c, b_c, _ = reach(st, "c")
    hi_n, b_n = reach_numpy(st)
    np.testing.assert_allclose(hi_c, hi_n, rtol=1e-6, atol=1e-9 * hi_n.max())
    np.testing.assert_allclose(b_c, b_n, rtol=1e-6, atol=1e-9 * b_n.max())


def test_without_a_compiler_the_numpy_passes_give_the_same_trajectory(monkeypatch):
    W = smooth_path(3)
    ref = time_parameterize(W, V, 2 * V, backend="numpy")
    monkeypatch.setenv("RMTKIT_CC", "none")
    tr = time_parameterize(W, V, 2 * V)
    assert "numpy" in tr.qp_status
    np.testing.assert_allclose(tr.t, ref.t, rtol=1e-9)
    monkeypatch.delenv("RMTKIT_CC")
    if load_reach() is not None:
        trc = time_parameterize(W, V, 2 * V)
        assert "(c)" in trc.qp_status
        np.testing.assert_allclose(trc.t, ref.t, rtol=1e-9)


@pytest.mark.parametrize("W, blend, K", CASES)
def test_profile_against_an_independent_lp(W, blend, K):
    """HiGHS maximises Σ b_i over the same rows.  Where the feasible set has a greatest element (no
    blends: straight pieces), that is the LP's unique optimum and the greedy profile equals it; with
    blends coarser than the grid it may have none, and the greedy profile (TOPP-RA's) is then within a
    few tenths of a percent of the LP profile's duration."""
    _, st = stages(W, blend, K)
    _, b, _ = reach(st)
    A = row_matrix(st)
    fu, fl = np.isfinite(st.up), np.isfinite(st.lo)
    res = linprog(-np.ones(st.K + 1), A_ub=sps.vstack([A[fu], -A[fl]]), b_ub=np.r_[st.up[fu], -st.lo[fl]],
                  bounds=np.c_[np.zeros(st.K + 1), np.where(np.isfinite(st.ub), st.ub, None)], method="highs",
                  options={"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10})
    assert res.status == 0
    if blend == 0.0:
        np.testing.assert_allclose(b, res.x, rtol=1e-6, atol=1e-7 * res.x.max())
    T = float(interval_times(st, b).sum())
    T_lp = float(interval_times(st, res.x).sum())
    assert T == pytest.approx(T_lp, rel=5e-3)
    # and it is feasible: every row holds up to rounding
    v = A @ b
    assert np.all(v <= st.up * (1 + 1e-9) + 1e-12) and np.all(v >= st.lo * (1 + 1e-9) - 1e-12)


def test_the_greedy_profile_is_optimal_as_the_grid_is_refined():
    """On a fine grid the greedy profile and the LP profile coincide in duration (TOPP-RA's asymptotic
    optimality)."""
    W, blend = smooth_path(0), 0.05
    gaps = []
    for K in (120, 960):
        _, st = stages(W, blend, K)
        _, b, _ = reach(st)
        A = row_matrix(st)
        fu, fl = np.isfinite(st.up), np.isfinite(st.lo)
        res = linprog(-np.ones(st.K + 1), A_ub=sps.vstack([A[fu], -A[fl]]), b_ub=np.r_[st.up[fu], -st.lo[fl]],
                      bounds=np.c_[np.zeros(st.K + 1), np.where(np.isfinite(st.ub), st.ub, None)], method="highs")
        gaps.append(float(interval_times(st, b).sum()) / float(interval_times(st, res.x).sum()) - 1)
    assert gaps[1] < gaps[0] and gaps[1] < 5e-4


@pytest.mark.parametrize("seed, blend", [(4, 0.05), (5, 0.2), (6, 0.0)])
def test_same_duration_as_the_osqp_method(seed, blend):
    W = smooth_path(seed, 30)
    tr = time_parameterize(W, V, 2 * V, blend=blend)
    qp = time_parameterize(W, V, 2 * V, blend=blend, method="qp")
    assert tr.duration == pytest.approx(qp.duration, rel=5e-3)
    for t in (tr, qp):
        dv, da = dense_ratios(t, V, 2 * V, per_interval=16)
        assert dv <= 1 + 1e-9 and da <= 1 + 1e-9


def test_against_toppra_on_the_same_path_and_grid():
    pytest.importorskip("toppra", reason="toppra (the `bench` extra) is not installed")
    from studies.benchmarks.bench_timing import A_MAX, BLEND, V_MAX, fanuc_path, overshoot, toppra_solve
    W = fanuc_path()
    bp = blend_path(W, BLEND)
    for npts in (301, 1001):
        K = npts - 1
        tr = time_parameterize(W, V_MAX, A_MAX, ds=bp.length / K * (1 + 1e-12), blend=BLEND)
        assert len(tr.grid) == npts
        jt = toppra_solve(bp, tr.grid, V_MAX, A_MAX)
        ts = np.linspace(0.0, jt.duration, 20 * K + 1)
        theirs = overshoot(jt(ts, 1), jt(ts, 2), V_MAX, A_MAX)["overshoot"]
        dv, da = dense_ratios(tr, V_MAX, A_MAX, per_interval=20)
        assert max(dv, da) <= 1 + 1e-9
        if npts == 1001:
            assert tr.duration == pytest.approx(float(jt.duration), rel=5e-3)
        else:
            # on the coarse grid TOPP-RA's profile is checked at the grid points only and overshoots the
            # acceleration limit between them; ours holds everywhere and is at most ~1.5 % longer
            assert theirs > 0.05
            assert float(jt.duration) <= tr.duration <= 1.015 * float(jt.duration)
