"""Keep-out boxes as a work cell: :func:`cell_from_keep_out`.

A keep-out box (:class:`planning.ompl.validity.KeepOutBox`, from ``rmt plan --keep-out`` files) is an
axis-aligned box in the robot's base frame that the tool point (and, with ``frames = "all"``, every
joint-frame origin) must stay out of.  As a cell obstacle it becomes a box that the whole robot — its
capsules and the tool's — must stay clear of: stricter than the tool point alone, never weaker.
The cell places the robot at its origin (``base`` = identity), so the boxes keep their coordinates.
"""
from __future__ import annotations

import numpy as np

from kin.geometry import Obstacle, Shape
from planning.cell.model import Cell
from planning.errors import CellError

__all__ = ["cell_from_keep_out"]


def cell_from_keep_out(boxes, name: str = "keep-out", path=None) -> Cell:
    """A :class:`Cell` with one box obstacle per keep-out box (named ``box 1``, ``box 2``, …)."""
    obstacles = []
    for k, b in enumerate(boxes, 1):
        lo = np.asarray(b.lower, dtype=float)
        hi = np.asarray(b.upper, dtype=float)
        if lo.shape != (3,) or hi.shape != (3,) or not np.all(np.isfinite(lo) & np.isfinite(hi)) or not np.all(lo < hi):
            raise CellError(f"{name}: box {k}: lower {tuple(lo)} must be below upper {tuple(hi)} in x, y and z")
        pose = np.eye(4)
        pose[:3, 3] = 0.5 * (lo + hi)
        obstacles.append(Obstacle(f"box {k}", (Shape("box", tuple(0.5 * (hi - lo)), pose),), kind="box"))
    return Cell(name, tuple(obstacles), path=path)
