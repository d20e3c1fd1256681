"""Reconfiguration plans (design.compose.reconfigure) over hand-made candidate lists and verdict
tables: the plan is the exhaustive optimum (inventory recomputed here from module counts), its swaps
turn the base into each part's assembly, the comparison with one assembly for every part says which
is cheaper by how much, the pool cap is said, bad input is refused with one line."""
from __future__ import annotations

import itertools
import json
from collections import Counter
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from design.compose.edits import apply_script, swaps
from design.compose.reconfigure import ReconfigurationError, reconfigure
from kin.modules import Assembly, load_catalogue

CATALOGUE = Path(__file__).resolve().parents[2] / "kin" / "modules" / "small_catalogue.toml"


@pytest.fixture(scope="module")
def cat():
    return load_catalogue(CATALOGUE)


def _table_judge(cat, table):
    calls = []

    def judge_many(pairs):
        calls.extend((a.text(cat), p.name) for a, p in pairs)
        return [SimpleNamespace(feasible=table.get((a.text(cat), p.name), False)) for a, p in pairs]
    return judge_many, calls


def _parts(*names):
    return [SimpleNamespace(name=n) for n in names]


def _family(cat):
    A = lambda t: Assembly.parse(t, cat)       # noqa: E731
    cands = [[A("B JS LL JL T"), A("B JS LL JS T")],
             [A("B JS LS JL JL T"), A("B JS LL JS JL T")],
             [A("B JS LL JL@90 T"), A("B JS JS LL JL T")]]
    table = {("B JS LL JS JL T", n): True for n in ("weld", "pick", "drill")}
    return cands, table


def test_the_family_plan_swaps_when_swaps_are_cheap(cat):
    cands, table = _family(cat)
    jm, calls = _table_judge(cat, table)
    plan = reconfigure(cat, _parts("weld", "pick", "drill"), swap_cost=500, candidates=cands, judge_many=jm,
                       verify=False)
    # every candidate judged for the two parts it is not a candidate of
    assert len(calls) == 12 == plan.verdicts and ("B JS LL JL T", "weld") not in calls
    assert plan.base_text == "B JS LL JL T"
    assert plan.texts == ("B JS LL JL T", "B JS LS JL JL T", "B JS LL JL@90 T")
    assert [len(o) for o in plan.operations] == [0, 2, 1]
    assert plan.operations[2] == ("turn JL to 90°",)
    assert plan.operations[1][0] == "replace link LL by LS" and plan.operations[1][1].startswith("add joint JL after")
    # owned: B, JS, LL, LS, T once and JL twice (the pick configuration) = 200+3000+200+100+500+2·1000
    assert plan.inventory == {"B": 1, "JS": 1, "JL": 2, "LS": 1, "LL": 1, "T": 1}
    assert plan.inventory_cost == 6000 and plan.swaps == 3 and plan.total == 7500
    assert plan.single_text == "B JS LL JS JL T" and plan.single_cost == 7900
    assert plan.comparison() == ("one assembly serves all 3 parts at 7 900 EUR (B JS LL JS JL T, the least among the "
                                 "candidates); the reconfigurable "
                                 "plan costs 6 000 EUR + 3 swaps × 500 EUR = 7 500 EUR, 400 EUR less: one assembly "
                                 "needs JS ×2 where the plan owns 1")
    text = "\n".join(plan.lines())
    assert "pick: 2 swaps: replace link LL by LS; add joint JL after" in text and "exact over 6 candidate" in text
    for e, a in zip(plan.edits, plan.assemblies):
        assert apply_script(plan.base, list(e)) == a
    d = json.loads(json.dumps(plan.to_json()))
    assert d["total"] == 7500 and d["configurations"][2]["operations"] == ["turn JL to 90°"]
    assert d["single"] == {"assembly": "B JS LL JS JL T", "cost": 7900.0} and not d["capped"]


def test_one_assembly_for_all_when_swaps_are_dear(cat):
    cands, table = _family(cat)
    jm, _ = _table_judge(cat, table)
    plan = reconfigure(cat, _parts("weld", "pick", "drill"), swap_cost=1000, candidates=cands, judge_many=jm,
                       verify=False)
    # 6000 + 3 × 1000 > 7900: the single assembly, no swaps
    assert plan.texts == ("B JS LL JS JL T",) * 3 and plan.swaps == 0 and plan.total == 7900
    assert plan.comparison() == ("one assembly serves all 3 parts at 7 900 EUR (the least among the candidates): no "
                                 "swap pays at 1 000 EUR a swap")


def _random_assembly(cat, rng):
    joints, links = ["JS", "JL"], ["LS", "LL", "LE"]
    mods = []
    for _ in range(int(rng.integers(1, 4))):
        mods.append(str(rng.choice(joints)))
        if rng.random() < 0.6:
            mods.append(str(rng.choice(links)))
    if rng.random() < 0.7:
        mods.append("T")
    return Assembly.parse(["B", *(f"{m}@{int(rng.choice([0, 90, 180, 270]))}" for m in mods)], cat)


def _exhaustive(cat, cands, feasible, s):
    pool = {a.text(cat): a for c in cands for a in c}
    best = None
    for b in pool.values():
        for picks in itertools.product(*[[pool[t] for t in f] for f in feasible]):
            owned = Counter()
            for a in (b, *picks):
                for n, c in Counter(a.modules).items():
                    owned[n] = max(owned[n], c)
            total = sum(cat.modules[n].cost * c for n, c in owned.items()) + s * sum(swaps(b, a) for a in picks)
            best = total if best is None else min(best, total)
    return best


def test_plans_equal_the_exhaustive_optimum_over_random_families(cat):
    rng = np.random.default_rng(11)
    for _ in range(30):
        m = int(rng.integers(1, 4))
        names = [f"p{t}" for t in range(m)]
        cands = [[_random_assembly(cat, rng) for _ in range(int(rng.integers(1, 4)))] for _ in range(m)]
        table = {(a.text(cat), n): bool(rng.random() < 0.4) for c in cands for a in c for n in names}
        s = float(rng.choice([0, 100, 700, 3000]))
        jm, _ = _table_judge(cat, table)
        plan = reconfigure(cat, _parts(*names), swap_cost=s, candidates=cands, judge_many=jm, verify=False)
        own = [{a.text(cat) for a in c} for c in cands]
        feasible = [sorted(own[t] | {a.text(cat) for c in cands for a in c if table[(a.text(cat), n)]})
                    for t, n in enumerate(names)]
        assert plan.exact and plan.total == _exhaustive(cat, cands, feasible, s)
        assert all(plan.texts[t] in feasible[t] for t in range(m))
        assert plan.swaps == sum(len(o) for o in plan.operations)
        every = [t for t in {a.text(cat) for c in cands for a in c} if all(t in f for f in feasible)]
        if every:
            assert plan.single_cost == min(Assembly.parse(t, cat).cost(cat) for t in every) >= plan.total


def test_the_pool_cap_is_said(cat):
    rng = np.random.default_rng(5)
    names = [f"p{t}" for t in range(7)]
    cands = [[_random_assembly(cat, rng) for _ in range(12)] for _ in names]
    jm, _ = _table_judge(cat, {})
    plan = reconfigure(cat, _parts(*names), swap_cost=100, k=10, candidates=cands, judge_many=jm, verify=False)
    assert (plan.k, plan.k_asked, plan.capped) == (8, 10, True)
    assert len(plan.pool) <= 56 and "k capped from 10 to 8 (k × parts ≤ 60)" in "\n".join(plan.lines())


def test_a_part_without_candidates_has_no_plan(cat):
    cands, table = _family(cat)
    jm, _ = _table_judge(cat, {})
    plan = reconfigure(cat, _parts("weld", "pick", "drill", "paint"), swap_cost=100, candidates=[*cands, []],
                       judge_many=jm, verify=False)
    assert not plan.found and plan.missing == ("paint",)
    assert plan.lines()[-1] == "  no plan: paint has no feasible assembly among the candidates searched"
    assert plan.to_json()["total"] is None


@pytest.mark.parametrize("kw, msg", [
    ({"swap_cost": -1}, r"swap cost -1 must be a number in \[0, 1e\+12\]"),
    ({"swap_cost": float("nan")}, "swap cost nan must be"),
    ({"swap_cost": "5"}, "swap cost '5' must be"),
    ({"k": 0}, r"k 0 must be an integer in \[1, 50\]"),
    ({"k": 51}, "k 51 must be"),
])
def test_bad_input_is_refused_with_one_line(cat, kw, msg):
    cands, table = _family(cat)
    args = {"swap_cost": 1.0, "k": 5, **kw}
    with pytest.raises(ReconfigurationError, match=msg):
        reconfigure(cat, _parts("weld", "pick", "drill"), candidates=cands, **args)
    with pytest.raises(ReconfigurationError, match="at least one part"):
        reconfigure(cat, [], swap_cost=1.0, candidates=[])


def test_the_single_search_sees_the_space_up_to_the_plans_total(cat):
    from fractions import Fraction

    from design.compose import ComposeSpace, Pruned
    from design.compose.reconfigure import _UpTo
    space = ComposeSpace(cat, joints=(1, 2), tools=["T"], links_per_joint=0)

    def prune(partial):          # every completion of a partial starting with the strong joint set aside
        return ("reach_bound", "test") if partial.modules[1] == "JS" and len(partial.modules) == 2 else None

    def cost(item):
        return item.cost if isinstance(item, Pruned) else item[1]
    every = list(space.ordered(prune))
    assert any(isinstance(x, Pruned) for x in every) and [cost(x) for x in every] == sorted(cost(x) for x in every)
    ceiling = float(cost(every[len(every) // 2]))
    cut = _UpTo(space, ceiling)
    kept = list(cut.ordered(prune))
    assert kept == [x for x in every if cost(x) <= Fraction(ceiling)] and len(kept) < len(every) and cut.stopped
    assert cut.size() == space.size() and cut.catalogue is cat
    whole = _UpTo(space, float(cost(every[-1])))
    assert list(whole.ordered(prune)) == every and not whole.stopped
