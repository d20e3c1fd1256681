"""The swaps between two assemblies: a minimum edit script turning one into the other.

An assembly is its base followed by a sequence of mounted modules, each a (name, twist) pair (the
twist at which it meets the module before, :class:`kin.modules.Assembly`).  One *swap* is one of

* ``replace``: a module taken off and another (or the same kind at another place) put in its place,
  mounted at the target's twist;
* ``add``: a module put in;
* ``remove``: a module taken off;
* ``turn``: a module kept but re-mounted at another twist.

:func:`edit_script` is the Levenshtein distance over the (name, twist) pairs — a pair kept as it is
costs nothing, a pair whose name is kept but whose twist changes is one ``turn``, any other
substitution one ``replace`` — with the bases aligned (replacing a base is one swap; aligning a base
with any other module is never cheaper, see :func:`edit_script`).  Among scripts of the least count,
the one with the fewest replacements of a module by one of another kind is chosen, so that "replace
link L300 by L450" wins over "replace link L300 by joint R80" where both are minimal.  O(n·m) in
the lengths of the two assemblies.
"""
from __future__ import annotations

from dataclasses import dataclass

from kin.modules.assembly import Assembly
from kin.modules.catalogue import Catalogue, _same_angle

__all__ = ["Edit", "edit_script", "swaps", "apply_script"]

OPS = ("replace", "add", "remove", "turn")


@dataclass(frozen=True)
class Edit:
    """One swap.  ``index``: the module's position in the *target* assembly (``add``, ``replace``,
    ``turn``) or in the *source* (``remove``); ``after``: the target's module before it (None: the
    base is replaced); ``old``/``new``: names; ``old_twist``/``new_twist``: rad (None for a base)."""

    op: str
    index: int
    old: str | None
    new: str | None
    old_twist: float | None
    new_twist: float | None
    after: str | None = None

    def text(self, catalogue: Catalogue | None = None, source: Assembly | None = None,
             target: Assembly | None = None) -> str:
        """Readable: "replace link L300 by L450", "add joint W2 at 90° after R80", "remove link L150",
        "turn R80 to 90°" (twists in the catalogue's angle unit; a name used more than once in its
        assembly gets its ordinal, "R80 (2nd)")."""
        def kind(name):
            m = catalogue.modules.get(name) if catalogue is not None else None
            return f"{m.kind} " if m is not None else ""

        def angle(t):
            return _angle_text(t, catalogue)

        def named(name, asm, index):
            return f"{name}{_ordinal(asm, index)}" if asm is not None else name

        if self.op == "remove":
            return f"remove {kind(self.old)}{named(self.old, source, self.index)}"
        if self.op == "turn":
            return f"turn {named(self.new, target, self.index)} to {angle(self.new_twist)}"
        at = "" if self.new_twist is None or _same_angle(self.new_twist, 0.0) else f" at {angle(self.new_twist)}"
        if self.op == "replace":
            same = kind(self.old) == kind(self.new)
            return f"replace {kind(self.old)}{self.old} by {'' if same else kind(self.new)}{self.new}{at}"
        prev = target.modules[self.index - 1] if target is not None and self.index > 0 else self.after
        where = f" after {named(prev, target, self.index - 1)}" if prev is not None else ""
        return f"add {kind(self.new)}{self.new}{at}{where}"


def _angle_text(t: float, catalogue: Catalogue | None) -> str:
    if catalogue is None or catalogue.angle_unit == "rad":
        return f"{round(t, 6):g} rad"
    return f"{round(t / catalogue.angle_scale, 6):g}°"


def _ordinal(asm: Assembly, index: int) -> str:
    name = asm.modules[index]
    if asm.modules.count(name) < 2:
        return ""
    k = asm.modules[:index + 1].count(name)
    return f" ({k}{'th' if 10 <= k % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(k % 10, 'th')})"


def _tokens(a: Assembly) -> list[tuple[str, float]]:
    return list(zip(a.modules[1:], a.twists))


def _kinds(catalogue: Catalogue | None):
    if catalogue is None:
        return lambda name: None
    return lambda name: getattr(catalogue.modules.get(name), "kind", None)


def edit_script(source: Assembly, target: Assembly, catalogue: Catalogue | None = None) -> list[Edit]:
    """A minimum list of swaps turning ``source`` into ``target`` (see the module text); its length is
    :func:`swaps`.  ``catalogue`` (optional) only breaks ties towards replacing a module by one of its
    own kind.

    The bases are aligned with each other: an alignment that matches a base with another module
    needs the other base inserted or deleted besides, so it costs at least as much as matching the
    bases and inserting (deleting) that module instead."""
    kind = _kinds(catalogue)
    A, B = _tokens(source), _tokens(target)
    n, m = len(A), len(B)
    # D[i][j] = (swaps, cross-kind replacements) turning A[:i] into B[:j]
    D = [[(0, 0)] * (m + 1) for _ in range(n + 1)]
    for i in range(1, n + 1):
        D[i][0] = (i, 0)
    for j in range(1, m + 1):
        D[0][j] = (j, 0)
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            (na, ta), (nb, tb) = A[i - 1], B[j - 1]
            if na == nb:
                sub = D[i - 1][j - 1] if _same_angle(ta, tb) else _plus(D[i - 1][j - 1], 1, 0)
            else:
                sub = _plus(D[i - 1][j - 1], 1, int(kind(na) != kind(nb)))
            D[i][j] = min(sub, _plus(D[i - 1][j], 1, 0), _plus(D[i][j - 1], 1, 0))
    # walk back
    edits: list[Edit] = []
    i, j = n, m
    while i > 0 or j > 0:
        if i > 0 and j > 0:
            (na, ta), (nb, tb) = A[i - 1], B[j - 1]
            if na == nb:
                same = _same_angle(ta, tb)
                if D[i][j] == (D[i - 1][j - 1] if same else _plus(D[i - 1][j - 1], 1, 0)):
                    if not same:
                        edits.append(Edit("turn", j, na, nb, ta, tb, target.modules[j - 1]))
                    i, j = i - 1, j - 1
                    continue
            elif D[i][j] == _plus(D[i - 1][j - 1], 1, int(kind(na) != kind(nb))):
                edits.append(Edit("replace", j, na, nb, ta, tb, target.modules[j - 1]))
                i, j = i - 1, j - 1
                continue
        if i > 0 and D[i][j] == _plus(D[i - 1][j], 1, 0):
            edits.append(Edit("remove", i, A[i - 1][0], None, A[i - 1][1], None, None))
            i -= 1
        else:
            edits.append(Edit("add", j, None, B[j - 1][0], None, B[j - 1][1], target.modules[j - 1]))
            j -= 1
    if source.modules[0] != target.modules[0]:
        edits.append(Edit("replace", 0, source.modules[0], target.modules[0], None, None, None))
    edits.reverse()
    return edits


def _plus(c: tuple[int, int], a: int, b: int) -> tuple[int, int]:
    return (c[0] + a, c[1] + b)


def swaps(source: Assembly, target: Assembly) -> int:
    """The least number of swaps turning ``source`` into ``target``."""
    return len(edit_script(source, target))


def apply_script(source: Assembly, edits: list[Edit]) -> Assembly:
    """``source`` with ``edits`` (an :func:`edit_script`) carried out: the target.  Removals index the
    source, the other swaps the target; every target position is either added or the next source
    module not removed (kept, replaced or turned)."""
    removed = {e.index for e in edits if e.op == "remove"}
    at = {e.index: e for e in edits if e.op != "remove"}
    kept = iter(k for k in range(1, len(source.modules)) if k not in removed)
    mods = [at[0].new if 0 in at else source.modules[0]]
    twists = []
    for j in range(1, len(source.modules) - len(removed) + sum(e.op == "add" for e in edits)):
        e = at.get(j)
        if e is None or e.op != "add":
            k = next(kept)
        if e is None:
            mods.append(source.modules[k])
            twists.append(source.twists[k - 1])
        else:
            mods.append(e.new)
            twists.append(e.new_twist)
    return Assembly(tuple(mods), tuple(twists))
