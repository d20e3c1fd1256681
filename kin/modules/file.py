"""Reading module catalogues (TOML): every field validated, one line naming the file and the field
on any error (:class:`~kin.modules.catalogue.CatalogueError`); nothing is evaluated.  The format:
:mod:`kin.modules.catalogue` and docs/modules.md."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from kin.chain import ANGLE_UNITS, LENGTH_UNITS, NAME_RE
from kin.modules.catalogue import (
    CAPSULE_FIELDS,
    CATALOGUE_DIR,
    CONNECTOR_FIELDS,
    FRAME_FIELDS,
    INERTIAL_FIELDS,
    KINDS,
    MAX_CAPSULES,
    MAX_CATALOGUE_BYTES,
    MAX_CONNECTORS,
    MAX_COST,
    MAX_MASS,
    MAX_MODULES,
    MAX_TWISTS,
    MODULE_FIELDS,
    TOP_FIELDS,
    TYPE_RE,
    Catalogue,
    CatalogueError,
    Connector,
    Module,
    Part,
    _same_angle,
)
from kin.robotfile import MAX_LENGTH, MAX_TORQUE, _placement, _Reader
from kin.transforms import make_transform, rot_y

__all__ = ["load_catalogue", "loads_catalogue", "catalogue_path", "bundled_catalogues"]


# ---- reading -------------------------------------------------------------------------------------
class _CatReader(_Reader):
    def fail(self, field: str | None, msg: str) -> CatalogueError:
        return CatalogueError(msg, self.path, field)

    def bounded(self, v: Any, field: str, lo: float, hi: float, unit: str = "") -> float:
        x = self.number(v, field)
        if not lo <= x <= hi:
            raise self.fail(field, f"must be in [{lo:g}, {hi:g}]{unit}, got {x:g}")
        return x


def _frame(r: _CatReader, raw: Any, fld: str, ls: float, as_: float) -> np.ndarray:
    """A frame ``{xyz, rpy}`` (file units) as a 4×4 (SI), read as a robot file's placement is."""
    r.table(raw, fld, FRAME_FIELDS)          # xyz and rpy only: no `matrix` here
    return _placement(r, raw, fld, ls, as_).matrix


def _point(r: _CatReader, v: Any, fld: str, ls: float) -> tuple[float, float, float]:
    return tuple(r.length(x, f"{fld}[{i}]", ls) for i, x in enumerate(r.vector(v, fld, 3)))  # type: ignore[return-value]


def _capsules(r: _CatReader, raw: Any, fld: str, ls: float, joint: bool) -> dict[str, list]:
    out: dict[str, list] = {"proximal": [], "distal": []}
    if raw is None:
        return out
    if not isinstance(raw, list):
        raise r.fail(fld, "must be [[...capsule]] tables")
    if len(raw) > MAX_CAPSULES:
        raise r.fail(fld, f"{len(raw)} capsules; at most {MAX_CAPSULES} per module")
    for i, c in enumerate(raw):
        f = f"{fld}[{i}]"
        r.table(c, f, CAPSULE_FIELDS)
        for k in ("a", "b", "radius"):
            if k not in c:
                raise r.fail(f"{f}.{k}", "missing required field")
        part = r.string(c.get("part", "proximal"), f"{f}.part", ("proximal", "distal") if joint else ("proximal",))
        rad = r.number(c["radius"], f"{f}.radius") * ls
        if not 0 <= rad <= MAX_LENGTH:
            raise r.fail(f"{f}.radius", f"must be in [0, {MAX_LENGTH / ls:g}] (file length unit), got {c['radius']}")
        out[part].append((_point(r, c["a"], f"{f}.a", ls), _point(r, c["b"], f"{f}.b", ls), rad))
    return out


def _spread(mass: float, capsules: list) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Centre of mass and inertia (about it) of ``mass`` spread uniformly over ``capsules`` taken as
    solid cylinders (segment × radius; a point capsule as a solid ball), by volume."""
    from kin.dynamics.inertia import LinkInertia
    parts = []
    vols = []
    for a, b, rad in capsules:
        a, b = np.asarray(a), np.asarray(b)
        L = float(np.linalg.norm(b - a))
        if L < 1e-12:
            vols.append(4 / 3 * math.pi * rad ** 3)
            parts.append(("ball", a, None, L, rad))
        else:
            vols.append(math.pi * rad * rad * L)
            parts.append(("cyl", (a + b) / 2, (b - a) / L, L, rad))
    total = sum(vols)
    if total <= 0:       # massless-radius capsules: the mass along the segments by length
        vols = [max(p[3], 1e-12) for p in parts]
        total = sum(vols)
    pieces = []
    for (kind, c, u, L, rad), v in zip(parts, vols):
        m = mass * v / total
        if kind == "ball":
            Mi = np.eye(3) * (0.4 * m * rad * rad)
        else:
            ia, ip = 0.5 * m * rad * rad, m * (3 * rad * rad + L * L) / 12
            Mi = ip * np.eye(3) + (ia - ip) * np.outer(u, u)
        pieces.append(LinkInertia(m, tuple(c), (Mi[0, 0], Mi[1, 1], Mi[2, 2], Mi[0, 1], Mi[0, 2], Mi[1, 2])))
    li = LinkInertia.combined(pieces)
    return li.com, li.inertia


def _part(r: _CatReader, raw: Any, fld: str, ls: float, capsules: list) -> Part:
    from kin.dynamics.inertia import InertiaError, LinkInertia
    caps = tuple(capsules)
    if raw is None:
        return Part(capsules=caps)
    r.table(raw, fld, INERTIAL_FIELDS)
    if "mass" not in raw:
        raise r.fail(f"{fld}.mass", "missing required field: the part's mass in kg")
    mass = r.number(raw["mass"], f"{fld}.mass")
    if not 0 <= mass <= MAX_MASS:
        raise r.fail(f"{fld}.mass", f"must be ≥ 0 and at most {MAX_MASS:g} kg, got {mass:g}")
    if "com" in raw:
        com = _point(r, raw["com"], f"{fld}.com", ls)
    elif caps:
        com = _spread(mass, list(caps))[0]
    else:
        raise r.fail(f"{fld}.com", "missing: give the centre of mass, or capsules to spread the mass over")
    if "inertia" in raw:
        inertia = tuple(x * ls * ls for x in r.vector(raw["inertia"], f"{fld}.inertia", 6))
    elif caps:
        c0, i0 = _spread(mass, list(caps))
        d = np.asarray(c0) - np.asarray(com)       # the spread's tensor moved to the stated com
        Mi = (LinkInertia(mass, c0, i0).tensor + mass * (float(d @ d) * np.eye(3) - np.outer(d, d)))
        inertia = (Mi[0, 0], Mi[1, 1], Mi[2, 2], Mi[0, 1], Mi[0, 2], Mi[1, 2])
    else:
        inertia = (0.0,) * 6
    try:
        li = LinkInertia(mass, com, tuple(float(x) for x in inertia))
    except InertiaError as e:
        raise r.fail(f"{fld}.inertia", f"is not a rigid body's: {str(e).split(': ', 1)[-1]}") from None
    return Part(li.mass, li.com, li.inertia, caps)


def _connectors(r: _CatReader, raw: Any, as_: float) -> dict[str, Connector]:
    raw = r.table(raw, "connectors", tuple(raw) if isinstance(raw, dict) else ())
    if not raw:
        raise r.fail("connectors", "must define at least one connector type ([connectors.NAME] with twists)")
    if len(raw) > MAX_CONNECTORS:
        raise r.fail("connectors", f"{len(raw)} connector types; at most {MAX_CONNECTORS}")
    like: dict[str, str | None] = {}
    own: dict[str, tuple[float, ...] | None] = {}
    titles: dict[str, str] = {}
    for name, c in raw.items():
        fld = f"connectors.{name}"
        if not TYPE_RE.match(name):
            raise r.fail(fld, "connector type names must match [A-Za-z0-9_.-]{1,64}")
        r.table(c, fld, CONNECTOR_FIELDS)
        titles[name] = r.string(c["title"], f"{fld}.title") if "title" in c else ""
        like[name] = r.string(c["like"], f"{fld}.like") if "like" in c else None
        if like[name] is not None and like[name] not in raw:
            raise r.fail(f"{fld}.like", f"unknown connector type {like[name]!r}; defined: {', '.join(raw)}")
        if "twists" in c:
            tw = c["twists"]
            if not isinstance(tw, list) or not tw:
                raise r.fail(f"{fld}.twists", "must be a non-empty list of angles")
            if len(tw) > MAX_TWISTS:
                raise r.fail(f"{fld}.twists", f"{len(tw)} twists; at most {MAX_TWISTS}")
            vals = []
            for i, t in enumerate(tw):
                x = r.angle(t, f"{fld}.twists[{i}]", as_) % (2 * math.pi)
                if any(_same_angle(x, y) for y in vals):
                    raise r.fail(f"{fld}.twists[{i}]", f"{t} repeats an earlier twist (modulo a full turn)")
                vals.append(x)
            own[name] = tuple(vals)
        elif like[name] is None:
            raise r.fail(f"{fld}.twists", "missing: the angles at which two connectors of this type meet "
                         "(or `like` another type)")
        else:
            own[name] = None
    out = {}
    for name in raw:
        seen, t = [name], name
        while like[t] is not None:
            t = like[t]  # type: ignore[assignment]
            if t in seen:
                cyc = " -> ".join([*seen[seen.index(t):], t])
                raise r.fail(f"connectors.{name}.like", f"the connector rules form a cycle: {cyc}")
            seen.append(t)
        twists = next(own[s] for s in seen if own[s] is not None)
        out[name] = Connector(name, t, twists, titles[name])  # type: ignore[arg-type]
    return out


def _module(r: _CatReader, raw: Any, i: int, ls: float, as_: float, connectors: dict) -> Module:
    fld = f"modules[{i}]"
    if not isinstance(raw, dict):
        raise r.fail(fld, "must be a [[modules]] table")
    kind = r.string(raw.get("kind"), f"{fld}.kind", KINDS) if "kind" in raw else None
    if kind is None:
        raise r.fail(f"{fld}.kind", f"missing required field; allowed: {', '.join(KINDS)}")
    if isinstance(raw.get("name"), str) and TYPE_RE.match(raw["name"]):
        fld = f"modules[{i}] ({raw['name']})"          # messages name the module as soon as it has a name
    r.table(raw, fld, MODULE_FIELDS[kind])
    for k in ("name", "cost"):
        if k not in raw:
            raise r.fail(f"{fld}.{k}", "missing required field")
    name = r.string(raw["name"], f"modules[{i}].name")
    if not TYPE_RE.match(name):
        raise r.fail(f"modules[{i}].name", f"{name!r} must match [A-Za-z0-9_.-]{{1,64}}")
    fld = f"modules[{i}] ({name})"
    cost = r.bounded(raw["cost"], f"{fld}.cost", 0.0, MAX_COST)
    faces = {}
    for face in ("input", "output"):
        if face not in MODULE_FIELDS[kind]:
            faces[face] = None
            continue
        if face not in raw:
            raise r.fail(f"{fld}.{face}", "missing required field: a connector type")
        t = r.string(raw[face], f"{fld}.{face}")
        if t not in connectors:
            raise r.fail(f"{fld}.{face}", f"unknown connector type {t!r}; defined: {', '.join(connectors)}")
        faces[face] = t
    caps = _capsules(r, raw.get("capsule"), f"{fld}.capsule", ls, kind == "joint")
    kw: dict[str, Any] = {}
    if kind == "joint":
        for k in ("type", "axis", "out", "limits", "max_velocity", "max_torque"):
            if k not in raw:
                raise r.fail(f"{fld}.{k}", "missing required field")
        jt = r.string(raw["type"], f"{fld}.type", ("revolute", "prismatic"))
        unit = as_ if jt == "revolute" else ls
        lo, hi = r.vector(raw["limits"], f"{fld}.limits", 2)
        lim = (r.angle(lo, f"{fld}.limits[0]", as_), r.angle(hi, f"{fld}.limits[1]", as_)) if jt == "revolute" \
            else (r.length(lo, f"{fld}.limits[0]", ls), r.length(hi, f"{fld}.limits[1]", ls))
        if not lim[0] < lim[1]:
            raise r.fail(f"{fld}.limits", f"must be [low, high] with low < high, got {raw['limits']}")
        kw.update(type=jt, axis=_frame(r, raw["axis"], f"{fld}.axis", ls, as_), limits=lim,
                  max_velocity=r.bounded(raw["max_velocity"], f"{fld}.max_velocity", 1e-9, 1e7 / unit) * unit,
                  max_torque=r.bounded(raw["max_torque"], f"{fld}.max_torque", 1e-9, MAX_TORQUE, " N·m or N"))
        if "max_acceleration" in raw:
            kw["max_acceleration"] = r.bounded(raw["max_acceleration"], f"{fld}.max_acceleration", 1e-9,
                                               1e9 / unit) * unit
        kw["distal"] = _part(r, raw.get("distal_inertial"), f"{fld}.distal_inertial", ls, caps["distal"])
    if kind == "link" and "out" not in raw:
        if "length" not in raw:
            raise r.fail(f"{fld}.out", "missing: give `out` (the output frame) or `length` (and `offset`, `bend`)")
        L = r.length(raw["length"], f"{fld}.length", ls)
        off = r.length(raw.get("offset", 0.0), f"{fld}.offset", ls)
        bend = r.angle(raw.get("bend", 0.0), f"{fld}.bend", as_)
        out = make_transform(rot_y(bend), [off, 0.0, L])
    else:
        for k in ("length", "offset", "bend"):
            if k in raw:
                raise r.fail(f"{fld}.{k}", "give either `out` or `length`/`offset`/`bend`, not both")
        if "out" not in raw:
            raise r.fail(f"{fld}.out", "missing required field: the output frame (xyz, rpy)"
                         if kind != "tool" else "missing required field: the tool centre point (xyz, rpy)")
        out = _frame(r, raw["out"], f"{fld}.out", ls, as_)
    return Module(name=name, kind=kind, cost=cost, input=faces["input"], output=faces["output"], out=out,
                  proximal=_part(r, raw.get("inertial"), f"{fld}.inertial", ls, caps["proximal"]),
                  title=r.string(raw["title"], f"{fld}.title") if "title" in raw else "", **kw)


def _connected(r: _CatReader, cat: Catalogue) -> None:
    """Refuse a module that connects to nothing: a base whose output no module's input meets, or a
    module that no chain of modules from a base can reach (no output reachable from a base meets its
    input)."""
    if not cat.of_kind("joint"):
        raise r.fail("modules", "the catalogue has no joint module (kind = \"joint\")")
    if not cat.of_kind("base"):
        raise r.fail("modules", "the catalogue has no base module (kind = \"base\"): an assembly starts at a base")
    root = {c: cat.connectors[c].root for c in cat.connectors}
    ins = {root[m.input] for m in cat.modules.values() if m.input is not None}
    names = list(cat.modules)
    for i, m in enumerate(cat.modules.values()):
        if m.kind == "base" and root[m.output] not in ins:
            raise r.fail(f"modules[{i}] ({m.name}).output", f"module {m.name!r} connects to nothing: no module's "
                         f"input meets its output {m.output!r}")
    reach = {root[m.output] for m in cat.of_kind("base")}
    grew = True
    while grew:
        grew = False
        for m in cat.modules.values():
            if m.input is not None and m.output is not None and root[m.input] in reach and root[m.output] not in reach:
                reach.add(root[m.output])
                grew = True
    for m in cat.modules.values():
        if m.input is not None and root[m.input] not in reach:
            i = names.index(m.name)
            raise r.fail(f"modules[{i}] ({m.name}).input", f"module {m.name!r} connects to nothing: no chain of "
                         f"modules from a base has an output that meets its input {m.input!r}")


def loads_catalogue(text: str, path: str | None = None) -> Catalogue:
    """Parse and validate catalogue text; ``path`` only names the file in messages."""
    r = _CatReader(path)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise r.fail(None, f"not valid TOML ({e})") from None
    r.table(doc, "", TOP_FIELDS)
    for k in ("name", "length_unit", "angle_unit", "connectors", "modules"):
        if k not in doc:
            raise r.fail(k, "missing required field")
    name = r.string(doc["name"], "name")
    if not NAME_RE.match(name):
        raise r.fail("name", f"{name!r} must match [a-z0-9_]+")
    lu = r.string(doc["length_unit"], "length_unit", tuple(LENGTH_UNITS))
    au = r.string(doc["angle_unit"], "angle_unit", tuple(ANGLE_UNITS))
    ls, as_ = LENGTH_UNITS[lu], ANGLE_UNITS[au]
    mods = doc["modules"]
    if not isinstance(mods, list) or not mods:
        raise r.fail("modules", "must hold at least one [[modules]] table")
    if len(mods) > MAX_MODULES:
        raise r.fail("modules", f"{len(mods)} modules; at most {MAX_MODULES}")
    connectors = _connectors(r, doc["connectors"], as_)
    modules: dict[str, Module] = {}
    for i, raw in enumerate(mods):
        m = _module(r, raw, i, ls, as_, connectors)
        if m.name in modules:
            raise r.fail(f"modules[{i}].name", f"{m.name!r} is defined twice")
        modules[m.name] = m
    text_fields = {k: r.string(doc[k], k) for k in ("title", "source", "currency") if k in doc}
    cat = Catalogue(name=name, connectors=connectors, modules=modules, length_unit=lu, angle_unit=au,
                    path=path or "", **text_fields)
    _connected(r, cat)
    return cat


def bundled_catalogues() -> list[str]:
    """Names of the bundled catalogues."""
    return sorted(p.stem for p in CATALOGUE_DIR.glob("*.toml"))


def catalogue_path(name_or_path: str | Path) -> Path:
    """A bundled catalogue's name or a file path → an existing file's path."""
    from kin.files import named_file
    p, given = named_file(name_or_path, CATALOGUE_DIR)
    if p.is_file():
        return p
    if given:
        raise CatalogueError("no such catalogue file", str(name_or_path))
    raise CatalogueError(f"unknown catalogue {str(name_or_path)!r}; bundled: "
                         f"{', '.join(bundled_catalogues()) or 'none'} (or give a path to a .toml file)")


def load_catalogue(name_or_path: str | Path) -> Catalogue:
    """Load a bundled catalogue by name, or a catalogue file by path (SI)."""
    from kin.files import read_text
    path = catalogue_path(name_or_path)
    text = read_text(path, "module catalogue", MAX_CATALOGUE_BYTES, error=CatalogueError)
    return loads_catalogue(text, str(path))
