"""Helpers of the 7-DOF window tests (not a test module): the Panda's and the iiwa's point-set
windows of margin 0.05 rad, and membership decided by brute force in numpy.

The windows are built once per session and kept in the windows cache (:mod:`planning.windows.cache`)
under a request of their own: ``rmt`` commands take ``--margin`` in the robot file's units (degrees
for the iiwa), so the tests' SI request must not share their key.
"""
from __future__ import annotations

import functools

import numpy as np

import kin
from planning.windows import build_windows
from planning.windows.cache import cached

MARGIN = 0.05          # rad
ROBOTS = ("franka_panda", "kuka_iiwa14")


@functools.cache
def margin_windows(name: str):
    """(robot, its windows of margin :data:`MARGIN` rad) for a bundled 7-DOF arm."""
    robot = kin.load_robot(name)
    return robot, cached(robot, {"margin": MARGIN, "units": "SI, tests"}, lambda: build_windows(robot, margin=MARGIN))


def inside_numpy(window, Q: np.ndarray, chunk: int = 1000) -> np.ndarray:
    """(N,) True where a configuration of Q (N, n) lies within the width of one of a plain point-set
    window's points over its joints — every distance computed, no KD-tree."""
    X = np.asarray(Q, dtype=float)[:, [j - 1 for j in window.joints]]
    out = np.zeros(len(X), bool)
    for s in range(0, len(X), chunk):
        d2 = ((X[s:s + chunk, None, :] - window.points[None]) ** 2).sum(axis=2)
        out[s:s + chunk] = (np.sqrt(d2.min(axis=1)) <= window.width)
    return out


def through_window(robot, window, rng, half: float = 0.4, windows=None) -> tuple[np.ndarray, np.ndarray]:
    """A start and goal inside the limits and outside every window of ``windows`` whose straight
    line passes through one of ``window``'s points (at its middle), ``half`` (rad) either side."""
    lo, hi = robot.chain.lower, robot.chain.upper
    while True:
        q = rng.uniform(lo, hi)
        q[[j - 1 for j in window.joints]] = window.points[rng.integers(len(window.points))]
        d = rng.normal(size=robot.n)
        d *= half / np.linalg.norm(d)
        s, g = q - d, q + d
        if np.all((s >= lo) & (s <= hi) & (g >= lo) & (g <= hi)) and not (
                windows is not None and windows.contains(np.array([s, g])).any()):
            return s, g
