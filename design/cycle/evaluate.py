"""The motion cycle of one design: its stop configurations by IK, the joint path between them, its
minimum-time timing and the motor torques along it (:func:`evaluate_cycle`, :class:`CycleResult`).

1. **Stops.**  Every target of the cycle's sequence is solved by IK (:meth:`kin.Robot.ik`) from
   ``ik_starts`` seeded random configurations; the distinct solutions (more than 1e-3 apart) are its
   candidate branches (a SCARA's elbow left and right).  With ``lift``, each candidate also needs the
   point ``lift`` above its target, solved from it.  Targets must be position-only ("free") or "pose".
2. **Branches.**  One candidate per stop is chosen for the whole cycle by dynamic programming over the
   closed sequence, minimising the sum of each segment's time estimate: per joint the rest-to-rest
   trapezoid (or triangle) time of its travel under v_max, a_max, the slowest joint counting, summed
   over the segment's legs.
3. **Path.**  Segment i runs from stop i to stop i + 1 (the last back to the first) along straight
   joint-space lines: stop → above it → above the next → next stop with ``lift``, else stop → next
   stop.  The tool rests at every stop (grasp, release: rest to rest); the corners above the stops are
   blended by :func:`planning.timing.blend_path` (``blend``), which passes them within blend/2 in joint
   space without stopping.  The tool's path between stops is straight in joint space, not in space.
4. **Timing.**  Each segment is timed by :func:`planning.timing.time_parameterize` — minimum time under
   the per-joint speed and acceleration limits, and with ``torque = "limit"`` under the motor torque
   limits too (the timing's ``robot``/``tau_max``); the cycle time is the sum plus ``dwell`` per stop.
5. **Torques.**  τ(t) = inverse dynamics (:meth:`kin.Robot.inverse_dynamics`) of the chain carrying the
   design's link mass model (:mod:`design.cycle.masses`; the robot's own inertial data when the spec
   has none), on ``PER_INTERVAL`` + 1 times in every
   interval of each segment's trajectory (both ends: q̈ jumps between intervals), from its exact s(t).
   The peak |τ_j| over the cycle, and its ratio to tau_max_j, are the metrics.

SI throughout: s, N·m (N for a prismatic joint).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

import kin
from design.cycle.masses import chain_own_masses, chain_with_masses
from design.cycle.model import CycleSpec
from design.task.model import Targets, TaskError
from planning.timing import time_parameterize
from planning.timing.limits import dense_times

__all__ = ["CycleResult", "evaluate_cycle", "stop_configurations", "choose_branches", "rest_to_rest_time",
           "cycle_paths", "PER_INTERVAL", "TORQUE_TOL"]

#: torque samples per trajectory interval (plus its end)
PER_INTERVAL = 4
#: a peak torque within this relative margin of tau_max meets it
TORQUE_TOL = 1e-6
_SAME = 1e-3            # candidate solutions closer than this (joint-space norm, SI) are one branch


def rest_to_rest_time(dq, v_max, a_max) -> np.ndarray:
    """Minimum rest-to-rest time (s) of joint travels ``dq`` (..., n) under v_max, a_max (n,), the
    slowest joint counting: per joint 2√(d/a) when d ≤ v²/a (triangle), else d/v + v/a (trapezoid)."""
    d = np.abs(np.asarray(dq, float))
    v, a = np.asarray(v_max, float), np.asarray(a_max, float)
    t = np.where(d <= v * v / a, 2 * np.sqrt(d / a), d / v + v / a)
    return t.max(axis=-1)


@dataclass
class CycleResult:
    """The cycle of one design.  ``ok``: every stop was reached (else the times are inf, the torques NaN
    and ``unreached`` lists the target indices).  ``q`` (m, n) the stop configurations, ``approach``
    (m, n) those above them (None without lift); ``segment_times`` (m,) s; ``cycle_time`` s (with the
    dwells); ``peak_torque`` (n,) the largest |τ_j| over the cycle (N·m, N); ``tau_max`` (n,) (NaN
    unknown); ``trajectories`` one per segment; ``torque_mode`` the spec's; ``moving_mass`` kg."""

    ok: bool
    cycle_time: float
    segment_times: np.ndarray
    peak_torque: np.ndarray
    tau_max: np.ndarray
    q: np.ndarray
    approach: np.ndarray | None
    torque_mode: str
    joint_names: tuple[str, ...]
    revolute: np.ndarray
    moving_mass: float = float("nan")
    unreached: tuple[int, ...] = ()
    trajectories: list = field(default_factory=list)

    @property
    def torque_ratios(self) -> np.ndarray:
        """peak |τ_j| / tau_max_j (n,), NaN where the limit is unknown."""
        return self.peak_torque / self.tau_max

    @property
    def torque_ratio(self) -> float:
        """The largest ratio over the joints with a known limit (NaN when none is known or not ok)."""
        r = self.torque_ratios
        return float(np.nanmax(r)) if self.ok and np.isfinite(r).any() else float("nan")

    @property
    def within_torque(self) -> bool:
        """Every known limit met (True when none is known)."""
        r = self.torque_ratio
        return self.ok and not (r > 1 + TORQUE_TOL)

    @property
    def peak(self) -> float:
        """The largest peak |τ| over the revolute joints (N·m; over all joints, N, for a chain without one)."""
        if not self.ok:
            return float("nan")
        sel = self.revolute if self.revolute.any() else np.ones_like(self.revolute)
        return float(self.peak_torque[sel].max())

    def metrics(self) -> dict:
        """Sweep columns (SI): cycle_time, peak_torque, torque_ratio and per joint peak_torque_NAME."""
        out = {"cycle_time": self.cycle_time if self.ok else float("inf"), "peak_torque": self.peak,
               "torque_ratio": self.torque_ratio}
        out.update({f"peak_torque_{nm}": float(t) for nm, t in zip(self.joint_names, self.peak_torque)})
        return out

    def to_dict(self) -> dict:
        return {"ok": self.ok, "cycle_time_s": self.cycle_time, "segment_times_s": self.segment_times,
                "peak_torque": dict(zip(self.joint_names, self.peak_torque.tolist())),
                "tau_max": dict(zip(self.joint_names, self.tau_max.tolist())),
                "torque_ratio": self.torque_ratio, "within_torque_limits": self.within_torque,
                "torque_mode": self.torque_mode, "moving_mass_kg": self.moving_mass,
                "unreached_targets": list(self.unreached)}


def _goals(targets: Targets, idx, offset: float) -> tuple[np.ndarray, str]:
    if targets.orientation not in ("free", "pose"):
        raise TaskError(f"a cycle needs position ('free') or 'pose' targets, not {targets.orientation!r}")
    G = np.tile(np.eye(4), (len(idx), 1, 1))
    G[:, :3, 3] = targets.positions[idx] + np.array([0.0, 0.0, offset])
    if targets.orientation == "pose":
        G[:, :3, :3] = targets.rotations[idx]
        return G, "pose"
    return G, "position"


def stop_configurations(robot: kin.Robot, spec: CycleSpec, targets: Targets, params=None, seed: int = 0):
    """Candidate branches per stop: a list (one per stop of the sequence) of (k, n) configurations
    (and of their approach configurations above the stop, or None without lift); an empty array
    where nothing reached the stop."""
    spec.check_targets(len(targets))
    uniq = sorted(set(spec.sequence))
    K = spec.ik_starts
    p = None if not robot.chain.parameters else robot.chain.parameter_vector(params)
    G, mode = _goals(targets, np.repeat(uniq, K), 0.0)
    Q0 = np.tile(robot.random_configurations(K, seed=seed), (len(uniq), 1))
    res = robot.ik(G, seed=seed, q0=Q0, mode=mode, restarts=1, rounds=1, tol_position=targets.tolerance, params=p)
    Q, ok = np.asarray(res.q).reshape(len(uniq), K, robot.n), np.asarray(res.success, bool).reshape(len(uniq), K)
    cands: dict[int, np.ndarray] = {}
    for u, i in enumerate(uniq):
        kept: list[np.ndarray] = []
        for q in Q[u][ok[u]]:
            if all(np.linalg.norm(q - k) > _SAME for k in kept):
                kept.append(q)
        cands[i] = np.array(kept).reshape(-1, robot.n)
    ups: dict[int, np.ndarray] | None = None
    if spec.lift > 0:
        ups = {}
        for i in uniq:
            C = cands[i]
            if not len(C):
                ups[i] = C
                continue
            Gu, _ = _goals(targets, np.full(len(C), i), spec.lift)
            r = robot.ik(Gu, seed=seed, q0=C, mode=mode, restarts=1, rounds=1, tol_position=targets.tolerance,
                         params=p)
            good = np.asarray(r.success, bool)
            cands[i], ups[i] = C[good], np.asarray(r.q).reshape(len(C), robot.n)[good]
    stops = [cands[i] for i in spec.sequence]
    return stops, None if ups is None else [ups[i] for i in spec.sequence]


def _legs(a, ua, ub, b):
    return [a, b] if ua is None else [a, ua, ub, b]


def choose_branches(stops, ups, v_max, a_max) -> np.ndarray:
    """One candidate index per stop (m,) minimising the closed cycle's summed segment estimates
    (:func:`rest_to_rest_time` per leg) by dynamic programming from every start candidate."""
    m = len(stops)

    def cost(i, j):                                    # (k_i, k_j) estimated time of segment i → j
        A, B = stops[i], stops[j]
        if ups is None:
            return rest_to_rest_time(A[:, None] - B[None], v_max, a_max)
        UA, UB = ups[i], ups[j]
        return (rest_to_rest_time(A - UA, v_max, a_max)[:, None] + rest_to_rest_time(UA[:, None] - UB[None],
                v_max, a_max) + rest_to_rest_time(UB - B, v_max, a_max)[None])
    costs = [cost(i, (i + 1) % m) for i in range(m)]
    best, pick = np.inf, None
    for s in range(len(stops[0])):
        acc = costs[0][s].copy()                       # to every candidate of stop 1
        back = []
        for i in range(1, m - 1):
            tot = acc[:, None] + costs[i]
            back.append(tot.argmin(axis=0))
            acc = tot.min(axis=0)
        close = acc + costs[m - 1][:, s]
        j = int(close.argmin())
        if close[j] < best - 1e-12:
            path = [j]
            for b in reversed(back):
                path.append(int(b[path[-1]]))
            best, pick = close[j], [s] + path[::-1]
    return np.array(pick[:m], int)


def cycle_paths(q: np.ndarray, approach: np.ndarray | None) -> list[np.ndarray]:
    """The joint path (waypoints) of every segment: stop i → (above i → above i+1 →) stop i+1, the
    last back to the first."""
    m = len(q)
    return [np.array(_legs(q[i], None if approach is None else approach[i],
                           None if approach is None else approach[(i + 1) % m], q[(i + 1) % m])) for i in range(m)]


def _timed(path, spec: CycleSpec, dyn_robot):
    if spec.torque == "limit":
        return time_parameterize(path, spec.v_max, spec.a_max, blend=spec.blend, robot=dyn_robot,
                                 tau_max=spec.tau_max)
    return time_parameterize(path, spec.v_max, spec.a_max, blend=spec.blend)


def peak_torques(dyn_robot: kin.Robot, traj, per_interval: int = PER_INTERVAL) -> np.ndarray:
    """The largest |τ_j| (n,) along a timed trajectory, on ``per_interval`` + 1 times per interval."""
    q, qd, qdd = traj.sample(dense_times(traj.t, per_interval))
    return np.abs(dyn_robot.inverse_dynamics(q, qd, qdd)).max(axis=0)


def evaluate_cycle(robot: kin.Robot, spec: CycleSpec, targets: Targets, params=None, seed: int = 0) -> CycleResult:
    """The cycle of ``robot`` at design ``params`` (SI; None: nominal): see the module text."""
    chain = robot.chain
    if spec.n != robot.n:
        raise TaskError(f"the cycle's limits and masses are for {spec.n} joints; {robot.name} has {robot.n}")
    names = tuple(j.name or f"J{k + 1}" for k, j in enumerate(chain.joints))
    stops, ups = stop_configurations(robot, spec, targets, params, seed)
    m = len(stops)
    missing = tuple(sorted({spec.sequence[i] for i in range(m) if not len(stops[i])}))
    rev = chain.revolute_mask.copy()
    if missing:
        return CycleResult(False, float("inf"), np.full(m, np.inf), np.full(robot.n, np.nan), spec.tau_max,
                           np.full((m, robot.n), np.nan), None, spec.torque, names, rev, unreached=missing)
    pick = choose_branches(stops, ups, spec.v_max, spec.a_max)
    q = np.array([stops[i][k] for i, k in enumerate(pick)])
    up = None if ups is None else np.array([ups[i][k] for i, k in enumerate(pick)])
    dyn_chain = (chain_with_masses(chain, params, spec.masses) if spec.masses is not None
                 else chain_own_masses(chain, params))
    # every design has its own masses (numbers in the Newton–Euler graph, not parameters), so a compiled
    # kernel would be built — and cached on disk — per design for a few thousand evaluations: the VM
    dyn = kin.Robot(dyn_chain, backend="vm")
    trajs = [_timed(path, spec, dyn) for path in cycle_paths(q, up)]
    peaks = np.max([peak_torques(dyn, tr) for tr in trajs], axis=0)
    seg = np.array([tr.duration for tr in trajs])
    mass = float(sum(j.inertia.mass for j in dyn_chain.joints if j.inertia is not None)
                 + (dyn_chain.payload.mass if dyn_chain.payload is not None else 0.0))
    return CycleResult(True, float(seg.sum() + m * spec.dwell), seg, peaks, spec.tau_max, q, up, spec.torque,
                       names, rev, mass, (), trajs)
