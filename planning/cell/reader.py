"""Reading work-cell files (TOML): :func:`load_cell`, :func:`parse_cell`.

The format is documented in docs/cells.md; in short::

    name = "weld cell"            # optional (default: the file's name)
    length_unit = "mm"            # "m" (default) | "mm" | "in": every length of the file
    angle_unit = "deg"            # "deg" (default) | "rad": every rpy of the file

    [robot]                       # where the robot's base placement sits in the cell (optional)
    xyz = [0, 0, 800]
    rpy = [0, 0, 0]               # fixed-axis roll-pitch-yaw, R = Rz(y)·Ry(p)·Rx(r), as robot files

    [[obstacle]]                  # any number, each with a unique name (a body's name too: "base")
    name = "table"
    type = "box"                  # box | sphere | cylinder | capsule | cone | mesh | point_cloud | compound
    size = [1200, 800, 40]        # box: full edge lengths; sphere: radius; cylinder, capsule, cone: radius, length
    xyz = [450, 0, 780]           # the shape's centre (mesh, point cloud: the file's origin)
    rpy = [0, 0, 0]
    ignore = ["base", "link 1"]   # bodies allowed to touch it (default: none)

    [[tool]]                      # the tool's shapes, in the tool frame: capsule a, b, radius | sphere center, radius
    tcp = [0, 0, 150, 0, 0, 0]    # one [[tool]] table may set the tool centre point: x, y, z [, roll, pitch, yaw]
    [allow]
    pairs = [["link 3", "tool"], ["link 6", "obstacle:base"]]  # body–body or body–obstacle pairs never checked

A mesh is a ``file`` or ``vertices`` and ``triangles`` written in the table; a compound obstacle has
``[[obstacle.part]]`` tables, each a shape of the other types placed in the obstacle's frame
(:mod:`planning.cell.obstacles`).  A name in ``ignore`` is a body; a name in a pair is the obstacle
of that name if there is one, else a body — and a name that could be both is written ``obstacle:NAME``
or ``body:NAME`` (:func:`planning.cell.model.split_reference`).

Every problem raises :class:`planning.errors.CellError` in one line naming the file, the obstacle
(index and name) or table, and the field.  The file is read as data (TOML, numbers, meshes through
trimesh from memory), never evaluated.
"""
from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np

from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from kin.errors import ArgumentError
from kin.geometry import LinkCapsule
from planning.cell.fields import MAX_LENGTH, Table, check_keys, is_num
from planning.cell.mesh import MAX_FILE_BYTES
from planning.cell.model import OBSTACLE, TOOL_BODY, Cell, is_body_like, split_reference
from planning.cell.obstacles import (
    COMMON,
    DEFAULT_MAX_SPHERES,
    DEFAULT_TOLERANCE,
    MAX_PARTS,
    MAX_SPHERES,
    OBSTACLE_TYPES,
    build_obstacle,
)
from planning.errors import CellError

__all__ = ["load_cell", "parse_cell", "cell_tcp", "OBSTACLE_TYPES", "TOOL_TYPES", "MAX_OBSTACLES", "MAX_TOOL_SHAPES",
           "MAX_PAIRS", "MAX_CELL_ELEMENTS", "MAX_CELL_PARTS", "MAX_CELL_BYTES", "MAX_PARTS", "MAX_SPHERES",
           "DEFAULT_MAX_SPHERES", "DEFAULT_TOLERANCE", "MAX_LENGTH"]

MAX_OBSTACLES = 10_000
MAX_TOOL_SHAPES = 100
MAX_PAIRS = 10_000
#: triangles and points of all the mesh and point-cloud files of one cell together
MAX_CELL_ELEMENTS = 1_000_000
#: parts of all the compound obstacles of one cell together
MAX_CELL_PARTS = 10_000
#: the largest cell file (bytes), checked before it is parsed (meshes written in it make it long)
MAX_CELL_BYTES = MAX_FILE_BYTES
MAX_NAME = 100

_TOP = {"name", "length_unit", "angle_unit", "robot", "obstacle", "tool", "allow"}
_ROBOT = {"xyz", "rpy"}
#: tool shape types and their keys
TOOL_TYPES = {"capsule": {"name", "type", "a", "b", "radius"}, "sphere": {"name", "type", "center", "radius"}}
_ALLOW = {"pairs"}


def _name(raw, label: str) -> str:
    """An obstacle's name: 1 to 100 printable characters, white space runs made one space.  Any name
    is allowed, a robot body's too (``base``): where a reference could mean either, the file says which
    (``body:`` / ``obstacle:``)."""
    if not isinstance(raw, str):
        raise CellError(f"{label}: name: required (a string)" if raw is None else
                        f"{label}: name: must be a string, not {type(raw).__name__} {raw!r}")
    name = " ".join(raw.split())
    if not name or len(name) > MAX_NAME or not name.isprintable():
        raise CellError(f"{label}: name {raw!r} must be 1 to {MAX_NAME} printable characters")
    return name


def _label(where: str, what: str, k: int, table: dict) -> str:
    name = table.get("name")
    return f"{where}: {what} {k}" + (f" ({name!r})" if isinstance(name, str) else "")


class _Budget:
    """The triangles and points (:data:`MAX_CELL_ELEMENTS`) and compound parts (:data:`MAX_CELL_PARTS`)
    of the whole cell."""

    def __init__(self):
        self.used = self.used_parts = 0

    def take(self, n: int, label: str) -> None:
        self.used += n
        if self.used > MAX_CELL_ELEMENTS:
            raise CellError(f"{label}: the cell's meshes and point clouds hold more than {MAX_CELL_ELEMENTS} "
                            f"triangles and points together")

    def parts(self, n: int, label: str) -> None:
        self.used_parts += n
        if self.used_parts > MAX_CELL_PARTS:
            raise CellError(f"{label}: the cell's compound obstacles have more than {MAX_CELL_PARTS} parts together")


def _ignore(where: str, k: int, ob_name: str, refs: list[str], names: dict[str, int]) -> list[str]:
    """The bodies an obstacle's ``ignore`` names: every name there is a robot body (``body:`` may say so);
    a name that is an obstacle's and not one every robot's bodies have is refused as a slip."""
    out = []
    for ref in refs:
        qual, name = split_reference(ref)
        if qual == OBSTACLE or (qual is None and name in names and not is_body_like(name)):
            raise CellError(f"{where}: obstacle {k} ({ob_name!r}): ignore: {ref!r} is an obstacle; ignore lists "
                            f"robot bodies (obstacles are never checked against each other; write 'body:{name}' "
                            f"for a body of that name)")
        out.append(name)
    return out


def _pair_side(where: str, k: int, ref: str, names: dict[str, int], body_like: dict[str, str]
               ) -> tuple[bool, str, bool]:
    """(is an obstacle, name, named without a qualifier) of one name of allowed pair ``k``;
    ``body_like``: the obstacles named like every robot's bodies, by their names as bodies are matched
    (case and spacing ignored)."""
    qual, name = split_reference(ref)
    if qual == OBSTACLE:
        if name not in names:
            raise CellError(f"{where}: [allow]: pair {k}: {ref!r}: the cell has no obstacle {name!r}")
        return True, name, False
    if qual is None and is_body_like(name) and name.casefold() in body_like:
        raise CellError(f"{where}: [allow]: pair {k}: {ref!r} is both obstacle {body_like[name.casefold()]!r} and a "
                        f"robot body; write 'obstacle:{body_like[name.casefold()]}' or 'body:{name}'")
    if qual is None and name in names:
        return True, name, True
    return False, name, False


def _tool(f: Table, k: int) -> LinkCapsule:
    kind = f.string("type", None, tuple(TOOL_TYPES))
    check_keys(f.label, f.t, TOOL_TYPES[kind] | {"tcp"})
    raw = f.t.get("name", "tool")
    if not (isinstance(raw, str) and raw.strip() and len(raw) <= MAX_NAME and raw.isprintable()):
        raise f.fail("name", f"must be 1 to {MAX_NAME} printable characters, not {raw!r}")
    r = f.number("radius")
    if kind == "sphere":
        c = f.point("center")
        return LinkCapsule(TOOL_BODY, c, c, r, raw)
    return LinkCapsule(TOOL_BODY, f.point("a"), f.point("b"), r, raw)


def _tcp(f: Table) -> np.ndarray:
    """A ``[[tool]]`` table's ``tcp = [x, y, z]`` or ``[x, y, z, roll, pitch, yaw]`` (the cell's units) → 4×4 (SI),
    bounded as ``--tcp``: each finite, lengths within ±10 km, angles within ±360°."""
    from kin.tcp import tcp_transform
    v, lu, au = f.t["tcp"], f.unit, f.angle_unit
    if not (isinstance(v, list) and len(v) in (3, 6) and all(is_num(x) for x in v)):
        raise f.fail("tcp", f"must be [x, y, z] or [x, y, z, roll, pitch, yaw] ({lu}, {au}), not {v!r}")
    try:
        return tcp_transform(v, lu, au, f"{f.label}: tcp")
    except ArgumentError as e:
        raise CellError(str(e)) from None


def _units(top: Table) -> tuple[str, str]:
    return top.string("length_unit", "m", tuple(LENGTH_UNITS)), top.string("angle_unit", "deg", tuple(ANGLE_UNITS))


def _tools(where: str, doc: dict, unit: str, angle_unit: str, shapes: bool = True):
    """The ``[[tool]]`` tables: (their shapes, the tcp one of them sets or None); ``shapes=False`` reads
    only the tcp."""
    tools_raw = doc.get("tool", [])
    if not isinstance(tools_raw, list) or not all(isinstance(o, dict) for o in tools_raw):
        raise CellError(f"{where}: tool must be an array of tables ([[tool]])")
    if len(tools_raw) > MAX_TOOL_SHAPES:
        raise CellError(f"{where}: {len(tools_raw)} tool shapes; at most {MAX_TOOL_SHAPES}")
    tool, tcp, tcp_at = [], None, 0
    for k, t in enumerate(tools_raw, 1):
        f = Table(_label(where, "tool", k, t), t, unit, LENGTH_UNITS[unit], angle_unit)
        if "tcp" in t:
            if tcp is not None:
                raise f.fail("tcp", f"the tool centre point is already set by tool {tcp_at}; a cell file holds one tcp")
            tcp, tcp_at = _tcp(f), k
        if shapes and not ("tcp" in t and set(t) <= {"tcp", "name"}):     # a table of only a tcp is no shape
            tool.append(_tool(f, k))
    return tool, tcp


def _document(text: str, where: str) -> dict:
    """The TOML document of a cell file's text: bounded, parsed, its top-level keys checked."""
    if len(text) > MAX_CELL_BYTES:
        raise CellError(f"{where}: {len(text)} characters; a cell file may have at most {MAX_CELL_BYTES}")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise CellError(f"{where}: not valid TOML ({e})") from None
    check_keys(where, doc, _TOP)
    return doc


def parse_cell(text: str, where: str = "cell", base_dir: str | Path | None = None) -> Cell:
    """A :class:`Cell` from the text of a cell file; ``where`` names it in messages; ``base_dir``:
    where mesh and point-cloud files are looked up (default: the current directory)."""
    base_dir = Path(".") if base_dir is None else Path(base_dir)
    doc = _document(text, where)
    top = Table(where, doc, "m", 1.0, "deg")
    unit, angle_unit = _units(top)
    scale = LENGTH_UNITS[unit]
    default_name = Path(where).stem if where.endswith(".toml") else "cell"
    name = top.string("name", default_name)
    if not name.strip() or len(name) > MAX_NAME or not name.isprintable():
        raise top.fail("name", f"must be 1 to {MAX_NAME} printable characters")

    robot = doc.get("robot", {})
    if not isinstance(robot, dict):
        raise CellError(f"{where}: robot must be a table ([robot] with xyz, rpy)")
    check_keys(f"{where}: [robot]", robot, _ROBOT)
    base = Table(f"{where}: [robot]", robot, unit, scale, angle_unit).pose()

    obstacles_raw = doc.get("obstacle", [])
    if not isinstance(obstacles_raw, list) or not all(isinstance(o, dict) for o in obstacles_raw):
        raise CellError(f"{where}: obstacle must be an array of tables ([[obstacle]])")
    if len(obstacles_raw) > MAX_OBSTACLES:
        raise CellError(f"{where}: {len(obstacles_raw)} obstacles; at most {MAX_OBSTACLES}")
    obstacles, notes, ignores, names, meshes = [], {}, [], {}, {}
    budget = _Budget()
    for k, t in enumerate(obstacles_raw, 1):
        label = _label(where, "obstacle", k, t)
        f = Table(label, t, unit, scale, angle_unit)
        kind = f.string("type", None, tuple(OBSTACLE_TYPES))
        check_keys(label, t, COMMON | OBSTACLE_TYPES[kind])
        ob_name = _name(t.get("name"), label)
        if ob_name in names:
            raise CellError(f"{label}: name {ob_name!r} is already obstacle {names[ob_name]}'s; names must be unique")
        names[ob_name] = k
        ignores.append((k, ob_name, f.names("ignore")))
        ob, note, triangles = build_obstacle(f, kind, ob_name, base_dir, budget)
        obstacles.append(ob)
        if note:
            notes[ob_name] = note
        if triangles is not None:
            meshes[ob_name] = triangles
    pairs_ob = [(ob_name, b) for k, ob_name, refs in ignores for b in _ignore(where, k, ob_name, refs, names)]

    tool, tcp = _tools(where, doc, unit, angle_unit)

    allow = doc.get("allow", {})
    if not isinstance(allow, dict):
        raise CellError(f"{where}: allow must be a table ([allow] with pairs)")
    check_keys(f"{where}: [allow]", allow, _ALLOW)
    raw_pairs = allow.get("pairs", [])
    if not isinstance(raw_pairs, list):
        raise CellError(f"{where}: [allow]: pairs must be a list of [name, name] pairs")
    if len(raw_pairs) > MAX_PAIRS:
        raise CellError(f"{where}: [allow]: {len(raw_pairs)} pairs; at most {MAX_PAIRS}")
    body_pairs, unqualified = [], set()
    body_like = {ob_name.casefold(): ob_name for ob_name in names if is_body_like(ob_name)}
    for k, p in enumerate(raw_pairs, 1):
        if not (isinstance(p, list) and len(p) == 2 and all(isinstance(x, str) and x.strip() for x in p)):
            raise CellError(f"{where}: [allow]: pair {k} must be two names [\"tool\", \"part\"], not {p!r}")
        (a_ob, a, a_loose), (b_ob, b, b_loose) = (_pair_side(where, k, x, names, body_like) for x in p)
        if a_ob and b_ob:
            raise CellError(f"{where}: [allow]: pair {k} [{a!r}, {b!r}] names two obstacles; obstacles are never "
                            f"checked against each other")
        if a_ob or b_ob:
            pairs_ob.append((a, b) if a_ob else (b, a))
            unqualified |= {a} if a_loose else {b} if b_loose else set()
        else:
            body_pairs.append((a, b))
    return Cell(name, tuple(obstacles), base, tuple(tool), tuple(body_pairs), tuple(pairs_ob), notes,
                unqualified=frozenset(unqualified), length_unit=unit, source=where, meshes=meshes, tcp=tcp)


def cell_tcp(path: str | Path):
    """The tool centre point a cell file's ``[[tool]] tcp`` sets (4×4, SI, in the robot file's tool
    frame), or None — read and checked as :func:`load_cell` does, without building the obstacles."""
    path = Path(path)
    doc = _document(_read(path), str(path))
    unit, angle_unit = _units(Table(str(path), doc, "m", 1.0, "deg"))
    return _tools(str(path), doc, unit, angle_unit, shapes=False)[1]


def load_cell(path: str | Path) -> Cell:
    """The :class:`Cell` of a cell file (TOML, see docs/cells.md); meshes and point clouds it names
    are found relative to it.  The file is bounded (:data:`MAX_CELL_BYTES`) before it is read."""
    path = Path(path)
    return replace(parse_cell(_read(path), str(path), path.parent), path=path)


def _read(path: Path) -> str:
    """A cell file's text, bounded (:data:`MAX_CELL_BYTES`) before it is read."""
    from kin.files import FileReadError, read_text
    try:
        return read_text(path, "cell file", MAX_CELL_BYTES)
    except FileReadError as e:
        raise CellError(str(e)) from None
