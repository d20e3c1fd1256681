"""TOPP-RA's reachability analysis over the stages of :mod:`planning.timing.stages`
(``method="reach"`` of :func:`planning.timing.time_parameterize`, the default).

Every row involves one interval, so stage i is a convex polygon P_i of pairs (x, y) = (b_i, b_{i+1})
(half-planes A·x + C·y ≤ R), and (0, 0) lies in every P_i (R ≥ 0: the speed and acceleration rows
are homogeneous, the torque rows of :mod:`planning.timing.torque` have 0 in their range when the
robot can hold the path at rest, which is checked before).  The set of
b_i from which the end can be reached at rest (the controllable set) is then an interval [0, hi_i]:
hi_K = 0 and hi_i = max{x : (x, y) ∈ P_i, 0 ≤ y ≤ hi_{i+1}, x ≤ ub_i} — one two-variable LP per
stage, solved exactly (backward pass).  The forward pass starts at rest and takes the largest
b_{i+1} ∈ [0, hi_{i+1}] with (b_i, b_{i+1}) ∈ P_i, a one-variable problem (the intersection of the
rows' bounds on y).  This is TOPP-RA's greedy profile (Pham and Pham 2018): it is feasible by
construction and, when the largest reachable b_{i+1} does not decrease with b_i (a grid fine against
the path's curvature, and always on straight pieces), the greatest element of the feasible set,
hence the minimum-time profile on the grid — the b the QP of :mod:`planning.timing.qp` approximates
with thousands of first-order iterations.  On a grid coarser than the blends the set may have no
greatest element and the greedy profile is slightly slower than the profile of largest Σ b (on a
6-joint test path with blends 0.1 rad long: 0.17 % slower at a grid step of 0.068 rad, 0.008 % at
0.0084 rad); it converges to the optimum as the grid is refined (TOPP-RA's asymptotic optimality).
Torque rows make this more visible: their ṡ² term B·b(s) couples b_i and b_{i+1} with the sign that
lowers the reachable b_{i+1} as b_i grows when h is large (on a 7-joint Panda test path, 300
intervals: 2.4 % slower than the QP's profile; 1000 intervals: 0.0001 %).

Both passes run in C (:mod:`planning.timing.native`) when a compiler is available, else in numpy
(:func:`reach_numpy`: a Python loop over stages, each LP by enumerating the polygon's vertices — the
same optimum, found differently, about 100× slower).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

from planning.timing.native import load_reach
from planning.timing.stages import Stages
from planning.timing.trajectory import TimingError

__all__ = ["reach", "reach_numpy", "half_planes", "BACKENDS"]

BACKENDS = ("auto", "c", "numpy")
#: stages with more half-planes than this are solved by HiGHS in the numpy passes
ENUMERATE_MAX = 64


def half_planes(st: Stages) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Stage half-planes A·x + C·y ≤ R sorted by stage, with ``off`` (K+1,) the first row of each
    stage, and ``xcap`` (K+1,) the box bound of each b: min(ub, maximum velocity curve)."""
    fu = np.isfinite(st.up)
    fl = np.isfinite(st.lo)
    iv = np.r_[st.iv[fu], st.iv[fl]]
    A = np.r_[st.ci[fu], -st.ci[fl]]
    C = np.r_[st.cj[fu], -st.cj[fl]]
    R = np.r_[st.up[fu], -st.lo[fl]]
    o = np.argsort(iv, kind="stable")
    off = np.searchsorted(iv[o], np.arange(st.K + 1)).astype(np.int64)
    # the box only has to contain the feasible set: a hair above the maximum velocity curve
    cap = np.where(np.isfinite(st.beta), st.beta * (1 + 1e-9) + 1e-300, 1e12)
    xcap = np.minimum(st.ub, cap)
    return (np.ascontiguousarray(A[o]), np.ascontiguousarray(C[o]), np.ascontiguousarray(R[o]), off,
            np.ascontiguousarray(xcap))


def _lp_max_x(a: np.ndarray, c: np.ndarray, r: np.ndarray) -> float:
    """max x over {a·x + c·y ≤ r} (bounded, feasible) by enumerating the vertices: every pair of
    boundary lines, kept when it satisfies every half-plane up to rounding.  A stage with more than
    :data:`ENUMERATE_MAX` half-planes (a grid interval spanning many path pieces) goes to HiGHS
    instead (O(m³) enumeration would not fit in memory), exact to its tolerance (1e-7)."""
    if len(a) > ENUMERATE_MAX:
        res = linprog([-1.0, 0.0], A_ub=np.c_[a, c], b_ub=r, bounds=[(None, None), (None, None)], method="highs")
        if res.status != 0:
            raise TimingError(f"HiGHS failed on a stage of the reachability pass: {res.message}")
        return float(res.x[0])
    i, j = np.triu_indices(len(a), 1)
    det = a[i] * c[j] - a[j] * c[i]
    ok = np.abs(det) > 1e-14 * (np.abs(a[i] * c[j]) + np.abs(a[j] * c[i]))
    i, j, det = i[ok], j[ok], det[ok]
    x = (r[i] * c[j] - r[j] * c[i]) / det
    y = (a[i] * r[j] - a[j] * r[i]) / det
    lhs = a[:, None] * x[None, :] + c[:, None] * y[None, :]
    tol = 1e-10 * (np.abs(a[:, None] * x[None, :]) + np.abs(c[:, None] * y[None, :]) + np.abs(r[:, None]))
    feas = np.all(lhs <= r[:, None] + tol, axis=0)
    return float(np.max(x[feas], initial=0.0))


def reach_numpy(st: Stages) -> tuple[np.ndarray, np.ndarray]:
    """hi (K+1,) and b (K+1,) of the two passes (module docstring) in numpy."""
    A, C, R, off, xcap = half_planes(st)
    K = st.K
    hi = np.empty(K + 1)
    hi[K] = xcap[K]
    box_a = np.array([1.0, -1.0, 0.0, 0.0])
    box_c = np.array([0.0, 0.0, 1.0, -1.0])
    for i in range(K - 1, -1, -1):
        sl = slice(off[i], off[i + 1])
        x = _lp_max_x(np.r_[box_a, A[sl]], np.r_[box_c, C[sl]], np.r_[xcap[i], 0.0, hi[i + 1], 0.0, R[sl]])
        hi[i] = min(max(x, 0.0), xcap[i])
    b = np.zeros(K + 1)
    for i in range(K):
        sl = slice(off[i], off[i + 1])
        a, c, r = A[sl], C[sl], R[sl]
        x = b[i]
        num = r - a * x
        eff = np.abs(c) * hi[i + 1] > 1e-12 * (np.abs(a * x) + np.abs(r))
        pos = eff & (c > 0)
        yhi = min(hi[i + 1], float(np.min(num[pos] / c[pos], initial=np.inf)))
        b[i + 1] = max(yhi, 0.0)
    return hi, b


def reach(st: Stages, backend: str = "auto") -> tuple[np.ndarray, np.ndarray, str]:
    """hi, b (K+1,) of the two passes and the backend used: ``"c"`` (compiled, :mod:`planning.timing.native`)
    or ``"numpy"``; ``backend="auto"`` takes C when a compiler is available."""
    if backend not in BACKENDS:
        raise TimingError(f"backend = {backend!r} unknown; allowed: {', '.join(BACKENDS)}")
    f = None if backend == "numpy" else load_reach()
    if f is None:
        if backend == "c":
            raise TimingError("backend 'c' needs a C compiler (set CC or RMTKIT_CC)")
        hi, b = reach_numpy(st)
        return hi, b, "numpy"
    A, C, R, off, xcap = half_planes(st)
    K = st.K
    hi = np.empty(K + 1)
    b = np.empty(K + 1)
    m = int(np.max(np.diff(off), initial=0)) + 4
    wa, wc, wr = np.empty(m), np.empty(m), np.empty(m)
    f(K, off.ctypes.data, A.ctypes.data, C.ctypes.data, R.ctypes.data, xcap.ctypes.data, hi.ctypes.data,
      b.ctypes.data, wa.ctypes.data, wc.ctypes.data, wr.ctypes.data)
    return hi, b, "c"
