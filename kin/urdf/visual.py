"""The <visual> meshes of an imported URDF, kept for viewers as the robot file's [visual] table
(:mod:`kin.visual`).

Each <visual> element with a <mesh> of a link fixed to a body of the chain (the bodies of
:mod:`kin.urdf.collision`) becomes one :class:`~kin.visual.VisualMesh`: its file found as collision
meshes are (:func:`kin.urdf.collision.resolve_mesh`: package://, file:// or a path; nothing fetched),
its pose F⁻¹·L·V in the body's DH frame F of the finished chain (L the link's frame, V the element's
origin, both at q = 0 in the base link's frame), its scale and its material's colour.  The files are
referenced, not read: a viewer reads them.  A visual whose file is missing, or in a format viewers do
not read, is left out with one :class:`~kin.urdf.errors.UrdfWarning`; boxes, cylinders and spheres are
left out (the viewer draws the body's capsules where it has no mesh).
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from kin.urdf.errors import UrdfError, UrdfWarning

#: at most this many visual meshes are kept (as a robot file's [visual] table holds)
MAX_VISUALS = 1000


def visual_meshes(sc, chain, package_dirs=None) -> tuple[tuple, str]:
    """(meshes, source) of the <visual> meshes of ``sc``'s links on the finished ``chain`` (same FK)."""
    from kin.geometry import body_frames
    from kin.urdf.collision import _scale, resolve_mesh
    from kin.visual import MAX_VISUAL_MESHES, MESH_SUFFIXES, VisualMesh, pose_placement

    F0 = body_frames(chain, np.zeros(chain.n))[0]
    inv = [np.linalg.inv(F) for F in F0]
    out, skipped, other, first = [], [], 0, ""
    for lk in sc.links:
        for i, v in enumerate(lk.visuals):
            g = v.geometry
            if g is None or g.mesh is None:
                other += g is not None
                continue
            where = f"link {lk.name!r} visual {i} mesh {g.mesh.filename!r}"
            try:
                file = resolve_mesh(g.mesh.filename or "", sc.path, package_dirs, where)
                if file.suffix.lower() not in MESH_SUFFIXES:
                    raise UrdfError(f"the format {file.suffix or '(no suffix)'} is not read by viewers; allowed: "
                                    f"{', '.join(MESH_SUFFIXES)}", sc.path, where)
                scale = _scale(g.mesh.scale, sc.path, where)
                origin = np.eye(4) if v.origin is None else np.asarray(v.origin, dtype=float)
                if not np.all(np.isfinite(origin)):
                    raise UrdfError("its <origin> holds a NaN or infinite value", sc.path, where)
            except UrdfError as e:
                skipped.append(lk.name)
                first = first or str(e)
                continue
            rgba = None
            m = v.material
            if m is not None and m.color is not None and m.color.rgba is not None:
                c = np.clip(np.asarray(m.color.rgba, dtype=float).reshape(-1)[:4], 0.0, 1.0)
                rgba = tuple(float(x) for x in c) if c.size == 4 and np.all(np.isfinite(c)) else None
            pose = pose_placement(inv[lk.body] @ lk.pose @ origin)
            out.append(VisualMesh(lk.body, str(Path(file).resolve()), pose, tuple(float(x) for x in scale), rgba,
                                  lk.name))
    if skipped:                         # one warning for them all: a URDF without its visual files is common
        links = ", ".join(dict.fromkeys(skipped))
        more = f" (and {len(skipped) - 1} more, on links {links})" if len(skipped) > 1 else ""
        warnings.warn(UrdfWarning(f"{first}{more}; visual meshes left out (drawn as the bodies' capsules)"),
                      stacklevel=3)
    if len(out) > min(MAX_VISUALS, MAX_VISUAL_MESHES):
        raise UrdfError(f"the chain's links hold {len(out)} visual meshes; at most {MAX_VISUALS} are kept", sc.path)
    if not out:
        return (), ""
    source = f"urdf: the <visual> meshes of {Path(sc.path).name} ({len(out)} mesh{'es' if len(out) > 1 else ''})"
    if other:
        source += f"; {other} box, cylinder or sphere visual(s) left out"
    if skipped:
        source += f"; left out (file missing or unread): {', '.join(dict.fromkeys(skipped))}"
    return tuple(out), source
