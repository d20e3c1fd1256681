"""The chain model: joints described by DH rows, limits, base/tool placement, design parameters.

Everything here is in SI units (m, rad).  Robot files carry their own units; :mod:`kin.robotfile`
converts once, at load.  A DH value (``a``, ``alpha``, ``d``, ``theta``) is either a number or the
name of a design parameter declared in :attr:`Chain.parameters`, so that design studies can vary it
and differentiate with respect to it.

Conventions (per row i, joint variable q_i):

* standard (distal) DH:   A_i = Rz(θ_i)·Tz(d_i)·Tx(a_i)·Rx(α_i); joint i moves about/along z_{i-1}
* modified (proximal) DH: A_i = Rx(α_{i-1})·Tx(a_{i-1})·Rz(θ_i)·Tz(d_i); row i holds a_{i-1}, α_{i-1}

A revolute joint has θ_i = q_i + theta (theta is the offset); a prismatic joint has
d_i = q_i + d (theta is a fixed angle).  FK = base · A_1 ⋯ A_n · tool.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from typing import Literal, Mapping, Sequence

import numpy as np

from kin.errors import ChainError, ConfigurationError, JointLimitError, ParameterError
from kin.placement import IDENTITY, Placement
from kin.transforms import make_transform, rigidity_defect, rot_x

JointType = Literal["revolute", "prismatic"]
Convention = Literal["standard", "modified"]

JOINT_TYPES = ("revolute", "prismatic")
CONVENTIONS = ("standard", "modified")
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "in": 0.0254}
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}
DH_FIELDS = ("a", "alpha", "d", "theta")
LENGTH_FIELDS = ("a", "d")
ANGLE_FIELDS = ("alpha", "theta")
TASK_ROWS = ("x", "y", "z", "rx", "ry", "rz")
NAME_RE = re.compile(r"^[a-z0-9_]+$")
#: the largest magnitude (m) of a prismatic joint value or a length design parameter that the
#: evaluators accept: 100 times the largest length a robot file may hold (10 km), so far outside
#: every joint's limits, yet small enough that no FK, Jacobian or dexterity measure overflows
#: (revolute joint values may be any finite angle: only their sine and cosine are used)
MAX_PRISMATIC = 1e6

Value = float | str  # a number (SI) or the name of a design parameter


@dataclass(frozen=True)
class Parameter:
    """A named design parameter: nominal value and bounds (SI), and whether it is a length or angle."""

    value: float
    bounds: tuple[float, float]
    kind: Literal["length", "angle"] = "length"




@dataclass(frozen=True)
class Joint:
    """One DH row and its joint.  SI units; a DH value may be a design-parameter name."""

    type: JointType
    a: Value = 0.0
    alpha: Value = 0.0
    d: Value = 0.0
    theta: Value = 0.0
    limits: tuple[float, float] = (-math.pi, math.pi)
    name: str | None = None
    max_velocity: float | None = None       # rad/s or m/s
    max_acceleration: float | None = None   # rad/s² or m/s²
    #: the largest joint torque (N·m, revolute) or force (N, prismatic) the drive gives; None: unknown
    max_torque: float | None = None
    #: the link's inertial model (:class:`kin.dynamics.LinkInertia`, in DH frame k); None: unknown
    inertia: object | None = None

    @property
    def is_revolute(self) -> bool:
        return self.type == "revolute"


@dataclass(frozen=True)
class Chain:
    """A serial chain of joint modules.

    ``task`` lists the rows of the 6-row geometric Jacobian (``x y z rx ry rz``) that the chain is
    meant to control; ``None`` picks them automatically (all six for six or more joints, the
    position rows that are not identically zero otherwise).  Manipulability, σ_min, the condition
    number and det J are computed on those rows.
    """

    name: str
    joints: tuple[Joint, ...]
    convention: Convention = "standard"
    title: str = ""
    source: str = ""
    length_unit: str = "m"
    angle_unit: str = "rad"
    base: Placement = IDENTITY
    tool: Placement = IDENTITY
    parameters: Mapping[str, Parameter] = field(default_factory=dict)
    task: tuple[str, ...] | None = None
    #: collision capsules (:class:`kin.geometry.RobotGeometry`); None: :func:`kin.geometry.default_geometry`
    geometry: object | None = None
    #: a payload at the tool (:class:`kin.dynamics.LinkInertia` in the tool frame); None: none
    payload: object | None = None
    #: gravity in the base placement's frame (m/s², the frame below ``base``): default 9.81 m/s² down z
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    #: the σ_min floor (SI) the CLI's path checks apply by default; None: the rule of
    #: :func:`kin.singular.floor.default_sigma_floor` (docs/robot-files.md, "sigma_floor")
    sigma_floor: float | None = None
    #: named configurations ("home"), SI, each inside the limits (:mod:`kin.states`; a robot file's [states])
    states: Mapping[str, tuple[float, ...]] = field(default_factory=dict)
    #: meshes a viewer draws on the bodies (:class:`kin.visual.VisualMesh`; a robot file's [visual]) and their source
    visual: tuple = ()
    visual_source: str = ""

    def __post_init__(self):
        if not self.joints:
            raise ChainError(f"chain {self.name!r} has no joints; a chain needs at least one")
        if self.convention not in CONVENTIONS:
            raise ChainError(f"convention {self.convention!r} unknown; allowed: {', '.join(CONVENTIONS)}")
        object.__setattr__(self, "joints", tuple(self.joints))
        object.__setattr__(self, "parameters", dict(self.parameters))
        for i, j in enumerate(self.joints, 1):
            if j.type not in JOINT_TYPES:
                raise ChainError(f"joint {i}: type {j.type!r} unknown; allowed: {', '.join(JOINT_TYPES)}")
            lo, hi = j.limits
            if not (math.isfinite(lo) and math.isfinite(hi)) or not lo < hi:
                raise ChainError(f"joint {i}: limits {j.limits} must be finite with lower < upper")
            for f in DH_FIELDS:
                v = getattr(j, f)
                if isinstance(v, str):
                    if v not in self.parameters:
                        raise ChainError(f"joint {i}: {f} refers to undefined parameter {v!r}; "
                                         f"defined: {', '.join(self.parameters) or 'none'}")
                    # the kind decides the unit a robot file writes the parameter in: it must match its use
                    kind = "length" if f in LENGTH_FIELDS else "angle"
                    if self.parameters[v].kind != kind:
                        raise ChainError(f"joint {i}: {f} uses parameter {v!r} of kind "
                                         f"{self.parameters[v].kind!r}; a {f} parameter must have kind {kind!r}")
                elif not math.isfinite(float(v)):
                    raise ChainError(f"joint {i}: {f} = {v} is not a finite number")
        for label in ("base", "tool"):
            pl = getattr(self, label)
            raw = np.array(pl.matrix_ if pl.matrix_ is not None else (*pl.xyz, *pl.rpy), dtype=float)
            if not np.all(np.isfinite(raw)):
                raise ChainError(f"{label} placement holds NaN or infinite values")
            T = pl.matrix
            if rigidity_defect(T) > 1e-6:
                raise ChainError(f"{label} placement is not a rigid transform (rotation not orthonormal with "
                                 f"det +1, or bottom row not [0, 0, 0, 1])")
        wrong = [v.body for v in self.visual if not 0 <= v.body <= self.n + 1]
        if wrong:
            raise ChainError(f"visual: a mesh on body {wrong[0]}; the bodies of a {self.n}-joint chain are "
                             f"0 (base) … {self.n + 1} (tool)")
        if self.geometry is not None:
            bodies = [c.body for c in getattr(self.geometry, "capsules", ())]
            wrong = [b for b in bodies if not 0 <= b <= self.n + 1]
            if wrong:
                raise ChainError(f"geometry: a capsule on body {wrong[0]}; the bodies of a {self.n}-joint chain are "
                                 f"0 (base) … {self.n + 1} (tool)")
        for i, j in enumerate(self.joints, 1):
            t = j.max_torque
            if t is not None and (isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t)
                                  or t <= 0):
                unit = "N·m" if j.type == "revolute" else "N"
                raise ChainError(f"joint {i}: max_torque = {t!r} must be a positive finite number ({unit}) or None")
        from kin.dynamics.inertia import LinkInertia
        for i, j in enumerate(self.joints, 1):
            if j.inertia is not None and not isinstance(j.inertia, LinkInertia):
                raise ChainError(f"joint {i}: inertia must be a kin.dynamics.LinkInertia, got "
                                 f"{type(j.inertia).__name__}")
        if self.payload is not None and not isinstance(self.payload, LinkInertia):
            raise ChainError(f"payload must be a kin.dynamics.LinkInertia, got {type(self.payload).__name__}")
        g = np.asarray(self.gravity, dtype=float) if not isinstance(self.gravity, str) else np.array([np.nan])
        if g.shape != (3,) or not np.all(np.isfinite(g)) or float(np.linalg.norm(g)) > 1e3:
            raise ChainError(f"gravity {self.gravity!r} must be 3 finite numbers (m/s², at most 1000 in size)")
        object.__setattr__(self, "gravity", tuple(float(x) for x in g))
        f = self.sigma_floor
        if f is not None and (isinstance(f, bool) or not isinstance(f, (int, float)) or not math.isfinite(f)
                              or not 0 <= f <= 1e3):
            raise ChainError(f"sigma_floor = {f!r} must be a finite number in [0, 1000] (SI) or None")
        if self.task is not None:
            bad = [r for r in self.task if r not in TASK_ROWS]
            if bad or not self.task or len(set(self.task)) != len(self.task):
                raise ChainError(f"task {self.task!r} invalid; rows must be distinct, from {', '.join(TASK_ROWS)}")
        from kin.states import checked_states
        object.__setattr__(self, "states", checked_states(self, self.states))

    # ---- sizes and limits ------------------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def joint_types(self) -> tuple[str, ...]:
        return tuple(j.type for j in self.joints)

    @property
    def revolute_mask(self) -> np.ndarray:
        """Boolean (n,): True for revolute joints."""
        return np.array([j.is_revolute for j in self.joints])

    @property
    def lower(self) -> np.ndarray:
        return np.array([j.limits[0] for j in self.joints])

    @property
    def upper(self) -> np.ndarray:
        return np.array([j.limits[1] for j in self.joints])

    @property
    def limits(self) -> np.ndarray:
        """Joint limits, shape (n, 2), SI."""
        return np.array([j.limits for j in self.joints], dtype=float)

    @property
    def length_scale(self) -> float:
        """Metres per file length unit."""
        return LENGTH_UNITS[self.length_unit]

    @property
    def angle_scale(self) -> float:
        """Radians per file angle unit."""
        return ANGLE_UNITS[self.angle_unit]

    @property
    def variable_scale(self) -> np.ndarray:
        """SI units per file unit of each joint variable (angle unit for revolute, length for prismatic), (n,)."""
        return np.where(self.revolute_mask, self.angle_scale, self.length_scale)

    def to_si(self, q_file) -> np.ndarray:
        """Joint values in the file's units → SI (same shape)."""
        return np.asarray(q_file, dtype=float) * self.variable_scale

    def from_si(self, q) -> np.ndarray:
        """Joint values in SI → the file's units (same shape)."""
        return np.asarray(q, dtype=float) / self.variable_scale

    def joint_names(self) -> list[str]:
        return [j.name or f"q{i}" for i, j in enumerate(self.joints, 1)]

    # ---- design parameters -----------------------------------------------------------------
    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(self.parameters)

    @property
    def parameter_values(self) -> np.ndarray:
        """Nominal design-parameter vector, shape (n_p,), in :attr:`parameter_names` order."""
        return np.array([p.value for p in self.parameters.values()], dtype=float)

    def parameter_vector(self, values: Mapping[str, float] | Sequence[float] | np.ndarray | None = None) -> np.ndarray:
        """Resolve ``values`` (a mapping name → SI value, or a full vector) into a parameter vector.

        Names not given keep their nominal value.  Unknown names raise :class:`ParameterError`.
        """
        p = self.parameter_values
        if values is None:
            return p
        if isinstance(values, Mapping):
            names = list(self.parameters)
            for k, v in values.items():
                if k not in self.parameters:
                    raise ParameterError(f"unknown design parameter {k!r}; defined: {', '.join(names) or 'none'}")
                v = float(v)
                if not math.isfinite(v):
                    raise ParameterError(f"design parameter {k!r} = {v} is not finite")
                if self.parameters[k].kind == "length" and abs(v) > MAX_PRISMATIC:
                    raise ParameterError(f"design parameter {k!r} = {v:.6g} m is beyond ±{MAX_PRISMATIC:g} m, "
                                         f"the range a length may take")
                p[names.index(k)] = v
            return p
        arr = np.asarray(values, dtype=float)
        if arr.shape[-1:] != (len(p),) and not (len(p) == 0 and arr.size == 0):
            raise ParameterError(f"parameter vector has shape {arr.shape}; expected (..., {len(p)}) "
                                 f"for {', '.join(self.parameters) or 'no parameters'}")
        if not (np.abs(arr) <= MAX_PRISMATIC).all():     # one pass in the common case (NaN compares False)
            if not np.all(np.isfinite(arr)):
                raise ParameterError("parameter vector holds NaN or infinite values")
            length = np.array([q.kind == "length" for q in self.parameters.values()], dtype=bool)
            beyond = (np.abs(arr) > MAX_PRISMATIC) & length
            if beyond.any():
                k, v = int(np.argwhere(beyond)[0][-1]), float(arr[beyond][0])
                raise ParameterError(f"design parameter {list(self.parameters)[k]!r} = {v:.6g} m is beyond "
                                     f"±{MAX_PRISMATIC:g} m, the range a length may take")
        return arr

    def resolve(self, value: Value, params: np.ndarray | None = None) -> float:
        """Numeric value of a DH entry (a number, or a parameter name looked up in ``params``)."""
        if isinstance(value, str):
            p = self.parameter_values if params is None else params
            return float(p[list(self.parameters).index(value)])
        return float(value)

    def dh_table(self, params: np.ndarray | None = None) -> np.ndarray:
        """Numeric DH table, shape (n, 4), columns a, alpha, d, theta (SI), parameters resolved."""
        return np.array([[self.resolve(getattr(j, f), params) for f in DH_FIELDS] for j in self.joints])

    def with_parameters(self, values: Mapping[str, float]) -> "Chain":
        """A copy of this chain whose parameters have new nominal values (SI)."""
        vec = self.parameter_vector(values)
        params = {k: replace(p, value=float(v)) for (k, p), v in zip(self.parameters.items(), vec)}
        return replace(self, parameters=params)._default_geometry_again()

    def frozen(self, params: np.ndarray | None = None) -> "Chain":
        """A copy with every parameter name replaced by its (given or nominal) value."""
        joints = tuple(replace(j, **{f: self.resolve(getattr(j, f), params) for f in DH_FIELDS}) for j in self.joints)
        return replace(self, joints=joints, parameters={})._default_geometry_again()

    # ---- geometry --------------------------------------------------------------------------
    def _default_geometry_again(self) -> "Chain":
        """A geometry made of the default capsules (a stated radius: ``[geometry] radius``) follows the
        DH offsets: rebuilt for this chain's rows, with the same radius, allowed pairs and source."""
        g = self.geometry
        if g is None or getattr(g, "radius", None) is None:
            return self
        from kin.geometry.default import default_geometry
        from kin.geometry.model import RobotGeometry
        new = default_geometry(self, g.radius)
        return replace(self, geometry=RobotGeometry(new.capsules, g.allowed, g.source, g.radius, g.over_estimate))

    def _moved_geometry(self, chain: "Chain", transforms: Mapping[int, np.ndarray]) -> "Chain":
        """``chain`` (this machine in other DH frames) with this chain's capsules: body k's capsule
        points mapped by ``transforms[k]`` (4×4, old frame k → new frame k; absent: unchanged)."""
        if self.visual:
            from kin.visual import moved_visual
            chain = replace(chain, visual=moved_visual(self.visual, transforms))
        g = self.geometry
        if g is None:
            return chain
        if getattr(g, "radius", None) is not None:
            return replace(chain, geometry=g)._default_geometry_again()
        caps = []
        for c in g.capsules:
            T = transforms.get(c.body)
            if T is not None:       # coordinates below 1 nm are rounding noise: 0, as a robot file reads them
                a, b = (np.where(np.abs(v) < 1e-9, 0.0, v) for v in (T[:3, :3] @ np.array(c.a) + T[:3, 3],
                                                                    T[:3, :3] @ np.array(c.b) + T[:3, 3]))
                c = replace(c, a=tuple(float(x) for x in a), b=tuple(float(x) for x in b))
            caps.append(c)
        hulls = tuple(replace(h, points=h.array @ transforms[h.body][:3, :3].T + transforms[h.body][:3, 3])
                      if h.body in transforms else h for h in g.hulls)
        return replace(chain, geometry=replace(g, capsules=tuple(caps), hulls=hulls))

    @staticmethod
    def _moved_inertia(joints: Sequence[Joint], transforms: Mapping[int, np.ndarray]) -> tuple[Joint, ...]:
        """``joints`` with each body k's inertial model re-expressed by ``transforms[k]`` (old frame k →
        new frame k), as the capsules are; the payload stays in the tool frame, which does not move."""
        return tuple(replace(j, inertia=j.inertia.transformed(transforms[k]))
                     if j.inertia is not None and k in transforms else j for k, j in enumerate(joints, 1))

    # ---- configurations --------------------------------------------------------------------
    def as_batch(self, q, what: str = "q", bounded: bool = True) -> tuple[np.ndarray, bool]:
        """Validate a configuration (n,) or batch (N, n); return (batch (N, n), was_single).

        Values must be finite, and with ``bounded`` a prismatic joint's within ±:data:`MAX_PRISMATIC`
        (:class:`ConfigurationError` otherwise); ``bounded=False`` is for the limit checks, which
        answer for any finite value.
        """
        arr = np.asarray(q, dtype=float)
        single = arr.ndim == 1
        if single:
            arr = arr[None, :]
        if arr.ndim != 2 or arr.shape[1] != self.n:
            raise ConfigurationError(f"{what} has shape {np.shape(q)}; expected ({self.n},) or (N, {self.n}) "
                                     f"for {self.name} ({self.n} joints)")
        if not (np.abs(arr) <= MAX_PRISMATIC).all():     # one pass in the common case (NaN compares False)
            if not np.all(np.isfinite(arr)):
                bad = np.argwhere(~np.isfinite(arr))[0]
                raise ConfigurationError(f"{what} holds a non-finite value (row {bad[0]}, joint {bad[1] + 1})")
            beyond = (np.abs(arr) > MAX_PRISMATIC) & ~self.revolute_mask
            if bounded and beyond.any():
                r, j = np.argwhere(beyond)[0]
                lo, hi = self.joints[j].limits
                where = "" if single else f" (row {r})"
                raise ConfigurationError(f"{what}: prismatic joint {j + 1} = {arr[r, j]:.6g} m{where} is beyond "
                                         f"±{MAX_PRISMATIC:g} m, the range a prismatic joint value may take "
                                         f"(its limits: [{lo:.6g}, {hi:.6g}] m)")
        return np.ascontiguousarray(arr), single

    def within_limits(self, q, tol: float = 0.0) -> np.ndarray | bool:
        """True where every joint is inside its limits (± tol); bool or (N,) bool array."""
        Q, single = self.as_batch(q, bounded=False)
        ok = np.all((Q >= self.lower - tol) & (Q <= self.upper + tol), axis=1)
        return bool(ok[0]) if single else ok

    def limit_violations(self, q, tol: float = 1e-12) -> list[tuple[int, float, tuple[float, float]]]:
        """The joints of one configuration outside their limits: (1-based index, value, limits), SI."""
        Q, _ = self.as_batch(q, bounded=False)
        out = []
        for i, (v, j) in enumerate(zip(Q[0], self.joints), 1):
            if v < j.limits[0] - tol or v > j.limits[1] + tol:
                out.append((i, float(v), j.limits))
        return out

    def check_limits(self, q, tol: float = 1e-12) -> None:
        """Raise :class:`JointLimitError` naming the first joint of ``q`` outside its limits.

        ``q`` is one configuration (n,) or a batch (N, n); every row of a batch is checked.
        """
        Q, single = self.as_batch(q, bounded=False)
        for r, row in enumerate(Q):
            bad = self.limit_violations(row, tol)
            if bad:
                i, v, (lo, hi) = bad[0]
                unit = "rad" if self.joints[i - 1].is_revolute else "m"
                where = "" if single else f" (row {r})"
                raise JointLimitError(f"{self.name}: joint {i} = {v:.6g} {unit}{where} is outside its limits "
                                      f"[{lo:.6g}, {hi:.6g}] {unit}")

    # ---- task rows -------------------------------------------------------------------------
    def task_rows(self, zero_rows: Sequence[int] = ()) -> tuple[int, ...]:
        """Indices (0..5) of the controlled Jacobian rows.

        ``zero_rows`` are rows known to be identically zero (found by the symbolic model); they are
        dropped from the automatic choice.
        """
        if self.task is not None:
            return tuple(TASK_ROWS.index(r) for r in self.task)
        if self.n >= 6:
            return tuple(range(6))
        return tuple(r for r in range(3) if r not in zero_rows)

    # ---- convention conversion -------------------------------------------------------------
    def to_modified(self) -> "Chain":
        """The same machine in modified (proximal) DH.  FK is unchanged.

        The last row's Tx(a_n)·Rx(α_n) moves into the tool transform; it must be numeric.
        """
        if self.convention == "modified":
            return self
        js = self.joints
        last = js[-1]
        if isinstance(last.a, str) or isinstance(last.alpha, str):
            raise ChainError("cannot convert to modified DH: the last joint's a/alpha is a design "
                             "parameter and would move into the fixed tool transform")
        new = []
        for i, j in enumerate(js):
            prev = js[i - 1] if i else None
            new.append(replace(j, a=prev.a if prev else 0.0, alpha=prev.alpha if prev else 0.0))
        tail = make_transform(rot_x(float(last.alpha)), [float(last.a), 0.0, 0.0])
        tool = Placement.from_matrix(tail @ self.tool.matrix) if (last.a or last.alpha) else self.tool
        # body k's frame moves back along its row's Tx(a)·Rx(α): a point p of it becomes Tx(a)·Rx(α)·p
        moves = {k: make_transform(rot_x(self.resolve(j.alpha)), [self.resolve(j.a), 0.0, 0.0])
                 for k, j in enumerate(js, 1)}
        return self._moved_geometry(replace(self, joints=self._moved_inertia(new, moves), convention="modified",
                                            tool=tool), moves)

    def to_standard(self) -> "Chain":
        """The same machine in standard (distal) DH.  FK is unchanged.

        The first row's Rx(α_0)·Tx(a_0) moves into the base transform; it must be numeric.
        """
        if self.convention == "standard":
            return self
        js = self.joints
        first = js[0]
        if isinstance(first.a, str) or isinstance(first.alpha, str):
            raise ChainError("cannot convert to standard DH: the first joint's a/alpha is a design "
                             "parameter and would move into the fixed base transform")
        new = []
        for i, j in enumerate(js):
            nxt = js[i + 1] if i + 1 < len(js) else None
            new.append(replace(j, a=nxt.a if nxt else 0.0, alpha=nxt.alpha if nxt else 0.0))
        head = make_transform(rot_x(float(first.alpha)), [float(first.a), 0.0, 0.0])
        base = Placement.from_matrix(self.base.matrix @ head) if (first.a or first.alpha) else self.base
        # body k < n: the standard frame k is the modified one moved on by row k + 1's Rx(α)·Tx(a)
        moves = {k: np.linalg.inv(make_transform(rot_x(self.resolve(js[k].alpha)), [self.resolve(js[k].a), 0.0, 0.0]))
                 for k in range(len(js))}
        return self._moved_geometry(replace(self, joints=self._moved_inertia(new, moves), convention="standard",
                                            base=base), moves)

