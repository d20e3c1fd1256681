"""Named states on the command line: a single non-numeric word names one of the robot's states wherever
a configuration is taken (fk, jacobian, plan --start/--goal), the same as its numbers typed out; an
unknown name is one line listing the robot's states; rmt show lists them; rmt import-urdf --srdf
writes a real SRDF's group states into the robot file."""
from __future__ import annotations

import json

import numpy as np
import pytest

import kin
from studies.cli import main
from studies.cli.common import CliInputError, joint_values

# ur_moveit_config's "test_configuration" (rad), in degrees as a user would type it
TEST_CONFIGURATION_DEG = [repr(float(np.degrees(x))) for x in (1.54, -1.62, 1.4, -1.2, -1.6, -0.11)]


def test_joint_values_reads_a_state_by_name():
    robot = kin.load_robot("ur5e")
    assert np.allclose(joint_values(robot, ["up"]), (0, -1.5707, 0, -1.5707, 0, 0), rtol=0, atol=1e-15)
    with pytest.raises(CliInputError, match="--start: 'hom' is neither a number nor a named state: ur5e has no "
                                            "state named 'hom'; its states: home, up, test_configuration"):
        joint_values(robot, ["hom"], "--start")
    with pytest.raises(CliInputError, match="its states: none"):
        joint_values(kin.load_robot("ur3_homework"), ["home"], "--goal")
    with pytest.raises(CliInputError, match="not a finite number"):      # a number, not a name
        joint_values(kin.load_robot("planar_2r"), ["nan", "0"])


def test_fk_and_jacobian_by_name_equal_the_typed_numbers(capsys):
    for cmd in ("fk", "jacobian"):
        assert main([cmd, "ur5e", "test_configuration", "--json"]) == 0
        by_name = json.loads(capsys.readouterr().out)
        assert main([cmd, "ur5e", *TEST_CONFIGURATION_DEG, "--json"]) == 0
        typed = json.loads(capsys.readouterr().out)
        assert by_name.keys() == typed.keys()
        for k, v in by_name.items():       # the same to rounding (typed degrees → rad)
            if isinstance(v, float) or (isinstance(v, list) and not isinstance(v[0], str)):
                assert np.allclose(v, typed[k], rtol=1e-12, atol=1e-12), (cmd, k)
            else:
                assert v == typed[k], (cmd, k)
    assert main(["fk", "ur5e", "homee"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "its states: home, up, test_configuration" in err


def test_plan_takes_states_as_start_and_goal(tmp_path, capsys):
    out = tmp_path / "p.csv"
    rc = main(["plan", "ur5e", "--start", "test_configuration", "--goal", "0", "-90", "90", "-90", "-90", "0",
               "--out", str(out)])
    assert rc == 0, capsys.readouterr().err
    first = np.array(out.read_text().splitlines()[1].split(","), float)
    assert np.allclose(first, np.array(TEST_CONFIGURATION_DEG, float), rtol=0, atol=1e-9)


def test_show_lists_the_states(capsys):
    assert main(["show", "ur5e", "--json"]) == 0
    states = json.loads(capsys.readouterr().out)["states"]
    assert states["up"] == pytest.approx([0, -1.5707 * 180 / np.pi, 0, -1.5707 * 180 / np.pi, 0, 0], abs=1e-12)
    assert main(["show", "ur5e"]) == 0
    assert "state up = 0 -89.9945 0 -89.9945 0 0" in capsys.readouterr().out


def test_import_urdf_writes_the_srdfs_states(tmp_path, capsys):
    from tests.kin.urdf.reference import erd_urdf
    urdf = erd_urdf("panda_description/urdf/panda.urdf")
    srdf = erd_urdf("panda_description/srdf/panda.srdf")
    out = tmp_path / "panda.toml"
    rc = main(["import-urdf", str(urdf), "--tip", "panda_link8", "--no-collision", "--srdf", str(srdf),
               "--out", str(out)])
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    assert "named states from the SRDF: default" in cap.out
    assert "group_state 'default': values of joints off the chain left out (panda_finger_joint1)" in cap.err
    assert "\n[states]\ndefault = [0.0, -0.785398, 0.0, -2.35619, 0.0, 1.5707, 0.785398]\n" in out.read_text()
    assert main(["fk", str(out), "default"]) == 0
