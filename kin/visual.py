"""The robot's real shape: a robot file's ``[visual]`` table — mesh files drawn on its bodies.

Collision checks use capsules (``[geometry]``); what a viewer draws can be the maker's meshes.
``rmt import-urdf`` keeps a URDF's ``<visual>`` meshes here, one ``[[visual.mesh]]`` table each::

    [visual]
    source = "urdf: the <visual> elements of ur5.urdf"

    [[visual.mesh]]
    body = "link 2"                        # as in [geometry]: base, link k, tool or a joint's name
    file = "../meshes/visual/upperarm.dae" # relative to the robot file's directory, or absolute
    xyz = [0.0, 0.0, 0.136]                # the mesh's origin in the body's DH frame (file length unit)
    rpy = [0.0, 1.5708, 0.0]               # (file angle unit)
    scale = [1.0, 1.0, 1.0]                # optional: mesh units → metres, per axis
    color = [0.7, 0.7, 0.7, 1.0]           # optional: RGBA, each 0 … 1
    name = "upper_arm_link"                # optional

Mesh files are referenced, not copied: a saved robot file names them relative to its own directory
when the two share a directory below the file system's root (so a robot file kept beside its URDF
package moves with it), absolutely otherwise.  The structure is checked when the robot file loads (one
:class:`~kin.errors.RobotFileError` naming the field); the files themselves are read only by a viewer
(:mod:`studies.shape.meshes`), which draws the capsules instead of a mesh that is missing or not in a
format it reads (:data:`MESH_SUFFIXES`), saying so in one line.  Poses are SI in the chain; the chain's
convention changes move them with the body frames (:meth:`kin.chain.Chain.to_modified`).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from kin.placement import Placement

__all__ = ["VisualMesh", "MESH_SUFFIXES", "MAX_VISUAL_MESHES", "VISUAL_FIELDS", "MESH_FIELDS", "read_visual",
           "visual_lines", "moved_visual"]

#: the mesh formats a viewer reads (trimesh; COLLADA through pycollada)
MESH_SUFFIXES = (".stl", ".dae", ".obj", ".ply", ".glb", ".gltf", ".off")
#: at most this many meshes in a [visual] table
MAX_VISUAL_MESHES = 1000
VISUAL_FIELDS = ("source", "mesh")
MESH_FIELDS = ("body", "file", "xyz", "rpy", "scale", "color", "name")


@dataclass(frozen=True)
class VisualMesh:
    """One mesh drawn on body ``body`` (0 base … n + 1 tool): the file (an absolute path once
    loaded from a file), its pose in the body's DH frame (SI), per-axis scale, RGBA colour or None."""

    body: int
    file: str
    pose: Placement = Placement()
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    color: tuple[float, float, float, float] | None = None
    name: str = ""


def read_visual(r, raw: Any, body_of, placement_of, path: str | None) -> tuple[tuple[VisualMesh, ...], str]:
    """The [visual] table → (meshes, source); ``r`` the robot file's reader (its fail, number, vector…),
    ``body_of(value, field)`` a body's number, ``placement_of(table or None, field)`` a placement (SI)."""
    r.table(raw, "visual", VISUAL_FIELDS)
    source = r.string(raw["source"], "visual.source") if "source" in raw else ""
    items = raw.get("mesh", [])
    if not isinstance(items, list) or not all(isinstance(t, dict) for t in items):
        raise r.fail("visual.mesh", "must be an array of tables: write [[visual.mesh]]")
    if len(items) > MAX_VISUAL_MESHES:
        raise r.fail("visual.mesh", f"lists {len(items)} meshes; at most {MAX_VISUAL_MESHES} are allowed")
    root = Path(path).resolve().parent if path else None
    out = []
    for i, t in enumerate(items):
        fld = f"visual.mesh[{i}]"
        r.table(t, fld, MESH_FIELDS)
        for k in ("body", "file"):
            if k not in t:
                raise r.fail(f"{fld}.{k}", "missing required field")
        body = body_of(t["body"], f"{fld}.body")
        name = r.string(t["file"], f"{fld}.file")
        if not name or "\x00" in name or "://" in name:
            raise r.fail(f"{fld}.file", f"{name!r} must be a file path (relative to the robot file, or absolute)")
        if Path(name).suffix.lower() not in MESH_SUFFIXES:
            raise r.fail(f"{fld}.file", f"{name!r}: the format {Path(name).suffix or '(no suffix)'} is not read; "
                         f"allowed: {', '.join(MESH_SUFFIXES)}")
        file = Path(name)
        if not file.is_absolute() and root is not None:
            file = root / file
        pose = placement_of({k: t[k] for k in ("xyz", "rpy") if k in t} or None, fld)
        scale = (1.0, 1.0, 1.0)
        if "scale" in t:
            s = r.vector(t["scale"], f"{fld}.scale", 3)
            if not all(1e-9 <= abs(x) <= 1e4 for x in s):
                raise r.fail(f"{fld}.scale", f"{s}: each factor must be non-zero, 1e-9 to 1e4 in size")
            scale = tuple(float(x) for x in s)
        color = None
        if "color" in t:
            c = r.vector(t["color"], f"{fld}.color", 4)
            if not all(0.0 <= x <= 1.0 for x in c):
                raise r.fail(f"{fld}.color", f"{c}: RGBA, each between 0 and 1")
            color = tuple(float(x) for x in c)
        label = r.string(t["name"], f"{fld}.name") if "name" in t else ""
        out.append(VisualMesh(body, os.path.normpath(str(file)), pose, scale, color, label))  # type: ignore[arg-type]
    return tuple(out), source


def visual_lines(chain, vec, string, label_of, ls: float, as_: float,
                 directory: str | Path | None = None) -> list[str]:
    """The [visual] table's lines (``vec``, ``string`` the robot file's writers, ``label_of(body)`` a
    body's name, ``ls``/``as_`` its units); files relative to ``directory`` when given (the saved
    file's), else as held (absolute once loaded from a file)."""
    _str, body_label = string, (lambda _chain, b: label_of(b))
    out = ["", "[visual]"]
    if chain.visual_source:
        out.append(f"source = {_str(chain.visual_source)}")
    for v in chain.visual:
        file = v.file
        if directory is not None and Path(file).is_absolute():
            here = str(Path(directory).resolve())
            common = Path(os.path.commonpath([file, here]))
            if common.parent != common:          # they share a directory below the root: relative
                file = os.path.relpath(file, here)
        out += ["", "[[visual.mesh]]", f"body = {_str(body_label(chain, v.body))}", f"file = {_str(file)}"]
        pl = v.pose if v.pose.matrix_ is None else _as_rpy(v.pose)
        if any(pl.xyz):
            out.append(f"xyz = {vec(pl.xyz, ls)}")
        if any(pl.rpy):
            out.append(f"rpy = {vec(pl.rpy, as_)}")
        if v.scale != (1.0, 1.0, 1.0):
            out.append(f"scale = {vec(v.scale)}")
        if v.color is not None:
            out.append(f"color = {vec(v.color)}")
        if v.name:
            out.append(f"name = {_str(v.name)}")
    return out


def _as_rpy(pl: Placement) -> Placement:
    from kin.transforms import matrix_to_rpy

    T = pl.matrix
    return Placement(xyz=tuple(float(x) for x in T[:3, 3]), rpy=tuple(float(x) for x in matrix_to_rpy(T[:3, :3])))


def pose_placement(T: np.ndarray) -> Placement:
    """A pose (4, 4) as xyz + rpy, rounding noise below 1 nm / 1e-12 rad written as 0."""
    pl = _as_rpy(Placement.from_matrix(T))
    return Placement(xyz=tuple(0.0 if abs(x) < 1e-9 else x for x in pl.xyz),
                     rpy=tuple(0.0 if abs(x) < 1e-12 else x for x in pl.rpy))


def moved_visual(visual: tuple[VisualMesh, ...], transforms) -> tuple[VisualMesh, ...]:
    """Each mesh of body k re-expressed by ``transforms[k]`` (old frame k → new frame k; absent: kept)."""
    out = []
    for v in visual:
        T = transforms.get(v.body)
        out.append(v if T is None else replace(v, pose=pose_placement(np.asarray(T) @ v.pose.matrix)))
    return tuple(out)
