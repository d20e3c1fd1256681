"""A cycle: several joint paths timed one after another, each rest to rest, with holds (dwells) between
them, as one trajectory (:func:`time_sequence`).  SI units: rad or m, s.

Each move is timed alone by :func:`planning.timing.time_parameterize` (same limits and options for
all), so the cycle's duration is exactly the sum of the moves' durations and the dwells.  A move must
start where the previous one ends (within ``tolerance``): the cycle inserts no motion of its own.  The
samples of the moves follow each other shifted in time; a dwell is a hold: the last sample of a move
(at rest) and the first of the next (at rest, same configuration) ``dwell`` seconds later, or, after
the last move, one more sample of the final configuration at rest.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planning.timing.trajectory import TimedTrajectory, TimingError

__all__ = ["SequenceTrajectory", "time_sequence", "MAX_DWELL", "MAX_MOVES", "JOIN_TOLERANCE"]

#: the longest dwell, s (one day)
MAX_DWELL = 86400.0
#: the most moves of one cycle
MAX_MOVES = 1000
#: largest joint difference (rad or m) between a move's first configuration and the previous move's last
JOIN_TOLERANCE = 1e-9


@dataclass
class SequenceTrajectory:
    """The timed cycle (SI): samples ``t`` (K,), ``q``, ``qd``, ``qdd`` (K, n), ``tau`` (K, n) or None;
    ``moves``: each move's own :class:`TimedTrajectory`; ``start`` (m,): when each move starts;
    ``dwell`` (m,): the hold after each; ``duration``: the whole cycle, s."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray | None
    moves: list[TimedTrajectory]
    start: np.ndarray
    dwell: np.ndarray
    duration: float


def join_gap(previous_end: np.ndarray, start: np.ndarray) -> tuple[float, int]:
    """The largest joint difference between two configurations and the joint (0-based) it is at."""
    d = np.abs(np.asarray(start, float) - np.asarray(previous_end, float))
    j = int(np.argmax(d))
    return float(d[j]), j


def time_sequence(paths, dwells, tolerance: float = JOIN_TOLERANCE, **timing) -> SequenceTrajectory:
    """Time the joint paths ``paths`` (each (M_k, n), SI) one after another, holding ``dwells[k]`` s
    after move k; ``timing``: the keyword arguments of :func:`planning.timing.time_parameterize` (with
    ``v_max`` and ``a_max``), the same for every move.  :class:`TimingError` for a bad dwell, a move
    that does not start where the previous one ends or that does not move."""
    from planning.timing.parameterize import time_parameterize

    paths = [np.asarray(p, dtype=float) for p in paths]
    dwell = np.asarray(dwells, dtype=float).ravel()
    if not 1 <= len(paths) <= MAX_MOVES:
        raise TimingError(f"a cycle needs 1 to {MAX_MOVES} moves, got {len(paths)}")
    if dwell.shape != (len(paths),):
        raise TimingError(f"{dwell.size} dwells for {len(paths)} moves; give one per move (0: none)")
    for k, d in enumerate(dwell):
        if not (math.isfinite(d) and 0 <= d <= MAX_DWELL):
            raise TimingError(f"move {k + 1}: dwell {d:g} s must be in [0, {MAX_DWELL:g}] s (one day)")
    n = paths[0].shape[1] if paths[0].ndim == 2 else 0
    for k, P in enumerate(paths):
        if P.ndim != 2 or P.shape[1] != n or len(P) < 2 or not np.all(np.isfinite(P)):
            raise TimingError(f"move {k + 1}: needs at least 2 configurations of {n} finite values, got shape "
                              f"{P.shape}")
        if np.all(P == P[0]):
            raise TimingError(f"move {k + 1} does not move (every configuration is the same); a hold is the "
                              "previous move's dwell")
        if k:
            gap, j = join_gap(paths[k - 1][-1], P[0])
            if gap > tolerance:
                raise TimingError(f"move {k + 1} starts {gap:.3g} (rad or m, joint {j + 1}) away from where move {k} "
                                  f"ends; a cycle inserts no motion: start each move at the previous one's end")
    moves = [time_parameterize(P, **timing) for P in paths]
    t, q, qd, qdd, tau = [], [], [], [], []
    start = np.zeros(len(moves))
    clock = 0.0
    for k, tr in enumerate(moves):
        start[k] = clock
        skip = 1 if k and dwell[k - 1] == 0 else 0        # the previous move's last sample is this one's first
        t.append(tr.t[skip:] + clock)
        q.append(tr.q[skip:])
        qd.append(tr.qd[skip:])
        qdd.append(tr.qdd[skip:])
        if tr.tau is not None:
            tau.append(tr.tau[skip:])
        clock += tr.duration + dwell[k]
    if dwell[-1] > 0:                                    # the final hold
        last = moves[-1]
        t.append(np.array([clock]))
        q.append(last.q[-1:])
        qd.append(np.zeros((1, n)))
        qdd.append(np.zeros((1, n)))
        if last.tau is not None:                         # at rest: gravity (and friction at rest) alone
            robot = timing["robot"]
            tau.append(np.atleast_2d(robot.inverse_dynamics(last.q[-1:], np.zeros((1, n)), np.zeros((1, n)))))
    T = np.concatenate(t)
    return SequenceTrajectory(T, np.vstack(q), np.vstack(qd), np.vstack(qdd),
                              np.vstack(tau) if len(tau) == len(t) else None, moves, start, dwell, clock)
