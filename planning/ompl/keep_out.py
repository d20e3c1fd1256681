"""Keep-out files: the boxes of a work cell that the robot must stay out of, as TOML.

    length_unit = "mm"          # optional: "m" | "mm" | "in" (default: the robot file's)

    [[box]]
    name = "fixture"            # optional
    lower = [400, -200, 0]      # corner with the smallest x, y, z, base frame
    upper = [700, 200, 300]     # corner with the largest x, y, z
    frames = "tool"             # "tool": the tool point only (default) | "all": every joint-frame origin too

Every problem raises :class:`KeepOutError` naming the file, the box and the field; the file is read
as data (TOML), never evaluated.
"""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

from kin.chain import LENGTH_UNITS
from kin.files import FileReadError, read_text
from planning.errors import PlanningError
from planning.ompl.validity import KeepOutBox

__all__ = ["KeepOutError", "load_keep_out", "parse_keep_out", "MAX_BOXES"]

MAX_BOXES = 1000
#: the largest keep-out file read
MAX_BYTES = 1 << 20
_TOP = {"length_unit", "box"}
_BOX = {"name", "lower", "upper", "frames"}
FRAMES = ("tool", "all")


class KeepOutError(PlanningError):
    """A keep-out file is missing or invalid."""


def parse_keep_out(text: str, default_length_unit: str, where: str = "keep-out") -> list[KeepOutBox]:
    """Boxes (SI, base frame) of a keep-out file's text; ``default_length_unit`` when it names none."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise KeepOutError(f"{where}: not valid TOML ({e})") from None
    unknown = sorted(set(doc) - _TOP)
    if unknown:
        raise KeepOutError(f"{where}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(sorted(_TOP))}")
    unit = doc.get("length_unit", default_length_unit)
    if unit not in LENGTH_UNITS:
        raise KeepOutError(f"{where}: length_unit {unit!r} unknown; allowed: {', '.join(LENGTH_UNITS)}")
    scale = LENGTH_UNITS[unit]
    boxes = doc.get("box", [])
    if not isinstance(boxes, list) or not all(isinstance(b, dict) for b in boxes):
        raise KeepOutError(f"{where}: 'box' must be an array of tables ([[box]])")
    if not boxes:
        raise KeepOutError(f"{where}: no [[box]] given")
    if len(boxes) > MAX_BOXES:
        raise KeepOutError(f"{where}: {len(boxes)} boxes; at most {MAX_BOXES}")
    out = []
    for k, b in enumerate(boxes, 1):
        label = f"{where}: box {k}" + (f" ({b['name']!r})" if isinstance(b.get("name"), str) else "")
        unknown = sorted(set(b) - _BOX)
        if unknown:
            raise KeepOutError(f"{label}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(sorted(_BOX))}")
        corners = []
        for field in ("lower", "upper"):
            v = b.get(field)
            if not (isinstance(v, list) and len(v) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                                 for x in v)):
                raise KeepOutError(f"{label}: {field} must be three numbers [x, y, z] ({unit})")
            if not all(math.isfinite(x) and abs(x) < 1e6 for x in v):
                raise KeepOutError(f"{label}: {field} must be finite numbers of magnitude < 1e6 {unit}")
            corners.append(tuple(float(x) * scale for x in v))
        if not all(lo < hi for lo, hi in zip(*corners)):
            raise KeepOutError(f"{label}: lower must be below upper in x, y and z (got {b['lower']} and {b['upper']})")
        frames = b.get("frames", "tool")
        if frames not in FRAMES:
            raise KeepOutError(f"{label}: frames {frames!r} unknown; allowed: {', '.join(FRAMES)}")
        out.append(KeepOutBox(corners[0], corners[1], all_frames=frames == "all"))
    return out


def load_keep_out(path: str | Path, default_length_unit: str) -> list[KeepOutBox]:
    """Boxes (SI) of a keep-out TOML file (see the module docstring)."""
    path = Path(path)
    try:
        text = read_text(path, "keep-out file", MAX_BYTES)
    except FileReadError as e:
        raise KeepOutError(str(e)) from None
    return parse_keep_out(text, default_length_unit, str(path))
