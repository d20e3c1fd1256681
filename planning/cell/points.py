"""Reading point clouds (PLY, CSV) for work cells, with bounds checked before parsing.

* PLY: the vertices of the file (a mesh's vertices count as points; faces are ignored); the vertex
  count is read from the header and refused above :data:`MAX_POINTS` before the body is parsed.
* CSV: one point per row, ``x,y,z`` (exactly three numbers, comma separated); lines starting with
  ``#`` are comments, and a first row of column names (``x,y,z``) is skipped.  The lines are counted
  before any is parsed (comment lines indented by spaces count as rows there).

Numbers are in the file's own units; they are read as numbers (numpy), never evaluated.
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from kin.states import is_number
from planning.cell.mesh import ply_header, read_bytes
from planning.errors import CellError

__all__ = ["POINT_SUFFIXES", "MAX_POINTS", "load_points"]

POINT_SUFFIXES = (".ply", ".csv")
MAX_POINTS = 200_000


def _too_many(label: str, name: str, n: int) -> CellError:
    return CellError(f"{label}: {name} has {n} points; at most {MAX_POINTS} (thin the scan out, e.g. to one point "
                     f"per point_radius)")


def load_points(path: str | Path, label: str = "point cloud") -> np.ndarray:
    """The points of a PLY or CSV file: (N, 3) float64, N ≥ 1, finite, in the file's own units."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in POINT_SUFFIXES:
        raise CellError(f"{label}: {path.name}: point clouds must be PLY or CSV files (suffix "
                        f"{', '.join(POINT_SUFFIXES)})")
    data = read_bytes(path, label, "point cloud")
    P = _ply(data, label, path.name) if suffix == ".ply" else _csv(data, label, path.name)
    if len(P) == 0:
        raise CellError(f"{label}: {path.name} has no points")
    if not np.all(np.isfinite(P)):
        row = int(np.flatnonzero(~np.all(np.isfinite(P), axis=1))[0]) + 1
        raise CellError(f"{label}: {path.name}: point {row} is not finite (NaN or infinite coordinates)")
    return P


def _ply(data: bytes, label: str, name: str) -> np.ndarray:
    n = ply_header(data, label, name).get("vertex", 0)
    if n > MAX_POINTS:
        raise _too_many(label, name, n)
    from trimesh.exchange.ply import load_ply
    try:
        loaded = load_ply(io.BytesIO(data), skip_materials=True)
    except Exception as e:      # trimesh raises many kinds on a malformed file
        raise CellError(f"{label}: {name} is not a readable PLY point cloud "
                        f"({type(e).__name__}: {str(e).splitlines()[0][:120] if str(e) else 'no detail'})") from None
    V = np.asarray(loaded.get("vertices", np.zeros((0, 3))), dtype=float)
    if V.ndim != 2 or (len(V) and V.shape[1] != 3):
        raise CellError(f"{label}: {name}: its vertices are not 3-D points")
    if len(V) > MAX_POINTS:
        raise _too_many(label, name, len(V))
    return V.reshape(-1, 3)


def _csv(data: bytes, label: str, name: str) -> np.ndarray:
    # count before parsing: lines, less those that start a comment or are blank (at a line's start)
    rows = (data.count(b"\n") + (not data.endswith(b"\n")) - data.count(b"\n#") - data.count(b"\n\n")
            - data.startswith(b"#"))
    first = data[:data.find(b"\n")] if b"\n" in data else data
    if not any(ch in first for ch in b"0123456789"):    # a header row of names
        rows -= 1
    if rows > MAX_POINTS:
        raise _too_many(label, name, rows)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise CellError(f"{label}: {name} is not a text CSV file (not UTF-8)") from None
    lines = text.splitlines()
    first = next((k for k, ln in enumerate(lines) if ln.strip() and not ln.lstrip().startswith("#")), None)
    if first is None:
        return np.zeros((0, 3))
    fields = lines[first].split(",")
    skip = 0
    if not any(is_number(f) for f in fields):          # a header row of column names
        if len(fields) != 3:
            raise CellError(f"{label}: {name}: line {first + 1}: expected three columns x,y,z")
        skip = first + 1
        if not any(ln.strip() and not ln.lstrip().startswith("#") for ln in lines[skip:]):
            return np.zeros((0, 3))     # a header only: no points (numpy would warn of an empty file)
    try:
        P = np.loadtxt(io.StringIO(text), delimiter=",", comments="#", skiprows=skip, ndmin=2, dtype=float)
    except ValueError as e:
        raise CellError(f"{label}: {name}: not rows of three numbers x,y,z ({str(e).splitlines()[0][:160]})") from None
    if P.size and P.shape[1] != 3:
        raise CellError(f"{label}: {name}: rows have {P.shape[1]} columns; expected three (x,y,z)")
    if len(P) > MAX_POINTS:
        raise _too_many(label, name, len(P))
    return P.reshape(-1, 3)
