"""Reading work-cell files (TOML): :func:`load_cell`, :func:`parse_cell`.

The format is documented in docs/cells.md; in short::

    name = "weld cell"            # optional (default: the file's name)
    length_unit = "mm"            # "m" (default) | "mm" | "in": every length of the file
    angle_unit = "deg"            # "deg" (default) | "rad": every rpy of the file

    [robot]                       # where the robot's base placement sits in the cell (optional)
    xyz = [0, 0, 800]
    rpy = [0, 0, 0]               # fixed-axis roll-pitch-yaw, R = Rz(y)·Ry(p)·Rx(r), as robot files

    [[obstacle]]                  # any number, each with a unique name
    name = "table"
    type = "box"                  # box | sphere | cylinder | capsule | mesh | point_cloud
    size = [1200, 800, 40]        # box: full edge lengths; sphere: radius; cylinder, capsule: radius, length
    xyz = [450, 0, 780]           # the shape's centre (mesh, point cloud: the file's origin)
    rpy = [0, 0, 0]
    ignore = ["base", "link 1"]   # bodies allowed to touch it (default: none)

    [[tool]]                      # the tool's shapes, in the tool frame: capsule a, b, radius | sphere center, radius
    [allow]
    pairs = [["link 3", "tool"]]  # body–body or body–obstacle pairs never checked

Every problem raises :class:`planning.errors.CellError` in one line naming the file, the obstacle
(index and name) or table, and the field.  The file is read as data (TOML, numbers, meshes through
trimesh from memory), never evaluated.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np

from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from kin.geometry import LinkCapsule, Obstacle, Shape
from kin.transforms import make_transform, rpy_to_matrix
from planning.cell.enclose import enclose_points, enclose_triangles
from planning.cell.mesh import load_mesh
from planning.cell.model import TOOL_BODY, Cell, is_body_like
from planning.cell.points import load_points
from planning.errors import CellError

__all__ = ["load_cell", "parse_cell", "OBSTACLE_TYPES", "TOOL_TYPES", "MAX_OBSTACLES", "MAX_TOOL_SHAPES",
           "MAX_PAIRS", "MAX_CELL_ELEMENTS", "MAX_SPHERES", "DEFAULT_MAX_SPHERES", "DEFAULT_TOLERANCE", "MAX_LENGTH"]

MAX_OBSTACLES = 10_000
MAX_TOOL_SHAPES = 100
MAX_PAIRS = 10_000
#: triangles and points of all the mesh and point-cloud files of one cell together
MAX_CELL_ELEMENTS = 1_000_000
#: the most spheres a mesh may ask for (``max_spheres``), and the default
MAX_SPHERES = 20_000
DEFAULT_MAX_SPHERES = 2_000
#: the default over-estimate wanted of a mesh's spheres (m)
DEFAULT_TOLERANCE = 0.005
#: no length or coordinate of a cell may exceed this (m): a cell is smaller than 10 km
MAX_LENGTH = 1e4
MAX_NAME = 100

_TOP = {"name", "length_unit", "angle_unit", "robot", "obstacle", "tool", "allow"}
_ROBOT = {"xyz", "rpy"}
_COMMON = {"name", "type", "xyz", "rpy", "ignore"}
#: obstacle types and their own keys
OBSTACLE_TYPES = {
    "box": {"size"},
    "sphere": {"radius"},
    "cylinder": {"radius", "length"},
    "capsule": {"radius", "length"},
    "mesh": {"file", "unit", "scale", "tolerance", "max_spheres"},
    "point_cloud": {"file", "unit", "scale", "point_radius", "merge"},
}
#: tool shape types and their keys
TOOL_TYPES = {"capsule": {"name", "type", "a", "b", "radius"}, "sphere": {"name", "type", "center", "radius"}}
_ALLOW = {"pairs"}


def _is_num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _keys(label: str, table: dict, allowed: set[str]) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise CellError(f"{label}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(sorted(allowed))}")


class _Table:
    """Checked access to one TOML table's fields; lengths converted to m with ``scale``."""

    def __init__(self, label: str, table: dict, unit: str, scale: float, angle_unit: str):
        self.label, self.t, self.unit, self.scale, self.angle_unit = label, table, unit, scale, angle_unit

    def fail(self, key: str, msg: str) -> CellError:
        return CellError(f"{self.label}: {key}: {msg}")

    def number(self, key: str, default=None, positive: bool = True) -> float | None:
        """A finite number (> 0 with ``positive``), in the cell's length unit → m."""
        v = self.t.get(key, default)
        if v is None:
            raise self.fail(key, f"required (a number, {self.unit})")
        if not _is_num(v):
            raise self.fail(key, f"must be a number ({self.unit}), not {type(v).__name__} {v!r}")
        if not math.isfinite(v):
            raise self.fail(key, f"must be finite, not {v}")
        if positive and not v > 0:
            raise self.fail(key, f"must be > 0, not {v}")
        m = float(v) * self.scale
        if abs(m) > MAX_LENGTH:
            raise self.fail(key, f"{v} {self.unit} is more than the {MAX_LENGTH / 1000:g} km a cell may span")
        return m

    def numbers(self, key: str, n: int, what: str, default=None) -> list[float] | None:
        """``n`` finite numbers (raw, file units)."""
        v = self.t.get(key, default)
        if v is None:
            raise self.fail(key, f"required ({what})")
        if not (isinstance(v, list) and len(v) == n and all(_is_num(x) for x in v)):
            raise self.fail(key, f"must be {n} numbers {what}, not {v!r}")
        if not all(math.isfinite(x) for x in v):
            raise self.fail(key, f"must be finite numbers, not {v}")
        return [float(x) for x in v]

    def point(self, key: str, default=None) -> np.ndarray:
        """Three coordinates [x, y, z] in the cell's length unit → m."""
        v = np.array(self.numbers(key, 3, f"[x, y, z] ({self.unit})", default)) * self.scale
        if np.abs(v).max() > MAX_LENGTH:
            raise self.fail(key, f"{self.t[key]} is more than the {MAX_LENGTH / 1000:g} km a cell may span")
        return v

    def sizes(self, key: str) -> np.ndarray:
        """Three positive lengths in the cell's length unit → m."""
        v = self.numbers(key, 3, f"[x, y, z] ({self.unit}, each > 0)")
        if not all(x > 0 for x in v):
            raise self.fail(key, f"every size must be > 0, not {v}")
        m = np.array(v) * self.scale
        if m.max() > MAX_LENGTH:
            raise self.fail(key, f"{v} is more than the {MAX_LENGTH / 1000:g} km a cell may span")
        return m

    def pose(self) -> np.ndarray:
        """4×4 from ``xyz`` (length unit) and ``rpy`` (angle unit), both optional."""
        xyz = self.point("xyz", [0, 0, 0])
        rpy = self.numbers("rpy", 3, f"[roll, pitch, yaw] ({self.angle_unit})", [0, 0, 0])
        if max(abs(a) for a in rpy) > 1e4:
            raise self.fail("rpy", f"angles of magnitude > 1e4 {self.angle_unit} are not angles ({rpy})")
        return make_transform(rpy_to_matrix(np.array(rpy) * ANGLE_UNITS[self.angle_unit]), xyz)

    def string(self, key: str, default=None, choices=None) -> str:
        v = self.t.get(key, default)
        if v is None:
            raise self.fail(key, "required" + (f"; one of: {', '.join(choices)}" if choices else " (a string)"))
        if not isinstance(v, str):
            raise self.fail(key, f"must be a string, not {type(v).__name__} {v!r}")
        if choices is not None and v not in choices:
            raise self.fail(key, f"{v!r} unknown; allowed: {', '.join(choices)}")
        return v

    def names(self, key: str) -> list[str]:
        v = self.t.get(key, [])
        if not (isinstance(v, list) and all(isinstance(x, str) and x.strip() for x in v)):
            raise self.fail(key, f"must be a list of body names such as [\"tool\", \"link 6\"], not {v!r}")
        if len(v) > 1000:
            raise self.fail(key, f"{len(v)} names; at most 1000")
        return v


def _name(raw, label: str) -> str:
    if not isinstance(raw, str):
        raise CellError(f"{label}: name: required (a string)" if raw is None else
                        f"{label}: name: must be a string, not {type(raw).__name__} {raw!r}")
    name = " ".join(raw.split())
    if not name or len(name) > MAX_NAME or not name.isprintable():
        raise CellError(f"{label}: name {raw!r} must be 1 to {MAX_NAME} printable characters")
    if is_body_like(name):
        raise CellError(f"{label}: name {raw!r} is the name of a robot body (base, tool, link k); rename the obstacle")
    return name


def _label(where: str, what: str, k: int, table: dict) -> str:
    name = table.get("name")
    return f"{where}: {what} {k}" + (f" ({name!r})" if isinstance(name, str) else "")


def _file(f: _Table, base_dir: Path) -> Path:
    rel = f.string("file")
    if not rel.strip() or "\x00" in rel:
        raise f.fail("file", "must name a file")
    p = Path(rel)
    return p if p.is_absolute() else base_dir / p


def _file_scale(f: _Table) -> np.ndarray:
    """Metres per number of the file: ``unit`` (default the cell's) times ``scale`` (1, or 3 factors)."""
    unit = f.string("unit", f.unit, tuple(LENGTH_UNITS))
    raw = f.t.get("scale", 1.0)
    if _is_num(raw):
        s = [float(raw)] * 3
    else:
        s = f.numbers("scale", 3, "(a positive factor, or three: [sx, sy, sz])")
    if not all(math.isfinite(x) and 0 < x <= 1e6 for x in s):
        raise f.fail("scale", f"must be positive and finite (at most 1e6), not {raw!r}")
    return np.array(s) * LENGTH_UNITS[unit]


def _place(points: np.ndarray, pose: np.ndarray, f: _Table, name: str) -> np.ndarray:
    out = points @ pose[:3, :3].T + pose[:3, 3]
    if np.abs(out).max() > MAX_LENGTH:
        raise CellError(f"{f.label}: {name} reaches {np.abs(out).max():.3g} m from the cell's origin; a cell is "
                        f"smaller than {MAX_LENGTH / 1000:g} km (check unit and scale)")
    return out


class _Budget:
    def __init__(self):
        self.used = 0

    def take(self, n: int, label: str) -> None:
        self.used += n
        if self.used > MAX_CELL_ELEMENTS:
            raise CellError(f"{label}: the cell's meshes and point clouds hold more than {MAX_CELL_ELEMENTS} "
                            f"triangles and points together")


def _obstacle(f: _Table, kind: str, name: str, base_dir: Path, budget: _Budget
              ) -> tuple[Obstacle, str | None, np.ndarray | None]:
    """The obstacle, its note (meshes, point clouds) and, for a mesh, its triangles placed in the cell (m)."""
    pose = f.pose()
    if kind == "box":
        return Obstacle(name, (Shape("box", tuple(0.5 * f.sizes("size")), pose),), kind=kind), None, None
    if kind == "sphere":
        return Obstacle(name, (Shape("sphere", (f.number("radius"), 0, 0), pose),), kind=kind), None, None
    if kind in ("cylinder", "capsule"):
        r, length = f.number("radius"), f.number("length")
        return Obstacle(name, (Shape(kind, (r, 0.5 * length, 0), pose),), kind=kind), None, None
    path = _file(f, base_dir)
    scale = _file_scale(f)
    if kind == "mesh":
        tol = f.number("tolerance", DEFAULT_TOLERANCE / f.scale)
        ms = f.t.get("max_spheres", DEFAULT_MAX_SPHERES)
        if not (isinstance(ms, int) and not isinstance(ms, bool) and 1 <= ms <= MAX_SPHERES):
            raise f.fail("max_spheres", f"must be a whole number from 1 to {MAX_SPHERES}, not {ms!r}")
        T = load_mesh(path, f"{f.label}: file")
        budget.take(len(T), f.label)
        T = _place(T.reshape(-1, 3) * scale, pose, f, path.name).reshape(-1, 3, 3)
        cover = enclose_triangles(T, tol, ms)
        note = (f"{path.name}: {len(T)} triangles in {len(cover.spheres)} spheres")
        return Obstacle(name, spheres=cover.spheres, over_estimate=cover.over_estimate, kind=kind), note, T
    pr = f.number("point_radius")
    merge = f.t.get("merge", True)
    if not isinstance(merge, bool):
        raise f.fail("merge", f"must be true or false, not {merge!r}")
    P = load_points(path, f"{f.label}: file")
    budget.take(len(P), f.label)
    P = _place(P * scale, pose, f, path.name)
    cover = enclose_points(P, pr, merge)
    note = f"{path.name}: {len(P)} points in {len(cover.spheres)} spheres"
    return Obstacle(name, spheres=cover.spheres, over_estimate=cover.over_estimate, kind=kind), note, None


def _tool(f: _Table, k: int) -> LinkCapsule:
    kind = f.string("type", None, tuple(TOOL_TYPES))
    _keys(f.label, f.t, TOOL_TYPES[kind])
    raw = f.t.get("name", "tool")
    if not (isinstance(raw, str) and raw.strip() and len(raw) <= MAX_NAME and raw.isprintable()):
        raise f.fail("name", f"must be 1 to {MAX_NAME} printable characters, not {raw!r}")
    r = f.number("radius")
    if kind == "sphere":
        c = f.point("center")
        return LinkCapsule(TOOL_BODY, c, c, r, raw)
    return LinkCapsule(TOOL_BODY, f.point("a"), f.point("b"), r, raw)


def parse_cell(text: str, where: str = "cell", base_dir: str | Path | None = None) -> Cell:
    """A :class:`Cell` from the text of a cell file; ``where`` names it in messages; ``base_dir``:
    where mesh and point-cloud files are looked up (default: the current directory)."""
    base_dir = Path(".") if base_dir is None else Path(base_dir)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise CellError(f"{where}: not valid TOML ({e})") from None
    _keys(where, doc, _TOP)
    top = _Table(where, doc, "m", 1.0, "deg")
    unit = top.string("length_unit", "m", tuple(LENGTH_UNITS))
    angle_unit = top.string("angle_unit", "deg", tuple(ANGLE_UNITS))
    scale = LENGTH_UNITS[unit]
    default_name = Path(where).stem if where.endswith(".toml") else "cell"
    name = top.string("name", default_name)
    if not name.strip() or len(name) > MAX_NAME or not name.isprintable():
        raise top.fail("name", f"must be 1 to {MAX_NAME} printable characters")

    robot = doc.get("robot", {})
    if not isinstance(robot, dict):
        raise CellError(f"{where}: robot must be a table ([robot] with xyz, rpy)")
    _keys(f"{where}: [robot]", robot, _ROBOT)
    base = _Table(f"{where}: [robot]", robot, unit, scale, angle_unit).pose()

    obstacles_raw = doc.get("obstacle", [])
    if not isinstance(obstacles_raw, list) or not all(isinstance(o, dict) for o in obstacles_raw):
        raise CellError(f"{where}: obstacle must be an array of tables ([[obstacle]])")
    if len(obstacles_raw) > MAX_OBSTACLES:
        raise CellError(f"{where}: {len(obstacles_raw)} obstacles; at most {MAX_OBSTACLES}")
    obstacles, notes, pairs_ob, names, meshes = [], {}, [], {}, {}
    budget = _Budget()
    for k, t in enumerate(obstacles_raw, 1):
        label = _label(where, "obstacle", k, t)
        f = _Table(label, t, unit, scale, angle_unit)
        kind = f.string("type", None, tuple(OBSTACLE_TYPES))
        _keys(label, t, _COMMON | OBSTACLE_TYPES[kind])
        ob_name = _name(t.get("name"), label)
        if ob_name in names:
            raise CellError(f"{label}: name {ob_name!r} is already obstacle {names[ob_name]}'s; names must be unique")
        names[ob_name] = k
        ignore = f.names("ignore")
        ob, note, triangles = _obstacle(f, kind, ob_name, base_dir, budget)
        obstacles.append(ob)
        if note:
            notes[ob_name] = note
        if triangles is not None:
            meshes[ob_name] = triangles
        pairs_ob += [(ob_name, b) for b in ignore]
    for ob_name, b in pairs_ob:
        if " ".join(b.split()) in names:
            k = names[ob_name]
            raise CellError(f"{where}: obstacle {k} ({ob_name!r}): ignore: {b!r} is an obstacle; ignore lists "
                            f"robot bodies (obstacles are never checked against each other)")

    tools_raw = doc.get("tool", [])
    if not isinstance(tools_raw, list) or not all(isinstance(o, dict) for o in tools_raw):
        raise CellError(f"{where}: tool must be an array of tables ([[tool]])")
    if len(tools_raw) > MAX_TOOL_SHAPES:
        raise CellError(f"{where}: {len(tools_raw)} tool shapes; at most {MAX_TOOL_SHAPES}")
    tool = [_tool(_Table(_label(where, "tool", k, t), t, unit, scale, angle_unit), k)
            for k, t in enumerate(tools_raw, 1)]

    allow = doc.get("allow", {})
    if not isinstance(allow, dict):
        raise CellError(f"{where}: allow must be a table ([allow] with pairs)")
    _keys(f"{where}: [allow]", allow, _ALLOW)
    raw_pairs = allow.get("pairs", [])
    if not isinstance(raw_pairs, list):
        raise CellError(f"{where}: [allow]: pairs must be a list of [name, name] pairs")
    if len(raw_pairs) > MAX_PAIRS:
        raise CellError(f"{where}: [allow]: {len(raw_pairs)} pairs; at most {MAX_PAIRS}")
    body_pairs = []
    for k, p in enumerate(raw_pairs, 1):
        if not (isinstance(p, list) and len(p) == 2 and all(isinstance(x, str) and x.strip() for x in p)):
            raise CellError(f"{where}: [allow]: pair {k} must be two names [\"tool\", \"part\"], not {p!r}")
        a, b = (" ".join(x.split()) for x in p)
        if a in names and b in names:
            raise CellError(f"{where}: [allow]: pair {k} [{a!r}, {b!r}] names two obstacles; obstacles are never "
                            f"checked against each other")
        if a in names or b in names:
            pairs_ob.append((a, b) if a in names else (b, a))
        else:
            body_pairs.append((a, b))
    return Cell(name, tuple(obstacles), base, tuple(tool), tuple(body_pairs), tuple(pairs_ob), notes,
                length_unit=unit, source=where, meshes=meshes)


def load_cell(path: str | Path) -> Cell:
    """The :class:`Cell` of a cell file (TOML, see docs/cells.md); meshes and point clouds it names
    are found relative to it."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise CellError(f"{path}: no such cell file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise CellError(f"{path}: cannot read ({e})") from None
    return replace(parse_cell(text, str(path), path.parent), path=path)
