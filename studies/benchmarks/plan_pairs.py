"""Start/goal pairs for the planning benchmark, classified independently of the planner.

:class:`Connectivity` labels the free set of every joint group (joints that share a window) on a grid
finer than the narrowest window (face connectivity, so no window can be jumped diagonally);
:func:`draw_pairs` draws valid pairs of a wanted class: ``"blocked"`` (same component, straight line
crossing a window) or ``"separated"`` (different components: no joint path exists); :func:`naive_plan`
plans the way a naive OMPL set-up would (state validity pointwise, OMPL's default resolution-based
motion checking), for comparison.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from planning.certify.cells import joint_groups as certify_joint_groups
from planning.ompl.bindings import og, quiet_rng_seed
from planning.ompl.planner import joint_space, start_goal
from planning.validate import check_path, densify
from planning.windows import WindowSet

GRID_FRACTION = 0.25     # grid step ≤ this fraction of the narrowest full window width (2 × margin)
MAX_DRAWS = 600_000      # start/goal pairs drawn per robot before giving up


# ---- connectivity, independent of the planner ------------------------------------------------
def joint_groups(ws: WindowSet) -> list[list[int]]:
    """0-based joints the windows depend on, grouped: joints sharing a window are in one group."""
    return certify_joint_groups(ws.windows)


@dataclass
class GroupGrid:
    """Connected components of the free set of one joint group, on a regular grid."""

    joints: list[int]           # 0-based
    axes: list[np.ndarray]      # grid values per joint (SI), from the lower to the upper limit
    labels: np.ndarray          # int32 grid, 0 inside a window, 1..count per component
    count: int
    step: float                 # largest grid step (SI)
    free_fraction: float
    seconds: float

    def label_of(self, Q: np.ndarray) -> np.ndarray:
        """Component label (N,) of the grid point nearest to each configuration (0: in a window)."""
        idx = []
        for j, ax in zip(self.joints, self.axes):
            h = (ax[-1] - ax[0]) / (len(ax) - 1)
            idx.append(np.clip(np.rint((Q[:, j] - ax[0]) / h).astype(int), 0, len(ax) - 1))
        return self.labels[tuple(idx)]


def label_group(robot, ws: WindowSet, joints: list[int], step: float) -> GroupGrid:
    """Label the free set of ``joints`` (their windows only) on a grid of step ≤ ``step``."""
    from scipy import ndimage

    t0 = time.perf_counter()
    lo, hi = robot.chain.lower, robot.chain.upper
    mine = [w for w in ws.windows if {j - 1 for j in w.joints} <= set(joints)]
    axes = [np.linspace(lo[j], hi[j], int(math.ceil((hi[j] - lo[j]) / step)) + 1) for j in joints]
    shape = tuple(len(a) for a in axes)
    free = np.empty(shape, bool)
    # one slice of the first joint at a time; the other joints stay at 0 (the group's windows do
    # not depend on them)
    rest = np.meshgrid(*axes[1:], indexing="ij") if len(joints) > 1 else []
    Q = np.zeros((int(np.prod(shape[1:])), robot.n), order="F")   # column access is what the windows do
    for k, j in enumerate(joints[1:], 1):
        Q[:, j] = rest[k - 1].ravel()
    for i, x in enumerate(axes[0]):
        Q[:, joints[0]] = x
        inside = np.zeros(len(Q), bool)
        for w in mine:
            inside |= w.contains(Q)
        free[i] = ~inside.reshape(shape[1:])
    free = free.reshape(shape)
    structure = ndimage.generate_binary_structure(len(joints), 1)   # faces only: no diagonal leaks
    labels, count = ndimage.label(free, structure=structure)
    return GroupGrid(joints, axes, labels, int(count), float(max((a[-1] - a[0]) / (len(a) - 1) for a in axes)),
                     float(free.mean()), time.perf_counter() - t0)


class Connectivity:
    """Whether two valid configurations lie in one connected component of the free joint space."""

    def __init__(self, robot, ws: WindowSet, fraction: float = GRID_FRACTION):
        widths = [2 * w.width for w in ws.windows if w.width > 0]
        self.step = fraction * min(widths) if widths else math.inf
        self.groups = [label_group(robot, ws, g, self.step) for g in joint_groups(ws)]

    def labels(self, Q: np.ndarray) -> np.ndarray:
        """(N, groups) component labels; a 0 means the nearest grid point is inside a window."""
        Q = np.atleast_2d(Q)
        if not self.groups:
            return np.ones((len(Q), 0), int)
        return np.stack([g.label_of(Q) for g in self.groups], axis=1)


# ---- pairs ---------------------------------------------------------------------------------
def crosses_window(robot, ws: WindowSet, a: np.ndarray, b: np.ndarray) -> bool:
    """Whether the straight joint-space line a→b enters a window (states 0.1° apart, windows only)."""
    Q, _, _ = densify(np.array([a, b]), robot.chain.revolute_mask)
    return bool(ws.contains(Q).any())


def draw_pairs(robot, ws: WindowSet, conn: Connectivity, count: int, seed: int, batch: int = 20_000,
               max_draws: int = MAX_DRAWS, kind: str = "blocked") -> tuple[np.ndarray, dict]:
    """``count`` blocked, connectable start/goal pairs (count, 2, n) and the tallies of the draw —
    or, with ``kind="separated"``, valid pairs in different components (no joint path exists).

    Configurations are drawn uniformly in the limits and paired in draw order.  A valid pair is
    rejected when its two ends lie in different components (unconnectable) or when its straight
    line stays outside every window (not a blocked case); the rest are kept, after a final dense
    :func:`check_path` of the straight line confirms it fails with kind ``window``.  Gives up after
    ``max_draws`` pairs (fewer pairs are returned: some machines have almost none, see the PUMA note
    in :func:`bench_robot`).
    """
    rng = np.random.default_rng(seed)
    lo, hi = robot.chain.lower, robot.chain.upper
    tally = {"drawn_pairs": 0, "invalid_pairs": 0, "grid_ambiguous_pairs": 0, "valid_pairs": 0,
             "unconnectable": 0, "connectable_straight_line_valid": 0, "kept": 0}
    pairs: list[np.ndarray] = []
    while len(pairs) < count:
        if tally["drawn_pairs"] >= max_draws:
            break
        A = rng.uniform(lo, hi, size=(batch, robot.n))
        B = rng.uniform(lo, hi, size=(batch, robot.n))
        valid = ~ws.contains(A) & ~ws.contains(B)
        LA, LB = conn.labels(A), conn.labels(B)
        resolved = (LA > 0).all(axis=1) & (LB > 0).all(axis=1)   # not within a grid step of a window
        same = (LA == LB).all(axis=1)
        for k in range(min(batch, max_draws - tally["drawn_pairs"])):
            tally["drawn_pairs"] += 1
            if not valid[k]:
                tally["invalid_pairs"] += 1
                continue
            if not resolved[k]:
                tally["grid_ambiguous_pairs"] += 1
                continue
            tally["valid_pairs"] += 1
            if not same[k]:
                tally["unconnectable"] += 1
                if kind == "separated":
                    tally["kept"] += 1
                    pairs.append(np.array([A[k], B[k]]))
                    if len(pairs) == count:
                        break
                continue
            if kind == "separated":
                continue
            if not crosses_window(robot, ws, A[k], B[k]):
                tally["connectable_straight_line_valid"] += 1
                continue
            chk = check_path(robot, np.array([A[k], B[k]]), ws)
            if chk.valid or chk.first_violation.kind != "window":   # cannot happen: a second opinion
                raise RuntimeError(f"{robot.name}: straight-line checks disagree for pair {tally['drawn_pairs']}")
            tally["kept"] += 1
            pairs.append(np.array([A[k], B[k]]))
            if len(pairs) == count:
                break
    return np.array(pairs).reshape(-1, 2, robot.n), tally


def naive_plan(robot, ws: WindowSet, a: np.ndarray, b: np.ndarray, time_limit: float, seed: int):
    """RRTConnect as a naive OMPL set-up would run it: the state validity checker tests the limits
    and the windows at single states, motions are checked by OMPL's default resolution-based
    validator (1 % of the space's extent).  Returns the path (M, n) or None."""
    n = robot.n
    quiet_rng_seed(seed)
    space, si = joint_space(robot)
    si.setStateValidityChecker(lambda s: not ws.contains(np.array([s[i] for i in range(n)])))
    si.setup()
    pdef, states = start_goal(space, si, a, b)
    pl = og.RRTConnect(si)
    pl.setProblemDefinition(pdef)
    pl.setup()
    status = pl.solve(float(time_limit))
    if not bool(status) or not pdef.hasExactSolution():
        return None
    path = pdef.getSolutionPath()
    return np.array([[path.getState(k)[i] for i in range(n)] for k in range(path.getStateCount())])
