"""A :class:`planning.cell.moveit.scene.Scene` as the text of a cell file: :func:`cell_text`.

The cell is in metres and degrees, in the scene's planning frame; each object becomes one obstacle
named by its id:

* an object of one shape → an obstacle of that type (``box``, ``sphere``, ``cylinder``, ``cone``,
  ``mesh``) placed at the object's pose · the shape's pose;
* an object of several shapes → a ``compound`` obstacle at the object's pose with one
  ``[[obstacle.part]]`` per shape, at the shape's pose;
* meshes are written in the cell (``vertices``, ``triangles``): the cell is one file.

Numbers are written as Python's shortest round-trip ``repr``; rotations as roll-pitch-yaw fitted so
that R = Rz(yaw)·Ry(pitch)·Rx(roll) gives back the scene's rotation to rounding, gimbal lock included
(:func:`rpy_degrees`).  Strings are escaped for TOML; nothing of the scene reaches the text unescaped.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from kin.transforms import rot_y, rot_z
from planning.cell.moveit.scene import Scene, SceneObject, SceneShape
from planning.cell.reader import MAX_NAME

__all__ = ["cell_text", "rpy_degrees", "toml_string", "cell_name"]


def toml_string(s: str) -> str:
    """``s`` as a TOML basic string: quotes, backslashes and every character that is not printable
    (controls, DEL, line separators) escaped."""
    out = ['"']
    for c in s:
        if c in '"\\':
            out.append("\\" + c)
        elif c.isprintable() and not 0xD800 <= ord(c) <= 0xDFFF:
            out.append(c)
        elif ord(c) <= 0xFFFF and not 0xD800 <= ord(c) <= 0xDFFF:
            out.append(f"\\u{ord(c):04X}")
        elif ord(c) > 0xFFFF:
            out.append(f"\\U{ord(c):08X}")
        else:
            out.append("\\uFFFD")                    # a lone surrogate is no character: the replacement one
    return "".join(out) + '"'


def _comment(s: str) -> str:
    """Text safe inside a comment line: printable characters only."""
    return "".join(c if c.isprintable() else "?" for c in s)[:200]


def _num(x: float) -> str:
    x = float(x)
    return "0.0" if x == 0 else repr(x)


def _vec(v) -> str:
    return "[" + ", ".join(_num(x) for x in v) + "]"


def rpy_degrees(R: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (degrees) with Rz(yaw)·Ry(pitch)·Rx(roll) = R to rounding everywhere: pitch from
    the well-conditioned column, yaw from the first column (any value at gimbal lock), roll fitted to
    what is left (Ry(pitch)ᵀ·Rz(yaw)ᵀ·R, a rotation about x)."""
    R = np.asarray(R, dtype=float)
    cp = math.hypot(R[0, 0], R[1, 0])
    pitch = math.atan2(-R[2, 0], cp)
    yaw = math.atan2(R[1, 0], R[0, 0]) if cp > 0 else 0.0
    M = rot_y(pitch).T @ rot_z(yaw).T @ R
    return np.degrees([math.atan2(M[2, 1], M[1, 1]), pitch, yaw])


def _pose_lines(T: np.ndarray) -> list[str]:
    out = []
    if np.any(T[:3, 3] != 0):
        out.append(f"xyz = {_vec(T[:3, 3])}")
    if np.any(T[:3, :3] != np.eye(3)):
        out.append(f"rpy = {_vec(rpy_degrees(T[:3, :3]))}")
    return out


def _shape_lines(s: SceneShape) -> list[str]:
    lines = [f"type = {toml_string(s.kind)}"]
    if s.kind == "box":
        lines.append(f"size = {_vec(s.size)}")
    elif s.kind == "sphere":
        lines.append(f"radius = {_num(s.size[0])}")
    elif s.kind in ("cylinder", "cone"):
        lines += [f"radius = {_num(s.size[0])}", f"length = {_num(s.size[1])}"]
    else:
        lines.append("vertices = [\n" + "".join(f"  {_vec(v)},\n" for v in s.vertices) + "]")
        lines.append("triangles = [\n" + "".join(f"  [{int(a)}, {int(b)}, {int(c)}],\n" for a, b, c in s.triangles)
                     + "]")
    return lines


def _obstacle(ob: SceneObject) -> str:
    head = ["[[obstacle]]", f"name = {toml_string(ob.name)}"]
    if len(ob.shapes) == 1:
        s = ob.shapes[0]
        body = _shape_lines(s)
        return "\n".join(head + body[:1] + _pose_lines(ob.pose @ s.pose) + body[1:]) + "\n"
    parts = []
    for s in ob.shapes:
        body = _shape_lines(s)
        parts.append("\n".join(["[[obstacle.part]]"] + body[:1] + _pose_lines(s.pose) + body[1:]) + "\n")
    return "\n".join(head + ['type = "compound"'] + _pose_lines(ob.pose)) + "\n\n" + "\n".join(parts)


def cell_name(scene: Scene, name: str | None = None) -> str:
    """The cell's name: ``name``, else the scene's (when 1 to 100 printable characters and not MoveIt's
    "(noname)"), else the scene file's name without its suffix."""
    for candidate in (name, scene.name, Path(scene.source).stem, "scene"):
        if isinstance(candidate, str):
            c = " ".join(candidate.split())
            if c and len(c) <= MAX_NAME and c.isprintable() and c != "(noname)":
                return c
    return "scene"


def cell_text(scene: Scene, name: str | None = None, robot_xyz=(0.0, 0.0, 0.0), robot_rpy=(0.0, 0.0, 0.0),
              body_like: tuple[str, ...] = ()) -> str:
    """The cell file of ``scene`` (TOML text): named ``name`` (default :func:`cell_name`), the robot's
    base placement at ``robot_xyz`` (m) and ``robot_rpy`` (degrees) in the scene's planning frame;
    ``body_like``: obstacle names that are also a robot body's, said in a comment."""
    lines = [f"# Imported by rmt import-scene from {_comment(Path(scene.source).name)} ({scene.format}).",
             "# Lengths in m, angles in degrees, everything in the scene's planning frame (MoveIt's model frame,",
             "# the robot's root link); obstacles are named by MoveIt's object ids (docs/cells.md)."]
    if body_like:
        names = ", ".join(_comment(n) for n in body_like)
        lines.append(f"# Obstacles named like robot bodies ({names}): in [allow] pairs write obstacle:NAME "
                     "for the obstacle, body:NAME for the body.")
    lines += [f"name = {toml_string(cell_name(scene, name))}", 'length_unit = "m"', 'angle_unit = "deg"', "",
              "[robot]                       # where the robot's base placement stands in the planning frame",
              f"xyz = {_vec(robot_xyz)}", f"rpy = {_vec(robot_rpy)}", ""]
    return "\n".join(lines) + "\n" + "\n".join(_obstacle(ob) for ob in scene.objects)
