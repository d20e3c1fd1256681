"""The frame of the tool poses a command takes (``rmt plan --goal-pose``, ``rmt ik --xyz/--rpy``): the
cell frame when ``--cell`` is given (where the cell's ``[robot] xyz/rpy`` places the robot — the frame
of the cell's obstacles and of ``reach`` and ``place`` targets), the robot's base frame otherwise;
``--frame base|cell`` says so explicitly.  Values are in the robot file's units either way."""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from kin.transforms import make_transform, rpy_to_matrix
from studies.cli.common import CliInputError, numbers, positions

__all__ = ["FRAMES", "frame_arg", "pose_from_args", "pose_frame"]

FRAMES = ("base", "cell")


def frame_arg(sp) -> None:
    sp.add_argument("--frame", choices=FRAMES,
                    help="frame of the tool pose: cell (the --cell file's frame; the default with --cell) or "
                         "base (the robot's base frame; the default without --cell)")


def pose_frame(args, what: str) -> str:
    """``"cell"`` or ``"base"`` from ``--frame`` and ``--cell``; ``--frame cell`` without a cell is refused."""
    frame = getattr(args, "frame", None)
    cell = getattr(args, "cell", None)
    if frame is None:
        return "cell" if cell is not None else "base"
    if frame == "cell" and cell is None:
        raise CliInputError(f"--frame cell: {what} in the cell frame needs --cell CELL (the cell that places "
                            "the robot)")
    return frame


def pose_from_args(chain, xyz: Sequence[str], rpy: Sequence[str] | None, what: str) -> np.ndarray:
    """A tool pose (4×4, SI) from X Y Z (file length unit) and R P Y (file angle unit, fixed-axis
    roll-pitch-yaw, each within ±360° or the same in the file's unit); a position (3,) without R P Y."""
    p = positions(chain, xyz, what)
    if rpy is None:
        return p
    r = np.array(numbers(rpy, what)) * chain.angle_scale
    if not np.all(np.abs(r) <= 2 * math.pi + 1e-9):
        raise CliInputError(f"{what}: R P Y must be within ±{2 * math.pi / chain.angle_scale:g} {chain.angle_unit} "
                            "(the robot file's angle unit)")
    return make_transform(rpy_to_matrix(r), p)


def frame_name(frame: str, world) -> str:
    """How messages name the frame, e.g. ``cell frame of 'ur5e shelf cell'``."""
    if frame == "cell" and world is not None and world.name:
        return f"cell frame of {world.name!r}"
    return f"{frame} frame"
