"""The space of assemblies (design.compose.space): its exact size against a brute-force listing, its
cost order, and the twist reduction — every assembly of the full space is the same machine as one
assembly of the reduced space (frames re-computed by kin.modules.module_frames), and the reduced
space holds exactly one assembly per such class."""
from __future__ import annotations

import math

import numpy as np
import pytest

from design.compose import ComposeSpace, Part
from design.compose.space import axisymmetric, full_turn_coaxial
from design.task import Targets
from kin.modules import Assembly, loads_catalogue, module_frames
from tests.design.compose import compose_helpers as h

TWISTY = """
name = "twisty"
length_unit = "mm"
angle_unit = "deg"
[connectors.F]
twists = [0, 90, 180, 270]
[connectors.G]
twists = [0, 180]

[[modules]]
name = "B"
kind = "base"
cost = 10
output = "F"
out = { xyz = [0, 0, 100] }

[[modules]]
name = "J"            # full-turn coaxial joint: reducible when no part has a cycle
kind = "joint"
cost = 100
input = "F"
output = "F"
type = "revolute"
axis = { xyz = [0, 0, 40], rpy = [0, 0, 30] }
out = { xyz = [0, 0, 40] }
limits = [-180, 180]
max_velocity = 90
max_torque = 50
[modules.inertial]
mass = 1
com = [0, 0, 20]
[[modules.capsule]]
a = [0, 0, 0]
b = [0, 0, 40]
radius = 30

[[modules]]
name = "Jh"           # coaxial, but less than a full turn: never reducible
kind = "joint"
cost = 90
input = "F"
output = "F"
type = "revolute"
axis = { xyz = [0, 0, 40] }
out = { xyz = [0, 0, 40] }
limits = [-170, 170]
max_velocity = 90
max_torque = 50

[[modules]]
name = "K"            # elbow
kind = "joint"
cost = 120
input = "F"
output = "F"
type = "revolute"
axis = { xyz = [0, 0, 50], rpy = [-90, 0, 0] }
out = { xyz = [0, -50, 0], rpy = [90, 0, 0] }
limits = [-120, 120]
max_velocity = 90
max_torque = 50

[[modules]]
name = "KG"           # elbow entered through a G connector
kind = "joint"
cost = 130
input = "G"
output = "F"
type = "revolute"
axis = { xyz = [0, 0, 50], rpy = [-90, 0, 0] }
out = { xyz = [0, -50, 0], rpy = [90, 0, 0] }
limits = [-120, 120]
max_velocity = 90
max_torque = 50

[[modules]]
name = "S"            # straight, symmetric: reducible
kind = "link"
cost = 20
input = "F"
output = "F"
length = 200
[modules.inertial]
mass = 0.5
[[modules.capsule]]
a = [0, 0, 0]
b = [0, 0, 200]
radius = 20

[[modules]]
name = "SG"           # straight, but what follows it meets at 0 and 180 only: not reducible
kind = "link"
cost = 15
input = "F"
output = "G"
length = 150

[[modules]]
name = "E"            # bent: never reducible
kind = "link"
cost = 25
input = "F"
output = "F"
length = 100
offset = 50
bend = 90

[[modules]]
name = "T"
kind = "tool"
cost = 30
input = "F"
out = { xyz = [0, 0, 80] }

[[modules]]
name = "TG"
kind = "tool"
cost = 35
input = "G"
out = { xyz = [0, 0, 60], rpy = [0, 0, 45] }
"""


@pytest.fixture(scope="module")
def cat():
    return loads_catalogue(TWISTY, "twisty.toml")


@pytest.mark.parametrize("joints, links, tools", [((1, 1), 1, None), ((2, 2), 0, ("T",)), ((1, 1), 2, (None,)),
                                                   ((1, 2), 0, ("TG", None))])
def test_size_is_the_brute_force_count(cat, joints, links, tools):
    tl = [*(m.name for m in cat.of_kind("tool")), None] if tools is None else list(tools)
    every = h.every_assembly(cat, joints, links, tools=tl)
    sp = ComposeSpace(cat, joints=joints, tools=tools, links_per_joint=links)
    assert sp.size() == sp.size_all() == len(every)
    listed = [a for a, _ in sp.ordered()]
    assert {a.text(cat) for a in listed} == {a.text(cat) for a, _ in every}
    assert len(listed) == len(every)
    keys = [h.order_key(cat, a, a.cost(cat)) for a in listed]
    assert keys == sorted(keys)                  # cost, then joints, then text
    raw, ok = sp.sequences()
    assert ok == len({a.modules for a, _ in every})
    n_j, n_l = len(cat.of_kind("joint")), len(cat.of_kind("link"))
    seg = n_j * sum(n_l ** i for i in range(links + 1))
    assert raw == sum(seg ** n for n in range(joints[0], joints[1] + 1)) * len(tl)


def test_symmetry_of_the_modules(cat):
    m = cat.modules
    assert [n for n in m if axisymmetric(m[n])] == ["S", "SG", "T", "TG"]
    assert [n for n in m if full_turn_coaxial(m[n])] == ["J"]


def _canonical(cat, a: Assembly, roll_free: bool, cycle_free: bool):
    """The representative of ``a`` by the rule of the module text, written out here: a reducible link
    or tool takes its first allowed twist and hands the rest on; a full-turn coaxial joint takes its
    first and shifts its joint value.  (modules, twists), joint shifts, leftover tool roll.  The space
    here has chains without a tool, where a link may be last: links are reduced only with roll_free."""
    reducible_links = {"S"} if roll_free else set()     # SG's successors meet at 0/180 only; E is bent
    mods = [cat.modules[n] for n in a.modules]
    twists, shifts, carry = [], [], 0.0
    for i, m in enumerate(mods[1:], 1):
        allowed = cat.twists(mods[i - 1].output, m.input)
        t = (a.twists[i - 1] + carry) % (2 * math.pi)
        assert any(abs((t - u + math.pi) % (2 * math.pi) - math.pi) < 1e-9 for u in allowed)
        carry = 0.0
        last = i == len(mods) - 1
        if m.name == "J" and cycle_free:
            twists.append(allowed[0])
            shifts.append(t - allowed[0])
            continue
        if m.kind == "joint":
            shifts.append(0.0)
        if m.name in reducible_links or (m.kind == "tool" and roll_free):
            twists.append(allowed[0])
            carry = t - allowed[0]
        else:
            twists.append(t)
        if last:
            break
    return Assembly(a.modules, tuple(twists)), np.array(shifts), carry


def _same_up_to_z(A, B) -> bool:
    return np.allclose(A[:3, 3], B[:3, 3], atol=1e-12) and np.allclose(A[:3, 2], B[:3, 2], atol=1e-12)


@pytest.mark.parametrize("roll_free, cycle_free", [(True, True), (True, False), (False, True)])
def test_reduced_space_holds_one_machine_per_class(cat, roll_free, cycle_free):
    rng = np.random.default_rng(4)
    full = ComposeSpace(cat, joints=(1, 1), links_per_joint=2)
    red = ComposeSpace(cat, joints=(1, 1), links_per_joint=2, twists="reduced", roll_free=roll_free,
                       cycle_free=cycle_free)
    reduced = {a.text(cat) for a in red}
    assert len(reduced) == red.size() <= full.size()
    assert (red.size() < full.size()) == (roll_free or cycle_free)
    reps = set()
    for i, a in enumerate(full):
        r, shift, roll = _canonical(cat, a, roll_free, cycle_free)
        reps.add(r.text(cat))
        assert r.text(cat) in reduced, a.text(cat)
        if i % 5:                  # the frames of every fifth pair (each class is met many times)
            continue
        n = len(a.joints(cat))
        for q in rng.uniform(-2.0, 2.0, size=(1, n)):
            fa, fr = module_frames(cat, a, q), module_frames(cat, r, q + shift)
            for (ia, oa), (ir, or_) in zip(fa, fr):
                assert _same_up_to_z(ia, ir)            # inputs on the same axis (turned about it at most)
                assert _same_up_to_z(oa, or_)
            tip_a, tip_r = fa[-1][1], fr[-1][1]
            if abs(math.remainder(roll, 2 * math.pi)) < 1e-12:
                assert np.allclose(tip_a, tip_r, atol=1e-12)
            else:                                        # the tool frame turned about its own z
                assert roll_free
    assert reps == reduced                               # one representative per class, and only those


def test_a_straight_link_hands_its_twist_to_the_next_joint(cat):
    red = ComposeSpace(cat, joints=(2, 2), links_per_joint=1, tools=("T",), twists="reduced", roll_free=True)
    texts = {a.text(cat) for a in red}
    a, r = Assembly.parse("B K S@90 K@180 T@90", cat), Assembly.parse("B K S K@270 T", cat)
    assert r.text(cat) in texts and a.text(cat) not in texts
    for q in np.random.default_rng(1).uniform(-2, 2, size=(5, 2)):
        fa, fr = module_frames(cat, a, q), module_frames(cat, r, q)
        assert np.allclose(fa[3][0], fr[3][0], atol=1e-12)     # the second elbow's input: the same frame
        assert _same_up_to_z(fa[-1][1], fr[-1][1])             # the tool point and axis: the same


def test_for_parts_reduces_what_the_parts_allow(cat):
    free = Part("free", Targets(np.array([[0.3, 0.0, 0.3]])))
    rot = np.eye(3)[None]
    pose = Part("pose", Targets(np.array([[0.3, 0.0, 0.3]]), orientation="pose", rotations=rot))
    a = ComposeSpace.for_parts(cat, [free], joints=(1, 2))
    b = ComposeSpace.for_parts(cat, [free, pose], joints=(1, 2))
    assert a.roll_free and a.cycle_free and not b.roll_free
    assert a.size() < b.size() < ComposeSpace(cat, joints=(1, 2)).size()


@pytest.mark.parametrize("kw, match", [({"joints": (0, 3)}, "joints"), ({"joints": (4, 3)}, "joints"),
                                       ({"joints": (1, 9)}, "joints"), ({"links_per_joint": 5}, "links_per_joint"),
                                       ({"links_per_joint": True}, "links_per_joint"),
                                       ({"twists": "some"}, "twists"), ({"bases": ["J"]}, "not a base"),
                                       ({"tools": ["nope"]}, "not a tool"), ({"bases": []}, "no base")])
def test_bad_space_arguments_are_refused(cat, kw, match):
    with pytest.raises(ValueError, match=match):
        ComposeSpace(cat, **kw)


def test_completion_counts_and_bounds_of_partial_states(cat):
    sp = ComposeSpace(cat, joints=(1, 2), links_per_joint=1, tools=("T", None))
    every = h.every_assembly(cat, (1, 2), 1, tools=("T", None))
    prefix = ("B", "K")
    members = [a for a, _ in every if a.modules[:2] == prefix and a.twists[:1] == (math.pi / 2,)]
    state = ("F", 1, 0)
    assert sp.count_from(state) == len(members)
    # the cheapest completion of the prefix (cost and joints) is the best of the members
    best = sp._best(state)
    cheapest = min((a.cost(cat), len(a.joints(cat))) for a in members)
    assert (float(cat.modules["B"].cost + cat.modules["K"].cost + best[0]), best[1]) == cheapest
    # the most the completions add to the reach is the members' largest sum of module extents
    from design.compose import module_extent
    added = max(sum(module_extent(cat.modules[n]) for n in a.modules[2:]) for a in members)
    assert sp.max_remaining(state, module_extent) == pytest.approx(added)
