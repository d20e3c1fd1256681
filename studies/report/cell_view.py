"""The interactive 3-D view of a robot in its work cell (plotly): the cell's obstacles, the robot's
collision capsules (and its tool's) at a configuration, the closest approach between the robot and
the cell (or itself) marked as a line with its clearance, and a joint path animated along a slider —
the capsules, the DH frames and the closest approach follow it frame by frame.

Everything is drawn from a :class:`planning.collision.CollisionWorld` — the capsules, obstacles and
placement the collision checks use, so what is drawn is what is checked.  Obstacles are meshes:
boxes, cylinders, spheres and capsules as their shapes; a mesh obstacle as its original triangles
when the cell kept them (:attr:`planning.cell.Cell.meshes`, given as ``meshes``) and no more than
:data:`MAX_MESH_TRIANGLES`, else — like a point cloud — as the spheres that enclose it (at most
:data:`MAX_SPHERES` of them, the largest first).  Coordinates are world (cell) coordinates shown in
the robot file's length unit, rounded to 0.1 mm, which keeps a report's size in check.

The mesh helpers (:func:`capsule_mesh`, :func:`shape_mesh`, :func:`spheres_mesh`,
:func:`triangles_mesh`, :func:`robot_mesh`) return plain arrays — vertices (k, 3) and triangles
(m, 3) of vertex indices — and can be used on their own.
"""
from __future__ import annotations

import math

import numpy as np

from kin.geometry import body_frames
from studies.jointpath import densify
from studies.report.view3d import add_path_controls, frame_step

__all__ = ["cell_view", "capsule_mesh", "shape_mesh", "spheres_mesh", "triangles_mesh", "robot_mesh",
           "obstacle_mesh", "closest_segments",
           "robot_parts", "placed_parts", "contact_world", "CLOSEST", "MAX_MESH_TRIANGLES", "MAX_SPHERES",
           "MAX_ANIMATION_FRAMES", "CAPSULE_SEGMENTS"]

#: a mesh obstacle with more triangles than this is drawn as its spheres
MAX_MESH_TRIANGLES = 20_000
#: at most this many spheres of a sphere-set obstacle are drawn (the largest first)
MAX_SPHERES = 2_000
#: the path is animated in at most this many frames (evenly spaced along its joint-space length)
MAX_ANIMATION_FRAMES = 48
#: vertices around a capsule, and rings per half sphere
CAPSULE_SEGMENTS, CAPSULE_RINGS = 12, 3
#: vertices around a cylinder obstacle
CYLINDER_SEGMENTS = 32
#: triangles a mesh file of the robot's real shape keeps in a view, and frames of its animation
SHAPE_BUDGET, SHAPE_FRAMES = 1_500, 32
#: points of the tool's trace along the path
TRACE_POINTS = 240
ROBOT_COLOUR, TOOL_COLOUR, FRAME_COLOUR = "#e0a800", "#4d4d4d", "#333333"
CLEAR_COLOUR, HIT_COLOUR = "#2ca02c", "#d62728"
OBSTACLE_COLOURS = ("#8c9aa8", "#a1887f", "#7fa37f", "#9c8fb8", "#b3a17a", "#7f9fb3", "#b38a8a")


# ---- meshes ---------------------------------------------------------------------------------------------
def _frame_of(u: np.ndarray) -> np.ndarray:
    """A rotation (3, 3) whose z column is the unit vector ``u``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, u)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(u, x), u])


def _capsule_template(segments: int, rings: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit directions (k, 3), whether each vertex belongs to the top half (k,), and triangles (m, 3)
    of a capsule along +z: vertex = radius · direction + length · top · ẑ."""
    phis = [math.pi * k / (2 * rings) for k in range(1, 2 * rings)]          # polar angles of the rings
    # the equator ring appears twice: once on the top half, once on the bottom half (the cylinder between)
    half = math.pi / 2
    rows = [(p, True) for p in phis if p <= half + 1e-12] + [(p, False) for p in phis if p >= half - 1e-12]
    t = 2 * math.pi * np.arange(segments) / segments
    dirs, top = [np.array([0.0, 0.0, 1.0])], [True]
    for p, is_top in rows:
        ring = np.column_stack([math.sin(p) * np.cos(t), math.sin(p) * np.sin(t), np.full(segments, math.cos(p))])
        dirs += list(ring)
        top += [is_top] * segments
    dirs.append(np.array([0.0, 0.0, -1.0]))
    top.append(False)
    D = np.array(dirs)
    last = len(D) - 1
    tri = []
    s = np.arange(segments)
    nxt = (s + 1) % segments
    first = 1
    tri += [[0, first + a, first + b] for a, b in zip(s, nxt)]                 # the top cap's fan
    for r in range(len(rows) - 1):
        a0, a1 = 1 + r * segments, 1 + (r + 1) * segments
        for a, b in zip(s, nxt):
            tri += [[a0 + a, a1 + a, a1 + b], [a0 + a, a1 + b, a0 + b]]
    lastring = 1 + (len(rows) - 1) * segments
    tri += [[last, lastring + b, lastring + a] for a, b in zip(s, nxt)]       # the bottom cap's fan
    return D, np.array(top), np.array(tri, dtype=np.int64)


def capsule_mesh(a, b, radius: float, segments: int = CAPSULE_SEGMENTS, rings: int = CAPSULE_RINGS
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (k, 3) and triangles (m, 3) of the capsule a–b of ``radius`` (a sphere when a == b).
    Its vertices lie on the capsule's surface."""
    return _capsules(np.array([a], float), np.array([b], float), np.array([radius], float), segments, rings)


def _capsules(A: np.ndarray, B: np.ndarray, r: np.ndarray, segments: int = CAPSULE_SEGMENTS,
              rings: int = CAPSULE_RINGS) -> tuple[np.ndarray, np.ndarray]:
    """Many capsules (C rows of a, b, radius) as one mesh."""
    D, top, F = _capsule_template(segments, rings)
    C, k = len(A), len(D)
    if C == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    V = np.empty((C, k, 3))
    for c in range(C):
        axis = B[c] - A[c]
        L = float(np.linalg.norm(axis))
        R = _frame_of(axis / L) if L > 0 else np.eye(3)
        local = r[c] * D + np.outer(top * L, [0.0, 0.0, 1.0])
        V[c] = A[c] + local @ R.T
    return V.reshape(-1, 3), (F[None] + (k * np.arange(C))[:, None, None]).reshape(-1, 3)


def _box(half, pose) -> tuple[np.ndarray, np.ndarray]:
    hx, hy, hz = half
    V = np.array([[x, y, z] for x in (-hx, hx) for y in (-hy, hy) for z in (-hz, hz)])
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return V @ pose[:3, :3].T + pose[:3, 3], F


def _cylinder(radius: float, half: float, pose, segments: int = CYLINDER_SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    t = 2 * math.pi * np.arange(segments) / segments
    ring = np.column_stack([radius * np.cos(t), radius * np.sin(t), np.zeros(segments)])
    V = np.vstack([ring - [0, 0, half], ring + [0, 0, half], [[0, 0, -half], [0, 0, half]]])
    s = np.arange(segments)
    n = (s + 1) % segments
    lo, hi = 2 * segments, 2 * segments + 1
    F = np.vstack([np.column_stack([s, n, segments + n]), np.column_stack([s, segments + n, segments + s]),
                   np.column_stack([np.full(segments, lo), n, s]),
                   np.column_stack([np.full(segments, hi), segments + s, segments + n])])
    return V @ pose[:3, :3].T + pose[:3, 3], F


def shape_mesh(shape) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of a :class:`kin.geometry.Shape` (sphere, capsule, box, cylinder) in the world."""
    P = np.asarray(shape.pose, float)
    r, h, z = shape.size
    if shape.kind == "box":
        return _box((r, h, z), P)
    if shape.kind == "cylinder":
        return _cylinder(r, h, P)
    if shape.kind == "capsule":
        ends = P[:3, 3] + np.outer([-h, h], P[:3, 2])
        return capsule_mesh(ends[0], ends[1], r)
    return capsule_mesh(P[:3, 3], P[:3, 3], r, rings=4)


_ICO = None


def _icosahedron() -> tuple[np.ndarray, np.ndarray]:
    global _ICO
    if _ICO is None:
        g = (1 + math.sqrt(5)) / 2
        V = np.array([[-1, g, 0], [1, g, 0], [-1, -g, 0], [1, -g, 0], [0, -1, g], [0, 1, g], [0, -1, -g], [0, 1, -g],
                      [g, 0, -1], [g, 0, 1], [-g, 0, -1], [-g, 0, 1]], float)
        V /= np.linalg.norm(V, axis=1, keepdims=True)
        F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                      [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                      [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
        _ICO = (V, F)
    return _ICO


def spheres_mesh(S, limit: int = MAX_SPHERES) -> tuple[np.ndarray, np.ndarray, int]:
    """Spheres (K, 4: x, y, z, radius) as icosahedra (vertices on the spheres), the ``limit`` largest
    of them; returns vertices, triangles and how many spheres were drawn."""
    S = np.asarray(S, float).reshape(-1, 4)
    if len(S) > limit:
        S = S[np.sort(np.argsort(-S[:, 3], kind="stable")[:limit])]
    V0, F0 = _icosahedron()
    V = (S[:, None, :3] + S[:, 3, None, None] * V0[None]).reshape(-1, 3)
    F = (F0[None] + (len(V0) * np.arange(len(S)))[:, None, None]).reshape(-1, 3)
    return V, F, len(S)


def triangles_mesh(T) -> tuple[np.ndarray, np.ndarray]:
    """Triangles (m, 3, 3) as shared vertices and index triangles (vertices merged to 1 µm)."""
    T = np.asarray(T, float).reshape(-1, 3, 3)
    P = T.reshape(-1, 3)
    key = np.round(P * 1e6).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return P[first], inverse.reshape(-1, 3)


def obstacle_mesh(obstacle, triangles=None) -> tuple[np.ndarray, np.ndarray, str]:
    """One obstacle (:class:`kin.geometry.Obstacle`) as vertices and triangles in the world, and how it
    is drawn (for the legend): its shapes, and its original ``triangles`` (m, 3, 3; e.g.
    ``cell.meshes[name]``) when given and not too many, else its enclosing spheres."""
    parts = [shape_mesh(s) for s in obstacle.shapes]
    how = ""
    if triangles is not None and 0 < len(triangles) <= MAX_MESH_TRIANGLES:
        parts.append(triangles_mesh(triangles))
        how = f"{len(triangles):,} triangles"
    elif obstacle.spheres is not None and len(obstacle.spheres):
        V, F, k = spheres_mesh(obstacle.spheres)
        parts.append((V, F))
        total = len(obstacle.spheres)
        how = f"{total:,} spheres" if k == total else f"the {k:,} largest of {total:,} spheres"
    return (*_join(parts), how)


def _join(parts) -> tuple[np.ndarray, np.ndarray]:
    Vs, Fs, off = [], [], 0
    for V, F in parts:
        Vs.append(V)
        Fs.append(F + off)
        off += len(V)
    if not Vs:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    return np.vstack(Vs), np.vstack(Fs)


def robot_parts(geometry, bodies, shape=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The robot's ``bodies`` as one mesh in their own frames: vertices (k, 3) each in its body's DH
    frame (m), triangles (m, 3), and each vertex's body (k,).  A body drawn by ``shape`` (a list of
    :class:`studies.shape.meshes.BodyMesh`, the real shape) has its meshes, any other its capsules."""
    have = {m.body for m in shape or ()}
    capsuled = {b for b in bodies if b not in have}
    caps = [c.body for c in geometry.capsules if c.body in capsuled]
    eye = np.broadcast_to(np.eye(4), (max(bodies, default=0) + 1, 4, 4))
    V, F = robot_mesh(geometry, eye, capsuled)                  # the capsules, in the geometry's order
    parts = [(V, F)]
    which = [np.repeat(np.asarray(caps, np.int64), len(V) // max(1, len(caps)))]   # a capsule's vertices: a count
    for m in shape or ():
        if m.body in bodies and len(m.vertices):
            parts.append((np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)))
            which.append(np.full(len(m.vertices), m.body))
    V, F = _join(parts)
    return V, F, np.concatenate(which)


def placed_parts(parts, frames) -> np.ndarray:
    """The vertices of :func:`robot_parts` in the world, each moved by its body's frame (``frames``
    (n + 2, 4, 4): :func:`kin.geometry.body_frames` of one configuration)."""
    V, _, body = parts
    M = np.asarray(frames, float)[body]
    return np.einsum("kij,kj->ki", M[:, :3, :3], V) + M[:, :3, 3]


def robot_mesh(geometry, frames, bodies=None) -> tuple[np.ndarray, np.ndarray]:
    """The capsules of a :class:`kin.geometry.RobotGeometry` placed by body ``frames`` (n + 2, 4, 4;
    :func:`kin.geometry.body_frames` of one configuration), those of ``bodies`` only when given, as one
    mesh in the world."""
    caps = [c for c in geometry.capsules if bodies is None or c.body in bodies]
    if not caps:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    F = np.asarray(frames, float)
    M = F[[c.body for c in caps]]
    A = np.einsum("cij,cj->ci", M[:, :3, :3], np.array([c.a for c in caps])) + M[:, :3, 3]
    B = np.einsum("cij,cj->ci", M[:, :3, :3], np.array([c.b for c in caps])) + M[:, :3, 3]
    return _capsules(A, B, np.array([c.radius for c in caps]))


#: what the closest approach is taken over: everything the world checks, the cell's obstacles only, the
#: robot's own pairs only
CLOSEST = ("all", "cell", "self")


def contact_world(world, among: str = "all"):
    """``world`` itself (``among="all"``), or a copy of it that checks only the obstacles (``"cell"``)
    or only the robot against itself (``"self"``) — for the closest approach of one kind."""
    if among not in CLOSEST:
        raise ValueError(f"closest approach among {among!r}: one of {', '.join(CLOSEST)}")
    if among == "all":
        return world
    from planning.collision import CollisionWorld

    if among == "self":
        return CollisionWorld(world.robot, world.geometry, (), world.base, world.margin, world.name, world.cap)
    B = world.chain.n + 2
    alone = world.geometry.with_allowed((i, j) for i in range(B) for j in range(i + 1, B))
    return CollisionWorld(world.robot, alone, world.obstacles, world.base, world.margin, world.name, world.cap)


def closest_segments(world, Q, among: str = "all") -> list[dict | None]:
    """The closest approach of each configuration of ``Q`` (N, n) — over everything ``world`` checks,
    or ``among`` the cell's obstacles or the robot's own pairs only (:func:`contact_world`): its two
    points (world, m), the clearance (m; negative: the depth of a collision), the body and the other
    party (an obstacle's index ≥ 0, or −1 − body), and the sentence
    :meth:`~planning.collision.CollisionWorld.describe` gives; None where nothing comes within the
    world's cap."""
    world = contact_world(world, among)
    c = world.nearest(np.atleast_2d(np.asarray(Q, float)))
    out = []
    for k in range(len(c.clearance)):
        body = int(c.body[k])
        if body < 0:
            out.append(None)
            continue
        clear, other = float(c.clearance[k]), int(c.other[k])
        out.append({"clearance": clear, "body": body, "other": other, "point_robot": np.array(c.point_robot[k]),
                    "point_other": np.array(c.point_other[k]), "text": world.describe(body, other, clear)})
    return out


# ---- the figure ---------------------------------------------------------------------------------------
def _decimals(scale: float) -> int:
    """Decimals of the shown unit that keep 0.1 mm."""
    return max(0, math.ceil(-math.log10(1e-4 / scale) - 1e-9))


class _Units:
    def __init__(self, chain):
        self.scale = chain.length_scale
        self.unit = chain.length_unit
        self.dec = _decimals(self.scale)

    def xyz(self, P) -> tuple[list, list, list]:
        P = np.round(np.asarray(P, float).reshape(-1, 3) / self.scale, self.dec) + 0.0     # no −0
        return P[:, 0].tolist(), P[:, 1].tolist(), P[:, 2].tolist()

    def length(self, x: float) -> str:
        return f"{x / self.scale:.4g} {self.unit}"


def _mesh_dict(U: _Units, V, F) -> dict:
    x, y, z = U.xyz(V)
    return dict(x=x, y=y, z=z, i=F[:, 0].tolist(), j=F[:, 1].tolist(), k=F[:, 2].tolist())


def _robot_data(world, U: _Units, q, contact: dict | None, closest, with_faces: bool, parts) -> list[dict]:
    """The animated traces' data at ``q``: links, tool (``parts``: their :func:`robot_parts`), frames,
    closest approach; None: the capsules, placed in the world)."""
    Fr = body_frames(world.chain, np.asarray(q, float)[None], world.base)[0]
    out = []
    n = world.chain.n
    for k, bodies in enumerate((set(range(n + 1)), {n + 1})):
        V, F = robot_mesh(world.geometry, Fr, bodies) if parts is None else (placed_parts(parts[k], Fr), parts[k][1])
        d = _mesh_dict(U, V, F)
        if not with_faces:                       # a frame moves the vertices; the triangles stay
            d = {key: d[key] for key in ("x", "y", "z")}
        out.append(d)
    x, y, z = U.xyz(Fr[:, :3, 3])
    out.append(dict(x=x, y=y, z=z))
    if closest:
        if contact is None:
            out.append(dict(x=[None], y=[None], z=[None], text=[""], hovertext=[""]))
        else:
            P = np.vstack([contact["point_robot"], contact["point_other"]])
            mid = P.mean(axis=0)
            x, y, z = U.xyz(np.vstack([P, mid]))
            colour = HIT_COLOUR if contact["clearance"] <= world.margin else CLEAR_COLOUR
            label = U.length(contact["clearance"]).replace("-", "−")
            out.append(dict(x=x, y=y, z=z, text=["", "", label], hovertext=[contact["text"]] * 3,
                            line=dict(color=colour, width=7), marker=dict(color=colour, size=[4, 4, 0]),
                            textfont=dict(color=colour, size=13)))
    return out


def _scene_ranges(points: np.ndarray, margin: float) -> list[list[float]]:
    lo, hi = points.min(axis=0) - margin, points.max(axis=0) + margin
    return [[float(a), float(b)] for a, b in zip(lo, hi)]


def cell_view(world, q=None, *, path=None, meshes=None, title: str = "", closest: str | None = "all", tip=None,
              points=(), frames: int = MAX_ANIMATION_FRAMES, path_name: str = "tool path", bounds=None,
              shape="auto"):
    """A plotly figure of ``world`` (a :class:`planning.collision.CollisionWorld`): its obstacles, the
    robot's capsules and DH frames at ``q`` (SI; default: the path's first waypoint) and the closest
    approach there — a line between the two nearest points, red when they are not clear (by the
    world's margin), green when they are, labelled with the clearance; ``closest``: over everything
    the world checks (``"all"``), the cell's obstacles only (``"cell"``), the robot's own pairs only
    (``"self"``), or None (not drawn).

    ``path`` (M, n; SI): a joint path, animated over at most ``frames`` configurations evenly spaced
    along its joint-space length (``q``, when given, replaces the nearest of them, and the slider
    starts there), with the trace of ``tip`` — a point in the tool frame (m; default its origin) —
    drawn along it (``path_name`` in the legend).  ``meshes``: original triangles of mesh obstacles
    by name (``cell.meshes``); ``points``: further markers, (name, positions (K, 3) in the world (m),
    colour) each; ``bounds``: the scene's box ((3, 2) world, m; default: the robot over the path and
    the markers, with a margin — obstacles reaching out of it are cut at its faces).  ``shape``: the
    robot's real shape drawn instead of its capsules — "auto" (its meshes where known,
    :func:`studies.shape.meshes.visual_meshes` decimated to :data:`SHAPE_BUDGET` triangles a file, and
    the animation then at most :data:`SHAPE_FRAMES` frames), a list of
    :class:`~studies.shape.meshes.BodyMesh`, or None (capsules).
    """
    import plotly.graph_objects as go

    chain = world.chain
    closest = closest or None
    if closest is not None and closest not in CLOSEST:
        raise ValueError(f"closest={closest!r}: one of {', '.join(CLOSEST)} or None")
    U = _Units(chain)
    meshes = meshes or {}
    if isinstance(shape, str):
        from studies.shape.meshes import visual_meshes
        shape = visual_meshes(chain, budget=SHAPE_BUDGET) if shape == "auto" else None
    if shape:
        frames = min(frames, SHAPE_FRAMES)
    n = chain.n
    parts = (robot_parts(world.geometry, set(range(n + 1)), shape),
             robot_parts(world.geometry, {n + 1}, shape)) if shape else None
    Q = None if path is None or not len(path) else np.asarray(path, float)
    q = (Q[0] if Q is not None else np.zeros(chain.n)) if q is None else np.asarray(q, float)
    anim, active = None, 0
    if Q is not None:
        anim = densify(Q, frames) if len(Q) > 1 else Q.copy()
        if not np.array_equal(q, Q[0]):
            active = int(np.argmin(np.linalg.norm(anim - q, axis=1)))
            anim[active] = q
    shown = anim if anim is not None else q[None]
    contacts = closest_segments(world, shown, closest) if closest else [None] * len(shown)
    c0 = contacts[active]

    names = ["robot links (meshes)" if shape else "robot links (capsules)", "tool", "DH frames",
             "closest approach" + {"all": "", "cell": " to the cell", "self": " within the robot", None: ""}[closest]]
    data0 = _robot_data(world, U, q, c0, closest, with_faces=True, parts=parts)
    traces = [go.Mesh3d(**data0[0], color=ROBOT_COLOUR, opacity=0.8, flatshading=True, name=names[0],
                        showlegend=True, hoverinfo="name"),
              go.Mesh3d(**data0[1], color=TOOL_COLOUR, opacity=0.9, flatshading=True, name=names[1],
                        showlegend=True, hoverinfo="name"),
              go.Scatter3d(**data0[2], mode="lines+markers", name=names[2], line=dict(color=FRAME_COLOUR, width=3),
                           marker=dict(size=2.5, color=FRAME_COLOUR), hoverinfo="skip", visible="legendonly")]
    if closest:
        traces.append(go.Scatter3d(**{k: v for k, v in data0[3].items() if k not in ("line", "marker", "textfont")},
                                   mode="lines+markers+text", name=names[3], line=data0[3].get("line", {}),
                                   marker=data0[3].get("marker", {}), textfont=data0[3].get("textfont", {}),
                                   textposition="top center", hovertemplate="%{hovertext}<extra></extra>"))
    n_anim = len(traces)

    # the scene: the robot over every shown configuration, the tool's trace and the markers
    Fs = body_frames(chain, shown, world.base)
    roi = [robot_mesh(world.geometry, F)[0] if parts is None else np.vstack([placed_parts(p, F) for p in parts])
           for F in [*Fs[:: max(1, len(Fs) // 12)], Fs[active]]]
    tip_local = np.zeros(3) if tip is None else np.asarray(tip, float)
    if Q is not None:
        dense = densify(Q, TRACE_POINTS) if len(Q) > 1 else Q
        Ft = body_frames(chain, dense, world.base)[:, -1]
        trace = np.einsum("kij,j->ki", Ft[:, :3, :3], tip_local) + Ft[:, :3, 3]
        roi.append(trace)
    for _, P, _ in points:
        roi.append(np.asarray(P, float).reshape(-1, 3))
    if bounds is None:
        allp = np.vstack([r for r in roi if len(r)])
        span = float(np.ptp(allp, axis=0).max())
        ranges = _scene_ranges(allp, max(0.1, 0.15 * span))
    else:
        ranges = [[float(a), float(b)] for a, b in np.asarray(bounds, float)]

    for k, ob in enumerate(world.obstacles):
        V, F, how = obstacle_mesh(ob, meshes.get(ob.name))
        if not len(V):
            continue
        label = f"{ob.name} ({ob.kind or 'obstacle'}{': ' + how if how else ''})"
        who = ", ".join(world.body_names[b] for b in sorted(ob.ignore))
        traces.append(go.Mesh3d(**_mesh_dict(U, V, F), color=OBSTACLE_COLOURS[k % len(OBSTACLE_COLOURS)],
                                opacity=0.45 if ob.spheres is None else 0.8, flatshading=True, name=label,
                                showlegend=True, hovertemplate=f"{label}" + (f"<br>may touch: {who}" if who else "")
                                + "<extra></extra>"))
    if Q is not None:
        x, y, z = U.xyz(trace)
        traces.append(go.Scatter3d(x=x, y=y, z=z, mode="lines", name=path_name, line=dict(color="#ff7f0e", width=5),
                                   hoverinfo="skip"))
    for name, P, colour in points:
        x, y, z = U.xyz(P)
        traces.append(go.Scatter3d(x=x, y=y, z=z, mode="markers", name=name,
                                   marker=dict(size=3.5, color=colour, symbol="diamond"),
                                   hovertemplate=f"%{{x:.4g}}, %{{y:.4g}}, %{{z:.4g}} {U.unit}<extra>{name}</extra>"))

    fig_frames, steps = [], []
    if anim is not None and len(anim) > 1:
        for k, qk in enumerate(anim):
            label = f"{100 * k / (len(anim) - 1):.0f}"
            d = _robot_data(world, U, qk, contacts[k], closest, with_faces=False, parts=parts)
            fr = [go.Mesh3d(**d[0]), go.Mesh3d(**d[1]), go.Scatter3d(**d[2])]
            if closest:
                fr.append(go.Scatter3d(**d[3]))
            fig_frames.append(go.Frame(name=label, data=fr, traces=list(range(n_anim))))
            steps.append(frame_step(label))
    fig = go.Figure(data=traces, frames=fig_frames)
    sc = np.array(ranges) / U.scale
    size = sc[:, 1] - sc[:, 0]
    axis = lambda i, c: dict(title=f"{c} ({U.unit})", range=sc[i].tolist())           # noqa: E731
    fig.update_layout(
        title=title or None, margin=dict(l=0, r=0, t=40 if title else 10, b=0),
        legend=dict(itemsizing="constant", x=0.01, y=0.99, bgcolor="rgba(255,255,255,0.7)"),
        scene=dict(aspectmode="manual", aspectratio=dict(zip("xyz", (size / size.max()).tolist())),
                   xaxis=axis(0, "x"), yaxis=axis(1, "y"), zaxis=axis(2, "z"),
                   camera=dict(eye=dict(x=1.0, y=-1.1, z=0.65))))
    if fig_frames:
        add_path_controls(fig, steps, active)
    return fig
