"""One assembly built in rmtkit (kin.modules.assemble → kin.Robot) and in timor-python (TUM) from the same
modules: the TCP pose, the joint axes and the inverse dynamics with gravity agree at random states.

timor runs in its own interpreter (tests/kin/modules/timor_ref.py: ``make timor-venv`` or
``RMT_TIMOR_PYTHON``); without one the test is skipped, saying how to get it.

The two tools build the robot differently: rmtkit extracts standard DH rows from the joint axes and
lumps every module's parts into one inertia per DH body (the tool as the payload); timor keeps every
module body as a pinocchio body at its connector-to-connector placement.  Only the modules' numbers are
shared; the mating convention is mapped in timor_ref.py (rmtkit: next input = previous output · Rz(twist),
both z axes distal; timor: connectors face each other, child connector = parent connector · Rx(π), so the
input connector sits at Rx(π)·Rz(twist) in its body).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import kin
from kin.modules import Assembly, assemble, loads_catalogue, module_frames
from tests.dh_numpy import frames_numpy
from tests.kin.modules.timor_ref import TimorUnavailableError, timor_python, timor_reference

# A catalogue in m and degrees with what makes a mapping go wrong if it is wrong: a tilted base (gravity
# is not along frame 0's z), joint axes off their faces' z (an elbow module), a prismatic module, a link
# with offset and bend, twists other than 0, parts with off-centre coms and products of inertia on both
# sides of every joint, a tool with a mass (rmtkit's payload).  Inertias are kg·m² about the com.
CATALOGUE = """
name = "timor_check"
source = "made-up modules for the timor-python comparison test"
length_unit = "m"
angle_unit = "deg"

[connectors.F63]
twists = [0, 90, 180, 270]
[connectors.F63_tool]
like = "F63"

[[modules]]
name = "wall"
kind = "base"
cost = 100
output = "F63"
out = { xyz = [0.12, -0.04, 0.65], rpy = [15, -10, 30] }
[modules.inertial]
mass = 6.0
com = [0, 0, 0.3]

[[modules]]
name = "R63"
kind = "joint"
cost = 2000
input = "F63"
output = "F63"
type = "revolute"
axis = { xyz = [0, 0, 0.055], rpy = [0, 0, 0] }
out = { xyz = [0, 0.012, 0.048], rpy = [4, 0, 0] }
limits = [-170, 170]
max_velocity = 180
max_torque = 5000
[modules.inertial]
mass = 1.6
com = [0.003, -0.002, 0.03]
inertia = [0.0021, 0.0023, 0.0012, 0.00004, -0.000025, 0.00006]
[modules.distal_inertial]
mass = 0.9
com = [0, 0.008, 0.02]
inertia = [0.0009, 0.0011, 0.0006, -0.00003, 0.000015, 0.00002]

[[modules]]
name = "E63"
kind = "joint"
cost = 2400
input = "F63"
output = "F63"
type = "revolute"
axis = { xyz = [0, 0, 0.07], rpy = [90, 0, 0] }
out = { xyz = [0, 0.065, 0], rpy = [-90, 0, 0] }
limits = [-120, 120]
max_velocity = 150
max_torque = 5000
[modules.inertial]
mass = 2.1
com = [0, 0, 0.045]
inertia = [0.003, 0.0028, 0.0015, 0, 0.00008, -0.00004]
[modules.distal_inertial]
mass = 1.1
com = [0.005, 0.03, 0]
inertia = [0.0014, 0.0009, 0.0013, 0.00005, 0, 0.000035]

[[modules]]
name = "P63"
kind = "joint"
cost = 3000
input = "F63"
output = "F63"
type = "prismatic"
axis = { xyz = [0.01, 0, 0.06], rpy = [0, 0, 20] }
out = { xyz = [0, 0, 0.035], rpy = [0, 0, -20] }
limits = [0, 0.25]
max_velocity = 0.5
max_torque = 20000
[modules.inertial]
mass = 3.0
com = [0, 0, 0.08]
inertia = [0.009, 0.0095, 0.0025, 0.0001, -0.00006, 0.00003]
[modules.distal_inertial]
mass = 1.4
com = [0, -0.004, 0.12]
inertia = [0.007, 0.0071, 0.0008, 0.00002, 0.00001, -0.00005]

[[modules]]
name = "L300"
kind = "link"
cost = 400
input = "F63"
output = "F63"
length = 0.3
offset = 0.04
bend = 30
[modules.inertial]
mass = 1.8
com = [0.02, 0.003, 0.15]
inertia = [0.014, 0.0145, 0.0009, 0.00006, 0.0004, -0.00002]

[[modules]]
name = "gripper"
kind = "tool"
cost = 900
input = "F63_tool"
out = { xyz = [0, 0.015, 0.14], rpy = [0, 0, 45] }
[modules.inertial]
mass = 1.2
com = [0, 0.006, 0.06]
inertia = [0.0018, 0.0017, 0.0007, 0.00001, 0, 0.000025]
"""

ASSEMBLY = ["wall", "R63", "L300@90", "E63@180", "P63@270", "L300", "R63@90", "gripper@180"]


def _matrix(part) -> list[list[float]]:
    ixx, iyy, izz, ixy, ixz, iyz = part.inertia
    return [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]


def _part(part) -> dict:
    return {"mass": part.mass, "com": list(part.com), "inertia": _matrix(part)}


def timor_modules(cat, assembly) -> list[dict]:
    """The assembly as timor_ref's plain numbers (SI), straight from the catalogue's modules."""
    out = []
    for i, name in enumerate(assembly.modules):
        m = cat.modules[name]
        d = {"kind": m.kind, "out": m.out.tolist(), "proximal": _part(m.proximal)}
        if i:
            d["twist"] = assembly.twists[i - 1]
        if m.is_joint:
            d.update(type=m.type, axis=m.axis.tolist(), distal=_part(m.distal))
        out.append(d)
    return out


@pytest.fixture(scope="module")
def built():
    exe, why = timor_python()
    if exe is None:
        pytest.skip(why)
    cat = loads_catalogue(CATALOGUE, "timor_check.toml")
    assembly = Assembly.parse(ASSEMBLY, cat)
    chain = assemble(cat, assembly, name="timor_check", check_holding=False)   # holding: not compared here
    robot = kin.Robot(chain, backend="vm")
    rng = np.random.default_rng(32)
    lo, hi = np.array([j.limits for j in chain.joints]).T
    states = [{"q": rng.uniform(lo, hi).tolist(), "dq": rng.normal(0.0, 1.0, chain.n).tolist(),
               "ddq": rng.normal(0.0, 2.0, chain.n).tolist()} for _ in range(5)]
    zero = [0.0] * chain.n
    states.append({"q": states[0]["q"], "dq": zero, "ddq": zero})      # at rest: gravity alone
    try:
        ref = timor_reference(exe, timor_modules(cat, assembly), states, gravity=chain.gravity)
    except TimorUnavailableError as e:
        pytest.skip(str(e))
    return cat, assembly, chain, robot, states, ref


def test_the_same_robot_in_both(built):
    cat, assembly, chain, robot, states, ref = built
    assert ref["dof"] == chain.n == 4
    assert chain.payload is not None and chain.payload.mass == pytest.approx(1.2)
    assert [j.type for j in chain.joints] == ["revolute", "revolute", "prismatic", "revolute"]


def test_fk_and_joint_axes_agree(built):
    cat, assembly, chain, robot, states, ref = built
    for st, res in zip(states, ref["results"]):
        q = np.array(st["q"])
        T_timor = np.array(res["tcp"])
        np.testing.assert_allclose(robot.fk(q), T_timor, rtol=0, atol=1e-12)
        np.testing.assert_allclose(module_frames(cat, assembly, q)[-1][1], T_timor, rtol=0, atol=1e-12)
        # joint i turns about z of DH frame i-1 (standard DH); timor's joint frame is on that line
        frames = frames_numpy(chain, q)
        for i, J in enumerate(res["joints"]):
            J = np.array(J)
            z, o = frames[i][:3, 2], frames[i][:3, 3]
            np.testing.assert_allclose(J[:3, 2], z, rtol=0, atol=1e-12)
            assert np.linalg.norm(np.cross(J[:3, 3] - o, z)) < 1e-12


def test_inverse_dynamics_with_gravity_agree(built):
    cat, assembly, chain, robot, states, ref = built
    for st, res in zip(states, ref["results"]):
        tau = robot.inverse_dynamics(np.array(st["q"]), np.array(st["dq"]), np.array(st["ddq"]))
        tau_timor = np.array(res["tau"])
        assert np.abs(tau_timor).max() > 1.0            # gravity and motion load every joint
        np.testing.assert_allclose(tau, tau_timor, rtol=0, atol=1e-9)


def test_gravity_alone_and_a_payload_change_are_seen(built):
    """At rest the torques are gravity's alone; without the tool's mass they differ from timor's (the
    comparison sees the payload)."""
    cat, assembly, chain, robot, states, ref = built
    q, tau_rest = np.array(states[-1]["q"]), np.array(ref["results"][-1]["tau"])
    np.testing.assert_allclose(robot.gravity(q), tau_rest, rtol=0, atol=1e-9)
    light = kin.Robot(replace(chain, payload=None), backend="vm")
    assert np.abs(light.gravity(q) - tau_rest).max() > 1e-3
