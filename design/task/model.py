"""The values of a design task: targets with their orientation requirement, the dexterity
requirement, the objective and the constraints.  Everything SI (m, rad); shapes stated per field.
A task is built by :func:`design.task.load_task` from a TOML file, or directly from Python."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from kin.errors import RmtError

#: orientation requirements: none, full pose, tool axis with free rotation about it, axis within a cone
ORIENTATIONS = ("free", "pose", "axis", "cone")
#: dexterity measures: σ_min of the translational rows, of the full Jacobian made dimensionless by a
#: characteristic length, or the manipulability of the robot's task rows
DEXTERITY_KINDS = ("none", "sigma_min", "sigma_min_full", "manipulability")
#: objectives: structural length Σ(|a|+|d|), structural length index Q_L = Σ(|a|+|d|)/∛V, coverage,
#: global conditioning index (mean 1/κ over the covered targets), the cycle time of the task's motion
#: cycle (s) and its largest peak motor torque over the motor's limit (needs the task's ``cycle``)
OBJECTIVES = ("length", "length_index", "coverage", "gci", "cycle_time", "torque_ratio")
#: the objectives that need the task's motion cycle (:mod:`design.cycle`)
CYCLE_OBJECTIVES = ("cycle_time", "torque_ratio")


class TaskError(RmtError, ValueError):
    """A task file or task value is invalid; the message names the file and the field."""

    def __init__(self, message: str, path: str | None = None, field: str | None = None):
        self.path, self.field = path, field
        where = ": ".join(x for x in (path, field) if x)
        super().__init__(f"{where}: {message}" if where else message)


@dataclass(frozen=True)
class Targets:
    """Target points and their orientation requirement.

    positions (N, 3) m, base frame.  axes (N, 3) unit tool-axis (tool z) directions, or None when
    ``orientation`` is "free".  rotations (N, 3, 3) full tool orientations for "pose", else None.
    ``cone_half_angle`` (rad) for "cone".  ``tolerance`` the position tolerance (m).
    """

    positions: np.ndarray
    orientation: str = "free"
    axes: np.ndarray | None = None
    rotations: np.ndarray | None = None
    cone_half_angle: float = 0.0
    tolerance: float = 1e-6
    kind: str = "points"

    def __post_init__(self):
        P = np.asarray(self.positions, dtype=float)
        if P.ndim != 2 or P.shape[1] != 3 or len(P) == 0:
            raise TaskError(f"target positions have shape {P.shape}; expected (N, 3) with N ≥ 1")
        if not np.all(np.isfinite(P)):
            raise TaskError("target positions hold NaN or infinite values")
        object.__setattr__(self, "positions", P)
        if self.orientation not in ORIENTATIONS:
            raise TaskError(f"orientation {self.orientation!r} unknown; allowed: {', '.join(ORIENTATIONS)}")
        if self.orientation == "pose" and (self.rotations is None or np.shape(self.rotations) != (len(P), 3, 3)):
            raise TaskError(f"orientation 'pose' needs rotations of shape ({len(P)}, 3, 3)")
        if self.orientation in ("axis", "cone"):
            A = np.asarray(self.axes, dtype=float) if self.axes is not None else None
            if A is None or A.shape != (len(P), 3) or not np.all(np.isfinite(A)):
                raise TaskError(f"orientation {self.orientation!r} needs tool axes of shape ({len(P)}, 3)")
            norm = np.linalg.norm(A, axis=1)
            if np.any(norm < 1e-12):
                raise TaskError("a tool axis has zero length")
            object.__setattr__(self, "axes", A / norm[:, None])
        if self.orientation == "pose":
            object.__setattr__(self, "axes", np.asarray(self.rotations)[:, :, 2].copy())
        if not (np.isfinite(self.tolerance) and self.tolerance > 0):
            raise TaskError(f"tolerance {self.tolerance} must be a positive length (m)")
        if not (0.0 <= self.cone_half_angle < np.pi / 2):
            raise TaskError(f"cone half-angle {self.cone_half_angle} must be in [0, π/2) rad")

    def __len__(self) -> int:
        return len(self.positions)

    @property
    def needs_rotation(self) -> bool:
        """True when the task constrains the tool's orientation (a PPP chain cannot serve it)."""
        return self.orientation != "free"


@dataclass(frozen=True)
class Dexterity:
    """The dexterity a covered target needs: ``kind`` ≥ ``value`` (σ_min in m/rad for the
    translational rows, dimensionless for the full Jacobian scaled by ``characteristic_length`` m;
    manipulability in the units of the robot's task Jacobian)."""

    kind: str = "none"
    value: float = 0.0
    characteristic_length: float = 1.0

    def __post_init__(self):
        if self.kind not in DEXTERITY_KINDS:
            raise TaskError(f"dexterity {self.kind!r} unknown; allowed: {', '.join(DEXTERITY_KINDS)}")
        if not (np.isfinite(self.value) and self.value >= 0):
            raise TaskError(f"dexterity value {self.value} must be a finite number ≥ 0")
        if not (np.isfinite(self.characteristic_length) and self.characteristic_length > 0):
            raise TaskError(f"characteristic_length {self.characteristic_length} must be a positive length (m)")


@dataclass(frozen=True)
class Task:
    """A design task: the robot (with design parameters), targets, dexterity, objective, constraints.

    ``robot`` is a :class:`kin.Robot`; ``min_coverage`` a fraction in [0, 1]; ``total_length`` an
    optional equality constraint Σ(|a_i|+|d_i|) = L (m); ``architectures`` joint-type strings to
    evaluate (empty: the robot's own).  ``length_unit`` / ``angle_unit`` are the units the task file
    was written in (results are reported in them).  ``cell``: the work cell (a
    :class:`planning.cell.Cell`) whose collisions rule solutions out, with ``clearance`` (m) required.
    ``region``: where the robot's base may stand when its placement is searched (a
    :class:`design.place.PlacementRegion`, SI; None: the placement search's default, around the targets).
    ``cycle``: the task's motion cycle (a :class:`design.cycle.CycleSpec`) whose cycle time and peak
    motor torques are metrics — and, for the cycle objectives, the objective, its torque limits a
    constraint; None: none.
    """

    name: str
    robot: object
    targets: Targets
    dexterity: Dexterity = field(default_factory=Dexterity)
    objective: str = "length"
    min_coverage: float = 1.0
    total_length: float | None = None
    architectures: tuple[str, ...] = ()
    seed: int = 0
    length_unit: str = "m"
    angle_unit: str = "rad"
    source: str = ""
    cell: object | None = None
    clearance: float = 0.0
    region: object | None = None
    cycle: object | None = None

    def __post_init__(self):
        if self.objective not in OBJECTIVES:
            raise TaskError(f"objective {self.objective!r} unknown; allowed: {', '.join(OBJECTIVES)}")
        if self.objective in CYCLE_OBJECTIVES and self.cycle is None:
            raise TaskError(f"objective {self.objective!r} needs the task's motion cycle (a [cycle] table)")
        if self.objective == "torque_ratio" and np.isnan(self.cycle.tau_max).all():
            raise TaskError("objective 'torque_ratio' needs motor torque limits (cycle tau_max)")
        if self.cycle is not None:
            self.cycle.check_targets(len(self.targets))
        if not (0.0 <= self.min_coverage <= 1.0):
            raise TaskError(f"min_coverage {self.min_coverage} must be in [0, 1]")
        if self.total_length is not None and not (np.isfinite(self.total_length) and self.total_length > 0):
            raise TaskError(f"total_length {self.total_length} must be a positive length")
