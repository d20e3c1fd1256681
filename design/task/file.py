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
from design.task.model import OBJECTIVES, Dexterity, Targets, Task, TaskError
from design.task.targets import box_points, read_points_csv, ring_points, shell_points
from kin import robotfile
from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from kin.robotfile import _tname
from kin.transforms import rpy_to_matrix

__all__ = ["load_task", "loads_task", "SHAPES"]

SHAPES = ("points", "box", "ring", "sphere", "toolpath")
_TOP = ("name", "title", "robot", "length_unit", "angle_unit", "seed", "objective", "target", "dexterity", "cell",
        "clearance",
        "constraints", "architecture")
_TARGET = {"points": ("file",), "box": ("min", "max", "count"),
           "ring": ("center", "r_inner", "r_outer", "count", "z", "theta"),
           "sphere": ("center", "r_inner", "r_outer", "count"), "toolpath": ("file",)}
_ORIENT = ("orientation", "axis", "half_angle", "rpy", "tolerance", "shape")


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
    p = Path(path)
    try:
        text = p.read_text()
    except OSError as e:
        raise TaskError(f"cannot read task file: {e.strerror or e}", str(p)) from None
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
    return Task(name=name, robot=robot, targets=targets, dexterity=dex, objective=objective, min_coverage=min_cov,
                total_length=total, architectures=arch, seed=seed, length_unit=lu, angle_unit=au,
                source=path or "", cell=cell, clearance=clearance)


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
