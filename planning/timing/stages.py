"""The discretised time-parameterisation problem shared by every solver of
:func:`planning.timing.time_parameterize`: the grid, the constraint points and the linear rows in
b = ṡ² (:class:`Stages`, built by :func:`build_stages`).

Grid and variables.  The grid s_0 < … < s_K is uniform (``K`` intervals) plus every stop; the
variables are b_0…b_K; s̈ is constant on each interval, a_i = (b_{i+1} − b_i)/(2·h_i), so b is
linear in s there.  Every piece of the path is a quadratic, so on the part of an interval that lies
on one piece (a "segment") q″ is constant and q′(s) linear: q̈ = q′·a_i + q″·b(s) is linear in s,
and |q̈_j| ≤ A_j at both ends of every segment bounds it on the whole segment.  For the speed,
q′_j(s)²·b(s) is a product of two non-negative functions that peak at an end, so κ·b(end) ≤ 1 with
κ = max over joints and both ends of q′_j²/v_j² bounds it on the whole segment too.  With the exact
s(t) of a piecewise-constant s̈ the continuous trajectory therefore meets both limits everywhere.

Every row involves one interval only: ``ci·b_i + cj·b_{i+1} ∈ [lo, up]`` (``iv`` = i), so the stage
problem of TOPP-RA is a two-variable LP.  The speed and acceleration rows are homogeneous in b (the
bounds are 0, ±A_j or 1); the torque rows of :mod:`planning.timing.torque` are not (gravity), but
every row has lo ≤ 0 ≤ up — b = 0 is feasible — so by convexity scaling a feasible b by c ∈ [0, 1]
keeps it feasible.

SI units throughout: rad, rad/s, rad/s² for revolute joints, m, m/s, m/s² for prismatic ones.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planning.timing.trajectory import BlendedPath, TimingError

__all__ = ["Stages", "build_stages", "max_velocity_curve", "sample_profile"]


@dataclass
class Stages:
    """The rows of the discretised problem (see the module docstring).

    ``s`` (K+1,) grid; ``h`` (K,) its steps; ``ub`` (K+1,) upper bound of each b (0 at both ends and
    at stops, else inf); ``beta`` (K+1,) the maximum velocity curve at the grid points, or an upper
    bound of it (see :func:`build_stages`; every feasible b_i ≤ beta_i; inf where nothing bounds it);
    rows ``iv, ci, cj, lo, up`` (R,) sorted by
    interval; the constraint points ``ri, rs, rp, theta`` (2·segments,) with ``d1, d2`` (…, n) = q′, q″
    there (pairs (0, 1), (2, 3), … are the two ends of one segment).
    """

    s: np.ndarray
    h: np.ndarray
    ub: np.ndarray
    beta: np.ndarray
    iv: np.ndarray
    ci: np.ndarray
    cj: np.ndarray
    lo: np.ndarray
    up: np.ndarray
    ri: np.ndarray
    rs: np.ndarray
    rp: np.ndarray
    theta: np.ndarray
    d1: np.ndarray
    d2: np.ndarray

    @property
    def K(self) -> int:
        return len(self.h)

    def samples(self, length: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """s, piece, interval (S,) of the trajectory's samples: every constraint point in order; at a
        point shared by two records the later interval / the piece to the right (points closer than
        1e-9 of the path ``length`` are merged)."""
        order = np.lexsort((self.ri, self.rp, self.rs))
        ks, kp, ki = self.rs[order], self.rp[order], self.ri[order]
        keep = np.r_[np.diff(ks) > 1e-9 * length, True]
        ks, kp, ki = ks[keep], kp[keep], ki[keep]
        ks[-1] = length
        return ks, kp, ki

    def residual_scale(self, b: np.ndarray) -> float:
        """The largest c ≤ 1 such that c·b meets every row (rows with lo ≤ 0 ≤ up: a row value v
        outside [lo, up] comes back in at c = up/v or lo/v, and stays in for smaller c by convexity)."""
        v = self.ci * b[self.iv] + self.cj * b[self.iv + 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            r_up = np.where((v > self.up) & (v > 0), v / np.maximum(self.up, 0.0), 0.0)
            r_lo = np.where((v < self.lo) & (v < 0), v / np.minimum(self.lo, 0.0), 0.0)
        worst = max(float(np.max(r_up, initial=0.0)), float(np.max(r_lo, initial=0.0)), 1.0)
        return 1.0 / worst


def _grid(bp: BlendedPath, K: int, grid: np.ndarray | None = None) -> np.ndarray:
    """Grid points s (≥ K+1): uniform (or ``grid``), plus every stop (an unblended corner must be a
    grid point — the trajectory is at rest there)."""
    s = np.linspace(0.0, bp.length, K + 1) if grid is None else np.asarray(grid, dtype=float)
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


def max_velocity_curve(d1: np.ndarray, d2: np.ndarray, amax: np.ndarray) -> np.ndarray:
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


def build_stages(bp: BlendedPath, K: int, vmax: np.ndarray, amax: np.ndarray, full_mvc: bool = True,
                 grid: np.ndarray | None = None) -> Stages:
    """The grid of ``K`` uniform intervals (plus stops) over ``bp`` — or the given increasing ``grid``
    from 0 to the path's length (stops added) — and every row of the problem (module docstring);
    ``vmax``, ``amax`` (n,) validated limits.  ``full_mvc=False``: ``beta`` is only the speed part of
    the maximum velocity curve where that bounds b (still an upper bound of every feasible b_i, all
    the reachability passes need; cheaper)."""
    n = bp.n
    s = _grid(bp, K, grid)
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
    ub = np.full(K + 1, np.inf)
    ub[0] = ub[-1] = 0.0
    for st in bp.stops:
        ub[np.argmin(np.abs(s - st))] = 0.0
    # speed: on a segment q′_j(s) is linear and b(s) = (1 − θ)·b_i + θ·b_{i+1} too, so
    # sup q′_j²·b ≤ max(q′_j² at its ends)·max(b at its ends): κ·b(end) ≤ 1 at both ends
    kap = np.max(d1 ** 2 / vmax[None, :] ** 2, axis=1)
    kappa = np.repeat(np.maximum(kap[0::2], kap[1::2]), 2)
    sv = np.flatnonzero(kappa > 0)
    iv = [ri[sv]]
    ci = [kappa[sv] * (1 - theta[sv])]
    cj = [kappa[sv] * theta[sv]]
    lo = [np.full(len(sv), -np.inf)]
    up = [np.ones(len(sv))]
    # acceleration: q′_j·(b_{i+1} − b_i)/(2h_i) + q″_j·b(s) ∈ [−A_j, A_j]
    for j in range(n):
        sel = np.flatnonzero((np.abs(d1[:, j]) > 1e-15) | (np.abs(d2[:, j]) > 1e-15))
        c1, c2, th, g = d1[sel, j], d2[sel, j], theta[sel], inv2h[sel]
        iv.append(ri[sel])
        ci.append(-c1 * g + c2 * (1 - th))
        cj.append(c1 * g + c2 * th)
        lo.append(np.full(len(sel), -amax[j]))
        up.append(np.full(len(sel), amax[j]))
    iv_a = np.concatenate(iv)
    o = np.argsort(iv_a, kind="stable")
    # the maximum velocity curve at the grid points bounds every feasible b_i; without ``full_mvc``
    # only its speed part (1/κ), plus the acceleration part where the speed does not bound b (q′ = 0)
    mvc = np.where(kappa > 0, 1.0 / np.where(kappa > 0, kappa, 1.0), np.inf)
    need = slice(None) if full_mvc else np.flatnonzero(kappa <= 0)
    mvc[need] = np.minimum(mvc[need], max_velocity_curve(d1[need], d2[need], amax))
    beta = np.full(K + 1, np.inf)
    at = np.where(theta <= 0.0, ri, np.where(theta >= 1.0, ri + 1, -1))
    on = at >= 0
    np.minimum.at(beta, at[on], mvc[on])
    return Stages(s=s, h=h, ub=ub, beta=beta, iv=iv_a[o], ci=np.concatenate(ci)[o], cj=np.concatenate(cj)[o],
                  lo=np.concatenate(lo)[o], up=np.concatenate(up)[o], ri=ri, rs=rs, rp=rp, theta=theta,
                  d1=d1, d2=d2)


def sample_profile(st: Stages, b: np.ndarray, bp: BlendedPath) -> tuple[np.ndarray, ...]:
    """The samples of profile ``b`` on ``st``: t, q, q̇, q̈, s, ṡ, s̈ at every constraint point in order
    (a point shared by two records keeps the later interval / the piece to the right; points closer
    than 1e-9 of the length are merged).  Raises :class:`TimingError` when b = 0 at both ends of an
    interval (the path would be at rest there forever)."""
    a = (b[1:] - b[:-1]) / (2 * st.h)
    ks, kp, ki = st.samples(bp.length)
    bs = np.maximum(b[ki] + 2 * a[ki] * (ks - st.s[ki]), 0.0)
    bs[-1] = b[-1]
    sd = np.sqrt(bs)
    with np.errstate(divide="ignore", invalid="ignore"):
        dt = 2 * np.diff(ks) / (sd[:-1] + sd[1:])
    if not np.all(np.isfinite(dt)):
        raise TimingError("the time parameterisation left the path at rest over an interval "
                          "(b = 0 at both ends): limits too tight for the grid or a degenerate path")
    t = np.r_[0.0, np.cumsum(dt)]
    q, d1, d2 = bp.evaluate(ks, kp)
    sdd = a[ki]
    qd = d1 * sd[:, None]
    qdd = d1 * sdd[:, None] + d2 * bs[:, None]
    return t, q, qd, qdd, ks, sd, sdd
