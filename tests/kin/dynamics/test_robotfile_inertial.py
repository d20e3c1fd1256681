"""Robot files' inertial tables: [joints.inertial], [payload] and gravity — load, units, save, and every
hostile value refused with one line naming the file and the field."""
import math

import numpy as np
import pytest

import kin
from kin.dynamics import LinkInertia
from kin.errors import RobotFileError
from kin.robotfile import with_units

HEAD = '''name = "arm"
convention = "standard"
length_unit = "{lu}"
angle_unit = "rad"
{top}
[[joints]]
type = "revolute"
a = {a1}
limits = [-3.0, 3.0]

[[joints]]
type = "revolute"
a = {a2}
limits = [-3.0, 3.0]

[[joints]]
type = "prismatic"
limits = [0.0, {d3}]
'''


def robot(inertial: str = "", payload: str = "", top: str = "", lu: str = "m", joint: int = 2) -> str:
    """A three-joint file in ``lu`` with ``inertial`` (the body of a [joints.inertial] table) on ``joint``
    (0-based) and an optional [payload] body."""
    s = 1000.0 if lu == "mm" else 1.0
    text = HEAD.format(lu=lu, top=top, a1=0.4 * s, a2=0.3 * s, d3=0.2 * s)
    if inertial:
        parts = text.split("[[joints]]")
        parts[joint + 1] = parts[joint + 1].rstrip("\n") + "\n\n[joints.inertial]\n" + inertial + "\n\n"
        text = "[[joints]]".join(parts)
    if payload:
        text += "\n[payload]\n" + payload + "\n"
    return text


FULL = """mass = 2.5
com = [-0.1, 0.02, 0.03]
inertia = [0.02, 0.03, 0.025, 0.001, -0.002, 0.0005]
motor_inertia = 0.0003
viscous = 0.8
coulomb = 1.5"""
FULL_MM = """mass = 2.5
com = [-100.0, 20.0, 30.0]
inertia = [20000.0, 30000.0, 25000.0, 1000.0, -2000.0, 500.0]
motor_inertia = 0.0003
viscous = 0.8
coulomb = 1.5"""


def test_values_are_read_in_si():
    chain = kin.loads_robot(robot(FULL, "mass = 1.2\ncom = [0.0, 0.0, 0.05]", "gravity = [0.0, -9.81, 0.0]"))
    li = chain.joints[2].inertia
    assert chain.joints[0].inertia is None and chain.joints[1].inertia is None
    assert li.mass == 2.5 and li.com == (-0.1, 0.02, 0.03)
    assert li.inertia == (0.02, 0.03, 0.025, 0.001, -0.002, 0.0005)
    assert (li.motor_inertia, li.viscous, li.coulomb) == (0.0003, 0.8, 1.5)
    assert chain.payload.mass == 1.2 and chain.payload.com == (0.0, 0.0, 0.05)
    assert chain.payload.inertia == (0.0,) * 6
    assert chain.gravity == (0.0, -9.81, 0.0)


def test_default_gravity_and_no_inertial_model():
    chain = kin.loads_robot(robot())
    assert chain.gravity == (0.0, 0.0, -9.81) and chain.payload is None
    assert all(j.inertia is None for j in chain.joints)
    assert "inertial" not in kin.dumps_robot(chain) and "gravity" not in kin.dumps_robot(chain)


def test_a_file_in_mm_gives_the_same_si_values():
    m = kin.loads_robot(robot(FULL, "mass = 1.2\ncom = [0.0, 0.0, 0.05]"))
    mm = kin.loads_robot(robot(FULL_MM, "mass = 1.2\ncom = [0.0, 0.0, 50.0]", lu="mm"))
    for a, b in zip(m.joints, mm.joints):
        assert LinkInertia.is_close(a.inertia, b.inertia, 1e-14)
    li_m, li_mm = m.joints[2].inertia, mm.joints[2].inertia
    assert (li_m.motor_inertia, li_m.viscous, li_m.coulomb) == (li_mm.motor_inertia, li_mm.viscous, li_mm.coulomb)
    assert LinkInertia.is_close(m.payload, mm.payload, 1e-14)


@pytest.mark.parametrize("lu, body", [("m", FULL), ("mm", FULL_MM)])
def test_round_trip_in_file_units(lu, body):
    chain = kin.loads_robot(robot(body, "mass = 0.7\ncom = [0.0, 0.0, 0.1]\ninertia = [1e-3, 1e-3, 5e-4, 0, 0, 0]",
                                  "gravity = [0.0, 0.0, -9.80665]", lu=lu))
    text = kin.dumps_robot(chain)
    again = kin.loads_robot(text)
    assert again == chain                                     # exact: inertia, payload, gravity
    assert kin.dumps_robot(again) == text
    if lu == "mm":
        assert "com = [-100.0, 20.0, 30.0]" in text and "inertia = [20000.0, 30000.0, 25000.0" in text


def test_round_trip_of_every_inertial_on_a_bundled_arm(tmp_path):
    chain = kin.load_chain("franka_panda")
    assert all(j.inertia is not None for j in chain.joints)
    path = kin.save_robot(chain, tmp_path / "panda.toml")
    assert kin.load_chain(path) == chain


def test_the_inertial_model_follows_a_change_of_units():
    chain = kin.loads_robot(robot(FULL))
    again = kin.loads_robot(kin.dumps_robot(with_units(chain, "mm")))
    assert LinkInertia.is_close(again.joints[2].inertia, chain.joints[2].inertia, 1e-14)


BAD_INERTIAL = [
    ("mass = -1.0", "joints[2].inertial.mass", "must be in [0"),
    ('mass = "3"', "joints[2].inertial.mass", "must be a number, got string"),
    ("mass = true", "joints[2].inertial.mass", "must be a number, got boolean"),
    ("mass = nan", "joints[2].inertial.mass", "finite"),
    ("mass = inf", "joints[2].inertial.mass", "finite"),
    ("mass = 1e9", "joints[2].inertial.mass", "must be in [0"),
    ("com = [0.0, 0.0, 0.0]", "joints[2].inertial.mass", "missing required field"),
    ("mass = 1.0\ncom = [0.0, 0.0]", "joints[2].inertial.com", "list of 3 numbers"),
    ("mass = 1.0\ncom = [0.0, nan, 0.0]", "joints[2].inertial.com[1]", "finite"),
    ('mass = 1.0\ncom = [0.0, "a", 0.0]', "joints[2].inertial.com[1]", "must be a number"),
    ("mass = 1.0\ncom = [0.0, 0.0, 1e5]", "joints[2].inertial.com[2]", "exceeds"),
    ("mass = 1.0\ncom = 0.5", "joints[2].inertial.com", "list of 3 numbers"),
    ("mass = 1.0\ninertia = [1.0, 1.0, 1.0]", "joints[2].inertial.inertia", "list of 6 numbers"),
    ("mass = 1.0\ninertia = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0]", "joints[2].inertial.inertia", "list of 6 numbers"),
    ("mass = 1.0\ninertia = [-1.0, 1.0, 1.0, 0.0, 0.0, 0.0]", "joints[2].inertial.inertia",
     "not positive semi-definite"),
    ("mass = 1.0\ninertia = [1.0, 1.0, 1.0, 2.0, 0.0, 0.0]", "joints[2].inertial.inertia",
     "not positive semi-definite"),
    ("mass = 1.0\ninertia = [1.0, 1.0, 3.0, 0.0, 0.0, 0.0]", "joints[2].inertial.inertia", "triangle inequality"),
    ("mass = 1.0\ninertia = [1.0, 1.0, nan, 0.0, 0.0, 0.0]", "joints[2].inertial.inertia[2]", "finite"),
    ("mass = 0.0\ninertia = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]", "joints[2].inertial.inertia", "massless"),
    ("mass = 1.0\nmotor_inertia = -0.1", "joints[2].inertial.motor_inertia", "must be ≥ 0"),
    ("mass = 1.0\nviscous = -1", "joints[2].inertial.viscous", "must be ≥ 0"),
    ('mass = 1.0\ncoulomb = "x"', "joints[2].inertial.coulomb", "must be a number"),
    ("mass = 1.0\ndensity = 7800", "joints[2].inertial.density", "unknown field; allowed: mass, com, inertia"),
]


def _one_line_naming(e: pytest.ExceptionInfo, field: str, text: str):
    msg = str(e.value)
    assert "\n" not in msg
    assert msg.startswith(f"arm.toml: {field}: "), msg
    assert text in msg, msg


@pytest.mark.parametrize("body, field, text", BAD_INERTIAL)
def test_hostile_inertial_values(body, field, text):
    with pytest.raises(RobotFileError) as e:
        kin.loads_robot(robot(body), "arm.toml")
    _one_line_naming(e, field, text)


@pytest.mark.parametrize("body, field, text", BAD_INERTIAL)
def test_hostile_payload_values(body, field, text):
    with pytest.raises(RobotFileError) as e:
        kin.loads_robot(robot(payload=body), "arm.toml")
    _one_line_naming(e, field.replace("joints[2].inertial", "payload"), text)


def test_an_inertial_that_is_not_a_table():
    text = robot().replace('type = "prismatic"', 'type = "prismatic"\ninertial = 3.0')
    with pytest.raises(RobotFileError) as e:
        kin.loads_robot(text, "arm.toml")
    _one_line_naming(e, "joints[2].inertial", "must be a table, got number")


@pytest.mark.parametrize("top, text", [
    ("gravity = [0.0, -9.81]", "list of 3 numbers"),
    ('gravity = "down"', "list of 3 numbers"),
    ("gravity = [0.0, 0.0, nan]", "finite"),
    ("gravity = [0.0, 0.0, -1e4]", "at most 1000"),
])
def test_hostile_gravity(top, text):
    with pytest.raises(RobotFileError) as e:
        kin.loads_robot(robot(top=top), "arm.toml")
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("arm.toml: gravity"), msg
    assert text in msg, msg


def test_a_mm_file_refuses_in_its_own_unit():
    """A tensor that breaks the triangle inequality in a mm file: the message quotes the file's values."""
    with pytest.raises(RobotFileError) as e:
        kin.loads_robot(robot("mass = 1.0\ninertia = [1000.0, 1000.0, 3000.0, 0.0, 0.0, 0.0]", lu="mm"), "arm.toml")
    _one_line_naming(e, "joints[2].inertial.inertia", "[1000.0, 1000.0, 3000.0, 0.0, 0.0, 0.0] (kg·mm²")


def test_convention_change_keeps_every_body_in_place():
    """to_modified moves each frame; the centres of mass and tensors in the base frame stay."""
    from tests.dh_numpy import frames_numpy
    li = "mass = 1.5\ncom = [0.05, -0.02, 0.1]\ninertia = [0.01, 0.02, 0.015, 0.001, 0.0, -0.002]"
    chain = kin.loads_robot(robot(li, joint=1).replace("[[joints]]\ntype = \"revolute\"\na = 0.3",
                                                       "[[joints]]\ntype = \"revolute\"\na = 0.3\nalpha = 0.7"))
    mod = chain.to_modified()
    q = np.array([0.3, -1.1, 0.12])
    for F1, F2, j1, j2 in zip(frames_numpy(chain, q)[1:], frames_numpy(mod, q)[1:], chain.joints, mod.joints):
        if j1.inertia is None:
            assert j2.inertia is None
            continue
        R1, R2 = F1[:3, :3], F2[:3, :3]
        np.testing.assert_allclose(R1 @ j1.inertia.com + F1[:3, 3], R2 @ j2.inertia.com + F2[:3, 3], atol=1e-15)
        np.testing.assert_allclose(R1 @ j1.inertia.tensor @ R1.T, R2 @ j2.inertia.tensor @ R2.T, atol=1e-15)
    assert all(LinkInertia.is_close(a.inertia, b.inertia, 1e-13) for a, b in zip(mod.to_standard().joints,
                                                                                chain.joints))
    assert math.isclose(sum(j.inertia.mass for j in mod.joints if j.inertia), 1.5)
