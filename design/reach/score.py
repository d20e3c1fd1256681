"""How well a reached target is reached: the score of a reach study.

The score of one IK solution is a weighted mean of three terms, each in [0, 1]:

* **dexterity** — σ_min of the translational Jacobian rows (m/rad), or the manipulability of the
  robot's task rows, divided by a reference and capped at 1.  The reference is ``dexterity_ref``
  (SI) or, when None, the best value the robot reaches over the study's fixed sample of
  configurations (so 1 means "as dexterous as this robot gets");
* **clearance** — the clearance to the cell and to the robot itself (m) divided by
  ``clearance_ref`` (default 50 mm), clipped to [0, 1];
* **joint-limit margin** — over the joints, the smallest distance to a limit as a share of half
  the joint's range: 1 in the middle of every range, 0 at a limit.

``score = (w_d·dexterity + w_c·clearance + w_l·limits) / (w_d + w_c + w_l)``; the defaults are
0.5, 0.25, 0.25.  A term the study cannot measure (clearance without a work cell) is left out and
the others' weights renormalised.  An unreached target scores 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from design.task.model import TaskError

__all__ = ["ScoreWeights", "limit_margin", "MEASURES"]

#: dexterity measures a score can use
MEASURES = ("sigma_min", "manipulability")


def _nonneg(v, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v) or v < 0:
        raise TaskError(f"{what} = {v!r} must be a finite number ≥ 0")
    return float(v)


@dataclass(frozen=True)
class ScoreWeights:
    """Weights and references of the reach score (see the module text).  SI units."""

    dexterity: float = 0.5
    clearance: float = 0.25
    limits: float = 0.25
    measure: str = "sigma_min"
    dexterity_ref: float | None = None
    clearance_ref: float = 0.05

    def __post_init__(self):
        for name in ("dexterity", "clearance", "limits"):
            object.__setattr__(self, name, _nonneg(getattr(self, name), f"score weight {name}"))
        if self.dexterity + self.clearance + self.limits <= 0:
            raise TaskError("score weights are all 0; give at least one positive weight")
        if self.measure not in MEASURES:
            raise TaskError(f"score measure {self.measure!r} unknown; allowed: {', '.join(MEASURES)}")
        if self.dexterity_ref is not None:
            v = _nonneg(self.dexterity_ref, "dexterity reference")
            if v == 0:
                raise TaskError("dexterity reference must be > 0 (SI), or None for the robot's best")
            object.__setattr__(self, "dexterity_ref", v)
        ref = _nonneg(self.clearance_ref, "clearance reference (m)")
        if ref == 0:
            raise TaskError("clearance reference must be > 0 m")
        object.__setattr__(self, "clearance_ref", ref)

    def combine(self, dexterity: np.ndarray, clearance: np.ndarray | None, limits: np.ndarray) -> np.ndarray:
        """The score (N,) from the three terms (each (N,) in [0, 1]; ``clearance`` None: not measured)."""
        wc = self.clearance if clearance is not None else 0.0
        total = self.dexterity + wc + self.limits
        if total <= 0:        # only a clearance weight, and no cell: the score is the limit margin
            return np.asarray(limits, float)
        s = self.dexterity * dexterity + self.limits * limits
        if clearance is not None:
            s = s + wc * clearance
        return s / total

    def to_dict(self) -> dict:
        return {"dexterity": self.dexterity, "clearance": self.clearance, "limits": self.limits,
                "measure": self.measure, "dexterity_ref": self.dexterity_ref, "clearance_ref_m": self.clearance_ref}


def limit_margin(Q: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The joint-limit term (N,): min over the joints of min(q − lo, hi − q) / ((hi − lo) / 2), in [0, 1]."""
    half = 0.5 * (upper - lower)
    m = np.minimum(Q - lower, upper - Q) / np.where(half > 0, half, 1.0)
    return np.clip(m.min(axis=1), 0.0, 1.0)
