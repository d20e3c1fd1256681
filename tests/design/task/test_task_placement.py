"""The ``[placement]`` table of a task file: read in the file's units into a
:class:`design.place.PlacementRegion` (SI), its defaults, and one TaskError line naming
``placement.<field>`` for every hostile value."""
import math

import numpy as np
import pytest

from design.place import PlacementRegion
from design.task import TaskError, loads_task
from design.task.file import placement_region

TASK = '''
name = "t"
robot = "planar_2r"
length_unit = "mm"
angle_unit = "deg"
[target]
shape = "box"
min = [150, -150, 0]
max = [350, 150, 0]
count = [3, 2, 1]
'''


def _task(placement: str):
    return loads_task(TASK + "[placement]\n" + placement + "\n", "t.toml")


def test_no_table_no_region():
    assert loads_task(TASK, "t.toml").region is None


def test_units_become_si():
    t = _task("x = [-100, 250]\ny = [20, 20]\nz = [-5, 5]\nyaw = [-90, 45]\ntilt = 10\n"
              "keep_out = [[-50, 50, -60, 60], [200, 240, 0, 10]]")
    r = t.region
    assert isinstance(r, PlacementRegion)
    assert r.x == pytest.approx((-0.1, 0.25)) and r.y == pytest.approx((0.02, 0.02))
    assert r.z == pytest.approx((-0.005, 0.005))
    assert r.yaw == pytest.approx((-math.pi / 2, math.pi / 4)) and r.tilt == pytest.approx(math.radians(10))
    assert np.allclose(r.keep_out, [[-0.05, 0.05, -0.06, 0.06], [0.2, 0.24, 0.0, 0.01]])
    assert r.names() == ["x", "z", "roll", "pitch", "yaw"]            # y fixed by equal ends


def test_defaults():
    r = _task("x = [0, 100]\ny = [-100, 0]").region
    assert r.z == (0.0, 0.0) and r.yaw == pytest.approx((-math.pi, math.pi))
    assert r.tilt == 0.0 and r.keep_out == ()
    assert r.names() == ["x", "y", "yaw"]


def test_tilt_of_exactly_90_degrees_and_a_full_turn_are_allowed():
    r = _task("x = [0, 1]\ny = [0, 1]\ntilt = 90\nyaw = [0, 360]").region
    assert r.tilt == pytest.approx(math.pi / 2) and r.tilt <= math.pi / 2
    assert r.yaw[1] - r.yaw[0] == pytest.approx(2 * math.pi)


@pytest.mark.parametrize("body,field", [
    ("x = [2, 1]\ny = [0, 1]", "placement.x"),                       # low > high
    ("x = [0, 1]\ny = [5, -5]", "placement.y"),
    ("x = [0, 1]\ny = [0, 1]\nz = [1, 0]", "placement.z"),
    ("x = [nan, 1]\ny = [0, 1]", "placement.x[0]"),                  # TOML's nan
    ("x = [0, inf]\ny = [0, 1]", "placement.x[1]"),
    ('x = ["nan", 1]\ny = [0, 1]', "placement.x[0]"),                # a NaN-like string
    ('x = [0, 1]\ny = ["0", "1"]', "placement.y[0]"),
    ("x = 1\ny = [0, 1]", "placement.x"),                           # wrong types
    ("x = [0, 1, 2]\ny = [0, 1]", "placement.x"),
    ("x = [true, 1]\ny = [0, 1]", "placement.x[0]"),
    ('x = [0, 1]\ny = [0, 1]\ntilt = "5"', "placement.tilt"),
    ("x = [0, 1]\ny = [0, 1]\ntilt = [5]", "placement.tilt"),
    ("x = [0, 1]\ny = [0, 1]\ntilt = 100", "placement.tilt"),        # tilt > 90°
    ("x = [0, 1]\ny = [0, 1]\ntilt = -1", "placement.tilt"),
    ("x = [0, 1]\ny = [0, 1]\nyaw = [90, -90]", "placement.yaw"),
    ("x = [0, 1]\ny = [0, 1]\nyaw = [-180, 270]", "placement.yaw"),  # more than a full turn
    ("x = [0, 1]\ny = [0, 1]\nyaw = [-400, 0]", "placement.yaw"),
    ("x = [0, 1e12]\ny = [0, 1]", "placement.x"),                     # beyond ±10 km
    ("x = [0, 1]\ny = [0, 1]\nkeep_out = [[0, 1, 2]]", "placement.keep_out[0]"),     # 3 numbers
    ("x = [0, 1]\ny = [0, 1]\nkeep_out = [0, 1, 0, 1]", "placement.keep_out[0]"),    # not nested
    ("x = [0, 1]\ny = [0, 1]\nkeep_out = 3", "placement.keep_out"),
    ("x = [0, 1]\ny = [0, 1]\nkeep_out = [[1, 0, 0, 1]]", "placement.keep_out[0]"),  # min > max
    ("x = [0, 1]\ny = [0, 1]\nkeep_out = [[0, 1, 0, 0]]", "placement.keep_out[0]"),  # empty
    ("x = [0, 1]\ny = [0, 1]\nkeep_out = [[0, 1, 0, 1], [0, 1, 0, nan]]", "placement.keep_out[1][3]"),
    ("x = [0, 10]\ny = [0, 10]\nkeep_out = [[-1, 11, -1, 11]]", "placement.keep_out[0]"),  # covers it all
    ("x = [0, 10]\ny = [0, 10]\nkeep_out = [[0, 10, 0, 10]]", "placement.keep_out[0]"),
    ("x = [0, 10]\ny = [3, 3]\nkeep_out = [[-1, 11, 2, 4]]", "placement.keep_out[0]"),
    ("x = [0, 1]\ny = [0, 1]\nbogus = 1", "placement.bogus"),         # unknown key
    ("y = [0, 1]", "placement.x"),                                    # x and y are required
    ("x = [0, 1]", "placement.y"),
    ("x = [0, 0]\ny = [0, 0]\nyaw = [0, 0]", "placement"),            # nothing left free
])
def test_hostile_values_name_the_field(body, field):
    with pytest.raises(TaskError) as e:
        _task(body)
    msg = str(e.value)
    assert msg.startswith(f"t.toml: {field}: ") and "\n" not in msg, msg


def test_not_a_table():
    with pytest.raises(TaskError, match=r"^t.toml: placement: must be a table"):
        loads_task(TASK.replace('name = "t"', 'name = "t"\nplacement = 3'), "t.toml")


def test_a_keep_out_on_the_edge_of_a_fixed_line_leaves_it():
    # keep-out rectangles are open: a base on a fixed y at the rectangle's edge is allowed
    r = _task("x = [0, 10]\ny = [2, 2]\nkeep_out = [[-1, 11, 2, 4]]").region
    assert r.allowed(np.array([[5, 2, 0, 0, 0, 0]]))[0]


def test_z_defaults_to_the_cells_placement_height(tmp_path):
    (tmp_path / "cell.toml").write_text('length_unit = "m"\n[robot]\nxyz = [0, 0, 0.25]\n')
    text = TASK.replace('name = "t"', 'name = "t"\ncell = "cell.toml"') + "[placement]\nx = [0, 1]\ny = [0, 1]\n"
    t = loads_task(text, str(tmp_path / "t.toml"), tmp_path)
    assert t.region.z == pytest.approx((0.25, 0.25))


def test_placement_region_overrides_a_base_key_by_key():
    base = PlacementRegion((0, 1), (0, 1), (0.5, 0.5), (0, 0), 0.1, ((0.2, 0.3, 0.2, 0.3),))
    r = placement_region({"yaw": [-90, 90]}, "mm", "deg", base=base)
    assert (r.x, r.y, r.z, r.tilt, r.keep_out) == (base.x, base.y, base.z, base.tilt, base.keep_out)
    assert r.yaw == pytest.approx((-math.pi / 2, math.pi / 2))
    r = placement_region({"x": [100, 200], "keep_out": []}, "mm", "deg", base=base)
    assert r.x == pytest.approx((0.1, 0.2)) and r.keep_out == () and r.yaw == base.yaw
    with pytest.raises(TaskError) as e:
        placement_region({"x": [2, 1]}, base=base, fields={"x": "--region XMIN XMAX"})
    assert str(e.value).startswith("--region XMIN XMAX: must be [low, high]")
