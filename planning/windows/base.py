"""What every singular window is: :class:`WindowBase`, the fields and the three operations that
planning, proofs, following and reports rely on, whatever the window's kind (intervals of one joint,
a predicate |g| ≤ ε, or a point set).  See :mod:`planning.windows` for what a window is."""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

__all__ = ["WindowBase"]


@dataclass
class WindowBase(ABC):
    """A window around one component of the singular set (SI units).

    ``name``: ``"<kind>: <expr>"``; ``kind``: the factor's kind (wrist, elbow, shoulder, …); ``expr``:
    the factor g (a label for a point-set window, which has no formula); ``joints``: the 1-based
    joints it involves; ``width``: its half-width (rad for revolute joints, m for prismatic ones);
    ``method``: where the width came from (:data:`planning.windows.METHODS`); ``n``: the robot's
    number of joints.
    """

    name: str
    kind: str
    expr: str
    joints: tuple[int, ...]
    width: float
    method: str
    n: int

    #: a point-set window (:class:`planning.windows.PointSetWindow`): known by samples (paths are proven
    #: clear of it as it is, by segment–point distances: :mod:`planning.certify.points`)
    is_point_set: ClassVar[bool] = False

    @property
    @abstractmethod
    def is_interval(self) -> bool:
        """True for a union of intervals of one joint (decided exactly along a straight segment)."""

    @abstractmethod
    def contains(self, Q) -> np.ndarray | bool:
        """Boolean (N,) for a batch (N, n), or a bool for one configuration: inside the window."""

    @abstractmethod
    def distance_out(self, Q) -> np.ndarray:
        """Signed margin (N,): > 0 outside, ≤ 0 inside (in joint units, or in |g| − ε)."""

    @abstractmethod
    def to_dict(self) -> dict:
        """The JSON form read back by the window's ``from_dict``."""
