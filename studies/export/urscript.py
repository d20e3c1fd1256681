"""A trajectory as a URScript program for a Universal Robots e-series arm (six revolute joints,
positions in rad; the arm's joint zero is the robot file's when its DH offsets are UR's own).

Two ways:

* :func:`servoj_program` — a ``servoj`` stream: one ``servoj(q, 0, 0, t, lookahead, gain)`` line per
  control cycle (the e-series controller runs at 500 Hz, t = 0.002 s), q the trajectory resampled at
  that rate (:func:`studies.export.interpolate.evaluate`).  The arm follows the whole timed trajectory
  (the path a planner checked, at the planned speed), within the servo's tracking lag.
* :func:`movej_program` — ``movej(q, t=…, r=0)`` through the trajectory's stops (the samples where it
  is at rest): each move a straight line in joint space taking exactly the planned time between the
  two stops, the controller's own speed profile in between.  It is the planned path only when the
  trajectory goes straight from stop to stop (a path timed with ``rmt time --blend 0``: it stops at
  every waypoint); a trajectory that curves between its stops is refused (:class:`MovejError`).

Both programs first check that the arm stands at the trajectory's start (every joint within
:data:`START_TOLERANCE` rad) and halt with a popup if not: they never move the arm to the start
themselves, since that motion would be one nobody planned.
"""
from __future__ import annotations

import numpy as np

__all__ = ["servoj_program", "movej_program", "MovejError", "START_TOLERANCE", "SERVO_RATE"]

#: how far (rad) each joint may stand from the trajectory's start when the program begins
START_TOLERANCE = 0.01
#: the e-series controller's rate, Hz
SERVO_RATE = 500.0
#: a joint at rest: |q̇| at most this (rad/s)
REST_SPEED = 1e-12
#: largest distance (rad) of a sample from the straight line between the stops around it, for movej
STRAIGHT_TOLERANCE = 1e-6


class MovejError(ValueError):
    """A trajectory that movej through its stops would not reproduce."""


def _num(x: float) -> str:
    """A URScript number: fixed point, 12 decimals (1e-12 rad), no exponent."""
    s = f"{x:.12f}"
    return "0.000000000000" if s == "-0.000000000000" else s


def _vec(q) -> str:
    return "[" + ", ".join(_num(float(x)) for x in q) + "]"


def _prologue(start, header: list[str]) -> list[str]:
    lines = [f"# {h}" for h in header]
    lines += ["def rmt_trajectory():",
              f"  start = {_vec(start)}",
              "  actual = get_actual_joint_positions()",
              "  i = 0",
              f"  while i < {len(start)}:",
              f"    if norm(actual[i] - start[i]) > {START_TOLERANCE:g}:",
              f'      popup("The arm is not at the trajectory start (each joint within {START_TOLERANCE:g} rad). '
              'Move it there first.", "rmt_trajectory", error=True, blocking=True)',
              "      halt",
              "    end",
              "    i = i + 1",
              "  end"]
    return lines


def servoj_program(Q: np.ndarray, rate: float, lookahead: float, gain: float, header: list[str]) -> str:
    """The servoj program of the stream ``Q`` (T, 6) rad sampled at ``rate`` Hz from t = 0 (Q[0] the
    start: the first servoj is Q[1]); ``header`` lines become ``#`` comments."""
    dt = 1.0 / rate
    lines = _prologue(Q[0], header)
    lines += [f"  servoj({_vec(q)}, 0, 0, {_num(dt)}, {lookahead:g}, {gain:g})" for q in Q[1:]]
    lines += ["  stopj(2.0)", "end", "rmt_trajectory()"]
    return "\n".join(lines) + "\n"


def stops(traj) -> np.ndarray:
    """Indices of the samples where every joint is at rest (|q̇| ≤ 1e-12 rad/s)."""
    return np.flatnonzero(np.all(np.abs(traj.qd) <= REST_SPEED, axis=1))


def movej_waypoints(traj) -> np.ndarray:
    """The stops movej goes through (their indices), after checking that the trajectory starts and ends at
    rest and goes straight, forwards, from each stop to the next."""
    k = stops(traj)
    if len(k) == 0 or k[0] != 0 or k[-1] != len(traj.t) - 1:
        raise MovejError("the trajectory does not start and end at rest (q̇ = 0); movej goes from stop to stop")
    for a, b in zip(k[:-1], k[1:]):
        d = traj.q[b] - traj.q[a]
        L = float(np.linalg.norm(d))
        seg = traj.q[a:b + 1] - traj.q[a]
        if L == 0.0:
            off = np.linalg.norm(seg, axis=1)
            s = np.zeros(len(seg))
        else:
            s = seg @ d / L
            off = np.linalg.norm(seg - np.outer(s / L, d), axis=1)
        if off.max() > STRAIGHT_TOLERANCE or np.any(np.diff(s) < -STRAIGHT_TOLERANCE):
            i = a + int(np.argmax(off))
            raise MovejError(f"between its stops at t = {traj.t[a]:.6g} s and t = {traj.t[b]:.6g} s the trajectory "
                             f"leaves the straight joint-space line by {off.max():.3g} rad (at t = {traj.t[i]:.6g} s), "
                             f"which movej would take: time the path with rmt time --blend 0 (it stops at every "
                             f"waypoint), or export --urscript-mode servoj")
    return k


def movej_program(traj, header: list[str]) -> str:
    """movej through the stops of ``traj`` (a :class:`~studies.export.trajectory.Trajectory` of six
    revolute joints, SI), each ``t=`` the planned time between two stops; a hold at one place is a
    ``sleep``.  Raises :class:`MovejError` (see :func:`movej_waypoints`)."""
    k = movej_waypoints(traj)
    lines = _prologue(traj.q[0], header)
    for a, b in zip(k[:-1], k[1:]):
        dt = float(traj.t[b] - traj.t[a])
        if np.array_equal(traj.q[a], traj.q[b]):
            lines.append(f"  sleep({_num(dt)})")
        else:
            lines.append(f"  movej({_vec(traj.q[b])}, a=1.4, v=1.05, t={_num(dt)}, r=0)")
    lines += ["end", "rmt_trajectory()"]
    return "\n".join(lines) + "\n"
