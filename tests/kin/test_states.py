"""Named states (kin.states, the robot file's [states]): read in the file's units and kept in SI,
written back exactly, refused in one line when hostile; the bundled UR arms carry the group states of
Universal Robots' MoveIt SRDF, and their "up" state stands the arm upright (closed form)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.errors import ChainError, RobotFileError
from kin.robotfile import dumps_robot, loads_robot
from kin.states import UnknownStateError, state

UR5E = kin.robotfile.ROBOT_DIR / "ur5e.toml"


def _with_states(table: str) -> str:
    text = UR5E.read_text()
    head, _, rest = text.partition("\n[geometry]\n")
    head = head.split("\n[states]\n")[0]          # the bundled file's own table replaced
    return head + "\n" + table + "\n\n[geometry]\n" + rest


def test_states_are_read_in_file_units_and_written_back_exactly():
    chain = loads_robot(_with_states("[states]\nready = [10, -90, 45.5, 0, -30, 359]\nzero = [0, 0, 0, 0, 0, 0]"))
    assert list(chain.states) == ["ready", "zero"]
    assert np.allclose(chain.states["ready"], np.radians([10, -90, 45.5, 0, -30, 359]), rtol=0, atol=1e-15)
    again = loads_robot(dumps_robot(chain))
    assert again.states == chain.states
    assert np.array_equal(state(chain, "zero"), np.zeros(6))
    with pytest.raises(UnknownStateError, match="no state named 'hom'; its states: ready, zero"):
        state(chain, "hom")


@pytest.mark.parametrize("table, words", [
    ("[states]\nhome = [0, -90, 0, 0, 0]", "states.home: must be a list of 6 numbers"),
    ("[states]\nhome = [0, -90, 0, 0, 0, nan]", "states.home[5]: must be a finite number"),
    ("[states]\nhome = [0, -90, 0, 0, 0, inf]", "states.home[5]: must be a finite number"),
    ("[states]\nhome = [0, -90, 0, 0, 0, 360.5]", "joint 6 (wrist3) = 360.5 deg lies outside its limits [-360, 360]"),
    ("[states]\nhome = \"up\"", "states.home: must be a list of 6 numbers"),
    ("[states]\ninf = [0, 0, 0, 0, 0, 0]", "'inf' reads as a number"),
    ("[states]\n\"my home\" = [0, 0, 0, 0, 0, 0]", "is not a state name"),
    ("[states]\n9 = [0, 0, 0, 0, 0, 0]", "is not a state name"),
    ("states = [0, 0, 0, 0, 0, 0]", "states: must be a table"),
    ("[states]\n" + "\n".join(f"s{k} = [0, 0, 0, 0, 0, 0]" for k in range(101)), "at most 100"),
])
def test_hostile_states_are_one_line_naming_the_field(table, words):
    text = _with_states(table) if not table.startswith("states =") else \
        _with_states("").replace("name = ", table + "\nname = ", 1)
    with pytest.raises(RobotFileError, match=words.replace("[", r"\[").replace("]", r"\]").replace("(", r"\(")
                       .replace(")", r"\)")) as e:
        loads_robot(text, "r.toml")
    assert "\n" not in str(e.value) and str(e.value).startswith("r.toml")


def test_a_chain_refuses_a_state_outside_its_limits():
    c = kin.load_chain("planar_2r")
    from dataclasses import replace
    hi = c.upper
    with pytest.raises(ChainError, match="state 'far' joint 1"):
        replace(c, states={"far": (hi[0] + 1e-9, 0.0)})
    with pytest.raises(ChainError, match="has 3 values"):
        replace(c, states={"x": (0.0, 0.0, 0.0)})
    assert replace(c, states={"edge": tuple(hi)}).states["edge"] == tuple(hi)


# group states of ur_moveit_config/srdf/ur_macro.srdf.xacro (UniversalRobots/Universal_Robots_ROS2_Driver), rad
UR_SRDF = {"home": (0, -1.5707, 0, 0, 0, 0), "up": (0, -1.5707, 0, -1.5707, 0, 0),
           "test_configuration": (1.54, -1.62, 1.4, -1.2, -1.6, -0.11)}
# UR's DH table (support article 45257): d1, a2, a3, d4, d5, d6 (m)
UR_DH = {"ur3e": (0.15185, -0.24355, -0.2132, 0.13105, 0.08535, 0.0921),
         "ur5e": (0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996),
         "ur10e": (0.1807, -0.6127, -0.57155, 0.17415, 0.11985, 0.11655),
         "ur16e": (0.1807, -0.4784, -0.36, 0.17415, 0.11985, 0.11655)}


@pytest.mark.parametrize("name", sorted(UR_DH))
def test_bundled_ur_arms_carry_the_moveit_group_states(name):
    robot = kin.load_robot(name)
    c = robot.chain
    assert set(c.states) == set(UR_SRDF)
    for k, q in UR_SRDF.items():
        assert np.allclose(c.states[k], q, rtol=0, atol=1e-15), k
    # "up": shoulder lift and wrist 1 at -pi/2 (to the SRDF's 1.5707): the arm upright, the flange at
    # z = d1 - a2 - a3 + d5, y = -(d4 + d6), x ≈ 0 (off by the SRDF's rounding of pi/2 over the arm's length)
    d1, a2, a3, d4, d5, d6 = UR_DH[name]
    p = robot.fk(np.array(c.states["up"]))[:3, 3]
    slack = (abs(a2) + abs(a3) + d5) * (math.pi / 2 - 1.5707) * 2
    assert p[2] == pytest.approx(d1 - a2 - a3 + d5, abs=slack)
    assert p[1] == pytest.approx(-(d4 + d6), abs=1e-12)
    assert abs(p[0]) <= slack
    # no acceleration limits: Universal Robots publishes none
    assert all(j.max_acceleration is None for j in c.joints)


def test_the_panda_carries_frankas_published_acceleration_limits():
    c = kin.load_chain("franka_panda")
    assert [j.max_acceleration for j in c.joints] == [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0]
