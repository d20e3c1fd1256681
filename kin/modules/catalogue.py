"""Module catalogues: the joint, link, base and tool modules a reconfigurable machine is built from,
and the connectors by which they meet (TOML files, validated like robot files, never evaluated).

A module has an *input* face (not a base) and an *output* face (not a tool), each a connector of a
named type.  Two faces meet when their types have the same root (a type may be ``like`` another:
it meets whatever that one meets), at one of the twists both allow about the connector axis.  Every
face carries a frame whose z axis points distally — out of an output face, into an input face — so
the next module's input frame is the previous output frame turned by the twist about z.

A joint module's *joint frame* (``axis``) is given in its input frame; the joint turns about (or
slides along) that frame's z; its output frame is given in the moved joint frame (``out``).  A link
module's output frame is given in its input frame (``out``, or ``length`` along z, an ``offset``
along x and a ``bend`` about the output's y); a base's output frame in the world; a tool's TCP in
its input frame.  A module's *proximal part* (mass model and capsules) is fixed to its input frame
(a base's to the world); a joint module's *distal part* moves with its output.  Masses are kg,
inertias kg·(length unit)² about the centre of mass (as in robot files), torques N·m (N for a
prismatic joint), costs plain numbers
in ``currency``; everything else in the file's ``length_unit`` and ``angle_unit``.  The library
holds everything SI (m, rad).  The format: docs/modules.md.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from kin.chain import ANGLE_UNITS, LENGTH_UNITS
from kin.errors import RmtError

__all__ = ["Catalogue", "CatalogueError", "Connector", "Module", "Part", "KINDS", "MAX_MODULES", "MAX_CONNECTORS",
           "MAX_CATALOGUE_BYTES"]

CATALOGUE_DIR = Path(__file__).resolve().parent.parent / "catalogues"
KINDS = ("base", "joint", "link", "tool")
TOP_FIELDS = ("name", "title", "source", "length_unit", "angle_unit", "currency", "connectors", "modules")
CONNECTOR_FIELDS = ("twists", "like", "title")
MODULE_FIELDS = {
    "base": ("name", "kind", "title", "cost", "output", "out", "inertial", "capsule"),
    "joint": ("name", "kind", "title", "cost", "input", "output", "type", "axis", "out", "limits", "max_velocity",
              "max_acceleration", "max_torque", "inertial", "distal_inertial", "capsule"),
    "link": ("name", "kind", "title", "cost", "input", "output", "out", "length", "offset", "bend", "inertial",
             "capsule"),
    "tool": ("name", "kind", "title", "cost", "input", "out", "inertial", "capsule"),
}
INERTIAL_FIELDS = ("mass", "com", "inertia")
CAPSULE_FIELDS = ("a", "b", "radius", "part")
FRAME_FIELDS = ("xyz", "rpy")
TYPE_RE = re.compile(r"^[A-Za-z0-9_.\-]{1,64}$")
#: a catalogue holds at most this many modules, connector types, twists per type, capsules per module
MAX_MODULES = 10_000
MAX_CONNECTORS = 1000
MAX_TWISTS = 360
MAX_CAPSULES = 16
MAX_CATALOGUE_BYTES = 10 * 2**20
MAX_MASS = 1e5          # kg
MAX_COST = 1e12


class CatalogueError(RmtError, ValueError):
    """A module catalogue that cannot be read: one line naming the file and the field."""

    def __init__(self, message: str, path: str | None = None, field: str | None = None):
        where = ": ".join(x for x in (path, field) if x)
        super().__init__(f"{where}: {message}" if where else message)
        self.path, self.field = path, field


@dataclass(frozen=True)
class Connector:
    """A connector type: ``root`` is the type it meets as (itself unless ``like`` another),
    ``twists`` the angles (rad, in [0, 2π)) at which two connectors of its root meet."""

    name: str
    root: str
    twists: tuple[float, ...]
    title: str = ""


@dataclass(frozen=True)
class Part:
    """A rigid part of a module in its frame (SI): ``mass`` (kg), ``com`` (m), ``inertia``
    (ixx, iyy, izz, ixy, ixz, iyz, kg·m² about the com) and ``capsules`` ((a, b, radius), m)."""

    mass: float = 0.0
    com: tuple[float, float, float] = (0.0, 0.0, 0.0)
    inertia: tuple[float, ...] = (0.0,) * 6
    capsules: tuple[tuple[tuple[float, ...], tuple[float, ...], float], ...] = ()

    def inertial(self, body: str = ""):
        """This part's :class:`kin.dynamics.LinkInertia` (its own frame)."""
        from kin.dynamics.inertia import LinkInertia
        return LinkInertia(self.mass, self.com, self.inertia, body=body)


@dataclass(frozen=True)
class Module:
    """One catalogue module (SI).  ``axis`` (joint frame in the input frame) and ``out`` (output
    frame: in the moved joint frame for a joint, the input frame for a link or tool, the world for a
    base) are 4×4 arrays; ``limits``, ``max_velocity``, ``max_acceleration``, ``max_torque`` are a
    joint's (rad or m; per s, s²; N·m or N)."""

    name: str
    kind: str
    cost: float
    input: str | None
    output: str | None
    out: np.ndarray = field(repr=False, compare=False, default_factory=lambda: np.eye(4))
    type: str | None = None
    axis: np.ndarray | None = field(repr=False, compare=False, default=None)
    limits: tuple[float, float] | None = None
    max_velocity: float | None = None
    max_acceleration: float | None = None
    max_torque: float | None = None
    proximal: Part = Part()
    distal: Part = Part()
    title: str = ""

    @property
    def is_joint(self) -> bool:
        return self.kind == "joint"


@dataclass(frozen=True)
class Catalogue:
    """A validated module catalogue (SI).  ``modules`` keeps the file's order."""

    name: str
    connectors: dict[str, Connector]
    modules: dict[str, Module]
    length_unit: str = "m"
    angle_unit: str = "rad"
    title: str = ""
    source: str = ""
    currency: str = ""
    path: str = ""

    def of_kind(self, kind: str) -> list[Module]:
        return [m for m in self.modules.values() if m.kind == kind]

    def meets(self, out_type: str, in_type: str) -> bool:
        """Whether an output face of ``out_type`` meets an input face of ``in_type``."""
        return bool(self.twists(out_type, in_type))

    def twists(self, out_type: str, in_type: str) -> tuple[float, ...]:
        """The twists (rad) at which an ``out_type`` output meets an ``in_type`` input (empty: never)."""
        a, b = self.connectors[out_type], self.connectors[in_type]
        if a.root != b.root:
            return ()
        return tuple(t for t in a.twists if any(_same_angle(t, u) for u in b.twists))

    @property
    def angle_scale(self) -> float:
        return ANGLE_UNITS[self.angle_unit]

    @property
    def length_scale(self) -> float:
        return LENGTH_UNITS[self.length_unit]


def _same_angle(a: float, b: float) -> bool:
    d = (a - b) % (2 * math.pi)
    return min(d, 2 * math.pi - d) < 1e-9
