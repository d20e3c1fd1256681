"""Mesh and point-cloud enclosures kept on disk, so that a cell is read in milliseconds the second time.

Enclosing a mesh by spheres (:func:`planning.cell.enclose.enclose_triangles`) takes about a second
for a part of a few thousand triangles, and parsing its file loads trimesh (another second); a cell
file read by every ``rmt plan --cell`` would pay both each time.  :func:`cached` keeps what they
give — the placed triangles (for drawing) or points, the spheres and their over-estimate — in
rmtkit's cache (``cache_dir()/cells``), under a hash of everything the result depends on: the file's
bytes (or the triangles written in the cell), how it is scaled and placed, the tolerance and sphere
budget, and the source of the code that reads and encloses it.  A changed file, a changed parameter
or a new rmtkit computes anew.

An entry is written to a temporary file and renamed into place (a reader sees the whole file or none);
one that cannot be read, or whose arrays are not what the key promises (shapes, finite values), is
ignored and computed anew; a path taken by something other than a regular file is never replaced.
The cache is an optimisation only: any failure to read or write it falls back to computing.
"""
from __future__ import annotations

import hashlib
import os
import tempfile
from functools import lru_cache
from pathlib import Path
from typing import Callable

import numpy as np

from kin.native.settings import cache_dir

__all__ = ["cached", "cache_key"]

#: the code whose results are kept (a new version of any computes anew)
_SOURCES = ("enclose.py", "mesh.py", "points.py", "cache.py")


@lru_cache(maxsize=1)
def _code_hash() -> str:
    h = hashlib.sha256()
    here = Path(__file__).resolve().parent
    for name in _SOURCES:
        try:
            h.update((here / name).read_bytes())
        except OSError:
            h.update(name.encode())
    return h.hexdigest()


def cache_key(kind: str, data: bytes, *params) -> str:
    """The hash naming an entry: ``kind`` (``mesh``, ``points``), the source ``data`` and the
    parameters (numbers and arrays) the result depends on."""
    h = hashlib.sha256()
    h.update(kind.encode())
    h.update(_code_hash().encode())
    h.update(hashlib.sha256(data).digest())
    for p in params:
        a = np.ascontiguousarray(p, dtype=float)
        h.update(repr(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()[:40]


def _path(key: str) -> Path:
    return cache_dir() / "cells" / f"{key}.npz"


def _read(key: str) -> dict | None:
    path = _path(key)
    try:
        if not path.is_file():
            return None
        with np.load(path, allow_pickle=False) as z:
            out = {k: np.array(z[k]) for k in z.files}
    except (OSError, ValueError, EOFError):
        return None
    pts, spheres, over = out.get("pieces"), out.get("spheres"), out.get("over")
    if pts is None or spheres is None or over is None or spheres.ndim != 2 or spheres.shape[1] != 4 \
            or not len(spheres) or over.shape != () or pts.shape[-1] != 3:
        return None
    if not (np.all(np.isfinite(pts)) and np.all(np.isfinite(spheres)) and np.isfinite(over)):
        return None
    return out


def _write(key: str, arrays: dict) -> None:
    path = _path(key)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        if os.path.lexists(path) and not path.is_file():
            return                                  # never replace anything but a regular file
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".cell-", suffix=".npz")
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez(f, **arrays)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    except OSError:
        pass


def cached(key: str, compute: Callable[[], tuple[np.ndarray, np.ndarray, float]]
           ) -> tuple[np.ndarray, np.ndarray, float]:
    """(pieces, spheres, over_estimate) for ``key``: from the cache, or ``compute()`` — placed triangles
    (m, 3, 3) or points (N, 3), spheres (K, 4), over-estimate (m) — then kept."""
    hit = _read(key)
    if hit is not None:
        return hit["pieces"], hit["spheres"], float(hit["over"])
    pieces, spheres, over = compute()
    _write(key, {"pieces": np.asarray(pieces, dtype=float), "spheres": np.asarray(spheres, dtype=float),
                 "over": np.asarray(float(over))})
    return pieces, spheres, over
