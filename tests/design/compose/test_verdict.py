"""The verdict of one assembly for one part (design.compose.verdict): its stages in order, the cycle
timed on the assembled robot with the modules' own masses (the peak torque is at least the gravity
torque at the stops, computed here by kin's gravity of the assembled chain; a payload adds to it),
and the verification study."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from design.compose import ComposeSettings, Part, PartCycle, judge, verify
from kin.modules import Assembly, assemble
from tests.design.compose import compose_helpers as h

ARM = "B Rz Ry L300 Ry L300"
SETTINGS = ComposeSettings(reach=h.LIGHT, verify=None)


@pytest.fixture(scope="module")
def cat():
    return h.catalogue()


@pytest.fixture(scope="module")
def targets(cat):
    return h.targets_of(cat, ARM, [[10, 20, 30], [-60, 45, -20]])


def _cycle(**kw) -> Part:
    base = dict(sequence=(0, 1), angle_scale=math.pi / 180, length_scale=1e-3)
    base.update(kw)
    return PartCycle(**base)


def test_stages_in_order(cat, targets):
    part = Part("p", targets)
    bad_twist = Assembly(("B", "Rz", "Ry"), (0.0, 0.5))
    assert judge(cat, bad_twist, part, SETTINGS).stage == "incompatible"
    assert judge(cat, Assembly.parse("B Rz Rz2 Rz2", cat), part, SETTINGS).stage == "dof"
    assert judge(cat, Assembly.parse("B Rz Ry Ry", cat), part, SETTINGS).stage == "reach_bound"
    assert judge(cat, Assembly.parse("B Rz Rw L300 Ry L300", cat), part, SETTINGS).stage == "holding"
    v = judge(cat, Assembly.parse("B Rz L300 Ry L300 Rz2", cat), part, SETTINGS)
    assert v.stage == "reach" and not v.feasible and "not tried" in v.reason
    ok = judge(cat, Assembly.parse(ARM, cat), part, SETTINGS)
    assert ok.feasible and ok.stage == "ok" and ok.reached == ok.targets == 2 and ok.cycle_time is None
    assert ok.assembly == ARM and ok.part == "p"


def test_the_cycle_uses_the_modules_masses(cat, targets):
    from design.cycle import evaluate_cycle
    a = Assembly.parse(ARM, cat)
    part = Part("p", targets, cycle=_cycle())
    v = judge(cat, a, part, SETTINGS)
    assert v.feasible and v.cycle_time > 0 and 0 < v.torque_ratio < 1
    chain = assemble(cat, a)
    robot = kin.Robot(chain, backend="vm")
    res = evaluate_cycle(robot, part.cycle.spec(chain), targets)
    assert v.cycle_time == pytest.approx(res.cycle_time) and v.torque_ratio == pytest.approx(res.torque_ratio)
    # the cycle rests at its stops: its peak torques are at least the assembled chain's gravity there
    for q in res.q:
        assert np.all(res.peak_torque >= np.abs(np.asarray(robot.gravity(q))).ravel() * (1 - 1e-6) - 1e-9)
    assert res.peak_torque.max() > 1.0                 # the modules' masses, not a massless chain
    heavy = judge(cat, a, Part("p", targets, cycle=_cycle(payload=3.0)), SETTINGS)
    assert heavy.torque_ratio > v.torque_ratio


def test_cycle_time_and_torque_limits(cat, targets):
    a = Assembly.parse(ARM, cat)
    v = judge(cat, a, Part("p", targets, cycle=_cycle()), SETTINGS)
    slow = judge(cat, a, Part("p", targets, cycle=_cycle(), max_cycle_time=0.5 * v.cycle_time), SETTINGS)
    assert slow.stage == "cycle" and "max_cycle_time" in slow.reason and not slow.feasible
    fast = judge(cat, a, Part("p", targets, cycle=_cycle(), max_cycle_time=2 * v.cycle_time), SETTINGS)
    assert fast.feasible and fast.cycle_time == pytest.approx(v.cycle_time)
    weak = judge(cat, a, Part("p", targets, cycle=_cycle(tau_max=0.01)), SETTINGS)
    assert weak.stage == "cycle" and weak.torque_ratio > 1 and "torque ratio" in weak.reason
    quick = judge(cat, a, Part("p", targets, cycle=_cycle(v_max=360.0, a_max=2000.0)), SETTINGS)
    assert quick.cycle_time < v.cycle_time                  # the part's own limits, above the ratings


def test_verify_explains_with_another_start_set(cat, targets):
    from design.reach import ReachSettings
    st = verify(cat, Assembly.parse(ARM, cat), Part("p", targets), ReachSettings(starts=6, samples=2048))
    assert st.reached.all() and st.settings.starts == 6
    miss = verify(cat, Assembly.parse("B Rz L300 Ry L300 Rz2", cat), Part("p", targets),
                  ReachSettings(starts=6, samples=2048))
    assert not miss.reached.all() and set(miss.reason_counts()) - {"reached"}


def test_windows_of_each_assembly_keep_solutions_out(cat):
    # the arm stretched out (elbow straight): reached only at its elbow singularity
    stretched = h.targets_of(cat, ARM, [[0, 40, 0]])
    a = Assembly.parse(ARM, cat)
    assert judge(cat, a, Part("p", stretched), SETTINGS).feasible
    v = judge(cat, a, Part("p", stretched, windows=("sigma_min", 0.04)), SETTINGS)
    assert v.stage == "reach" and "inside a singular window" in v.reason
