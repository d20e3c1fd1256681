"""The space of assemblies a composition searches (:class:`ComposeSpace`): a base, then ``joints``
joint modules each followed by up to ``links_per_joint`` link modules, then a tool or none — every
module mounted at every twist its connector allows.  Connector compatibility is structural: only
modules whose input meets the previous output are ever formed.

**Twists reduced by a proven equivalence** (``twists="reduced"``).  A link or tool module M is
*axisymmetric* when its output frame is its input frame moved along and turned about the input z
axis only, and its part (mass, centre of mass, inertia, capsules) is symmetric about that axis.  M
mounted at twist t and followed by N at twist u is then the same machine as M at twist t₀ followed by
N at u + t − t₀ — every frame after M, every part of M and after it, is identical (Rz(t) commutes
with a move along and a turn about z) — provided u + t − t₀ is a twist N's connector allows: M is
reduced (only t₀, the first allowed twist, is formed) when every module that meets M's output allows
a set of twists that every such shift maps onto itself.  When M may end the chain (a tool; a link
when the space has chains without a tool) the shift becomes a turn of the tool frame about its own z
axis: reduced only with ``roll_free`` (no part asks for a full pose).  A *full-turn coaxial* joint
module — revolute, its axis the input z axis, its travel at least a full turn, its proximal part
symmetric about the axis — mounted at twist t is the machine at twist t₀ with the joint's values
shifted by t − t₀; over a full turn of travel both take every angle, so they reach the same set of
configurations (every body's pose): reduced only with ``cycle_free`` (no part has a motion cycle,
whose straight joint-space moves would see the shifted travel).  Other joint modules are never
reduced.  :meth:`ComposeSpace.for_parts` sets both flags from the parts.  :meth:`ComposeSpace.size`
counts the reduced space and :meth:`ComposeSpace.size_all` the unreduced one.

**Order.**  :meth:`ComposeSpace.ordered` yields the assemblies lazily in non-decreasing cost, ties by
fewer joints, then by the assembly's text (``rmt assemble --modules`` form, text order): a heap of
partial assemblies keyed by the exact least (cost, joints) of their completions (dynamic programming
over (output connector, joints so far, links since the last joint)), costs summed exactly as
fractions.  A ``prune`` callback may declare a partial assembly's every completion infeasible; the
generator then yields a :class:`Pruned` with the exact number of assemblies it removes.
"""
from __future__ import annotations

import heapq
import math
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import Callable, Iterator

import numpy as np

from kin.modules import MAX_JOINTS, Assembly, Catalogue
from kin.modules.catalogue import Module, _same_angle

__all__ = ["ComposeSpace", "Pruned", "Partial", "axisymmetric", "full_turn_coaxial", "MAX_LINKS_PER_JOINT",
           "TWIST_MODES"]

MAX_LINKS_PER_JOINT = 4
TWIST_MODES = ("all", "reduced")
_EPS = 1e-12            # m, rad: a frame or part "on the axis"


def _on_axis(T: np.ndarray) -> bool:
    """A frame on the z axis, turned about it only."""
    T = np.asarray(T)
    return not (np.abs(T[:2, 3]).max() > _EPS or abs(T[2, 2] - 1.0) > _EPS or np.abs(T[:2, 2]).max() > _EPS)


def full_turn_coaxial(m: Module) -> bool:
    """A revolute joint module turning about its input z axis over at least a full turn, its proximal
    part symmetric about that axis (module text)."""
    return (m.kind == "joint" and m.type == "revolute" and _on_axis(m.axis)
            and m.limits[1] - m.limits[0] >= 2 * math.pi - 1e-12 and _symmetric(m))


def axisymmetric(m: Module) -> bool:
    """A link or tool whose output frame lies on its input z axis, turned about it only, and whose part
    is symmetric about that axis (capsules on it, centre of mass on it, inertia ixx = iyy, no products)."""
    return m.kind in ("link", "tool") and _on_axis(m.out) and _symmetric(m)


def _symmetric(m: Module) -> bool:
    p = m.proximal
    if max(abs(p.com[0]), abs(p.com[1])) > _EPS:
        return False
    ixx, iyy, _izz, ixy, ixz, iyz = p.inertia
    if abs(ixx - iyy) > _EPS * max(1.0, abs(ixx)) or max(abs(ixy), abs(ixz), abs(iyz)) > _EPS * max(1.0, abs(ixx)):
        return False
    return all(max(abs(a[0]), abs(a[1]), abs(b[0]), abs(b[1])) <= _EPS for a, b, _r in p.capsules)


@dataclass(frozen=True)
class Partial:
    """A prefix of assemblies: module names and twists so far, its ``state`` (output connector type,
    joints, links since the last joint) and its exact ``cost``."""

    modules: tuple[str, ...]
    twists: tuple[float, ...]
    state: tuple[str, int, int]
    cost: Fraction

    @property
    def joints(self) -> int:
        return self.state[1]

    def assembly(self) -> Assembly:
        return Assembly(self.modules, self.twists)


@dataclass(frozen=True)
class Pruned:
    """A partial assembly whose ``count`` completions ``prune`` proved infeasible (``stage``, ``reason``);
    ``cost`` is the least cost among them."""

    partial: Partial
    stage: str
    reason: str
    count: int
    cost: Fraction


class ComposeSpace:
    """The assemblies of ``catalogue`` (module text): ``joints`` = (least, most) joint modules;
    ``bases`` the base names (None: every base); ``tools`` tool names, None in the list meaning "no
    tool" (None: every tool, and no tool); ``links_per_joint`` link modules after each joint at most;
    ``twists`` "all" or "reduced"; ``roll_free``: the parts need no turn of the tool about its axis;
    ``cycle_free``: no part has a motion cycle."""

    def __init__(self, catalogue: Catalogue, joints=(3, 7), bases=None, tools=None, links_per_joint: int = 1,
                 twists: str = "all", roll_free: bool = False, cycle_free: bool = False):
        self.catalogue = cat = catalogue
        try:
            lo, hi = (int(joints), int(joints)) if isinstance(joints, (int, np.integer)) else map(int, joints)
        except (TypeError, ValueError):
            raise ValueError(f"joints must be (least, most), got {joints!r}") from None
        if not 1 <= lo <= hi <= MAX_JOINTS:
            raise ValueError(f"joints ({lo}, {hi}) must satisfy 1 ≤ least ≤ most ≤ {MAX_JOINTS}")
        if isinstance(links_per_joint, bool) or not isinstance(links_per_joint, (int, np.integer)) \
                or not 0 <= links_per_joint <= MAX_LINKS_PER_JOINT:
            raise ValueError(f"links_per_joint must be an integer in [0, {MAX_LINKS_PER_JOINT}], "
                             f"got {links_per_joint!r}")
        if twists not in TWIST_MODES:
            raise ValueError(f"twists must be one of {', '.join(TWIST_MODES)}, got {twists!r}")
        self.joints, self.links_per_joint, self.twist_mode = (lo, hi), int(links_per_joint), twists
        self.roll_free, self.cycle_free = bool(roll_free), bool(cycle_free)
        self.bases = tuple(self._names(bases, "base", "bases"))
        all_tools = [m.name for m in cat.of_kind("tool")]
        tools = [*all_tools, None] if tools is None else list(tools)
        self.no_tool = None in tools
        self.tools = tuple(self._names([t for t in tools if t is not None], "tool", "tools"))
        if not self.bases:
            raise ValueError("the space has no base module")
        self._joint_mods = [m for m in cat.of_kind("joint")]
        self._link_mods = [m for m in cat.of_kind("link")] if self.links_per_joint else []
        self._tool_mods = [cat.modules[t] for t in self.tools]
        self._moves_cache: dict[tuple[str, str, bool], list] = {}
        self._cost = {m.name: Fraction(m.cost) for m in cat.modules.values()}
        self._count = lru_cache(maxsize=None)(self._count_impl)
        self._best = lru_cache(maxsize=None)(self._best_impl)
        self._reach = lru_cache(maxsize=None)(self._reach_impl)

    @classmethod
    def for_parts(cls, catalogue: Catalogue, parts, **kw) -> "ComposeSpace":
        """The space for ``parts`` with every twist reduction they allow (``twists="reduced"``,
        ``roll_free`` and ``cycle_free`` from the parts); ``kw``: the other arguments."""
        parts = list(parts)
        kw.setdefault("twists", "reduced")
        return cls(catalogue, roll_free=not any(p.needs_roll for p in parts),
                   cycle_free=not any(p.cycle is not None for p in parts), **kw)

    def _names(self, names, kind: str, what: str) -> list[str]:
        if names is None:
            return [m.name for m in self.catalogue.of_kind(kind)]
        out = []
        for n in names:
            m = self.catalogue.modules.get(n)
            if m is None or m.kind != kind:
                have = ", ".join(x.name for x in self.catalogue.of_kind(kind)) or "none"
                raise ValueError(f"{what}: {n!r} is not a {kind} module of catalogue {self.catalogue.name!r} "
                                 f"(its {kind}s: {have})")
            if n not in out:
                out.append(n)
        return out

    # ---- moves ---------------------------------------------------------------------------------------
    def _reducible(self, c: str, m: Module) -> bool:
        """Whether M's twist after an output of type ``c`` may be fixed to its first (module text)."""
        if self.twist_mode != "reduced":
            return False
        if m.kind == "joint":
            return self.cycle_free and full_turn_coaxial(m)
        if not axisymmetric(m):
            return False
        cat = self.catalogue
        ends = m.kind == "tool" or (self.no_tool and m.kind == "link")
        if ends and not self.roll_free:
            return False
        if m.kind == "tool":
            return True
        tw = cat.twists(c, m.input)
        shifts = [t - tw[0] for t in tw]
        for n in cat.modules.values():
            if n.kind == "base" or not cat.meets(m.output, n.input):
                continue
            allowed = cat.twists(m.output, n.input)
            for s in shifts:
                if not all(any(_same_angle(u + s, v) for v in allowed) for u in allowed):
                    return False
        return True

    def moves(self, c: str, kind: str, reduced: bool = True) -> list[tuple[Module, tuple[float, ...]]]:
        """The modules of ``kind`` whose input meets an output of type ``c``, each with its twists
        (rad; the first only where reduced), in catalogue order."""
        key = (c, kind, reduced)
        got = self._moves_cache.get(key)
        if got is None:
            mods = {"joint": self._joint_mods, "link": self._link_mods, "tool": self._tool_mods}[kind]
            got = []
            for m in mods:
                tw = self.catalogue.twists(c, m.input)
                if tw:
                    got.append((m, tw[:1] if reduced and self._reducible(c, m) else tw))
            self._moves_cache[key] = got
        return got

    def _children(self, state, reduced: bool = True):
        """(module, twists, next state or None for the end) from ``state``."""
        c, k, l_ = state
        lo, hi = self.joints
        if k < hi:
            for m, tw in self.moves(c, "joint", reduced):
                yield m, tw, (m.output, k + 1, 0)
        if k >= 1 and l_ < self.links_per_joint:
            for m, tw in self.moves(c, "link", reduced):
                yield m, tw, (m.output, k, l_ + 1)
        if k >= lo:
            for m, tw in self.moves(c, "tool", reduced):
                yield m, tw, None

    # ---- counts and bounds over completions ----------------------------------------------------------
    def _count_impl(self, state, reduced: bool = True, twisted: bool = True) -> int:
        n = 1 if (state[1] >= self.joints[0] and self.no_tool) else 0
        for m, tw, nxt in self._children(state, reduced):
            mult = len(tw) if twisted else 1
            n += mult * (1 if nxt is None else self._count(nxt, reduced, twisted))
        return n

    def count_from(self, state) -> int:
        """The assemblies of the space that complete a partial assembly in ``state``."""
        return self._count(state)

    def size(self) -> int:
        """The number of assemblies in the space (exact, computed without enumerating them)."""
        return sum(self._count((self.catalogue.modules[b].output, 0, 0)) for b in self.bases)

    def size_all(self) -> int:
        """The number of assemblies with every allowed twist (no twist reduction)."""
        return sum(self._count((self.catalogue.modules[b].output, 0, 0), False) for b in self.bases)

    def sequences(self) -> tuple[int, int]:
        """(module sequences of the space's structure whatever their connectors, those whose connectors meet)."""
        lo, hi = self.joints
        nj, nl = len(self._joint_mods), len(self._link_mods)
        seg = nj * sum(nl ** i for i in range(self.links_per_joint + 1))
        ends = len(self._tool_mods) + (1 if self.no_tool else 0)
        raw = len(self.bases) * sum(seg ** n for n in range(lo, hi + 1)) * ends
        ok = sum(self._count((self.catalogue.modules[b].output, 0, 0), False, False) for b in self.bases)
        return raw, ok

    def _best_impl(self, state):
        """The least (added cost, final joints) over the completions of ``state`` (None: none)."""
        best = (Fraction(0), state[1]) if (state[1] >= self.joints[0] and self.no_tool) else None
        for m, _tw, nxt in self._children(state):
            sub = (Fraction(0), state[1]) if nxt is None else self._best(nxt)
            if sub is None:
                continue
            cand = (self._cost[m.name] + sub[0], sub[1])
            if best is None or cand < best:
                best = cand
        return best

    def _reach_impl(self, state, extent: Callable[[Module], float]) -> float:
        """The largest sum of ``extent`` over the modules a completion of ``state`` adds (−inf: none)."""
        best = 0.0 if (state[1] >= self.joints[0] and self.no_tool) else -math.inf
        for m, _tw, nxt in self._children(state):
            sub = 0.0 if nxt is None else self._reach(nxt, extent)
            best = max(best, extent(m) + sub)
        return best

    def max_remaining(self, state, extent: Callable[[Module], float]) -> float:
        """The largest Σ extent(module) over the modules any completion of ``state`` adds."""
        return self._reach(state, extent)

    # ---- enumeration ---------------------------------------------------------------------------------
    def _text(self, modules, twists) -> str:
        return Assembly(modules, twists).text(self.catalogue)

    def ordered(self, prune: Callable[[Partial], tuple[str, str] | None] | None = None
                ) -> Iterator[tuple[Assembly, Fraction] | Pruned]:
        """Every assembly in non-decreasing (cost, joints, text) order as (Assembly, exact cost);
        ``prune(partial)`` (called on each partial assembly with at least one joint when it comes up)
        may return (stage, reason): its completions are skipped and a :class:`Pruned` is yielded."""
        heap: list = []
        seq = 0

        def push(p: Partial, complete: bool):
            nonlocal seq
            if complete:
                key = (p.cost, p.joints)
            else:
                b = self._best(p.state)
                if b is None:
                    return
                key = (p.cost + b[0], b[1])
            heapq.heappush(heap, (key[0], key[1], self._text(p.modules, p.twists), seq, complete, p))
            seq += 1

        for b in self.bases:
            m = self.catalogue.modules[b]
            push(Partial((b,), (), (m.output, 0, 0), self._cost[b]), False)
        while heap:
            cost, _j, _text, _s, complete, p = heapq.heappop(heap)
            if complete:
                yield p.assembly(), p.cost
                continue
            if prune is not None and p.joints >= 1:
                why = prune(p)
                if why is not None:
                    yield Pruned(p, why[0], why[1], self._count(p.state), cost)
                    continue
            if p.state[1] >= self.joints[0] and self.no_tool:
                push(p, True)
            for m, tw, nxt in self._children(p.state):
                for t in tw:
                    q = Partial(p.modules + (m.name,), p.twists + (t,), nxt or (m.output, p.state[1], -1),
                                p.cost + self._cost[m.name])
                    push(q, nxt is None)

    def __iter__(self) -> Iterator[Assembly]:
        for item in self.ordered():
            yield item[0]

    def describe(self) -> str:
        lo, hi = self.joints
        tools = ", ".join(self.tools) + (" or none" if self.no_tool else "") if self.tools else "none"
        return (f"{'base ' + ', '.join(self.bases)}; {lo}–{hi} joints, up to {self.links_per_joint} link(s) after "
                f"each; tool {tools}; twists {self.twist_mode}")
