"""MoveIt planning scenes as work cells (``rmt import-scene``, docs/cells.md "MoveIt planning scenes").

* :mod:`planning.cell.moveit.scene` — :class:`Scene`, the world of a planning scene, and the checks
  both readers share;
* :mod:`planning.cell.moveit.yaml_scene` — a ``moveit_msgs/PlanningScene`` in YAML (``rostopic echo``,
  robowflex, MotionBenchMaker);
* :mod:`planning.cell.moveit.text_scene` — MoveIt's ``.scene`` text (RViz's "Export scene"), both
  versions;
* :mod:`planning.cell.moveit.cell_text` — a scene as the text of a cell file.

:func:`load_scene` reads a file (bounded before it is parsed, the format by its suffix);
:func:`scene_cell` gives the cell file's text and the :class:`planning.cell.Cell` it reads as — every
import is read back by the cell reader before anyone writes it.
"""
from __future__ import annotations

from pathlib import Path

from kin.files import FileReadError, read_text
from planning.cell.model import Cell, is_body_like
from planning.cell.moveit.cell_text import cell_name, cell_text
from planning.cell.moveit.scene import MAX_SCENE_BYTES, Scene, SceneObject, SceneShape
from planning.cell.moveit.text_scene import parse_scene_text
from planning.cell.moveit.yaml_scene import parse_scene_yaml
from planning.cell.reader import parse_cell
from planning.errors import CellError

__all__ = ["Scene", "SceneObject", "SceneShape", "SCENE_SUFFIXES", "load_scene", "parse_scene_text",
           "parse_scene_yaml", "scene_cell", "cell_text", "cell_name"]

#: the suffixes read, and as what
SCENE_SUFFIXES = {".yaml": "yaml", ".yml": "yaml", ".scene": "text"}


def load_scene(path: str | Path, frame: str | None = None) -> Scene:
    """The :class:`Scene` of a file: ``.yaml``/``.yml`` a PlanningScene in YAML, ``.scene`` MoveIt's
    text; at most :data:`MAX_SCENE_BYTES`, UTF-8.  ``frame``: the planning frame's name (YAML only;
    see :func:`parse_scene_yaml`)."""
    path = Path(path)
    kind = SCENE_SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise CellError(f"{path}: a MoveIt planning scene is a .scene text file (RViz's Export) or a PlanningScene "
                        f"in YAML (.yaml, .yml)")
    try:
        text = read_text(path, "scene file", MAX_SCENE_BYTES)
    except FileReadError as e:
        raise CellError(str(e)) from None
    if kind == "yaml":
        return parse_scene_yaml(text, str(path), frame)
    if frame is not None:
        raise CellError(f"{path}: a .scene file names no frames (its objects are in the planning frame); give no "
                        f"frame")
    return parse_scene_text(text, str(path))


def scene_cell(scene: Scene, where: str = "cell", name: str | None = None, robot_xyz=(0.0, 0.0, 0.0),
               robot_rpy=(0.0, 0.0, 0.0)) -> tuple[str, Cell]:
    """The cell file's text of ``scene`` (see :func:`cell_text`) and the :class:`Cell` the cell reader
    makes of it (``where`` names it in messages).  Obstacles named like every robot's bodies (``base``,
    ``tool``, ``link k``) are said in a comment of the file."""
    body_like = tuple(ob.name for ob in scene.objects if is_body_like(ob.name))
    text = cell_text(scene, name, robot_xyz, robot_rpy, body_like)
    return text, parse_cell(text, where)
