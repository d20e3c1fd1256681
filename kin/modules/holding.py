"""Whether each joint can hold the rest of the chain at rest: its gravity torque (force) against its
``max_torque`` over every configuration within the joint limits.

For joint j two numbers bracket the largest |g_j(q)| over the limits:

* a **bound** that no configuration exceeds.  A revolute joint's gravity torque is
  Σ_{k ≥ j} m_k (c_k − o) × g · z_j for any point o on its axis, so |g_j| ≤ |g| Σ m_k ‖c_k − o_{j−1}‖,
  and only the part of c_k − o_{j−1} across the axis counts: at most the DH rows' moves j … k across
  it plus ‖c_k‖ in frame k (the payload's through the tool transform).  A row moves d_i along z_i,
  then a_i across it: while z_i stays parallel to z_j in every configuration (every revolute joint
  from j to i turns about a parallel axis; row j always) only |a_i| counts, else the whole move
  √(a_i² + d_i²) (the largest over a prismatic joint's travel).  A prismatic joint carries at most
  |g| Σ_{k ≥ j} m_k.  Where the axis keeps its direction z_j in every configuration (every revolute
  joint before it turns about a parallel axis: joint 1 always), only gravity across it counts — the
  bound is multiplied by |ĝ × z_j| (|ĝ · z_j| for a prismatic joint): 0 for a vertical first axis;
* a **witness**: the largest |g_j| found at configurations within the limits — a Halton sample
  (scipy.stats.qmc, unscrambled: no seed) refined by bounded local maximisation from its best points.

Verdict per joint: ``holds`` (bound ≤ max_torque: proven), ``fails`` (witness > max_torque: proven,
the configuration is given), ``unproven`` (in between: held at every configuration tried), or
``unknown`` (no max_torque).  Gravity is the chain's (``chain.gravity``, in its base placement's frame).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kin.chain import Chain

__all__ = ["HoldingReport", "holding", "gravity_bound"]

SAMPLES = 512         # Halton configurations per chain
REFINE = 3            # local maximisations per joint, from the best samples


@dataclass(frozen=True)
class HoldingReport:
    """Per joint: ``bound`` (N·m or N, proven upper bound of |g_j| over the limits), ``witness`` (the
    largest |g_j| found) at ``witness_q`` (SI), ``max_torque`` (nan: unknown), ``verdict``."""

    bound: np.ndarray
    witness: np.ndarray
    witness_q: np.ndarray
    max_torque: np.ndarray
    verdict: tuple[str, ...]

    @property
    def fails(self) -> list[int]:
        """The joints (0-based) that provably cannot hold the chain."""
        return [j for j, v in enumerate(self.verdict) if v == "fails"]

    def failure_text(self, chain: Chain) -> str:
        j = self.fails[0]
        name = chain.joints[j].name or f"joint {j + 1}"
        unit = "N·m" if chain.joints[j].is_revolute else "N"
        q = chain.from_si(self.witness_q[j])
        return (f"joint {j + 1} ({name}) cannot hold the rest of the chain at rest: gravity needs "
                f"{self.witness[j]:.4g} {unit} at q = ({', '.join(f'{x:.4g}' for x in np.ravel(q))}) "
                f"({chain.angle_unit}, {chain.length_unit}), beyond its max_torque {self.max_torque[j]:.4g} {unit}")

    def lines(self, chain: Chain) -> list[str]:
        out = []
        for j, v in enumerate(self.verdict):
            unit = "N·m" if chain.joints[j].is_revolute else "N"
            tm = "unknown" if math.isnan(self.max_torque[j]) else f"{self.max_torque[j]:.4g} {unit}"
            out.append(f"joint {j + 1} ({chain.joints[j].name or j + 1}): {v} — gravity at most "
                       f"{self.bound[j]:.4g} {unit} (bound), {self.witness[j]:.4g} {unit} found; max_torque {tm}")
        return out


def _masses(chain: Chain) -> tuple[np.ndarray, np.ndarray]:
    """Mass (kg) and ‖com‖ (m, in its own frame: body k's DH frame, the payload's via the tool) per body 1…n+1."""
    n = chain.n
    m, r = np.zeros(n + 1), np.zeros(n + 1)
    for k, j in enumerate(chain.joints):
        if j.inertia is not None:
            m[k], r[k] = j.inertia.mass, float(np.linalg.norm(j.inertia.com))
    if chain.payload is not None:
        T = chain.tool.matrix
        m[n] = chain.payload.mass
        r[n] = float(np.linalg.norm(T[:3, :3] @ np.asarray(chain.payload.com) + T[:3, 3]))
    return m, r


def gravity_bound(chain: Chain) -> np.ndarray:
    """The proven bound of |g_j(q)| over the joint limits, per joint (N·m or N; module text)."""
    from kin.geometry.frames import body_frames
    if chain.convention != "standard":
        raise ValueError("gravity_bound takes a standard-DH chain")
    n = chain.n
    g = float(np.linalg.norm(chain.gravity))
    m, r = _masses(chain)
    dh = chain.dh_table()
    step = np.zeros(n)           # the largest distance between DH frame origins i−1 and i
    across = np.abs(dh[:, 0])    # |a_i|: the row's move across z_i
    for i, (j, (a, _alpha, d, _theta)) in enumerate(zip(chain.joints, dh)):
        if j.is_revolute:
            step[i] = math.hypot(a, d)
        else:
            step[i] = max(math.hypot(a, d + j.limits[0]), math.hypot(a, d + j.limits[1]))
    # z_j at q = 0 in the base placement's frame; it keeps its direction in every configuration when
    # every revolute joint before j turns about an axis parallel to it
    zs = body_frames(chain, np.zeros((1, n)))[0, :n, :3, 2]      # DH frames 0 … n−1
    gu = np.asarray(chain.gravity, float) / g if g > 0 else np.zeros(3)
    out = np.zeros(n)
    for j in range(n):
        fixed = all(np.linalg.norm(np.cross(zs[i], zs[j])) < 1e-12
                    for i in range(j) if chain.joints[i].is_revolute)
        if not chain.joints[j].is_revolute:
            out[j] = g * float(m[j:].sum()) * (abs(float(gu @ zs[j])) if fixed else 1.0)
            continue
        # each DH row's largest move across axis j: only |a_i| while z_i stays parallel to z_j (every
        # revolute joint from j to i turns about a parallel axis), else the whole move
        part = step.copy()
        steady = True
        for i in range(j, n):
            if steady and np.linalg.norm(np.cross(zs[i], zs[j])) < 1e-12:
                part[i] = across[i]
            elif chain.joints[i].is_revolute:
                steady = False
        total = 0.0
        for k in range(j, n + 1):              # body k + 1 (0-based k: joint k's body; k = n: the payload)
            reach = float(part[j:min(k, n - 1) + 1].sum()) + r[k]
            total += m[k] * reach
        out[j] = g * total * (float(np.linalg.norm(np.cross(gu, zs[j]))) if fixed else 1.0)
    return out


def holding(chain: Chain) -> HoldingReport:
    """The holding verdict of every joint of ``chain`` (a standard-DH chain with inertial data)."""
    from scipy.optimize import minimize
    from scipy.stats import qmc

    import kin

    n = len(chain.joints)
    tmax = np.array([np.nan if j.max_torque is None else j.max_torque for j in chain.joints])
    bound = gravity_bound(chain)
    witness, wq = np.zeros(n), np.zeros((n, n))
    massive = any(j.inertia is not None and j.inertia.mass > 0 for j in chain.joints) or \
        (chain.payload is not None and chain.payload.mass > 0)
    if massive:
        robot = kin.Robot(chain, backend="vm")
        lo, hi = chain.lower, chain.upper
        Q = lo + qmc.Halton(d=n, scramble=False).random(SAMPLES + 1)[1:] * (hi - lo)
        G = np.abs(np.asarray(robot.gravity(Q)).reshape(-1, n))
        for j in range(n):
            if bound[j] <= (tmax[j] if not math.isnan(tmax[j]) else -1):
                best = int(np.argmax(G[:, j]))
                witness[j], wq[j] = G[best, j], Q[best]
                continue
            order = np.argsort(-G[:, j])[:REFINE]
            witness[j], wq[j] = G[order[0], j], Q[order[0]]
            for s in order:
                res = minimize(lambda x, j=j: -float(np.asarray(robot.gravity(x))[j]) ** 2, Q[s], method="L-BFGS-B",
                               bounds=list(zip(lo, hi)), options={"maxiter": 60})
                v = abs(float(np.asarray(robot.gravity(res.x))[j]))
                if v > witness[j]:
                    witness[j], wq[j] = v, np.clip(res.x, lo, hi)
    verdict = []
    for j in range(n):
        if math.isnan(tmax[j]):
            verdict.append("unknown")
        elif bound[j] <= tmax[j]:
            verdict.append("holds")
        elif witness[j] > tmax[j]:
            verdict.append("fails")
        else:
            verdict.append("unproven")
    return HoldingReport(bound, witness, wq, tmax, tuple(verdict))
