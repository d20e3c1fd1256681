"""Time parameterisation of a joint path under joint speed and acceleration limits, with OSQP.

A geometric joint path q(s) (s a path parameter, here joint-space arc length) becomes a trajectory
once s(t) is chosen.  With b(s) = ṡ² and a(s) = s̈ (so that b′(s) = 2a):

    q̇  = q′(s)·ṡ                 |q̇_j| ≤ v_j   ⇔   q′_j(s)²·b ≤ v_j²           (a bound on b)
    q̈  = q′(s)·a + q″(s)·b       |q̈_j| ≤ A_j   ⇔   −A_j ≤ q′_j·a + q″_j·b ≤ A_j   (linear in a, b)

and b ≥ 0, b(0) = b(end) = 0 (rest to rest) — all linear in (a, b).

Discretisation.  The grid s_0 < … < s_K is uniform (``DEFAULT_INTERVALS`` intervals unless ``ds`` is
given) plus every stop.  The variables are b_0…b_K; s̈ is held constant on each interval, so
b is linear in s there and a_i = (b_{i+1} − b_i)/(2·Δs_i) is substituted (no separate a variables).
Every piece of the path is a quadratic, so on the part of an interval that lies on one piece (a
"segment") q″ is constant and q′(s) is linear: q̈ = q′·a_i + q″·b(s) is linear in s, and imposing
|q̈_j| ≤ A_j at both ends of every segment bounds it on the whole segment.  For the speed,
q′_j(s)²·b(s) is a product of two non-negative functions that peak at an end, so the rows
κ·b(end) ≤ 1 with κ = max over joints and both ends of q′_j²/v_j² bound it on the whole segment too.
With the exact s(t) of a piecewise-constant s̈, the continuous trajectory therefore respects both
limits everywhere (up to the solver tolerance, removed below).

Objective.  The time T = ∫ ds/√b = Σ_i 2·Δs_i/(√b_i + √b_{i+1}) is convex in b but not a QP.  The
QP solved instead is minimise Σ_i w_i·(b_i/β_i − 1)², w_i the trapezoid weights of the grid and β_i
the maximum velocity curve at s_i (the largest b for which some s̈ meets every constraint at that
point — an upper bound of every feasible b_i).  Why this gives the minimum-time profile: the feasible
profiles have a greatest element (the largest b_{i+1} reachable from b_i grows with b_i when the grid
is fine — its slope is 1 − O(Δs) — so the profile of the classical forward/backward switching-curve
and TOPP-RA methods dominates every feasible profile pointwise), T decreases in every b_i, and so
does every term of the QP objective on [0, β_i]; a greatest element is then the unique minimiser of
both.  No linearisation of 1/√b is needed; dividing by β_i (rather than one common scale) cut OSQP's
iterations about fourfold on a dense, curved test path.  After the solve, b is
scaled by one factor c ≤ 1 (every row is homogeneous in b) so that every constraint holds exactly
despite the solver's tolerance; c differs from 1 by about that tolerance (1e-7).  OSQP is a first-order
method: a long grid with many active constraints (a dense, curved path) takes tens of thousands of
iterations — seconds, not milliseconds.

Corners.  The path is made C¹ by blending its corners with quadratic Bézier pieces, or stops at
every corner with ``blend=0``; a dense path is first thinned.  See :mod:`planning.timing.shaping`
(:func:`blend_path`, :func:`simplify_path`) and :mod:`planning.timing.trajectory` (:class:`BlendedPath`,
:class:`TimedTrajectory`, :class:`TimingError`).  The result is checked against the limits by
:func:`check_limits` (:mod:`planning.timing.limits`).

SI units throughout: rad and rad/s, rad/s² for revolute joints, m, m/s, m/s² for prismatic ones.
"""
from __future__ import annotations

import math

import numpy as np
import osqp
import scipy.sparse as sps

from planning.timing.limits import _limits
from planning.timing.shaping import blend_path
from planning.timing.trajectory import BlendedPath, TimedTrajectory, TimingError

__all__ = ["time_parameterize", "DEFAULT_INTERVALS", "MAX_INTERVALS"]

#: default grid: this many intervals over the whole path (plus every piece boundary)
DEFAULT_INTERVALS = 300
#: the QP has one variable per grid point; OSQP (first order) needs more iterations on longer grids
MAX_INTERVALS = 5000
# rho and scaling chosen on a 1-joint, a blended 3-joint and a dense 6-joint path (fewest iterations);
# polishing is off (OSQP prints a line when there is nothing to polish) — the scale repair makes the
# result exactly feasible instead
_SETTINGS = dict(verbose=False, eps_abs=1e-7, eps_rel=1e-7, eps_prim_inf=1e-9, eps_dual_inf=1e-9,
                 max_iter=200000, polishing=False, rho=1.0, scaling=10, adaptive_rho=True)



def _grid(bp: BlendedPath, K: int) -> np.ndarray:
    """Grid points s (≥ K+1): uniform, plus every stop (an unblended corner must be a grid point —
    the trajectory is at rest there)."""
    s = np.linspace(0.0, bp.length, K + 1)
    if len(bp.stops):
        s = np.unique(np.r_[s, bp.stops])
        s = s[np.r_[True, np.diff(s) > 1e-12 * max(bp.length, 1.0)]]
        s[-1] = bp.length
    return s


def _records(bp: BlendedPath, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Constraint points: (interval index, s, piece) for both ends of every grid interval and both
    sides of every piece boundary inside an interval."""
    K = len(s) - 1
    iv = np.arange(K)
    recs_i = [iv, iv]
    recs_s = [s[:-1], s[1:]]
    recs_p = [bp.piece_of(s[:-1], "right"), bp.piece_of(s[1:], "left")]
    inner = bp.s0[1:]
    inner = inner[~np.isin(inner, s)]
    if len(inner):
        i = np.clip(np.searchsorted(s, inner, side="right") - 1, 0, K - 1)
        p = np.searchsorted(bp.s0, inner, side="left")     # bp.s0[p] == inner: the piece starting there
        recs_i += [i, i]
        recs_s += [inner, inner]
        recs_p += [p - 1, p]
    return np.concatenate(recs_i), np.concatenate(recs_s), np.concatenate(recs_p)


def _max_velocity_curve(d1: np.ndarray, d2: np.ndarray, amax: np.ndarray) -> np.ndarray:
    """Largest b (R,) for which some s̈ satisfies |q′_j·s̈ + q″_j·b| ≤ A_j for every joint, at each of R
    points with q′ = d1 (R, n) and q″ = d2 (R, n) — the classical maximum velocity curve.

    Joint j allows s̈ ∈ [L_j(b), U_j(b)] = (∓A_j − q″_j·b)/q′_j (ordered); some s̈ exists iff
    L_j(b) ≤ U_k(b) for every pair, each a bound b ≤ (A_j/|q′_j| + A_k/|q′_k|)/(slope_j − slope_k)
    when the slopes −q″/q′ differ in that direction.  A joint with q′_j = 0 needs |q″_j|·b ≤ A_j."""
    tiny = np.abs(d1) <= 1e-12
    inv = np.where(tiny, 0.0, 1.0 / np.where(tiny, 1.0, np.abs(d1)))
    slope = np.where(tiny, 0.0, -d2 / np.where(tiny, 1.0, d1))
    rhs = (amax[None, :] * inv)[:, :, None] + (amax[None, :] * inv)[:, None, :]
    coef = slope[:, :, None] - slope[:, None, :]
    ok = (coef > 1e-15) & ~tiny[:, :, None] & ~tiny[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        pair = np.where(ok, rhs / np.where(ok, coef, 1.0), np.inf).min(axis=(1, 2))
        lone = np.where(tiny & (np.abs(d2) > 1e-15), amax[None, :] / np.abs(d2), np.inf).min(axis=1)
    return np.minimum(pair, lone)


def time_parameterize(path, v_max, a_max, ds: float | None = None, blend: float = 0.05,
                      simplify: float = 1e-4) -> TimedTrajectory:
    """Near-minimum-time, rest-to-rest trajectory along a joint path under per-joint limits.

    Parameters
    ----------
    path : (M, n) joint waypoints (SI), joined by straight segments; corners are blended (``blend``).
    v_max, a_max : per-joint speed and acceleration limits, scalars or (n,) arrays, > 0.
    ds : grid step in s (joint-space arc length); None: path length / :data:`DEFAULT_INTERVALS`.
        The constraints are imposed at the grid points and at every piece boundary (both sides), so
        a dense path keeps the grid small (the QP has one variable per grid point).
    blend : corner blend half-length r (rad or m, joint-space distance); 0: stop at every corner.
    simplify : waypoint thinning tolerance (rad or m; 0: off), see :func:`blend_path`.

    Returns a :class:`TimedTrajectory` sampled at the grid points and piece boundaries (see the module
    docstring for the formulation).  Raises :class:`TimingError` for bad input or when OSQP does not
    solve the QP.
    """
    bp = blend_path(path, blend, simplify)
    n = bp.n
    vmax = _limits(v_max, n, "v_max")
    amax = _limits(a_max, n, "a_max")
    if bp.length == 0.0:
        z = np.zeros((1, n))
        return TimedTrajectory(np.zeros(1), bp.waypoints[:1].copy(), z, z.copy(), np.zeros(1), np.zeros(1),
                               np.zeros(1), 0.0, 0.0, 0.0, bp, vmax, amax, "trivial (zero-length path)")
    if ds is None:
        K = DEFAULT_INTERVALS
    else:
        if not (math.isfinite(ds) and ds > 0):
            raise TimingError(f"ds = {ds!r} must be a positive finite grid step (rad or m of path length)")
        K = max(1, int(math.ceil(bp.length / ds - 1e-9)))
        if K > MAX_INTERVALS:
            raise TimingError(f"ds = {ds:g} gives {K} grid intervals; at most {MAX_INTERVALS} (choose a larger ds)")
    s = _grid(bp, K)
    K = len(s) - 1
    h = np.diff(s)
    ri, rs, rp = _records(bp, s)
    # sorted by interval, then s, then piece: consecutive pairs (0, 1), (2, 3), … are the two ends of
    # one segment (the part of one grid interval on one piece)
    o = np.lexsort((rp, rs, ri))
    ri, rs, rp = ri[o], rs[o], rp[o]
    _, d1, d2 = bp.evaluate(rs, rp)
    theta = np.clip((rs - s[ri]) / h[ri], 0.0, 1.0)
    inv2h = 1.0 / (2 * h[ri])
    nb = K + 1
    rows, cols, vals, lo_l, up_l = [], [], [], [], []
    r0 = 0

    def add(ci: np.ndarray, cj: np.ndarray, sel: np.ndarray, lo: np.ndarray, up: np.ndarray) -> None:
        """Rows ci·b_i + cj·b_{i+1} ∈ [lo, up] for the records ``sel``."""
        nonlocal r0
        m = len(sel)
        if m == 0:
            return
        rr = r0 + np.arange(m)
        rows.extend([rr, rr])
        cols.extend([ri[sel], ri[sel] + 1])
        vals.extend([ci, cj])
        lo_l.append(lo)
        up_l.append(up)
        r0 += m

    # 0 ≤ b_i: one row per grid point (b_0 = b_K = 0, and 0 at the stops)
    rows.append(np.arange(nb))
    cols.append(np.arange(nb))
    vals.append(np.ones(nb))
    ub = np.full(nb, np.inf)
    ub[0] = ub[-1] = 0.0
    for st in bp.stops:
        ub[np.argmin(np.abs(s - st))] = 0.0
    lo_l.append(np.zeros(nb))
    up_l.append(ub)
    r0 = nb
    # speed: on a segment q′_j(s) is linear and b(s) = (1 − θ)·b_i + θ·b_{i+1} too, so
    # sup q′_j²·b ≤ max(q′_j² at its ends)·max(b at its ends): κ·b(end) ≤ 1 at both ends, with
    # κ = max over joints and both ends of q′_j²/v_j², bounds the speed on the whole segment
    kap = np.max(d1 ** 2 / vmax[None, :] ** 2, axis=1)
    kseg = np.maximum(kap[0::2], kap[1::2])
    kappa = np.repeat(kseg, 2)
    sel = np.flatnonzero(kappa > 0)
    add(kappa[sel] * (1 - theta[sel]), kappa[sel] * theta[sel], sel, np.full(len(sel), -np.inf),
        np.ones(len(sel)))
    # acceleration: q′_j·(b_{i+1} − b_i)/(2h_i) + q″_j·b(s) ∈ [−A_j, A_j]
    for j in range(n):
        sel = np.flatnonzero((np.abs(d1[:, j]) > 1e-15) | (np.abs(d2[:, j]) > 1e-15))
        c1, c2, th, g = d1[sel, j], d2[sel, j], theta[sel], inv2h[sel]
        add(-c1 * g + c2 * (1 - th), c1 * g + c2 * th, sel, np.full(len(sel), -amax[j]),
            np.full(len(sel), amax[j]))
    A = sps.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(r0, nb))
    lo = np.concatenate(lo_l)
    up = np.concatenate(up_l)
    # objective: Σ w_i·(b_i/β_i − 1)² with β_i ≥ every feasible b_i (the "maximum velocity curve" at
    # grid point i: the largest b for which some s̈ satisfies all the point's constraints).  Each term
    # decreases in b_i up to β_i, so the minimiser is the feasible set's greatest element (module
    # docstring); scaling by β_i makes the QP well conditioned for OSQP's first-order iterations.
    mvc = np.minimum(_max_velocity_curve(d1, d2, amax), np.where(kappa > 0, 1.0 / np.where(kappa > 0, kappa, 1.0),
                                                                 np.inf))
    beta = np.full(nb, np.inf)
    at = np.where(theta <= 0.0, ri, np.where(theta >= 1.0, ri + 1, -1))
    on = at >= 0
    np.minimum.at(beta, at[on], mvc[on])
    fin = np.isfinite(beta) & (beta > 0)
    beta = np.where(fin, beta, 1.0)
    w = np.zeros(nb)
    w[:-1] += 0.5 * h
    w[1:] += 0.5 * h
    w = np.where(fin & (ub > 0), w / w.max(), 0.0)
    beta *= 1.0 + 1e-6          # strictly decreasing up to the bound itself
    P = sps.diags(np.maximum(w, 1e-12) / beta ** 2, format="csc")
    qv = -w / beta
    solver = osqp.OSQP()
    solver.setup(P, qv, A, lo, up, **_SETTINGS)
    res = solver.solve(raise_error=False)
    status = res.info.status
    if status not in ("solved", "solved inaccurate"):
        raise TimingError(f"OSQP did not solve the time-parameterisation QP: {status} "
                          f"({res.info.iter} iterations, {K} grid intervals)")
    b = np.clip(res.x, 0.0, ub)
    # one common scale c ≤ 1 makes every constraint row hold exactly (all rows are homogeneous in b)
    Ab = (A @ b)[nb:]
    lo_r, up_r = lo[nb:], up[nb:]
    over = np.r_[0.0, Ab[(Ab > 0) & np.isfinite(up_r)] / up_r[(Ab > 0) & np.isfinite(up_r)],
                 Ab[(Ab < 0) & np.isfinite(lo_r)] / lo_r[(Ab < 0) & np.isfinite(lo_r)]]
    c = 1.0 / max(float(over.max()), 1.0)
    b *= c
    a = (b[1:] - b[:-1]) / (2 * h)
    # samples: every constraint point in order; at a point shared by two records keep the later
    # interval / the piece to the right (points closer than 1e-9 of the length are merged)
    order = np.lexsort((ri, rp, rs))
    ks, kp, ki = rs[order], rp[order], ri[order]
    keep = np.r_[np.diff(ks) > 1e-9 * bp.length, True]
    ks, kp, ki = ks[keep], kp[keep], ki[keep]
    ks[-1] = bp.length
    bs = np.maximum(b[ki] + 2 * a[ki] * (ks - s[ki]), 0.0)
    bs[-1] = b[-1]
    sd = np.sqrt(bs)
    with np.errstate(divide="ignore", invalid="ignore"):
        dt = 2 * np.diff(ks) / (sd[:-1] + sd[1:])
    if not np.all(np.isfinite(dt)):
        raise TimingError("the time-parameterisation QP left the path at rest over an interval "
                          "(b = 0 at both ends): limits too tight for the grid or a degenerate path")
    t = np.r_[0.0, np.cumsum(dt)]
    q, dd1, dd2 = bp.evaluate(ks, kp)
    sdd = a[ki]
    qd = dd1 * sd[:, None]
    qdd = dd1 * sdd[:, None] + dd2 * bs[:, None]
    vr = float(np.max(np.abs(qd) / vmax[None, :]))
    ar = float(np.max(np.abs(qdd) / amax[None, :]))
    return TimedTrajectory(t=t, q=q, qd=qd, qdd=qdd, s=ks, sd=sd, sdd=sdd, duration=float(t[-1]),
                           max_velocity_ratio=vr, max_acceleration_ratio=ar, path=bp, v_max=vmax, a_max=amax,
                           qp_status=status, scale=c, grid=s)
