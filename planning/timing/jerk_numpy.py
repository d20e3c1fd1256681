"""The jerk pass of :mod:`planning.timing.jerk` in numpy, for machines without a C compiler: the same
convex-concave passes and the same primal-dual interior-point method (Mehrotra's predictor-corrector,
pentadiagonal Newton systems solved by :func:`scipy.linalg.solveh_banded`) as ``jerk_ipm.c`` — see
its first comment — about ten times slower.

Rows are ``g·b[c0:c0+3] ≤ r`` on windows of three consecutive b (``c0 ≤ K − 2``).
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import LinAlgError, solveh_banded

__all__ = ["jerk_passes"]


def _intervals(b: np.ndarray, h: np.ndarray, hessian: bool = False):
    """Δt of every interval at b and its derivatives (zero in a variable at 0)."""
    u, w = np.sqrt(np.maximum(b[:-1], 0.0)), np.sqrt(np.maximum(b[1:], 0.0))
    S = u + w
    with np.errstate(divide="ignore", invalid="ignore"):
        gx = np.where(u > 0, -h / (S * S * u), 0.0)
        gy = np.where(w > 0, -h / (S * S * w), 0.0)
        if not hessian:
            return 2 * h / S, gx, gy
        hxx = np.where(u > 0, h / (S ** 3 * u * u) + h / (2 * S * S * u ** 3), 0.0)
        hyy = np.where(w > 0, h / (S ** 3 * w * w) + h / (2 * S * S * w ** 3), 0.0)
        hxy = np.where((u > 0) & (w > 0), h / (S ** 3 * u * w), 0.0)
    return 2 * h / S, gx, gy, hxx, hyy, hxy


def _gradient(b, h):
    T, gx, gy = _intervals(b, h)
    g = np.zeros(len(b))
    g[:-1] += gx
    g[1:] += gy
    return float(T.sum()), g


def _apply(c0, G, x):
    """G·x on the windows: (M,)."""
    return G[:, 0] * x[c0] + G[:, 1] * x[c0 + 1] + G[:, 2] * x[c0 + 2]


def _apply_t(c0, G, y, n):
    """Gᵀ·y (n,)."""
    return (np.bincount(c0, G[:, 0] * y, n) + np.bincount(c0 + 1, G[:, 1] * y, n)
            + np.bincount(c0 + 2, G[:, 2] * y, n))


def _ipm(c0, G, r, h, free, b, lam, maxit, gap_tol):
    """Minimise T(b) under G·b ≤ r from a strictly feasible b (see ``jerk_ipm.c``); (b, lam, iterations)."""
    n, M = len(b), len(r)
    s = r - _apply(c0, G, b)
    if not np.all(s > 0):
        return None, None, -1
    T, _ = _gradient(b, h)
    floor = 1e-3 * T / (M * s)
    lam = T / (M * s) if lam is None else np.maximum(lam, floor)
    for it in range(maxit):
        eta = float(s @ lam)
        T, grad = _gradient(b, h)
        rd = grad + _apply_t(c0, G, lam, n)
        if eta <= gap_tol * T and np.max(np.abs(rd[free])) <= 1e-6 * np.max(np.abs(grad[free])):
            return b, lam, it
        mu = eta / M
        _, _, _, hxx, hyy, hxy = _intervals(b, h, True)
        w = lam / s
        ab = np.zeros((3, n))                              # lower form: ab[k, i] = H[i + k, i]
        ab[0, :-1] += hxx
        ab[0, 1:] += hyy
        ab[1, :-1] += hxy
        for p in range(3):
            ab[0] += np.bincount(c0 + p, w * G[:, p] ** 2, n)
        ab[1] += np.bincount(c0, w * G[:, 0] * G[:, 1], n) + np.bincount(c0 + 1, w * G[:, 1] * G[:, 2], n)
        ab[2] += np.bincount(c0, w * G[:, 0] * G[:, 2], n)
        ab[0] += 1e-14 * ab[0].max()
        fixed = ~free
        ab[0, fixed] = 1.0
        ab[1, fixed] = 0.0
        ab[2, fixed] = 0.0
        ab[1, :-1][fixed[1:]] = 0.0
        ab[2, :-2][fixed[2:]] = 0.0

        def solve(e):
            x = -grad - (0.0 if e is None else _apply_t(c0, G, e / s, n))
            x[fixed] = 0.0
            dbx = solveh_banded(ab, x, lower=True)
            gd = _apply(c0, G, dbx)
            return dbx, -gd, ((0.0 if e is None else e) + lam * gd) / s - lam

        def step(ds, dl, frac):
            with np.errstate(divide="ignore"):
                a = min(1.0, float(np.min(np.where(dl < 0, -frac * lam / dl, np.inf), initial=np.inf)),
                        float(np.min(np.where(ds < 0, -frac * s / ds, np.inf), initial=np.inf)))
            return a

        try:
            _, dsa, dla = solve(None)
            aa = step(dsa, dla, 1.0)
            sigma = (float((s + aa * dsa) @ (lam + aa * dla)) / M / mu) ** 3
            db, ds, dl = solve(sigma * mu - dsa * dla)
        except (LinAlgError, ValueError):
            return None, None, -2
        alpha = step(ds, dl, 0.99)
        if alpha < 1e-4:
            break
        bn = b + alpha * db
        sn = r - _apply(c0, G, bn)
        if not np.all(sn > 0):
            break
        b, s, lam = bn, sn, lam + alpha * dl
    return b, lam, it


def jerk_passes(h, free, xcap, iv, A, C, R, jc0, jd, kch, jmax, ref, passes, tol, maxit):
    """The passes of ``rmt_jerk`` (same arguments, as arrays): (b, status), status 0 when all went well."""
    K = len(h)
    n = len(jmax)
    last = K - 2
    sc0 = np.minimum(iv, last)
    Gs = np.zeros((len(A), 3))
    p = iv - sc0
    rows = np.arange(len(A))
    Gs[rows, p] = A / R
    Gs[rows, p + 1] = C / R
    fi = np.flatnonzero(free)
    ci = fi[xcap[fi] < 1e12]
    bc0 = np.r_[np.minimum(fi, last), np.minimum(ci, last)]
    Gb = np.zeros((len(bc0), 3))
    Gb[np.arange(len(fi)), fi - bc0[:len(fi)]] = -1.0
    Gb[len(fi) + np.arange(len(ci)), ci - bc0[len(fi):]] = 1.0 / xcap[ci]
    rb = np.r_[np.zeros(len(fi)), np.ones(len(ci))]
    # jerk rows: change m, joint j, sign ∓ (the C order)
    mm = np.repeat(np.arange(K + 2), 2 * n)
    jj = np.tile(np.repeat(np.arange(n), 2), K + 2)
    sg = np.tile([-1.0, 1.0], n * (K + 2))
    jrow_c0 = jc0[mm]
    kk = kch[mm]
    c0 = np.r_[sc0, bc0, jrow_c0].astype(np.int64)
    bh = ref.copy()
    T_prev, _ = _gradient(bh, h)
    lam = None
    for _ in range(passes):
        dt, gx, gy = _intervals(bh, h)
        rhs = jmax[jj] * (dt[kk] - gx[kk] * bh[kk] - gy[kk] * bh[kk + 1])
        Gj = sg[:, None] * jd[mm, jj]
        Gj[np.arange(len(mm)), kk - jrow_c0] -= jmax[jj] * gx[kk]
        Gj[np.arange(len(mm)), kk + 1 - jrow_c0] -= jmax[jj] * gy[kk]
        G = np.vstack([Gs, Gb, Gj / rhs[:, None]])
        r = np.r_[np.ones(len(A)), rb, np.ones(len(mm))]
        cs = 0.99
        for _ in range(60):
            if np.all(r - _apply(c0, G, cs * bh) > 0):
                break
            cs *= 0.7
        else:
            return bh, -3
        b, lam, it = _ipm(c0, G, r, h, free, cs * bh, lam, maxit, 1e-7)
        if it < 0:
            return bh, it
        T, _ = _gradient(b, h)
        if not T < T_prev:
            break
        bh = b
        improved = T < T_prev * (1 - tol)
        T_prev = T
        if not improved:
            break
    return bh, 0
