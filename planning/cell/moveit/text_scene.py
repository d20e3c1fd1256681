"""Reading MoveIt's ``.scene`` text files (RViz's "Export scene", ``PlanningScene::saveGeometryToStream``):
:func:`parse_scene_text`.

The format, as MoveIt writes and reads it (whitespace-separated tokens, one item per line)::

    my scene                      the scene's name (the whole first line)
    * table                       an object: "*" and its id (the rest of the line)
    0.5 0 0.4                     (MoveIt ≥ 1.1.10) the object's pose: x y z,
    0 0 0 1                       then a quaternion x y z w
    1                             the number of shapes, then per shape:
    box                           its type: box | sphere | cylinder | cone | mesh
    1.2 0.8 0.04                  box x y z (full edge lengths); sphere r; cylinder r length; cone r length;
                                  mesh "V T", V lines of x y z, T lines of vertex indices i j k (from 0)
    0 0 0                         the shape's pose (in the object's frame): x y z,
    0 0 0.0399643 0.999201        then a quaternion x y z w
    0 0 0 0                       its colour r g b a (MoveIt always writes it; read when present)
    0                             (MoveIt ≥ 1.1.10) the number of subframes, then per subframe a name and a pose
    .                             the end

The version is told as MoveIt tells it: when the line after the first ``*`` line has a space, objects
have poses and subframes (MoveIt ≥ 1.1.10, Noetic); else not (Melodic and before: shape poses are in
the planning frame).  Planes are refused (infinite); subframes and colours are read and left out.

Every token is checked as it is read: numbers against a decimal pattern (then ``float``; nothing is
evaluated), counts as digits and bounded before anything is allocated; an error names the object and
the line.
"""
from __future__ import annotations

import io
import re

import numpy as np

from planning.cell.mesh import MAX_TRIANGLES
from planning.cell.moveit.scene import (
    SHAPE_DIMENSIONS,
    Scene,
    SceneBuilder,
    SceneObject,
    SceneShape,
    mesh_arrays,
    number,
    object_name,
    pose_matrix,
    positive_sizes,
)
from planning.cell.obstacles import MAX_PARTS, MAX_VERTICES
from planning.errors import CellError

__all__ = ["parse_scene_text", "FORMAT_POSES", "FORMAT_NO_POSES"]

FORMAT_POSES = ".scene text (object poses: MoveIt ≥ 1.1.10, Noetic)"
FORMAT_NO_POSES = ".scene text (no object poses: MoveIt ≤ 1.1.9, Melodic)"
_COUNT = re.compile(r"^[0-9]{1,9}$")
_SIZES = {"box": ("x", "y", "z"), "sphere": ("radius",), "cylinder": ("radius", "length"), "cone": ("radius", "length")}


class _Cursor:
    """Tokens of the text, line by line (read lazily), with the line number of each."""

    def __init__(self, text: str, where: str):
        self.lines = io.StringIO(text)
        self.where = where
        self.lineno, self.raw, self.tokens, self.pos = 0, "", [], 0

    def _advance(self) -> bool:
        """Move to the next line with a token; False at the end of the text."""
        while self.pos >= len(self.tokens):
            line = self.lines.readline()
            if not line:
                return False
            self.lineno += 1
            self.raw, self.tokens, self.pos = line.rstrip("\r\n"), line.split(), 0
        return True

    def fail(self, label: str, msg: str) -> CellError:
        return CellError(f"{label}, line {self.lineno}: {msg}")

    def next(self, label: str, what: str) -> str:
        if not self._advance():
            raise CellError(f"{label}: the file ends where {what} should be (is it cut short? a scene ends with a "
                            f"'.' line)")
        tok = self.tokens[self.pos]
        self.pos += 1
        return tok

    def rest_of_line(self) -> str:
        """The current line after the marker just read (an object's id: "* table top" → " table top"),
        consumed."""
        marker = self.tokens[self.pos - 1]
        rest = self.raw[self.raw.find(marker) + len(marker):]
        self.pos = len(self.tokens)
        return rest

    def peek_rest(self) -> list[str]:
        """The tokens left on the current line, or on the next line with tokens (nothing consumed)."""
        return self.tokens[self.pos:] if self._advance() else []

    def numbers(self, n: int, label: str, what: str, unit: str = "m") -> list[float]:
        """``n`` finite numbers; ``what`` and ``unit`` name them in a message."""
        return [number(self.next(label, what), f"{label}, line {self.lineno}: {what}", unit) for _ in range(n)]

    def count(self, label: str, what: str, most: int) -> int:
        tok = self.next(label, what)
        if not _COUNT.match(tok):
            raise self.fail(label, f"{what}: expected a whole number, not {tok[:40]!r}")
        n = int(tok)
        if n > most:
            raise self.fail(label, f"{what}: {n}; at most {most}")
        return n

    def pose(self, label: str) -> np.ndarray:
        p = self.numbers(3, label, "a position x y z")
        q = self.numbers(4, label, "a quaternion x y z w", "a rotation")
        return pose_matrix(p, q, f"{label}, line {self.lineno}")


def _shape(cur: _Cursor, label: str) -> SceneShape:
    kind = cur.next(label, "a shape type")
    line = cur.lineno
    if kind == "plane":
        raise cur.fail(label, "a plane is infinite, not an obstacle of a cell; model it as a box")
    if kind not in SHAPE_DIMENSIONS:
        raise cur.fail(label, f"shape type {kind[:40]!r} unknown; allowed: box, sphere, cylinder, cone, mesh")
    vertices = triangles = None
    size: tuple[float, ...] = ()
    if kind in _SIZES:
        names = _SIZES[kind]
        values = cur.numbers(len(names), label, f"the {kind}'s {' '.join(names)}")
        size = positive_sizes(values, names, f"{label}, line {cur.lineno}: {kind}")
    else:
        nv = cur.count(label, "the mesh's vertex count", MAX_VERTICES)
        nt = cur.count(label, "the mesh's triangle count", MAX_TRIANGLES)
        vertices = [cur.numbers(3, label, "a vertex x y z") for _ in range(nv)]
        triangles = [[cur.count(label, "a vertex index", MAX_VERTICES) for _ in range(3)] for _ in range(nt)]
        vertices, triangles = mesh_arrays(vertices, triangles, f"{label}, line {line}: mesh")
    pose = cur.pose(label)
    rest = cur.peek_rest()
    if len(rest) == 4 and all(re.match(r"^[-+0-9.eE]+$", t) for t in rest):
        cur.numbers(4, label, "a colour r g b a", "0 to 1")
    return SceneShape(kind, size, pose, vertices, triangles)


def _format(text: str) -> bool:
    """Whether objects have poses: MoveIt's own test — the line after the first '*' line has a space."""
    m = re.search(r"^[ \t]*\*[^\n]*\n([^\n]*)", text, re.M)
    return m is not None and " " in m.group(1).strip()


def parse_scene_text(text: str, where: str = "scene") -> Scene:
    """The :class:`Scene` of a MoveIt ``.scene`` text; ``where`` names it in messages."""
    if "\x00" in text:
        raise CellError(f"{where}: not a text file (it holds NUL bytes)")
    poses = _format(text)
    first, _, body = text.partition("\n")
    cur = _Cursor(body, where)
    cur.lineno = 1
    builder = SceneBuilder(where)
    k = 0
    while True:
        tok = cur.next(where, "'*' (an object) or '.' (the end)")
        if tok == ".":
            break
        if tok != "*":
            raise cur.fail(where, f"expected '*' (an object) or '.' (the end), not {tok[:40]!r}")
        k += 1
        builder.count(k)
        name = object_name(cur.rest_of_line(), f"{where}: object {k}, line {cur.lineno}")
        label = f"{where}: object {k} ({name!r})"
        builder.check_id(name, k, label)
        pose = cur.pose(label) if poses else np.eye(4)
        n = cur.count(label, "the number of shapes", MAX_PARTS)
        shapes = tuple(_shape(cur, label) for _ in range(n))
        if poses:
            for _ in range(cur.count(label, "the number of subframes", 1000)):
                cur.next(label, "a subframe's name")
                cur.pose(label)
        builder.add(SceneObject(name, pose, shapes), k, label)
    name = first.rstrip("\r").strip()
    return Scene("" if name == "(noname)" else name, tuple(builder.objects), FORMAT_POSES if poses else FORMAT_NO_POSES,
                 where)
