"""Robot files: TOML load, validation and save (the public file format; see docs/robot-files.md).

Units are converted once, here: the returned :class:`~kin.chain.Chain` is in SI units and
remembers the file's units, so that :func:`dumps_robot` writes the values back as they were
(load → save → load gives an identical chain).
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from kin.chain import (
    ANGLE_UNITS,
    CONVENTIONS,
    DH_FIELDS,
    JOINT_TYPES,
    LENGTH_FIELDS,
    LENGTH_UNITS,
    NAME_RE,
    TASK_ROWS,
    Chain,
    Joint,
    Parameter,
    Placement,
)
from kin.errors import ChainError, RobotFileError, UnknownRobotError
from kin.output import write_output
from kin.transforms import rigidity_defect
from kin.validation import Fields, type_name

ROBOT_DIR = Path(__file__).parent / "robots"
TOP_FIELDS = ("name", "title", "source", "convention", "length_unit", "angle_unit", "joints", "base",
              "tool", "parameters", "task", "geometry", "payload", "gravity", "sigma_floor", "states", "visual")
REQUIRED_TOP = ("name", "convention", "length_unit", "angle_unit", "joints")
JOINT_FIELDS = ("type", "a", "alpha", "d", "theta", "limits", "name", "max_velocity", "max_acceleration",
                "max_torque", "inertial")
#: the fields of a [joints.inertial] or [payload] table (mass required; see docs/robot-files.md)
INERTIAL_FIELDS = ("mass", "com", "inertia", "motor_inertia", "viscous", "coulomb")
PLACEMENT_FIELDS = ("xyz", "rpy", "matrix")
PARAMETER_FIELDS = ("value", "bounds")
GEOMETRY_FIELDS = ("source", "radius", "allow", "over_estimate", "capsule", "sphere", "box", "cylinder", "hull")
#: the fields of each shape table, required ones first (``rpy`` and ``name`` are optional)
SHAPE_FIELDS = {"capsule": ("body", "a", "b", "radius", "name"),
                "sphere": ("body", "center", "radius", "name"),
                "box": ("body", "center", "size", "rpy", "name"),
                "cylinder": ("body", "center", "radius", "length", "rpy", "name")}
OPTIONAL_SHAPE_FIELDS = ("rpy", "name")
#: at most this many shapes, and allowed pairs, in a [geometry] table
MAX_SHAPES = 1000
#: A revolute limit beyond this (rad) is almost surely a degree value in a file that says "rad".
MAX_REVOLUTE_LIMIT = 8 * math.pi
RIGID_TOL = 1e-6
#: lengths (m): at most 10 km, and a non-zero length at least 1 nm (smaller is zero in disguise and
#: makes every dexterity measure a rounding error)
MAX_LENGTH = 1e4
MIN_LENGTH = 1e-9
#: the largest joint torque (N·m) or force (N) a robot file may give: far beyond any machine's drive
MAX_TORQUE = 1e7
#: the largest gravity vector (m/s²) a robot file may give, as :class:`~kin.chain.Chain` allows
MAX_GRAVITY = 1e3
#: the largest ``sigma_floor`` (SI) a robot file may give, as :class:`~kin.chain.Chain` allows
MAX_SIGMA_FLOOR = 1e3


# ---- bundled library ---------------------------------------------------------------------------
def bundled_robots() -> list[str]:
    """Names of the robots shipped with rmtkit, sorted."""
    return sorted(p.stem for p in ROBOT_DIR.glob("*.toml"))


#: a robot file may have at most this many bytes (the largest bundled one has a few kB)
MAX_ROBOT_BYTES = 10 * 2**20


def robot_path(name_or_path: str | Path) -> Path:
    """Resolve a bundled robot name or a file path to an existing file path."""
    from kin.files import named_file
    p, given = named_file(name_or_path, ROBOT_DIR)
    if p.is_file():
        return p
    if given:
        raise UnknownRobotError(f"{name_or_path}: no such robot file")
    raise UnknownRobotError(f"unknown robot {str(name_or_path)!r}; bundled robots: {', '.join(bundled_robots())} "
                            "(or give a path to a .toml file)")


def load_chain(name_or_path: str | Path) -> Chain:
    """Load a bundled robot by name, or a robot file by path, into a :class:`Chain` (SI units)."""
    from kin.files import read_text
    path = robot_path(name_or_path)
    text = read_text(path, "robot file", MAX_ROBOT_BYTES, error=RobotFileError)
    return loads_robot(text, str(path))


# ---- parsing -----------------------------------------------------------------------------------
class _Reader(Fields):
    """Robot-file fields (:class:`kin.validation.Fields`) with the robot file's own error, lengths and
    angles."""

    def __init__(self, path: str | None):
        super().__init__(path)
        self.path = path

    def fail(self, field: str | None, msg: str) -> RobotFileError:
        return RobotFileError(msg, self.path, field)

    def length(self, v: Any, field: str, scale: float) -> float:
        """A length in file units → m, within ±:data:`MAX_LENGTH` and 0 or at least :data:`MIN_LENGTH`."""
        x = self.number(v, field) * scale
        if abs(x) > MAX_LENGTH or 0 < abs(x) < MIN_LENGTH:
            raise self.fail(field, f"{v} is outside the allowed range: 0 or {MIN_LENGTH / scale:g} to "
                            f"{MAX_LENGTH / scale:g} in magnitude (file length unit; 1 nm to 10 km)")
        return x

    def angle(self, v: Any, field: str, scale: float) -> float:
        """An angle in file units → rad, within ±:data:`MAX_REVOLUTE_LIMIT`."""
        x = self.number(v, field) * scale
        if abs(x) > MAX_REVOLUTE_LIMIT:
            raise self.fail(field, f"{v} exceeds ±{MAX_REVOLUTE_LIMIT / scale:g} (±8π rad, four turns)")
        return x

    def positive(self, v: Any, field: str) -> float:
        x = self.number(v, field)
        if x <= 0:
            raise self.fail(field, f"must be positive, got {x}")
        return x


_tname = type_name


class _ShapeReader(_Reader):
    """A reader whose messages also say which shape and body they are about."""

    def __init__(self, path: str | None, note: str):
        super().__init__(path)
        self.note = note

    def fail(self, field: str | None, msg: str) -> RobotFileError:
        return RobotFileError(f"{msg}; {self.note}", self.path, field)


def loads_robot(text: str, path: str | None = None) -> Chain:
    """Parse and validate robot-file text; ``path`` only names the file in error messages."""
    r = _Reader(path)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise r.fail(None, f"not valid TOML ({e})") from None
    r.table(doc, "", TOP_FIELDS)
    for k in REQUIRED_TOP:
        if k not in doc:
            raise r.fail(k, "missing required field")
    name = r.string(doc["name"], "name")
    if not NAME_RE.match(name):
        raise r.fail("name", f"{name!r} must match [a-z0-9_]+")
    convention = r.string(doc["convention"], "convention", CONVENTIONS)
    lu = r.string(doc["length_unit"], "length_unit", tuple(LENGTH_UNITS))
    au = r.string(doc["angle_unit"], "angle_unit", tuple(ANGLE_UNITS))
    ls, as_ = LENGTH_UNITS[lu], ANGLE_UNITS[au]

    # parameters: kind from use, values scaled accordingly
    raw_params_doc = doc.get("parameters", {})
    raw_params = r.table(raw_params_doc, "parameters",
                         tuple(raw_params_doc) if isinstance(raw_params_doc, dict) else ())
    joints_raw = doc["joints"]
    if not isinstance(joints_raw, list) or not joints_raw:
        raise r.fail("joints", "must hold at least one [[joints]] table")
    kinds: dict[str, str] = {}
    for i, jr in enumerate(joints_raw):
        r.table(jr, f"joints[{i}]", JOINT_FIELDS)
        for f in DH_FIELDS:
            v = jr.get(f)
            if isinstance(v, str):
                if v not in raw_params:
                    raise r.fail(f"joints[{i}].{f}", f"refers to undefined parameter {v!r}; defined: "
                                 f"{', '.join(raw_params) or 'none (add a [parameters.NAME] table)'}")
                kind = "length" if f in LENGTH_FIELDS else "angle"
                if kinds.setdefault(v, kind) != kind:
                    raise r.fail(f"joints[{i}].{f}", f"parameter {v!r} is used as both a length and an angle")
    params: dict[str, Parameter] = {}
    for pname, pr in raw_params.items():
        fld = f"parameters.{pname}"
        r.table(pr, fld, PARAMETER_FIELDS)
        for k in PARAMETER_FIELDS:
            if k not in pr:
                raise r.fail(f"{fld}.{k}", "missing required field")
        kind = kinds.get(pname, "length")
        s = ls if kind == "length" else as_
        check = r.length if kind == "length" else r.angle
        val = r.number(pr["value"], f"{fld}.value")
        lo, hi = r.vector(pr["bounds"], f"{fld}.bounds", 2)
        for x, sub_field in ((val, "value"), (lo, "bounds[0]"), (hi, "bounds[1]")):
            check(x, f"{fld}.{sub_field}", s)
        if not lo <= hi:
            raise r.fail(f"{fld}.bounds", f"[{lo}, {hi}] is reversed; write [lower, upper]")
        if not lo <= val <= hi:
            raise r.fail(f"{fld}.value", f"{val} lies outside its bounds [{lo}, {hi}]")
        params[pname] = Parameter(val * s, (lo * s, hi * s), kind)  # type: ignore[arg-type]

    joints = []
    for i, jr in enumerate(joints_raw):
        fld = f"joints[{i}]"
        if "type" not in jr:
            raise r.fail(f"{fld}.type", f"missing required field; allowed: {', '.join(JOINT_TYPES)}")
        jtype = r.string(jr["type"], f"{fld}.type", JOINT_TYPES)
        if "limits" not in jr:
            raise r.fail(f"{fld}.limits", "missing required field: [lower, upper] of the joint variable")
        dh = {}
        for f in DH_FIELDS:
            v = jr.get(f, 0.0)
            dh[f] = v if isinstance(v, str) else (r.length(v, f"{fld}.{f}", ls) if f in LENGTH_FIELDS
                                                  else r.angle(v, f"{fld}.{f}", as_))
        var_scale = as_ if jtype == "revolute" else ls
        lo, hi = r.vector(jr["limits"], f"{fld}.limits", 2)
        if lo == hi:
            raise r.fail(f"{fld}.limits", f"[{lo}, {hi}] is empty; lower must be below upper")
        if lo > hi:
            raise r.fail(f"{fld}.limits", f"[{lo}, {hi}] is reversed; write [lower, upper]")
        if jtype == "prismatic":
            r.length(lo, f"{fld}.limits[0]", ls)
            r.length(hi, f"{fld}.limits[1]", ls)
        if jtype == "revolute" and max(abs(lo), abs(hi)) * as_ > MAX_REVOLUTE_LIMIT:
            hint = " (a degree value in a file whose angle_unit is rad?)" if au == "rad" else ""
            raise r.fail(f"{fld}.limits", f"[{lo}, {hi}] {au} exceeds ±8π rad, four turns{hint}")
        extra = {}
        if "name" in jr:
            extra["name"] = r.string(jr["name"], f"{fld}.name")
        for k in ("max_velocity", "max_acceleration"):
            if k in jr:
                extra[k] = r.positive(jr[k], f"{fld}.{k}") * var_scale
        if "max_torque" in jr:      # SI whatever the file's units, as the inertial table's friction
            unit = "N·m" if jtype == "revolute" else "N"
            t = r.positive(jr["max_torque"], f"{fld}.max_torque")
            if t > MAX_TORQUE:
                raise r.fail(f"{fld}.max_torque", f"{t:g} {unit} exceeds {MAX_TORQUE:g} {unit}")
            extra["max_torque"] = t
        if "inertial" in jr:
            extra["inertia"] = _inertial(r, jr["inertial"], f"{fld}.inertial", ls, lu, f"joint {i + 1}")
        joints.append(Joint(jtype, limits=(lo * var_scale, hi * var_scale), **dh, **extra))  # type: ignore[arg-type]

    base = _placement(r, doc.get("base"), "base", ls, as_)
    tool = _placement(r, doc.get("tool"), "tool", ls, as_)
    task = None
    if "task" in doc:
        t = doc["task"]
        if not isinstance(t, list) or not t:
            raise r.fail("task", f"must be a non-empty list of rows from {', '.join(TASK_ROWS)}")
        task = tuple(r.string(x, f"task[{i}]", TASK_ROWS) for i, x in enumerate(t))
        if len(set(task)) != len(task):
            raise r.fail("task", "lists a row twice")
    title = r.string(doc.get("title", ""), "title")
    source = r.string(doc.get("source", ""), "source")
    dyn: dict[str, Any] = {}
    if "payload" in doc:
        dyn["payload"] = _inertial(r, doc["payload"], "payload", ls, lu, "payload")
    if "gravity" in doc:
        g = r.vector(doc["gravity"], "gravity", 3)
        if math.hypot(*g) > MAX_GRAVITY:
            raise r.fail("gravity", f"{g} is {math.hypot(*g):g} m/s² in size; at most {MAX_GRAVITY:g} m/s²")
        dyn["gravity"] = tuple(g)
    if "sigma_floor" in doc:      # SI whatever the file's units (σ_min mixes m and rad: docs/robot-files.md)
        f = r.number(doc["sigma_floor"], "sigma_floor")
        if not 0 <= f <= MAX_SIGMA_FLOOR:
            raise r.fail("sigma_floor", f"{f:g} is outside the allowed range [0, {MAX_SIGMA_FLOOR:g}] (SI)")
        dyn["sigma_floor"] = f
    try:
        chain = Chain(name=name, joints=tuple(joints), convention=convention, title=title, source=source,  # type: ignore[arg-type]
                      length_unit=lu, angle_unit=au, base=base, tool=tool, parameters=params, task=task, **dyn)
    except ChainError as e:
        raise r.fail(None, str(e)) from None
    if "geometry" in doc:
        chain = replace(chain, geometry=_geometry(r, doc["geometry"], chain, ls, as_))
    if "states" in doc:
        from kin.states import read_states
        chain = replace(chain, states=read_states(r, doc["states"], chain))
    if "visual" in doc:
        from kin.visual import read_visual
        meshes, vsource = read_visual(r, doc["visual"], lambda v, f: _body(r, v, f, chain),
                                      lambda t, f: _placement(r, t, f, ls, as_), path)
        chain = replace(chain, visual=meshes, visual_source=vsource)
    return chain


# ---- inertial tables ------------------------------------------------------------------------------
def _inertial(r: _Reader, raw: Any, fld: str, ls: float, lu: str, body: str):
    """A [joints.inertial] or [payload] table → :class:`kin.dynamics.LinkInertia` (SI): mass kg, com
    in the file length unit ``lu`` (``ls`` m each), inertia in kg·lu², motor_inertia, viscous, coulomb SI."""
    from kin.dynamics.inertia import MAX_MASS, InertiaError, LinkInertia

    r.table(raw, fld, INERTIAL_FIELDS)
    if "mass" not in raw:
        raise r.fail(f"{fld}.mass", "missing required field: the body's mass in kg")
    mass = r.number(raw["mass"], f"{fld}.mass")
    if not 0.0 <= mass <= MAX_MASS:
        raise r.fail(f"{fld}.mass", f"{mass:g} kg must be in [0, {MAX_MASS:g}] kg")
    com = r.vector(raw.get("com", [0.0, 0.0, 0.0]), f"{fld}.com", 3)
    for i, x in enumerate(com):
        if abs(x * ls) > MAX_LENGTH:
            raise r.fail(f"{fld}.com[{i}]", f"{x:g} exceeds ±{MAX_LENGTH / ls:g} (file length unit; 10 km)")
    inertia = r.vector(raw.get("inertia", [0.0] * 6), f"{fld}.inertia", 6)
    extra = {}
    for k in ("motor_inertia", "viscous", "coulomb"):
        if k in raw:
            v = r.number(raw[k], f"{fld}.{k}")
            if v < 0:
                raise r.fail(f"{fld}.{k}", f"must be ≥ 0, got {v:g}")
            extra[k] = v
    s2 = ls * ls
    try:
        return LinkInertia(mass, tuple(x * ls for x in com), tuple(x * s2 for x in inertia), body=body,
                           **extra)  # type: ignore[arg-type]
    except InertiaError as e:
        raise r.fail(f"{fld}.inertia", f"{inertia} (kg·{lu}², about the centre of mass) "
                     f"is not a rigid body's: {str(e).split(': ', 1)[-1]}") from None



# ---- the [geometry] table ------------------------------------------------------------------------
def _body_names(chain: Chain) -> dict[str, int]:
    """The fixed body names: ``base``, ``link 1`` … ``link n``, ``tool``."""
    return {"base": 0, **{f"link {k}": k for k in range(1, chain.n + 1)}, "tool": chain.n + 1}


def _body(r: _Reader, v: Any, fld: str, chain: Chain) -> int:
    """A body named ``base``, ``tool``, ``link k`` or by its joint's name → its number (0 … n + 1).

    ``base``, ``tool`` and ``link k`` always mean those bodies (a joint named ``base``, as Universal
    Robots name their first, is ``link 1`` here); a joint's name names its body when no other joint
    has that name."""
    s = r.string(v, fld)
    fixed = _body_names(chain)
    if s in fixed:
        return fixed[s]
    hits = [k for k, j in enumerate(chain.joints, 1) if j.name == s]
    if len(hits) > 1:
        raise r.fail(fld, f"{s!r} names joints {', '.join(str(k) for k in hits)}; use 'link k' "
                     "(body k moves with joint k)")
    if not hits:
        named = [j.name for j in chain.joints if j.name and j.name not in fixed]
        raise r.fail(fld, f"{s!r} is not a body; allowed: base, link 1 … link {chain.n}, tool"
                     + (f", or a joint name ({', '.join(named)})" if named else ""))
    return hits[0]


def body_label(chain: Chain, k: int) -> str:
    """The name a robot file gives body ``k``: ``base``, ``tool``, its joint's name when that names
    it alone, else ``link k``."""
    if k == 0:
        return "base"
    if k == chain.n + 1:
        return "tool"
    nm = chain.joints[k - 1].name
    if nm and nm not in _body_names(chain) and sum(j.name == nm for j in chain.joints) == 1:
        return nm
    return f"link {k}"


def _point(r: _Reader, v: Any, fld: str, ls: float) -> tuple[float, float, float]:
    """A point of a shape in file units → m; a coordinate below 1 nm is 0 (rounding noise of a
    computed geometry)."""
    xs = r.vector(v, fld, 3)
    return tuple(0.0 if abs(x * ls) < MIN_LENGTH else r.length(x, f"{fld}[{i}]", ls)  # type: ignore[return-value]
                 for i, x in enumerate(xs))


def _size(r: _Reader, v: Any, fld: str, ls: float) -> float:
    """A positive length (radius, edge, length) in file units → m."""
    x = r.number(v, fld)
    if x <= 0:
        raise r.fail(fld, f"must be a positive length, got {x:g} (file length unit)")
    return r.length(x, fld, ls)


def _geometry(r: _Reader, raw: Any, chain: Chain, ls: float, as_: float):
    """The [geometry] table → :class:`kin.geometry.RobotGeometry` (SI, body frames)."""
    from kin.geometry import LinkCapsule, RobotGeometry, default_geometry
    from kin.geometry.enclose import enclose_box, enclose_cylinder
    from kin.transforms import make_transform, rpy_to_matrix

    r.table(raw, "geometry", GEOMETRY_FIELDS)
    source = r.string(raw["source"], "geometry.source") if "source" in raw else None
    shapes = [k for k in SHAPE_FIELDS if k in raw]
    count = 0
    for kind in shapes:
        if not isinstance(raw[kind], list) or not all(isinstance(t, dict) for t in raw[kind]):
            raise r.fail(f"geometry.{kind}", f"must be an array of tables: write [[geometry.{kind}]]")
        count += len(raw[kind])
    if count > MAX_SHAPES:
        raise r.fail("geometry", f"lists {count} shapes; at most {MAX_SHAPES} are allowed")
    allowed = set()
    pairs = raw.get("allow", [])
    if not isinstance(pairs, list) or len(pairs) > MAX_SHAPES:
        raise r.fail("geometry.allow", f"must be a list of at most {MAX_SHAPES} pairs of body names, "
                     f'e.g. [["link 4", "link 6"]]')
    for i, pair in enumerate(pairs):
        fld = f"geometry.allow[{i}]"
        if not isinstance(pair, list) or len(pair) != 2:
            raise r.fail(fld, f'must be a pair of body names, e.g. ["link 4", "link 6"], got {_tname(pair)} {pair!r}')
        b0, b1 = (_body(r, x, f"{fld}[{j}]", chain) for j, x in enumerate(pair))
        if b0 == b1:
            raise r.fail(fld, f"names body {b0} twice; a pair is two bodies")
        allowed.add((min(b0, b1), max(b0, b1)))
    if "hull" in raw and not shapes:
        raise r.fail("geometry.hull", "needs the body's capsules listed too ([[geometry.capsule]] or other shapes): "
                     "the robot is taken to lie inside both")
    if not shapes:
        if "over_estimate" in raw:
            raise r.fail("geometry.over_estimate", "applies to listed shapes; without shapes the default "
                         "capsules are the geometry")
        radius = _size(r, raw["radius"], "geometry.radius", ls) if "radius" in raw else None
        g = default_geometry(chain, radius)
        return RobotGeometry(g.capsules, frozenset(allowed), source or g.source, g.radius)
    if "radius" in raw:
        raise r.fail("geometry.radius", "sets the radius of the default capsules, which are used only when no "
                     "shapes are listed; give each shape its own radius")
    over = 0.0
    if "over_estimate" in raw:
        if r.number(raw["over_estimate"], "geometry.over_estimate") < 0:
            raise r.fail("geometry.over_estimate", f"must be ≥ 0, got {raw['over_estimate']}")
        over = r.length(raw["over_estimate"], "geometry.over_estimate", ls)
    caps = []
    for kind in shapes:
        fields = SHAPE_FIELDS[kind]
        for i, t in enumerate(raw[kind]):
            fld = f"geometry.{kind}[{i}]"
            r.table(t, fld, fields)
            required = [f for f in fields if f not in OPTIONAL_SHAPE_FIELDS]
            for f in required:
                if f not in t:
                    optional = [f for f in fields if f in OPTIONAL_SHAPE_FIELDS]
                    raise r.fail(f"{fld}.{f}", f"missing required field; a {kind} has {', '.join(required)} "
                                 f"(optional: {', '.join(optional)})")
            body = _body(r, t["body"], f"{fld}.body", chain)
            sr = _ShapeReader(r.path, f"the {kind} on body {body_label(chain, body)!r}")
            label = sr.string(t["name"], f"{fld}.name") if "name" in t else f"{body_label(chain, body)} {kind}"
            if kind == "capsule":
                caps.append(LinkCapsule(body, _point(sr, t["a"], f"{fld}.a", ls), _point(sr, t["b"], f"{fld}.b", ls),
                                        _size(sr, t["radius"], f"{fld}.radius", ls), label))
                continue
            center = _point(sr, t["center"], f"{fld}.center", ls)
            if kind == "sphere":
                caps.append(LinkCapsule(body, center, center, _size(sr, t["radius"], f"{fld}.radius", ls), label))
                continue
            rpy = sr.vector(t.get("rpy", [0.0, 0.0, 0.0]), f"{fld}.rpy", 3)
            pose = make_transform(rpy_to_matrix([sr.angle(x, f"{fld}.rpy[{j}]", as_) for j, x in enumerate(rpy)]),
                                  np.array(center))
            if kind == "box":
                edges = sr.vector(t["size"], f"{fld}.size", 3)
                enc = enclose_box([_size(sr, x, f"{fld}.size[{j}]", ls) for j, x in enumerate(edges)], pose)
            else:
                enc = enclose_cylinder(_size(sr, t["radius"], f"{fld}.radius", ls),
                                       _size(sr, t["length"], f"{fld}.length", ls), pose)
            over = max(over, enc.over_estimate)
            caps += [LinkCapsule(body, c.a, c.b, c.radius, label) for c in enc.capsules]
    hulls = ()
    if "hull" in raw:
        from kin.geometry.hull_table import read_hulls
        hulls = tuple(read_hulls(raw["hull"], r.fail, lambda v, f: _body(r, v, f, chain), r.string, ls))
    return RobotGeometry(tuple(caps), frozenset(allowed), source or "robot file", None, over, hulls)


def _placement(r: _Reader, raw: Any, fld: str, ls: float, as_: float) -> Placement:
    if raw is None:
        return Placement()
    r.table(raw, fld, PLACEMENT_FIELDS)
    if "matrix" in raw:
        if "xyz" in raw or "rpy" in raw:
            raise r.fail(fld, "give either matrix or xyz/rpy, not both")
        m = raw["matrix"]
        if not isinstance(m, list) or len(m) != 4:
            raise r.fail(f"{fld}.matrix", "must be 4 rows of 4 numbers")
        rows = [r.vector(row, f"{fld}.matrix[{i}]", 4) for i, row in enumerate(m)]
        T = np.array(rows)
        for i in range(3):
            r.length(T[i, 3], f"{fld}.matrix[{i}][3]", ls)
        defect = rigidity_defect(T)
        if defect > RIGID_TOL:
            raise r.fail(f"{fld}.matrix", f"is not a rigid transform (rotation not orthonormal with det +1, or "
                         f"bottom row not [0, 0, 0, 1]; defect {defect:.3g} > {RIGID_TOL:g})")
        T[:3, 3] *= ls
        return Placement.from_matrix(T)
    xyz = r.vector(raw.get("xyz", [0.0, 0.0, 0.0]), f"{fld}.xyz", 3)
    rpy = r.vector(raw.get("rpy", [0.0, 0.0, 0.0]), f"{fld}.rpy", 3)
    return Placement(xyz=tuple(r.length(x, f"{fld}.xyz[{i}]", ls) for i, x in enumerate(xyz)),  # type: ignore[arg-type]
                     rpy=tuple(r.angle(x, f"{fld}.rpy[{i}]", as_) for i, x in enumerate(rpy)))


# ---- saving ------------------------------------------------------------------------------------
def _to_file(x_si: float, scale: float) -> float:
    """Value in file units whose re-conversion gives back exactly ``x_si`` when one exists."""
    y = x_si / scale
    if scale == 1.0 or y * scale == x_si:
        return y
    for direction in (math.inf, -math.inf):
        z = y
        for _ in range(4):
            z = math.nextafter(z, direction)
            if z * scale == x_si:
                return z
    return y


def _fmt(x: float) -> str:
    if x == int(x) and abs(x) < 1e15:
        return f"{x:.1f}"
    return repr(float(x))


def _vec(xs, scale: float = 1.0) -> str:
    return "[" + ", ".join(_fmt(_to_file(float(x), scale)) for x in xs) + "]"


def _str(s: str) -> str:
    """A TOML basic string: backslash, quote and every control character (TOML forbids them raw) escaped."""
    def esc(ch: str) -> str:
        if ch in '\\"':
            return "\\" + ch
        if ch == "\n":
            return "\\n"
        if ord(ch) < 0x20 or ord(ch) == 0x7F:
            return f"\\u{ord(ch):04x}"
        return ch
    return '"' + "".join(esc(ch) for ch in s) + '"'


def _key(k: str) -> str:
    """A TOML key: bare when it may be, quoted otherwise (a parameter name may hold any character)."""
    return k if k and all(ch.isascii() and (ch.isalnum() or ch in "_-") for ch in k) else _str(k)


def dumps_robot(chain: Chain, directory: str | Path | None = None) -> str:
    """Robot-file text for ``chain``, written in the chain's own units; ``directory``: where the file
    goes, which its [visual] mesh files are named relative to (absolute paths without it)."""
    ls, as_ = LENGTH_UNITS[chain.length_unit], ANGLE_UNITS[chain.angle_unit]
    out = [f"name = {_str(chain.name)}"]
    if chain.title:
        out.append(f"title = {_str(chain.title)}")
    if chain.source:
        out.append(f"source = {_str(chain.source)}")
    out += [f"convention = {_str(chain.convention)}", f"length_unit = {_str(chain.length_unit)}",
            f"angle_unit = {_str(chain.angle_unit)}"]
    if chain.task is not None:
        out.append("task = [" + ", ".join(_str(t) for t in chain.task) + "]")
    if chain.gravity != (0.0, 0.0, -9.81):
        out.append(f"gravity = {_vec(chain.gravity)}")
    if chain.sigma_floor is not None:
        out.append(f"sigma_floor = {_fmt(chain.sigma_floor)}")
    for j in chain.joints:
        out += ["", "[[joints]]"]
        if j.name:
            out.append(f"name = {_str(j.name)}")
        out.append(f"type = {_str(j.type)}")
        for f in DH_FIELDS:
            v = getattr(j, f)
            s = ls if f in LENGTH_FIELDS else as_
            out.append(f"{f} = {_str(v) if isinstance(v, str) else _fmt(_to_file(float(v), s))}")
        vs = as_ if j.is_revolute else ls
        out.append(f"limits = {_vec(j.limits, vs)}")
        for k in ("max_velocity", "max_acceleration"):
            v = getattr(j, k)
            if v is not None:
                out.append(f"{k} = {_fmt(_to_file(v, vs))}")
        if j.max_torque is not None:
            out.append(f"max_torque = {_fmt(j.max_torque)}")
        if j.inertia is not None:
            out += ["", "[joints.inertial]", *_inertial_lines(j.inertia, ls)]
    for label, pl in (("base", chain.base), ("tool", chain.tool)):
        if pl == Placement():
            continue
        out += ["", f"[{label}]"]
        if pl.matrix_ is not None:
            rows = [list(row) for row in pl.matrix_]
            out.append("matrix = [")
            for i, row in enumerate(rows):
                cells = [_fmt(x) for x in row[:3]] + [_fmt(_to_file(row[3], ls) if i < 3 else row[3])]
                out.append("  [" + ", ".join(cells) + "],")
            out.append("]")
        else:
            out.append(f"xyz = {_vec(pl.xyz, ls)}")
            out.append(f"rpy = {_vec(pl.rpy, as_)}")
    for pname, p in chain.parameters.items():
        s = ls if p.kind == "length" else as_
        out += ["", f"[parameters.{_key(pname)}]", f"value = {_fmt(_to_file(p.value, s))}",
                f"bounds = {_vec(p.bounds, s)}"]
    if chain.payload is not None:
        out += ["", "[payload]", *_inertial_lines(chain.payload, ls)]
    from kin.states import state_lines
    out += state_lines(chain, lambda x, s: _fmt(_to_file(x, s)))
    if chain.geometry is not None:
        out += _geometry_lines(chain, ls)
    if chain.visual:
        from kin.visual import visual_lines
        out += visual_lines(chain, _vec, _str, lambda b: body_label(chain, b), ls, as_, directory)
    return "\n".join(out) + "\n"


def _inertial_lines(li, ls: float) -> list[str]:
    """The keys of a [joints.inertial] or [payload] table, lengths in the file's unit."""
    out = [f"mass = {_fmt(li.mass)}", f"com = {_vec(li.com, ls)}", f"inertia = {_vec(li.inertia, ls * ls)}"]
    for k in ("motor_inertia", "viscous", "coulomb"):
        v = getattr(li, k)
        if v:
            out.append(f"{k} = {_fmt(v)}")
    return out


def _geometry_lines(chain: Chain, ls: float) -> list[str]:
    """The [geometry] table: the default capsules' radius, or every capsule (boxes and cylinders were
    turned into capsules at load, and are written as those)."""
    g = chain.geometry
    out = ["", "[geometry]"]
    if g.source not in ("default", "robot file"):
        out.append(f"source = {_str(g.source)}")
    if g.radius is not None:
        out.append(f"radius = {_fmt(_to_file(g.radius, ls))}")
    elif g.over_estimate > 0:
        out.append(f"over_estimate = {_fmt(_to_file(g.over_estimate, ls))}")
    if g.allowed:
        out.append("allow = [" + ", ".join(f"[{_str(body_label(chain, i))}, {_str(body_label(chain, j))}]"
                                           for i, j in sorted(g.allowed)) + "]")
    if g.radius is not None:
        return out
    for c in g.capsules:
        out += ["", "[[geometry.capsule]]", f"body = {_str(body_label(chain, c.body))}", f"a = {_vec(c.a, ls)}",
                f"b = {_vec(c.b, ls)}", f"radius = {_fmt(_to_file(c.radius, ls))}"]
        if c.name:
            out.append(f"name = {_str(c.name)}")
    if g.hulls:
        from kin.geometry.hull_table import hull_lines
        out += hull_lines(g.hulls, lambda b: body_label(chain, b), _vec, lambda x: _fmt(float(x)), _str, ls)
    return out


def save_robot(chain: Chain, path: str | Path) -> Path:
    """Write ``chain`` as a robot file with :func:`kin.output.write_output` (atomic; never replaces
    anything but a regular file; missing parent directories are created)."""
    return write_output(path, dumps_robot(chain, Path(path).parent))


def with_units(chain: Chain, length_unit: str | None = None, angle_unit: str | None = None) -> Chain:
    """The same chain, to be displayed and saved in other units (values stay SI inside)."""
    if length_unit is not None and length_unit not in LENGTH_UNITS:
        raise ChainError(f"length unit {length_unit!r} unknown; allowed: {', '.join(LENGTH_UNITS)}")
    if angle_unit is not None and angle_unit not in ANGLE_UNITS:
        raise ChainError(f"angle unit {angle_unit!r} unknown; allowed: {', '.join(ANGLE_UNITS)}")
    return replace(chain, length_unit=length_unit or chain.length_unit, angle_unit=angle_unit or chain.angle_unit)
