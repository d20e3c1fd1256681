"""Analytic inverse kinematics of 6R arms whose joints 2, 3 and 4 have parallel axes (the Universal
Robots family: UR3e, UR5e, UR10e, UR16e): every branch, in closed form.

The chain is read in modified DH (``Chain.to_modified``; rows i = 1…6 hold a_{i−1}, α_{i−1}, d_i and
the offset of θ_i = q_i + offset).  The structure is read from the DH values, not from the robot's
name: all six joints revolute, axes 2, 3, 4 parallel (sin α₂ = sin α₃ = 0), axis 1 not parallel to
them (sin α₁ ≠ 0), a₂·a₃ ≠ 0 (a planar two-link arm between them), a₅ = 0 (frame 5's origin is
the flange minus d₆ along z₆) and sin α₄·sin α₅ ≠ 0 (the wrist axes 5 and 6 are not parallel to
their neighbours).  A twist α₂ or α₃ of π is folded away first: Rx(π)·Rz(θ)Tz(d) = Rz(−θ)Tz(−d)·Rx(π),
so θ₃, θ₄ and d₃, d₄ change sign and α₄ takes the π.

With α₂ = α₃ = 0 the middle of the chain is Tz(D)·Rz(θ₂)Tx(a₂)Rz(θ₃)Tx(a₃)Rz(θ₄), D = d₂ + d₃ + d₄: a
planar 3R arm in the plane normal to the parallel axes.  Write V = M⁻¹·Tz(d₁)⁻¹·Rz(θ₁)⁻¹·G⁻¹·W with
G = Rx(α₀)Tx(a₀), M = Rx(α₁)Tx(a₁)Tz(D) and W the flange pose (tool removed):

* θ₁: frame 5's origin o₅ = p₆ − d₆·z₆ lies at height cα₄·d₅ along the parallel axes, whatever
  θ₂…θ₄; in the frame of axis 1 that reads sα₁(s₁x − c₁y) = cα₄d₅ + D − cα₁(z − d₁): two θ₁.
* θ₅: the third column of V's rotation has z-component cα₄cα₅ − sα₄sα₅·cos θ₅: two θ₅ (±).
* θ₆: the parallel axis seen from frame 6, V's third row, is Rz(−θ₆)·(s₅sα₄, cα₅c₅sα₄ + sα₅cα₄, ·):
  θ₆ is the angle between the two (free when that vector vanishes — axes 4 and 6 aligned, the wrist
  singularity — where θ₆ is taken from the reference configuration).
* θ₂, θ₃, θ₄: V·(Rx(α₄)Tx(a₄)Rz(θ₅)Tz(d₅)Rx(α₅)Rz(θ₆)Tz(d₆))⁻¹ = Rz(θ₂)Tx(a₂)Rz(θ₃)Tx(a₃)Rz(θ₄): a
  planar two-link arm (θ₃ = ±acos, two elbows) and φ = θ₂ + θ₃ + θ₄ from its rotation.

So 2 shoulder × 2 wrist × 2 elbow = 8 branches at a generic pose.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kin.chain import Chain
from kin.ik.trig import rx as _rx
from kin.ik.trig import rz as _rz
from kin.ik.trig import trans as _trans
from kin.ik.trig import two_angles as _two_angles

__all__ = ["ParallelArm", "parallel_arm", "parallel_candidates"]


@dataclass(frozen=True)
class ParallelArm:
    """The modified-DH constants of a 6R chain with parallel axes 2, 3, 4, α₂ = α₃ = 0 after folding
    (``sign``: the factor of θ₃ and θ₄ that folding introduced, ±1 each; see the module docstring)."""

    a: np.ndarray          # (6,) a_{i−1}
    alpha: np.ndarray      # (6,) α_{i−1}, folded
    d: np.ndarray          # (6,) d_i, folded
    offset: np.ndarray     # (6,) θ_i − q_i
    sign: np.ndarray       # (6,) θ_real = sign · θ_folded
    base_inv: np.ndarray   # 4×4, (base · G)⁻¹
    tool_inv: np.ndarray   # 4×4, tool⁻¹
    lower: np.ndarray
    upper: np.ndarray


def parallel_arm(chain: Chain, params=None) -> ParallelArm | str:
    """The closed-form structure of ``chain`` (design parameters at ``params`` or nominal), or a
    sentence saying which condition fails (see the module docstring)."""
    if chain.n != 6 or not all(j.is_revolute for j in chain.joints):
        return f"analytic IK needs six revolute joints (has {chain.n}: {', '.join(chain.joint_types)})"
    m = chain.frozen(params).to_modified()
    tab = m.dh_table()
    a, al, d, off = tab[:, 0].copy(), tab[:, 1].copy(), tab[:, 2].copy(), tab[:, 3].copy()
    scale = max(np.abs(tab[:, [0, 2]]).max(), 1e-3)
    if abs(math.sin(al[2])) > 1e-9 or abs(math.sin(al[3])) > 1e-9:
        return "joints 2, 3 and 4 do not have parallel axes (modified DH needs α2, α3 of 0 or 180°)"
    if abs(math.sin(al[1])) < 1e-9:
        return "axis 1 is parallel to axes 2, 3 and 4"
    if abs(a[2]) <= 1e-9 * scale or abs(a[3]) <= 1e-9 * scale:
        return "no planar two-link arm between the parallel axes (modified DH needs a2, a3 ≠ 0)"
    if abs(a[5]) > 1e-9 * scale or abs(math.sin(al[4])) < 1e-9 or abs(math.sin(al[5])) < 1e-9:
        return "the wrist does not fit (modified DH needs a5 = 0 and wrist twists α4, α5 not 0 or 180°)"
    sign = np.ones(6)
    s3 = 1.0 if math.cos(al[2]) > 0 else -1.0          # fold Rx(π) out of α₂, then out of α₃
    s4 = s3 * (1.0 if math.cos(al[3]) > 0 else -1.0)
    sign[2], sign[3] = s3, s4
    d[2], d[3] = s3 * d[2], s4 * d[3]
    al[2] = al[3] = 0.0
    if s4 < 0:
        al[4] += math.pi
    G = _rx(al[0]) @ _trans(a[0])
    return ParallelArm(a=a, alpha=al, d=d, offset=off, sign=sign, base_inv=np.linalg.inv(m.base.matrix @ G),
                       tool_inv=np.linalg.inv(m.tool.matrix), lower=m.lower, upper=m.upper)


def _wrist_tail(arm: ParallelArm, t5: float, t6: float) -> np.ndarray:
    al, a, d = arm.alpha, arm.a, arm.d
    return _rx(al[4]) @ _trans(a[4]) @ _rz(t5) @ _trans(z=d[4]) @ _rx(al[5]) @ _rz(t6) @ _trans(z=d[5])


def parallel_candidates(arm: ParallelArm, W: np.ndarray, theta_ref: np.ndarray) -> list[np.ndarray]:
    """Joint angles θ (6,) of every branch for the flange pose W (robot base frame, tool removed);
    ``theta_ref`` (6,): the angles θ₆ takes where it is free (the wrist singularity)."""
    a, al, d = arm.a, arm.alpha, arm.d
    Wb = arm.base_inv @ W
    p5 = Wb[:3, 3] - d[5] * Wb[:3, 2]
    s1a, c1a, s4a, c4a = math.sin(al[1]), math.cos(al[1]), math.sin(al[4]), math.cos(al[4])
    s5a, c5a = math.sin(al[5]), math.cos(al[5])
    D = d[1] + d[2] + d[3]
    K = c4a * d[4] + D - c1a * (p5[2] - d[0])
    Minv = np.linalg.inv(_rx(al[1]) @ _trans(a[1]) @ _trans(z=D))
    out = []
    for t1 in _two_angles(-s1a * p5[1], s1a * p5[0], K):
        V = Minv @ np.linalg.inv(_trans(z=d[0])) @ _rz(-t1) @ Wb
        c5 = (c4a * c5a - V[2, 2]) / (s4a * s5a)
        if abs(c5) > 1 + 1e-9:
            continue
        if 1 - abs(c5) < 1e-12:             # θ₅ within ~1.4e-6 rad of 0 or π: the singular family (polished later)
            c5 = math.copysign(1.0, c5)
        base5 = math.acos(max(-1.0, min(1.0, c5)))
        for t5 in ([base5, -base5] if 1e-12 < base5 < math.pi - 1e-12 else [base5]):
            x = math.sin(t5) * s4a
            y = c5a * math.cos(t5) * s4a + s5a * c4a
            if abs(c5) < 1.0 and math.hypot(x, y) > 1e-10:
                t6 = math.atan2(y, x) - math.atan2(V[2, 1], V[2, 0])
            else:                                  # axes 4 and 6 aligned: θ₆ free, the reference's
                t6 = float(theta_ref[5])
            P = V @ np.linalg.inv(_wrist_tail(arm, t5, t6))
            px, py = P[0, 3], P[1, 3]
            phi = math.atan2(P[1, 0], P[0, 0])
            c3 = (px * px + py * py - a[2] ** 2 - a[3] ** 2) / (2 * a[2] * a[3])
            if abs(c3) > 1 + 1e-9:
                continue
            base3 = math.acos(max(-1.0, min(1.0, c3)))
            for t3 in ([base3, -base3] if base3 > 1e-12 else [0.0]):
                t2 = math.atan2(py, px) - math.atan2(a[3] * math.sin(t3), a[2] + a[3] * math.cos(t3))
                t4 = phi - t2 - t3
                th = np.array([t1, t2, t3, t4, t5, t6]) * arm.sign
                out.append(np.arctan2(np.sin(th), np.cos(th)))
    return out
