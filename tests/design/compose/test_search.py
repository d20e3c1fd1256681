"""The search (design.compose.search): the k cheapest for one part equal the brute-force list's, a
family of parts is judged part by part (the next part only for the assemblies the earlier left
feasible), a budget makes it a stated heuristic whose accounting still covers the space once, and
nothing feasible is said as such."""
from __future__ import annotations

import numpy as np
import pytest

from design.compose import ComposeSettings, ComposeSpace, Part, cheapest, compose, judge
from design.task import Targets, TaskError
from tests.design.compose import compose_helpers as h

SETTINGS = ComposeSettings(reach=h.LIGHT, verify=None, batch=3)
NEAR = [[10, 60, 60], [-60, 90, -45], [120, -70, -30], [-150, 45, 90]]
WHERE = ("dof", "reach_bound", "holding", "evaluated", "not_cheaper", "not_judged")


@pytest.fixture(scope="module")
def cat():
    return h.catalogue()


def _space(cat, links=0):
    return ComposeSpace(cat, joints=(3, 3), tools=[None], links_per_joint=links)


def test_the_k_cheapest_are_the_brute_force_ones(cat):
    targets = h.targets_of(cat, "B Rz Ry Ry", NEAR)
    every = h.every_assembly(cat, (3, 3), 0)
    feasible = sorted(h.order_key(cat, a, c) for a, c in every if h.direct_feasible(cat, a, targets))
    res = cheapest(cat, Part("p", targets), _space(cat), 2, SETTINGS)
    assert [f.text for f in res.found] == [k[2] for k in feasible[:2]]
    assert [f.cost for f in res.found] == [k[0] for k in feasible[:2]]
    assert res.exhaustive and sum(res.counts[k] for k in WHERE) == res.counts["total"] == len(every)
    with pytest.raises(TaskError, match="k must be"):
        cheapest(cat, Part("p", targets), _space(cat), 0)


def test_a_family_is_judged_part_by_part(cat):
    near = Part("near", h.targets_of(cat, "B Rz Ry Ry", NEAR))
    other = Part("other", h.targets_of(cat, "B Rz Ry Ry", [[30, -40, 70], [100, 80, -60]]))
    calls = []

    def judge_many(items):
        calls.append([(a.text(cat), p.name) for a, p in items])
        return [judge(cat, a, p, SETTINGS) for a, p in items]
    res = compose(cat, [near, other], _space(cat), SETTINGS, judge_many=judge_many)
    every = h.every_assembly(cat, (3, 3), 0)
    both = sorted(h.order_key(cat, a, c) for a, c in every
                  if h.direct_feasible(cat, a, near.targets) and h.direct_feasible(cat, a, other.targets))
    assert res.found[0].text == both[0][2] and set(res.verdicts) == {"near", "other"}
    seen_near = {t for c in calls for t, p in c if p == "near"}
    for c in calls:                              # a call judges one part; "other" only after "near" said yes
        assert len({p for _, p in c}) == 1
        for t, p in c:
            if p == "other":
                assert t in seen_near
    with pytest.raises(TaskError, match="two parts are named"):
        compose(cat, [near, near], _space(cat), SETTINGS)


def test_a_budget_makes_a_stated_heuristic(cat):
    # the least cost needs links (4700); with 12 verdicts allowed, 6 are spent in cost order, then
    # every s-th assembly is judged: a feasible one is found, costlier, and said not exhaustive
    targets = h.targets_of(cat, "B Rz Ry L300 Ry L300", [[10, 20, 30], [-60, 45, -20]])
    lines = []
    res = compose(cat, [Part("p", targets)], _space(cat, 1), ComposeSettings(reach=h.LIGHT, verify=None, batch=1),
                  max_judged=12, progress=lines.append)
    c = res.counts
    assert sum(c[k] for k in WHERE) == c["total"] and c["evaluated"] <= 12
    assert len(lines) == res.batches and all(x.startswith("compose: batch ") for x in lines)
    assert "exhaustive" in lines[0] and "1 in " in lines[-1]
    assert h.direct_feasible(cat, res.best, targets)
    assert res.cost > 4700 and not res.exhaustive and c["not_judged"] > 0
    text = "\n".join(res.lines())
    assert f"not exhaustive: {c['not_judged']} assemblies of cost ≤ {res.cost:g} EUR not judged" in text
    assert f"exhaustive below cost {res.frontier:g} EUR" in text and res.frontier < 4700


def test_nothing_feasible_is_said(cat):
    far = Part("far", Targets(np.array([[3.0, 0.0, 0.5]])))
    res = compose(cat, [far], _space(cat, 1), SETTINGS)
    assert not res.found and res.exhaustive and res.counts["reach_bound"] == res.counts["total"]
    assert "no feasible assembly in the space" in "\n".join(res.lines())


def test_the_space_must_fit_the_parts(cat):
    pose = Part("pose", Targets(np.array([[0.2, 0, 0.3]]), orientation="pose", rotations=np.eye(3)[None]))
    roll_free = ComposeSpace(cat, joints=(3, 3), twists="reduced", roll_free=True)
    with pytest.raises(TaskError, match="full poses"):
        compose(cat, [pose], roll_free, SETTINGS)
    with pytest.raises(TaskError, match="another catalogue"):
        compose(h.catalogue(), [pose], _space(cat), SETTINGS)
    with pytest.raises(TaskError, match="budget_s"):
        compose(cat, [pose], _space(cat), SETTINGS, budget_s=0)
