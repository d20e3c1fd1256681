"""The obstacle types of a cell file, each table → a :class:`kin.geometry.Obstacle` (SI, cell frame).

* ``box``, ``sphere``, ``cylinder``, ``capsule``: one primitive;
* ``cone`` (radius of its base, length along its local z, centred like a cylinder, apex at +z): its
  cylinder, which holds it; ``over_estimate`` = r·h/√(r² + h²), the farthest the cylinder stands out
  of the cone (its top rim from the cone's side);
* ``mesh``: triangles from a file (STL, OBJ, PLY) or written in the table (``vertices``,
  ``triangles``), enclosed by spheres (:func:`planning.cell.enclose.enclose_triangles`);
* ``point_cloud``: points from a file, enclosed by spheres (:func:`planning.cell.enclose.enclose_points`);
* ``compound``: several of the above (``[[obstacle.part]]`` tables, each with its own ``xyz``/``rpy``
  in the obstacle's frame) as one obstacle — a MoveIt collision object with several shapes.

Every field is checked through :class:`planning.cell.fields.Table`; files are bounded before they are
parsed (:mod:`planning.cell.mesh`, :mod:`planning.cell.points`) and the triangles and points of the
whole cell by the reader's budget.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kin.chain import LENGTH_UNITS
from kin.geometry import Obstacle, Shape
from planning.cell.cache import cache_key, cached
from planning.cell.enclose import enclose_points, enclose_triangles
from planning.cell.fields import MAX_LENGTH, Table, check_keys, is_num
from planning.cell.mesh import MAX_TRIANGLES, load_mesh, mesh_suffix, read_bytes
from planning.cell.points import POINT_SUFFIXES, load_points
from planning.errors import CellError

__all__ = ["OBSTACLE_TYPES", "PART_TYPES", "MAX_PARTS", "MAX_VERTICES", "MAX_SPHERES", "DEFAULT_MAX_SPHERES",
           "DEFAULT_TOLERANCE", "cone_over_estimate", "build_obstacle"]

#: the most parts a compound obstacle may have
MAX_PARTS = 1000
#: the most vertices a mesh written in the cell file may have
MAX_VERTICES = 3 * MAX_TRIANGLES
#: the most spheres a mesh may ask for (``max_spheres``), and the default
MAX_SPHERES = 20_000
DEFAULT_MAX_SPHERES = 2_000
#: the default over-estimate wanted of a mesh's spheres (m)
DEFAULT_TOLERANCE = 0.005

#: the keys every obstacle table may have
COMMON = {"name", "type", "xyz", "rpy", "ignore"}
#: the keys every part of a compound obstacle may have
PART_COMMON = {"type", "xyz", "rpy"}
#: obstacle types and their own keys
OBSTACLE_TYPES = {
    "box": {"size"},
    "sphere": {"radius"},
    "cylinder": {"radius", "length"},
    "capsule": {"radius", "length"},
    "cone": {"radius", "length"},
    "mesh": {"file", "vertices", "triangles", "unit", "scale", "tolerance", "max_spheres"},
    "point_cloud": {"file", "unit", "scale", "point_radius", "merge"},
    "compound": {"part"},
}
#: the types a part of a compound obstacle may have
PART_TYPES = tuple(k for k in OBSTACLE_TYPES if k != "compound")


def cone_over_estimate(radius: float, length: float) -> float:
    """How far the cylinder (radius, length) stands out of the cone it holds (m): r·h/√(r² + h²)."""
    return radius * length / math.hypot(radius, length)


@dataclass
class _Piece:
    """What one shape table gives: primitives, spheres (K, 4) or None, their over-estimate (m), a note
    for reports and, for a mesh, its triangles placed in the cell (m, 3, 3)."""

    shapes: list
    spheres: np.ndarray | None = None
    over_estimate: float = 0.0
    note: str | None = None
    triangles: np.ndarray | None = None


def _file(f: Table, base_dir: Path) -> Path:
    rel = f.string("file")
    if not rel.strip() or "\x00" in rel:
        raise f.fail("file", "must name a file")
    p = Path(rel)
    return p if p.is_absolute() else base_dir / p


def _file_scale(f: Table) -> np.ndarray:
    """Metres per number of the file: ``unit`` (default the cell's) times ``scale`` (1, or 3 factors)."""
    unit = f.string("unit", f.unit, tuple(LENGTH_UNITS))
    raw = f.t.get("scale", 1.0)
    if is_num(raw):
        s = [float(raw)] * 3
    else:
        s = f.numbers("scale", 3, "(a positive factor, or three: [sx, sy, sz])")
    if not all(math.isfinite(x) and 0 < x <= 1e6 for x in s):
        raise f.fail("scale", f"must be positive and finite (at most 1e6), not {raw!r}")
    return np.array(s) * LENGTH_UNITS[unit]


def _place(points: np.ndarray, pose: np.ndarray, f: Table, name: str) -> np.ndarray:
    out = points @ pose[:3, :3].T + pose[:3, 3]
    if np.abs(out).max() > MAX_LENGTH:
        raise CellError(f"{f.label}: {name} reaches {np.abs(out).max():.3g} m from the cell's origin; a cell is "
                        f"smaller than {MAX_LENGTH / 1000:g} km (check unit and scale)")
    return out


def _inline_triangles(f: Table) -> np.ndarray:
    """The triangles (m, 3, 3) of a mesh written in the table: ``vertices`` [[x, y, z], …] (numbers of
    the mesh, like a file's) and ``triangles`` [[i, j, k], …] (0-based vertex indices)."""
    V, F = f.t.get("vertices"), f.t.get("triangles")
    if V is None or F is None:
        raise f.fail("triangles" if F is None else "vertices",
                     "required with the other (a mesh written in the file has vertices = [[x, y, z], …] and "
                     "triangles = [[i, j, k], …])")
    if not isinstance(V, list) or not V:
        raise f.fail("vertices", f"must be a non-empty list of [x, y, z], not {type(V).__name__}")
    if len(V) > MAX_VERTICES:
        raise f.fail("vertices", f"{len(V)} vertices; at most {MAX_VERTICES}")
    for k, v in enumerate(V):
        if not (isinstance(v, list) and len(v) == 3 and all(is_num(x) for x in v)):
            raise f.fail("vertices", f"vertex {k} must be 3 numbers [x, y, z], not {v!r}")
    P = np.array(V, dtype=float)
    if not np.all(np.isfinite(P)):
        k = int(np.flatnonzero(~np.all(np.isfinite(P), axis=1))[0])
        raise f.fail("vertices", f"vertex {k} must be finite, not {V[k]}")
    if not isinstance(F, list) or not F:
        raise f.fail("triangles", f"must be a non-empty list of [i, j, k], not {type(F).__name__}")
    if len(F) > MAX_TRIANGLES:
        raise f.fail("triangles", f"{len(F)} triangles; at most {MAX_TRIANGLES} (simplify the mesh)")
    n = len(P)
    for k, t in enumerate(F):
        if not (isinstance(t, list) and len(t) == 3
                and all(isinstance(i, int) and not isinstance(i, bool) and 0 <= i < n for i in t)):
            raise f.fail("triangles", f"triangle {k} must be 3 vertex indices from 0 to {n - 1}, not {t!r}")
    return P[np.array(F, dtype=np.int64)]


def _mesh(f: Table, pose: np.ndarray, base_dir: Path, budget) -> _Piece:
    scale = _file_scale(f)
    tol = f.number("tolerance", DEFAULT_TOLERANCE / f.scale)
    ms = f.t.get("max_spheres", DEFAULT_MAX_SPHERES)
    if not (isinstance(ms, int) and not isinstance(ms, bool) and 1 <= ms <= MAX_SPHERES):
        raise f.fail("max_spheres", f"must be a whole number from 1 to {MAX_SPHERES}, not {ms!r}")
    if "file" in f.t:
        if "vertices" in f.t or "triangles" in f.t:
            raise f.fail("file", "a mesh is a file or vertices and triangles, not both")
        path = _file(f, base_dir)
        mesh_suffix(path, f"{f.label}: file")
        data, source = read_bytes(path, f"{f.label}: file", "mesh"), path.name
        key = cache_key("mesh" + path.suffix.lower(), data, scale, pose, [tol, ms])
        read = lambda: load_mesh(path, f"{f.label}: file")      # noqa: E731
    else:
        T0, source = _inline_triangles(f), "vertices and triangles"
        key = cache_key("mesh", np.ascontiguousarray(T0).tobytes(), scale, pose, [tol, ms])
        read = lambda: T0                                         # noqa: E731

    taken = []

    def compute():
        T = read()
        budget.take(len(T), f.label)                    # before the work it bounds
        taken.append(True)
        T = _place(T.reshape(-1, 3) * scale, pose, f, source).reshape(-1, 3, 3)
        cover = enclose_triangles(T, tol, ms)
        return T, cover.spheres, cover.over_estimate

    T, spheres, over = cached(key, compute)             # the enclosure of an unchanged mesh is kept on disk
    T = T.reshape(-1, 3, 3)
    if not taken:
        budget.take(len(T), f.label)
    return _Piece([], spheres, over, f"{source}: {len(T)} triangles in {len(spheres)} spheres", T)


def _piece(f: Table, kind: str, base_dir: Path, budget, parent: np.ndarray) -> _Piece:
    """One shape table (an obstacle's or a part's) placed at ``parent`` · its own pose."""
    pose = parent @ f.pose()
    if kind == "box":
        return _Piece([Shape("box", tuple(0.5 * f.sizes("size")), pose)])
    if kind == "sphere":
        return _Piece([Shape("sphere", (f.number("radius"), 0, 0), pose)])
    if kind in ("cylinder", "capsule"):
        r, length = f.number("radius"), f.number("length")
        return _Piece([Shape(kind, (r, 0.5 * length, 0), pose)])
    if kind == "cone":
        r, length = f.number("radius"), f.number("length")
        over = cone_over_estimate(r, length)
        return _Piece([Shape("cylinder", (r, 0.5 * length, 0), pose)], None, over,
                      f"a cone enclosed by its cylinder, which stands out ≤ {over * 1000:.1f} mm")
    if kind == "mesh":
        return _mesh(f, pose, base_dir, budget)
    path = _file(f, base_dir)
    scale = _file_scale(f)
    pr = f.number("point_radius")
    merge = f.t.get("merge", True)
    if not isinstance(merge, bool):
        raise f.fail("merge", f"must be true or false, not {merge!r}")
    if path.suffix.lower() not in POINT_SUFFIXES:
        load_points(path, f"{f.label}: file")             # says which files are point clouds
    data = read_bytes(path, f"{f.label}: file", "point cloud")
    taken = []

    def compute():
        P = load_points(path, f"{f.label}: file")
        budget.take(len(P), f.label)
        taken.append(True)
        P = _place(P * scale, pose, f, path.name)
        cover = enclose_points(P, pr, merge)
        return P, cover.spheres, cover.over_estimate

    P, spheres, over = cached(cache_key("points" + path.suffix.lower(), data, scale, pose, [pr, float(merge)]),
                              compute)
    if not taken:
        budget.take(len(P), f.label)
    return _Piece([], spheres, over, f"{path.name}: {len(P)} points in {len(spheres)} spheres")


def _compound(f: Table, base_dir: Path, budget) -> _Piece:
    parts = f.t.get("part")
    if not (isinstance(parts, list) and parts and all(isinstance(p, dict) for p in parts)):
        raise f.fail("part", "required: one [[obstacle.part]] table per shape of the obstacle")
    if len(parts) > MAX_PARTS:
        raise f.fail("part", f"{len(parts)} parts; at most {MAX_PARTS}")
    budget.parts(len(parts), f.label)
    pose = f.pose()
    pieces = []
    for j, t in enumerate(parts, 1):
        label = f"{f.label}: part {j}"
        g = Table(label, t, f.unit, f.scale, f.angle_unit)
        kind = g.string("type", None, PART_TYPES)
        check_keys(label, t, PART_COMMON | OBSTACLE_TYPES[kind])
        pieces.append(_piece(g, kind, base_dir, budget, pose))
    spheres = [p.spheres for p in pieces if p.spheres is not None]
    triangles = [p.triangles for p in pieces if p.triangles is not None]
    notes = [f"part {j}: {p.note}" for j, p in enumerate(pieces, 1) if p.note]
    return _Piece([s for p in pieces for s in p.shapes], np.concatenate(spheres) if spheres else None,
                  max(p.over_estimate for p in pieces), "; ".join([f"{len(pieces)} parts"] + notes),
                  np.concatenate(triangles) if triangles else None)


def build_obstacle(f: Table, kind: str, name: str, base_dir: Path, budget
                   ) -> tuple[Obstacle, str | None, np.ndarray | None]:
    """The obstacle of table ``f`` (of type ``kind``, already checked), its note (meshes, point clouds,
    cones, compounds) and, for meshes, its triangles placed in the cell (m); ``budget`` counts the
    triangles, points and parts of the whole cell (``take(n, label)``, ``parts(n, label)``)."""
    p = _compound(f, base_dir, budget) if kind == "compound" else _piece(f, kind, base_dir, budget, np.eye(4))
    return Obstacle(name, tuple(p.shapes), p.spheres, over_estimate=p.over_estimate, kind=kind), p.note, p.triangles
