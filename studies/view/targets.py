"""Reach results in ``rmt view --reach OUT_DIR``: the targets of a saved reach study (``rmt reach --out
OUT_DIR`` writes ``OUT_DIR/TASK/reach.json``) as coloured points — by score (reached: red 0 → green 1;
missed: grey) or by the reason they are missed (the colours of the reach plots,
:data:`studies.plots.reach.REASON_COLOURS`) — each with the configuration the study found for it."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from studies.view.errors import ViewInputError

__all__ = ["reach_file", "load_reach", "target_colours", "target_label", "MISSED_GREY"]

#: the colour of a missed target when coloured by score
MISSED_GREY = (150, 150, 150)
#: the largest reach study read (as rmt reach-compare)
MAX_STUDY_BYTES = 200 * 2**20


def reach_file(arg: str) -> Path:
    """``--reach`` → its reach.json: the file itself, ``DIR/reach.json``, or ``DIR/TASK/reach.json`` when
    DIR holds exactly one study; else one line naming what was looked for."""
    p = Path(arg)
    if p.is_file():
        return p
    if not p.is_dir():
        raise ViewInputError(f"--reach {arg}: no such directory (give the --out directory of rmt reach, or its "
                            "reach.json)")
    if (p / "reach.json").is_file():
        return p / "reach.json"
    found = sorted(p.glob("*/reach.json"))
    if len(found) == 1:
        return found[0]
    if not found:
        raise ViewInputError(f"--reach {arg}: no reach.json in it or in a folder of it (rmt reach --out DIR writes "
                            "DIR/TASK/reach.json)")
    raise ViewInputError(f"--reach {arg}: {len(found)} studies in it ({', '.join(f.parent.name for f in found)}); "
                        "give one of their folders")


def load_reach(arg: str, robot):
    """The :class:`design.reach.ReachStudy` of ``--reach`` for ``robot``: its configurations must have
    the robot's joint count and its robot the same name."""
    from design.reach import ReachStudy
    from design.task.model import TaskError
    from kin.files import FileReadError, read_json
    path = reach_file(arg)
    try:
        study = ReachStudy.from_dict(read_json(path, "reach study", MAX_STUDY_BYTES), str(path))
    except (FileReadError, TaskError) as e:
        raise ViewInputError(f"--reach: {e}") from None
    if study.robot and study.robot != robot.name:
        raise ViewInputError(f"--reach {path}: a study of robot {study.robot!r}, not {robot.name!r}")
    if study.q.shape != (len(study), robot.n) or not np.all(np.isfinite(study.q)):
        raise ViewInputError(f"--reach {path}: its targets' configurations are not {robot.n} finite joint values each "
                            f"({robot.name})")
    return study


def _hex(colour: str) -> tuple[int, int, int]:
    return tuple(int(colour[i:i + 2], 16) for i in (1, 3, 5))


def target_colours(study, by: str = "score") -> np.ndarray:
    """(N, 3) uint8 colours of the targets: ``by`` "score" (reached: red at 0 → yellow → green at 1,
    missed grey) or "reason" (one colour per verdict)."""
    if by == "reason":
        from studies.plots.reach import REASON_COLOURS
        return np.array([_hex(REASON_COLOURS.get(str(r), "#000000")) for r in study.reason], np.uint8)
    s = np.clip(np.asarray(study.score, float), 0.0, 1.0)
    red = np.where(s < 0.5, 1.0, 2 * (1 - s))
    green = np.where(s < 0.5, 2 * s, 1.0)
    C = np.column_stack([red, green, np.zeros_like(s)]) * 220
    C[~np.asarray(study.reached, bool)] = MISSED_GREY
    return np.round(C).astype(np.uint8)


def target_label(study, i: int, length_scale: float, length_unit: str) -> str:
    """One line for target ``i``: its position (robot file length unit), verdict and score."""
    p = " ".join(f"{v / length_scale:.5g}" for v in study.positions[i])
    verdict = "reached" if study.reached[i] else f"missed: {str(study.reason[i]).replace('_', ' ')}"
    return f"target {i} ({p}) {length_unit}: {verdict}, score {float(study.score[i]):.3f}"
