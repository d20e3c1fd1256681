"""Checked access to the fields of one table of a cell file: :class:`Table`.

Every getter checks the type, finiteness and range of one key and raises :class:`CellError` in one
line, ``<where>: <table>: <key>: <what is wrong>``; lengths are converted from the file's
``length_unit`` to metres and angles from its ``angle_unit`` to radians.
"""
from __future__ import annotations

import math

import numpy as np

from kin.chain import ANGLE_UNITS
from kin.transforms import make_transform, rpy_to_matrix
from planning.errors import CellError

__all__ = ["MAX_LENGTH", "Table", "check_keys", "is_num"]

#: no length or coordinate of a cell may exceed this (m): a cell is smaller than 10 km
MAX_LENGTH = 1e4


def is_num(x) -> bool:
    """A TOML number: int or float, not a boolean."""
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def check_keys(label: str, table: dict, allowed: set[str]) -> None:
    """Refuse keys of ``table`` outside ``allowed``, listing the allowed ones."""
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise CellError(f"{label}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(sorted(allowed))}")


class Table:
    """Checked access to one TOML table's fields (``table``), named ``label`` in messages; lengths are
    in ``unit`` and converted to m with ``scale`` (m per unit); angles are in ``angle_unit``."""

    def __init__(self, label: str, table: dict, unit: str, scale: float, angle_unit: str):
        self.label, self.t, self.unit, self.scale, self.angle_unit = label, table, unit, scale, angle_unit

    def fail(self, key: str, msg: str) -> CellError:
        return CellError(f"{self.label}: {key}: {msg}")

    def number(self, key: str, default=None, positive: bool = True) -> float | None:
        """A finite number (> 0 with ``positive``), in the cell's length unit → m."""
        v = self.t.get(key, default)
        if v is None:
            raise self.fail(key, f"required (a number, {self.unit})")
        if not is_num(v):
            raise self.fail(key, f"must be a number ({self.unit}), not {type(v).__name__} {v!r}")
        if not math.isfinite(v):
            raise self.fail(key, f"must be finite, not {v}")
        if positive and not v > 0:
            raise self.fail(key, f"must be > 0, not {v}")
        m = float(v) * self.scale
        if abs(m) > MAX_LENGTH:
            raise self.fail(key, f"{v} {self.unit} is more than the {MAX_LENGTH / 1000:g} km a cell may span")
        return m

    def numbers(self, key: str, n: int, what: str, default=None) -> list[float] | None:
        """``n`` finite numbers (raw, file units)."""
        v = self.t.get(key, default)
        if v is None:
            raise self.fail(key, f"required ({what})")
        if not (isinstance(v, list) and len(v) == n and all(is_num(x) for x in v)):
            raise self.fail(key, f"must be {n} numbers {what}, not {v!r}")
        if not all(math.isfinite(x) for x in v):
            raise self.fail(key, f"must be finite numbers, not {v}")
        return [float(x) for x in v]

    def point(self, key: str, default=None) -> np.ndarray:
        """Three coordinates [x, y, z] in the cell's length unit → m."""
        v = np.array(self.numbers(key, 3, f"[x, y, z] ({self.unit})", default)) * self.scale
        if np.abs(v).max() > MAX_LENGTH:
            raise self.fail(key, f"{self.t[key]} is more than the {MAX_LENGTH / 1000:g} km a cell may span")
        return v

    def sizes(self, key: str) -> np.ndarray:
        """Three positive lengths in the cell's length unit → m."""
        v = self.numbers(key, 3, f"[x, y, z] ({self.unit}, each > 0)")
        if not all(x > 0 for x in v):
            raise self.fail(key, f"every size must be > 0, not {v}")
        m = np.array(v) * self.scale
        if m.max() > MAX_LENGTH:
            raise self.fail(key, f"{v} is more than the {MAX_LENGTH / 1000:g} km a cell may span")
        return m

    def pose(self) -> np.ndarray:
        """4×4 from ``xyz`` (length unit) and ``rpy`` (angle unit), both optional."""
        xyz = self.point("xyz", [0, 0, 0])
        rpy = self.numbers("rpy", 3, f"[roll, pitch, yaw] ({self.angle_unit})", [0, 0, 0])
        if max(abs(a) for a in rpy) > 1e4:
            raise self.fail("rpy", f"angles of magnitude > 1e4 {self.angle_unit} are not angles ({rpy})")
        return make_transform(rpy_to_matrix(np.array(rpy) * ANGLE_UNITS[self.angle_unit]), xyz)

    def string(self, key: str, default=None, choices=None) -> str:
        v = self.t.get(key, default)
        if v is None:
            raise self.fail(key, "required" + (f"; one of: {', '.join(choices)}" if choices else " (a string)"))
        if not isinstance(v, str):
            raise self.fail(key, f"must be a string, not {type(v).__name__} {v!r}")
        if choices is not None and v not in choices:
            raise self.fail(key, f"{v!r} unknown; allowed: {', '.join(choices)}")
        return v

    def names(self, key: str) -> list[str]:
        v = self.t.get(key, [])
        if not (isinstance(v, list) and all(isinstance(x, str) and x.strip() for x in v)):
            raise self.fail(key, f"must be a list of body names such as [\"tool\", \"link 6\"], not {v!r}")
        if len(v) > 1000:
            raise self.fail(key, f"{len(v)} names; at most 1000")
        return v
