"""The clearance kernel in numpy: what :class:`kin.geometry.ClearanceModel` runs when no C compiler is
available — the method of ``clearance.c`` (read its first comment), vectorised over configurations
and capsules instead of pruned pair by pair, with the same promise: every value a lower bound of the
true signed clearance, within :data:`~kin.geometry.clearance.TOL` of it, values above ``cap``
reported as ``cap``.

* capsule – sphere, capsule – capsule: Ericson's closest points of two segments; near-parallel
  segments by the convex minimisation below;
* capsule – box, capsule – cylinder: the minimum of the solid's signed distance along the capsule's
  segment, bracketed by the tangent lines of a convex function (secant and tangent-crossing steps);
* capsule – sphere set: the bounding-sphere hierarchy walked level by level for every capsule at
  once, pruned against an upper bound (a sphere of each node evaluated) and the running minimum.
"""
from __future__ import annotations

import numpy as np

from kin.geometry.frames import body_frames

__all__ = ["NumpyClearance", "convex_min", "seg_seg", "sdf_box", "sdf_cylinder"]

TOL = 1e-7               # as clearance.c
MAX_STEPS = 200
NEAR_PARALLEL = 1e-4
BLOCK = 1024             # configurations per pass (memory: a few MB per pass)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _clamp01(x: np.ndarray) -> np.ndarray:
    return np.clip(x, 0.0, 1.0)


def _inv(x: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return np.where(x > 0.0, 1.0 / np.where(x > 0.0, x, 1.0), 0.0)


def seg_point(a, d, idd, p) -> tuple[np.ndarray, np.ndarray]:
    """Squared distance of points p from segments a .. a + d (idd = 1/(d·d) or 0), and the parameter."""
    v = p - a
    t = _clamp01(_dot(v, d) * idd)
    w = v - t[..., None] * d
    return _dot(w, w), t


# ---- signed distance functions: value f, unit (sub)gradient n and the gradient's rounding at p (M, 3) ----
EPS = np.finfo(float).eps


def sdf_box(h: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A box of half sizes h (3,) centred on the origin; ``cond`` as in clearance.c's sdf."""
    size = np.abs(p).sum(axis=1) + h.sum()
    q = np.abs(p) - h
    o = np.maximum(q, 0.0)
    o2 = _dot(o, o)
    out = o2 > 0.0
    r = np.sqrt(o2)
    k = np.argmax(q, axis=1)
    f = np.where(out, r, q[np.arange(len(q)), k])
    n = np.zeros_like(p)
    n[np.arange(len(q)), k] = 1.0
    n = np.where(out[:, None], o * _inv(r)[:, None], n)
    cond = np.where(out, 8.0 * (1.0 + size * _inv(r)), 8.0)
    return f, np.copysign(n, p), cond


def sdf_cylinder(R: float, h: float, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A cylinder of radius R about the z axis, z in [−h, h]."""
    size = np.abs(p).sum(axis=1) + R + h
    rho = np.hypot(p[:, 0], p[:, 1])
    pos = rho > 0.0
    irho = _inv(rho)
    ux, uy = np.where(pos, p[:, 0] * irho, 1.0), np.where(pos, p[:, 1] * irho, 0.0)
    qr, qz, sz = rho - R, np.abs(p[:, 2]) - h, np.copysign(1.0, p[:, 2])
    out = (qr > 0.0) | (qz > 0.0)
    wr, wz = np.maximum(qr, 0.0), np.maximum(qz, 0.0)
    r = np.sqrt(wr * wr + wz * wz)
    ir = _inv(r)
    radial = qr >= qz
    f = np.where(out, r, np.where(radial, qr, qz))
    n = np.empty_like(p)
    n[:, 0] = np.where(out, wr * ir * ux, np.where(radial, ux, 0.0))
    n[:, 1] = np.where(out, wr * ir * uy, np.where(radial, uy, 0.0))
    n[:, 2] = np.where(out, wz * ir * sz, np.where(radial, 0.0, sz))
    cond = np.where(out, 8.0 * (1.0 + size * ir),
                    np.where(radial, 8.0 * (1.0 + np.where(pos, size * irho, np.inf)), 8.0))
    return f, n, cond


def bracket_bound(lo, flo, glo, elo, hi, fhi, ghi, ehi) -> np.ndarray:
    """clearance.c's bracket_bound: a lower bound of min f on [0, 1] from two evaluations whose slopes
    are known within e."""
    s1, s2, w = glo - elo, ghi + ehi, hi - lo
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = (s2 * flo - s1 * fhi + s1 * s2 * w) / (s2 - s1)
    lb = np.where(s1 >= 0.0, flo, np.where(s2 <= 0.0, fhi, cross))
    left = flo - lo * np.maximum(glo + elo, 0.0)
    right = fhi - (1.0 - hi) * np.maximum(ehi - ghi, 0.0)
    return np.minimum(np.minimum(lb, left), right)


def convex_min(sdf, P: np.ndarray, D: np.ndarray, thr: np.ndarray):
    """For each segment P + t·D (t in [0, 1]): a lower bound of the minimum of the convex function
    ``sdf(points) -> (f, n, cond)`` along it, within TOL of it unless the bound reaches ``thr`` — the
    method of clearance.c's convex_min, vectorised.  Returns (bound, t, f, n) of the best point seen."""
    M = len(P)
    eps = EPS * np.sqrt(_dot(D, D))
    f0, n0, c0 = sdf(P)
    g0, e0 = _dot(n0, D), eps * c0
    tb, fb, nb = np.zeros(M), f0.copy(), n0.copy()
    res = np.where(g0 - e0 >= 0.0, f0, f0 + (g0 - e0))
    act = np.flatnonzero(g0 < 0.0)
    if not len(act):
        return res, tb, fb, nb
    f1, n1, c1 = sdf(P[act] + D[act])
    g1, e1 = _dot(n1, D[act]), eps[act] * c1
    better = f1 < f0[act]
    tb[act[better]], fb[act[better]], nb[act[better]] = 1.0, f1[better], n1[better]
    at1 = g1 <= 0.0
    lb1 = np.where(g1 + e1 <= 0.0, f1, f1 - (g1 + e1))
    l0 = f0[act] + np.minimum(g0[act] - e0[act], 0.0)
    res[act[at1]] = np.maximum(l0, lb1)[at1]
    keep = ~at1
    act = act[keep]
    lo, hi = np.zeros(len(act)), np.ones(len(act))
    flo, glo, elo, fhi, ghi, ehi = f0[act], g0[act], e0[act], f1[keep], g1[keep], e1[keep]
    lb = bracket_bound(lo, flo, glo, elo, hi, fhi, ghi, ehi)
    for step in range(MAX_STEPS):
        if not len(act):
            break
        w, den = hi - lo, ghi - glo
        stop = (lb >= thr[act]) | (fb[act] - lb <= TOL) | ~(w > 1e-15)
        res[act[stop]] = lb[stop]
        go = ~stop
        act, lo, hi, flo, glo, elo, fhi, ghi, ehi, w, den, lb = (
            x[go] for x in (act, lo, hi, flo, glo, elo, fhi, ghi, ehi, w, den, lb))
        if not len(act):
            break
        if step & 1:
            t = lo + (flo - fhi + ghi * w) / den
        else:
            t = lo - glo * w / den
        margin = 0.02 * w
        t = np.minimum(np.maximum(t, lo + margin), hi - margin)
        ft, nt, ct = sdf(P[act] + t[:, None] * D[act])
        gt, et = _dot(nt, D[act]), eps[act] * ct
        better = ft < fb[act]
        tb[act[better]], fb[act[better]], nb[act[better]] = t[better], ft[better], nt[better]
        left = gt < 0.0
        lo, flo, glo, elo = (np.where(left, x, y) for x, y in ((t, lo), (ft, flo), (gt, glo), (et, elo)))
        hi, fhi, ghi, ehi = (np.where(left, y, x) for x, y in ((t, hi), (ft, fhi), (gt, ghi), (et, ehi)))
        lb = np.maximum(lb, bracket_bound(lo, flo, glo, elo, hi, fhi, ghi, ehi))
    res[act] = lb
    return res, tb, fb, nb


def seg_seg_parallel(a1, d1, a2, d2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """clearance.c's seg_seg_parallel: near-parallel segments measured across the first one's line."""
    e2 = _dot(d2, d2)
    ie = _inv(e2)
    best, t = seg_point(a2, d2, ie, a1)
    v, t1 = seg_point(a2, d2, ie, a1 + d1)
    s = np.zeros(len(a1))
    one = v < best
    best, s, t = np.where(one, v, best), np.where(one, 1.0, s), np.where(one, t1, t)
    L = np.sqrt(_dot(d1, d1))
    u = d1 / L[:, None]
    r = a2 - a1
    ru, du = _dot(r, u), _dot(d2, u)
    cp, dp = r - ru[:, None] * u, d2 - du[:, None] * u
    with np.errstate(divide="ignore", invalid="ignore"):
        x, y = -ru / du, (L - ru) / du
    tlo = np.where(du > 0, np.maximum(0.0, x), np.where(du < 0, np.maximum(0.0, y), 0.0))
    thi = np.where(du > 0, np.minimum(1.0, y), np.where(du < 0, np.minimum(1.0, x),
                                                        np.where((ru < 0) | (ru > L), -1.0, 1.0)))
    pp = _dot(dp, dp)
    with np.errstate(divide="ignore", invalid="ignore"):
        tp = np.where(pp > 0, -_dot(cp, dp) / np.where(pp > 0, pp, 1.0), tlo)
    tp = np.minimum(np.maximum(tp, tlo), thi)
    xp = cp + tp[:, None] * dp
    w2 = _dot(xp, xp)
    take = (tlo <= thi) & (w2 < best)
    best = np.where(take, w2, best)
    t = np.where(take, tp, t)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(take, _clamp01((ru + tp * du) / L), s)
    return np.sqrt(best), s, t


def seg_seg(a1, d1, a2, d2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance of segments a1 .. a1 + d1 and a2 .. a2 + d2 (M, 3 each; exact but for rounding) and the
    closest points' parameters s, t."""
    r = a1 - a2
    a, e, b, c, f = _dot(d1, d1), _dot(d2, d2), _dot(d1, d2), _dot(d1, r), _dot(d2, r)
    den = a * e - b * b
    ia, ie = _inv(a), _inv(e)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(den > 0.0, _clamp01((b * f - c * e) / np.where(den > 0.0, den, 1.0)), 0.0)
    t = _clamp01((b * s + f) * ie)
    s = _clamp01((b * t - c) * ia)
    w = r + s[:, None] * d1 - t[:, None] * d2
    dist = np.sqrt(_dot(w, w))
    near = np.flatnonzero((den <= NEAR_PARALLEL * a * e) & (a > 0.0) & (e > 0.0))
    if len(near):
        dist[near], s[near], t[near] = seg_seg_parallel(a1[near], d1[near], a2[near], d2[near])
    return dist, s, t


def _witness(p: np.ndarray, o: np.ndarray, r, ro) -> tuple[np.ndarray, np.ndarray]:
    v = o - p
    length = np.sqrt(_dot(v, v))
    u = np.where((length > 0.0)[:, None], v * _inv(length)[:, None], np.array([0.0, 0.0, 1.0]))
    r = np.asarray(r, dtype=float)
    ro = np.asarray(ro, dtype=float)
    return p + np.reshape(r, (-1, 1)) * u, o - np.reshape(ro, (-1, 1)) * u


def _first_min(keys: np.ndarray, values: np.ndarray, *payload: np.ndarray):
    """For each distinct key, the smallest value and its payload: (keys, values, *payload)."""
    order = np.lexsort((values, keys))
    k = keys[order]
    first = np.concatenate([[True], k[1:] != k[:-1]]) if len(k) else np.zeros(0, bool)
    sel = order[first]
    return (keys[sel], values[sel], *(x[sel] for x in payload))


class NumpyClearance:
    """The numpy back end of :class:`kin.geometry.ClearanceModel` (``flat``: its arrays)."""

    def __init__(self, chain, flat):
        self.chain, self.f = chain, flat

    # ---- one primitive against many capsules ---------------------------------------------------------
    def _prim(self, p: int, A, D, r, thr, want: bool):
        """Clearance of capsules (A, D, r; M each) against primitive p, and the witness points."""
        f = self.f
        kind = int(f.prim_int[p, 0])
        P = f.prim[p]
        M = len(A)
        pr = po = None
        if kind == 0 or kind == 1:
            R = P[10]
            if kind == 0:
                d2, s = seg_point(A, D, _inv(_dot(D, D)), np.broadcast_to(P[4:7], A.shape))
                v = np.sqrt(d2) - r - R
                o = np.broadcast_to(P[4:7], A.shape)
            else:
                d2v = P[7:10] - P[4:7]
                dist, s, t = seg_seg(A, D, np.broadcast_to(P[4:7], A.shape), np.broadcast_to(d2v, A.shape))
                v = dist - r - R
                o = P[4:7] + t[:, None] * d2v
            if want:
                pr, po = _witness(A + s[:, None] * D, o, r, np.full(M, R))
            return v, pr, po, None
        if kind in (2, 3):
            X, Y, Z, origin = P[12:15], P[15:18], P[18:21], P[21:24]
            Rm = np.stack([X, Y, Z], axis=1)          # columns: local → world
            a0 = A - origin
            Al = np.stack([_dot(a0, X), _dot(a0, Y), _dot(a0, Z)], axis=1)
            Dl = np.stack([_dot(D, X), _dot(D, Y), _dot(D, Z)], axis=1)
            if kind == 2:
                h = P[4:7]
                fn = lambda q: sdf_box(h, q)
            else:
                Rc, hc = P[4], P[5]
                fn = lambda q: sdf_cylinder(Rc, hc, q)
            lb, tb, fb, nb = convex_min(fn, Al, Dl, thr + r)
            v = lb - r
            if want:
                ps = A + tb[:, None] * D
                nw = nb @ Rm.T
                pr, po = ps - r[:, None] * nw, ps - fb[:, None] * nw
            return v, pr, po, None
        v, hit = self._set(int(f.prim_int[p, 2]), A, D, r, thr)
        if want:
            ok = hit >= 0
            S = f.sphere[np.where(ok, hit, 0)]
            _, s = seg_point(A, D, _inv(_dot(D, D)), S[:, :3])
            pr, po = _witness(A + s[:, None] * D, S[:, :3], r, S[:, 3])
        return v, pr, po, hit

    def _set(self, root: int, A, D, r, thr) -> tuple[np.ndarray, np.ndarray]:
        """The nearest sphere of a set below thr for each capsule (value, sphere; thr and −1 if none)."""
        f = self.f
        M = len(A)
        idd = _inv(_dot(D, D))
        best, hit = thr.astype(float).copy(), np.full(M, -1, np.int64)

        def offer(q, s):
            S = f.sphere[s]
            d2, _ = seg_point(A[q], D[q], idd[q], S[:, :3])
            v = np.sqrt(d2) - r[q] - S[:, 3]
            qq, vv, ss = _first_min(q, v, s)
            better = vv < best[qq]
            best[qq[better]], hit[qq[better]] = vv[better], ss[better]

        fq, fn = np.arange(M), np.full(M, root, np.int64)
        while len(fq):
            offer(fq, f.rep[fn])
            Nd = f.node[fn]
            d2, _ = seg_point(A[fq], D[fq], idd[fq], Nd[:, :3])
            lb = np.sqrt(d2) - r[fq] - Nd[:, 3]
            keep = lb < best[fq]
            fq, fn = fq[keep], fn[keep]
            L = f.link[fn]
            leaf = L[:, 1] < 0
            if leaf.any():
                cnt, st = -L[leaf, 1], L[leaf, 0]
                offsets = np.concatenate([[0], np.cumsum(cnt)[:-1]])
                s = np.repeat(st - offsets, cnt) + np.arange(int(cnt.sum()))
                offer(np.repeat(fq[leaf], cnt), s)
            inner = ~leaf
            fq = np.concatenate([fq[inner], fq[inner]])
            fn = np.concatenate([L[inner, 0], L[inner, 1]])
        return best, hit

    # ---- a batch ------------------------------------------------------------------------------------------
    def evaluate(self, Q: np.ndarray, mode: int, cap: float) -> dict[str, np.ndarray]:
        N = len(Q)
        B = self.f.nbody
        out: dict[str, np.ndarray] = {}
        if mode == 2:
            out["obstacle"], out["self"] = np.full((N, B), cap), np.full((N, B), cap)
        else:
            out["clearance"] = np.full(N, cap)
        if mode == 1:
            out["body"], out["other"] = np.full(N, -1, np.int64), np.full(N, -1, np.int64)
            out["point_robot"], out["point_other"] = np.full((N, 3), np.nan), np.full((N, 3), np.nan)
        for i in range(0, N, BLOCK):
            self._block(Q[i:i + BLOCK], mode, cap, {k: v[i:i + BLOCK] for k, v in out.items()})
        return out

    def _block(self, Q: np.ndarray, mode: int, cap: float, out: dict[str, np.ndarray]) -> None:
        f = self.f
        N, C = len(Q), len(f.cap)
        if C == 0 or N == 0:
            return
        F = body_frames(self.chain, Q, f.world_base)
        Fc = F[:, f.cap_body]                                                 # (N, C, 4, 4)
        Rb, ob = Fc[:, :, :3, :3], Fc[:, :, :3, 3]
        A = np.einsum("ncij,cj->nci", Rb, f.cap[:, :3]) + ob
        D = np.einsum("ncij,cj->nci", Rb, f.cap[:, 3:6]) + ob - A
        r = f.cap[:, 6]
        want = mode == 1
        rows = np.arange(N)

        def report(v, caps, other, pr, po):
            """v (N, k) values of capsules `caps` against `other` (obstacle index, or −1 − body)."""
            if mode == 2:
                key = "obstacle" if other >= 0 else "self"
                for b in np.unique(f.cap_body[caps]):
                    cols = f.cap_body[caps] == b
                    np.minimum(out[key][:, b], v[:, cols].min(axis=1), out=out[key][:, b])
                return
            j = np.argmin(v, axis=1)
            vj = v[rows, j]
            better = vj < out["clearance"]
            out["clearance"][better] = vj[better]
            if want:
                out["body"][better] = f.cap_body[caps][j[better]]
                out["other"][better] = other
                out["point_robot"][better] = pr[rows, j][better]
                out["point_other"][better] = po[rows, j][better]

        for p in range(len(f.prim)):
            mask = int(f.prim_int[p, 3])
            caps = np.flatnonzero([(mask >> int(b)) & 1 == 0 for b in f.cap_body])
            if not len(caps):
                continue
            k = len(caps)
            if mode == 2:
                thr = out["obstacle"][:, f.cap_body[caps]]
            else:
                thr = np.repeat(out["clearance"][:, None], k, axis=1)
            a, d = A[:, caps].reshape(-1, 3), D[:, caps].reshape(-1, 3)
            rr = np.tile(r[caps], N)
            v, pr, po, _ = self._prim(p, a, d, rr, thr.reshape(-1), want)
            v = np.minimum(v.reshape(N, k), thr)
            report(v, caps, int(f.prim_int[p, 1]), None if pr is None else pr.reshape(N, k, 3),
                   None if po is None else po.reshape(N, k, 3))
        for bi, bj in f.pair:
            ci = np.arange(f.body_cap[bi], f.body_cap[bi + 1])
            cj = np.arange(f.body_cap[bj], f.body_cap[bj + 1])
            for u in ci:
                rr = r[u] + r[cj]
                dist, s, t = seg_seg(np.repeat(A[:, u], len(cj), axis=0), np.repeat(D[:, u], len(cj), axis=0),
                                     A[:, cj].reshape(-1, 3), D[:, cj].reshape(-1, 3))
                v = dist.reshape(N, len(cj)) - rr
                pr = po = None
                if want:
                    p1 = np.repeat(A[:, u], len(cj), axis=0) + s[:, None] * np.repeat(D[:, u], len(cj), axis=0)
                    p2 = A[:, cj].reshape(-1, 3) + t[:, None] * D[:, cj].reshape(-1, 3)
                    pr, po = _witness(p1, p2, np.full(len(p1), r[u]), np.tile(r[cj], N))
                    pr, po = pr.reshape(N, len(cj), 3), po.reshape(N, len(cj), 3)
                if mode == 2:
                    m = v.min(axis=1)
                    np.minimum(out["self"][:, bi], m, out=out["self"][:, bi])
                    np.minimum(out["self"][:, bj], m, out=out["self"][:, bj])
                else:
                    report(v, np.full(len(cj), u), -1 - int(bj), pr, po)
