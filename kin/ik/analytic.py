"""Analytic inverse kinematics of 6R arms with a spherical wrist (Pieper's solution): every branch.
Arms whose joints 2, 3, 4 are parallel instead (the UR family) are solved by :mod:`kin.ik.parallel`;
:func:`analytic_ik` dispatches to whichever structure the DH values show (:func:`closed_form`).

The chain is read in modified DH (``Chain.to_modified``; rows i = 1…6 hold a_{i−1}, α_{i−1}, d_i and
the offset of θ_i = q_i + offset).  It has a closed form when all six joints are revolute and the
last three axes meet in one point — a₄ = a₅ = 0, d₅ = 0, sin α₄ ≠ 0, sin α₅ ≠ 0 — which makes that
point, frame 4's origin, the wrist centre.  The structure is read from the DH values, not from the
robot's name.

Position (Pieper): the wrist centre o₄ = p₆ − d₆·z₆ follows from the target.  With G = Rx(α₀)Tx(a₀)Tz(d₁)
and P = G⁻¹·o₄ = Rz(θ₁)·g(θ₂, θ₃), where h(θ₃) = Rx(α₂)Tx(a₂)Rz(θ₃)Tz(d₃)·(a₃, −sα₃d₄, cα₃d₄) + d₂·ẑ:

    r = |P|² = a₁² + |h|² + 2a₁(h₁c₂ − h₂s₂),     z = P_z = sα₁(h₁s₂ + h₂c₂) + cα₁h₃.

θ₃ solves r alone (a₁ = 0: quadratic in tan θ₃/2), z alone (sα₁ = 0) or, eliminating θ₂,
((r − a₁² − |h|²)/2a₁)² + ((z − cα₁h₃)/sα₁)² = h₁² + h₂² (a quartic in tan θ₃/2); its polynomial
is found by interpolation at five points and its real roots are polished by Newton steps.  θ₂ then
follows from the linear pair (or the one equation: two solutions), θ₁ from atan2.

Orientation: M = Rx(α₃)ᵀ·R₀₃ᵀ·R₀₆ = Rz(θ₄)Rx(α₄)Rz(θ₅)Rx(α₅)Rz(θ₆).  Its third column m = M·ẑ gives
sα₄(s₄m_x − c₄m_y) = cα₅ − cα₄m_z (two θ₄), then θ₅ from Rz(θ₅)·Rx(α₅)ẑ = Rx(−α₄)Rz(−θ₄)·m and θ₆
from the remaining rotation about z.

So up to 4 arm × 2 wrist = 8 branches.  Every candidate gets two Gauss–Newton polishing steps on the
FK (the compiled evaluator) and is kept only when its position and orientation errors are below
``tol`` and it lies within the joint limits (angles are moved by whole turns into the limits).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from kin.chain import Chain
from kin.errors import RmtError
from kin.ik.numeric import _targets
from kin.ik.trig import EPS as _EPS
from kin.ik.trig import rx as _rx
from kin.ik.trig import rz as _rz
from kin.ik.trig import trans as _trans
from kin.ik.trig import two_angles as _two_angles
from kin.transforms import rotation_error

__all__ = ["NoClosedFormError", "PieperArm", "analytic_branches", "analytic_ik", "closed_form", "pieper_arm",
           "turn_copies"]


class NoClosedFormError(RmtError):
    """The chain has no closed-form IK here (not six revolute joints with a spherical wrist)."""


@dataclass(frozen=True)
class PieperArm:
    """The modified-DH constants of a spherical-wrist 6R chain (see the module docstring)."""

    a: np.ndarray          # (6,) a_{i−1}
    alpha: np.ndarray      # (6,) α_{i−1}
    d: np.ndarray          # (6,) d_i
    offset: np.ndarray     # (6,) θ_i − q_i
    base: np.ndarray       # 4×4, base · G   (G = Rx(α₀)Tx(a₀)Tz(d₁))
    tool_inv: np.ndarray   # 4×4, tool⁻¹
    lower: np.ndarray
    upper: np.ndarray

    def h(self, t3: float) -> np.ndarray:
        """h(θ₃) (3,): the wrist centre in frame 2 (before Rz(θ₂)), plus d₂ along z."""
        a, al, d = self.a, self.alpha, self.d
        p3 = np.array([a[3], -math.sin(al[3]) * d[3], math.cos(al[3]) * d[3], 1.0])
        f = _rx(al[2]) @ _trans(a[2]) @ _rz(t3) @ _trans(z=d[2]) @ p3
        return f[:3] + np.array([0.0, 0.0, d[1]])

    def h_terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(h₀, h_c, h_s) with h(θ₃) = h₀ + h_c·cos θ₃ + h_s·sin θ₃ (h is linear in cos θ₃, sin θ₃)."""
        hA, hB, hC = self.h(0.0), self.h(math.pi / 2), self.h(math.pi)
        h0 = (hA + hC) / 2
        return h0, (hA - hC) / 2, hB - h0


def pieper_arm(chain: Chain, params=None) -> PieperArm:
    """The closed-form structure of ``chain`` (design parameters at ``params`` or nominal); raises
    :class:`NoClosedFormError` naming what is missing."""
    if chain.n != 6 or not all(j.is_revolute for j in chain.joints):
        raise NoClosedFormError(f"{chain.name}: analytic IK needs six revolute joints "
                                f"(has {chain.n}: {', '.join(chain.joint_types)})")
    m = chain.frozen(params).to_modified()
    tab = m.dh_table()
    a, al, d, off = tab[:, 0], tab[:, 1], tab[:, 2], tab[:, 3]
    scale = max(np.abs(tab[:, [0, 2]]).max(), 1e-3)
    if abs(a[4]) > 1e-9 * scale or abs(a[5]) > 1e-9 * scale or abs(d[4]) > 1e-9 * scale \
            or abs(math.sin(al[4])) < 1e-9 or abs(math.sin(al[5])) < 1e-9:
        raise NoClosedFormError(f"{chain.name}: no spherical wrist (the last three joint axes do not meet in one "
                                f"point: modified DH needs a4 = a5 = 0, d5 = 0 and wrist twists α4, α5 not 0 or π)")
    if abs(a[1]) <= 1e-9 * scale and abs(math.sin(al[1])) < 1e-9:
        raise NoClosedFormError(f"{chain.name}: joints 1 and 2 share their axis; the arm has no closed form")
    G = _rx(al[0]) @ _trans(a[0]) @ _trans(z=d[0])
    return PieperArm(a=a, alpha=al, d=d, offset=off, base=m.base.matrix @ G,
                     tool_inv=np.linalg.inv(m.tool.matrix), lower=m.lower, upper=m.upper)


def _trig_roots(F, scale: float) -> list[float]:
    """Real roots in (−π, π] of F(θ) → (value, derivative), a trigonometric polynomial of degree ≤ 2
    (F·(1 + u²)² is a quartic in u = tan θ/2), each polished by Newton steps that lower |F|."""
    us = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
    vals = np.array([F(2 * math.atan(u))[0] * (1 + u * u) ** 2 for u in us])
    coef = np.linalg.solve(np.vander(us, 5), vals)          # highest power first
    big = np.abs(coef).max()
    if big <= 1e-14 * scale:
        return []                                            # F ≡ 0: no isolated solution
    roots: list[float] = []
    c = coef.copy()
    while abs(c[0]) <= 1e-12 * big and len(c) > 1:          # degree drops: a root at u = ∞ (θ = π)
        c = c[1:]
    if len(c) < len(coef):
        roots.append(math.pi)
    if len(c) > 1:
        for u in np.roots(c):
            if abs(u.imag) <= 1e-5 * (1 + abs(u.real)):
                roots.append(2 * math.atan(u.real))
    out = []
    for t in roots:
        f0, df = F(t)
        for _ in range(8):
            if df == 0 or not math.isfinite(df) or f0 == 0:
                break
            tn = t - f0 / df
            fn, dfn = F(tn)
            if not abs(fn) < abs(f0):
                break
            t, f0, df = tn, fn, dfn
        out.append(math.atan2(math.sin(t), math.cos(t)))
    return out


def _arm_candidates(arm: PieperArm, W: np.ndarray) -> list[np.ndarray]:
    """Joint angles θ (6,) of every branch for frame 6's pose W (chain base frame, tool removed)."""
    a, al, d = arm.a, arm.alpha, arm.d
    o4 = W[:3, 3] - d[5] * W[:3, 2]
    P = np.linalg.solve(arm.base, np.append(o4, 1.0))[:3]   # G⁻¹·base⁻¹·o₄ (base folded in)
    r, z = float(P @ P), float(P[2])
    a1, s1, c1 = a[1], math.sin(al[1]), math.cos(al[1])
    use_r, use_z = abs(a1) > _EPS, abs(s1) > 1e-12      # θ₂ appears in r / in z
    scale = max(r, 1e-6)

    h0, hc, hs = arm.h_terms()

    def F(t3: float) -> tuple[float, float]:
        c3, s3 = math.cos(t3), math.sin(t3)
        h = h0 + hc * c3 + hs * s3
        dh = hs * c3 - hc * s3
        rr, drr = r - a1 * a1 - h @ h, -2.0 * (h @ dh)      # r − a₁² − |h|² and its derivative
        zz, dzz = z - c1 * h[2], -c1 * dh[2]
        if use_r and use_z:
            R, Z = rr / (2 * a1), zz / s1
            return (R * R + Z * Z - (h[0] ** 2 + h[1] ** 2),
                    2 * R * drr / (2 * a1) + 2 * Z * dzz / s1 - 2 * (h[0] * dh[0] + h[1] * dh[1]))
        # θ₂ drops out of r when a₁ = 0, out of z when sin α₁ = 0: that equation alone fixes θ₃
        return (rr, drr) if not use_r else (zz, dzz)

    out = []
    for t3 in _trig_roots(F, scale):
        h = h0 + hc * math.cos(t3) + hs * math.sin(t3)
        k1, k2 = h[0], -h[1]
        R = (r - a1 * a1 - h @ h) / (2 * a1) if use_r else None
        Z = (z - c1 * h[2]) / s1 if use_z else None
        if R is not None and Z is not None:
            den = k1 * k1 + k2 * k2
            if den < _EPS:
                continue
            t2s = [math.atan2((k2 * R + k1 * Z) / den, (k1 * R - k2 * Z) / den)]
        elif R is not None:
            t2s = _two_angles(k1, k2, R)
        else:
            t2s = _two_angles(-k2, k1, Z)
        for t2 in t2s:
            u = _rz(t2)[:3, :3] @ h
            g = np.array([a1 + u[0], c1 * u[1] - s1 * u[2], s1 * u[1] + c1 * u[2]])
            t1 = math.atan2(P[1], P[0]) - math.atan2(g[1], g[0]) if math.hypot(g[0], g[1]) > _EPS else 0.0
            out.extend(_wrist(arm, W, t1, t2, t3))
    return out


def _wrist(arm: PieperArm, W: np.ndarray, t1: float, t2: float, t3: float) -> list[np.ndarray]:
    al = arm.alpha
    R03 = (arm.base @ _rz(t1) @ _rx(al[1]) @ _rz(t2) @ _rx(al[2]) @ _rz(t3))[:3, :3]
    M = _rx(al[3])[:3, :3].T @ R03.T @ W[:3, :3]
    m = M[:, 2]
    s4a, c4a, s5a, c5a = math.sin(al[4]), math.cos(al[4]), math.sin(al[5]), math.cos(al[5])
    t4s = _two_angles(-s4a * m[1], s4a * m[0], c5a - c4a * m[2]) or [0.0]   # [0]: axes 4 and 6 aligned
    v = np.array([0.0, -s5a, c5a])
    out = []
    for t4 in t4s:
        w = _rx(-al[4])[:3, :3] @ _rz(-t4)[:3, :3] @ m
        t5 = math.atan2(v[0] * w[1] - v[1] * w[0], v[0] * w[0] + v[1] * w[1])
        Rr = (_rz(t4) @ _rx(al[4]) @ _rz(t5) @ _rx(al[5]))[:3, :3].T @ M
        t6 = math.atan2(Rr[1, 0], Rr[0, 0])
        out.append(np.array([t1, t2, t3, t4, t5, t6]))
    return out


def _into_limits(q: np.ndarray, lo: np.ndarray, hi: np.ndarray, ref: np.ndarray, all_turns: bool) -> list[np.ndarray]:
    """Whole turns added to each angle to bring it within [lo, hi]: the one nearest ``ref`` (or all)."""
    choices = []
    for x, lo_k, hi_k, r in zip(q, lo, hi, ref):
        k0 = math.ceil((lo_k - x) / (2 * math.pi) - 1e-12)
        vals = [x + 2 * math.pi * k for k in range(k0, k0 + 8) if x + 2 * math.pi * k <= hi_k + 1e-12]
        vals = [min(max(v, lo_k), hi_k) for v in vals]
        if not vals:
            return []
        choices.append(vals if all_turns else [min(vals, key=lambda v: abs(v - r))])
    out = [np.array([])]
    for vals in choices:
        out = [np.append(o, v) for o in out for v in vals]
    return out


def turn_copies(q: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Every whole-turn copy of configuration ``q`` (revolute angles, SI) within [lower, upper]:
    (k, n), k = 0 when some joint has no copy inside its limits."""
    return np.array(_into_limits(np.asarray(q, dtype=float), lower, upper, q, True)).reshape(-1, len(q))


def _errors(robot, Q, T, P) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    res = robot.evaluator.evaluate(Q, P, 3)                 # WANT_T | WANT_J
    Tq, J = res["T"], res["J"]
    ep = T[:3, 3] - Tq[:, :3, 3]
    eo = rotation_error(np.broadcast_to(T[:3, :3], Tq[:, :3, :3].shape), Tq[:, :3, :3])
    return ep, eo, J, Tq


def closed_form(chain: Chain, params=None):
    """The closed-form structure of ``chain``: a :class:`PieperArm` (spherical wrist) or a
    :class:`kin.ik.parallel.ParallelArm` (joints 2, 3, 4 parallel, the UR family); raises
    :class:`NoClosedFormError` saying why neither fits."""
    from kin.ik.parallel import parallel_arm
    try:
        return pieper_arm(chain, params)
    except NoClosedFormError as e:
        arm = parallel_arm(chain, params)
        if isinstance(arm, str):
            raise NoClosedFormError(f"{e}; nor is it a parallel-axes arm: {arm}") from None
        return arm


def _prepare(robot, T, params):
    """(closed-form arm, target positions, rotations (None for positions alone), single, parameter
    values) of an IK call."""
    chain = robot.chain
    arm = closed_form(chain, None if params is None else chain.parameter_vector(params))
    Pt, Rt, single = _targets(T, f"for {chain.name}")
    P = chain.parameter_values if params is None else chain.parameter_vector(params)
    return arm, Pt, Rt, single, P


def _reference(chain, q_ref) -> np.ndarray:
    """The reference configuration (6,) SI: ``q_ref`` checked, or zero."""
    return np.zeros(6) if q_ref is None else chain.as_batch(q_ref, "q_ref")[0][0]


def _thetas(arm, Tt: np.ndarray, ref: np.ndarray) -> list[np.ndarray]:
    """The closed form's joint angles θ (offsets included) reaching the pose ``Tt`` (4×4)."""
    from kin.ik.parallel import ParallelArm, parallel_candidates
    W = Tt @ arm.tool_inv
    return parallel_candidates(arm, W, ref + arm.offset) if isinstance(arm, ParallelArm) else _arm_candidates(arm, W)


def analytic_ik(robot, T, params=None, q_ref=None, all_turns: bool = False, tol: float = 1e-9):
    """Every IK branch of a 6R arm with a closed form (a spherical wrist, or joints 2, 3, 4 parallel as
    on the UR family, :mod:`kin.ik.parallel`) within the joint limits.

    Parameters
    ----------
    T : target pose (4, 4) or batch (N, 4, 4), base frame, SI (a rigid transform).
    params : design parameters (mapping or (n_p,)); None: nominal.
    q_ref : (6,) each branch is moved by whole turns into the limits nearest this configuration
        (default 0); ``all_turns``: list every whole-turn copy of every branch within the limits
        instead (up to 2⁶ per branch on joints of ±360°).
    tol : a branch is kept when its FK position error (m) and orientation error (rad) are ≤ tol.

    Returns (k, 6) configurations, SI, sorted by distance to ``q_ref`` (k = 0 when the target is out
    of reach or every branch is beyond the limits), or a list of such arrays for a batch.  Raises
    :class:`NoClosedFormError` for a chain without a closed form.
    """
    arm, Pt, Rt, single, P = _prepare(robot, T, params)
    if Rt is None:
        raise NoClosedFormError("analytic IK needs a pose target (4, 4); a position alone has a continuum of solutions")
    ref = _reference(robot.chain, q_ref)
    results = []
    for p, R in zip(Pt, Rt):
        Tt = np.eye(4)
        Tt[:3, :3], Tt[:3, 3] = R, p
        cands = [q for th in _thetas(arm, Tt, ref)
                 for q in _into_limits(th - arm.offset, arm.lower, arm.upper, ref, False)]
        Q = _verified(robot, cands, Tt, P, arm, tol, ref)
        if all_turns and len(Q):
            Q = _dedup([c for q in Q for c in _into_limits(q, arm.lower, arm.upper, ref, True)], ref)
        results.append(Q)
    return results[0] if single else results


def analytic_branches(robot, T, params=None, q_ref=None, tol: float = 1e-9) -> np.ndarray:
    """Every IK branch of one pose T (4, 4; base frame, SI) whatever the joint limits: (k, 6), each
    branch once, as the whole-turn copy nearest ``q_ref`` (default 0), verified by FK to ``tol``,
    sorted by distance to ``q_ref``.  An empty result means out of reach.  Raises
    :class:`NoClosedFormError` as :func:`analytic_ik`."""
    arm, Pt, Rt, single, P = _prepare(robot, T, params)
    if Rt is None or not single:
        raise NoClosedFormError("analytic branches need one pose target (4, 4)")
    ref = _reference(robot.chain, q_ref)
    Tt = np.eye(4)
    Tt[:3, :3], Tt[:3, 3] = Rt[0], Pt[0]
    cands = [ref + np.mod(th - arm.offset - ref + math.pi, 2 * math.pi) - math.pi for th in _thetas(arm, Tt, ref)]
    unlimited = replace(arm, lower=np.full(6, -np.inf), upper=np.full(6, np.inf))   # the polish clips nothing
    return _verified(robot, cands, Tt, P, unlimited, tol, ref)


def _dedup(Q, ref) -> np.ndarray:
    """The distinct rows of Q (1e-7), sorted by distance to ``ref``."""
    Q = np.asarray(Q, dtype=float).reshape(-1, 6)
    keep: list[np.ndarray] = []
    for q in Q[np.argsort(np.linalg.norm(Q - ref, axis=1), kind="stable")]:
        if all(np.abs(q - k).max() > 1e-7 for k in keep):
            keep.append(q)
    return np.array(keep).reshape(-1, 6)


def _verified(robot, cands, Tt, P, arm, tol, ref) -> np.ndarray:
    if not cands:
        return np.zeros((0, 6))
    Q = np.array(cands)
    ep, eo, J, _ = _errors(robot, Q, Tt, P)
    for _ in range(2):                                       # Gauss–Newton polish on the real FK
        e = np.concatenate([ep, eo], axis=1)
        err = np.linalg.norm(e, axis=1)
        todo = err > 1e-14                                   # the closed form is usually exact already
        if not todo.any():
            break
        step = (np.linalg.pinv(J[todo], rcond=1e-10) @ e[todo, :, None])[:, :, 0]
        Qn = np.clip(Q[todo] + step, arm.lower, arm.upper)
        epn, eon, Jn, _ = _errors(robot, Qn, Tt, P)
        better = np.linalg.norm(np.concatenate([epn, eon], 1), axis=1) < err[todo]
        idx = np.nonzero(todo)[0][better]
        Q[idx], ep[idx], eo[idx], J[idx] = Qn[better], epn[better], eon[better], Jn[better]
    ok = (np.linalg.norm(ep, axis=1) <= tol) & (np.linalg.norm(eo, axis=1) <= tol)
    return _dedup(Q[ok], ref)
