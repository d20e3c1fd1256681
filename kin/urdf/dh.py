"""DH parameters of a general serial chain from its joint axes (the common-normal construction).

Given the joint axes as lines at q = 0 (a point and a unit direction each, in the base link's frame)
and the tip pose, build standard (distal) DH frames 0…n, each fixed in its link:

* z_{i-1} is joint i's axis, with the URDF's direction (so q turns the same way);
* frame i (1 ≤ i < n) sits where the common normal of axes i and i+1 meets axis i+1; x_i lies along
  that normal.  Where the normal is not unique the choice is documented:

  - skew axes: the unique common normal;
  - intersecting axes: the normal through the intersection point, x_i ∥ z_{i-1} × z_i;
  - parallel axes (|z_{i-1} × z_i| < ``PARALLEL_TOL``): the normal through o_{i-1}, so d_i = 0;
  - coincident axes: x_i = x_{i-1} and o_i = o_{i-1} (a_i = d_i = 0).

  Of the two directions ±x_i the one with |θ_i offset| ≤ π/2 is taken (a_i may then be negative,
  as in Universal Robots' tables);
* frame 0 sits on axis 1 at the foot of the base link's origin, x_0 along the base link's x axis
  (its y axis if x is along the joint axis) made perpendicular to z_0;
* frame n: z_n = z_{n-1} (α_n = 0, a_n = 0), origin on axis n level with the tip (d_n), x_n along the
  tip's x axis (its y axis if x is along z_n) made perpendicular to z_n.

The base transform is frame 0 in the base link's frame, the tool transform the tip in frame n.  Each
DH matrix is read off F_{i-1}⁻¹·F_i and checked to have the DH form, so FK is the URDF's.  Joint
axes that are almost but not quite parallel (a URDF's 1.5708 for π/2) give a far-away common normal
and a large d; the construction stays exact, only the table looks odd (beyond the 10 km a robot
file holds, the URDF is refused: :mod:`kin.urdf.writable`, which also writes rounding noise as 0).
"""
from __future__ import annotations

import math
import re
import warnings

import numpy as np

from kin.chain import NAME_RE, Chain, Joint, Placement
from kin.urdf.errors import UrdfError, UrdfWarning
from kin.urdf.read import SerialChain, read_serial_chain

PARALLEL_TOL = 1e-12     # |sin| between consecutive axes below which they are parallel
DH_FORM_TOL = 1e-9       # largest entry of F_{i-1}^-1·F_i that the DH form cannot hold
SNAP = 1e-14             # DH angles this close to k·π/2 (rad) are snapped (lengths: kin.urdf.writable)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _perp(v: np.ndarray, z: np.ndarray) -> np.ndarray | None:
    """``v`` made perpendicular to unit ``z`` and normalised; None when v is (nearly) along z."""
    w = v - (v @ z) * z
    n = float(np.linalg.norm(w))
    return w / n if n > 1e-6 else None


def _frame(o: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    F = np.eye(4)
    x = _unit(x - (x @ z) * z)
    F[:3, 0], F[:3, 1], F[:3, 2], F[:3, 3] = x, np.cross(z, x), z, o
    return F


def _offset(x_prev: np.ndarray, x: np.ndarray, z: np.ndarray) -> float:
    """Angle about z from x_prev to x (rad)."""
    return math.atan2(float(np.cross(x_prev, x) @ z), float(x_prev @ x))


def _next_frame(F: np.ndarray, p: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Frame i from frame i-1 (on axis i) and axis i+1 (point p, unit direction u)."""
    o, x_prev, z = F[:3, 3], F[:3, 0], F[:3, 2]
    c = np.cross(z, u)
    s = float(np.linalg.norm(c))
    if s < PARALLEL_TOL:
        foot = p + ((o - p) @ u) * u           # the normal through o_{i-1}
        w = (foot - o) - ((foot - o) @ z) * z
        if np.linalg.norm(w) < 1e-12:          # coincident axes
            return _frame(o, x_prev, u)
        o_new, x = foot, _unit(w)
    else:
        w = o - p
        b, d, e = float(z @ u), float(z @ w), float(u @ w)
        o_new = p + ((e - b * d) / (s * s)) * u  # foot of the common normal on axis i+1
        x = c / s
    if abs(_offset(x_prev, x, z)) > math.pi / 2 + 1e-12:
        x = -x
    return _frame(o_new, x, u)


def _dh_of(M: np.ndarray, i: int, path: str) -> tuple[float, float, float, float]:
    """(a, alpha, d, theta) of M = Rz(θ)·Tz(d)·Tx(a)·Rx(α); refuses an M of another form."""
    theta = math.atan2(M[1, 0], M[0, 0])
    alpha = math.atan2(M[2, 1], M[2, 2])
    ct, st = math.cos(theta), math.sin(theta)
    a = M[0, 3] * ct + M[1, 3] * st
    d = M[2, 3]
    defect = max(abs(M[2, 0]), abs(M[0, 3] * st - M[1, 3] * ct))
    if defect > DH_FORM_TOL:
        raise UrdfError(f"the DH frames of joints {i} and {i + 1} are not related by a DH transform "
                        f"(defect {defect:.3g}); please report this URDF", path)
    return a, alpha, d, theta


def _snap(x: float) -> float:
    """An angle (rad) within :data:`SNAP` of a multiple of π/2 as that multiple."""
    k = round(x / (math.pi / 2))
    return k * (math.pi / 2) if abs(x - k * (math.pi / 2)) < SNAP else x


def dh_frames(points: np.ndarray, dirs: np.ndarray, tip: np.ndarray) -> list[np.ndarray]:
    """Standard DH frames 0…n (each (4, 4), base-link frame, q = 0) for axes (n, 3) + (n, 3), tip (4, 4)."""
    n = len(points)
    z0 = _unit(dirs[0])
    o0 = points[0] - (points[0] @ z0) * z0          # foot of the base origin on axis 1
    x0 = _perp(np.array([1.0, 0.0, 0.0]), z0)
    if x0 is None:
        x0 = _perp(np.array([0.0, 1.0, 0.0]), z0)
    frames = [_frame(o0, x0, z0)]
    for i in range(1, n):
        frames.append(_next_frame(frames[-1], points[i], _unit(dirs[i])))
    Fl = frames[-1]
    o, z = Fl[:3, 3], Fl[:3, 2]
    on = o + ((tip[:3, 3] - o) @ z) * z
    xn = _perp(tip[:3, 0], z)
    if xn is None:
        xn = _perp(tip[:3, 1], z)
    frames.append(_frame(on, xn, z))
    return frames


def dh_rows(points: np.ndarray, dirs: np.ndarray, tip: np.ndarray, path: str = ""):
    """The standard DH frames 0…n (:func:`dh_frames`) of axes ``points``/``dirs`` (n, 3) and ``tip`` (4, 4),
    and the DH rows (a, α, d, θ offset) between them (angles within 1e-14 rad of k·π/2 snapped to it);
    :class:`UrdfError` (naming ``path``) if two frames are not related by a DH transform."""
    frames = dh_frames(points, dirs, tip)
    rows = []
    for i, (Fa, Fb) in enumerate(zip(frames[:-1], frames[1:]), 1):
        a, alpha, d, theta = _dh_of(np.linalg.solve(Fa, Fb), i, path)
        rows.append((a, _snap(alpha), d, _snap(theta)))
    return frames, rows


def chain_from_serial(sc: SerialChain, convention: str = "standard", name: str | None = None,
                      collision: bool = True, max_capsules: int = 3, package_dirs=None, search: str = "fast",
                      progress=None, srdf=None, visual: bool = True, hulls: float | None = None) -> Chain:
    """The rmtkit chain (SI; lengths in m, angles in rad) of a URDF serial chain, same FK.

    ``convention`` is "standard" or "modified"; ``name`` defaults to the URDF robot's name made
    lower-case with every other character than [a-z0-9] turned into "_".  With ``collision`` the
    links' <collision> elements become the chain's capsules (:mod:`kin.urdf.collision`: up to
    ``max_capsules`` per mesh, cut by the ``search`` of :mod:`kin.geometry.meshfit`, ``package_dirs``
    maps package names to directories, ``progress(stage, done, total)`` hears of each mesh).  The
    links' <inertial> elements become the bodies' inertial models (:mod:`kin.urdf.inertial`).  Every
    number is one a robot file holds (:mod:`kin.urdf.writable`).  ``srdf``: a MoveIt SRDF whose disabled
    collision pairs leave body pairs unchecked (:mod:`kin.urdf.srdf`).  With ``visual`` the links'
    <visual> meshes are kept for viewers (:mod:`kin.urdf.visual`, the chain's ``visual``).  ``hulls``
    (m): the collision elements as hulls too, meshes' thinned to within it (``[[geometry.hull]]``).
    """
    if convention not in ("standard", "modified"):
        raise UrdfError(f"convention {convention!r} unknown; allowed: standard, modified", sc.path)
    points, dirs = sc.axes_at_zero()
    tip = sc.fk(np.zeros(sc.n))
    frames, rows = dh_rows(points, dirs, tip, sc.path)
    joints = [Joint(uj.type, a=a, alpha=alpha, d=d, theta=theta, limits=uj.limits, name=uj.name,
                    max_velocity=uj.max_velocity, max_torque=uj.max_torque)
              for uj, (a, alpha, d, theta) in zip(sc.joints, rows)]
    base, tool = frames[0], np.linalg.solve(frames[-1], tip)
    if name is None:
        name = re.sub(r"[^a-z0-9]+", "_", sc.robot_name.lower()).strip("_") or "imported"
    elif not NAME_RE.match(name):
        raise UrdfError(f"robot name {name!r} must match [a-z0-9_]+", sc.path)
    from dataclasses import replace

    from kin.urdf.inertial import inertial_model
    from kin.urdf.writable import chain_scale, writable
    inertias, payload, placeholders = inertial_model(sc, [*frames, tip])
    joints = [replace(j, inertia=li) for j, li in zip(joints, inertias)]
    geometry = None
    if collision:
        from kin.urdf.collision import collision_geometry
        geometry = collision_geometry(sc, [*frames, tip], max_capsules, package_dirs, search, progress, hulls)
    notes = [f"converted from the URDF file {sc.path.rsplit('/', 1)[-1]} (chain {sc.base} -> {sc.tip}) "
             "by rmt import-urdf"]
    if sc.tip_note:
        notes.append(sc.tip_note)
    if any(j.continuous for j in sc.joints):
        notes.append("continuous joints get limits of one turn [-pi, pi]")
    if sc.held:
        notes.append("the tool (body n + 1) carries the links of joints off the chain held at "
                     + sc.held_text)
    if any(li is not None for li in inertias) or payload is not None:
        note = "inertial values from its <inertial> elements (the tool's: the payload)"
        if sc.loose_masses:
            note += f", left out (moved by joints off the chain): {', '.join(sc.loose_masses)}"
        notes.append(note)
    if placeholders:
        notes.append(f"placeholder inertials (mass 0 with a tensor) left out: {', '.join(placeholders)}")
    states: dict = {}
    if srdf is not None:
        from kin.urdf.srdf import allowed_body_pairs, chain_states, disabled_link_pairs, read_root
        root = read_root(srdf)                   # read and parsed once for the pairs and the states
        disabled = disabled_link_pairs(srdf, root)
        srdf_name = str(srdf).rsplit("/", 1)[-1]
        if geometry is None:
            notes.append(f"the SRDF {srdf_name} not applied: the chain's links have no collision geometry")
        else:
            pairs, unknown = allowed_body_pairs(geometry, disabled)
            geometry = geometry.with_allowed(pairs)
            notes.append(f"self-collision pairs the SRDF {srdf_name} disables: {len(pairs)} body pair(s) not checked "
                         "(every link pair between the two disabled)")
            if unknown:
                more = " …" if len(unknown) > 8 else ""
                warnings.warn(UrdfWarning(f"{srdf}: disable_collisions names link(s) with no collision geometry on the "
                                          f"chain, ignored: {', '.join(unknown[:8])}{more}"), stacklevel=3)
        states, left_out = chain_states(srdf, sc.joints, root)
        if states:
            notes.append(f"named states from the SRDF {srdf_name}'s group_state elements: " + ", ".join(states))
        for note in left_out:
            warnings.warn(UrdfWarning(f"{srdf}: {note}"), stacklevel=3)
    chain = Chain(name=name, joints=tuple(joints), convention="standard", geometry=geometry, states=states,
                  title=f"{sc.robot_name or name}, {sc.base} to {sc.tip} (imported from URDF)", source="; ".join(notes),
                  base=_placement(base), tool=_placement(tool), payload=payload)
    chain = chain.to_modified() if convention == "modified" else chain
    chain = writable(chain, sc, chain_scale([*frames, tip]))
    if visual:
        from kin.urdf.visual import visual_meshes
        meshes, vsource = visual_meshes(sc, chain, package_dirs)
        chain = replace(chain, visual=meshes, visual_source=vsource)
    return chain


def _placement(T: np.ndarray) -> Placement:
    T = T.copy()
    T[3] = (0.0, 0.0, 0.0, 1.0)
    return Placement() if np.array_equal(T, np.eye(4)) else Placement.from_matrix(T)


def import_urdf(path: str, base: str | None = None, tip: str | None = None, convention: str = "standard",
                name: str | None = None, collision: bool = True, max_capsules: int = 3,
                package_dirs=None, search: str = "fast", progress=None, srdf=None, hulls: float | None = None) -> Chain:
    """Read a URDF file and convert the chain ``base`` → ``tip`` to an rmtkit :class:`~kin.Chain`.

    Defaults: base = the root link, tip = the only leaf link, or the link every leaf hangs from
    through fixed and mimic joints (:mod:`kin.urdf.read`; an error lists the leaves otherwise).
    Fixed joints fold into the neighbouring transforms; revolute, continuous and prismatic joints
    become DH rows in ``convention``; base and tool transforms make FK identical.  With
    ``collision`` (default) the links' <collision> elements become capsules on the chain's bodies
    (:mod:`kin.urdf.collision`; ``search`` "exhaustive" tries every cut of a mesh exactly, slower);
    ``collision=False`` skips them (and their mesh files).  ``progress(stage, done, total)`` is
    called as meshes are enclosed.  Placeholder inertials are left out with a
    :class:`~kin.urdf.errors.UrdfWarning`.  ``srdf``: a MoveIt SRDF whose ``<disable_collisions>`` pairs
    leave the body pairs all of whose link pairs they name unchecked (:mod:`kin.urdf.srdf`).  ``hulls`` (m):
    the collision elements as hulls too, meshes' thinned to within it (:mod:`kin.geometry.hulls`).
    """
    return chain_from_serial(read_serial_chain(path, base, tip), convention, name, collision, max_capsules,
                             package_dirs, search, progress, srdf, hulls=hulls)
