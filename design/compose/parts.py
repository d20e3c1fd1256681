"""Part files: what one part of a family asks of a machine built from modules — a task file
(:mod:`design.task.file`) without ``robot``, since the machine is what composition looks for.

A part has targets (with their orientation requirement and position tolerance), optionally a
dexterity requirement, a work cell with a clearance, singular windows to keep out of
(``[windows] sigma_min`` or ``manipulability``, SI: built for each assembly, which is expensive),
a motion cycle and ``max_cycle_time`` (s).  The robot stands at the cell's ``[robot]`` placement
(the world origin without a cell).  A tool path's numbers are in the part file's units.

The ``[cycle]`` table is a task file's, except that the joint limits are *scalars* (every joint;
a list per joint has no meaning before the machine is known), each defaulting to the assembled
modules' ratings (``max_velocity``, ``max_acceleration``, ``max_torque``): ``v_max``, ``a_max`` in
the part's angle unit per s (s²) for revolute joints and length unit for prismatic ones, ``tau_max``
in N·m (N).  The masses are the assembled modules' own; ``[cycle.masses]`` takes only ``payload``
(kg: the workpiece, a point mass at the tool frame's origin).

Task-file fields that need a robot (``architecture``, ``placement``, ``objective``,
``constraints``) are refused.  Every bad field raises :class:`design.task.TaskError` naming the
file and the field.  The format: docs/modules.md, "Composition".
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

from design.task.file import MAX_TASK_BYTES, TaskReader, read_dexterity, read_targets
from design.task.model import Dexterity, Targets, TaskError
from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from kin.errors import RmtError

__all__ = ["Part", "PartCycle", "load_part", "loads_part", "PART_KEYS", "PART_CYCLE_KEYS", "MAX_CYCLE_TIME"]

PART_KEYS = ("name", "title", "length_unit", "angle_unit", "target", "dexterity", "cell", "clearance", "windows",
             "cycle", "max_cycle_time")
PART_CYCLE_KEYS = ("sequence", "v_max", "a_max", "tau_max", "torque", "lift", "dwell", "blend", "ik_starts", "masses")
_ROBOT_KEYS = ("robot", "architecture", "placement", "objective", "constraints", "seed")
#: the longest cycle time a part may ask for (s)
MAX_CYCLE_TIME = 1e5


@dataclass(frozen=True)
class PartCycle:
    """A part's motion cycle before the machine is known (SI): the limits are scalars in the part
    file's units (``v_max``, ``a_max``: angle unit for revolute joints, length unit for prismatic
    ones, per s and s²; ``tau_max`` N·m or N), None for the modules' ratings; ``angle_scale`` and
    ``length_scale`` turn them into SI per joint."""

    sequence: tuple[int, ...]
    v_max: float | None = None
    a_max: float | None = None
    tau_max: float | None = None
    torque: str = "check"
    lift: float = 0.0
    dwell: float = 0.0
    blend: float = 0.05
    ik_starts: int = 8
    payload: float = 0.0
    angle_scale: float = 1.0
    length_scale: float = 1.0

    def spec(self, chain):
        """The :class:`design.cycle.CycleSpec` of this cycle on ``chain`` (an assembled robot whose
        bodies carry their masses); :class:`TaskError` when a limit is neither given nor rated."""
        from design.cycle.model import CycleSpec
        n = len(chain.joints)
        unit = np.where(chain.revolute_mask, self.angle_scale, self.length_scale)
        lims = {}
        for key, attr in (("v_max", "max_velocity"), ("a_max", "max_acceleration")):
            v = getattr(self, key)
            if v is not None:
                lims[key] = v * unit
                continue
            rated = [getattr(j, attr) for j in chain.joints]
            missing = [j.name or str(k + 1) for k, (j, r) in enumerate(zip(chain.joints, rated)) if r is None]
            if missing:
                raise TaskError(f"cycle.{key}: not given, and joint {missing[0]} has no {attr} rating to default to")
            lims[key] = np.array(rated, float)
        if self.tau_max is not None:
            tau = np.full(n, float(self.tau_max))
        else:
            tau = np.array([math.nan if j.max_torque is None else float(j.max_torque) for j in chain.joints])
        return CycleSpec(self.sequence, lims["v_max"], lims["a_max"], tau, None, self.torque, self.lift, self.dwell,
                         self.blend, self.ik_starts)


@dataclass(frozen=True)
class Part:
    """A part of a family (SI): ``targets`` (cell frame), ``dexterity``, ``cell`` (a
    :class:`planning.cell.Cell` or None) with ``clearance`` (m), ``windows`` (("sigma_min" |
    "manipulability", threshold) or None), ``cycle`` (:class:`PartCycle` or None),
    ``max_cycle_time`` (s or None); ``length_unit``/``angle_unit`` the file's."""

    name: str
    targets: Targets
    dexterity: Dexterity = field(default_factory=Dexterity)
    cell: object | None = None
    clearance: float = 0.0
    windows: tuple[str, float] | None = None
    cycle: PartCycle | None = None
    max_cycle_time: float | None = None
    length_unit: str = "m"
    angle_unit: str = "rad"
    title: str = ""
    source: str = ""

    def __post_init__(self):
        if not isinstance(self.targets, Targets):
            raise TaskError(f"part {self.name!r}: targets must be design.task.Targets")
        if self.max_cycle_time is not None and self.cycle is None:
            raise TaskError(f"part {self.name!r}: max_cycle_time needs a cycle")
        if self.cycle is not None and self.targets.orientation not in ("free", "pose"):
            raise TaskError(f"part {self.name!r}: a cycle needs position ('free') or 'pose' targets, not "
                            f"{self.targets.orientation!r}")

    @property
    def needs_roll(self) -> bool:
        """Whether the tool's rotation about its own axis matters (a full pose is asked)."""
        return self.targets.orientation == "pose"

    @property
    def placement(self) -> np.ndarray:
        """Where the robot's base stands in the cell (4×4, SI): the cell's ``[robot]`` placement or the identity."""
        return np.array(self.cell.base, float) if self.cell is not None else np.eye(4)


def load_part(path: str | Path) -> Part:
    """Read a part file (module text); relative file names in it are relative to its folder."""
    from kin.files import read_text
    p = Path(path)
    text = read_text(p, "part file", MAX_TASK_BYTES, error=TaskError)
    return loads_part(text, str(p), p.parent)


def loads_part(text: str, path: str | None = None, base: Path | None = None) -> Part:
    """Parse part-file text (see :func:`load_part`)."""
    r = TaskReader(path)
    base = Path(".") if base is None else base
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise TaskError(f"not valid TOML: {e}", path) from None
    for key in _ROBOT_KEYS:
        if key in raw:
            raise r.fail(key, "a part file names no robot: composition looks for the machine (a task file's "
                              f"{key!r} has no place here)")
    r.table(raw, "", PART_KEYS)
    for key in ("name", "length_unit", "angle_unit", "target"):
        if key not in raw:
            raise r.fail(key, "missing (required)")
    name = r.string(raw["name"], "name")
    if not name or len(name) > 64 or not all(c.isalnum() or c in "_-" for c in name):
        raise r.fail("name", f"{name!r} must be 1 to 64 letters, digits, '_' or '-'")
    title = r.string(raw.get("title", ""), "title")
    lu = r.string(raw["length_unit"], "length_unit", tuple(LENGTH_UNITS))
    au = r.string(raw["angle_unit"], "angle_unit", tuple(ANGLE_UNITS))
    ls, as_ = LENGTH_UNITS[lu], ANGLE_UNITS[au]
    units = SimpleNamespace(length_unit=lu, angle_unit=au)       # a tool path's numbers are in the part's units
    try:
        targets = read_targets(r, raw["target"], ls, as_, base, units)
    except TaskError:
        raise
    except RmtError as e:          # a tool path's own error
        raise r.fail("target.file", str(e)) from None
    dex = read_dexterity(r, raw.get("dexterity", {}), ls)
    if dex.kind == "sigma_min_full":
        raise r.fail("dexterity.characteristic_length", "the reach study checks sigma_min (translational rows) or "
                                                        "manipulability; characteristic_length has no place here")
    cell = None
    if "cell" in raw:
        from planning.cell import load_cell
        try:
            cell = load_cell(r.file(raw["cell"], "cell", base))
        except TaskError:
            raise
        except RmtError as e:
            raise r.fail("cell", str(e)) from None
    from planning.collision import MAX_MARGIN
    clearance = r.number(raw.get("clearance", 0.0), "clearance", 0.0, MAX_MARGIN / ls) * ls
    if clearance and cell is None:
        raise r.fail("clearance", "needs a cell (the work cell it applies to)")
    windows = _windows(r, raw.get("windows"))
    cycle = _cycle(r, raw["cycle"], len(targets), ls, as_) if "cycle" in raw else None
    if cycle is not None and targets.orientation not in ("free", "pose"):
        raise r.fail("cycle", f"needs position ('free') or 'pose' targets, not {targets.orientation!r}")
    tmax = None
    if "max_cycle_time" in raw:
        if cycle is None:
            raise r.fail("max_cycle_time", "needs a [cycle] table (the motion whose time it bounds)")
        tmax = r.number(raw["max_cycle_time"], "max_cycle_time", 0.0, MAX_CYCLE_TIME, strict_lo=True)
    return Part(name=name, targets=targets, dexterity=dex, cell=cell, clearance=clearance, windows=windows,
                cycle=cycle, max_cycle_time=tmax, length_unit=lu, angle_unit=au, title=title, source=path or "")


def _windows(r, raw: Any) -> tuple[str, float] | None:
    if raw is None:
        return None
    r.table(raw, "windows", ("sigma_min", "manipulability"))
    if len(raw) != 1:
        raise r.fail("windows", "give exactly one of sigma_min or manipulability (SI)")
    (kind, v), = raw.items()
    return kind, r.number(v, f"windows.{kind}", 0.0, 1e3, strict_lo=True)


def _cycle(r, raw: Any, count: int, ls: float, as_: float) -> PartCycle:
    from design.cycle.file import MAX_LIMIT, MIN_LIMIT
    from design.cycle.masses import MAX_PART_MASS
    from design.cycle.model import MAX_STOPS, TORQUE_MODES
    r.table(raw, "cycle", PART_CYCLE_KEYS)
    if "sequence" not in raw:
        raise r.fail("cycle.sequence", "missing (required): the target indices (0-based) the cycle visits in order")
    seq = raw["sequence"]
    if not isinstance(seq, list) or not 2 <= len(seq) <= MAX_STOPS:
        raise r.fail("cycle.sequence", f"must be a list of 2 to {MAX_STOPS} target indices (0-based)")
    seq = tuple(r.integer(x, f"cycle.sequence[{i}]", 0, count - 1) for i, x in enumerate(seq))
    lims = {}
    for key in ("v_max", "a_max", "tau_max"):
        if key in raw:
            if isinstance(raw[key], list):
                raise r.fail(f"cycle.{key}", "must be one number for every joint (a part names no robot, so a list "
                                             "per joint has no meaning); leave it out for the modules' ratings")
            lims[key] = r.number(raw[key], f"cycle.{key}", MIN_LIMIT, MAX_LIMIT)
    torque = r.string(raw.get("torque", "check"), "cycle.torque", TORQUE_MODES)
    lift = r.number(raw.get("lift", 0.0), "cycle.lift", 0.0, 1e3 / ls) * ls
    dwell = r.number(raw.get("dwell", 0.0), "cycle.dwell", 0.0, 3600.0)
    blend = r.number(raw.get("blend", 0.05), "cycle.blend", 0.0, 10.0)
    starts = r.integer(raw.get("ik_starts", 8), "cycle.ik_starts", 1, 64)
    m = raw.get("masses", {})
    if isinstance(m, dict) and set(m) - {"payload"}:
        raise r.fail(f"cycle.masses.{sorted(set(m) - {'payload'})[0]}", "the assembled modules carry their own "
                                                                       "masses; only payload (kg) is taken here")
    m = r.table(m, "cycle.masses", ("payload",))
    payload = r.number(m.get("payload", 0.0), "cycle.masses.payload", 0.0, MAX_PART_MASS)
    return PartCycle(seq, lims.get("v_max"), lims.get("a_max"), lims.get("tau_max"), torque, lift, dwell, blend, starts,
                     payload, as_, ls)
