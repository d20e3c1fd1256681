"""Reading task files (TOML).  Every bad field raises :class:`TaskError` naming the file and the
field; nothing is evaluated.  Lengths are in the file's ``length_unit``, angles in its
``angle_unit``; dexterity values are SI (as ``--sigma-min`` is).  Schema: docs/design.md, "Task files"."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

import kin
from design.task.model import CYCLE_OBJECTIVES, OBJECTIVES, Dexterity, Targets, Task, TaskError
from design.task.targets import box_points, read_points_csv, ring_points, shell_points
from kin import robotfile
from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from kin.robotfile import _tname
from kin.transforms import rpy_to_matrix

__all__ = ["load_task", "loads_task", "placement_region", "SHAPES", "PLACEMENT_KEYS", "MAX_PLACEMENT", "TaskReader",
           "read_targets", "read_dexterity"]

SHAPES = ("points", "box", "ring", "sphere", "toolpath")
_TOP = ("name", "title", "robot", "length_unit", "angle_unit", "seed", "objective", "target", "dexterity", "cell",
        "clearance",
        "constraints", "architecture", "placement", "cycle")
_TARGET = {"points": ("file",), "box": ("min", "max", "count"),
           "ring": ("center", "r_inner", "r_outer", "count", "z", "theta"),
           "sphere": ("center", "r_inner", "r_outer", "count"), "toolpath": ("file",)}
_ORIENT = ("orientation", "axis", "half_angle", "rpy", "tolerance", "shape")
#: the keys of a task's ``[placement]`` table
PLACEMENT_KEYS = ("x", "y", "z", "yaw", "tilt", "keep_out")
#: placement coordinates and keep-out corners lie within ±this (m), as :class:`design.place.PlacementRegion`'s
MAX_PLACEMENT = 1e4
#: a task (or sweep) file may have at most this many bytes
MAX_TASK_BYTES = 10 * 2**20


class _Reader(robotfile._Reader):
    """The robot-file field reader (table, number, string, vector), failing with :class:`TaskError`."""

    def fail(self, field: str | None, msg: str) -> TaskError:
        return TaskError(msg, self.path, field)

    def number(self, v: Any, field: str, lo: float = -math.inf, hi: float = math.inf, strict_lo=False) -> float:
        x = super().number(v, field)
        if x < lo or x > hi or (strict_lo and x == lo):
            raise self.fail(field, f"must be a finite number in {'(' if strict_lo else '['}{lo:g}, {hi:g}], got {v}")
        return x

    def integer(self, v: Any, field: str, lo: int = 1, hi: int = 100_000) -> int:
        return super().integer(v, field, lo, hi)

    def counts(self, v: Any, field: str, size: int, limit: int = 200_000) -> list[int]:
        if not isinstance(v, list) or len(v) != size:
            raise self.fail(field, f"must be a list of {size} integers, got {v!r}")
        c = [self.integer(x, f"{field}[{i}]", 1, limit) for i, x in enumerate(v)]
        if math.prod(c) > limit:
            raise self.fail(field, f"{math.prod(c)} targets; at most {limit}")
        return c

    def file(self, v: Any, field: str, base: Path) -> Path:
        p = Path(self.string(v, field))
        p = p if p.is_absolute() else base / p
        if not p.is_file():
            raise self.fail(field, f"no such file {str(p)!r}")
        return p


def load_task(path: str | Path, robot: kin.Robot | None = None) -> Task:
    """Read a task file; relative file names in it are relative to the task file's folder.
    ``robot`` overrides the file's ``robot`` entry (used by the architecture enumeration)."""
    from kin.files import read_text
    p = Path(path)
    text = read_text(p, "task file", MAX_TASK_BYTES, error=TaskError)
    return loads_task(text, str(p), p.parent, robot)


def loads_task(text: str, path: str | None = None, base: Path | None = None, robot: kin.Robot | None = None) -> Task:
    """Parse task-file text (see :func:`load_task`)."""
    r = _Reader(path)
    base = Path(".") if base is None else base
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise TaskError(f"not valid TOML: {e}", path) from None
    r.table(raw, "", _TOP)
    for key in ("name", "robot", "length_unit", "angle_unit", "target"):
        if key not in raw:
            raise r.fail(key, "missing (required)")
    name = r.string(raw["name"], "name")
    if not name or not all(c.isalnum() or c in "_-" for c in name):
        raise r.fail("name", f"{name!r} must be letters, digits, '_' or '-'")
    lu = r.string(raw["length_unit"], "length_unit", tuple(LENGTH_UNITS))
    au = r.string(raw["angle_unit"], "angle_unit", tuple(ANGLE_UNITS))
    ls, as_ = LENGTH_UNITS[lu], ANGLE_UNITS[au]
    if robot is None:
        ref = r.string(raw["robot"], "robot")
        cand = base / ref
        try:
            robot = kin.load_robot(cand if cand.suffix == ".toml" and cand.is_file() else ref)
        except kin.RmtError as e:
            raise r.fail("robot", str(e)) from None
    seed = r.integer(raw.get("seed", 0), "seed", 0, 2 ** 31 - 1)
    targets = _targets(r, raw["target"], ls, as_, base, robot)
    dex = _dexterity(r, raw.get("dexterity", {}), ls)
    objective = r.string(raw.get("objective", "length"), "objective", OBJECTIVES)
    cons = r.table(raw.get("constraints", {}), "constraints", ("min_coverage", "total_length"))
    min_cov = r.number(cons.get("min_coverage", 1.0), "constraints.min_coverage", 0.0, 1.0)
    total = cons.get("total_length")
    total = None if total is None else r.number(total, "constraints.total_length", 0.0, strict_lo=True) * ls
    arch = _architectures(r, raw.get("architecture"), robot.n)
    cell = None
    if "cell" in raw:
        from planning.cell import load_cell
        try:
            cell = load_cell(r.file(raw["cell"], "cell", base))
        except kin.RmtError as e:
            raise r.fail("cell", str(e)) from None
    clearance = r.number(raw.get("clearance", 0.0), "clearance", 0.0, 1.0 / ls) * ls
    if clearance and cell is None:
        raise r.fail("clearance", "needs a cell (the work cell it applies to)")
    region = None
    if "placement" in raw:
        z0 = float(np.asarray(cell.base)[2, 3]) if cell is not None else 0.0
        region = _placement(r, r.table(raw["placement"], "placement", PLACEMENT_KEYS), ls, as_, None, z0)
    cycle = None
    if "cycle" in raw:
        from design.cycle.file import read_cycle
        cycle = read_cycle(r, raw["cycle"], robot, targets, ls, as_)
    if objective in CYCLE_OBJECTIVES and cycle is None:
        raise r.fail("objective", f"{objective!r} needs a [cycle] table (the task's motion cycle)")
    if objective == "torque_ratio" and np.isnan(cycle.tau_max).all():
        raise r.fail("objective", "'torque_ratio' needs motor torque limits (cycle.tau_max)")
    return Task(name=name, robot=robot, targets=targets, dexterity=dex, objective=objective, min_coverage=min_cov,
                total_length=total, architectures=arch, seed=seed, length_unit=lu, angle_unit=au,
                source=path or "", cell=cell, clearance=clearance, region=region, cycle=cycle)


def placement_region(values: dict, length_unit: str = "m", angle_unit: str = "rad", base=None, z: float = 0.0,
                     fields: dict[str, str] | None = None, source: str | None = None):
    """A :class:`design.place.PlacementRegion` (SI) from the values of a ``[placement]`` table (keys
    :data:`PLACEMENT_KEYS`, in ``length_unit`` and ``angle_unit``), checked as a task file's are.

    A key missing from ``values`` keeps ``base``'s value (a region, SI); without ``base``, x and y are
    required and the defaults are z = [z, z] (m), yaw a full turn, tilt 0, no keep-out rectangle.
    ``fields`` maps a key (``""``: the region as a whole) to the name an error gives it (default
    ``placement.KEY``); ``source`` names the file.  Every bad value raises one :class:`TaskError`."""
    r = _Reader(source)
    if length_unit not in LENGTH_UNITS or angle_unit not in ANGLE_UNITS:
        raise TaskError(f"units {length_unit!r}, {angle_unit!r} unknown; allowed: {', '.join(LENGTH_UNITS)} and "
                        f"{', '.join(ANGLE_UNITS)}", source)
    return _placement(r, values, LENGTH_UNITS[length_unit], ANGLE_UNITS[angle_unit], base, z, fields)


def _placement(r: _Reader, raw: dict, ls: float, as_: float, base, z0: float, fields: dict[str, str] | None = None):
    """The ``[placement]`` table (file units) → a PlacementRegion (SI); see :func:`placement_region`."""
    # imported here: design.place imports design.task.model
    from design.place.region import PlacementRegion

    def name(key: str) -> str:
        return (fields or {}).get(key) or (f"placement.{key}" if key else "placement")

    def interval(key: str, scale: float, limit: float, unit: str) -> tuple[float, float]:
        a, b = r.vector(raw[key], name(key), 2)
        if a > b:
            raise r.fail(name(key), f"must be [low, high] with low ≤ high, got [{a:g}, {b:g}]")
        if a * scale < -limit * (1 + 1e-12) or b * scale > limit * (1 + 1e-12):
            raise r.fail(name(key), f"must lie within ±{limit / scale:g} ({unit}), got [{a:g}, {b:g}]")
        return max(a * scale, -limit), min(b * scale, limit)

    if base is None:
        for key in ("x", "y"):
            if key not in raw:
                raise r.fail(name(key), "missing (required in a [placement] table)")
    lu = "file length unit"
    x = interval("x", ls, MAX_PLACEMENT, lu) if "x" in raw else base.x
    y = interval("y", ls, MAX_PLACEMENT, lu) if "y" in raw else base.y
    z = interval("z", ls, MAX_PLACEMENT, lu) if "z" in raw else (base.z if base is not None else (z0, z0))
    if "yaw" in raw:
        yaw = interval("yaw", as_, 2 * math.pi, "file angle unit")
        if yaw[1] - yaw[0] > 2 * math.pi * (1 + 1e-12):
            raise r.fail(name("yaw"), f"spans more than a full turn ({2 * math.pi / as_:g} file angle units)")
    else:
        yaw = base.yaw if base is not None else (-math.pi, math.pi)
    if "tilt" in raw:
        tilt = min(r.number(raw["tilt"], name("tilt"), 0.0, math.pi / 2 / as_ * (1 + 1e-12)) * as_, math.pi / 2)
    else:
        tilt = base.tilt if base is not None else 0.0
    if "keep_out" in raw:
        rects = raw["keep_out"]
        if not isinstance(rects, list):
            raise r.fail(name("keep_out"), f"must be a list of [x_min, x_max, y_min, y_max] rectangles, got "
                                           f"{_tname(rects)}")
        keep_out = []
        for i, rect in enumerate(rects):
            f = f"{name('keep_out')}[{i}]"
            x0, x1, y0, y1 = r.vector(rect, f, 4)
            if x0 >= x1 or y0 >= y1:
                raise r.fail(f, f"must be [x_min, x_max, y_min, y_max] with min < max, got {[x0, x1, y0, y1]}")
            if max(abs(v) for v in (x0, x1, y0, y1)) * ls > MAX_PLACEMENT:
                raise r.fail(f, f"must lie within ±{MAX_PLACEMENT / ls:g} (file length unit)")
            keep_out.append((x0 * ls, x1 * ls, y0 * ls, y1 * ls))
    else:
        keep_out = list(base.keep_out) if base is not None else []

    def covers(lo: float, hi: float, a: float, b: float) -> bool:
        # a keep-out rectangle is open (its edges may be stood on); the searches try inner points of a free range
        return (a <= lo and hi <= b) if lo < hi else (a < lo < b)
    for i, (x0, x1, y0, y1) in enumerate(keep_out):
        if covers(*x, x0, x1) and covers(*y, y0, y1):
            raise r.fail(f"{name('keep_out')}[{i}]", "covers the whole x–y range of the placement: no placement "
                                                     "is left to try")
    try:
        return PlacementRegion(x, y, z, yaw, tilt, tuple(keep_out))
    except TaskError as e:
        raise r.fail(name(""), str(e)) from None


def _targets(r: _Reader, raw: Any, ls: float, as_: float, base: Path, robot) -> Targets:
    if not isinstance(raw, dict):
        raise r.fail("target", f"must be a table, got {_tname(raw)}")
    shape = r.string(raw.get("shape"), "target.shape", SHAPES) if "shape" in raw else None
    if shape is None:
        raise r.fail("target.shape", f"missing (required); allowed: {', '.join(SHAPES)}")
    r.table(raw, "target", _TARGET[shape] + _ORIENT)
    for key in _TARGET[shape]:
        if key not in raw and key not in ("z", "theta"):
            raise r.fail(f"target.{key}", f"missing (required for shape {shape!r})")
    f = lambda k: f"target.{k}"
    axes = rotations = None
    if shape == "box":
        lo, hi = np.array(r.vector(raw["min"], f("min"), 3)), np.array(r.vector(raw["max"], f("max"), 3))
        if np.any(lo > hi):
            raise r.fail(f("max"), "must be ≥ min in every coordinate")
        P = box_points(lo * ls, hi * ls, r.counts(raw["count"], f("count"), 3))
    elif shape in ("ring", "sphere"):
        c = np.array(r.vector(raw["center"], f("center"), 3)) * ls
        ri = r.number(raw["r_inner"], f("r_inner"), 0.0) * ls
        ro = r.number(raw["r_outer"], f("r_outer"), 0.0, strict_lo=True) * ls
        if ro <= ri:
            raise r.fail(f("r_outer"), "must be greater than r_inner")
        if shape == "sphere":
            P = shell_points(c, ri, ro, r.counts(raw["count"], f("count"), 2))
        else:
            z = np.array(r.vector(raw.get("z", [0, 0]), f("z"), 2)) * ls
            th = np.array(r.vector(raw.get("theta", [0, 360 if as_ != 1.0 else 2 * math.pi]), f("theta"), 2)) * as_
            if z[1] < z[0] or th[1] <= th[0] or th[1] - th[0] > 2 * math.pi + 1e-9:
                raise r.fail(f("z") if z[1] < z[0] else f("theta"),
                             "must be [low, high] with low ≤ high (theta: a span ≤ 360°)")
            P = ring_points(c, ri, ro, r.counts(raw["count"], f("count"), 3), z, th)
    elif shape == "points":
        P, axes = read_points_csv(r.file(raw["file"], f("file"), base), ls)
    else:
        from planning.toolpath import load_toolpath
        tp = load_toolpath(r.file(raw["file"], f("file"), base), robot)
        P = tp.poses[:, :3, 3]
        rotations = tp.poses[:, :3, :3] if tp.has_orientation else None
    orient = r.string(raw.get("orientation", "free"), f("orientation"), ("free", "pose", "axis", "cone"))
    half = 0.0
    if orient == "pose" and rotations is None:
        if "rpy" not in raw:
            raise r.fail(f("rpy"), "missing (required for orientation 'pose' unless a tool path gives the poses)")
        R = rpy_to_matrix(np.array(r.vector(raw["rpy"], f("rpy"), 3)) * as_)
        rotations = np.broadcast_to(R, (len(P), 3, 3)).copy()
    if orient in ("axis", "cone") and axes is None:
        if "axis" not in raw:
            raise r.fail(f("axis"), f"missing (required for orientation {orient!r} unless the points file gives axes)")
        a = np.array(r.vector(raw["axis"], f("axis"), 3))
        if np.linalg.norm(a) < 1e-12:
            raise r.fail(f("axis"), "must not be the zero vector")
        axes = np.broadcast_to(a, (len(P), 3)).copy()
    if orient == "cone":
        if "half_angle" not in raw:
            raise r.fail(f("half_angle"), "missing (required for orientation 'cone')")
        half = r.number(raw["half_angle"], f("half_angle"), 0.0, math.pi / 2 / as_ * (1 - 1e-9))
        half *= as_
    tol = r.number(raw.get("tolerance", 1e-6 / ls), f("tolerance"), 0.0, strict_lo=True) * ls
    if orient == "free":
        axes = rotations = None
    elif orient != "pose":
        rotations = None
    return Targets(P, orient, axes, rotations, half, tol, shape)


def _dexterity(r: _Reader, raw: Any, ls: float) -> Dexterity:
    r.table(raw, "dexterity", ("sigma_min", "characteristic_length", "manipulability"))
    if "sigma_min" in raw and "manipulability" in raw:
        raise r.fail("dexterity", "give sigma_min or manipulability, not both")
    if "manipulability" in raw:
        return Dexterity("manipulability", r.number(raw["manipulability"], "dexterity.manipulability", 0.0))
    if "characteristic_length" in raw and "sigma_min" not in raw:
        raise r.fail("dexterity.characteristic_length", "only meaningful with sigma_min")
    if "sigma_min" in raw:
        s = r.number(raw["sigma_min"], "dexterity.sigma_min", 0.0)
        if "characteristic_length" in raw:
            L = r.number(raw["characteristic_length"], "dexterity.characteristic_length", 0.0, strict_lo=True) * ls
            return Dexterity("sigma_min_full", s, L)
        return Dexterity("sigma_min", s)
    return Dexterity()


def _architectures(r: _Reader, raw: Any, n: int) -> tuple[str, ...]:
    if raw is None:
        return ()
    if raw == "all":
        from design.architecture import all_architectures
        return tuple(all_architectures(n))
    if not isinstance(raw, list) or not raw:
        raise r.fail("architecture", f"must be \"all\" or a non-empty list of joint-type strings, got {raw!r}")
    out = []
    for i, s in enumerate(raw):
        s = r.string(s, f"architecture[{i}]")
        if len(s) != n or set(s) - {"R", "P"}:
            raise r.fail(f"architecture[{i}]", f"{s!r} must be {n} letters R or P (the robot has {n} joints)")
        out.append(s)
    return tuple(dict.fromkeys(out))


# the readers a part file shares with task files (design.compose.parts: a part is a task without a robot)
TaskReader = _Reader
read_targets = _targets
read_dexterity = _dexterity
