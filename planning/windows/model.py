"""The window values: :class:`Window` (one factor's neighbourhood: intervals of one joint or the
predicate |g(q)| ≤ ε) and :class:`WindowSet` (all of a robot's windows: batch membership, JSON).
See :mod:`planning.windows` for what a window is."""
from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
import sympy as sp


from planning.errors import WindowError
from planning.windows.sampled import PointSetWindow, is_point_set_entry

METHODS = ("margin", "sigma_min", "manipulability", "learned")


@dataclass
class Window:
    """One singular window (SI units).

    ``intervals`` (single-joint factor): list of (lo, hi) on joint ``joints[0]`` (1-based);
    ``epsilon`` (other factors): |g(q)| ≤ ε with g = ``expr`` in q1…qn.
    """

    name: str
    kind: str
    expr: str
    joints: tuple[int, ...]
    width: float
    method: str
    n: int
    intervals: list[tuple[float, float]] | None = None
    epsilon: float | None = None
    detail: dict = field(default_factory=dict)
    _g: Callable | None = field(default=None, repr=False, compare=False)

    @property
    def is_interval(self) -> bool:
        return self.intervals is not None

    @property
    def joint(self) -> int | None:
        """0-based joint of an interval window."""
        return self.joints[0] - 1 if self.is_interval else None

    def g(self, Q: np.ndarray) -> np.ndarray:
        """The factor at a batch (N, n) → (N,)."""
        if self._g is None:
            q = sp.symbols(f"q1:{self.n + 1}", real=True)
            expr = sp.sympify(self.expr, locals={f"q{i + 1}": q[i] for i in range(self.n)})
            f = sp.lambdify([q], expr, modules="numpy")
            self._g = lambda Q: np.broadcast_to(np.asarray(f(Q.T), dtype=float), (Q.shape[0],))
        return self._g(Q)

    def contains(self, Q) -> np.ndarray:
        """Boolean (N,) — or a bool for one configuration — True inside the window."""
        arr = np.asarray(Q, dtype=float)
        single = arr.ndim == 1
        Q2 = arr.reshape(-1, self.n)
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
        Q2 = np.asarray(Q, dtype=float).reshape(-1, self.n)
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
        try:
            ivs = d.get("intervals")
            w = cls(name=str(d["name"]), kind=str(d["kind"]), expr=str(d["expr"]),
                    joints=tuple(int(j) for j in d["joints"]), width=float(d["width"]), method=str(d["method"]),
                    n=n, intervals=None if ivs is None else [(float(a), float(b)) for a, b in ivs],
                    epsilon=None if ivs is not None else float(d["epsilon"]), detail=dict(d.get("detail", {})))
        except (KeyError, TypeError, ValueError) as e:
            raise WindowError(f"{where}: window entry is incomplete or malformed ({e}); needs name, kind, expr, "
                              "joints, width, method and intervals or epsilon") from None
        if not all(1 <= j <= n for j in w.joints):
            raise WindowError(f"{where}: window {w.name!r} names joints {w.joints} of a {n}-joint robot")
        return w


@dataclass
class WindowSet:
    """All windows of one robot; membership is the union."""

    robot: str
    n: int
    windows: list[Window | PointSetWindow]

    def membership(self, Q) -> np.ndarray:
        """(N, k) boolean: configuration i inside window j."""
        Q2 = np.asarray(Q, dtype=float).reshape(-1, self.n)
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
        arr = np.asarray(Q, dtype=float)
        inside = self.membership(arr).any(axis=1)
        return bool(inside[0]) if arr.ndim == 1 else inside

    def to_dict(self) -> dict:
        return {"robot": self.robot, "n": self.n, "units": "SI (rad, m)",
                "windows": [w.to_dict() for w in self.windows]}

    def save(self, path: str | Path) -> Path:
        """Write JSON atomically."""
        path = Path(path)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(self.to_dict(), indent=2) + "\n", encoding="utf-8")
        tmp.replace(path)
        return path

    @classmethod
    def load(cls, path: str | Path) -> "WindowSet":
        path = Path(path)
        try:
            d = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise WindowError(f"{path}: no such windows file") from None
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
            raise WindowError(f"{path}: not a readable JSON windows file ({e})") from None
        if not isinstance(d, dict) or not isinstance(d.get("windows"), list) or not isinstance(d.get("n"), int):
            raise WindowError(f"{path}: needs fields robot, n (integer) and windows (list)")
        return cls(robot=str(d.get("robot", "")), n=d["n"],
                   windows=[(PointSetWindow if is_point_set_entry(w) else Window).from_dict(w, d["n"], str(path))
                            for w in d["windows"]])
