"""planning.toolpath.load: :func:`load_toolpath` needs the robot whose units the file is written in;
without one (``robot=None``) it says so with a ToolPathError instead of an AttributeError."""
from __future__ import annotations

from pathlib import Path

import pytest

import kin
from planning.toolpath import ToolPathError, load_toolpath

TOOLPATHS = Path(__file__).resolve().parents[3] / "studies" / "toolpaths"


@pytest.mark.parametrize("name", ["scara_line.csv", "ur3_drawing.toml"])
@pytest.mark.parametrize("robot", [None, "scara_rrp", object()])
def test_a_missing_robot_is_named(name, robot):
    with pytest.raises(ToolPathError, match="robot is .*; expected a kin.Robot or kin.Chain"):
        load_toolpath(TOOLPATHS / name, robot)
    with pytest.raises(ToolPathError, match="robot is None"):
        load_toolpath(TOOLPATHS / name, None)


def test_a_robot_or_its_chain_reads_the_file():
    scara = kin.load_robot("scara_rrp")
    a = load_toolpath(TOOLPATHS / "scara_line.csv", scara)
    b = load_toolpath(TOOLPATHS / "scara_line.csv", scara.chain)
    assert len(a) == len(b) == 21
