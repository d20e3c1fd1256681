"""The reconfiguration optimum over candidate sets: a base assembly B and one assembly A_t per part,
each feasible for its part, minimising

    inventory(B, A_1 … A_m) + swap_cost · Σ_t swaps(B, A_t)

where the inventory is what must be owned — for each module type the largest number any single
configuration among B and the A_t uses, times its cost — and swaps(B, A) the least number of swaps
turning B into A (:mod:`design.compose.edits`).  B ranges over every candidate (it need not serve a
part itself).

Exact by branch and bound: for each base (cheapest first), the parts are assigned depth first
(fewest candidates first; at each part the candidates in order of what they add); a branch is cut
when a lower bound is not below the best plan found: the inventory only grows as configurations are
added, so it is at least that of the configurations chosen so far and at least, for every part still
open, the least inventory it can reach with any of its candidates; the swaps are at least those made
plus each open part's fewest swaps from the base.  Worst case O(P · Π_t K_t · T) for P candidate
bases, K_t candidates of part t and T module types — the bound cuts almost all of it in practice; a
``node_budget`` stops the search, and the answer is then the best found, not proven least
(``exact`` False).  Ties go to fewer swaps, then to the base found first (the cheapest).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Choice", "choose", "inventory_of", "NODE_BUDGET"]

#: search nodes (partial plans) the branch and bound visits at most before it stops unproven
NODE_BUDGET = 2_000_000


@dataclass(frozen=True)
class Choice:
    """The optimum: ``base`` and ``assemblies`` (one per part) index the candidate pool;
    ``inventory`` the count of each module type owned; ``exact`` whether the search finished (the
    optimum is proven over the candidates) or stopped at the node budget; ``nodes`` visited."""

    base: int
    assemblies: tuple[int, ...]
    inventory: tuple[int, ...]
    inventory_cost: float
    swaps: int
    total: float
    exact: bool
    nodes: int


def inventory_of(counts: np.ndarray, chosen) -> np.ndarray:
    """The module counts owned for configurations ``chosen`` (rows of ``counts``): the largest per type."""
    return np.max(counts[list(chosen)], axis=0)


def choose(counts: np.ndarray, prices: np.ndarray, feasible: list[list[int]], swap: np.ndarray,
           swap_cost: float, node_budget: int = NODE_BUDGET) -> Choice | None:
    """The optimum (module text) over a pool of P candidate assemblies.

    ``counts`` (P, T): how many of each module type each candidate uses; ``prices`` (T,) each
    type's cost; ``feasible[t]``: the pool indices feasible for part t; ``swap`` (P, P): swaps from
    row (the base) to column; ``swap_cost`` ≥ 0.  None when a part has no feasible candidate."""
    counts = np.asarray(counts, dtype=np.int64)
    prices = np.asarray(prices, dtype=float)
    swap = np.asarray(swap, dtype=np.int64)
    P = counts.shape[0]
    m = len(feasible)
    if P == 0 or any(not f for f in feasible):
        return None
    order = sorted(range(m), key=lambda t: (len(feasible[t]), t))
    F = [np.array(sorted(set(feasible[t])), dtype=np.int64) for t in order]
    unit = counts @ prices
    s = float(swap_cost)
    node_budget = max(int(node_budget), m + 1)      # the first descent always reaches a plan
    best: list = [None]          # (total, swaps, base, picks in part order, inventory)
    nodes = [0]
    stopped = [False]

    def better(total, sw) -> bool:
        if best[0] is None:
            return True
        bt, bs = best[0][0], best[0][1]
        eps = 1e-9 * max(1.0, abs(bt))
        return total < bt - eps or (total <= bt + eps and sw < bs)

    def dfs(b: int, depth: int, cur: np.ndarray, sw: int, picks: list, minsw: np.ndarray):
        nodes[0] += 1
        if nodes[0] > node_budget:
            stopped[0] = True
            return
        inv = float(cur @ prices)
        if depth == m:
            total = inv + s * sw
            if better(total, sw):
                best[0] = (total, sw, b, list(picks), cur.copy())
            return
        # lower bound: every open part's least reachable inventory, and its fewest swaps
        reach = [np.min(np.maximum(cur, counts[f]) @ prices) for f in F[depth:]]
        lb_sw = sw + int(minsw[depth:].sum())
        if not better(max(inv, *reach) + s * lb_sw, lb_sw):
            return
        f = F[depth]
        add = np.maximum(cur, counts[f]) @ prices + s * swap[b, f]
        for i in np.argsort(add, kind="stable"):
            a = int(f[i])
            picks.append(a)
            dfs(b, depth + 1, np.maximum(cur, counts[a]), sw + int(swap[b, a]), picks, minsw)
            picks.pop()
            if stopped[0]:
                return

    for b in sorted(range(P), key=lambda i: (unit[i], i)):
        minsw = np.array([int(swap[b, f].min()) for f in F], dtype=np.int64)
        dfs(b, 0, counts[b].copy(), 0, [], minsw)
        if stopped[0]:
            break
    if best[0] is None:
        return None
    total, sw, b, picks, cur = best[0]
    per_part = [0] * m
    for t, a in zip(order, picks):
        per_part[t] = a
    return Choice(b, tuple(per_part), tuple(int(x) for x in cur), float(cur @ prices), int(sw), float(total),
                  not stopped[0], nodes[0])
