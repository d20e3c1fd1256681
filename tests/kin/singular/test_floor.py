"""kin.singular.floor: a robot's default σ_min floor — the rule from the chain's length scale (sums of
the DH lengths written out by hand), a robot file's own ``sigma_floor`` (SI in any file units, saved
back, hostile values refused naming the field and the range)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.errors import ChainError, RobotFileError
from kin.robotfile import dumps_robot, loads_robot
from kin.singular.floor import FLOOR_FACTOR, default_sigma_floor, length_scale, sigma_floor

SMALL = """\
name = "small"
convention = "standard"
length_unit = "mm"
angle_unit = "deg"
{extra}
[[joints]]
type = "revolute"
a = 200.0
d = 50.0
limits = [-170.0, 170.0]

[[joints]]
type = "revolute"
a = 100.0
limits = [-170.0, 170.0]

[[joints]]
type = "prismatic"
limits = [-80.0, 30.0]
"""


def test_ur5e_length_scale_and_floor():
    # UR5e DH (kin/robots/ur5e.toml): d1 + |a2| + |a3| + d4 + d5 + d6, tool at the flange
    L = 0.1625 + 0.425 + 0.3922 + 0.1333 + 0.0997 + 0.0996
    c = kin.load_chain("ur5e")
    assert length_scale(c) == pytest.approx(L, rel=1e-12)
    f = sigma_floor(c)
    assert (f.value, f.source) == (pytest.approx(1e-3), "rule")      # L > 1 m: the cap
    assert f.describe("ur5e") == "default floor of ur5e, 0.001 (SI)"


def test_small_robot_floor_scales_with_size():
    """L = 0.2 + 0.05 + 0.1 + 0.08 m (the prismatic travel |−80 mm|), below 1 m: floor 10⁻³ · L."""
    c = loads_robot(SMALL.format(extra=""))
    assert length_scale(c) == pytest.approx(0.43, rel=1e-12)
    assert default_sigma_floor(c) == pytest.approx(FLOOR_FACTOR * 0.43, rel=1e-12)
    # the same robot twice as large: twice the floor (σ_min of its position rows doubles too)
    big = loads_robot(SMALL.format(extra="").replace("200.0", "400.0").replace("a = 100.0", "a = 200.0")
                      .replace("d = 50.0", "d = 100.0").replace("-80.0, 30.0", "-160.0, 60.0"))
    assert default_sigma_floor(big) == pytest.approx(2 * default_sigma_floor(c), rel=1e-12)
    r, rb = kin.Robot(c), kin.Robot(big)
    q = np.array([0.3, 1.1, -0.05])
    assert float(rb.sigma_min(q * [1, 1, 2])) == pytest.approx(2 * float(r.sigma_min(q)), rel=1e-9)


def test_robot_file_floor_replaces_the_rule_and_round_trips():
    c = loads_robot(SMALL.format(extra="sigma_floor = 0.0025\n"))
    assert c.sigma_floor == 0.0025            # SI although the file is in mm and degrees
    f = sigma_floor(c)
    assert (f.value, f.source) == (0.0025, "robot file")
    assert "sigma_floor of the robot file of small" in f.describe("small")
    again = loads_robot(dumps_robot(c))
    assert again == c and again.sigma_floor == 0.0025
    assert "sigma_floor" not in dumps_robot(loads_robot(SMALL.format(extra="")))
    assert sigma_floor(loads_robot(SMALL.format(extra="sigma_floor = 0\n"))).value == 0.0


@pytest.mark.parametrize("value, words", [("-1e-3", "allowed range [0, 1000] (SI)"), ("1e4", "allowed range"),
                                          ("nan", "finite"), ("inf", "finite"), ('"1e-3"', "must be a number"),
                                          ("true", "must be a number"), ("[1e-3]", "must be a number")])
def test_bad_robot_file_floor_is_refused(value, words):
    with pytest.raises(RobotFileError, match="sigma_floor") as e:
        loads_robot(SMALL.format(extra=f"sigma_floor = {value}\n"))
    assert words in str(e.value)


def test_chain_refuses_a_bad_floor():
    c = kin.load_chain("planar_2r")
    from dataclasses import replace
    for bad in (-1.0, math.nan, math.inf, True, "0.1"):
        with pytest.raises(ChainError, match="sigma_floor"):
            replace(c, sigma_floor=bad)
