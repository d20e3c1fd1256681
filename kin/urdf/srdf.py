"""A MoveIt SRDF's disabled collision pairs, as the body pairs of an imported chain that are never checked.

MoveIt's Setup Assistant writes, beside a URDF, an SRDF whose ``<disable_collisions link1= link2=
reason=/>`` elements name the link pairs a planner need not check: ``Adjacent`` (joined by a joint),
``Never`` (found apart in every one of many sampled configurations), ``Default`` (touching at the
default configuration, so always ignored) and ``User``.  MotionBenchMaker's problems, and every MoveIt
planner, check only the other pairs.

An imported chain merges links into bodies (a link is on the body of the last joint before it), so a
body pair (i, j) is left unchecked — added to the geometry's ``allowed`` pairs, written as the robot
file's ``allow`` — only when *every* pair of links with collision geometry on i and on j is disabled:
one enabled link pair keeps the whole body pair checked.  Pairs the SRDF names with links the URDF
does not have are reported, not guessed.  What is proven clear then is clear of the cell and of every
pair still checked, as MoveIt means it; the robot file's ``source`` says that the SRDF was applied.

Its ``<group_state name= group=><joint name= value=/>…</group_state>`` elements — MoveIt's named
states, "home", "up" — become the chain's named configurations (:mod:`kin.states`, the robot file's
``[states]``), matched to the chain's joints by name (:func:`chain_states`).  A state is taken when it
sets every joint of the chain (values of joints off the chain, another group's, are left out and
said); one that sets only some, or none, of them is left out and said; a state name a robot file
cannot hold (:func:`kin.states.name_problem`) is left out and said.  A value that is missing, not a
number or not finite, a joint set twice, a state given twice, or a value outside the joint's limits is
refused with the file, the state and the joint named (a continuous joint's value is first taken into
[-π, π] by whole turns: the same pose).

The file is read with the standard library's XML parser after a size check (at most :data:`MAX_BYTES`);
a document type declaration (the way entities come in) is refused, since an SRDF never needs one.
"""
from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from kin.files import read_text
from kin.urdf.errors import UrdfError

__all__ = ["MAX_BYTES", "GroupState", "read_root", "disabled_link_pairs", "group_states", "chain_states",
           "allowed_body_pairs"]

#: the largest SRDF read
MAX_BYTES = 10 * 2**20


def read_root(path: str | Path) -> ET.Element:
    """The ``<robot>`` element of an SRDF file (size, encoding and document type checked)."""
    path = Path(path)
    text = read_text(path, "SRDF file", MAX_BYTES, error=UrdfError)
    if re.search(r"<!DOCTYPE|<!ENTITY", text, re.IGNORECASE):
        raise UrdfError("a document type declaration (<!DOCTYPE or <!ENTITY) is not read in an SRDF", str(path))
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise UrdfError(f"not well-formed XML ({e})", str(path)) from None
    if root.tag != "robot":
        raise UrdfError(f"the root element is <{root.tag}>, not <robot>", str(path))
    return root


def disabled_link_pairs(path: str | Path, root: ET.Element | None = None) -> set[frozenset[str]]:
    """The link pairs an SRDF's ``<disable_collisions>`` elements name (each a frozenset of two names);
    ``root``: the file's element when already read (:func:`read_root`)."""
    root = read_root(path) if root is None else root
    out = set()
    for k, e in enumerate(root.iter("disable_collisions")):
        a, b = e.get("link1"), e.get("link2")
        if not a or not b:
            raise UrdfError("needs link1 and link2", str(path), f"disable_collisions {k + 1}")
        if a != b:
            out.add(frozenset((a, b)))
    return out


def allowed_body_pairs(geometry, disabled: set[frozenset[str]]) -> tuple[set[tuple[int, int]], list[str]]:
    """The body pairs (i < j) of ``geometry`` (capsules named after their URDF links, as the importer
    names them) whose every link pair is in ``disabled``, and the link names of ``disabled`` that no
    capsule has (sorted)."""
    links: dict[int, set[str]] = {}
    for c in geometry.capsules:
        links.setdefault(c.body, set()).add(c.name)
    known = set().union(*links.values()) if links else set()
    unknown = sorted({name for pair in disabled for name in pair} - known)
    bodies = sorted(links)
    out = set()
    for x, i in enumerate(bodies):
        for j in bodies[x + 1:]:
            if all(frozenset((a, b)) in disabled for a in links[i] for b in links[j]):
                out.add((i, j))
    return out, unknown


@dataclass(frozen=True)
class GroupState:
    """One ``<group_state>``: its name, group and joint values (joint name → value, rad or m)."""

    name: str
    group: str
    values: dict[str, float]


def group_states(path: str | Path, root: ET.Element | None = None) -> list[GroupState]:
    """The ``<group_state>`` elements of an SRDF, in file order; each needs a name and joints with a
    name and a finite numeric value, each joint once (:class:`UrdfError` naming the element otherwise);
    ``root``: the file's element when already read (:func:`read_root`)."""
    root = read_root(path) if root is None else root
    out = []
    for k, e in enumerate(root.iter("group_state")):
        name = e.get("name")
        where = f"group_state {name!r}" if name else f"group_state {k + 1}"
        if not name:
            raise UrdfError("needs a name", str(path), where)
        values: dict[str, float] = {}
        for m, je in enumerate(e.iter("joint")):
            jn = je.get("name")
            if not jn:
                raise UrdfError(f"its joint {m + 1} needs a name", str(path), where)
            text = je.get("value")
            if text is None:
                raise UrdfError(f"joint {jn!r} has no value", str(path), where)
            try:
                v = float(text.split()[0]) if text.split() else float("nan")
            except ValueError:
                raise UrdfError(f"joint {jn!r}: value {text!r} is not a number", str(path), where) from None
            if len(text.split()) != 1 or not math.isfinite(v):
                raise UrdfError(f"joint {jn!r}: value {text!r} must be one finite number (rad or m)", str(path),
                                where)
            if jn in values:
                raise UrdfError(f"joint {jn!r} is set twice", str(path), where)
            values[jn] = v
        out.append(GroupState(name, e.get("group") or "", values))
    return out


def chain_states(path: str | Path, joints, root: ET.Element | None = None
                 ) -> tuple[dict[str, tuple[float, ...]], list[str]]:
    """The SRDF's group states that set every one of ``joints`` (the chain's
    :class:`kin.urdf.read.UrdfJoint`, matched by name) as name → configuration (SI, in chain order),
    and one note per state left out or trimmed (why).  Values outside a joint's limits are refused."""
    from kin.states import name_problem

    names = [j.name for j in joints]
    out: dict[str, tuple[float, ...]] = {}
    notes: list[str] = []
    for gs in group_states(path, root):
        where = f"group_state {gs.name!r}"
        have = [nm for nm in names if nm in gs.values]
        if len(have) < len(names):
            missing = [nm for nm in names if nm not in gs.values]
            notes.append(f"{where} (group {gs.group!r}) sets {len(have)} of the chain's {len(names)} joints (not "
                         f"{', '.join(missing[:4])}{' …' if len(missing) > 4 else ''}): left out")
            continue
        why = name_problem(gs.name)
        if why is not None:
            notes.append(f"{where}: left out, {why}")
            continue
        if gs.name in out:
            raise UrdfError("is given twice with every joint of the chain", str(path), where)
        extra = sorted(set(gs.values) - set(names))
        if extra:
            notes.append(f"{where}: values of joints off the chain left out ({', '.join(extra[:4])}"
                         f"{' …' if len(extra) > 4 else ''})")
        q = []
        for j in joints:
            v = gs.values[j.name]
            if j.continuous:
                v = math.remainder(v, 2 * math.pi)
            lo, hi = j.limits
            if not lo <= v <= hi:
                unit = "rad" if j.type == "revolute" else "m"
                raise UrdfError(f"joint {j.name!r} = {gs.values[j.name]:g} {unit} lies outside its limits "
                                f"[{lo:g}, {hi:g}] {unit}", str(path), where)
            q.append(v)
        out[gs.name] = tuple(q)
    return out, notes
