"""The proven bounds (design.compose.bounds) never rule out what a configuration reaches: the tool
pose of random configurations within the limits (frames by kin.modules.module_frames) offered as a
target is never declared infeasible, the tool point's distance from the first axis point stays
within the reach bounds, a partial assembly's bound covers every completion — and the bounds do
rule out what they should (a target off the one circle a coaxial chain can reach, a tilted axis)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from design.compose import ComposeSpace, Part, PartGeometry, dof_bound, holding_bound, module_extent, reach_bound
from design.compose.bounds import ANGLE_MARGIN, partial_reach_bound, sketch
from design.task import Targets
from kin.modules import Assembly, assemble, load_catalogue, loads_catalogue, module_frames
from tests.design.compose import compose_helpers as h
from tests.design.compose.test_space import TWISTY

PRISMATIC = """
[[modules]]
name = "P"            # a slide along its input z, 0 to 200 mm out
kind = "joint"
cost = 200
input = "F"
output = "F"
type = "prismatic"
axis = { xyz = [0, 0, 30] }
out = { xyz = [0, 0, 20] }
limits = [0, 200]
max_velocity = 100
max_torque = 500

[[modules]]
name = "Px"           # a slide across its input z, -100 to 50 mm
kind = "joint"
cost = 210
input = "F"
output = "F"
type = "prismatic"
axis = { xyz = [20, 0, 30], rpy = [0, 90, 0] }
out = { xyz = [0, 0, 0], rpy = [0, -90, 0] }
limits = [-100, 50]
max_velocity = 100
max_torque = 500
"""


@pytest.fixture(scope="module")
def cat():
    return loads_catalogue(TWISTY + PRISMATIC, "bounds.toml")


def _random_q(cat, a, rng, k):
    lims = np.array([cat.modules[n].limits for n in a.joints(cat)])
    return lims[:, 0] + rng.random((k, len(lims))) * (lims[:, 1] - lims[:, 0])


def _sample(cat, rng, joints, links, count):
    """``count`` random assemblies: random modules whose connectors meet, at random allowed twists."""
    def pick(prev, kinds):
        opts = [m for m in cat.modules.values() if m.kind in kinds and cat.meets(prev.output, m.input)]
        if not opts:
            return None
        m = opts[rng.integers(len(opts))]
        tw = cat.twists(prev.output, m.input)
        return m, tw[rng.integers(len(tw))]

    out = []
    while len(out) < count:
        mods = [cat.of_kind("base")[rng.integers(len(cat.of_kind("base")))]]
        twists = []
        for _ in range(rng.integers(joints[0], joints[1] + 1)):
            for kinds in [("joint",)] + [("link",)] * int(rng.integers(0, links + 1)):
                got = pick(mods[-1], kinds)
                if got:
                    mods.append(got[0])
                    twists.append(got[1])
        if rng.random() < 0.5 and (got := pick(mods[-1], ("tool",))):
            mods.append(got[0])
            twists.append(got[1])
        a = Assembly(tuple(m.name for m in mods), tuple(twists))
        if a.joints(cat):
            a.check(cat)
            out.append(a)
    return out


def _pose_part(T: np.ndarray, orientation: str) -> Part:
    P, R = T[None, :3, 3], T[None, :3, :3]
    if orientation == "pose":
        t = Targets(P, orientation="pose", rotations=R, tolerance=1e-6)
    elif orientation == "axis":
        t = Targets(P, orientation="axis", axes=R[:, :, 2], tolerance=1e-6)
    else:
        t = Targets(P, tolerance=1e-6)
    return Part("reached", t)


def test_module_extent_bounds_every_motion(cat):
    rng = np.random.default_rng(0)
    for m in cat.modules.values():
        if m.kind == "base":
            continue
        if m.kind != "joint":
            assert module_extent(m) == pytest.approx(np.linalg.norm(m.out[:3, 3]))
            continue
        for q in m.limits[0] + rng.random(200) * (m.limits[1] - m.limits[0]):
            M = np.eye(4)
            if m.type == "revolute":
                M[:2, :2] = [[math.cos(q), -math.sin(q)], [math.sin(q), math.cos(q)]]
            else:
                M[2, 3] = q
            assert np.linalg.norm((m.axis @ M @ m.out)[:3, 3]) <= module_extent(m) + 1e-12


@pytest.mark.parametrize("orientation", ["free", "axis", "pose"])
def test_what_a_configuration_reaches_is_never_ruled_out(cat, orientation):
    rng = np.random.default_rng(1)
    for a in _sample(cat, rng, (1, 3), 1, 60):
        sk = sketch(cat, a.modules, a.twists)
        for q in _random_q(cat, a, rng, 4):
            tip = module_frames(cat, a, q)[-1][1]
            g = PartGeometry.of(_pose_part(tip, orientation))
            assert dof_bound(sk, g) is None, a.text(cat)
            assert reach_bound(sk, g) is None, a.text(cat)


def test_tool_point_distance_stays_within_the_reach_bounds(cat):
    rng = np.random.default_rng(2)
    for a in _sample(cat, rng, (1, 3), 1, 80):
        sk = sketch(cat, a.modules, a.twists)
        lo, hi = sk.segments()
        U, inner = hi.sum(), max(0.0, float(np.max(lo - (hi.sum() - hi))))
        for q in _random_q(cat, a, rng, 20):
            frames = module_frames(cat, a, q)
            d = np.linalg.norm(frames[-1][1][:3, 3] - sk.points[0])
            assert inner - 1e-12 <= d <= U + 1e-12, a.text(cat)


def test_a_partial_bound_covers_every_completion(cat):
    rng = np.random.default_rng(3)
    sp = ComposeSpace(cat, joints=(1, 2), links_per_joint=1, tools=("T", None))
    prefixes = {(a.modules[:n], a.twists[:n - 1]) for a in _sample(cat, rng, (1, 2), 1, 40) for n in (2, 3)
                if len(a.modules) > n}
    for mods, tws in sorted(prefixes)[::8]:
        n = len(mods)

        def inside(p, mods=mods, tws=tws, n=n):      # keep only this prefix's subtree
            m = min(n, len(p.modules))
            return None if (p.modules[:m], p.twists[:m - 1]) == (mods[:m], tws[:m - 1]) else ("x", "")
        members = [it[0] for it in sp.ordered(prune=inside) if isinstance(it, tuple)
                   and (it[0].modules[:n], it[0].twists[:n - 1]) == (mods, tws) and len(it[0].modules) > n]
        last = cat.modules[mods[-1]]
        k = sum(cat.modules[x].kind == "joint" for x in mods)
        rem = sp.max_remaining((last.output, k, 0 if last.kind == "joint" else 1), module_extent)
        sk = sketch(cat, mods, tws)
        U = sk.segments()[1].sum() + rem
        for a in members[::7]:
            for q in _random_q(cat, a, rng, 2):
                d = np.linalg.norm(module_frames(cat, a, q)[-1][1][:3, 3] - sk.points[0])
                assert d <= U + 1e-12, a.text(cat)
        # a target just beyond is ruled out, one just inside is not
        g_out = PartGeometry("p", sk.points[0][None] + [[U + 2e-6, 0, 0]], None, None, 0.0, 1e-6)
        g_in = PartGeometry("p", sk.points[0][None] + [[U - 2e-6, 0, 0]], None, None, 0.0, 1e-6)
        assert partial_reach_bound(sk, g_out, rem) and partial_reach_bound(sk, g_in, rem) is None


def test_a_coaxial_chain_reaches_one_circle_only(cat):
    a = Assembly.parse("B J S J@90 T", cat)          # both axes one vertical line; the tool on it
    sk = sketch(cat, a.modules, a.twists)
    tip = module_frames(cat, a, [0.3, -1.0])[-1][1]
    ok = Part("ok", Targets(tip[None, :3, 3], tolerance=1e-6))
    assert dof_bound(sk, PartGeometry.of(ok)) is None
    higher = Part("up", Targets(tip[None, :3, 3] + [0, 0, 1e-3], tolerance=1e-6))
    assert "height" in dof_bound(sk, PartGeometry.of(higher))
    aside = Part("aside", Targets(tip[None, :3, 3] + [1e-3, 0, 0], tolerance=1e-6))
    assert "one line" in dof_bound(sk, PartGeometry.of(aside))
    # the tool axis stays vertical: a tilted axis is out, a cone wide enough is not
    tilt = math.radians(10)
    axis = np.array([[math.sin(tilt), 0.0, math.cos(tilt)]])
    tilted = Part("tilted", Targets(tip[None, :3, 3], orientation="axis", axes=axis, tolerance=1e-6))
    assert "axis" in dof_bound(sk, PartGeometry.of(tilted))
    cone = Part("cone", Targets(tip[None, :3, 3], orientation="cone", axes=axis,
                                cone_half_angle=tilt + 2 * ANGLE_MARGIN, tolerance=1e-6))
    assert dof_bound(sk, PartGeometry.of(cone)) is None


def test_a_vertical_slide_lets_the_height_change_within_its_travel(cat):
    a = Assembly.parse("B J P S T", cat)
    sk = sketch(cat, a.modules, a.twists)
    tip0 = module_frames(cat, a, [0.0, 0.0])[-1][1][:3, 3]
    for dz, out in ((0.1999, False), (0.2001, True), (-1e-4, True)):
        g = PartGeometry.of(Part("p", Targets(tip0[None] + [0, 0, dz], tolerance=1e-6)))
        assert (dof_bound(sk, g) is not None) == out, dz


def test_the_placement_of_a_cell_is_undone():
    from planning.cell import load_cell
    from studies.cli.common import CELL_DIR
    cell = load_cell(CELL_DIR / "fanuc_weld_cell.toml")
    P = np.array([[0.5, 0.2, 1.0]])
    g = PartGeometry.of(Part("c", Targets(P), cell=cell))
    assert np.allclose(g.positions, (P - np.asarray(cell.base)[:3, 3]) @ np.asarray(cell.base)[:3, :3])


def test_holding_bound_names_the_joint_that_cannot_hold():
    cat = h.catalogue()
    weak = assemble(cat, Assembly.parse("B Rz Rw Ry", cat), check_holding=False)
    assert "joint 2" in holding_bound(weak) and "cannot hold" in holding_bound(weak)
    assert holding_bound(assemble(cat, Assembly.parse("B Rz Ry Rw", cat))) is None


def test_the_bundled_catalogue_keeps_the_bounds_sound():
    cat = load_catalogue("dynamixel_y")
    rng = np.random.default_rng(5)
    for a in _sample(cat, rng, (2, 3), 1, 40):
        sk = sketch(cat, a.modules, a.twists)
        for q in _random_q(cat, a, rng, 3):
            g = PartGeometry.of(_pose_part(module_frames(cat, a, q)[-1][1], "axis"))
            assert dof_bound(sk, g) is None and reach_bound(sk, g) is None, a.text(cat)
