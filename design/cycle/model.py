"""A task's motion cycle: which targets it visits in which order, the joints' speed, acceleration and
torque limits, the mass model, and how the joint path between the stops is shaped
(:class:`CycleSpec`).  Everything SI; built from a task file's ``[cycle]`` table by
:func:`design.cycle.file.read_cycle`, or directly from Python."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from design.cycle.masses import LinkMasses
from design.task.model import TaskError

__all__ = ["CycleSpec", "TORQUE_MODES", "MAX_STOPS"]

#: "check": the cycle is timed under the speed and acceleration limits and its peak torques are
#: checked against tau_max (a constraint of the design); "limit": it is timed under the torque limits
#: too (planning.timing's tau_max), so it is slower where the motors are too weak
TORQUE_MODES = ("check", "limit")
#: the most stops a cycle may have
MAX_STOPS = 1000


def _positive(v, n: int, name: str, allow_nan: bool = False) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    vals = np.full(n, float(arr)) if arr.ndim == 0 else arr
    ok = vals.shape == (n,) and np.all(np.isnan(vals) | (np.isfinite(vals) & (vals > 0)) if allow_nan
                                       else np.isfinite(vals) & (vals > 0))
    if not ok:
        raise TaskError(f"{name} {v!r} must be {n} positive finite numbers (one per joint)"
                        + (" or NaN for unknown" if allow_nan else ""))
    return vals.astype(float)


@dataclass(frozen=True)
class CycleSpec:
    """The motion cycle of a task (SI).

    ``sequence``: indices (0-based) of the task's targets, visited in this order and back to the
    first (pick → place → pick is ``(0, 1)``); the tool stops at each (rest to rest) and waits
    ``dwell`` s there.  ``lift`` (m): each stop is approached from and left to a point ``lift`` above
    it (along the base z axis), so a segment is stop → above it → above the next → next stop, its
    corners blended (``blend``: the joint-space blend half-length of :func:`planning.timing.blend_path`,
    rad or m).  ``v_max``, ``a_max`` (n,): per-joint speed and acceleration limits (rad/s, rad/s²; m/s,
    m/s²); ``tau_max`` (n,): motor torque limits (N·m; N), NaN where unknown; ``torque``: one of
    :data:`TORQUE_MODES`; ``masses``: the link mass model (None: the robot's own inertial data, as an
    assembly of catalogue modules carries it — :func:`design.cycle.masses.chain_own_masses`);
    ``ik_starts``: IK starts per stop (the branches found among them are all candidates,
    :mod:`design.cycle.evaluate`).
    """

    sequence: tuple[int, ...]
    v_max: np.ndarray
    a_max: np.ndarray
    tau_max: np.ndarray
    masses: LinkMasses | None
    torque: str = "check"
    lift: float = 0.0
    dwell: float = 0.0
    blend: float = 0.05
    ik_starts: int = 8

    def __post_init__(self):
        n = self.masses.n if self.masses is not None else int(np.size(self.v_max))
        seq = tuple(self.sequence)
        if not (2 <= len(seq) <= MAX_STOPS) or not all(isinstance(i, (int, np.integer)) and not isinstance(i, bool)
                                                        and i >= 0 for i in seq):
            raise TaskError(f"cycle sequence {self.sequence!r} must list 2 to {MAX_STOPS} target indices (0-based)")
        object.__setattr__(self, "sequence", tuple(int(i) for i in seq))
        object.__setattr__(self, "v_max", _positive(self.v_max, n, "cycle v_max"))
        object.__setattr__(self, "a_max", _positive(self.a_max, n, "cycle a_max"))
        object.__setattr__(self, "tau_max", _positive(self.tau_max, n, "cycle tau_max", allow_nan=True))
        if self.torque not in TORQUE_MODES:
            raise TaskError(f"cycle torque {self.torque!r} unknown; allowed: {', '.join(TORQUE_MODES)}")
        if self.torque == "limit" and np.isnan(self.tau_max).any():
            raise TaskError("cycle torque = \"limit\" needs a tau_max for every joint")
        for name, v, hi in (("lift", self.lift, 1e3), ("dwell", self.dwell, 3600.0), ("blend", self.blend, 1e3)):
            if isinstance(v, bool) or not (isinstance(v, (int, float, np.number)) and math.isfinite(v)
                                           and 0 <= v <= hi):
                raise TaskError(f"cycle {name} {v!r} must be a finite number in [0, {hi:g}]")
        if isinstance(self.ik_starts, bool) or not isinstance(self.ik_starts, (int, np.integer)) \
                or not 1 <= self.ik_starts <= 64:
            raise TaskError(f"cycle ik_starts {self.ik_starts!r} must be an integer in [1, 64]")

    @property
    def n(self) -> int:
        return self.masses.n if self.masses is not None else int(np.size(self.v_max))

    def check_targets(self, count: int) -> None:
        """Every index of the sequence names one of ``count`` targets."""
        bad = [i for i in self.sequence if i >= count]
        if bad:
            raise TaskError(f"cycle sequence index {bad[0]} is beyond the task's {count} targets (0-based)")
