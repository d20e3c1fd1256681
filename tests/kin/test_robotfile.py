"""kin.robotfile: every kind of bad robot file gives a RobotFileError whose message names the field
(and the allowed values where there is a choice); load → dump → load gives an identical chain;
atomic save; unknown robot names."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kin
from kin.errors import RobotFileError
from kin.robotfile import dumps_robot, load_chain, loads_robot, save_robot
from tests.dh_numpy import fk_numpy

DEG = math.pi / 180

GOOD = """\
name = "arm"
title = "A test arm"
convention = "standard"
length_unit = "mm"
angle_unit = "deg"

[[joints]]
type = "revolute"
a = 100.0
alpha = -90.0
d = 250.0
limits = [-170.0, 170.0]

[[joints]]
type = "prismatic"
a = 0.0
theta = 90.0
limits = [10.0, 300.0]
max_velocity = 500.0
"""


def edit(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def bad(text: str) -> kin.RobotFileError:
    with pytest.raises(kin.RobotFileError) as e:
        loads_robot(text, "arm.toml")
    return e.value


def test_good_file_loads_in_si():
    c = loads_robot(GOOD)
    np.testing.assert_allclose(c.dh_table(), [[0.1, -math.pi / 2, 0.25, 0.0], [0.0, 0.0, 0.0, math.pi / 2]],
                               atol=1e-15)
    np.testing.assert_allclose(c.limits, [[-170 * DEG, 170 * DEG], [0.01, 0.3]], atol=1e-15)
    assert c.joints[1].max_velocity == pytest.approx(0.5)


# ================================================================= missing required fields
@pytest.mark.parametrize("field", ["name", "convention", "length_unit", "angle_unit"])
def test_missing_top_field(field):
    text = re.sub(rf"^{field} = .*\n", "", GOOD, count=1, flags=re.M)
    assert text != GOOD
    e = bad(text)
    assert e.field == field and field in str(e) and "missing" in str(e) and "arm.toml" in str(e)


def test_missing_joints():
    e = bad(GOOD.split("[[joints]]")[0])
    assert e.field == "joints" and "missing" in str(e)


def test_missing_joint_type_lists_types():
    e = bad(edit(GOOD, 'type = "prismatic"\n', ""))
    assert e.field == "joints[1].type" and "missing" in str(e)
    assert "revolute" in str(e) and "prismatic" in str(e)


def test_missing_joint_limits():
    e = bad(edit(GOOD, "limits = [10.0, 300.0]\n", ""))
    assert e.field == "joints[1].limits" and "missing" in str(e) and "lower, upper" in str(e)


def test_missing_parameter_value():
    text = edit(GOOD, "a = 100.0", 'a = "L1"') + "\n[parameters.L1]\nbounds = [50.0, 150.0]\n"
    e = bad(text)
    assert e.field == "parameters.L1.value" and "missing" in str(e)


# ============================================================================ unknown fields
def test_unknown_top_field_lists_allowed():
    e = bad("colour = \"red\"\n" + GOOD)
    assert e.field == "colour" and "unknown field" in str(e)
    for allowed in ("name", "convention", "length_unit", "angle_unit", "joints", "base", "tool", "parameters"):
        assert allowed in str(e)


def test_unknown_joint_field_lists_allowed():
    e = bad(edit(GOOD, "d = 250.0", "d = 250.0\noffset = 3.0"))
    assert e.field == "joints[0].offset" and "unknown field" in str(e)
    for allowed in ("type", "a", "alpha", "d", "theta", "limits", "max_velocity"):
        assert allowed in str(e)


def test_unknown_base_field():
    e = bad(GOOD + "\n[base]\nxyz = [0.0, 0.0, 0.0]\nquat = [1.0, 0.0, 0.0, 0.0]\n")
    assert e.field == "base.quat" and "xyz, rpy, matrix" in str(e)


# ================================================================================ wrong types
@pytest.mark.parametrize("old, new, field", [
    ("limits = [-170.0, 170.0]", 'limits = ["-170", 170.0]', "joints[0].limits[0]"),
    ("max_velocity = 500.0", 'max_velocity = "fast"', "joints[1].max_velocity"),
    ("a = 100.0", "a = true", "joints[0].a"),
    ("limits = [10.0, 300.0]", "limits = [false, 300.0]", "joints[1].limits[0]"),
    ("d = 250.0", "d = [250.0]", "joints[0].d"),
])
def test_wrong_type_where_number(old, new, field):
    e = bad(edit(GOOD, old, new))
    assert e.field == field and "must be a number" in str(e)


def test_string_field_given_a_number():
    e = bad(edit(GOOD, 'name = "arm"', "name = 7"))
    assert e.field == "name" and "must be a string" in str(e)


def test_limits_wrong_length():
    e = bad(edit(GOOD, "limits = [-170.0, 170.0]", "limits = [-170.0, 0.0, 170.0]"))
    assert e.field == "joints[0].limits" and "list of 2 numbers" in str(e)


def test_negative_max_velocity():
    e = bad(edit(GOOD, "max_velocity = 500.0", "max_velocity = -5.0"))
    assert e.field == "joints[1].max_velocity" and "positive" in str(e)


# ============================================================================ unknown choices
@pytest.mark.parametrize("old, new, field, allowed", [
    ('type = "revolute"', 'type = "spherical"', "joints[0].type", ("revolute", "prismatic")),
    ('convention = "standard"', 'convention = "craig"', "convention", ("standard", "modified")),
    ('length_unit = "mm"', 'length_unit = "cm"', "length_unit", ("m", "mm", "in")),
    ('angle_unit = "deg"', 'angle_unit = "grad"', "angle_unit", ("rad", "deg")),
])
def test_unknown_choice_lists_allowed(old, new, field, allowed):
    e = bad(edit(GOOD, old, new))
    assert e.field == field and "not allowed" in str(e)
    for a in allowed:
        assert a in str(e).split("allowed:")[1]


def test_unknown_task_row():
    e = bad(edit(GOOD, 'angle_unit = "deg"', 'angle_unit = "deg"\ntask = ["x", "roll"]'))
    assert e.field == "task[1]" and "rx" in str(e)


# ==================================================================================== limits
def test_reversed_limits():
    e = bad(edit(GOOD, "limits = [-170.0, 170.0]", "limits = [170.0, -170.0]"))
    assert e.field == "joints[0].limits" and "reversed" in str(e)


def test_empty_limits():
    e = bad(edit(GOOD, "limits = [10.0, 300.0]", "limits = [10.0, 10.0]"))
    assert e.field == "joints[1].limits" and "empty" in str(e)


def test_degree_limit_in_radian_file():
    text = edit(GOOD, 'angle_unit = "deg"', 'angle_unit = "rad"')
    text = edit(text, "alpha = -90.0", "alpha = -1.5707963267948966")
    text = edit(text, "theta = 90.0", "theta = 1.5707963267948966")
    e = bad(text)
    assert e.field == "joints[0].limits" and "degree" in str(e)
    # the same numbers in a degree file are fine, and 3 rad is fine in a radian file
    loads_robot(GOOD)
    loads_robot(edit(text, "limits = [-170.0, 170.0]", "limits = [-3.0, 3.0]"))


# ============================================================================ non-finite numbers
@pytest.mark.parametrize("old, new, field", [
    ("a = 100.0", "a = nan", "joints[0].a"),
    ("d = 250.0", "d = inf", "joints[0].d"),
    ("limits = [-170.0, 170.0]", "limits = [-inf, 170.0]", "joints[0].limits[0]"),
    ("limits = [10.0, 300.0]", "limits = [10.0, nan]", "joints[1].limits[1]"),
    ("theta = 90.0", "theta = -inf", "joints[1].theta"),
])
def test_nan_and_inf(old, new, field):
    e = bad(edit(GOOD, old, new))
    assert e.field == field and "finite" in str(e)


def test_nan_in_base_and_parameter():
    e = bad(GOOD + "\n[base]\nxyz = [0.0, nan, 0.0]\n")
    assert e.field == "base.xyz[1]" and "finite" in str(e)
    text = edit(GOOD, "a = 100.0", 'a = "L1"') + "\n[parameters.L1]\nvalue = 100.0\nbounds = [50.0, inf]\n"
    e = bad(text)
    assert e.field == "parameters.L1.bounds[1]" and "finite" in str(e)


# ================================================================================ parameters
def test_undefined_parameter():
    e = bad(edit(GOOD, "a = 100.0", 'a = "L1"'))
    assert e.field == "joints[0].a" and "'L1'" in str(e) and "undefined" in str(e)
    text = edit(GOOD, "a = 100.0", 'a = "L1"') + "\n[parameters.L2]\nvalue = 100.0\nbounds = [50.0, 150.0]\n"
    e = bad(text)
    assert "'L1'" in str(e) and "L2" in str(e)  # names the defined ones


def test_parameter_used_as_length_and_angle():
    text = edit(GOOD, "a = 100.0", 'a = "P"')
    text = edit(text, "theta = 90.0", 'theta = "P"')
    text += "\n[parameters.P]\nvalue = 10.0\nbounds = [0.0, 20.0]\n"
    e = bad(text)
    assert e.field == "joints[1].theta" and "'P'" in str(e) and "length" in str(e) and "angle" in str(e)


@pytest.mark.parametrize("value, bounds, field, word", [
    ("170.0", "[50.0, 150.0]", "parameters.L1.value", "outside"),
    ("100.0", "[150.0, 50.0]", "parameters.L1.bounds", "reversed"),
])
def test_parameter_bounds(value, bounds, field, word):
    text = edit(GOOD, "a = 100.0", 'a = "L1"') + f"\n[parameters.L1]\nvalue = {value}\nbounds = {bounds}\n"
    e = bad(text)
    assert e.field == field and word in str(e)


def test_parameter_unknown_field():
    text = edit(GOOD, "a = 100.0", 'a = "L1"') + "\n[parameters.L1]\nvalue = 1.0\nbounds = [0.0, 2.0]\nstep = 1.0\n"
    e = bad(text)
    assert e.field == "parameters.L1.step" and "value, bounds" in str(e)


def test_parameters_scaled_by_use():
    text = edit(GOOD, "a = 100.0", 'a = "L1"')
    text = edit(text, "theta = 90.0", 'theta = "TH"')
    text += "\n[parameters.L1]\nvalue = 100.0\nbounds = [50.0, 150.0]\n"
    text += "\n[parameters.TH]\nvalue = 90.0\nbounds = [0.0, 180.0]\n"
    c = loads_robot(text)
    assert c.parameters["L1"].kind == "length" and c.parameters["TH"].kind == "angle"
    assert c.parameters["L1"].value == pytest.approx(0.1) and c.parameters["L1"].bounds == pytest.approx((0.05, 0.15))
    assert c.parameters["TH"].value == pytest.approx(math.pi / 2)
    assert c.parameters["TH"].bounds == pytest.approx((0.0, math.pi))


@pytest.mark.parametrize("value", ["5", "5.5", "true", "1979-05-27", "[1]", '"L1"'])
def test_parameters_not_a_table(value):
    e = bad(edit(GOOD, 'angle_unit = "deg"', f'angle_unit = "deg"\nparameters = {value}'))
    assert e.field == "parameters" and "must be a table" in str(e)


def test_round_trip_parameter_name_needing_quotes():
    text = edit(GOOD, "a = 100.0", 'a = "L 1.x"') + '\n[parameters."L 1.x"]\nvalue = 100.0\nbounds = [50.0, 150.0]\n'
    c = loads_robot(text)
    assert c.parameters["L 1.x"].value == pytest.approx(0.1)
    assert loads_robot(dumps_robot(c)) == c


# ================================================================================ placements
MATRIX = "matrix = [[1.0, 0.0, 0.0, 10.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]\n"


@pytest.mark.parametrize("old, new", [
    ("[1.0, 0.0, 0.0, 10.0]", "[1.1, 0.0, 0.0, 10.0]"),                                # scaled
    ("[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]", "[0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0]"),  # det -1
    ("[0.0, 0.0, 0.0, 1.0]]", "[0.0, 0.0, 1.0, 1.0]]"),                                # bottom row
    ("[1.0, 0.0, 0.0, 10.0]", "[1.0, 0.1, 0.0, 10.0]"),                                # sheared
])
def test_non_rigid_matrix(old, new):
    e = bad(GOOD + "\n[tool]\n" + edit(MATRIX, old, new))
    assert e.field == "tool.matrix" and "rigid" in str(e)


def test_rigid_matrix_loads_with_scaled_translation():
    c = loads_robot(GOOD + "\n[tool]\n" + MATRIX)
    np.testing.assert_allclose(c.tool.matrix[:3, 3], [0.01, 0.0, 0.0], atol=1e-17)


def test_matrix_and_xyz_together():
    e = bad(GOOD + "\n[base]\nxyz = [0.0, 0.0, 1.0]\n" + MATRIX)
    assert e.field == "base" and "either" in str(e)


def test_matrix_wrong_shape():
    e = bad(GOOD + "\n[base]\nmatrix = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]\n")
    assert e.field == "base.matrix" and "4 rows" in str(e)


def test_xyz_wrong_length():
    e = bad(GOOD + "\n[tool]\nxyz = [0.0, 1.0]\n")
    assert e.field == "tool.xyz" and "3 numbers" in str(e)


# ==================================================================================== others
def test_no_joints():
    e = bad(GOOD.split("[[joints]]")[0] + "joints = []\n")
    assert e.field == "joints" and "at least one" in str(e)


def test_invalid_toml():
    e = bad(GOOD + "\n[[joints]\ntype = \n")
    assert "not valid TOML" in str(e) and "arm.toml" in str(e)


@pytest.mark.parametrize("name", ["My Arm", "arm-2", "Arm", "", "arm/../x"])
def test_bad_name_pattern(name):
    e = bad(edit(GOOD, 'name = "arm"', f'name = "{name}"'))
    assert e.field == "name" and "[a-z0-9_]+" in str(e)


def test_load_chain_file_errors_name_the_file(tmp_path):
    p = tmp_path / "broken.toml"
    p.write_text(edit(GOOD, 'type = "revolute"', 'type = "rotary"'))
    with pytest.raises(kin.RobotFileError) as e:
        load_chain(p)
    assert str(p) in str(e.value) and "joints[0].type" in str(e.value)
    p.write_bytes(b"\xff\xfe\x00bad")
    with pytest.raises(kin.RobotFileError, match="not UTF-8 text"):
        load_chain(p)


def test_unknown_robot_lists_bundled():
    with pytest.raises(kin.UnknownRobotError) as e:
        kin.load_robot("puma_9000")
    msg = str(e.value)
    assert "puma_9000" in msg
    for name in kin.bundled_robots():
        assert name in msg
    assert set(kin.bundled_robots()) >= {"puma560", "fanuc_m16ib20", "scara_rrp"}


def test_missing_robot_path():
    with pytest.raises(kin.UnknownRobotError, match="no such robot file"):
        kin.load_robot("/nonexistent/dir/arm.toml")


VALUES = ['"x"', "1", "-2.5", "true", "[]", "[1.0, 2.0]", '["a", 1]', "{}", "{ a = 1 }", "nan", "1979-05-27",
          '[[1.0, 0.0], [0.0, 1.0]]', '"revolute"', '"L1"', "1e400"]


def test_mutations_only_ever_raise_robot_file_error():
    """Any value in any field replaced by a value of another type, or any line deleted: the loader
    either accepts the file or raises RobotFileError — never a TypeError/KeyError/... from inside."""
    base = (edit(GOOD, "a = 100.0", 'a = "L1"') + "\n[parameters.L1]\nvalue = 100.0\nbounds = [50.0, 150.0]\n"
            + "\n[tool]\nxyz = [0.0, 0.0, 10.0]\nrpy = [0.0, 90.0, 0.0]\n")
    lines = base.splitlines()
    count = 0
    for i, line in enumerate(lines):
        variants = ["\n".join(lines[:i] + lines[i + 1:])]
        if " = " in line:
            key = line.split(" = ")[0]
            variants += ["\n".join(lines[:i] + [f"{key} = {v}"] + lines[i + 1:]) for v in VALUES]
        for text in variants:
            count += 1
            try:
                loads_robot(text, "m.toml")
            except kin.RobotFileError as e:
                assert str(e).startswith("m.toml")
    assert count > 200


# ================================================================================ round trip
def _num(rng, lo, hi) -> str:
    return repr(float(rng.uniform(lo, hi)))


def random_robot_text(seed: int, length_unit: str, angle_unit: str, placement: str) -> str:
    """A random robot file in the given units (numbers with full float precision)."""
    rng = np.random.default_rng(seed)
    L = {"m": 1.0, "mm": 1000.0, "in": 39.37}[length_unit]
    A = 180.0 if angle_unit == "deg" else math.pi
    n = int(rng.integers(2, 8))
    lines = [f'name = "rand_{seed}"', 'title = "Random \\"quoted\\" arm\\nline two"', 'source = "C:\\\\robots"',
             f'convention = "{"standard" if seed % 2 else "modified"}"',
             f'length_unit = "{length_unit}"', f'angle_unit = "{angle_unit}"']
    if seed % 3 == 0:
        lines.append('task = ["x", "y", "z"]')
    params = []
    for i in range(n):
        rev = rng.uniform() < 0.7
        lines += ["", "[[joints]]", f'name = "j{i}"', f'type = "{"revolute" if rev else "prismatic"}"']
        for f in ("a", "alpha", "d", "theta"):
            if rng.uniform() < 0.2:
                pname = f"p_{i}_{f}"
                params.append((pname, f))
                lines.append(f'{f} = "{pname}"')
            else:
                lines.append(f"{f} = {_num(rng, -L, L) if f in 'ad' else _num(rng, -A, A)}")
        if rev:
            lines.append(f"limits = [{_num(rng, -A, -0.1 * A)}, {_num(rng, 0.1 * A, A)}]")
        else:
            lines.append(f"limits = [{_num(rng, -L, 0)}, {_num(rng, 0.01 * L, L)}]")
        if rng.uniform() < 0.5:
            lines.append(f"max_velocity = {_num(rng, 0.1, 10)}")
            lines.append(f"max_acceleration = {_num(rng, 0.1, 10)}")
    for label in ("base", "tool"):
        lines += ["", f"[{label}]"]
        if placement == "xyz":
            lines.append(f"xyz = [{_num(rng, -L, L)}, {_num(rng, -L, L)}, {_num(rng, -L, L)}]")
            lines.append(f"rpy = [{_num(rng, -A, A)}, {_num(rng, -A, A)}, {_num(rng, -A, A)}]")
        else:
            T = np.eye(4)
            T[:3, :3] = Rotation.from_rotvec(rng.uniform(-2, 2, 3)).as_matrix()
            T[:3, 3] = rng.uniform(-L, L, 3)
            lines.append("matrix = ["
                         + ", ".join("[" + ", ".join(repr(float(x)) for x in row) + "]" for row in T) + "]")
    for pname, f in params:
        s = L if f in "ad" else A
        v = rng.uniform(-s, s)
        lines += ["", f"[parameters.{pname}]", f"value = {v!r}",
                  f"bounds = [{v - rng.uniform(0, s)!r}, {v + rng.uniform(0, s)!r}]"]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("units", [("mm", "deg"), ("in", "deg"), ("m", "rad")], ids=lambda u: "/".join(u))
@pytest.mark.parametrize("placement", ["xyz", "matrix"])
@pytest.mark.parametrize("seed", range(6))
def test_round_trip_identical(units, placement, seed):
    text = random_robot_text(seed, *units, placement)
    c = loads_robot(text)
    again = loads_robot(dumps_robot(c))
    assert again == c
    assert dumps_robot(again) == dumps_robot(c)
    # the first load really converted units: compare with the numbers written in the file
    L = {"m": 1.0, "mm": 1e-3, "in": 0.0254}[units[0]]
    first_d = re.search(r"\[\[joints\]\][^\[]*?\nd = (\S+)", text)
    if first_d and not first_d.group(1).startswith('"'):
        assert c.joints[0].d == pytest.approx(float(first_d.group(1)) * L, rel=1e-15)


def test_round_trip_keeps_fk(tmp_path):
    text = random_robot_text(11, "in", "deg", "matrix")
    c = loads_robot(text)
    path = save_robot(c, tmp_path / "r.toml")
    c2 = load_chain(path)
    rng = np.random.default_rng(0)
    for q in rng.uniform(c.lower, c.upper, size=(5, c.n)):
        np.testing.assert_array_equal(fk_numpy(c2, q), fk_numpy(c, q))


def test_round_trip_strings_with_control_characters():
    text = edit(GOOD, 'title = "A test arm"', 'title = "tab\\there, cr\\rthere, bell\\u0007, del\\u007f"')
    c = loads_robot(text)
    assert c.title == "tab\there, cr\rthere, bell\x07, del\x7f"
    assert loads_robot(dumps_robot(c)) == c


@pytest.mark.parametrize("seed", range(8))
def test_programmatic_chain_round_trip(seed):
    """A chain built in SI with display units mm/deg saves and loads back to the same FK."""
    from kin.robotfile import with_units
    from tests.chain_factory import random_chain
    c = with_units(random_chain(seed, params=True, name="prog"), "mm", "deg")
    c2 = loads_robot(dumps_robot(c))
    assert c2.length_unit == "mm" and c2.angle_unit == "deg"
    rng = np.random.default_rng(1)
    for q in rng.uniform(c.lower, c.upper, size=(5, c.n)):
        np.testing.assert_allclose(fk_numpy(c2, q), fk_numpy(c, q), atol=1e-14)
    # every SI value that has an exact file-unit representation (some y with y·scale == x) comes back exactly
    exact = 0
    for j, j2 in zip(c.joints, c2.joints):
        for f, scale in (("a", 1e-3), ("alpha", DEG), ("d", 1e-3), ("theta", DEG)):
            x, x2 = getattr(j, f), getattr(j2, f)
            if isinstance(x, str):
                assert x2 == x
                continue
            y = x / scale
            candidates = [y]
            for direction in (math.inf, -math.inf):
                z = y
                for _ in range(4):
                    z = math.nextafter(z, direction)
                    candidates.append(z)
            if any(z * scale == x for z in candidates):
                assert x2 == x, (f, x, x2)
                exact += 1
            else:
                assert x2 == pytest.approx(x, rel=1e-15)
    assert exact >= 4


def test_programmatic_parameters_round_trip_in_file_units():
    from kin.chain import Chain, Joint, Parameter
    c = Chain(name="tw", joints=(Joint("revolute", a="L", alpha="TW"), Joint("prismatic", theta="TH", limits=(0, 1))),
              parameters={"L": Parameter(0.3, (0.1, 0.5)), "TW": Parameter(0.4, (-1.0, 1.0), "angle"),
                          "TH": Parameter(-0.2, (-1.0, 1.0), "angle")},
              length_unit="mm", angle_unit="deg")
    text = dumps_robot(c)
    assert "value = 300.0" in text                                     # 0.3 m in mm
    assert f"value = {0.4 / DEG!r}" in text or "value = 22.918" in text  # 0.4 rad in degrees
    c2 = loads_robot(text)
    for k in ("L", "TW", "TH"):
        assert c2.parameters[k].value == pytest.approx(c.parameters[k].value, rel=1e-15)
        assert c2.parameters[k].bounds == pytest.approx(c.parameters[k].bounds, rel=1e-15)
        assert c2.parameters[k].kind == c.parameters[k].kind


# ============================================================================== atomic save
def test_save_robot_atomic(tmp_path):
    c = loads_robot(GOOD)
    path = tmp_path / "arm.toml"
    path.write_text("old contents")
    out = save_robot(c, path)
    assert out == path and path.is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.toml"]  # no .tmp left behind
    assert load_chain(path) == c


def test_save_robot_failure_leaves_old_file(tmp_path, monkeypatch):
    """A write that dies half-way must not touch the existing file (it goes to a temporary first,
    which is removed)."""
    import os

    from kin.output import OutputError
    path = tmp_path / "arm.toml"
    path.write_text(GOOD)
    c = loads_robot(edit(GOOD, "a = 100.0", "a = 120.0"))
    real_fdopen = os.fdopen

    class HalfFile:
        def __init__(self, fh):
            self.fh = fh

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

        def write(self, data):
            self.fh.write(data[: len(data) // 2])
            raise OSError(28, "No space left on device")
    monkeypatch.setattr(os, "fdopen", lambda fd, mode: HalfFile(real_fdopen(fd, mode)))
    with pytest.raises(OutputError, match="No space left on device"):
        save_robot(c, path)
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.toml"]      # the temporary file is gone
    assert path.read_text() == GOOD


# ---- magnitudes: huge or vanishing lengths, angles beyond four turns --------------------------
@pytest.mark.parametrize("old,new,field", [
    ("a = 100.0", "a = 1e308", "joints[0].a"),                  # overflows every product
    ("a = 100.0", "a = 1e-300", "joints[0].a"),                 # zero in disguise
    ("d = 250.0", "d = 1.1e7", "joints[0].d"),                  # 11 km in mm
    ("d = 250.0", "d = 1e-7", "joints[0].d"),                   # 0.1 nm in mm
    ("limits = [10.0, 300.0]", "limits = [10.0, 1e300]", "joints[1].limits[1]"),
    ("alpha = -90.0", "alpha = 1e308", "joints[0].alpha"),
    ("theta = 90.0", "theta = 1441.0", "joints[1].theta"),     # just beyond ±1440° = ±8π
])
def test_magnitudes_outside_their_range_are_refused(old, new, field):
    with pytest.raises(RobotFileError, match=re.escape(field)) as e:
        loads_robot(edit(GOOD, old, new), "arm.toml")
    assert "\n" not in str(e.value) and ("allowed range" in str(e.value) or "exceeds" in str(e.value))


def test_magnitudes_at_the_edges_are_accepted():
    c = loads_robot(edit(edit(GOOD, "a = 100.0", "a = 1e-6"), "d = 250.0", "d = 1e7"))   # 1 nm, 10 km in mm
    assert c.joints[0].a == pytest.approx(1e-9) and c.joints[0].d == pytest.approx(1e4)
    c = loads_robot(edit(GOOD, "theta = 90.0", "theta = 1440.0"))
    assert c.joints[1].theta == pytest.approx(8 * math.pi)


def test_placement_and_parameter_magnitudes():
    with pytest.raises(RobotFileError, match=r"tool.xyz\[2\]"):
        loads_robot(GOOD + "\n[tool]\nxyz = [0.0, 0.0, 1e300]\n")
    with pytest.raises(RobotFileError, match=r"base.matrix\[0\]\[3\]"):
        loads_robot(GOOD + "\n[base]\nmatrix = [[1, 0, 0, 1e-300], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n")
    with pytest.raises(RobotFileError, match=r"parameters.L.bounds\[1\]"):
        loads_robot(edit(GOOD, "a = 100.0", 'a = "L"') + "\n[parameters.L]\nvalue = 100.0\nbounds = [0.0, 1e308]\n")
