"""Two reach studies of the same targets side by side — two robots, two placements, two cells — as
REACH users compare set-ups: targets gained and lost, the score change, the reasons that changed."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from design.reach.result import ReachStudy
from design.task.model import TaskError

__all__ = ["ReachComparison", "compare_studies"]


@dataclass
class ReachComparison:
    """``a`` → ``b``: per target (N,) ``gained`` (reached by b only), ``lost`` (by a only), ``both``,
    ``score_change`` (b − a, unreached scoring 0); ``reasons``: (reason in a, reason in b) → count
    over the targets whose verdict or reason differs."""

    a: ReachStudy
    b: ReachStudy
    gained: np.ndarray
    lost: np.ndarray
    both: np.ndarray
    score_change: np.ndarray
    labels: tuple[str, str] = ("a", "b")

    def classes(self) -> np.ndarray:
        """Per target (N,) what changed: "gained", "lost", "both" (reached by both) or "neither"."""
        out = np.full(len(self.gained), "neither", dtype=object)
        out[self.both], out[self.gained], out[self.lost] = "both", "gained", "lost"
        return out.astype(str)

    @property
    def reasons(self) -> dict[tuple[str, str], int]:
        out: dict[tuple[str, str], int] = {}
        for ra, rb in zip(self.a.reason, self.b.reason):
            if ra != rb:
                out[(str(ra), str(rb))] = out.get((str(ra), str(rb)), 0) + 1
        return out

    def to_dict(self) -> dict:
        la, lb = self.labels
        return {"labels": [la, lb], "targets": int(len(self.gained)),
                "coverage_percent": {la: 100 * self.a.coverage, lb: 100 * self.b.coverage},
                "mean_score": {la: self.a.mean_score, lb: self.b.mean_score},
                "gained": [int(i) for i in np.flatnonzero(self.gained)],
                "lost": [int(i) for i in np.flatnonzero(self.lost)],
                "reached_by_both": int(self.both.sum()),
                "mean_score_change": float(self.score_change.mean()),
                "mean_score_change_both": float(self.score_change[self.both].mean()) if self.both.any() else 0.0,
                "reason_changes": [{"from": k[0], "to": k[1], "targets": v} for k, v in sorted(self.reasons.items())],
                "studies": {la: self.a.summary(), lb: self.b.summary()}}


def compare_studies(a: ReachStudy, b: ReachStudy, labels: tuple[str, str] = ("a", "b"),
                    tolerance: float = 1e-9) -> ReachComparison:
    """Compare two reach studies of the same targets (positions equal within ``tolerance`` m, cell
    frame); raises :class:`TaskError` when they are not the same targets."""
    if a.positions.shape != b.positions.shape or not np.allclose(a.positions, b.positions, atol=tolerance, rtol=0):
        raise TaskError(f"the two reach studies have different targets ({len(a)} and {len(b)} targets, or "
                        f"different positions); compare studies of the same task")
    return ReachComparison(a, b, gained=b.reached & ~a.reached, lost=a.reached & ~b.reached,
                           both=a.reached & b.reached, score_change=b.score - a.score,
                           labels=(str(labels[0]), str(labels[1])))
