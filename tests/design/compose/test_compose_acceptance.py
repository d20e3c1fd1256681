"""Acceptance of the composition search (issue 32, item 3): on a small catalogue the search finds the
same least-cost assembly as an exhaustive enumeration written here (every assembly listed by
brute force, each judged directly: it must hold itself and the reach study must reach every
target), and every assembly it set aside by a bound is infeasible by that direct judgement — the
part of the space it says is empty is."""
from __future__ import annotations

import pytest

from design.compose import ComposeSettings, ComposeSpace, Part, Pruned, compose
from tests.design.compose import compose_helpers as h


def _run(joints, links_per_joint, answer_text, degrees):
    cat = h.catalogue()
    targets = h.targets_of(cat, answer_text, degrees)
    part = Part("family_member", targets)
    everything = h.every_assembly(cat, joints, links_per_joint)
    direct = {a.text(cat): h.direct_feasible(cat, a, targets) for a, _ in everything}
    feasible = sorted(h.order_key(cat, a, c) for a, c in everything if direct[a.text(cat)])
    assert feasible, "the scenario needs a feasible assembly"

    space = ComposeSpace(cat, joints=joints, tools=[None], links_per_joint=links_per_joint)
    log = []
    res = compose(cat, [part], space, ComposeSettings(reach=h.LIGHT, verify=None, batch=4),
                  trace=lambda what, item: log.append((what, item)))
    # the same least-cost assembly, found exhaustively
    assert res.exhaustive
    assert res.found[0].text == feasible[0][2]
    assert res.cost == pytest.approx(feasible[0][0])
    assert res.verdicts["family_member"].feasible
    # every assembly set aside by a bound is infeasible by the direct judgement
    by_prefix = 0
    for what, item in log:
        if what == "pruned":
            assert isinstance(item, Pruned)
            members = [a for a, _ in everything if a.modules[:len(item.partial.modules)] == item.partial.modules
                       and a.twists[:len(item.partial.twists)] == item.partial.twists]
            assert len(members) == item.count            # the count it reports is the subtree's
            assert not any(direct[a.text(cat)] for a in members), item.reason
            by_prefix += item.count
        elif what == "bound":
            a, stage, reason = item
            assert not direct[a.text(cat)], f"{a.text(cat)}: {stage}: {reason}"
        elif what == "judged":
            a, verdicts = item
            assert verdicts["family_member"].feasible == direct[a.text(cat)]
    # the accounting covers the whole space, once
    c = res.counts
    assert c["total"] == len(everything) == space.size()
    where = ("dof", "reach_bound", "holding", "evaluated", "not_cheaper", "not_judged")
    assert sum(c[k] for k in where) == c["total"]
    assert c["not_judged"] == 0
    proven = [x for x in log if x[0] in ("pruned", "bound")]
    assert sum(x[1].count if x[0] == "pruned" else 1 for x in proven) == c["dof"] + c["reach_bound"] + c["holding"]
    # every assembly cheaper than the answer (in the stated order) was judged or set aside
    seen = {x[1][0].text(cat) for x in log if x[0] in ("bound", "judged")}
    for a, cost in everything:
        if h.order_key(cat, a, cost) < feasible[0] and a.text(cat) not in seen:
            assert any(x[0] == "pruned" and a.modules[:len(x[1].partial.modules)] == x[1].partial.modules
                       for x in log), a.text(cat)
    return res, by_prefix


@pytest.mark.parametrize("degrees, bounds", [
    # near targets: the chain of coaxial joints keeps its tool point on one circle (dof)
    ([[10, 60, 60], [-60, 90, -45], [120, -70, -30], [-150, 45, 90]], ("holding", "dof")),
    # one target 272 mm from the waist: every chain with the short Rz2 reaches at most 270 mm (reach bound)
    ([[-60, 45, -20], [10, 60, 60], [120, -70, -30], [-150, 45, 90]], ("holding", "reach_bound")),
])
def test_least_cost_equals_the_exhaustive_enumeration_small(degrees, bounds):
    # 9 assemblies (no links): the weak elbow Rw, cheaper than Ry and of the same shape, serves as the
    # last joint (it holds only itself) but not as the second
    res, _ = _run((3, 3), 0, "B Rz Ry Ry", degrees)
    assert res.found[0].text == "B Rz Ry Rw"
    for b in bounds:
        assert res.counts[b] > 0, b


def test_least_cost_equals_the_exhaustive_enumeration_with_links():
    # 72 assemblies (slow: tests/conftest.py): partial assemblies are pruned whole by the reach bound
    res, by_prefix = _run((3, 3), 1, "B Rz Ry L300 Ry L300",
                          [[10, 20, 30], [-60, 45, -20], [120, 60, 10], [-150, 10, 80]])
    assert by_prefix > 0
    assert res.counts["holding"] > 0 and res.counts["dof"] > 0 and res.counts["evaluated"] > 1
