"""The reconfiguration optimum over candidate sets (design.compose.choose) equals an exhaustive
enumeration of every base and every per-part choice, with the inventory recomputed here."""
from __future__ import annotations

import itertools

import numpy as np

from design.compose.choose import choose


def _exhaustive(counts, prices, feasible, swap, s):
    best = None
    for b in range(len(counts)):
        for picks in itertools.product(*feasible):
            owned = [max(counts[c][j] for c in (b, *picks)) for j in range(len(prices))]
            total = sum(o * p for o, p in zip(owned, prices)) + s * sum(swap[b][a] for a in picks)
            best = total if best is None else min(best, total)
    return best


def test_branch_and_bound_equals_the_exhaustive_optimum():
    rng = np.random.default_rng(3)
    for _ in range(400):
        P, T, m = int(rng.integers(1, 9)), int(rng.integers(1, 5)), int(rng.integers(1, 5))
        counts = rng.integers(0, 3, (P, T))
        prices = rng.integers(1, 20, T).astype(float) * 100
        feasible = [sorted({int(x) for x in rng.choice(P, int(rng.integers(1, P + 1)))}) for _ in range(m)]
        swap = rng.integers(0, 4, (P, P))
        np.fill_diagonal(swap, 0)
        s = float(rng.choice([0, 50, 300, 5000]))
        c = choose(counts, prices, feasible, swap, s)
        assert c.exact
        assert c.total == _exhaustive(counts.tolist(), prices.tolist(), feasible, swap.tolist(), s)
        # the choice is what it says it is
        assert all(a in feasible[t] for t, a in enumerate(c.assemblies))
        owned = np.max(counts[[c.base, *c.assemblies]], axis=0)
        assert tuple(owned) == c.inventory and c.inventory_cost == float(owned @ prices)
        assert c.swaps == sum(int(swap[c.base, a]) for a in c.assemblies)
        assert c.total == c.inventory_cost + s * c.swaps


def test_swapping_beats_owning_when_swaps_are_cheap_and_not_when_dear():
    # types: strong joint 3000, light joint 1000, long link 200; part 0 needs the strong joint,
    # part 1 the long link; pool 2 serves both but carries two strong joints
    counts = np.array([[1, 1, 0],      # 0: strong + light
                       [0, 2, 1],      # 1: two light + long link
                       [2, 0, 1]])     # 2: two strong + long link (serves both)
    prices = np.array([3000.0, 1000.0, 200.0])
    feasible = [[0, 2], [1, 2]]
    swap = np.array([[0, 2, 2], [2, 0, 2], [2, 2, 0]])
    cheap = choose(counts, prices, feasible, swap, 100)
    # parts on pools 0 and 1: own strong 1, light 2, long 1 = 5200, and two swaps from either base
    # (a tie: the cheaper base, pool 1, is taken)
    assert (cheap.base, cheap.assemblies, cheap.total, cheap.swaps) == (1, (0, 1), 5400.0, 2)
    dear = choose(counts, prices, feasible, swap, 1000)
    # 5200 + 2000 = 7200 > pool 2 alone (6200, no swaps)
    assert (dear.base, dear.assemblies, dear.total, dear.swaps) == (2, (2, 2), 6200.0, 0)


def test_no_plan_when_a_part_has_no_candidate_and_the_budget_stops_unproven():
    assert choose(np.ones((2, 1)), np.ones(1), [[0], []], np.zeros((2, 2)), 1.0) is None
    rng = np.random.default_rng(0)
    counts = rng.integers(0, 3, (8, 4))
    swap = rng.integers(1, 4, (8, 8))
    c = choose(counts, np.ones(4), [list(range(8))] * 5, swap, 1.0, node_budget=20)
    assert not c.exact and c.nodes > 20
