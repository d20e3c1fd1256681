"""The work cell: obstacles in the world, where the robot stands, the tool it carries, and the pairs
never checked — and :meth:`Cell.resolve`, which ties a cell to one robot.

A :class:`Cell` knows no robot: it names bodies (``"base"``, ``"tool"``, ``"link 3"``, a joint's
name) as strings.  Obstacles may have any name, a body's too (MoveIt scenes have objects called
``base``): where a cell file could mean either, it says which with ``body:`` or ``obstacle:``
(:func:`split_reference`), and messages name obstacles as ``obstacle 'base'``.

:meth:`Cell.resolve` looks the names up in a robot's chain and returns a :class:`ResolvedCell`: the
obstacles with their ``ignore`` body sets, the robot's geometry with the tool's capsules on body
n + 1 and the extra allowed pairs, the base placement, and the body pairs checked for self-collision —
everything :class:`kin.geometry.ClearanceModel` takes.

Everything is SI (m) in the *cell frame* (the world); the robot's DH frame 0 sits at
``cell.base · chain.base``.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from kin.geometry import LinkCapsule, Obstacle, RobotGeometry, body_names, default_geometry
from kin.transforms import matrix_to_rpy, rigidity_defect
from planning.errors import CellError

__all__ = ["Cell", "ResolvedCell", "TOOL_BODY", "BODY", "OBSTACLE", "body_lookup", "is_body_like", "split_reference"]

#: the body of a cell's tool capsules before :meth:`Cell.resolve` (then: n + 1)
TOOL_BODY = -1
_LINK = re.compile(r"^link\s*(\d+)$")
#: the qualifiers of a name in an ``ignore`` list or an allowed pair
BODY, OBSTACLE = "body", "obstacle"
_QUALIFIED = re.compile(r"^(body|obstacle)\s*:\s*(.*)$", re.I | re.S)


def _key(name: str) -> str:
    return " ".join(str(name).split()).casefold()


def is_body_like(name: str) -> bool:
    """True for the names every robot's bodies have: ``base``, ``tool``, ``link k`` (any case)."""
    k = _key(name)
    return k in ("base", "tool") or bool(_LINK.match(k))


def split_reference(ref: str) -> tuple[str | None, str]:
    """A name as a cell file refers to it → (:data:`BODY`, :data:`OBSTACLE` or None, the name):
    ``"obstacle:base"`` → ("obstacle", "base"), ``"body: link 3"`` → ("body", "link 3"), ``"table"`` →
    (None, "table").  One qualifier is taken off (any case, spaces around the colon ignored); the name
    is spaced as obstacle names are (runs of white space → one space, none at the ends)."""
    m = _QUALIFIED.match(" ".join(ref.split()))
    if m is None:
        return None, " ".join(ref.split())
    return m.group(1).lower(), m.group(2)


def body_lookup(chain) -> dict[str, int]:
    """Body index by name (case and spacing ignored): ``base`` 0, ``link k`` and joint k's name k,
    ``link k (name)`` as :func:`kin.geometry.body_names` prints it, ``tool`` n + 1."""
    n = chain.n
    out = {"base": 0, "tool": n + 1}
    for k, j in enumerate(chain.joints, 1):
        out[f"link {k}"] = k
        if j.name:
            out.setdefault(_key(j.name), k)
    for k, label in enumerate(body_names(chain)):
        out.setdefault(_key(label), k)
    return out


def _valid_bodies(chain) -> str:
    return ", ".join(body_names(chain)) + " (a link by 'link k' or by its joint's name)"


@dataclass(frozen=True, eq=False)
class Cell:
    """A work cell (SI, cell frame).

    ``obstacles``: named :class:`kin.geometry.Obstacle` s (their ``ignore`` sets may already hold
    body indices; names add to them at :meth:`resolve`); ``base``: 4×4, where the robot's base
    placement sits in the cell; ``tool``: capsules of the tool in the tool frame, body
    :data:`TOOL_BODY` until resolved; ``body_pairs``: pairs of body names never checked against each
    other; ``obstacle_pairs``: (obstacle name, body name) pairs never checked; ``notes``: a line per
    obstacle saying where its spheres come from (meshes, point clouds), for reports; ``unqualified``:
    the obstacle names an allowed pair of the file named without ``obstacle:`` (:meth:`resolve` refuses
    them when the robot has a body of that name: the pair could mean either); ``path``: the
    file read, if any; ``length_unit``: the file's (values here are SI); ``source``: what the cell was
    read from when not a file (for messages); ``meshes``: the triangles (k, 3, 3) of each mesh obstacle
    by name, placed in the cell (m, float32, read-only) — what its spheres enclose, kept for drawing;
    ``tcp``: the tool centre point the file's ``[[tool]] tcp`` sets (4×4, SI, in the robot file's tool
    frame, read-only), or None — :meth:`with_tcp` gives a robot that uses it.
    """

    name: str
    obstacles: tuple[Obstacle, ...] = ()
    base: np.ndarray = field(default_factory=lambda: np.eye(4))
    tool: tuple[LinkCapsule, ...] = ()
    body_pairs: tuple[tuple[str, str], ...] = ()
    obstacle_pairs: tuple[tuple[str, str], ...] = ()
    notes: dict[str, str] = field(default_factory=dict)
    unqualified: frozenset[str] = frozenset()
    path: Path | None = None
    length_unit: str = "m"
    source: str = ""
    meshes: dict[str, np.ndarray] = field(default_factory=dict)
    tcp: np.ndarray | None = None

    def __post_init__(self):
        where = self.where
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        object.__setattr__(self, "tool", tuple(self.tool))
        object.__setattr__(self, "body_pairs", tuple((str(a), str(b)) for a, b in self.body_pairs))
        object.__setattr__(self, "obstacle_pairs", tuple((str(a), str(b)) for a, b in self.obstacle_pairs))
        object.__setattr__(self, "notes", dict(self.notes))
        object.__setattr__(self, "unqualified", frozenset(self.unqualified))
        meshes = {}
        for ob_name, T in self.meshes.items():
            T = np.array(T, dtype=np.float32).reshape(-1, 3, 3)
            T.setflags(write=False)
            meshes[str(ob_name)] = T
        object.__setattr__(self, "meshes", meshes)
        B = np.array(self.base, dtype=float)
        if B.shape != (4, 4) or not np.all(np.isfinite(B)) or rigidity_defect(B) > 1e-6:
            raise CellError(f"{where}: the robot's placement must be a finite rigid 4×4 transform")
        B.setflags(write=False)
        object.__setattr__(self, "base", B)
        if self.tcp is not None:
            T = np.array(self.tcp, dtype=float)
            if T.shape != (4, 4) or not np.all(np.isfinite(T)) or rigidity_defect(T) > 1e-6:
                raise CellError(f"{where}: the tool centre point (tcp) must be a finite rigid 4×4 transform")
            T.setflags(write=False)
            object.__setattr__(self, "tcp", T)
        seen: set[str] = set()
        for k, ob in enumerate(self.obstacles, 1):
            if not isinstance(ob, Obstacle):
                raise CellError(f"{where}: obstacle {k} is a {type(ob).__name__}, not a kin.geometry.Obstacle")
            if ob.name in seen:
                raise CellError(f"{where}: obstacle {k}: the name {ob.name!r} is used twice; names must be unique")
            seen.add(ob.name)
        for ob_name, _ in self.obstacle_pairs:
            if ob_name not in seen:
                raise CellError(f"{where}: allowed pair names obstacle {ob_name!r}, which the cell does not have")
        for ob_name in self.unqualified:
            if ob_name not in seen:
                raise CellError(f"{where}: an allowed pair names obstacle {ob_name!r}, which the cell does not have")
        for ob_name in self.meshes:
            if ob_name not in seen:
                raise CellError(f"{where}: a mesh is given for obstacle {ob_name!r}, which the cell does not have")

    # ---- what it holds ------------------------------------------------------------------------
    @property
    def where(self) -> str:
        """The file (or what the cell was read from), else the cell's name, for messages."""
        return str(self.path) if self.path is not None else (self.source or self.name or "cell")

    def obstacle(self, name: str) -> Obstacle:
        """The obstacle named ``name``."""
        for ob in self.obstacles:
            if ob.name == name:
                return ob
        raise CellError(f"{self.where}: no obstacle {name!r}; obstacles: {', '.join(o.name for o in self.obstacles)}")

    @property
    def n_primitives(self) -> int:
        """Shapes and spheres over all obstacles."""
        return sum(ob.n_primitives for ob in self.obstacles)

    @property
    def over_estimate(self) -> float:
        """The largest over-estimate of any obstacle (m)."""
        return max((ob.over_estimate for ob in self.obstacles), default=0.0)

    def summary(self) -> list[str]:
        """One line per obstacle (kind, primitives, over-estimate, who may touch it) and per tool shape."""
        touch: dict[str, list[str]] = {}
        for ob_name, body in self.obstacle_pairs:
            touch.setdefault(ob_name, []).append(body)
        return self._lines(touch, self.body_pairs)

    def _lines(self, touch: dict[str, list[str]], never: tuple[tuple[str, str], ...]) -> list[str]:
        out = [f"cell {self.name!r}: {len(self.obstacles)} obstacles, {self.n_primitives} primitives, "
               f"tool {len(self.tool)} shapes"]
        for ob in self.obstacles:
            line = f"  obstacle {ob.name!r}: {ob.kind or 'obstacle'}, {ob.n_primitives} primitive(s)"
            if ob.over_estimate >= 5e-5:
                line += f", its enclosure stands out ≤ {ob.over_estimate * 1000:.1f} mm"
            if ob.name in self.notes:
                line += f" ({self.notes[ob.name]})"
            if touch.get(ob.name):
                line += f"; may touch: {', '.join(touch[ob.name])}"
            out.append(line)
        for c in self.tool:
            shape = f"sphere radius {c.radius * 1000:.1f} mm" if c.length == 0 else \
                f"capsule radius {c.radius * 1000:.1f} mm, length {c.length * 1000:.1f} mm"
            out.append(f"  tool shape {c.name or 'tool'!r}: {shape}")
        if self.tcp is not None:
            xyz = " ".join(f"{v * 1000:.6g}" for v in self.tcp[:3, 3])
            rpy = " ".join(f"{math.degrees(v):.6g}" for v in matrix_to_rpy(self.tcp[:3, :3]))
            out.append(f"  tool centre point (tcp): xyz {xyz} mm, rpy {rpy}° in the robot file's tool frame")
        if never:
            out.append("  never checked against each other: " + "; ".join(f"{a} – {b}" for a, b in never))
        return out

    # ---- tying it to a robot ------------------------------------------------------------------
    def with_tcp(self, robot):
        """``robot`` (a :class:`kin.Robot`) with the cell's tool centre point (:func:`kin.tcp.with_tcp`):
        FK, IK and goal poses are then about that point.  ``robot`` itself when the cell has no
        ``tcp`` or the robot already carries one of its own (``kin.with_tcp``, ``--tcp``): that one wins."""
        if self.tcp is None or getattr(robot, "tcp", None) is not None:
            return robot
        from kin.tcp import with_tcp
        return with_tcp(robot, self.tcp)

    def resolve(self, robot, geometry: RobotGeometry | None = None) -> "ResolvedCell":
        """The cell for one robot (a :class:`kin.Robot` or a chain): body names looked up, the tool's
        capsules put on body n + 1, obstacles given their ``ignore`` sets.

        ``geometry``: the robot's capsules (default: the robot's own, :attr:`kin.Robot.geometry`, or
        the default along the DH offsets).  Raises :class:`CellError` for a body name the robot does
        not have (listing the valid ones), a pair of one body with itself, or an allowed pair that names,
        without ``obstacle:`` or ``body:``, an obstacle that has the name of one of its bodies.
        """
        chain = getattr(robot, "chain", robot)
        if geometry is None:
            geometry = getattr(robot, "geometry", None) if hasattr(robot, "chain") else None
            if geometry is None:
                geometry = chain.geometry if getattr(chain, "geometry", None) is not None else default_geometry(chain)
        n = chain.n
        lookup = body_lookup(chain)
        where = self.where

        def body(name: str, context: str) -> int:
            k = lookup.get(_key(name))
            if k is None:
                raise CellError(f"{where}: {context}: {name!r} is not a body of {chain.name}; bodies: "
                                f"{_valid_bodies(chain)}")
            return k

        for ob_name in sorted(self.unqualified):
            if _key(ob_name) in lookup:
                raise CellError(f"{where}: [allow]: {ob_name!r} is both obstacle {ob_name!r} and the body "
                                f"{body_names(chain)[lookup[_key(ob_name)]]} of {chain.name}; write "
                                f"'obstacle:{ob_name}' or 'body:{ob_name}'")
        for ob in self.obstacles:
            bad = sorted(b for b in ob.ignore if not 0 <= b <= n + 1)
            if bad:
                raise CellError(f"{where}: obstacle {ob.name!r}: ignore holds body {bad[0]}; {chain.name} has "
                                f"bodies 0 … {n + 1}")
        ignore: dict[str, set[int]] = {ob.name: set(ob.ignore) for ob in self.obstacles}
        for ob_name, b in self.obstacle_pairs:
            ignore[ob_name].add(body(b, f"obstacle {ob_name!r} may touch"))
        pairs = set()
        for a, b in self.body_pairs:
            i, j = body(a, f"allowed pair [{a!r}, {b!r}]"), body(b, f"allowed pair [{a!r}, {b!r}]")
            if i == j:
                raise CellError(f"{where}: allowed pair [{a!r}, {b!r}] names body {i} twice")
            pairs.add((min(i, j), max(i, j)))
        tool = tuple(replace(c, body=n + 1) for c in self.tool)
        tcp = getattr(robot, "tcp", None)       # kin.with_tcp moved the tool frame; the cell's tool stays put
        if tcp is not None and tool:
            inv = np.linalg.inv(np.asarray(tcp, dtype=float))
            at = lambda p: tuple(float(x) for x in (inv @ [*p, 1.0])[:3])  # noqa: E731
            tool = tuple(replace(c, a=at(c.a), b=at(c.b)) for c in tool)
        source = geometry.source + (" + cell tool" if tool else "")
        geom = RobotGeometry(tuple(geometry.capsules) + tool, geometry.allowed | frozenset(pairs), source,
                             geometry.radius, geometry.over_estimate, geometry.hulls)
        obstacles = tuple(replace(ob, ignore=frozenset(ignore[ob.name])) for ob in self.obstacles)
        return ResolvedCell(self, chain, geom, obstacles, self.base, tuple(geom.checked_pairs(n)))


@dataclass(frozen=True, eq=False)
class ResolvedCell:
    """A cell tied to one robot (SI): what a clearance model needs.

    ``geometry``: the robot's capsules plus the cell's tool capsules (body n + 1), its allowed pairs
    plus the cell's; ``obstacles``: the cell's, each with ``ignore`` = the bodies allowed to touch it;
    ``base``: the robot's placement in the cell (4×4; body 0 is ``base · chain.base``);
    ``self_pairs``: the body pairs (i < j) checked against each other.
    """

    cell: Cell
    chain: object
    geometry: RobotGeometry
    obstacles: tuple[Obstacle, ...]
    base: np.ndarray
    self_pairs: tuple[tuple[int, int], ...]

    @property
    def body_names(self) -> tuple[str, ...]:
        return body_names(self.chain)

    def obstacle_pairs(self) -> list[tuple[int, int]]:
        """(body, obstacle index) pairs checked: every body holding a capsule against every obstacle
        that does not ignore it."""
        bodies = self.geometry.bodies()
        return [(b, k) for k, ob in enumerate(self.obstacles) for b in bodies if b not in ob.ignore]

    def describe(self) -> list[str]:
        """Lines for reports: the cell's summary, then who is checked against what."""
        names = self.body_names
        touch = {ob.name: [names[b] for b in sorted(ob.ignore)] for ob in self.obstacles}
        extra = sorted(self.geometry.allowed)
        out = self.cell._lines(touch, tuple((names[i], names[j]) for i, j in extra))
        out.append(f"  self-collision pairs checked: {len(self.self_pairs)}; body–obstacle pairs checked: "
                   f"{len(self.obstacle_pairs())}")
        if self.cell.over_estimate >= 5e-5:
            out.append(f"  obstacle enclosures stand out by at most {self.cell.over_estimate * 1000:.1f} mm")
        return out
