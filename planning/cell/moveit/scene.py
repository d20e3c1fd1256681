"""A MoveIt planning scene's world as rmtkit reads it: :class:`Scene` of :class:`SceneObject` of
:class:`SceneShape` — and the checks both readers (YAML, ``.scene`` text) share.

Everything is SI (m) in the scene's *planning frame* (MoveIt's model frame: the robot's root link, or
the parent frame of its virtual joint); poses are 4×4 rigid transforms.  An object's shapes are
placed in the object's frame (MoveIt ≥ 1.1 gives objects a pose of their own; before, the object
frame is the planning frame).

The checks raise :class:`planning.errors.CellError` in one line: the scene file, the object (index and
id), the field, and what is allowed.  Numbers are read as numbers, never evaluated; a quaternion is
normalised when its norm is within :data:`QUATERNION_TOLERANCE` of 1 and refused beyond (all zeros is
MoveIt's empty orientation: the identity).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from planning.cell.fields import MAX_LENGTH
from planning.cell.mesh import MAX_FILE_BYTES, MAX_TRIANGLES
from planning.cell.obstacles import MAX_PARTS, MAX_VERTICES
from planning.cell.reader import MAX_CELL_ELEMENTS, MAX_CELL_PARTS, MAX_NAME, MAX_OBSTACLES
from planning.errors import CellError

__all__ = ["Scene", "SceneObject", "SceneShape", "SHAPE_DIMENSIONS", "QUATERNION_TOLERANCE", "MAX_SCENE_BYTES",
           "MAX_OBJECTS", "MAX_SHAPES", "number", "quaternion_matrix", "pose_matrix", "positive_sizes",
           "object_name", "mesh_arrays", "SceneBuilder"]

#: the largest scene file (bytes), checked before it is parsed
MAX_SCENE_BYTES = MAX_FILE_BYTES
#: the most objects of a scene (a cell's obstacles)
MAX_OBJECTS = MAX_OBSTACLES
#: the most shapes of all objects together, and of one object
MAX_SHAPES = MAX_CELL_PARTS
MAX_OBJECT_SHAPES = MAX_PARTS
#: how far a quaternion's norm may be from 1 and still be normalised
QUATERNION_TOLERANCE = 1e-3
#: the shape kinds of a scene and what their sizes are (m)
SHAPE_DIMENSIONS = {"box": ("x", "y", "z"), "sphere": ("radius",), "cylinder": ("radius", "length"),
                    "cone": ("radius", "length"), "mesh": ()}

# YAML 1.2's decimal numbers (PyYAML reads 1e-05, which has no dot, as a string)
_NUMBER = re.compile(r"^[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?$")


@dataclass(frozen=True, eq=False)
class SceneShape:
    """One shape of an object: ``kind`` (a key of :data:`SHAPE_DIMENSIONS`), ``size`` (m: box full edge
    lengths x, y, z; sphere radius; cylinder and cone radius, length — axis along the local z, centred),
    ``pose`` (4×4, in the object's frame); a mesh has ``vertices`` (V, 3; m, its own frame) and
    ``triangles`` (F, 3; 0-based vertex indices)."""

    kind: str
    size: tuple[float, ...]
    pose: np.ndarray
    vertices: np.ndarray | None = None
    triangles: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class SceneObject:
    """A collision object: ``name`` (MoveIt's id, runs of white space made one space), ``pose`` (4×4, the
    object's frame in the planning frame), ``shapes`` (at least one)."""

    name: str
    pose: np.ndarray
    shapes: tuple[SceneShape, ...]


@dataclass(frozen=True, eq=False)
class Scene:
    """The world of a planning scene: ``name`` (the scene's, may be empty), ``objects``, ``format`` (what
    was read: ``"PlanningScene YAML"`` or one of :data:`planning.cell.moveit.text_scene.FORMAT_POSES`,
    ``FORMAT_NO_POSES``), ``source`` (the file, for messages), ``notes`` (what was read but not imported:
    the robot's state, attached objects, the allowed collision matrix, octomaps, …) and
    ``robot_model_name`` (as the scene says, may be empty)."""

    name: str
    objects: tuple[SceneObject, ...]
    format: str
    source: str
    notes: tuple[str, ...] = ()
    robot_model_name: str = ""

    @property
    def kinds(self) -> dict[str, int]:
        """How many shapes of each kind the scene has."""
        out: dict[str, int] = {}
        for ob in self.objects:
            for s in ob.shapes:
                out[s.kind] = out.get(s.kind, 0) + 1
        return out


def number(v, label: str, what: str) -> float:
    """A finite number from a YAML or text value: int, float or a decimal string (``1e-05``); never a
    boolean, never evaluated."""
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise CellError(f"{label}: must be a number ({what}), not {type(v).__name__} {v!r}")
    if isinstance(v, str) and not _NUMBER.match(v.strip()):
        raise CellError(f"{label}: must be a number ({what}), not {v[:40]!r}")
    x = float(v)
    if not math.isfinite(x):
        raise CellError(f"{label}: must be a finite number ({what}), not {str(v)[:40]}")
    return x


def quaternion_matrix(q, label: str) -> np.ndarray:
    """The rotation (3×3) of a quaternion (x, y, z, w): all zeros → identity (MoveIt's empty
    orientation); a norm within :data:`QUATERNION_TOLERANCE` of 1 → normalised; else refused."""
    x, y, z, w = (float(c) for c in q)
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if n == 0:
        return np.eye(3)
    if abs(n - 1.0) > QUATERNION_TOLERANCE:
        raise CellError(f"{label}: the quaternion [{x:g}, {y:g}, {z:g}, {w:g}] (x, y, z, w) has norm {n:.6g}; a "
                        f"rotation's is 1 (within {QUATERNION_TOLERANCE:g}), or all zeros for none")
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def pose_matrix(position, quaternion, label: str) -> np.ndarray:
    """4×4 from a position (3 finite numbers, m, within 10 km) and a quaternion (x, y, z, w)."""
    p = np.array([float(c) for c in position])
    if np.abs(p).max() > MAX_LENGTH:
        raise CellError(f"{label}: position {p.tolist()} is more than the {MAX_LENGTH / 1000:g} km a cell may span "
                        f"(MoveIt scenes are in metres)")
    T = np.eye(4)
    T[:3, :3] = quaternion_matrix(quaternion, label)
    T[:3, 3] = p
    return T


def positive_sizes(values: list[float], names: tuple[str, ...], label: str) -> tuple[float, ...]:
    """Sizes (m) that must be > 0 and within 10 km; ``names`` say which is which in the message."""
    for v, n in zip(values, names):
        if not v > 0:
            raise CellError(f"{label}: {n} must be > 0 (m), not {v:g}")
        if v > MAX_LENGTH:
            raise CellError(f"{label}: {n} {v:g} m is more than the {MAX_LENGTH / 1000:g} km a cell may span")
    return tuple(values)


def object_name(raw, label: str) -> str:
    """A MoveIt object id as an obstacle name: a string (a YAML integer is taken as its digits), 1 to 100
    printable characters once runs of white space are one space."""
    if isinstance(raw, int) and not isinstance(raw, bool):
        raw = str(raw)
    if not isinstance(raw, str):
        raise CellError(f"{label}: id: required (a string)" if raw is None else
                        f"{label}: id: must be a string, not {type(raw).__name__} {raw!r}")
    name = " ".join(raw.split())
    if not name or len(name) > MAX_NAME or not name.isprintable():
        raise CellError(f"{label}: id {raw[:120]!r} must be 1 to {MAX_NAME} printable characters (it becomes the "
                        f"obstacle's name)")
    return name


def mesh_arrays(vertices: list, triangles: list, label: str) -> tuple[np.ndarray, np.ndarray]:
    """Checked mesh arrays: vertices (V, 3) finite floats (m, within 10 km), triangles (F, 3) indices of
    them; at least one triangle, at most :data:`planning.cell.mesh.MAX_TRIANGLES`."""
    if len(vertices) > MAX_VERTICES:
        raise CellError(f"{label}: {len(vertices)} vertices; at most {MAX_VERTICES}")
    if not triangles:
        raise CellError(f"{label}: no triangles; a mesh needs at least one")
    if len(triangles) > MAX_TRIANGLES:
        raise CellError(f"{label}: {len(triangles)} triangles; at most {MAX_TRIANGLES} (simplify the mesh)")
    V = np.array(vertices, dtype=float).reshape(-1, 3)
    if len(V) and np.abs(V).max() > MAX_LENGTH:
        raise CellError(f"{label}: a vertex lies {np.abs(V).max():.3g} m out; a cell is smaller than "
                        f"{MAX_LENGTH / 1000:g} km")
    F = np.array(triangles, dtype=np.int64).reshape(-1, 3)
    bad = np.flatnonzero((F < 0).any(axis=1) | (F >= len(V)).any(axis=1))
    if len(bad):
        raise CellError(f"{label}: triangle {int(bad[0])} refers to vertex {F[bad[0]].tolist()}; the mesh has "
                        f"{len(V)} vertices (0 to {len(V) - 1})")
    return V, F


class SceneBuilder:
    """Collects a scene's objects: ids unique, at most :data:`MAX_OBJECTS` objects, :data:`MAX_SHAPES`
    shapes and :data:`planning.cell.reader.MAX_CELL_ELEMENTS` mesh triangles together."""

    def __init__(self, source: str):
        self.source = source
        self.objects: list[SceneObject] = []
        self.where: dict[str, int] = {}
        self.shapes = self.triangles = 0

    def count(self, n_objects: int) -> None:
        """Refuse a scene announcing more than :data:`MAX_OBJECTS` objects before any is read."""
        if n_objects > MAX_OBJECTS:
            raise CellError(f"{self.source}: {n_objects} collision objects; at most {MAX_OBJECTS}")

    def check_id(self, name: str, k: int, label: str) -> None:
        if name in self.where:
            raise CellError(f"{label}: id {name!r} is already object {self.where[name]}'s; ids must be unique "
                            f"(the scene's objects become obstacles of one cell)")

    def add(self, ob: SceneObject, k: int, label: str) -> None:
        self.check_id(ob.name, k, label)
        self.count(len(self.objects) + 1)
        if not ob.shapes:
            raise CellError(f"{label}: no shapes (primitives or meshes); an object needs at least one")
        if len(ob.shapes) > MAX_OBJECT_SHAPES:
            raise CellError(f"{label}: {len(ob.shapes)} shapes; at most {MAX_OBJECT_SHAPES}")
        self.shapes += len(ob.shapes)
        if self.shapes > MAX_SHAPES:
            raise CellError(f"{label}: the scene's objects have more than {MAX_SHAPES} shapes together")
        self.triangles += sum(len(s.triangles) for s in ob.shapes if s.triangles is not None)
        if self.triangles > MAX_CELL_ELEMENTS:
            raise CellError(f"{label}: the scene's meshes have more than {MAX_CELL_ELEMENTS} triangles together")
        self.where[ob.name] = k
        self.objects.append(ob)
