"""Reconfiguration across a part family: a *base* assembly and, for each part, the assembly it runs
on — the base itself or the base with some modules swapped — at the least total cost

    modules owned + swap_cost × swaps,

the modules owned being, for each module type, the largest number any single configuration (the base
or a part's) uses, times its cost.  The capability change made concrete: "for part B, replace link
L300 by L450 and add joint W2 after R80".

The candidates are each part's ``k`` cheapest feasible assemblies
(:func:`design.compose.search.cheapest`, or given) and the least-cost single assembly that serves
every part (:func:`design.compose.search.compose` on the same space, when there is a space).  Every
candidate is judged for every other part too (``judge_many``: the verdict cache and the workers of
:mod:`design.compose.store`), so a part may run on any candidate feasible for it, and the best
*single* assembly is known for comparison.  The optimum over these sets is exact
(:func:`design.compose.choose.choose`, branch and bound; it says when its node budget stopped it).
What is capped: the candidate pool (k × parts ≤ ``max_pool``; k is lowered and the plan says so) —
assemblies outside the pool are not considered, so the plan is the least over the candidates, not
over every assembly of the space.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from design.compose.choose import NODE_BUDGET, Choice, choose
from design.compose.edits import edit_script, swaps
from design.compose.plan import MAX_POOL, ReconfigurationPlan, money
from kin.errors import RmtError
from kin.modules import Assembly, Catalogue

__all__ = ["ReconfigurationPlan", "ReconfigurationError", "reconfigure", "MAX_POOL", "MAX_K", "money"]

MAX_K = 50
MAX_SWAP_COST = 1e12


class ReconfigurationError(RmtError, ValueError):
    """Bad reconfiguration input (swap cost, k, parts): one line."""


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


def _search_settings(settings):
    """The candidates' search settings: no verification of each part's cheapest (the plan's own
    assemblies are verified instead)."""
    from design.compose.verdict import ComposeSettings
    settings = settings or ComposeSettings()
    return dataclasses.replace(settings, verify=None) if dataclasses.is_dataclass(settings) else settings


def _candidates(catalogue, parts, space, k, settings, judge_many, share, progress, notes) -> list[list[Assembly]]:
    """Each part's k cheapest feasible assemblies (:func:`design.compose.search.cheapest`), each
    search within ``share`` (seconds, verdicts; None: no limit)."""
    from design.compose.search import cheapest
    out = []
    for p in parts:
        res = cheapest(catalogue, p, space, k, _search_settings(settings), budget_s=share[0], progress=progress,
                       judge_many=judge_many, max_judged=share[1])
        out.append([f.assembly for f in res.found])
        if not res.exhaustive:
            notes.append(f"part {p.name}: the search for its candidates was cut by the budget "
                         f"({res.counts.get('not_judged', 0)} assemblies not judged); cheaper ones may exist")
    return out


class _UpTo:
    """A composition space cut at a cost: its assemblies in cost order (:meth:`ordered`) up to the
    last costing at most ``ceiling``; ``stopped`` says whether costlier ones were left.  Everything
    else is the space's own.  A single assembly costing more than the plan's total cannot make a
    cheaper plan (it would be owned whole), so the single search need not look beyond it."""

    def __init__(self, space, ceiling: float):
        self._space, self.ceiling, self.stopped = space, float(ceiling), False

    def __getattr__(self, name):
        return getattr(self._space, name)

    def ordered(self, prune=None):
        from design.compose.space import Pruned
        tol = 1e-9 * max(1.0, abs(self.ceiling))
        for item in self._space.ordered(prune):
            if float(item.cost if isinstance(item, Pruned) else item[1]) > self.ceiling + tol:
                self.stopped = True
                return
            yield item


def _single(catalogue, parts, space, settings, judge_many, ceiling, share, progress, notes):
    """The least-cost assembly of the space serving every part, searched up to ``ceiling``
    (:func:`design.compose.search.compose`): (assembly or None, scope) with scope "space" (it is the
    least of the space, or the whole space has none), "below" (none costs up to the ceiling) or
    "candidates" (the search was cut by the budget)."""
    from design.compose.search import compose
    cut = _UpTo(space, ceiling)
    res = compose(catalogue, parts, cut, _search_settings(settings), budget_s=share[0], progress=progress,
                  judge_many=judge_many, max_judged=share[1])
    if not res.exhaustive:
        notes.append(f"the search for one assembly serving every part was cut by the budget "
                     f"({res.counts.get('not_judged', 0)} assemblies not judged)")
        return res.best, "candidates"
    return res.best, ("below" if cut.stopped and res.best is None else "space")


def _verify(catalogue, parts, chosen, settings) -> list[tuple[str, int, int]]:
    """Each part's assembly re-judged by the denser reach study of ``settings.verify``:
    (part, reached, targets)."""
    from design.compose.verdict import ComposeSettings, verify
    settings = settings or ComposeSettings()
    if getattr(settings, "verify", None) is None:
        return []
    out = []
    for p, a in zip(parts, chosen):
        st = verify(catalogue, a, p, settings.verify)
        out.append((p.name, int(st.reached.sum()), len(st)))
    return out


def reconfigure(catalogue: Catalogue, parts, space=None, swap_cost: float = 0.0, k: int = 5, settings=None,
                judge_many=None, candidates=None, max_pool: int = MAX_POOL, node_budget: int = NODE_BUDGET,
                budget_s: float | None = None, max_judged: int | None = None, progress=None, verify: bool = True,
                single_search: bool = True) -> ReconfigurationPlan:
    """The least-cost reconfiguration plan (module text) for ``parts`` (:class:`design.compose.Part`).

    ``candidates``: per part, its feasible assemblies cheapest first (default: the ``k`` cheapest of
    ``space`` by :func:`design.compose.search.cheapest` with ``settings`` (a
    :class:`design.compose.ComposeSettings`; its verification left to the plan), ``judge_many``,
    ``progress``, and ``budget_s`` and ``max_judged`` shared among the searches).
    ``judge_many(pairs) -> verdicts`` also judges every candidate for the other parts (default: in
    this process, no cache).  With a
    ``space`` and ``single_search``, the least-cost single assembly for every part is searched too
    (:func:`design.compose.search.compose`, up to the plan's total: a dearer one cannot help) and
    joins the candidates.  ``max_pool`` caps k × len(parts); ``node_budget`` the optimum's search.
    With ``verify``, each part's assembly is re-judged by ``settings.verify``'s denser reach study
    (:func:`design.compose.verdict.verify`)."""
    parts = list(parts)
    _check(parts, swap_cost, k, max_pool)
    m = len(parts)
    k_used = min(k, max(1, max_pool // m))
    names = _part_names(parts)
    notes: list[str] = []
    searches = (m if candidates is None else 0) + (space is not None and single_search)
    n = max(searches, 1)
    share = (None if budget_s is None else budget_s / n, None if max_judged is None else max(1, max_judged // n))
    if judge_many is None:
        from design.compose.store import VerdictJudge
        judge_many = VerdictJudge(catalogue, _search_settings(settings))
    if candidates is None:
        candidates = _candidates(catalogue, parts, space, k_used, settings, judge_many, share, progress, notes)
    if len(candidates) != m:
        raise ReconfigurationError(f"candidates for {len(candidates)} parts given; there are {m} parts")
    pool = _Pool(catalogue, m)
    for t, cands in enumerate(candidates):
        for a in list(cands)[:k_used]:
            pool.add(a, (t,))
    # every candidate judged for the parts it is not a candidate of
    pairs = [(i, t) for t in range(m) for i in range(len(pool.items)) if i not in pool.feasible[t]]
    for (i, t), v in zip(pairs, judge_many([(pool.items[i], parts[t]) for i, t in pairs]) if pairs else []):
        if v.feasible:
            pool.feasible[t].add(i)
    choice = pool.choose(swap_cost, node_budget)
    scope, floor = "candidates", None
    if choice is not None and space is not None and single_search:
        best, scope = _single(catalogue, parts, space, settings, judge_many, choice.total, share, progress, notes)
        floor = choice.total if scope == "below" else None
        if best is not None:
            pool.add(best, range(m))
            choice = pool.choose(swap_cost, node_budget)
    return _plan(catalogue, parts, names, pool, choice, swap_cost, k_used, k, len(pairs), max_pool, notes, scope,
                 floor, settings if verify else False)


class _Pool:
    """The candidate assemblies (each once, by its text) and the parts each is feasible for."""

    def __init__(self, catalogue: Catalogue, m: int):
        self.catalogue, self.items, self.index = catalogue, [], {}
        self.feasible: list[set[int]] = [set() for _ in range(m)]

    def add(self, a: Assembly, parts) -> None:
        text = a.text(self.catalogue)
        if text not in self.index:
            self.index[text] = len(self.items)
            self.items.append(a)
        for t in parts:
            self.feasible[t].add(self.index[text])

    def arrays(self):
        """(module types, counts (P, T), prices (T,))."""
        cat, P = self.catalogue, len(self.items)
        types = [n for n in cat.modules if any(n in a.modules for a in self.items)]
        counts = np.array([[a.modules.count(n) for n in types] for a in self.items], dtype=np.int64)
        return types, counts.reshape(P, len(types)), np.array([cat.modules[n].cost for n in types], dtype=float)

    def single(self) -> int | None:
        """The cheapest candidate feasible for every part."""
        every = [i for i in range(len(self.items)) if all(i in f for f in self.feasible)]
        return min(every, key=lambda i: (self.items[i].cost(self.catalogue), i), default=None)

    def choose(self, swap_cost: float, node_budget: int) -> Choice | None:
        if any(not f for f in self.feasible):
            return None
        _, counts, prices = self.arrays()
        P = len(self.items)
        sw = np.array([[swaps(b, a) for a in self.items] for b in self.items], dtype=np.int64).reshape(P, P)
        choice = choose(counts, prices, [sorted(f) for f in self.feasible], sw, float(swap_cost), node_budget)
        single = self.single()
        if single is not None:
            cost = self.items[single].cost(self.catalogue)
            if choice.total > cost or (choice.total == cost and choice.swaps > 0):
                # only when the node budget stopped the search short of the single assembly (a plan too)
                choice = Choice(single, (single,) * len(self.feasible), tuple(int(c) for c in counts[single]),
                                cost, 0, cost, choice.exact, choice.nodes)
        return choice


def _plan(catalogue, parts, names, pool: _Pool, choice, swap_cost, k_used, k, verdicts, max_pool, notes, scope, floor,
          verify_settings) -> ReconfigurationPlan:
    m = len(parts)
    texts = [a.text(catalogue) for a in pool.items]
    costs = [a.cost(catalogue) for a in pool.items]
    types, counts, _ = pool.arrays()
    single = pool.single()
    common = dict(
        catalogue=catalogue.name, currency=catalogue.currency, parts=tuple(names), swap_cost=float(swap_cost),
        pool=tuple((texts[i], costs[i], tuple(names[t] for t in range(m) if i in pool.feasible[t]))
                   for i in range(len(texts))),
        k=k_used, k_asked=k, verdicts=verdicts, max_pool=max_pool, notes=tuple(notes), single_scope=scope,
        single_floor=floor, single=pool.items[single] if single is not None else None,
        single_text=texts[single] if single is not None else "",
        single_cost=costs[single] if single is not None else None,
        single_counts={n: int(c) for n, c in zip(types, counts[single])} if single is not None else {})
    if choice is None:
        missing = tuple(names[t] for t in range(m) if not pool.feasible[t])
        return ReconfigurationPlan(base=None, base_text="", assemblies=(None,) * m, texts=("",) * m,
                                   edits=((),) * m, operations=((),) * m, inventory={}, inventory_cost=0.0,
                                   swaps=0, total=0.0, exact=True, nodes=0, missing=missing, **common)
    base = pool.items[choice.base]
    chosen = [pool.items[i] for i in choice.assemblies]
    scripts = [tuple(edit_script(base, a, catalogue)) for a in chosen]
    ops = tuple(tuple(e.text(catalogue, base, a) for e in s) for s, a in zip(scripts, chosen))
    checked = _verify(catalogue, parts, chosen, verify_settings) if verify_settings is not False else []
    return ReconfigurationPlan(base=base, base_text=texts[choice.base], assemblies=tuple(chosen),
                               texts=tuple(texts[i] for i in choice.assemblies), edits=tuple(scripts),
                               operations=ops, inventory={n: c for n, c in zip(types, choice.inventory) if c},
                               inventory_cost=choice.inventory_cost, swaps=choice.swaps, total=choice.total,
                               exact=choice.exact, nodes=choice.nodes, verification=tuple(checked), **common)


def _part_names(parts) -> list[str]:
    names = [str(getattr(p, "name", "") or f"part{i + 1}") for i, p in enumerate(parts)]
    seen: dict[str, int] = {}
    out = []
    for n in names:
        seen[n] = seen.get(n, 0) + 1
        out.append(n if names.count(n) == 1 else f"{n} ({seen[n]})")
    return out
