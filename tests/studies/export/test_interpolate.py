"""The trajectory between samples: the quartic of q, q̇, q̈ at one sample and q, q̇ at the next, checked
against a numpy solve of its 5×5 conditions, exact on a quartic, and equal to planning.timing's own
sampling of a timed path (blends included)."""
from __future__ import annotations

import numpy as np
import pytest

from planning.timing import time_parameterize
from studies.export.interpolate import MAX_SAMPLES, evaluate, resample_times
from studies.export.trajectory import Trajectory


def _quartic_by_solve(t0, t1, q0, v0, a0, q1, v1, t):
    """q(t) of the quartic through the five conditions, by a linear solve in the monomials of (t − t0)."""
    h = t1 - t0
    M = np.array([[1, 0, 0, 0, 0], [0, 1, 0, 0, 0], [0, 0, 2, 0, 0],
                  [1, h, h ** 2, h ** 3, h ** 4], [0, 1, 2 * h, 3 * h ** 2, 4 * h ** 3]], float)
    c = np.linalg.solve(M, np.array([q0, v0, a0, q1, v1]))
    x = t - t0
    return c @ x ** np.arange(5)


def test_matches_the_quartic_of_its_five_conditions():
    rng = np.random.default_rng(3)
    t = np.r_[0.0, np.cumsum(rng.uniform(0.05, 0.3, 6))]
    tr = Trajectory(t, rng.uniform(-1, 1, (7, 3)), rng.uniform(-1, 1, (7, 3)), rng.uniform(-2, 2, (7, 3)))
    times = np.linspace(0, t[-1], 97)
    Q, _, _ = evaluate(tr, times)
    for i, x in enumerate(times):
        k = min(np.searchsorted(t, x, side="right") - 1, len(t) - 2)
        for j in range(3):
            ref = _quartic_by_solve(t[k], t[k + 1], tr.q[k, j], tr.qd[k, j], tr.qdd[k, j], tr.q[k + 1, j],
                                    tr.qd[k + 1, j], x)
            assert Q[i, j] == pytest.approx(ref, abs=1e-12)
    Qs, Vs, As = evaluate(tr, t)                         # at the samples: the samples themselves
    assert np.array_equal(Qs, tr.q) and np.array_equal(Vs, tr.qd)
    assert np.array_equal(As[:-1], tr.qdd[:-1])


def test_exact_on_a_quartic_and_its_derivatives_by_finite_differences():
    p = np.array([0.3, -1.0, 0.5, 2.0, -0.7])            # q(t) = Σ p_k t^k
    t = np.array([0.0, 0.2, 0.45, 1.0])

    def poly(x, d=0):
        c = np.polynomial.polynomial.polyder(p, d) if d else p
        return np.polynomial.polynomial.polyval(x, c)[:, None]
    tr = Trajectory(t, poly(t), poly(t, 1), poly(t, 2))
    x = np.linspace(0, 1, 41)[1:-1]
    Q, V, A = evaluate(tr, x)
    assert np.allclose(Q, poly(x), atol=1e-14) and np.allclose(V, poly(x, 1), atol=1e-13)
    assert np.allclose(A, poly(x, 2), atol=1e-12)
    e = 1e-6                                             # V and A are the derivatives of Q
    assert np.allclose(V, (evaluate(tr, x + e)[0] - evaluate(tr, x - e)[0]) / (2 * e), atol=1e-8)
    assert np.allclose(A, (evaluate(tr, x + e)[1] - evaluate(tr, x - e)[1]) / (2 * e), atol=1e-7)


def test_reproduces_planning_timings_own_sampling():
    P = np.radians([[0, -90, 0, 0, 0, 0], [30, -60, 60, -90, -90, 0], [60, -80, 40, -60, -45, 30]])
    for blend in (0.0, 0.05):
        tm = time_parameterize(P, np.pi, 3.0, blend=blend)
        tr = Trajectory(tm.t, tm.q, tm.qd, tm.qdd)
        times = resample_times(tm.duration, 500.0)
        Q, V, A = evaluate(tr, times)
        q, v, a = tm.sample(times)
        assert np.abs(Q - q).max() < 1e-12 and np.abs(V - v).max() < 1e-9 and np.abs(A - a).max() < 1e-6


def test_resample_times():
    T = resample_times(1.0, 500.0)
    assert len(T) == 501 and T[0] == 0 and T[-1] == 1.0 and np.allclose(np.diff(T), 0.002)
    T = resample_times(1.0005, 500.0)
    assert len(T) == 502 and T[-1] == 1.0005 and T[-2] == pytest.approx(1.0)
    with pytest.raises(ValueError, match=f"at most {MAX_SAMPLES}"):
        resample_times(86400.0, 500.0)
