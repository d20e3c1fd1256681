"""Reading a URDF: parse it with yourdfpy, check the link tree, pick the serial chain base → tip.

The result, :class:`SerialChain`, is the URDF's own kinematics of that chain (SI units): for each
movable joint the fixed transform from the previous joint's moving frame (fixed joints folded in),
its unit axis and its limits, and the fixed transform from the last joint to the tip link.  Its
:meth:`SerialChain.fk` is the URDF forward kinematics, ``origin_1·M_1(q_1) ⋯ origin_n·M_n(q_n)·tip``
with ``M`` a rotation about (revolute, continuous) or a translation along (prismatic) the axis.

* **The tip.** Without ``tip``, the only leaf link below the base; when there are several and they
  all hang below the same movable joints (they differ only by fixed and mimic joints: a gripper's
  fingers, a tool frame, a sensor frame), the deepest link that every leaf hangs from through fixed
  joints (the flange, say) — its FK is the chain's, and the leaves ride on the tool body; otherwise
  an error lists the leaves.
* **The tool.** The links below the last movable joint's own link — through fixed joints, and
  through joints off the chain (a gripper's fingers), which are *held*: at 0, or the limit nearest 0
  when 0 is outside their limits; a mimic joint at multiplier × its leader's held value + offset —
  make the tool body (:class:`RigidLink`); :attr:`SerialChain.held` says which joint is held where.
* **Numbers.** Every number read is checked against what a robot file holds (lengths up to 10 km,
  revolute limits within ±8π, efforts up to 10⁷, speeds finite and ≥ 0): one :class:`UrdfError`
  naming the file, the joint and the field otherwise.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from kin.files import FileReadError, read_bytes
from kin.robotfile import MAX_LENGTH, MAX_REVOLUTE_LIMIT, MAX_TORQUE, MIN_LENGTH
from kin.urdf.errors import UrdfError

#: the largest URDF file read (the robot's description; meshes are read apart)
MAX_URDF_BYTES = 20 * 2**20
#: range given to a continuous joint (one turn: every orientation), rad
CONTINUOUS_LIMITS = (-math.pi, math.pi)
MOVABLE = ("revolute", "continuous", "prismatic")
REFUSED = {"floating": "a floating joint (6 degrees of freedom) is not a serial-chain joint",
           "planar": "a planar joint (3 degrees of freedom) is not a serial-chain joint"}


@dataclass(frozen=True)
class UrdfJoint:
    """One movable joint of the chain, SI units."""

    name: str
    type: Literal["revolute", "prismatic"]   # a continuous joint is revolute, with ``continuous`` set
    origin: np.ndarray                       # (4, 4): previous joint's moving frame (or the base link)
                                             # → this joint's frame
    axis: np.ndarray                         # (3,) unit, in this joint's frame
    limits: tuple[float, float]
    max_velocity: float | None = None        # rad/s or m/s
    continuous: bool = False
    max_torque: float | None = None          # N·m or N: <limit effort>; None when 0 or missing


@dataclass(frozen=True)
class RigidLink:
    """A link rigidly attached to one body of the chain: ``body`` 0 (the base link and what is fixed
    to it), k (moved by the chain's joint k), n + 1 (the tool: every link below the last joint's own
    link, through fixed joints and held joints off the chain); ``pose`` its frame in the base link's
    frame at q = 0 (held joints at their held values); ``collisions`` its <collision> elements
    (yourdfpy's); ``inertial`` its <inertial> (yourdfpy's or None); ``visuals`` its <visual> elements
    (yourdfpy's, a referenced material's colour filled in)."""

    name: str
    body: int
    pose: np.ndarray
    collisions: tuple = ()
    inertial: object | None = None
    visuals: tuple = ()


@dataclass(frozen=True)
class SerialChain:
    """The serial chain from ``base`` to ``tip`` of a URDF file (SI units).

    ``links``: every link rigidly attached to a body of the chain (through fixed joints in any
    branch, and held joints below the last joint); ``held``: (joint, value in rad or m, how) of each
    joint off the chain held for the tool; ``loose_links``: links that hold <collision> elements but
    move with a joint off the chain that no body can carry (not below the last joint, or mimicking
    a joint of the chain); ``loose_masses``: those of such links that have a mass (left out too);
    ``tip_note``: why the tip was chosen, when it was not given and several leaves exist.
    """

    path: str
    robot_name: str
    base: str
    tip: str
    joints: tuple[UrdfJoint, ...]
    tip_offset: np.ndarray                   # (4, 4): last joint's moving frame → tip link
    links: tuple[RigidLink, ...] = ()
    loose_links: tuple[str, ...] = ()
    loose_masses: tuple[str, ...] = ()
    held: tuple[tuple[str, float, str], ...] = ()
    tip_note: str = ""

    @property
    def n(self) -> int:
        return len(self.joints)

    def fk(self, q) -> np.ndarray:
        """Pose (4, 4) of the tip link in the base link's frame at configuration ``q`` (n,)."""
        q = np.asarray(q, dtype=float)
        T = np.eye(4)
        for j, v in zip(self.joints, q):
            T = T @ j.origin @ joint_motion(j, float(v))
        return T @ self.tip_offset

    def axes_at_zero(self) -> tuple[np.ndarray, np.ndarray]:
        """Points (n, 3) on the joint axes and unit directions (n, 3), base-link frame, q = 0."""
        T = np.eye(4)
        points, dirs = [], []
        for j in self.joints:
            T = T @ j.origin
            points.append(T[:3, 3].copy())
            dirs.append(T[:3, :3] @ j.axis)
        return np.array(points), np.array(dirs)

    @property
    def held_text(self) -> str:
        """The held joints in words: "finger = 0 (at 0), finger2 = 0.04 (mimic …)"."""
        return ", ".join(f"{name} = {q:.6g} ({how})" for name, q, how in self.held)


def joint_motion(j: UrdfJoint, q: float) -> np.ndarray:
    """The joint's own motion (4, 4): rotation by q about its axis, or translation by q along it."""
    M = np.eye(4)
    if j.type == "prismatic":
        M[:3, 3] = q * j.axis
        return M
    k = j.axis
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    M[:3, :3] = np.eye(3) + math.sin(q) * K + (1.0 - math.cos(q)) * (K @ K)
    return M


def load_urdf_model(path: str | Path):
    """Parse a URDF file with yourdfpy (no meshes, no scene graph: :mod:`kin.urdf.collision` reads
    collision meshes itself); errors become :class:`UrdfError`."""
    import yourdfpy

    path = str(path)
    try:                 # bounded like every file rmt reads (a regular file, the size cap) before the parser opens it
        read_bytes(path, "URDF file", MAX_URDF_BYTES)
    except FileReadError as e:
        raise UrdfError("no such file" if not Path(path).exists() else e.reason, path) from None
    quiet = logging.getLogger("yourdfpy")      # it logs parse errors itself; ours is the one message
    level = quiet.level
    quiet.setLevel(logging.CRITICAL)
    try:
        with np.errstate(all="ignore"):
            model = yourdfpy.URDF.load(path, build_scene_graph=False, build_collision_scene_graph=False,
                                       load_meshes=False, load_collision_meshes=False)
    except Exception as e:  # lxml, yourdfpy and attribute errors alike: not a URDF
        raise UrdfError(f"not a readable URDF ({type(e).__name__}: {str(e).strip() or 'malformed XML'})",
                        path, "robot") from None
    finally:
        quiet.setLevel(level)
    if model.robot is None or not model.robot.links:
        raise UrdfError("the URDF has no <link>", path, "robot")
    return model


def read_serial_chain(path: str | Path, base: str | None = None, tip: str | None = None) -> SerialChain:
    """The serial chain from link ``base`` (default: the root) to link ``tip`` (default: the only leaf)."""
    path = str(path)
    robot = load_urdf_model(path).robot
    links = [lk.name for lk in robot.links]
    if len(set(links)) != len(links):
        dup = next(n for n in links if links.count(n) > 1)
        raise UrdfError("two links have this name", path, f"link {dup!r}")
    parent_joint: dict[str, object] = {}
    children: dict[str, list] = {n: [] for n in links}
    seen_joints: set[str] = set()
    for j in robot.joints:
        el = f"joint {j.name!r}"
        if j.name in seen_joints:
            raise UrdfError("two joints have this name", path, el)
        seen_joints.add(j.name)
        for role, link in (("parent", j.parent), ("child", j.child)):
            if link not in children:
                raise UrdfError(f"its {role} link {link!r} is not defined", path, el)
        if j.child in parent_joint:
            raise UrdfError(f"link {j.child!r} has two parent joints; a URDF must be a tree", path, el)
        parent_joint[j.child] = j
        children[j.parent].append(j)
    roots = [n for n in links if n not in parent_joint]
    if len(roots) != 1:
        raise UrdfError(f"the links form {'a loop' if not roots else 'several trees'}; a URDF has one root link"
                        + (f" (roots: {', '.join(roots)})" if roots else ""), path, "robot")
    base = roots[0] if base is None else base
    if base not in children:
        raise UrdfError(f"base link {base!r} is not defined; links: {', '.join(links)}", path)
    tip_note = ""
    if tip is None:
        leaves = _leaves_below(base, children)
        tip = leaves[0] if len(leaves) == 1 else _common_tip(base, leaves, parent_joint)
        if tip is None:
            raise UrdfError(f"the tree below {base!r} has {len(leaves)} leaf links; choose the tip link "
                            f"(--tip) from: {', '.join(leaves)}", path)
        if len(leaves) > 1:
            tip_note = (f"tip {tip!r}: the link that all {len(leaves)} leaves hang from through fixed and mimic "
                        f"joints ({', '.join(leaves)}: another tip with --tip)")
    if tip not in children:
        raise UrdfError(f"tip link {tip!r} is not defined; links: {', '.join(links)}", path)

    path_joints = []
    link = tip
    while link != base:
        if link not in parent_joint:
            above = _ancestors(tip, parent_joint)
            raise UrdfError(f"tip link {tip!r} is not below base link {base!r}; links above it: "
                            f"{', '.join(above) or 'none'}", path)
        j = parent_joint[link]
        path_joints.append(j)
        link = j.parent
    path_joints.reverse()

    joints: list[UrdfJoint] = []
    acc = np.eye(4)
    for j in path_joints:
        el = f"joint {j.name!r}"
        origin = _checked_origin(j, path)
        if j.type == "fixed":
            acc = acc @ origin
            continue
        if j.type in REFUSED:
            raise UrdfError(f"{REFUSED[j.type]}; rmtkit imports revolute, continuous, prismatic and fixed joints",
                            path, el)
        if j.type not in MOVABLE:
            raise UrdfError(f"type {j.type!r} unknown; allowed: revolute, continuous, prismatic, fixed", path, el)
        if j.mimic is not None:
            raise UrdfError(f"a mimic joint (its value follows joint {j.mimic.joint!r}) is not an independent "
                            "joint; rmtkit chains have independent joints only", path, el)
        joints.append(_movable(j, acc @ origin, path, el))
        acc = np.eye(4)
    if not joints:
        raise UrdfError(f"the chain {base!r} → {tip!r} has no revolute, continuous or prismatic joint", path)
    links, loose, loose_masses, held = _rigid_links(robot, base, path_joints, parent_joint, children, path)
    return SerialChain(path=path, robot_name=robot.name or "", base=base, tip=tip, joints=tuple(joints),
                       tip_offset=acc, links=links, loose_links=loose, loose_masses=loose_masses, held=held,
                       tip_note=tip_note)


def _origin(j) -> np.ndarray:
    return np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=float)


def _checked_origin(j, path: str) -> np.ndarray:
    """The joint's <origin> (4, 4), refused when not finite or farther than a robot file reaches."""
    origin = _origin(j)
    el = f"joint {j.name!r}"
    if not np.all(np.isfinite(origin)):
        raise UrdfError("its <origin> holds a NaN or infinite value", path, el)
    far = float(np.abs(origin[:3, 3]).max())
    if far > MAX_LENGTH:
        raise UrdfError(f"its <origin> xyz {origin[:3, 3].tolist()} reaches {far:g} m; allowed: at most "
                        f"{MAX_LENGTH:g} m (10 km) in each coordinate", path, el)
    return origin


def _rigid_links(robot, base: str, path_joints, parent_joint, children, path: str):
    """The links fixed to each body of the chain and their poses at q = 0 (see :class:`RigidLink`),
    the links with collision elements and with masses that no body carries, and the held joints."""
    by_name = {lk.name: lk for lk in robot.links}
    movable = [j for j in path_joints if j.type != "fixed"]
    on_path = {j.name: k for k, j in enumerate(movable, 1)}
    n, last = len(movable), movable[-1].child          # the last joint's own link: body n
    held_at = _held_positions(robot, on_path, path)
    held: list[tuple[str, float, str]] = []
    found: dict[str, tuple[int, np.ndarray]] = {base: (0, np.eye(4))}
    stack = [base]
    while stack:
        link = stack.pop()
        body, pose = found[link]
        neighbours = [(j.child, j, False) for j in children[link]]
        if body == 0 and link in parent_joint:     # the base body reaches up through fixed joints too
            neighbours.append((parent_joint[link].parent, parent_joint[link], True))
        for other, j, up in neighbours:
            if other in found:
                continue
            below = body == n + 1 or link == last     # in the tool's part of the tree
            if j.type == "fixed":
                b = n + 1 if below else body
                found[other] = (b, pose @ (np.linalg.inv(_checked_origin(j, path)) if up else _checked_origin(j, path)))
            elif not up and j.name in on_path:
                found[other] = (on_path[j.name], pose @ _origin(j))
            elif not up and below and held_at(j.name) is not None:
                uj, q, how = held_at(j.name)
                found[other] = (n + 1, pose @ _checked_origin(j, path) @ joint_motion(uj, q))
                held.append((j.name, q, how))
            else:
                continue
            stack.append(other)
    links = tuple(RigidLink(name, b, T, tuple(by_name[name].collisions or ()), by_name[name].inertial,
                            _visuals(robot, by_name[name]))
                  for name, (b, T) in found.items())
    loose = tuple(lk.name for lk in robot.links if lk.name not in found and lk.collisions)
    loose_masses = tuple(lk.name for lk in robot.links if lk.name not in found and lk.inertial is not None
                         and lk.inertial.mass)
    return links, loose, loose_masses, tuple(held)


def _visuals(robot, link) -> tuple:
    """The link's <visual> elements, a material given by name only (defined at the robot's level)
    given its colour."""
    from dataclasses import replace
    named = {m.name: m for m in (robot.materials or ()) if m.name}
    out = []
    for v in link.visuals or ():
        m = v.material
        if m is not None and m.color is None and m.name in named:
            v = replace(v, material=named[m.name])
        out.append(v)
    return tuple(out)


def _held_positions(robot, on_path: dict[str, int], path: str):
    """A function: the name of a revolute, continuous or prismatic joint off the chain → (its
    :class:`UrdfJoint`, the value it is held at, how — "0", "the limit nearest 0" or "mimic of
    LEADER"), or None when it cannot be held (it mimics a joint of the chain, directly or through
    others, or is of another type)."""
    joints = {j.name: j for j in robot.joints}
    out: dict[str, tuple | None] = {}

    def value(name: str, seen: tuple[str, ...] = ()) -> tuple | None:
        if name in out:
            return out[name]
        j = joints.get(name)
        if j is None or name in on_path or name in seen or j.type not in MOVABLE:
            return None
        el = f"joint {name!r}"
        uj = _movable(j, np.eye(4), path, el, held=True)
        if j.mimic is not None:
            leader = value(j.mimic.joint, (*seen, name))
            if leader is None:
                out[name] = None
                return None
            mult = 1.0 if j.mimic.multiplier is None else float(j.mimic.multiplier)
            off = 0.0 if j.mimic.offset is None else float(j.mimic.offset)
            q = mult * leader[1] + off
            if not math.isfinite(q):
                raise UrdfError(f"its <mimic> multiplier = {mult:g}, offset = {off:g} give a held value {q:g}; "
                                "allowed: finite numbers", path, el)
            out[name] = (uj, q, f"mimic of {j.mimic.joint}")
        else:
            lo, hi = uj.limits
            q = min(max(0.0, lo), hi)
            out[name] = (uj, q, "0" if q == 0.0 else "the limit nearest 0")
        return out[name]
    return value


def _movable(j, origin: np.ndarray, path: str, el: str, held: bool = False) -> UrdfJoint:
    """The joint as a :class:`UrdfJoint`, every value checked; ``held``: a joint off the chain held
    for the tool (its limits may be missing: then only 0 is allowed)."""
    axis = np.array([1.0, 0.0, 0.0]) if j.axis is None else np.asarray(j.axis, dtype=float)
    norm = float(np.linalg.norm(axis)) if axis.shape == (3,) else 0.0
    if not np.all(np.isfinite(axis)) or norm < 1e-9:
        raise UrdfError(f"its <axis> {axis.tolist()} must be three finite numbers, not all zero", path, el)
    if j.type == "prismatic" and abs(norm - 1.0) > 1e-3:
        # tools disagree on a longer axis (a unit step, or a step of its length): refuse rather than guess
        raise UrdfError(f"the <axis> {axis.tolist()} of a prismatic joint must be a unit vector (norm {norm:.6g})",
                        path, el)
    axis = axis / norm
    lim = j.limit
    unit = "rad" if j.type != "prismatic" else "m"
    velocity = None     # URDF requires velocity; 0 is what writers put when it is unknown
    if lim is not None and lim.velocity is not None:
        v = float(lim.velocity)
        if not math.isfinite(v) or v < 0:
            raise UrdfError(f"<limit> velocity = {v:g}; allowed: a finite number ≥ 0 ({unit}/s; 0: unknown)", path, el)
        velocity = v if v > 0 else None
    effort = None      # URDF requires effort; 0 (or a missing one) is what writers put when it is unknown
    if lim is not None and lim.effort is not None:
        e = float(lim.effort)
        if not math.isfinite(e) or e < 0 or e > MAX_TORQUE:
            raise UrdfError(f"<limit> effort = {e:g}; allowed: 0 to {MAX_TORQUE:g} "
                            f"({'N·m' if j.type != 'prismatic' else 'N'}; 0: unknown)", path, el)
        effort = e if e > 0 else None
    if j.type == "continuous":
        return UrdfJoint(j.name, "revolute", origin, axis, CONTINUOUS_LIMITS, velocity, continuous=True,
                         max_torque=effort)
    if lim is None or lim.lower is None or lim.upper is None:
        if held:
            return UrdfJoint(j.name, j.type, origin, axis, (0.0, 0.0), velocity, max_torque=effort)
        raise UrdfError(f"a {j.type} joint needs <limit lower=… upper=…>", path, el)
    lo, hi = float(lim.lower), float(lim.upper)
    if not (math.isfinite(lo) and math.isfinite(hi)) or not (lo <= hi if held else lo < hi):
        raise UrdfError(f"<limit> lower = {lo:g}, upper = {hi:g} must be finite with lower < upper "
                        "(a joint that cannot move should be fixed)", path, el)
    if j.type == "revolute" and max(abs(lo), abs(hi)) > MAX_REVOLUTE_LIMIT:
        raise UrdfError(f"<limit> [{lo:g}, {hi:g}] rad exceeds ±8π rad, four turns", path, el)
    if j.type == "prismatic":
        for name, x in (("lower", lo), ("upper", hi)):
            if abs(x) > MAX_LENGTH or 0 < abs(x) < MIN_LENGTH:
                raise UrdfError(f"<limit> {name} = {x:g} m; allowed: 0 or {MIN_LENGTH:g} to {MAX_LENGTH:g} m "
                                "in magnitude (1 nm to 10 km)", path, el)
    return UrdfJoint(j.name, j.type, origin, axis, (lo, hi), velocity, max_torque=effort)


def _leaves_below(base: str, children: dict[str, list]) -> list[str]:
    leaves, stack = [], [base]
    while stack:
        link = stack.pop()
        kids = [j.child for j in children[link]]
        if not kids:
            leaves.append(link)
        stack.extend(reversed(kids))
    return leaves


def _common_tip(base: str, leaves: list[str], parent_joint: dict) -> str | None:
    """The default tip when several leaves hang below the same movable joints (those neither fixed
    nor mimic): the deepest link on every leaf's path that the last of those joints' link reaches
    through fixed joints; None when the leaves differ in their movable joints (or have none)."""
    paths = []
    for leaf in leaves:
        joints, link = [], leaf
        while link != base:
            joints.append(parent_joint[link])
            link = parent_joint[link].parent
        paths.append(joints[::-1])
    actuated = {tuple(j.name for j in p if j.type != "fixed" and j.mimic is None) for p in paths}
    if len(actuated) != 1 or not next(iter(actuated)):
        return None
    common = 0
    while all(len(p) > common and p[common].name == paths[0][common].name for p in paths):
        common += 1
    shared = paths[0][:common]
    last = max(i for i, j in enumerate(shared) if j.type != "fixed" and j.mimic is None)
    tip = shared[last].child
    for j in shared[last + 1:]:                 # down from the last joint's link through fixed joints
        if j.type != "fixed":
            break
        tip = j.child
    return tip


def _ancestors(link: str, parent_joint: dict) -> list[str]:
    out = []
    while link in parent_joint:
        link = parent_joint[link].parent
        out.append(link)
    return out
