"""The window values: :class:`Window` (one factor's neighbourhood: intervals of one joint or the
predicate |g(q)| ≤ ε) and :class:`WindowSet` (all of a robot's windows: batch membership, JSON).
See :mod:`planning.windows` for what a window is."""
from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from kin.errors import ConfigurationError
from kin.output import write_output
from kin.singular.evaluate import batch_function
from kin.singular.expression import ExpressionError, parse_tree
from kin.singular.tree import Node
from kin.validation import is_count, is_real
from planning.errors import WindowError
from planning.windows.base import WindowBase
from planning.windows.sampled import PointSetWindow, is_point_set_entry

METHODS = ("margin", "sigma_min", "manipulability", "learned")
#: the largest joint count a windows file may declare
MAX_JOINTS = 64


def _batch(Q, n: int) -> tuple[np.ndarray, bool]:
    """One configuration (n,) or a batch (N, n) of real numbers → ((N, n) float array, single?).

    Any other shape, or values that are not real numbers (strings, complex), raise
    :class:`~kin.errors.ConfigurationError` instead of being reshaped or cast."""
    arr = np.asarray(Q)
    if arr.dtype.kind not in "biuf":
        raise ConfigurationError(f"configurations must be real numbers, got an array of {arr.dtype}")
    if not ((arr.ndim == 1 and arr.shape[0] == n) or (arr.ndim == 2 and arr.shape[1] == n)):
        raise ConfigurationError(f"configurations have shape {arr.shape}; expected ({n},) or (N, {n})")
    return (arr.astype(float, copy=False).reshape(-1, n), arr.ndim == 1)


@dataclass
class Window(WindowBase):
    """One singular window with a formula (SI units; the common fields are :class:`WindowBase`'s).

    ``intervals`` (single-joint factor): list of (lo, hi) on joint ``joints[0]`` (1-based);
    ``epsilon`` (other factors): |g(q)| ≤ ε with g = ``expr`` in q1…qn.
    """

    intervals: list[tuple[float, float]] | None = None
    epsilon: float | None = None
    detail: dict = field(default_factory=dict)
    _g: Callable | None = field(default=None, repr=False, compare=False)
    _tree: Node | None = field(default=None, repr=False, compare=False)

    @property
    def is_interval(self) -> bool:
        return self.intervals is not None

    @property
    def joint(self) -> int | None:
        """0-based joint of an interval window."""
        return self.joints[0] - 1 if self.is_interval else None

    @property
    def tree(self) -> Node:
        """The factor's expression tree (:mod:`kin.singular.tree`), read once from ``expr`` by the
        safe grammar of :mod:`kin.singular.expression`."""
        if self._tree is None:
            self._tree = parse_tree(self.expr, self.n, f"window {self.name!r}")
        return self._tree

    def g(self, Q: np.ndarray) -> np.ndarray:
        """The factor at a batch (N, n) → (N,)."""
        if self._g is None:
            self._g = batch_function(self.tree)
        return self._g(Q)

    def contains(self, Q) -> np.ndarray:
        """Boolean (N,) — or a bool for one configuration — True inside the window."""
        Q2, single = _batch(Q, self.n)
        if self.is_interval:
            x = Q2[:, self.joint]
            inside = np.zeros(len(Q2), bool)
            for lo, hi in self.intervals:
                inside |= (x >= lo) & (x <= hi)
        else:
            inside = np.abs(self.g(Q2)) <= self.epsilon
        return bool(inside[0]) if single else inside

    def distance_out(self, Q) -> np.ndarray:
        """Signed margin (N,): > 0 outside (how far, in joint units for intervals, in |g| − ε
        otherwise), ≤ 0 inside."""
        Q2, _ = _batch(Q, self.n)
        if self.is_interval:
            x = Q2[:, self.joint]
            d = np.full(len(Q2), np.inf)
            for lo, hi in self.intervals:
                d = np.minimum(d, np.maximum(lo - x, x - hi))
            return d
        return np.abs(self.g(Q2)) - self.epsilon

    def to_dict(self) -> dict:
        d = {"name": self.name, "kind": self.kind, "expr": self.expr, "joints": list(self.joints),
             "width": self.width, "method": self.method, "detail": self.detail}
        if self.is_interval:
            d["intervals"] = [list(iv) for iv in self.intervals]
        else:
            d["epsilon"] = self.epsilon
        return d

    @classmethod
    def from_dict(cls, d: dict, n: int, where: str = "windows") -> "Window":
        """A window from its JSON form (:meth:`to_dict`), validated: ``expr`` is parsed with the safe
        grammar of :mod:`kin.singular.expression` (never evaluated as Python); the width, ε and the
        interval bounds must be finite, ε and the width ≥ 0, every interval [lo, hi] with lo ≤ hi."""
        if not isinstance(d, dict):
            raise WindowError(f"{where}: a window entry must be a JSON object, got {type(d).__name__}")
        need = ("name", "kind", "expr", "joints", "width", "method")
        missing = [k for k in need if k not in d] + ([] if "intervals" in d or "epsilon" in d else ["epsilon"])
        if missing:
            raise WindowError(f"{where}: window entry lacks {missing[0]}; needs name, kind, expr, joints, width, "
                              "method and intervals or epsilon")
        name = d["name"]
        label = f"{where}: window {name!r}"
        for k in ("name", "kind", "expr", "method"):
            if not isinstance(d[k], str):
                raise WindowError(f"{label}: {k} must be a string, got {type(d[k]).__name__}")
        if d["method"] not in METHODS:
            raise WindowError(f"{label}: method {d['method']!r} unknown; allowed: {', '.join(METHODS)}")
        joints = d["joints"]
        if (not isinstance(joints, list) or not joints
                or not all(is_count(j) and 1 <= j <= n for j in joints)):
            raise WindowError(f"{label}: joints must be a non-empty list of joint numbers 1…{n}, got {joints!r}")

        def number(v, what: str) -> float:
            if not is_real(v) or not math.isfinite(v):
                raise WindowError(f"{label}: {what} must be a finite number, got {v!r}")
            return float(v)

        width = number(d["width"], "width")
        if width < 0:
            raise WindowError(f"{label}: width {width} must be ≥ 0 (rad or m)")
        try:
            tree = parse_tree(d["expr"], n, f"{label}: expr")
        except ExpressionError as e:
            raise WindowError(str(e)) from None
        intervals = epsilon = None
        if "intervals" in d and d["intervals"] is not None:
            ivs = d["intervals"]
            if not isinstance(ivs, list) or not all(isinstance(iv, list) and len(iv) == 2 for iv in ivs):
                raise WindowError(f"{label}: intervals must be a list of [lo, hi] pairs")
            if len(joints) != 1:
                raise WindowError(f"{label}: an interval window names exactly one joint, got {joints}")
            intervals = []
            for k, (lo, hi) in enumerate(ivs):
                lo, hi = number(lo, f"intervals[{k}][0]"), number(hi, f"intervals[{k}][1]")
                if lo > hi:
                    raise WindowError(f"{label}: intervals[{k}] = [{lo}, {hi}] is reversed; write [lo, hi]")
                intervals.append((lo, hi))
        else:
            epsilon = number(d.get("epsilon"), "epsilon")
            if epsilon < 0:
                raise WindowError(f"{label}: epsilon {epsilon} must be ≥ 0")
        detail = d.get("detail", {})
        if not isinstance(detail, dict):
            raise WindowError(f"{label}: detail must be a JSON object")
        return cls(name=name, kind=d["kind"], expr=d["expr"], joints=tuple(joints), width=width,
                   method=d["method"], n=n, intervals=intervals, epsilon=epsilon, detail=dict(detail), _tree=tree)


def robot_key(robot) -> str:
    """Hash of everything a robot's windows depend on: its chain's frozen DH table, joint types,
    convention, base, tool, limits and units, and its task rows (not its name)."""
    chain = robot.chain.frozen()
    content = {"convention": chain.convention, "types": list(chain.joint_types),
               "dh": [[repr(float(x)) for x in row] for row in chain.dh_table()],
               "base": [repr(float(x)) for x in chain.base.matrix.ravel()],
               "tool": [repr(float(x)) for x in chain.tool.matrix.ravel()],
               "limits": [[repr(float(lo)), repr(float(hi))] for lo, hi in zip(chain.lower, chain.upper)],
               "units": [repr(float(chain.angle_scale)), repr(float(chain.length_scale))],
               "rows": [int(r) for r in robot.task_rows]}
    return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()[:32]


@dataclass
class WindowSet:
    """All windows of one robot; membership is the union.  ``robot_key`` (:func:`robot_key`) names
    the robot's content when known, so that windows are never applied to another robot."""

    robot: str
    n: int
    windows: list[WindowBase]
    robot_key: str | None = None

    def check_robot(self, robot, what: str = "windows") -> None:
        """Raise :class:`WindowError` unless these windows were built for ``robot``: the same content
        (when the set records it) or else the same name, and the same number of joints."""
        if self.n != robot.n:
            raise WindowError(f"{what} are for a {self.n}-joint robot ({self.robot!r}); {robot.name} has "
                              f"{robot.n} joints")
        if self.robot_key is not None:
            if self.robot_key != robot_key(robot):
                raise WindowError(f"{what} were built for another robot ({self.robot!r}: other DH values, limits, "
                                  f"units or task rows than {robot.name!r}); build them for this robot")
        elif self.robot != robot.name:
            raise WindowError(f"{what} are of {self.robot!r}, not of {robot.name!r}; build them for this robot")

    def membership(self, Q) -> np.ndarray:
        """(N, k) boolean: configuration i inside window j."""
        Q2, _ = _batch(Q, self.n)
        if not self.windows:
            return np.zeros((len(Q2), 0), bool)
        return np.stack([w.contains(Q2) for w in self.windows], axis=1)

    def which(self, Q) -> np.ndarray:
        """(N,) index of the first window each configuration is in, −1 when in none."""
        M = self.membership(Q)
        if M.shape[1] == 0:
            return np.full(len(M), -1)
        return np.where(M.any(axis=1), M.argmax(axis=1), -1)

    def contains(self, Q) -> np.ndarray | bool:
        """True where a configuration is inside any window."""
        Q2, single = _batch(Q, self.n)
        inside = self.membership(Q2).any(axis=1)
        return bool(inside[0]) if single else inside

    def to_dict(self) -> dict:
        d = {"robot": self.robot, "n": self.n, "units": "SI (rad, m)"}
        if self.robot_key is not None:
            d["robot_key"] = self.robot_key
        return {**d, "windows": [w.to_dict() for w in self.windows]}

    def save(self, path: str | Path) -> Path:
        """Write JSON with :func:`kin.output.write_output` (atomic; never replaces anything but a
        regular file; missing parent directories are created)."""
        return write_output(path, json.dumps(self.to_dict(), indent=2, allow_nan=False) + "\n")

    @classmethod
    def load(cls, path: str | Path) -> "WindowSet":
        """Read a windows JSON file (:meth:`save`), validating every entry (:meth:`Window.from_dict`)."""
        path = Path(path)
        try:
            d = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise WindowError(f"{path}: no such windows file") from None
        except (OSError, UnicodeDecodeError, ValueError, RecursionError) as e:
            why = str(e).splitlines()[0] if str(e) else type(e).__name__
            raise WindowError(f"{path}: not a readable JSON windows file ({why})") from None
        return cls.from_dict(d, str(path))

    @classmethod
    def from_dict(cls, d, where: str = "windows") -> "WindowSet":
        """A WindowSet from its JSON form (:meth:`to_dict`), every entry validated."""
        path = where
        if not isinstance(d, dict) or not isinstance(d.get("windows"), list):
            raise WindowError(f"{path}: needs fields robot, n (integer) and windows (list)")
        n = d.get("n")
        if not is_count(n) or not 1 <= n <= MAX_JOINTS:
            raise WindowError(f"{path}: n must be the robot's number of joints, an integer 1…{MAX_JOINTS}, got {n!r}")
        robot = d.get("robot", "")
        if not isinstance(robot, str):
            raise WindowError(f"{path}: robot must be a string")
        key = d.get("robot_key")
        if key is not None and not (isinstance(key, str) and re.fullmatch(r"[0-9a-f]{32}", key)):
            raise WindowError(f"{path}: robot_key must be 32 hexadecimal digits, got {key!r}")
        return cls(robot=robot, n=n, robot_key=key,
                   windows=[(PointSetWindow if is_point_set_entry(w) else Window).from_dict(w, n, str(path))
                            for w in d["windows"]])
