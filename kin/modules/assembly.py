"""Assemblies: an ordered list of catalogue modules, each mounted on the one before at a twist, made
into a robot (:class:`kin.Chain`) with the same forward kinematics as the product of the modules'
transforms.

An assembly starts at a base, carries joint and link modules, and may end with a tool.  Module
``i + 1``'s input frame is module ``i``'s output frame turned by ``twists[i]`` about its z axis
(:mod:`kin.modules.catalogue`).  The robot is built from the joint axes at q = 0 by the same
frame-to-DH extraction the URDF import uses (:func:`kin.urdf.dh.dh_rows`: standard DH, base and tool
transforms), so its FK equals the modules' product.  Its bodies get the modules' parts: a joint
module's proximal part belongs to the body before its joint, its distal part and every link after it
(up to the next joint module's proximal part) to the body the joint moves; a tool is the payload.
Each body's parts are combined into one inertial model, and their capsules become the body's
collision geometry, in the body's DH frame.

Refused (:class:`AssemblyError`, one line): an unknown module, a first module that is not a base, a
base or tool elsewhere, faces that do not meet or a twist they do not allow, no joint or more than
:data:`MAX_JOINTS` joints.  Whether every joint holds the rest of the chain at rest is
:func:`kin.modules.holding.holding`'s to say (:func:`assemble` refuses a chain a joint provably
cannot hold, with ``check_holding``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from kin.chain import NAME_RE, Chain, Joint
from kin.errors import RmtError
from kin.modules.catalogue import Catalogue, Module, _same_angle
from kin.placement import Placement
from kin.transforms import make_transform, rot_z

__all__ = ["Assembly", "AssemblyError", "assemble", "module_frames", "MAX_JOINTS", "MAX_MODULES_IN_ASSEMBLY"]

#: an assembly has at most this many joints, and at most this many modules in all
MAX_JOINTS = 8
MAX_MODULES_IN_ASSEMBLY = 64
#: lengths of the DH table, base and tool within this fraction of the robot's size of 0 are
#: floating-point noise of the modules' product, written as 0
NOISE = 1e-12


class AssemblyError(RmtError, ValueError):
    """An assembly that cannot be built: one line saying which module and why."""


@dataclass(frozen=True)
class Assembly:
    """Module names base first (``modules``) and the twist (rad) at which each module after the base
    meets the one before (``twists``, one fewer)."""

    modules: tuple[str, ...]
    twists: tuple[float, ...]

    def __post_init__(self):
        object.__setattr__(self, "modules", tuple(self.modules))
        object.__setattr__(self, "twists", tuple(float(t) for t in self.twists))
        if len(self.twists) != max(len(self.modules) - 1, 0):
            raise AssemblyError(f"an assembly of {len(self.modules)} modules needs {len(self.modules) - 1} twists, "
                                f"got {len(self.twists)}")

    @classmethod
    def parse(cls, items, catalogue: Catalogue) -> "Assembly":
        """``items``: "NAME[@TWIST]" strings (or one string of them separated by spaces or commas), the
        base first; TWIST in the catalogue's angle unit (default 0).  Validated (:meth:`check`)."""
        if isinstance(items, str):
            items = items.replace(",", " ").split()
        items = list(items)
        if not items:
            raise AssemblyError("no modules given; an assembly lists a base, joint and link modules, and maybe a tool")
        if len(items) > MAX_MODULES_IN_ASSEMBLY:
            raise AssemblyError(f"{len(items)} modules; an assembly has at most {MAX_MODULES_IN_ASSEMBLY}")
        names, twists = [], []
        for i, it in enumerate(items):
            if not isinstance(it, str) or not it:
                raise AssemblyError(f"modules[{i}]: expected NAME or NAME@TWIST, got {it!r}")
            name, sep, tw = it.partition("@")
            if i == 0 and sep:
                raise AssemblyError(f"modules[0] {it!r}: the base takes no twist (it stands on the world)")
            if i > 0:
                try:
                    t = float(tw) if sep else 0.0
                except ValueError:
                    t = math.nan
                if not math.isfinite(t) or abs(t) > 1e6:
                    raise AssemblyError(f"modules[{i}] {it!r}: the twist must be a finite number "
                                        f"({catalogue.angle_unit}), got {tw!r}")
                twists.append((t * catalogue.angle_scale) % (2 * math.pi))
            names.append(name)
        a = cls(tuple(names), tuple(twists))
        a.check(catalogue)
        return a

    def text(self, catalogue: Catalogue) -> str:
        """The assembly as ``rmt assemble --modules`` takes it (twists in the catalogue's unit, 0 left out)."""
        out = [self.modules[0]] if self.modules else []
        for name, t in zip(self.modules[1:], self.twists):
            v = t / catalogue.angle_scale
            out.append(name if _same_angle(t, 0.0) else f"{name}@{round(v, 9):g}")
        return " ".join(out)

    def cost(self, catalogue: Catalogue) -> float:
        return float(sum(catalogue.modules[m].cost for m in self.modules))

    def joints(self, catalogue: Catalogue) -> list[str]:
        """The joint modules' names, base to tip."""
        return [m for m in self.modules if catalogue.modules[m].kind == "joint"]

    def check(self, catalogue: Catalogue) -> list[Module]:
        """The modules, validated as an assembly (see the module text)."""
        mods = []
        for i, name in enumerate(self.modules):
            m = catalogue.modules.get(name)
            if m is None:
                close = ", ".join(sorted(catalogue.modules)[:12])
                raise AssemblyError(f"modules[{i}]: no module {name!r} in catalogue {catalogue.name!r} "
                                    f"(it has: {close}{' …' if len(catalogue.modules) > 12 else ''})")
            mods.append(m)
        if not mods:
            raise AssemblyError("an assembly needs at least a base and a joint module")
        if mods[0].kind != "base":
            raise AssemblyError(f"modules[0] {mods[0].name!r} is a {mods[0].kind} module; an assembly starts at a base")
        for i, m in enumerate(mods[1:], 1):
            if m.kind == "base":
                raise AssemblyError(f"modules[{i}] {m.name!r} is a base; only the first module may be one")
            if m.kind == "tool" and i != len(mods) - 1:
                raise AssemblyError(f"modules[{i}] {m.name!r} is a tool; only the last module may be one")
            prev, t = mods[i - 1], self.twists[i - 1]
            allowed = catalogue.twists(prev.output, m.input)
            if not allowed:
                raise AssemblyError(f"modules[{i}] {m.name!r}: its input {m.input!r} does not meet the output "
                                    f"{prev.output!r} of {prev.name!r}")
            if not any(_same_angle(t, u) for u in allowed):
                s = catalogue.angle_scale
                raise AssemblyError(f"modules[{i}] {m.name!r}: twist {t / s:g} {catalogue.angle_unit} is not one at "
                                    f"which {prev.output!r} meets {m.input!r}; allowed: "
                                    f"{', '.join(f'{u / s:g}' for u in allowed)}")
        n = sum(m.kind == "joint" for m in mods)
        if n == 0:
            raise AssemblyError("the assembly has no joint module")
        if n > MAX_JOINTS:
            raise AssemblyError(f"the assembly has {n} joints; at most {MAX_JOINTS}")
        return mods


def _motion(m: Module, q: float) -> np.ndarray:
    return make_transform(rot_z(q)) if m.type == "revolute" else make_transform(None, [0.0, 0.0, q])


def module_frames(catalogue: Catalogue, assembly: Assembly, q) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each module's (input, output) frames in the world at joint values ``q`` (SI, one per joint); a
    base's input is the world, a tool's output its TCP."""
    mods = assembly.check(catalogue)
    q = np.asarray(q, dtype=float).ravel()
    n = sum(m.is_joint for m in mods)
    if q.shape != (n,):
        raise AssemblyError(f"q must hold {n} joint values, got {q.shape[0]}")
    out, T, k = [], np.eye(4), 0
    for i, m in enumerate(mods):
        Tin = T if i == 0 else T @ make_transform(rot_z(assembly.twists[i - 1]))
        if m.kind == "base":
            T = m.out
        elif m.is_joint:
            T = Tin @ m.axis @ _motion(m, q[k]) @ m.out
            k += 1
        else:
            T = Tin @ m.out
        out.append((Tin, T))
    return out


def _noise_free(x: float, tol: float) -> float:
    return 0.0 if abs(x) <= tol else x


def _placement(T: np.ndarray, tol: float) -> Placement:
    T = T.copy()
    T[:3, :3] = np.where(np.abs(T[:3, :3]) < 1e-15, 0.0, T[:3, :3])
    T[:3, 3] = [_noise_free(float(x), tol) for x in T[:3, 3]]
    T[3] = (0.0, 0.0, 0.0, 1.0)
    return Placement() if np.array_equal(T, np.eye(4)) else Placement.from_matrix(T)


def assemble(catalogue: Catalogue, assembly: Assembly, name: str | None = None, check_holding: bool = True) -> Chain:
    """The robot of ``assembly`` (see the module text): standard DH, SI, the catalogue's units for
    saving.  With ``check_holding`` a joint that provably cannot hold the rest of the chain at rest
    (:func:`kin.modules.holding.holding`: a configuration within the limits whose gravity torque
    exceeds its ``max_torque``) refuses the assembly."""
    from kin.dynamics.inertia import LinkInertia
    from kin.geometry.model import RobotGeometry
    from kin.geometry.shapes import LinkCapsule
    from kin.urdf.dh import dh_rows
    from kin.urdf.errors import UrdfError

    name = name or "assembly"
    if not NAME_RE.match(name):
        raise AssemblyError(f"robot name {name!r} must match [a-z0-9_]+")
    mods = assembly.check(catalogue)
    n = sum(m.is_joint for m in mods)
    frames0 = module_frames(catalogue, assembly, np.zeros(n))
    # the joint axes at q = 0, the tip, and each part's world pose with the body it belongs to
    points, dirs, parts = [], [], []         # parts: (body, world pose, Part, module name)
    body = 0
    for m, (Tin, Tout) in zip(mods, frames0):
        if m.kind == "base":
            parts.append((0, np.eye(4), m.proximal, m.name))
            continue
        parts.append((n + 1 if m.kind == "tool" else body, Tin, m.proximal, m.name))
        if m.is_joint:
            J = Tin @ m.axis
            points.append(J[:3, 3])
            dirs.append(J[:3, 2])
            body += 1
            parts.append((body, Tout, m.distal, m.name))
    tip = frames0[-1][1]
    try:
        frames, rows = dh_rows(np.array(points), np.array(dirs), tip, f"assembly {assembly.text(catalogue)}")
    except UrdfError as e:
        raise AssemblyError(str(e)) from None
    scale = max(float(np.linalg.norm(F[:3, 3])) for F in [*frames, tip])
    tol = NOISE * max(scale, 1.0)
    jmods = [m for m in mods if m.is_joint]
    joints = []
    for k, (m, (a, alpha, d, theta)) in enumerate(zip(jmods, rows), 1):
        joints.append(Joint(m.type, a=_noise_free(a, tol), alpha=alpha, d=_noise_free(d, tol), theta=theta,
                            limits=m.limits, name=f"j{k}_{m.name}".lower().replace(".", "_").replace("-", "_"),
                            max_velocity=m.max_velocity, max_acceleration=m.max_acceleration,
                            max_torque=m.max_torque))
    tool_frame = np.linalg.solve(frames[-1], tip)

    def in_body(k: int, P: np.ndarray) -> np.ndarray:      # a part's pose in body k's frame
        return np.linalg.solve(tip if k == n + 1 else frames[min(k, n)], P)

    inertias: dict[int, list] = {}
    capsules = []
    for k, P, part, mname in parts:
        if part.mass > 0:
            inertias.setdefault(k, []).append(part.inertial(mname).transformed(in_body(k, P)))
        # capsules: the tool body's in frame n, like body n's (kin.geometry.shapes)
        C = np.linalg.solve(frames[min(k, n)], P)
        for a, b, r in part.capsules:
            pa, pb = (C @ np.array([*a, 1.0]))[:3], (C @ np.array([*b, 1.0]))[:3]
            capsules.append(LinkCapsule(k, tuple(pa), tuple(pb), r, name=mname))
    joints = [replace(j, inertia=LinkInertia.combined(inertias[k], body=f"body {k}") if k in inertias else None)
              for k, j in enumerate(joints, 1)]
    payload = LinkInertia.combined(inertias[n + 1], body="tool") if n + 1 in inertias else None
    geometry = RobotGeometry(tuple(capsules), source="modules") if capsules else None
    text = assembly.text(catalogue)
    chain = Chain(name=name, joints=tuple(joints), convention="standard",
                  title=f"{text} (catalogue {catalogue.name})",
                  source=f"assembled by rmtkit from the module catalogue {catalogue.name!r}: {text}"
                         + (f" (catalogue source: {catalogue.source})" if catalogue.source else ""),
                  length_unit=catalogue.length_unit, angle_unit=catalogue.angle_unit,
                  base=_placement(frames[0], tol), tool=_placement(tool_frame, tol), geometry=geometry,
                  payload=payload)
    if check_holding:
        from kin.modules.holding import holding
        rep = holding(chain)
        if rep.fails:
            raise AssemblyError(rep.failure_text(chain))
    return chain
