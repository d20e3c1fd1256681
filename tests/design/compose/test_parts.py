"""Part files (design.compose.parts): a task file without a robot.  Values land in SI; the cycle's
scalar limits become per-joint limits of the assembled robot (or its modules' ratings); every bad
field is one TaskError naming the file and the field."""
from __future__ import annotations

import math

import numpy as np
import pytest

from design.compose import load_part, loads_part
from design.task import TaskError
from kin.modules import Assembly, assemble
from tests.design.compose import compose_helpers as h

GOOD = """
name = "pick-1"
title = "two stops"
length_unit = "mm"
angle_unit = "deg"
max_cycle_time = 4
[target]
shape = "box"
min = [200, -50, 300]
max = [250, 50, 300]
count = [2, 2, 1]
tolerance = 0.2
[dexterity]
sigma_min = 0.01
[windows]
sigma_min = 0.02
[cycle]
sequence = [0, 3]
v_max = 90
tau_max = 40
lift = 20
dwell = 0.5
[cycle.masses]
payload = 1.5
"""


def test_a_part_file_in_si():
    p = loads_part(GOOD, "good.toml")
    assert p.name == "pick-1" and p.title == "two stops" and len(p.targets) == 4
    assert np.allclose(p.targets.positions[0], [0.2, -0.05, 0.3]) and p.targets.tolerance == pytest.approx(2e-4)
    assert p.dexterity.kind == "sigma_min" and p.dexterity.value == 0.01
    assert p.windows == ("sigma_min", 0.02)
    assert p.max_cycle_time == 4 and p.cycle.lift == pytest.approx(0.02) and p.cycle.payload == 1.5
    assert not p.needs_roll and np.array_equal(p.placement, np.eye(4))


def test_cycle_limits_become_the_assembled_robots():
    cat = h.catalogue()
    chain = assemble(cat, Assembly.parse("B Rz Ry L300 Ry", cat))
    spec = loads_part(GOOD, "good.toml").cycle.spec(chain)
    assert np.allclose(spec.v_max, math.radians(90))             # the part's scalar, deg/s → rad/s
    assert np.allclose(spec.a_max, math.radians(360))            # the modules' rating (catalogue deg/s²)
    assert np.allclose(spec.tau_max, 40) and spec.masses is None  # the modules' own masses
    rated = loads_part(GOOD.replace("v_max = 90\ntau_max = 40\n", ""), "rated.toml").cycle.spec(chain)
    assert np.allclose(rated.v_max, math.radians(180)) and np.allclose(rated.tau_max, 100)
    assert spec.sequence == (0, 3) and spec.dwell == 0.5


def test_a_missing_rating_is_said_when_the_cycle_is_built():
    from kin.modules import loads_catalogue
    from tests.design.compose.test_space import TWISTY
    cat = loads_catalogue(TWISTY, "twisty.toml")                  # no max_acceleration anywhere
    chain = assemble(cat, Assembly.parse("B K K", cat), check_holding=False)
    with pytest.raises(TaskError, match="cycle.a_max: not given, and joint .* has no max_acceleration"):
        loads_part(GOOD, "good.toml").cycle.spec(chain)


def test_load_part_reads_relative_files(tmp_path):
    (tmp_path / "pts.csv").write_text("x,y,z\n100,0,200\n150,0,250\n")
    (tmp_path / "p.toml").write_text('name = "p"\nlength_unit = "mm"\nangle_unit = "deg"\n'
                                     '[target]\nshape = "points"\nfile = "pts.csv"\n')
    p = load_part(tmp_path / "p.toml")
    assert np.allclose(p.targets.positions, [[0.1, 0, 0.2], [0.15, 0, 0.25]])
    with pytest.raises(TaskError, match="nope.toml"):
        load_part(tmp_path / "nope.toml")


@pytest.mark.parametrize("edit, field", [
    (('name = "pick-1"', 'name = "pick-1"\nrobot = "ur5e"'), "robot"),
    (('name = "pick-1"', 'name = "pick-1"\narchitecture = "all"'), "architecture"),
    (('name = "pick-1"', 'name = "pick-1"\nobjective = "length"'), "objective"),
    (('name = "pick-1"', 'name = "pick-1"\ncolour = 1'), "colour"),
    (('name = "pick-1"', 'name = "pick 1"'), "name"),
    (("v_max = 90", "v_max = [90, 90, 90]"), "cycle.v_max"),
    (("v_max = 90", "v_max = -1"), "cycle.v_max"),
    (("payload = 1.5", "mass_per_length = 2"), "cycle.masses.mass_per_length"),
    (("payload = 1.5", "payload = -1"), "cycle.masses.payload"),
    (("sequence = [0, 3]", "sequence = [0, 4]"), "cycle.sequence[1]"),
    (("max_cycle_time = 4", "max_cycle_time = 0"), "max_cycle_time"),
    (("max_cycle_time = 4", "max_cycle_time = inf"), "max_cycle_time"),
    (("[windows]\nsigma_min = 0.02", "[windows]\nsigma_min = 0.02\nmanipulability = 0.1"), "windows"),
    (("[windows]\nsigma_min = 0.02", "[windows]\nmargin = 5"), "windows.margin"),
    (("[windows]\nsigma_min = 0.02", "[windows]\nsigma_min = 0"), "windows.sigma_min"),
    (("[dexterity]\nsigma_min = 0.01", "[dexterity]\nsigma_min = 0.01\ncharacteristic_length = 100"),
     "dexterity.characteristic_length"),
    (("tolerance = 0.2", "tolerance = 0.2\norientation = \"axis\"\naxis = [0, 0, 1]"), "cycle"),
    (("max_cycle_time = 4", "clearance = 5"), "clearance"),
    (('angle_unit = "deg"', 'angle_unit = "grad"'), "angle_unit"),
])
def test_bad_fields_are_refused_with_their_name(edit, field):
    old, new = edit
    assert old in GOOD
    with pytest.raises(TaskError) as e:
        loads_part(GOOD.replace(old, new), "bad.toml")
    msg = str(e.value)
    assert msg.startswith(f"bad.toml: {field}:") and "\n" not in msg, msg


def test_max_cycle_time_needs_a_cycle():
    text = GOOD[:GOOD.index("[cycle]")]
    with pytest.raises(TaskError, match="bad.toml: max_cycle_time: needs a \\[cycle\\]"):
        loads_part(text, "bad.toml")


def test_not_toml_and_missing_target():
    with pytest.raises(TaskError, match="not valid TOML"):
        loads_part("name = ", "x.toml")
    with pytest.raises(TaskError, match="x.toml: target: missing"):
        loads_part('name = "a"\nlength_unit = "m"\nangle_unit = "rad"\n', "x.toml")
