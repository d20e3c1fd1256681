"""Reading triangle meshes (STL, OBJ, PLY) for work cells, with bounds checked before parsing.

A mesh file is read as bytes (at most :data:`MAX_FILE_BYTES`), its triangle count is read from its
header (binary STL, PLY) or counted (ASCII STL, OBJ) and refused above :data:`MAX_TRIANGLES` before
anything is parsed, then `trimesh` parses the bytes — from memory, so nothing the file refers to
(an OBJ's material library, a texture) is opened, and nothing is fetched from a network.  What comes
back must be a non-empty triangle mesh with finite vertices and valid faces; anything else is "not
a triangle mesh", in one line.
"""
from __future__ import annotations

import io
import re
import struct
from pathlib import Path

import numpy as np

from planning.errors import CellError

__all__ = ["MESH_SUFFIXES", "MAX_FILE_BYTES", "MAX_TRIANGLES", "read_bytes", "load_mesh", "mesh_suffix"]

MESH_SUFFIXES = (".stl", ".obj", ".ply")
MAX_FILE_BYTES = 50 * 2**20
MAX_TRIANGLES = 200_000
_PLY_HEADER_BYTES = 64 * 1024


def read_bytes(path: Path, label: str, what: str) -> bytes:
    """The bytes of ``path``, at most :data:`MAX_FILE_BYTES`; ``what`` names the kind of file."""
    from kin.files import FileReadError
    from kin.files import read_bytes as bounded_bytes
    try:
        return bounded_bytes(path, f"{what} file", MAX_FILE_BYTES)
    except FileReadError as e:
        raise CellError(f"{label}: {e}") from None


def ply_header(data: bytes, label: str, name: str) -> dict[str, int]:
    """The element counts of a PLY header ({"vertex": N, "face": M, …}); refuses a file that does not
    start like one."""
    end = data.find(b"end_header", 0, _PLY_HEADER_BYTES)
    if not data.startswith(b"ply") or end < 0:
        raise CellError(f"{label}: {name} is not a PLY file (no 'ply' … 'end_header' header)")
    counts = {}
    for m in re.finditer(rb"^element\s+(\w+)\s+(\d+)\s*$", data[:end], re.M):
        counts[m.group(1).decode("ascii", "replace")] = int(m.group(2))
    return counts


def _count_triangles(data: bytes, suffix: str, label: str, name: str) -> int:
    """The triangle count a file announces (a lower bound for OBJ polygons), read without parsing it."""
    if suffix == ".stl":
        if len(data) >= 84:
            n = struct.unpack("<I", data[80:84])[0]
            if len(data) == 84 + 50 * n:           # a binary STL: its header says how many
                return n
        return data.count(b"endfacet")
    if suffix == ".obj":
        return len(re.findall(rb"^[ \t]*f[ \t]", data, re.M))
    return ply_header(data, label, name).get("face", 0)


def mesh_suffix(path: Path, label: str) -> str:
    """The suffix of a mesh file, one of :data:`MESH_SUFFIXES` (else a :class:`CellError`)."""
    suffix = Path(path).suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise CellError(f"{label}: {Path(path).name}: mesh files must be "
                        f"{', '.join(s[1:].upper() for s in MESH_SUFFIXES)} (suffix {', '.join(MESH_SUFFIXES)})")
    return suffix


def load_mesh(path: str | Path, label: str = "mesh") -> np.ndarray:
    """The triangles of a mesh file: (m, 3, 3) float64, in the file's own units.

    Raises :class:`CellError` (prefixed by ``label``) for a missing or too large file, an unknown
    suffix, more than :data:`MAX_TRIANGLES` triangles, or a file that is not a non-empty triangle mesh
    with finite vertices.
    """
    path = Path(path)
    suffix = mesh_suffix(path, label)
    data = read_bytes(path, label, "mesh")
    if suffix == ".ply":
        counts = ply_header(data, label, path.name)
        if counts.get("vertex", 0) and not counts.get("face", 0):
            raise CellError(f"{label}: {path.name} is not a triangle mesh: it has vertices but no faces "
                            f"(a point cloud? use type = \"point_cloud\")")
    announced = _count_triangles(data, suffix, label, path.name)
    if announced > MAX_TRIANGLES:
        raise CellError(f"{label}: {path.name} has {announced} triangles; at most {MAX_TRIANGLES} "
                        f"(simplify it, or enclose the part by primitives)")
    import trimesh
    kwargs = {"skip_materials": True} if suffix == ".obj" else {}
    try:
        mesh = trimesh.load_mesh(io.BytesIO(data), file_type=suffix[1:], process=False, **kwargs)
    except Exception as e:      # trimesh raises many kinds on a malformed file: all mean "not a mesh"
        raise CellError(f"{label}: {path.name} is not a readable {suffix[1:].upper()} triangle mesh "
                        f"({type(e).__name__}: {str(e).splitlines()[0][:120] if str(e) else 'no detail'})") from None
    return _triangles(mesh, label, path.name)


def _triangles(mesh, label: str, name: str) -> np.ndarray:
    faces = getattr(mesh, "faces", None)
    vertices = getattr(mesh, "vertices", None)
    if faces is None or vertices is None:
        raise CellError(f"{label}: {name} is not a triangle mesh (it holds a {type(mesh).__name__})")
    F = np.asarray(faces)
    V = np.asarray(vertices, dtype=float)
    if F.ndim != 2 or F.shape[1] != 3 or len(F) == 0:
        raise CellError(f"{label}: {name} is not a triangle mesh: it has no triangles"
                        + (" (a point cloud? use type = \"point_cloud\")" if len(V) else ""))
    if len(F) > MAX_TRIANGLES:
        raise CellError(f"{label}: {name} has {len(F)} triangles; at most {MAX_TRIANGLES} "
                        f"(simplify it, or enclose the part by primitives)")
    if V.ndim != 2 or V.shape[1] != 3 or not np.all(np.isfinite(V)):
        raise CellError(f"{label}: {name} is not a triangle mesh: its vertices are not all finite 3-D points")
    if not np.issubdtype(F.dtype, np.integer) or F.min() < 0 or F.max() >= len(V):
        raise CellError(f"{label}: {name} is not a triangle mesh: a face refers to a vertex it does not have")
    return V[F]
