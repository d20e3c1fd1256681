"""The collision geometry of an imported URDF: each <collision> element of a link fixed to a body of
the chain becomes capsules on that body (:mod:`kin.geometry.enclose`), with its over-estimate.

* **Bodies** (:mod:`kin.urdf.read`). A link belongs to body 0 (the base link and what is fixed to
  it), to body k (moved by the chain's joint k, with the links fixed to it in any branch) or to the
  tool (every link below the last joint's own link: through fixed joints, and through joints off
  the chain held at stated values — a gripper's fingers).  The DH frame of a body is fixed in its
  links, so a collision origin C of a link whose frame is L (both at q = 0, base-link frame) sits at
  F⁻¹·L·C in the body's frame F.  Links moved by joints off the chain that cannot be held (not below
  the last joint) ride on no body and are left out; the geometry's ``source`` names them, and the
  held joints with their values.
* **Shapes.** A sphere is a capsule; a box and a cylinder are enclosed by one capsule, a mesh by up to
  ``max_capsules`` (:mod:`kin.geometry.meshfit`, ``search`` "fast" or "exhaustive"); a cylinder with
  a sphere of its radius on each end — how :func:`kin.urdf.chain_to_urdf` writes a capsule — is read
  back as that capsule, exactly.  The over-estimate stated is the largest of all elements', each mesh's
  refined only where it could exceed the others'.
* **Meshes** are read with trimesh, scaled by the element's ``scale``: a plain path is relative to the
  URDF's directory, ``file://`` is an absolute path, ``package://NAME/REST`` is REST inside the
  directory given for NAME in ``package_dirs``, else inside the nearest directory above the URDF file
  that is named NAME (how ROS packages are laid out).  Nothing is fetched from a network: other
  schemes are refused.  A file beyond :data:`MAX_MESH_BYTES` or a mesh beyond
  :data:`MAX_MESH_TRIANGLES` is refused; one beyond :data:`SPLIT_TRIANGLES` gets a single capsule.
* **Sizes** are those a robot file holds: a sphere's, box's or cylinder's dimensions from 1 nm to
  10 km, mesh vertices (scaled) and collision origins within 10 km.

Every problem is one :class:`~kin.urdf.errors.UrdfError` naming the file, the link and the element.
"""
from __future__ import annotations

import math
from pathlib import Path
from urllib.parse import unquote, urlparse

import numpy as np

from kin.robotfile import MAX_LENGTH, MIN_LENGTH
from kin.urdf.errors import UrdfError

#: a mesh file larger than this is refused (bytes)
MAX_MESH_BYTES = 64 * 2 ** 20
#: a mesh with more triangles than this is refused
MAX_MESH_TRIANGLES = 1_000_000
#: a mesh with more triangles than this is enclosed by one capsule (the search for cuts would be slow)
SPLIT_TRIANGLES = 50_000
#: at most this many <collision> elements on the chain's links
MAX_ELEMENTS = 1000
CAPSULE_TOL = 1e-9       # relative: a cylinder's end and a sphere's centre this close are one point


#: hull points are written to 1 µm: the radius grows by the most that moves a point
HULL_ROUNDING = math.sqrt(3) / 2 * 1e-6


def resolve_mesh(filename: str, urdf_path: str, package_dirs=None, where: str | None = None) -> Path:
    """The file a <mesh filename="…"> names (see the module docstring); UrdfError (naming ``where``,
    the element) when it is not a readable file."""
    urdf_dir = Path(urdf_path).resolve().parent
    where = where or f"mesh {filename!r}"
    if "://" in filename:
        url = urlparse(filename)
        if url.scheme == "file":
            path = Path(unquote(url.path))
        elif url.scheme == "package":
            name, rest = url.netloc, unquote(url.path).lstrip("/")
            dirs = dict(package_dirs or {})
            if name in dirs:
                root = Path(dirs[name])
            else:
                root = next((d for d in urdf_dir.parents if d.name == name), None)
                if urdf_dir.name == name:
                    root = urdf_dir
                if root is None:
                    raise UrdfError(f"package {name!r} is neither a directory above the URDF file nor given "
                                    f"(rmt import-urdf --package {name}=DIR)", urdf_path, where)
            path = root / rest
        else:
            raise UrdfError(f"the scheme {url.scheme}:// is not read (only package://, file:// and file paths; "
                            "nothing is fetched from a network)", urdf_path, where)
    else:
        path = Path(filename)
        if not path.is_absolute():
            path = urdf_dir / path
    if not path.is_file():
        raise UrdfError(f"no such mesh file {str(path)!r}", urdf_path, where)
    size = path.stat().st_size
    if size > MAX_MESH_BYTES:
        raise UrdfError(f"the mesh file is {size / 2 ** 20:.0f} MB; at most {MAX_MESH_BYTES // 2 ** 20} MB are read",
                        urdf_path, where)
    return path


def load_mesh(path: Path, urdf_path: str, where: str) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and triangles (F, 3) of a mesh file, read with trimesh (a scene's meshes
    placed and joined)."""
    import logging

    import trimesh

    quiet = logging.getLogger("trimesh")
    level = quiet.level
    quiet.setLevel(logging.CRITICAL)
    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
        V = np.asarray(mesh.vertices, dtype=float)
        F = np.asarray(mesh.faces, dtype=np.int64)
    except Exception as e:          # any reader's error: an unreadable mesh
        raise UrdfError(f"cannot read the mesh file {str(path)!r} ({type(e).__name__}: "
                        f"{str(e).strip()[:200] or 'unreadable'})", urdf_path, where) from None
    finally:
        quiet.setLevel(level)
    if F.ndim != 2 or F.shape[1] != 3 or len(F) == 0:
        raise UrdfError(f"the mesh file {str(path)!r} holds no triangles", urdf_path, where)
    if len(F) > MAX_MESH_TRIANGLES:
        raise UrdfError(f"the mesh has {len(F)} triangles; at most {MAX_MESH_TRIANGLES} are read", urdf_path, where)
    if F.min() < 0 or F.max() >= len(V):
        raise UrdfError(f"the mesh file {str(path)!r} has triangles referring to missing vertices", urdf_path, where)
    if not np.all(np.isfinite(V)):
        raise UrdfError(f"the mesh file {str(path)!r} has NaN or infinite vertices", urdf_path, where)
    return V, F


def _snap(p) -> tuple[float, float, float]:
    """Coordinates below 1 nm are rounding noise: 0 (as a robot file reads them)."""
    return tuple(0.0 if abs(x) < 1e-9 else float(x) for x in p)  # type: ignore[return-value]


def _scale(scale, urdf_path: str, where: str) -> np.ndarray:
    s = np.ones(3) if scale is None else np.broadcast_to(np.asarray(scale, dtype=float), (3,)).copy()
    if not np.all(np.isfinite(s)) or np.any(s == 0):
        raise UrdfError(f"the mesh scale {s.tolist()} must be finite and non-zero", urdf_path, where)
    return s


def _positive(x, what: str, urdf_path: str, where: str) -> float:
    v = float(x) if x is not None else math.nan
    if not (math.isfinite(v) and v > 0):
        raise UrdfError(f"the {what} {x!r} must be a positive finite number (m)", urdf_path, where)
    if not MIN_LENGTH <= v <= MAX_LENGTH:
        raise UrdfError(f"the {what} {v:g} m; allowed: {MIN_LENGTH:g} to {MAX_LENGTH:g} m (1 nm to 10 km)",
                        urdf_path, where)
    return v


def _capsules_of_pairs(elements, urdf_path: str):
    """Find cylinders with a sphere of the same radius centred on each end: (cylinder index, sphere
    indices, a, b, radius) — capsules as :func:`kin.urdf.chain_to_urdf` writes them."""
    out, used = [], set()
    spheres = [(i, T[:3, 3], g.sphere.radius) for i, (T, g) in enumerate(elements) if g.sphere is not None]
    for i, (T, g) in enumerate(elements):
        if g.cylinder is None or g.cylinder.radius is None or g.cylinder.length is None:
            continue
        r, h = float(g.cylinder.radius), float(g.cylinder.length) / 2
        ends = [T[:3, 3] - h * T[:3, 2], T[:3, 3] + h * T[:3, 2]]
        tol = CAPSULE_TOL * max(1.0, 2 * h, r)
        match = []
        for end in ends:
            hit = next((j for j, c, rs in spheres if j not in used and j not in match and rs is not None
                        and abs(float(rs) - r) <= tol and np.linalg.norm(c - end) <= tol), None)
            match.append(hit)
        if None not in match:
            used.update(match)
            a, b = (elements[j][0][:3, 3] for j in match)
            out.append((i, tuple(match), a, b, r))
    return out


def collision_geometry(sc, frames: list[np.ndarray], max_capsules: int = 3, package_dirs=None,
                       search: str = "fast", progress=None, hulls: float | None = None):
    """The :class:`~kin.geometry.RobotGeometry` of the <collision> elements of the chain's links;
    ``frames``: the poses at q = 0 (base-link frame) of bodies 0 … n + 1 (DH frames 0 … n, then the
    tip).  None when the chain's links have no collision elements.  ``search``: how meshes are cut
    (:mod:`kin.geometry.meshfit`); ``progress(stage, done, total)`` is called as meshes are fitted.
    ``hulls`` (m): besides the capsules, every element as a hull (:class:`kin.geometry.LinkHull`) — a
    mesh's convex hull thinned to within ``hulls`` (:func:`kin.geometry.hull_fit.thin_hull`), a box,
    cylinder, sphere or capsule as its capsules — points to 1 µm, the radius covering both."""
    from kin.geometry import LinkCapsule, LinkHull, RobotGeometry
    from kin.geometry.enclose import enclose_box, enclose_cylinder

    path = sc.path
    count = sum(len(lk.collisions) for lk in sc.links)
    if count == 0:
        return None
    if count > MAX_ELEMENTS:
        raise UrdfError(f"the chain's links hold {count} <collision> elements; at most {MAX_ELEMENTS} are read", path)
    inv = [np.linalg.inv(F) for F in frames]
    parts: list = []                    # (link, body, pose in the body frame, Enclosure or mesh key)
    over = 0.0
    kinds = {"mesh": 0, "box": 0, "cylinder": 0, "sphere": 0, "capsule": 0}
    meshes: dict[tuple, tuple] = {}     # key → (file, scale, where)
    for lk in sc.links:
        place = inv[lk.body] @ lk.pose                  # link frame → body frame
        elements = [(np.eye(4) if c.origin is None else np.asarray(c.origin, dtype=float), c.geometry)
                    for c in lk.collisions]
        for i, (T, g) in enumerate(elements):
            where = f"link {lk.name!r} collision {i}"
            if g is None or not np.all(np.isfinite(T)):
                raise UrdfError("its <origin> holds a NaN or infinite value, or it has no <geometry>", path, where)
            if np.abs(T[:3, 3]).max() > MAX_LENGTH:
                raise UrdfError(f"its <origin> xyz {T[:3, 3].tolist()}; allowed: at most {MAX_LENGTH:g} m (10 km) in "
                                "each coordinate", path, where)
        done = set()
        for i, sphere_ids, a, b, r in _capsules_of_pairs(elements, path):
            r = _positive(r, "capsule radius", path, f"link {lk.name!r} collision {i}")
            parts.append((lk, None, None, ((place[:3, :3] @ a + place[:3, 3], place[:3, :3] @ b + place[:3, 3], r),)))
            done.update((i, *sphere_ids))
            kinds["capsule"] += 1
        for i, (T, g) in enumerate(elements):
            if i in done:
                continue
            where = f"link {lk.name!r} collision {i}"
            if g.sphere is not None:
                r = _positive(g.sphere.radius, "sphere radius", path, where)
                c = place[:3, :3] @ T[:3, 3] + place[:3, 3]
                parts.append((lk, None, None, ((c, c, r),)))
                kinds["sphere"] += 1
                continue
            if g.box is not None:
                size = np.asarray(g.box.size, dtype=float).reshape(-1)
                if size.shape != (3,):
                    raise UrdfError(f"the box size {size.tolist()} must be three lengths", path, where)
                enc = enclose_box([_positive(x, "box size", path, where) for x in size], place @ T)
                kinds["box"] += 1
            elif g.cylinder is not None:
                enc = enclose_cylinder(_positive(g.cylinder.radius, "cylinder radius", path, where),
                                       _positive(g.cylinder.length, "cylinder length", path, where), place @ T)
                kinds["cylinder"] += 1
            elif g.mesh is not None:
                where = f"{where} mesh {g.mesh.filename!r}"
                file = resolve_mesh(g.mesh.filename or "", path, package_dirs, where)
                scale = _scale(g.mesh.scale, path, where)
                key = (str(file), tuple(scale))
                meshes.setdefault(key, (file, scale, where))
                parts.append((lk, key, place @ T, None))
                kinds["mesh"] += 1
                continue
            else:
                raise UrdfError("its <geometry> holds no box, cylinder, sphere or mesh", path, where)
            over = max(over, enc.over_estimate)
            parts.append((lk, None, None, tuple((c.a, c.b, c.radius) for c in enc.capsules)))
    fits = _fit_meshes(meshes, path, max_capsules, search, progress)
    floor = max([over, *(f.lower for f in fits.values())])     # only the largest over-estimate is stated
    for i, (key, f) in enumerate(fits.items()):
        over = max(over, f.over_estimate(floor))
        if progress is not None:
            progress("stating the over-estimate", i + 1, len(fits))
    caps, hull_list = [], []
    thin = {}
    if hulls is not None:
        from kin.geometry.hull_fit import thin_hull
        for i, (key, f) in enumerate(fits.items()):
            thin[key] = thin_hull(f.tris.reshape(-1, 3), hulls)
            if progress is not None:
                progress("thinning the meshes' hulls", i + 1, len(fits))
    for lk, key, pose, shapes in parts:
        if key is not None:
            shapes = tuple((m.a, m.b, m.radius) for m in (c.moved(pose) for c in fits[key].capsules))
            if hulls is not None:
                P, r = thin[key]
                hull_list.append(LinkHull(lk.body, np.round(P @ pose[:3, :3].T + pose[:3, 3], 6),
                                          r + HULL_ROUNDING, lk.name))
        elif hulls is not None:
            hull_list += [LinkHull(lk.body, np.array([a, b]), float(r), lk.name) for a, b, r in shapes]
        for a, b, r in shapes:
            caps.append(LinkCapsule(lk.body, _snap(a), _snap(b), float(r), lk.name))
    for c in caps:
        far = max(abs(x) for x in (*c.a, *c.b))
        if far > MAX_LENGTH or not MIN_LENGTH <= c.radius <= MAX_LENGTH:
            raise UrdfError(f"a capsule enclosing its collision elements reaches {far:g} m from the body frame with "
                            f"radius {c.radius:g} m; allowed: at most {MAX_LENGTH:g} m, radius {MIN_LENGTH:g} to "
                            f"{MAX_LENGTH:g} m", path, f"link {c.name!r}")
    plural = {"mesh": "meshes", "box": "boxes"}
    what = ", ".join(f"{v} {k if v == 1 else plural.get(k, k + 's')}" for k, v in kinds.items() if v)
    over = 0.0 if over == 0.0 else max(over, MIN_LENGTH)       # a robot file holds 0 or at least 1 nm
    source = (f"urdf: the <collision> elements of {Path(path).name} ({what}), capsules enclosing each "
              f"(over-estimate {over * 1000:.1f} mm)")
    if sc.held:
        source += "; the tool carries joints off the chain held at " + sc.held_text
    if sc.loose_links:
        source += f"; left out, moved by joints off the chain: {', '.join(sc.loose_links)}"
    if hull_list:
        source += f"; hulls of every element (meshes' thinned to within {hulls * 1000:g} mm)"
    return RobotGeometry(tuple(caps), frozenset(), source, None, over, tuple(hull_list))


def _fit_meshes(meshes: dict, path: str, max_capsules: int, search: str, progress) -> dict:
    """Each distinct mesh (file and scale) read and fitted (:func:`kin.geometry.meshfit.fit_mesh`)."""
    from kin.geometry.meshfit import fit_mesh

    fits = {}
    for i, (key, (file, scale, where)) in enumerate(meshes.items()):
        V, F = load_mesh(file, path, where)
        V = V * scale
        far = float(np.abs(V).max())
        if far > MAX_LENGTH:
            raise UrdfError(f"the mesh's vertices (scale {scale.tolist()}) reach {far:g} m from its origin; allowed: "
                            f"at most {MAX_LENGTH:g} m (10 km) in each coordinate", path, where)
        fits[key] = fit_mesh(V, F, max_capsules if len(F) <= SPLIT_TRIANGLES else 1, search=search)
        if progress is not None:
            progress("enclosing collision meshes", i + 1, len(meshes))
    return fits
