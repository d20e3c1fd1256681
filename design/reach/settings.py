"""The effort of a reach study: IK starts per target, the Halton sample they are chosen from, rotations
about a free tool axis, iterations per IK run."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from design.task.model import TaskError

__all__ = ["ReachSettings"]


@dataclass(frozen=True)
class ReachSettings:
    """The effort of a reach study: ``starts`` IK starts per target and orientation variant (1–64),
    chosen among ``samples`` Halton configurations; ``spins`` rotations about a free tool axis;
    ``max_iter`` IK iterations per start."""

    starts: int = 8
    samples: int = 4096
    spins: int = 8
    max_iter: int = 200

    def __post_init__(self):
        for name, lo, hi in (("starts", 1, 64), ("samples", 16, 2_000_000), ("spins", 1, 72), ("max_iter", 1, 10_000)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= hi:
                raise TaskError(f"reach setting {name} = {v!r} must be an integer in [{lo}, {hi}]")
        if self.samples < self.starts:
            raise TaskError(f"reach setting samples = {self.samples} must be ≥ starts = {self.starts}")
