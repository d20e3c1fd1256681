"""The robot's real shape: triangle meshes fixed in its bodies, for the 3-D views.

:func:`visual_meshes` gives, for a robot, a list of :class:`BodyMesh` — vertices in metres in body
k's DH frame (place them with :func:`kin.geometry.body_frames`), triangles, a colour — or None when
no real shape is known (then the views draw the collision capsules).  Sources, in order:

1. **The robot file's [visual] table** (:mod:`kin.visual`; ``rmt import-urdf`` keeps a URDF's
   <visual> meshes there).  Each file is read with trimesh (STL, COLLADA, OBJ, PLY, glTF, OFF); a file
   that is missing, too large or unreadable is left out with one line on standard error (a
   :class:`MeshWarning`), and when none is left the robot is drawn as capsules.
2. **A bundled arm whose maker's URDF ships with example-robot-data** (the optional extra
   ``pip install rmtkit[meshes]``): the URDF is imported (:func:`kin.urdf.chain_from_serial`), its
   bodies mapped onto the bundled arm's by constant transforms checked at random configurations
   (:func:`studies.shape.mapping.body_map`), its <visual> meshes carried over.  Only arms whose URDF
   there has the bundled file's kinematics qualify (:data:`BUNDLED`): example-robot-data ships the
   Panda, and Universal Robots' older CB-series arms, whose lengths differ from the e-series'.

Bodies with no mesh of their own (a URDF's boxes, the tool of a bundled arm) have none in the list:
draw their capsules.  Meshes larger than ``budget`` triangles are decimated by vertex clustering
(:func:`decimate`: vertices merged on a grid, collapsed triangles dropped) to keep pages small;
files are read once (cached by path, size and modification time).
"""
from __future__ import annotations

import functools
import importlib.metadata
import logging
import math
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["BodyMesh", "MeshWarning", "visual_meshes", "decimate", "BUNDLED", "DEFAULT_BUDGET",
           "DEFAULT_COLOUR", "load_mesh_file"]

#: triangles per mesh file kept by default (more are decimated)
DEFAULT_BUDGET = 6_000
#: a mesh file larger than this is not read (bytes)
MAX_FILE_BYTES = 64 * 2 ** 20
DEFAULT_COLOUR = (0.78, 0.78, 0.80, 1.0)
#: bundled arm → (URDF inside example-robot-data's robots directory, base link, tip link)
BUNDLED = {"franka_panda": ("panda_description/urdf/panda.urdf", None, "panda_link8")}
ERD_ROBOTS = "cmeel.prefix/share/example-robot-data/robots"


class MeshWarning(UserWarning):
    """A mesh left out (missing, foreign format, unreadable): drawn as capsules instead."""


@dataclass(frozen=True)
class BodyMesh:
    """A mesh fixed in body ``body`` (0 base, k link k, n + 1 tool): vertices (k, 3) in metres in the
    body's DH frame, triangles (m, 3) of vertex indices, colour RGBA (0 … 1)."""

    body: int
    vertices: np.ndarray
    faces: np.ndarray
    rgba: tuple[float, float, float, float] = DEFAULT_COLOUR
    name: str = ""


def _say(message: str) -> None:
    warnings.warn(MeshWarning(message), stacklevel=3)


def decimate(V: np.ndarray, F: np.ndarray, budget: int) -> tuple[np.ndarray, np.ndarray]:
    """At most about ``budget`` triangles: vertices merged on a grid whose cell is chosen by bisection
    so that the surviving triangles fit, triangles that collapse dropped (vertex clustering)."""
    if budget is None or len(F) <= budget:
        return V, F
    lo_, hi_ = V.min(axis=0), V.max(axis=0)
    size = float(np.max(hi_ - lo_)) or 1.0

    def cluster(cell: float):
        cells = np.floor((V - lo_) / cell).astype(np.int64)
        m = int(cells.max()) + 1                          # ≤ 4097 cells a side: one int64 key per vertex
        _, inverse, counts = np.unique((cells[:, 0] * m + cells[:, 1]) * m + cells[:, 2], return_inverse=True,
                                       return_counts=True)
        inverse = inverse.reshape(-1)
        sums = np.zeros((len(counts), 3))
        np.add.at(sums, inverse, V)
        G = inverse[F]
        keep = (G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 0] != G[:, 2])
        G = G[keep]
        S = np.sort(G, axis=1)
        k = len(counts)
        first = np.unique((S[:, 0] * k + S[:, 1]) * k + S[:, 2], return_index=True)[1]   # one of each triangle
        return sums / counts[:, None], G[np.sort(first)]

    lo, hi = size / 4096, size / 4
    best = cluster(hi)
    for _ in range(10):
        mid = math.sqrt(lo * hi)
        W, T = cluster(mid)
        if len(T) <= budget:
            best, hi = (W, T), mid
        else:
            lo = mid
    W, T = best
    used = np.unique(T)
    remap = np.full(len(W), -1)
    remap[used] = np.arange(len(used))
    return W[used], remap[T]


@functools.lru_cache(maxsize=256)
def _read(path: str, size: int, mtime: float, budget: int | None):
    import trimesh

    quiet = logging.getLogger("trimesh")
    level = quiet.level
    quiet.setLevel(logging.CRITICAL)
    try:
        mesh = trimesh.load(path, force="mesh", process=False)
        V = np.asarray(mesh.vertices, dtype=float)
        F = np.asarray(mesh.faces, dtype=np.int64)
        colour = None
        try:                    # the file's main colour, unless trimesh's default grey
            c = [float(x) for x in np.asarray(mesh.visual.main_color).reshape(-1)]
            if len(c) == 4 and c != [102.0, 102.0, 102.0, 255.0]:
                colour = tuple(x / 255 for x in c)
        except Exception:       # no colour in the file: the default
            colour = None
    finally:
        quiet.setLevel(level)
    if F.ndim != 2 or F.shape[1] != 3 or len(F) == 0:
        raise ValueError("it holds no triangles")
    if F.min() < 0 or F.max() >= len(V) or not np.all(np.isfinite(V)):
        raise ValueError("its triangles refer to missing vertices, or it has NaN vertices")
    V, F = decimate(V, F, budget)
    V.setflags(write=False)
    F.setflags(write=False)
    return V, F, colour


def load_mesh_file(path: str | Path, budget: int | None = DEFAULT_BUDGET):
    """(vertices, triangles, colour or None) of a mesh file, cached; ValueError saying why it cannot be
    read (missing, foreign format, too large, no triangles)."""
    from kin.visual import MESH_SUFFIXES

    p = Path(path)
    if p.suffix.lower() not in MESH_SUFFIXES:
        raise ValueError(f"the format {p.suffix or '(no suffix)'} is not read; allowed: {', '.join(MESH_SUFFIXES)}")
    try:
        st = p.stat()
    except OSError:
        raise ValueError("no such file") from None
    if not p.is_file():
        raise ValueError("not a regular file")
    if st.st_size > MAX_FILE_BYTES:
        raise ValueError(f"{st.st_size / 2 ** 20:.0f} MB; at most {MAX_FILE_BYTES // 2 ** 20} MB are read")
    try:
        return _read(str(p.resolve()), st.st_size, st.st_mtime, budget)
    except ValueError:
        raise
    except Exception as e:      # any reader's error: not a mesh it reads
        raise ValueError(f"unreadable ({type(e).__name__}: {str(e).strip()[:160] or 'not a mesh'})") from None


def _placed(v, budget) -> BodyMesh | None:
    """A :class:`kin.visual.VisualMesh` read and placed in its body's frame; None (said) when unreadable."""
    try:
        V, F, colour = load_mesh_file(v.file, budget)
    except ValueError as e:
        _say(f"visual mesh {v.file!r} ({v.name or f'body {v.body}'}): {e}; drawn as capsules")
        return None
    T = v.pose.matrix
    P = (V * np.asarray(v.scale)) @ T[:3, :3].T + T[:3, 3]
    if np.prod(v.scale) < 0:           # a mirroring scale turns the triangles inside out
        F = F[:, ::-1]
    return BodyMesh(v.body, P, np.ascontiguousarray(F), v.color or colour or DEFAULT_COLOUR, v.name)


def _meshes_of(visual, budget) -> list[BodyMesh] | None:
    out = [m for m in (_placed(v, budget) for v in visual) if m is not None]
    return out or None


def visual_meshes(robot, budget: int | None = DEFAULT_BUDGET) -> list[BodyMesh] | None:
    """The robot's real shape (see the module docstring); ``robot`` a :class:`kin.Robot` or a chain;
    ``budget``: triangles kept per mesh file (None: every triangle)."""
    chain = getattr(robot, "chain", robot)
    if chain.visual:
        return _meshes_of(chain.visual, budget)
    if chain.name in BUNDLED:
        visual = _bundled_visual(chain)
        if visual:
            return _meshes_of(visual, budget)
    return None


def _erd_path(relative: str) -> Path | None:
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    path = Path(dist.locate_file(f"{ERD_ROBOTS}/{relative}"))
    return path if path.is_file() else None


def _chain_key(chain) -> tuple:
    from kin.geometry.frames import dh_rows
    return (chain.name, chain.convention, dh_rows(chain).tobytes(), chain.base.matrix.tobytes(),
            chain.tool.matrix.tobytes(), chain.lower.tobytes(), chain.upper.tobytes())


_BUNDLED_CACHE: dict[tuple, tuple] = {}


def _bundled_visual(chain) -> tuple:
    """The maker's <visual> meshes of a bundled arm, as :class:`kin.visual.VisualMesh` on ``chain``'s
    bodies (the tool's left out: the arm ends at its flange); () when example-robot-data is absent or
    its URDF is not this chain's machine."""
    key = _chain_key(chain)
    if key in _BUNDLED_CACHE:
        return _BUNDLED_CACHE[key]
    relative, base, tip = BUNDLED[chain.name]
    path = _erd_path(relative)
    out: tuple = ()
    if path is not None:
        out = _mapped_visual(chain, path, base, tip)
    _BUNDLED_CACHE[key] = out
    return out


def _mapped_visual(chain, path: Path, base, tip) -> tuple:
    from dataclasses import replace

    from kin.urdf import UrdfError, UrdfWarning, chain_from_serial, read_serial_chain
    from kin.visual import pose_placement
    from studies.shape.mapping import MappingError, body_map

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UrdfWarning)
            imported = chain_from_serial(read_serial_chain(str(path), base, tip), collision=False)
        X = body_map(chain, imported)
    except (UrdfError, MappingError) as e:
        print(f"rmt: note: the maker's meshes of {chain.name} are not used ({e})", file=sys.stderr)
        return ()
    return tuple(replace(v, pose=pose_placement(X[v.body] @ v.pose.matrix)) for v in imported.visual
                 if v.body <= chain.n)
