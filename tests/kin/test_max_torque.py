"""Joint torque limits (``Joint.max_torque``): robot-file key (SI, N·m or N, whatever the file's units),
exact round trips, one-line errors for hostile values, URDF ``<limit effort>`` read and written."""
from __future__ import annotations

import math
from dataclasses import replace

import pytest

import kin
from kin.errors import ChainError, RobotFileError
from kin.robotfile import dumps_robot, loads_robot
from kin.urdf import UrdfError, import_urdf, read_serial_chain, save_urdf
from tests.kin.urdf.synthetic import joint, urdf_text

TEXT = """\
name = "arm"
convention = "standard"
length_unit = "mm"
angle_unit = "deg"

[[joints]]
type = "revolute"
a = 100.0
alpha = -90.0
d = 250.0
limits = [-170.0, 170.0]
max_torque = 87.5

[[joints]]
type = "prismatic"
limits = [10.0, 300.0]
max_velocity = 500.0
max_torque = 1234.0000000000002
"""


def test_max_torque_is_si_in_any_file_units():
    c = loads_robot(TEXT)
    # N·m and N as written, not scaled by the file's mm: a force is not a length
    assert c.joints[0].max_torque == 87.5 and c.joints[1].max_torque == 1234.0000000000002
    assert c.joints[1].max_velocity == pytest.approx(0.5)


def test_round_trip_is_exact():
    c = loads_robot(TEXT)
    text = dumps_robot(c)
    assert "max_torque = 87.5" in text and "max_torque = 1234.0000000000002" in text
    again = loads_robot(text)
    assert again == c and dumps_robot(again) == text


def test_absent_max_torque_is_none_and_not_written():
    c = loads_robot(TEXT.replace("max_torque = 87.5\n", ""))
    assert c.joints[0].max_torque is None
    assert dumps_robot(c).count("max_torque") == 1


@pytest.mark.parametrize("value, message", [
    ("-5.0", "must be positive, got -5.0"),
    ("0.0", "must be positive, got 0.0"),
    ("nan", "must be a finite number, got nan"),
    ("inf", "must be a finite number, got inf"),
    ('"strong"', "must be a number, got string 'strong'"),
    ("true", "must be a number"),
    ("[87.0]", "must be a number"),
    ("1e12", "1e+12 N·m exceeds 1e+07 N·m"),
])
def test_hostile_max_torque_is_one_line_naming_the_field(value, message):
    with pytest.raises(RobotFileError) as e:
        loads_robot(TEXT.replace("max_torque = 87.5", f"max_torque = {value}"), "arm.toml")
    assert e.value.field == "joints[0].max_torque"
    assert "arm.toml" in str(e.value) and message in str(e.value) and "\n" not in str(e.value)


def test_prismatic_limit_is_named_in_newtons():
    with pytest.raises(RobotFileError, match=r"joints\[1\].max_torque.*1e\+08 N exceeds"):
        loads_robot(TEXT.replace("max_torque = 1234.0000000000002", "max_torque = 1e8"))


@pytest.mark.parametrize("value", [-1.0, 0.0, math.nan, math.inf, "87", True])
def test_chain_refuses_bad_max_torque(value):
    c = loads_robot(TEXT)
    with pytest.raises(ChainError, match="joint 1: max_torque = .* must be a positive finite number"):
        replace(c, joints=(replace(c.joints[0], max_torque=value), c.joints[1]))


# ---- URDF ------------------------------------------------------------------------------------------
def _urdf(tmp_path, effort: str | None):
    j = joint("j1", "revolute", "a", "b")
    text = urdf_text([j], "one")
    text = text.replace('effort="10"', "" if effort is None else f'effort="{effort}"')
    path = tmp_path / "one.urdf"
    path.write_text(text)
    return path


@pytest.mark.parametrize("effort, expected", [("42.5", 42.5), ("0", None), (None, None)])
def test_urdf_effort_is_the_torque_limit(tmp_path, effort, expected):
    assert read_serial_chain(_urdf(tmp_path, effort)).joints[0].max_torque == expected


@pytest.mark.parametrize("effort", ["-3", "nan"])
def test_urdf_bad_effort_is_refused(tmp_path, effort):
    with pytest.raises(UrdfError, match=r"one.urdf: joint 'j1': <limit> effort = .*; allowed: 0 to 1e\+07"):
        read_serial_chain(_urdf(tmp_path, effort))


def test_urdf_export_import_keeps_torque_limits(tmp_path):
    chain = kin.load_chain("franka_panda")
    assert [j.max_torque for j in chain.joints] == [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]
    path = save_urdf(chain, tmp_path / "panda.urdf")
    again = import_urdf(str(path), collision=False)
    assert [j.max_torque for j in again.joints] == [j.max_torque for j in chain.joints]
    unknown = replace(chain, joints=tuple(replace(j, max_torque=None) for j in chain.joints))
    text = save_urdf(unknown, tmp_path / "unknown.urdf").read_text()
    assert 'effort="0.0"' in text
    assert all(j.max_torque is None for j in import_urdf(str(tmp_path / "unknown.urdf"), collision=False).joints)


def test_real_ur5_urdf_efforts():
    """example-robot-data's ur5_robot.urdf gives effort 150, 150, 150, 28, 28, 28 (its <limit> elements)."""
    from tests.kin.urdf.reference import erd_urdf
    path = erd_urdf("ur_description/urdf/ur5_robot.urdf")
    chain = import_urdf(str(path), tip="tool0", collision=False)
    assert [j.max_torque for j in chain.joints] == [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]
