"""One way to validate what users give rmtkit: numbers and counts handed to the Python API or the
command line (:func:`is_real`, :func:`is_count`, :func:`real`, :func:`count`) and the fields of the
files they write (:class:`Fields`: robot files, task, sweep and tool-path files).

Every check refuses a bool where a number is meant (``True`` is an ``int`` to Python, never to a
user), NaN and infinities, and values outside the stated range, with one line that names the
argument or the file and field and what is allowed.  The error class is the caller's: each layer
raises its own :class:`~kin.errors.RmtError` subclass.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from kin.errors import ArgumentError, RmtError

__all__ = ["is_real", "is_count", "real", "count", "type_name", "Fields", "real_array"]


def is_real(x: Any) -> bool:
    """A real number (int, float or a numpy scalar of either), not a bool; finite or not."""
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))


def is_count(x: Any) -> bool:
    """An integer (int or a numpy integer), not a bool."""
    return isinstance(x, (int, np.integer)) and not isinstance(x, (bool, np.bool_))


def type_name(x: Any) -> str:
    """A short, user-facing name of a value's type (TOML and JSON words where they exist)."""
    return {bool: "boolean", int: "integer", float: "number", str: "string", list: "array",
            dict: "table", type(None): "nothing"}.get(type(x), type(x).__name__)


def _range_text(low: float | None, high: float | None, low_open: bool, high_open: bool) -> str:
    if low is None and high is None:
        return "a finite number"
    if high is None:
        return f"a finite number {'>' if low_open else '≥'} {low:g}"
    if low is None:
        return f"a finite number {'<' if high_open else '≤'} {high:g}"
    return f"a number in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"


def real(x: Any, what: str, low: float | None = None, high: float | None = None, *, low_open: bool = False,
         high_open: bool = False, error: type[RmtError] = ArgumentError) -> float:
    """``x`` as a float when it is a finite real number within [low, high] (open ends with
    ``low_open``/``high_open``; −0 read as 0); else ``error`` naming ``what`` and the range."""
    allowed = _range_text(low, high, low_open, high_open)
    if not is_real(x):
        raise error(f"{what} must be {allowed}, got {type_name(x)} {x!r}")
    v = float(x) + 0.0
    if (not math.isfinite(v) or (low is not None and (v < low or (low_open and v == low)))
            or (high is not None and (v > high or (high_open and v == high)))):
        raise error(f"{what} = {v!r} must be {allowed}")
    return v


def count(x: Any, what: str, low: int | None = None, high: int | None = None, *,
          error: type[RmtError] = ArgumentError) -> int:
    """``x`` as an int when it is an integer within [low, high]; else ``error`` naming ``what``."""
    lo = "" if low is None else f" ≥ {low}"
    allowed = f"an integer{lo}" if high is None else f"an integer in [{low}, {high}]"
    if not is_count(x):
        raise error(f"{what} must be {allowed}, got {type_name(x)} {x!r}")
    if (low is not None and x < low) or (high is not None and x > high):
        raise error(f"{what} = {int(x)} must be {allowed}")
    return int(x)


class Fields:
    """Field-by-field reading of a parsed file (TOML or JSON) with messages naming the file and the
    dotted field: subclass it and give :meth:`fail` (or pass ``fail``) the layer's error."""

    def __init__(self, source: str | None = None, fail: Callable[[str | None, str], RmtError] | None = None):
        self.source = source
        self._fail = fail

    def fail(self, field: str | None, msg: str) -> RmtError:
        """The error to raise for ``field`` (None: the whole file)."""
        if self._fail is not None:
            return self._fail(field, msg)
        where = ": ".join(x for x in (self.source, field) if x)
        return RmtError(f"{where}: {msg}" if where else msg)

    def table(self, obj: Any, field: str, allowed: Sequence[str]) -> dict:
        """A table whose keys are all in ``allowed``."""
        if not isinstance(obj, dict):
            raise self.fail(field, f"must be a table, got {type_name(obj)}")
        for k in obj:
            if k not in allowed:
                raise self.fail(f"{field}.{k}" if field else k, f"unknown field; allowed: {', '.join(allowed)}")
        return obj

    def number(self, v: Any, field: str, positive: bool = False) -> float:
        """A finite number (> 0 with ``positive``)."""
        if not is_real(v):
            raise self.fail(field, f"must be a number, got {type_name(v)} {v!r}")
        x = float(v)
        if not math.isfinite(x):
            raise self.fail(field, f"must be a finite number, got {v}")
        if positive and x <= 0:
            raise self.fail(field, f"must be > 0, got {x:g}")
        return x

    def integer(self, v: Any, field: str, low: int = 1, high: int | None = None) -> int:
        """An integer within [low, high]."""
        allowed = f"an integer ≥ {low}" if high is None else f"an integer in [{low}, {high}]"
        if not is_count(v):
            raise self.fail(field, f"must be {allowed}, got {type_name(v)} {v!r}")
        if v < low or (high is not None and v > high):
            raise self.fail(field, f"must be {allowed}, got {v}")
        return int(v)

    def string(self, v: Any, field: str, allowed: Sequence[str] | None = None) -> str:
        """A string, one of ``allowed`` when given."""
        if not isinstance(v, str):
            raise self.fail(field, f"must be a string, got {type_name(v)} {v!r}")
        if allowed is not None and v not in allowed:
            raise self.fail(field, f"{v!r} is not allowed; allowed: {', '.join(allowed)}")
        return v

    def vector(self, v: Any, field: str, size: int) -> list[float]:
        """A list of ``size`` finite numbers."""
        if not isinstance(v, list) or len(v) != size:
            got = f"{type_name(v)} of length {len(v)}" if isinstance(v, list) else f"{type_name(v)} {v!r}"
            raise self.fail(field, f"must be a list of {size} numbers, got {got}")
        return [self.number(x, f"{field}[{i}]") for i, x in enumerate(v)]


def real_array(x, what: str, error: type[Exception]) -> np.ndarray:
    """``x`` as an array of real numbers (int or float dtype), else ``error`` naming ``what``.

    Strings, complex numbers, booleans, None and ragged nestings are refused (numpy would turn "1.5"
    into 1.5 and drop imaginary parts).  Shape and finiteness are the caller's to check.
    """
    if type(x) is not np.ndarray:
        try:
            x = np.asarray(x)
        except (ValueError, TypeError) as e:
            raise error(f"{what} is not an array of numbers ({e})") from None
    if x.dtype.kind not in "fiu":
        raise error(f"{what} must hold real numbers; got {x.dtype.name} values "
                    f"(strings, complex numbers, booleans and objects are refused)")
    return x
