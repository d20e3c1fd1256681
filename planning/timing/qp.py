"""The OSQP solver of the discretised time parameterisation (``method="qp"`` of
:func:`planning.timing.time_parameterize`): the whole problem in b = ṡ² as one sparse QP.

The time T = ∫ ds/√b = Σ_i 2·Δs_i/(√b_i + √b_{i+1}) is convex in b but not a QP.  The QP solved
instead is minimise Σ_i w_i·(b_i/β_i − 1)², w_i the trapezoid weights of the grid and β_i the maximum
velocity curve at s_i (an upper bound of every feasible b_i).  Why this gives the minimum-time
profile: the feasible profiles have a greatest element (the largest b_{i+1} reachable from b_i grows
with b_i when the grid is fine — its slope is 1 − O(Δs) — so the profile of the classical
switching-curve and TOPP-RA methods dominates every feasible profile pointwise), T decreases in
every b_i, and so does every term of the QP objective on [0, β_i]; a greatest element is then the
unique minimiser of both.  Dividing by β_i (rather than one common scale) cut OSQP's iterations about
fourfold on a dense, curved test path.  OSQP is a first-order method: a long grid with many active
constraints takes tens of thousands of iterations — seconds, not milliseconds; the reachability
passes (:mod:`planning.timing.reachability`) solve the same problem exactly in milliseconds.
Torque rows (:mod:`planning.timing.torque`) enter as they are: they are linear in b with bounds
lo ≤ 0 ≤ up, so the feasible set stays a convex polytope containing b = 0.
"""
from __future__ import annotations

import numpy as np
import osqp
import scipy.sparse as sps

from planning.timing.stages import Stages
from planning.timing.trajectory import TimingError

__all__ = ["solve_qp", "row_matrix"]

#: seconds OSQP may spend on one solve
TIME_LIMIT = 120.0
# rho and scaling chosen on a 1-joint, a blended 3-joint and a dense 6-joint path (fewest iterations);
# polishing is off (OSQP prints a line when there is nothing to polish) — the scale repair of the
# caller makes the result exactly feasible instead
_SETTINGS = dict(verbose=False, eps_abs=1e-7, eps_rel=1e-7, eps_prim_inf=1e-9, eps_dual_inf=1e-9,
                 max_iter=200000, polishing=False, rho=1.0, scaling=10, adaptive_rho=True,
                 time_limit=TIME_LIMIT)


def row_matrix(st: Stages) -> sps.csc_matrix:
    """The rows of ``st`` as a sparse matrix (R, K+1): row r has ci at b_iv and cj at b_{iv+1}."""
    R = len(st.iv)
    rr = np.arange(R)
    return sps.csc_matrix((np.r_[st.ci, st.cj], (np.r_[rr, rr], np.r_[st.iv, st.iv + 1])), shape=(R, st.K + 1))


def solve_qp(st: Stages, time_limit: float = TIME_LIMIT) -> tuple[np.ndarray, str]:
    """b (K+1,) ≥ 0 of the QP in the module docstring (before the caller's scale repair) and OSQP's
    status, within ``time_limit`` seconds.  Raises :class:`TimingError` when OSQP does not solve it."""
    nb = st.K + 1
    A = sps.vstack([sps.identity(nb, format="csc"), row_matrix(st)], format="csc")
    lo = np.r_[np.zeros(nb), st.lo]
    up = np.r_[st.ub, st.up]
    fin = np.isfinite(st.beta) & (st.beta > 0)
    beta = np.where(fin, st.beta, 1.0)
    w = np.zeros(nb)
    w[:-1] += 0.5 * st.h
    w[1:] += 0.5 * st.h
    w = np.where(fin & (st.ub > 0), w / w.max(), 0.0)
    beta *= 1.0 + 1e-6          # strictly decreasing up to the bound itself
    P = sps.diags(np.maximum(w, 1e-12) / beta ** 2, format="csc")
    solver = osqp.OSQP()
    solver.setup(P, -w / beta, A, lo, up, **{**_SETTINGS, "time_limit": time_limit})
    res = solver.solve(raise_error=False)
    status = res.info.status
    if status not in ("solved", "solved inaccurate"):
        raise TimingError(f"OSQP did not solve the time-parameterisation QP: {status} "
                          f"({res.info.iter} iterations, {st.K} grid intervals)")
    return np.clip(res.x, 0.0, st.ub), status
