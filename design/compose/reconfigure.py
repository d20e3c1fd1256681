"""Reconfiguration across a part family: a *base* assembly and, for each part, the assembly it runs
on — the base itself or the base with some modules swapped — at the least total cost

    modules owned + swap_cost × swaps,

the modules owned being, for each module type, the largest number any single configuration (the base
or a part's) uses, times its cost.  The capability change made concrete: "for part B, replace link
L300 by L450 and add joint W2 after R80".

The candidates are each part's ``k`` cheapest feasible assemblies (:func:`design.compose.search.cheapest`,
or given).  Every candidate is judged for every other part too (``judge_many``: the verdict cache and
the workers of :mod:`design.compose.store`), so a part may run on any candidate feasible for it, and
the best *single* assembly — one candidate feasible for every part, at its own cost — is known for
comparison.  The optimum over these sets is exact (:func:`design.compose.choose.choose`, branch and
bound; it says when its node budget stopped it).  What is capped: the candidate pool (k × parts ≤
``max_pool``; k is lowered and the plan says so) — assemblies outside the pool are not considered,
so the plan is the least over the candidates, not over every assembly of the space.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from design.compose.choose import NODE_BUDGET, Choice, choose
from design.compose.edits import Edit, edit_script, swaps
from kin.errors import RmtError
from kin.modules import Assembly, Catalogue

__all__ = ["ReconfigurationPlan", "ReconfigurationError", "reconfigure", "MAX_POOL", "MAX_K", "money"]

#: the candidate pool (k × number of parts) is capped at this many assemblies
MAX_POOL = 60
MAX_K = 50
MAX_SWAP_COST = 1e12


class ReconfigurationError(RmtError, ValueError):
    """Bad reconfiguration input (swap cost, k, parts): one line."""


def money(x: float, currency: str = "") -> str:
    """A cost as "21 400 EUR" (thousands spaced; cents only when there are any)."""
    s = f"{round(x):,}" if abs(x - round(x)) < 1e-9 else f"{x:,.2f}"
    return s.replace(",", " ") + (f" {currency}" if currency else "")


@dataclass
class ReconfigurationPlan:
    """A base assembly and each part's assembly (``assemblies``, same order as ``parts``), the swaps
    from the base to each (``edits``; ``operations`` as text), the modules to own (``inventory``:
    name → count, catalogue order) and the costs; the best single assembly serving every part
    (``single``, or None: no candidate does) for comparison.  ``exact``: the optimum over the
    candidates is proven; ``capped``: fewer than the asked ``k`` candidates per part were used.
    ``missing``: parts with no feasible candidate (then there is no plan: ``base`` is None)."""

    catalogue: str
    currency: str
    parts: tuple[str, ...]
    swap_cost: float
    base: Assembly | None
    base_text: str
    assemblies: tuple[Assembly | None, ...]
    texts: tuple[str, ...]
    edits: tuple[tuple[Edit, ...], ...]
    operations: tuple[tuple[str, ...], ...]
    inventory: dict[str, int]
    inventory_cost: float
    swaps: int
    total: float
    single: Assembly | None
    single_text: str
    single_cost: float | None
    pool: tuple[tuple[str, float, tuple[str, ...]], ...]     # (assembly, cost, parts it serves)
    k: int
    k_asked: int
    exact: bool
    nodes: int
    verdicts: int
    missing: tuple[str, ...] = ()
    single_counts: dict[str, int] = field(default_factory=dict)
    max_pool: int = MAX_POOL

    @property
    def found(self) -> bool:
        return self.base is not None

    @property
    def capped(self) -> bool:
        return self.k < self.k_asked

    def _m(self, x: float) -> str:
        return money(x, self.currency)

    def comparison(self, short: bool = False) -> str:
        """Which is cheaper, the reconfigurable plan or one assembly for every part, and why
        (``short``: without restating the plan's cost, as :meth:`lines` has it the line before)."""
        m = len(self.parts)
        every = f"all {m} parts" if m > 2 else ("both parts" if m == 2 else "the part")
        if not self.found:
            return (f"no plan: {', '.join(self.missing)} {'has' if len(self.missing) == 1 else 'have'} no feasible "
                    f"assembly among the candidates searched")
        s = "s" if self.swaps != 1 else ""
        plan = (f"the reconfigurable plan costs {self._m(self.inventory_cost)} + {self.swaps} swap{s} × "
                f"{self._m(self.swap_cost)} = {self._m(self.total)}")
        if self.single is None:
            return f"no candidate assembly serves {every} (of {len(self.pool)} judged for every part)" + \
                ("" if short else f"; {plan}")
        if self.swaps == 0:
            return f"one assembly serves {every} at {self._m(self.single_cost)}: no swap pays at " \
                   f"{self._m(self.swap_cost)} a swap"
        extra = [f"{n} ×{c} where the plan owns {self.inventory.get(n, 0)}"
                 for n, c in self.single_counts.items() if c > self.inventory.get(n, 0)]
        why = f": one assembly needs {', '.join(extra)}" if extra else ""
        saves = self._m(self.single_cost - self.total)
        if short:
            return f"one assembly for {every}: {self.single_text} at {self._m(self.single_cost)}; the plan is " \
                   f"{saves} cheaper{why}"
        return f"one assembly serves {every} at {self._m(self.single_cost)} ({self.single_text}); {plan}, " \
               f"{saves} less{why}"

    def lines(self) -> list[str]:
        """The plan as text (the CLI prints these)."""
        head = (f"reconfiguration for {len(self.parts)} part{'s' if len(self.parts) != 1 else ''} "
                f"(catalogue {self.catalogue}, {self._m(self.swap_cost)} a swap):")
        out = [head]
        if not self.found:
            return [*out, f"  {self.comparison()}"]
        out.append(f"  base assembly: {self.base_text}")
        for name, ops in zip(self.parts, self.operations):
            if not ops:
                out.append(f"  {name}: the base as it is")
            else:
                out.append(f"  {name}: {len(ops)} swap{'s' if len(ops) != 1 else ''}: {'; '.join(ops)}")
        owned = ", ".join(f"{n} ×{c}" for n, c in self.inventory.items() if c)
        out.append(f"  modules to own: {owned} = {self._m(self.inventory_cost)}")
        out.append(f"  total: {self._m(self.inventory_cost)} + {self.swaps} swap{'s' if self.swaps != 1 else ''} × "
                   f"{self._m(self.swap_cost)} = {self._m(self.total)}")
        out.append(f"  {self.comparison(short=True)}")
        how = "exact" if self.exact else f"not proven least (search stopped after {self.nodes} nodes)"
        cap = f"; k capped from {self.k_asked} to {self.k} (k × parts ≤ {self.max_pool})" if self.capped else ""
        out.append(f"  {how} over {len(self.pool)} candidate assemblies (up to {self.k} feasible per part, cheapest "
                   f"first{cap}; {self.verdicts} verdicts for the other parts)")
        return out

    def to_json(self) -> dict:
        return {
            "catalogue": self.catalogue, "currency": self.currency, "parts": list(self.parts),
            "swap_cost": self.swap_cost, "found": self.found, "missing": list(self.missing),
            "base": self.base_text if self.found else None,
            "configurations": [{"part": p, "assembly": t, "swaps": len(ops), "operations": list(ops)}
                               for p, t, ops in zip(self.parts, self.texts, self.operations)] if self.found else [],
            "inventory": dict(self.inventory), "inventory_cost": self.inventory_cost if self.found else None,
            "swaps": self.swaps if self.found else None, "total": self.total if self.found else None,
            "single": ({"assembly": self.single_text, "cost": self.single_cost} if self.single is not None else None),
            "comparison": self.comparison(), "exact": self.exact, "k": self.k, "k_asked": self.k_asked,
            "capped": self.capped, "nodes": self.nodes, "verdicts": self.verdicts,
            "pool": [{"assembly": t, "cost": c, "serves": list(s)} for t, c, s in self.pool],
        }


def _check(parts, swap_cost, k, max_pool) -> None:
    if not parts:
        raise ReconfigurationError("reconfiguration needs at least one part")
    if isinstance(swap_cost, bool) or not isinstance(swap_cost, (int, float)) or not math.isfinite(swap_cost) \
            or not 0 <= swap_cost <= MAX_SWAP_COST:
        raise ReconfigurationError(f"swap cost {swap_cost!r} must be a number in [0, {MAX_SWAP_COST:g}]")
    if isinstance(k, bool) or not isinstance(k, int) or not 1 <= k <= MAX_K:
        raise ReconfigurationError(f"k {k!r} must be an integer in [1, {MAX_K}]")
    if isinstance(max_pool, bool) or not isinstance(max_pool, int) or max_pool < 1:
        raise ReconfigurationError(f"max_pool {max_pool!r} must be a positive integer")


def _candidates(catalogue, parts, space, k, settings, judge_many, cheapest_kw) -> list[list[Assembly]]:
    from design.compose.search import cheapest
    out = []
    for p in parts:
        found = cheapest(catalogue, p, space, k, settings=settings, judge_many=judge_many, **cheapest_kw)
        out.append([getattr(x, "assembly", x) for x in found])
    return out


def reconfigure(catalogue: Catalogue, parts, space=None, swap_cost: float = 0.0, k: int = 5, settings=None,
                judge_many=None, candidates=None, max_pool: int = MAX_POOL, node_budget: int = NODE_BUDGET,
                **cheapest_kw) -> ReconfigurationPlan:
    """The least-cost reconfiguration plan (module text) for ``parts`` (each with a ``name``).

    ``candidates``: per part, its feasible assemblies cheapest first (default: the ``k`` cheapest of
    ``space``, :func:`design.compose.search.cheapest` with ``settings``, ``judge_many`` and
    ``cheapest_kw``).  ``judge_many(pairs) -> verdicts`` judges candidates for the other parts
    (default: in this process, no cache).  ``max_pool`` caps k × len(parts); ``node_budget`` the
    optimum's search."""
    parts = list(parts)
    _check(parts, swap_cost, k, max_pool)
    m = len(parts)
    k_used = min(k, max(1, max_pool // m))
    names = _part_names(parts)
    if candidates is None:
        candidates = _candidates(catalogue, parts, space, k_used, settings, judge_many, cheapest_kw)
    if len(candidates) != m:
        raise ReconfigurationError(f"candidates for {len(candidates)} parts given; there are {m} parts")
    candidates = [list(c)[:k_used] for c in candidates]
    # the pool: every candidate once (by its text), and which parts it is known to serve
    pool: list[Assembly] = []
    index: dict[str, int] = {}
    feasible: list[set[int]] = [set() for _ in range(m)]
    for t, cands in enumerate(candidates):
        for a in cands:
            text = a.text(catalogue)
            if text not in index:
                index[text] = len(pool)
                pool.append(a)
            feasible[t].add(index[text])
    # every candidate judged for the parts it is not a candidate of
    pairs = [(i, t) for t in range(m) for i in range(len(pool)) if i not in feasible[t]]
    if pairs:
        if judge_many is None:
            from design.compose.store import VerdictJudge
            judge_many = VerdictJudge(catalogue, settings)
        verdicts = judge_many([(pool[i], parts[t]) for i, t in pairs])
        for (i, t), v in zip(pairs, verdicts):
            if v.feasible:
                feasible[t].add(i)
    texts = [a.text(catalogue) for a in pool]
    costs = [a.cost(catalogue) for a in pool]
    serves = tuple((texts[i], costs[i], tuple(names[t] for t in range(m) if i in feasible[t]))
                   for i in range(len(pool)))
    single = min((i for i in range(len(pool)) if all(i in f for f in feasible)), key=lambda i: (costs[i], i),
                 default=None)
    types = [n for n in catalogue.modules if any(n in a.modules for a in pool)]
    counts = np.array([[a.modules.count(n) for n in types] for a in pool], dtype=np.int64).reshape(len(pool),
                                                                                                 len(types))
    prices = np.array([catalogue.modules[n].cost for n in types], dtype=float)
    common = dict(catalogue=catalogue.name, currency=catalogue.currency, parts=tuple(names),
                  swap_cost=float(swap_cost), pool=serves, k=k_used, k_asked=k, verdicts=len(pairs), max_pool=max_pool,
                  single=pool[single] if single is not None else None,
                  single_text=texts[single] if single is not None else "",
                  single_cost=costs[single] if single is not None else None,
                  single_counts=({n: int(c) for n, c in zip(types, counts[single])} if single is not None else {}))
    missing = tuple(names[t] for t in range(m) if not feasible[t])
    choice = None if missing else choose(counts, prices, [sorted(f) for f in feasible],
                                         np.array([[swaps(b, a) for a in pool] for b in pool], dtype=np.int64)
                                         .reshape(len(pool), len(pool)), float(swap_cost), node_budget)
    if single is not None and (choice is None or choice.total > costs[single] or
                               (choice.total == costs[single] and choice.swaps > 0)):
        # only when the node budget stopped the search short of the single assembly (it is a plan)
        choice = Choice(single, (single,) * m, tuple(int(c) for c in counts[single]), costs[single], 0,
                        costs[single], False if choice is None else choice.exact, 0 if choice is None else choice.nodes)
    if choice is None:
        return ReconfigurationPlan(base=None, base_text="", assemblies=(None,) * m, texts=("",) * m,
                                   edits=((),) * m, operations=((),) * m, inventory={}, inventory_cost=0.0,
                                   swaps=0, total=0.0, exact=True, nodes=0, missing=missing, **common)
    base = pool[choice.base]
    chosen = [pool[i] for i in choice.assemblies]
    scripts = [tuple(edit_script(base, a, catalogue)) for a in chosen]
    ops = tuple(tuple(e.text(catalogue, base, a) for e in s) for s, a in zip(scripts, chosen))
    return ReconfigurationPlan(base=base, base_text=texts[choice.base], assemblies=tuple(chosen),
                               texts=tuple(texts[i] for i in choice.assemblies), edits=tuple(scripts),
                               operations=ops, inventory={n: c for n, c in zip(types, choice.inventory) if c},
                               inventory_cost=choice.inventory_cost, swaps=choice.swaps, total=choice.total,
                               exact=choice.exact, nodes=choice.nodes, **common)


def _part_names(parts) -> list[str]:
    names = [str(getattr(p, "name", "") or f"part{i + 1}") for i, p in enumerate(parts)]
    seen: dict[str, int] = {}
    out = []
    for n in names:
        seen[n] = seen.get(n, 0) + 1
        out.append(n if names.count(n) == 1 else f"{n} ({seen[n]})")
    return out
