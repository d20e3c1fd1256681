"""Task coverage decided by inverse kinematics.

A target is *covered* by a design when some configuration within the joint limits reaches it
(position within the tolerance, with its orientation requirement) with the required dexterity.
IK is seeded from a nearest-neighbour index (scikit-learn ``NearestNeighbors``, a KD-tree) over the
forward kinematics of sampled configurations: every target gets the ``seeds`` nearest samples as
initial guesses, one IK run each (plus one random start of that run's seed), so the answer is
deterministic given ``seed``.  A target is covered when any seed's solution passes; a target
*flips* when the seeds disagree (an IK that is seed-sensitive is a known failure of reach studies).

Orientation requirements: "pose" is solved as a pose; "axis" (tool z along a given axis, free
rotation about it) by pose IK at ``spins`` equally spaced rotations about the axis; "cone" (tool
axis within a half-angle of the axis) additionally at six axes tilted by the half-angle.

In a work cell (``cell``, a :class:`planning.cell.Cell`) a target counts only when a seed's solution is
also clear of the cell and of the robot itself (by the required ``clearance``, m): ``blocked`` marks
the targets reached only through a collision — the coverage that collisions remove.  Each design gets
its own robot geometry (a default geometry follows the design's link lengths).

Many designs are verified in one batch (:func:`coverage_of_designs`): every (design, target, seed)
is one row of the same IK call, which is what makes grids and differential evolution affordable.
Everything SI; σ_min of the translational rows in m/rad.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from sklearn.neighbors import NearestNeighbors

import kin
from design.task.model import Dexterity, Targets, TaskError
from design.task.targets import orientation_variants

__all__ = ["Coverage", "coverage", "coverage_of_designs", "dexterity_jacobian", "dexterity_measure",
           "seed_configurations"]


@dataclass
class Coverage:
    """Coverage of one design.  Arrays are per target (N,) unless stated.

    reached: IK found a configuration (tolerance, limits, orientation);  covered: reached with the
    dexterity; best: best dexterity measure over the seeds' solutions (NaN where not reached);
    inverse_condition: 1/κ of the dexterity Jacobian at that solution (NaN where not reached);
    q (N, n): that configuration (SI); verdicts (N, seeds): covered per seed; flips: targets whose
    verdict changes across seeds.
    """

    reached: np.ndarray
    covered: np.ndarray
    best: np.ndarray
    inverse_condition: np.ndarray
    q: np.ndarray
    verdicts: np.ndarray
    measure: str
    threshold: float
    blocked: np.ndarray | None = None      # (N,) reached, but only in collision (None: no work cell)

    @property
    def flips(self) -> int:
        return int(np.sum(self.verdicts.any(axis=1) & ~self.verdicts.all(axis=1)))

    @property
    def reach_fraction(self) -> float:
        return float(self.reached.mean())

    @property
    def fraction(self) -> float:
        """Covered share of the targets (0..1)."""
        return float(self.covered.mean())

    @property
    def gci(self) -> float:
        """Global conditioning index: mean 1/κ over the covered targets (0 when none is covered)."""
        return float(self.inverse_condition[self.covered].mean()) if self.covered.any() else 0.0

    def to_dict(self) -> dict:
        return {"targets": int(len(self.covered)), "reach_percent": 100 * self.reach_fraction,
                "coverage_percent": 100 * self.fraction, "flips": self.flips, "seeds": int(self.verdicts.shape[1]),
                "measure": self.measure, "threshold": self.threshold, "gci": self.gci,
                "best": self.best, "covered": self.covered,
                "blocked_by_collision": None if self.blocked is None else int(self.blocked.sum())}


def dexterity_jacobian(robot: kin.Robot, J: np.ndarray, dex: Dexterity) -> np.ndarray:
    """The Jacobian (N, m, n) the dexterity requirement is measured on: the translational rows, or
    (``sigma_min_full``) all six rows made dimensionless by the characteristic length L (linear rows
    ÷ L, prismatic columns × L)."""
    if dex.kind == "sigma_min_full":
        L = dex.characteristic_length
        Jh = J.copy()
        Jh[:, :, ~robot.chain.revolute_mask] *= L
        Jh[:, :3, :] /= L
        return Jh
    return J[:, :3, :]


def dexterity_measure(robot: kin.Robot, Q: np.ndarray, dex: Dexterity, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(measure, 1/κ) at configurations Q (M, n) with parameter rows P (M, n_p) or (n_p,)."""
    J = robot.jacobian(Q, params=P)
    sv = np.linalg.svd(dexterity_jacobian(robot, J, dex), compute_uv=False)
    inv_cond = np.where(sv[:, 0] > 0, sv[:, -1] / np.where(sv[:, 0] > 0, sv[:, 0], 1.0), 0.0)
    if dex.kind == "manipulability":
        return robot.manipulability(Q, params=P), inv_cond
    return sv[:, -1], inv_cond


def seed_configurations(robot: kin.Robot, targets: Targets, P: np.ndarray, k: int, Qs: np.ndarray) -> np.ndarray:
    """IK seeds: for every target the k sampled configurations Qs (M, n) whose tool positions (and
    tool axes, weighted by the targets' extent, when the task has axes) are nearest, found with a
    scikit-learn KD-tree.  P is one design (n_p,) → (N, k, n), or D designs (D, n_p) → (D, N, k, n);
    the forward kinematics of all designs run as one batch."""
    P = np.asarray(P, float)
    one = P.ndim == 1
    P = np.atleast_2d(P)
    D, M = len(P), len(Qs)
    scale = max(float(np.ptp(targets.positions, axis=0).max()), 0.1)
    query = targets.positions if targets.axes is None else np.hstack([targets.positions, scale * targets.axes])
    out = np.empty((D, len(targets), k, robot.n))
    per = max(1, (1 << 20) // M)                     # designs per FK batch (about a million rows)
    for s in range(0, D, per):
        Pc = P[s:s + per]
        T = robot.fk(np.tile(Qs, (len(Pc), 1)), params=np.repeat(Pc, M, axis=0)).reshape(len(Pc), M, 4, 4)
        for d in range(len(Pc)):
            feats = T[d, :, :3, 3] if targets.axes is None else np.hstack([T[d, :, :3, 3], scale * T[d, :, :3, 2]])
            nn = NearestNeighbors(n_neighbors=k, algorithm="kd_tree").fit(feats)
            out[s + d] = Qs[nn.kneighbors(query, return_distance=False)]
    return out[0] if one else out


def coverage_of_designs(robot: kin.Robot, targets: Targets, dexterity: Dexterity | None, P: np.ndarray,
                        seeds: int = 4, samples: int = 5000, seed: int = 0, spins: int = 4,
                        max_iter: int = 150, cell=None, clearance: float = 0.0) -> list[Coverage]:
    """Coverage of every design row of P (D, n_p) (SI parameter vectors), verified in one IK batch.

    ``samples`` configurations are sampled once (seeded) and mapped through each design's FK to
    build that design's nearest-neighbour index; ``seeds`` IK seeds per target; ``cell``: a work cell
    whose collisions (and self-collisions) rule a solution out, with the required ``clearance`` (m).
    """
    dex = dexterity or Dexterity()
    chain = robot.chain
    P = np.atleast_2d(np.asarray(P, dtype=float))
    if P.shape[1] != len(chain.parameters):
        raise TaskError(f"design parameter rows have {P.shape[1]} values; {robot.name} has "
                        f"{len(chain.parameters)} ({', '.join(chain.parameters) or 'none'})")
    for name, (lo, hi), col in zip(chain.parameters, (p.bounds for p in chain.parameters.values()), P.T):
        if np.any(col < lo - 1e-12) or np.any(col > hi + 1e-12):
            raise TaskError(f"design parameter {name} outside its bounds [{lo:g}, {hi:g}] (SI)")
    if not (1 <= seeds <= 64) or not (seeds <= samples <= 10_000_000):
        raise TaskError(f"seeds {seeds} must be in [1, 64] and samples {samples} in [seeds, 1e7]")
    D, N, n = len(P), len(targets), robot.n
    V = orientation_variants(targets, spins)
    nv = 1 if V is None else V.shape[1]
    Qs = robot.random_configurations(samples, seed=seed)
    k = min(seeds, samples)
    starts = seed_configurations(robot, targets, P, k, Qs)
    rows_d = np.repeat(np.arange(D), N * nv)                 # row layout: design, target, variant
    rows_t = np.tile(np.repeat(np.arange(N), nv), D)
    if V is None:
        goal = targets.positions[rows_t]
    else:
        goal = np.tile(np.eye(4), (len(rows_t), 1, 1))
        goal[:, :3, :3] = V.reshape(N * nv, 3, 3)[np.tile(np.arange(N * nv), D)]
        goal[:, :3, 3] = targets.positions[rows_t]
    Prow = P[rows_d]
    mode = "position" if V is None else "pose"
    worlds = _worlds(robot, P, cell, clearance) if cell is not None else None
    ok = np.zeros((D, N, k), bool)
    reach_any = np.zeros((D, N), bool)
    meas = np.full((D, N, k), np.nan)
    icond = np.full((D, N, k), np.nan)
    qsol = np.zeros((D, N, k, n))
    for j in range(k):
        q0 = starts[rows_d, rows_t, j]
        res = robot.ik(goal, seed=seed + 7919 * (j + 1), q0=q0, mode=mode, restarts=1, rounds=1,
                       max_iter=max_iter, tol_position=targets.tolerance, params=Prow)
        good = np.asarray(res.success, bool)
        if worlds is not None:
            reach_any |= good.reshape(D, N, nv).any(axis=2)
            for d, w in enumerate(worlds):
                rows = np.flatnonzero(good & (rows_d == d))
                if len(rows):
                    good[rows] = w.clearance(res.q[rows]) > w.margin
        m, ic = np.full(len(good), np.nan), np.full(len(good), np.nan)
        if good.any():
            m[good], ic[good] = dexterity_measure(robot, res.q[good], dex, Prow[good])
        # best variant per (design, target): reached first, then the largest measure
        score = np.where(good, np.nan_to_num(m, nan=-1.0) + 1.0, -1.0).reshape(D, N, nv)
        bi = score.argmax(axis=2)
        pick = (np.arange(D)[:, None] * N + np.arange(N)[None]) * nv + bi
        ok[:, :, j] = good[pick]
        meas[:, :, j], icond[:, :, j] = m[pick], ic[pick]
        qsol[:, :, j] = res.q[pick]
    thr = dex.value if dex.kind != "none" else -np.inf
    verdict = ok & (np.nan_to_num(meas, nan=-np.inf) >= thr)
    out = []
    for d in range(D):
        score = np.where(ok[d], np.nan_to_num(meas[d], nan=-1.0), -np.inf)
        b = score.argmax(axis=1)
        ar = np.arange(N)
        out.append(Coverage(reached=ok[d].any(axis=1), covered=verdict[d].any(axis=1), best=meas[d, ar, b],
                            inverse_condition=icond[d, ar, b], q=qsol[d, ar, b], verdicts=verdict[d],
                            measure=dex.kind, threshold=float(dex.value),
                            blocked=None if worlds is None else reach_any[d] & ~ok[d].any(axis=1)))
    return out


def _worlds(robot: kin.Robot, P: np.ndarray, cell, clearance: float) -> list:
    """One collision world per design row (its own link lengths, hence its own default geometry)."""
    from planning.collision import collision_world
    if not len(robot.chain.parameters):
        w = collision_world(robot, cell, clearance)
        return [w] * len(P)
    names = list(robot.chain.parameters)
    return [collision_world(kin.Robot(robot.chain.with_parameters(dict(zip(names, p))).frozen()), cell, clearance)
            for p in P]


def coverage(robot: kin.Robot, targets: Targets, dexterity: Dexterity | None = None, params=None,
             seeds: int = 4, samples: int = 20_000, seed: int = 0, spins: int = 4, cell=None,
             clearance: float = 0.0) -> Coverage:
    """Coverage of ``targets`` by ``robot`` at design ``params`` (mapping or vector, SI; None = nominal),
    in the work ``cell`` (None: no collisions) with the required ``clearance`` (m)."""
    p = robot.chain.parameter_vector(params)
    return coverage_of_designs(robot, targets, dexterity, p[None], seeds, samples, seed, spins, cell=cell,
                               clearance=clearance)[0]
