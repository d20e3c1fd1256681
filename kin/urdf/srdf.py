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

The file is read with the standard library's XML parser after a size check (at most :data:`MAX_BYTES`);
a document type declaration (the way entities come in) is refused, since an SRDF never needs one.
"""
from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

from kin.urdf.errors import UrdfError

__all__ = ["MAX_BYTES", "disabled_link_pairs", "allowed_body_pairs"]

#: the largest SRDF read
MAX_BYTES = 10 * 2**20


def disabled_link_pairs(path: str | Path) -> set[frozenset[str]]:
    """The link pairs an SRDF's ``<disable_collisions>`` elements name (each a frozenset of two names)."""
    path = Path(path)
    try:
        size = path.stat().st_size
        if not path.is_file():
            raise UrdfError("not a file", str(path))
        if size > MAX_BYTES:
            raise UrdfError(f"{size / 2**20:.1f} MB; an SRDF may have at most {MAX_BYTES // 2**20} MB", str(path))
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise UrdfError("no such SRDF file", str(path)) from None
    except UnicodeDecodeError as e:
        raise UrdfError(f"not a UTF-8 text file (byte {e.start})", str(path)) from None
    except OSError as e:
        raise UrdfError(f"cannot read ({e.strerror or e})", str(path)) from None
    if re.search(r"<!DOCTYPE|<!ENTITY", text, re.IGNORECASE):
        raise UrdfError("a document type declaration (<!DOCTYPE or <!ENTITY) is not read in an SRDF", str(path))
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise UrdfError(f"not well-formed XML ({e})", str(path)) from None
    if root.tag != "robot":
        raise UrdfError(f"the root element is <{root.tag}>, not <robot>", str(path))
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
