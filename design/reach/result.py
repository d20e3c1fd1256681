"""The result of a reach study (:func:`design.reach.reach_study`): per target the verdict, the score
and its terms, the reason a target is missed and the configuration; its summary, rows, JSON and back."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from design.reach.score import ScoreWeights
from design.reach.settings import ReachSettings
from design.task.model import TaskError

__all__ = ["ReachStudy", "REASONS"]

#: the reasons a target is not reached, in the order of the stages
REASONS = ("out_of_reach", "joint_limits", "collision", "window", "dexterity")
_STAGE_NAMES = REASONS + ("reached",)


@dataclass
class ReachStudy:
    """The result of :func:`reach_study`.  Arrays are per target (N,) unless stated; SI.

    ``positions`` (N, 3) cell frame; ``placement`` 4×4 (the robot's base placement in the cell);
    ``reached``; ``score`` (0 where unreached); ``dexterity``, ``clearance`` (m; NaN without a cell),
    ``limit_margin``: the terms at the best solution (NaN where unreached); ``q`` (N, n) the best
    solution (the least failing one where unreached); ``reason``: "reached" or one of
    :data:`REASONS`; ``detail``: words for the reason (the colliding pair); ``obstacle``: the object
    hit ('' unless collision; a robot body's name for a self-collision); ``support`` starts reaching.
    """

    robot: str
    positions: np.ndarray
    placement: np.ndarray
    reached: np.ndarray
    score: np.ndarray
    dexterity: np.ndarray
    clearance: np.ndarray
    limit_margin: np.ndarray
    q: np.ndarray
    reason: np.ndarray
    detail: np.ndarray
    obstacle: np.ndarray
    support: np.ndarray
    settings: ReachSettings
    weights: ScoreWeights
    dexterity_ref: float
    cell: str = ""
    orientation: str = "free"
    required_clearance: float = 0.0
    windows: int = 0
    notes: list[str] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.reached)

    @property
    def coverage(self) -> float:
        """Reached share of the targets (0..1)."""
        return float(self.reached.mean())

    @property
    def mean_score(self) -> float:
        """Mean score over all targets (unreached count 0), in [0, 1]."""
        return float(self.score.mean())

    @property
    def value(self) -> float:
        """Reached targets plus the mean score: coverage first, then score (placement objective)."""
        return float(self.reached.sum()) + self.mean_score

    @property
    def fragile(self) -> np.ndarray:
        """Targets reached from a single start (may flip with other study settings)."""
        return self.reached & (self.support == 1)

    def reason_counts(self) -> dict[str, int]:
        return {r: int(np.sum(self.reason == r)) for r in _STAGE_NAMES if np.any(self.reason == r)}

    def obstacle_counts(self) -> dict[str, int]:
        names = [o for o in self.obstacle if o]
        return {str(o): names.count(o) for o in sorted(set(names))}

    def summary(self) -> dict:
        """The headline numbers (no per-target arrays)."""
        from kin.transforms import matrix_to_rpy
        return {"robot": self.robot, "cell": self.cell, "targets": len(self),
                "coverage_percent": 100 * self.coverage, "reached": int(self.reached.sum()),
                "mean_score": self.mean_score,
                "mean_score_reached": float(self.score[self.reached].mean()) if self.reached.any() else 0.0,
                "placement": {"xyz": [float(v) for v in self.placement[:3, 3]],
                              "rpy": [float(v) for v in matrix_to_rpy(self.placement[:3, :3])]},
                "reasons": self.reason_counts(), "collisions_by_object": self.obstacle_counts(),
                "fragile": int(self.fragile.sum()), "orientation": self.orientation,
                "required_clearance_m": self.required_clearance, "windows": self.windows,
                "dexterity_ref": self.dexterity_ref, "weights": self.weights.to_dict(),
                "settings": dataclasses.asdict(self.settings), "notes": list(self.notes)}

    def rows(self) -> list[dict]:
        """One row per target (for CSV and JSON): position, verdict, score and its terms, reason."""
        out = []
        for i in range(len(self)):
            f = lambda a: None if not np.isfinite(a[i]) else float(a[i])
            out.append({"target": i, "x": float(self.positions[i, 0]), "y": float(self.positions[i, 1]),
                        "z": float(self.positions[i, 2]), "reached": bool(self.reached[i]),
                        "score": float(self.score[i]), "dexterity": f(self.dexterity),
                        "clearance_m": f(self.clearance), "limit_margin": f(self.limit_margin),
                        "reason": str(self.reason[i]), "obstacle": str(self.obstacle[i]),
                        "detail": str(self.detail[i]), "support": int(self.support[i]),
                        "q": [float(v) for v in self.q[i]]})
        return out

    def to_dict(self) -> dict:
        return {**self.summary(), "per_target": self.rows()}

    @classmethod
    def from_dict(cls, d: dict, where: str = "reach study") -> "ReachStudy":
        """A study back from :meth:`to_dict` (e.g. ``rmt reach --json`` output), for comparisons.
        Every field is checked; a bad one raises :class:`TaskError` naming ``where`` and the field."""
        from kin.transforms import make_transform, rpy_to_matrix

        def fail(field: str, msg: str):
            return TaskError(msg, where, field)

        if not isinstance(d, dict):
            raise fail("", "must be a JSON object (the output of rmt reach --json)")
        rows = d.get("per_target")
        if not isinstance(rows, list) or not rows:
            raise fail("per_target", "missing or empty: write the study with rmt reach --json")
        try:
            pl = d["placement"]
            xyz, rpy = (np.array([float(v) for v in pl[k]]) for k in ("xyz", "rpy"))
            if xyz.shape != (3,) or rpy.shape != (3,) or not np.all(np.isfinite(np.r_[xyz, rpy])):
                raise ValueError
        except (KeyError, TypeError, ValueError):
            raise fail("placement", "must hold xyz and rpy, three finite numbers each") from None
        cols: dict[str, list] = {k: [] for k in ("pos", "reached", "score", "reason", "obstacle", "support", "q")}
        for i, r in enumerate(rows):
            try:
                pos = [float(r[k]) for k in ("x", "y", "z")]
                sc = float(r["score"])
                reason = str(r["reason"])
                if not (np.all(np.isfinite(pos)) and 0.0 <= sc <= 1.0) or reason not in _STAGE_NAMES:
                    raise ValueError
                if not isinstance(r["reached"], bool) or r["reached"] != (reason == "reached"):
                    raise ValueError
                q = [float(v) for v in r.get("q", [])]
            except (KeyError, TypeError, ValueError):
                raise fail(f"per_target[{i}]", "needs finite x, y, z, reached (true/false, agreeing with "
                                                f"reason), score in [0, 1] and reason in "
                                                f"{', '.join(_STAGE_NAMES)}") from None
            cols["pos"].append(pos)
            cols["reached"].append(r["reached"])
            cols["score"].append(sc)
            cols["reason"].append(reason)
            cols["obstacle"].append(str(r.get("obstacle", "")))
            cols["support"].append(int(r.get("support", 0)) if isinstance(r.get("support", 0), int) else 0)
            cols["q"].append(q)
        N = len(rows)
        nq = {len(q) for q in cols["q"]}
        Q = np.array(cols["q"], float) if len(nq) == 1 else np.zeros((N, 0))
        nan = np.full(N, np.nan)
        return cls(robot=str(d.get("robot", "")), positions=np.array(cols["pos"], float),
                   placement=make_transform(rpy_to_matrix(rpy), xyz), reached=np.array(cols["reached"], bool),
                   score=np.array(cols["score"], float), dexterity=nan.copy(), clearance=nan.copy(),
                   limit_margin=nan.copy(), q=Q, reason=np.array(cols["reason"]),
                   detail=np.array([""] * N), obstacle=np.array(cols["obstacle"]),
                   support=np.array(cols["support"], int), settings=ReachSettings(), weights=ScoreWeights(),
                   dexterity_ref=float("nan"), cell=str(d.get("cell", "")), orientation=str(d.get("orientation", "")),
                   notes=[f"read from {where}"])
