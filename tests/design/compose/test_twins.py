"""Kinematic twins share one reach study: assemblies whose modules have, module for module, the same
frames, travel and capsules (here the DYNAMIXEL-Y R051 and R099 gear ratios of one housing) get the
same reach verdict as a fresh judgement of their own, which the cache then gives without one; modules
of another geometry never share it, and holding is still judged for each."""
from __future__ import annotations

import numpy as np

import design.compose.verdict as verdict
from design.compose import judge, load_part
from design.compose.verdict import twin_key
from kin import Robot
from kin.modules import Assembly, assemble, load_catalogue
from studies.cli.compose import PARTS_DIR

CAT = load_catalogue("dynamixel_y")
PART = load_part(PARTS_DIR / "pick_demo.toml")
REACHES = "BASE Y80-51 R80-70 Y70-51 F200 Y70-51 E70 GRIP"          # the part's least-cost answer (docs/modules.md)
MISSES = "BASE Y80-51 R80-70 Y70-51 F200 Y70-51 F200 GRIP"         # passes the bounds, fails the reach study


def _fresh(a: Assembly):
    verdict._TWINS.clear()
    return judge(CAT, a, PART)


def test_twins_have_one_key_and_one_robot_geometry():
    a, b = (Assembly.parse(t, CAT) for t in (REACHES, REACHES.replace("Y70-51", "Y70-99")))
    assert twin_key(CAT, a) == twin_key(CAT, b)
    assert twin_key(CAT, a) != twin_key(CAT, Assembly.parse(REACHES.replace("F200", "E70"), CAT))
    assert twin_key(CAT, a) != twin_key(CAT, Assembly.parse(REACHES.replace("Y80-51", "Y80-99B"), CAT))  # longer
    ra, rb = (Robot(assemble(CAT, x, check_holding=False)) for x in (a, b))
    Q = np.random.default_rng(3).uniform(ra.chain.lower, ra.chain.upper, (20, ra.n))
    assert np.abs(ra.fk(Q) - rb.fk(Q)).max() < 1e-12                   # what the reach study sees is the same
    assert [j.max_torque for j in ra.chain.joints] != [j.max_torque for j in rb.chain.joints]


def test_a_twin_gets_the_verdict_its_own_reach_study_gives():
    for text in (REACHES, MISSES):
        a, twin = Assembly.parse(text, CAT), Assembly.parse(text.replace("Y70-51", "Y70-99"), CAT)
        own = _fresh(twin)                                  # the twin judged alone, empty cache
        _fresh(a)                                           # the cache now holds a's reach study
        shared = judge(CAT, twin, PART)
        assert own.stage == ("ok" if text == REACHES else "reach")
        assert (shared.feasible, shared.stage, shared.reached) == (own.feasible, own.stage, own.reached)
        assert ("kinematic twin" in shared.reason) == (not own.feasible)
    verdict._TWINS.clear()
