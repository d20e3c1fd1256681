"""The [geometry] table of robot files (kin/robotfile.py): bodies by name, shapes in the file's units,
boxes and cylinders enclosed by capsules with their over-estimate, allowed pairs, every error one line
naming the file, the shape table and the field; load → dump → load gives an identical chain; convention
changes keep every capsule where it was."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.geometry import body_frames, default_geometry, default_radius
from kin.geometry.enclose import enclose_box, enclose_cylinder
from kin.robotfile import MAX_SHAPES, dumps_robot, loads_robot
from kin.transforms import make_transform, rpy_to_matrix

ARM = """\
name = "arm"
convention = "standard"
length_unit = "mm"
angle_unit = "deg"

[[joints]]
name = "J1"
type = "revolute"
d = 300.0
alpha = -90.0
limits = [-170.0, 170.0]

[[joints]]
name = "J2"
type = "revolute"
a = 400.0
limits = [-120.0, 120.0]

[[joints]]
type = "revolute"
a = 300.0
limits = [-150.0, 150.0]

[tool]
xyz = [0.0, 0.0, 100.0]
"""

SHAPES = ARM + """
[geometry]
source = "a test arm's outline"
allow = [["base", "J2"], ["link 3", "base"]]

[[geometry.capsule]]
body = "J2"
a = [-400.0, 0.0, 0.0]
b = [0.0, 0.0, 0.0]
radius = 60.0
name = "upper arm"

[[geometry.sphere]]
body = "base"
center = [0.0, 0.0, 150.0]
radius = 120.0

[[geometry.box]]
body = "link 3"
center = [-150.0, 0.0, 0.0]
size = [300.0, 80.0, 60.0]

[[geometry.cylinder]]
body = "tool"
center = [0.0, 0.0, -50.0]
rpy = [0.0, 0.0, 30.0]
radius = 30.0
length = 100.0
"""


def bad(text: str) -> kin.RobotFileError:
    with pytest.raises(kin.RobotFileError) as e:
        loads_robot(text, "arm.toml")
    assert str(e.value).startswith("arm.toml: ") and "\n" not in str(e.value)
    return e.value


def test_no_geometry_table_means_defaults():
    chain = loads_robot(ARM)
    assert chain.geometry is None
    g = kin.Robot(chain).geometry
    assert g.source == "default" and g.radius == pytest.approx(default_radius(chain))


def test_shapes_in_file_units_on_named_bodies():
    chain = loads_robot(SHAPES)
    g = chain.geometry
    assert g.source == "a test arm's outline" and g.radius is None
    by_name = {c.name: c for c in g.capsules}
    upper = by_name["upper arm"]
    assert (upper.body, upper.a, upper.b, upper.radius) == (2, (-0.4, 0.0, 0.0), (0.0, 0.0, 0.0), 0.06)
    ball = by_name["base sphere"]
    assert (ball.body, ball.a, ball.b) == (0, (0.0, 0.0, 0.15), (0.0, 0.0, 0.15)) and ball.radius == pytest.approx(0.12)
    # the box and the cylinder are the capsules kin.geometry.enclose makes of them
    box = by_name["link 3 box"]
    T = make_transform(np.eye(3), [-0.15, 0.0, 0.0])
    (ref,) = enclose_box([0.3, 0.08, 0.06], T).capsules
    assert box.body == 3 and box.radius == pytest.approx(ref.radius, rel=1e-12)
    np.testing.assert_allclose([box.a, box.b], [ref.a, ref.b], atol=1e-15)
    cyl = by_name["tool cylinder"]
    enc = enclose_cylinder(0.03, 0.1, make_transform(rpy_to_matrix([0, 0, math.radians(30)]), [0, 0, -0.05]))
    assert cyl.body == 4 and cyl.radius == pytest.approx(enc.capsules[0].radius, rel=1e-12)
    # the over-estimate is the largest of the enclosures'
    assert g.over_estimate == pytest.approx(max(enclose_box([0.3, 0.08, 0.06]).over_estimate, enc.over_estimate))
    assert g.allowed == frozenset({(0, 2), (0, 3)})


def test_radius_only_gives_default_capsules_of_that_radius():
    chain = loads_robot(ARM + "\n[geometry]\nradius = 50\nallow = [[\"link 1\", \"tool\"]]\n")
    g = chain.geometry
    ref = default_geometry(chain, 0.05)
    assert g.capsules == ref.capsules and g.radius == 0.05 and g.source == "default"
    assert g.allowed == frozenset({(1, 4)})
    # an empty table: the default radius, stated
    g = loads_robot(ARM + "\n[geometry]\n").geometry
    assert g.radius == pytest.approx(default_radius(loads_robot(ARM)))


@pytest.mark.parametrize("text", [SHAPES, ARM + "\n[geometry]\nradius = 50\n", ARM + "\n[geometry]\n",
                                  ARM + '\n[geometry]\nallow = [["J1", "J2"]]\n[[geometry.box]]\nbody = "tool"\n'
                                        'center = [1.0, 2.0, 3.0]\nsize = [10.0, 20.0, 30.0]\nrpy = [1.0, 2.0, 3.0]\n'])
@pytest.mark.parametrize("units", [None, ("mm", "rad"), ("in", "rad"), ("m", "deg")])
def test_round_trip_identical(text, units):
    """In the file's own units load → dump → load is exact; in other units the values are those up to
    rounding, and exact from then on."""
    chain = loads_robot(text)
    if units is not None:
        chain = kin.robotfile.with_units(chain, *units)
    again = loads_robot(dumps_robot(chain))
    if units is None:
        assert again == chain and again.geometry == chain.geometry
    else:
        for c, d in zip(chain.geometry.capsules, again.geometry.capsules, strict=True):
            assert (c.body, c.name) == (d.body, d.name)
            np.testing.assert_allclose([*c.a, *c.b, c.radius], [*d.a, *d.b, d.radius], rtol=1e-15, atol=1e-16)
        assert again.geometry.allowed == chain.geometry.allowed
        assert again.geometry.over_estimate == pytest.approx(chain.geometry.over_estimate, rel=1e-15)
    assert loads_robot(dumps_robot(again)) == again


def test_dump_writes_capsules_and_over_estimate():
    text = dumps_robot(loads_robot(SHAPES))
    assert "[[geometry.box]]" not in text and text.count("[[geometry.capsule]]") == 4
    assert "over_estimate = " in text and 'source = "a test arm\'s outline"' in text
    assert 'allow = [["base", "J2"], ["base", "link 3"]]' in text
    assert 'body = "J2"' in text and 'body = "tool"' in text


def test_bodies_named_by_joint_name_link_k_base_and_tool():
    for body, k in (("base", 0), ("J1", 1), ("link 1", 1), ("J2", 2), ("link 2", 2), ("link 3", 3), ("tool", 4)):
        text = ARM + f'\n[[geometry.sphere]]\nbody = "{body}"\ncenter = [0, 0, 0]\nradius = 1\n'
        assert loads_robot(text).geometry.capsules[0].body == k, body


def test_convention_change_keeps_capsules_in_place():
    chain = loads_robot(SHAPES)
    Q = np.random.default_rng(2).uniform(chain.lower, chain.upper, size=(20, chain.n))

    def world(c):
        F = body_frames(c, Q)
        out = []
        for cap in c.geometry.capsules:
            T = F[:, cap.body]
            out.append(np.stack([T[:, :3, :3] @ np.array(p) + T[:, :3, 3] for p in (cap.a, cap.b)]))
        return np.array(out), [cap.radius for cap in c.geometry.capsules]

    ref, radii = world(chain)
    mod = chain.to_modified()
    got, radii2 = world(mod)
    np.testing.assert_allclose(got, ref, atol=1e-12)
    assert radii2 == radii
    back = mod.to_standard()
    np.testing.assert_allclose(world(back)[0], ref, atol=1e-12)


def test_default_capsules_follow_design_parameters():
    text = ARM.replace("a = 400.0", 'a = "L2"') + "\n[parameters.L2]\nvalue = 400.0\nbounds = [300.0, 500.0]\n"
    chain = loads_robot(text + "\n[geometry]\nradius = 50\n")
    longer = chain.with_parameters({"L2": 0.45})
    assert longer.geometry.capsules == default_geometry(longer, 0.05).capsules != chain.geometry.capsules


@pytest.mark.parametrize("extra, field, words", [
    ("[geometry]\ncolour = 1\n", "geometry.colour", "unknown field"),
    ("[geometry]\nradius = -5\n", "geometry.radius", "positive"),
    ("[geometry]\nradius = 0\n", "geometry.radius", "positive"),
    ("[geometry]\nradius = nan\n", "geometry.radius", "finite"),
    ("[geometry]\nradius = 5\n[[geometry.sphere]]\nbody = \"base\"\ncenter = [0, 0, 0]\nradius = 1\n",
     "geometry.radius", "no shapes"),
    ("[geometry]\nover_estimate = 3\n", "geometry.over_estimate", "listed shapes"),
    ("[geometry]\nallow = [[\"base\"]]\n", "geometry.allow[0]", "pair of body names"),
    ("[geometry]\nallow = [[\"base\", \"base\"]]\n", "geometry.allow[0]", "twice"),
    ("[geometry]\nallow = [[\"base\", \"elbow\"]]\n", "geometry.allow[0][1]", "not a body; allowed: base, link 1"),
    ("[geometry]\nallow = \"base\"\n", "geometry.allow", "list"),
    ("[geometry.capsule]\nbody = \"base\"\n", "geometry.capsule", "[[geometry.capsule]]"),
    ("[[geometry.capsule]]\nbody = \"base\"\na = [0, 0, 0]\nb = [0, 0, 1]\n", "geometry.capsule[0].radius",
     "missing required field"),
    ("[[geometry.capsule]]\nbody = \"link 4\"\na = [0, 0, 0]\nb = [0, 0, 1]\nradius = 1\n", "geometry.capsule[0].body",
     "not a body"),
    ("[[geometry.capsule]]\nbody = 2\na = [0, 0, 0]\nb = [0, 0, 1]\nradius = 1\n", "geometry.capsule[0].body",
     "must be a string"),
    ("[[geometry.capsule]]\nbody = \"J1\"\na = [0, 0]\nb = [0, 0, 1]\nradius = 1\n", "geometry.capsule[0].a",
     "list of 3 numbers"),
    ("[[geometry.capsule]]\nbody = \"J1\"\na = [0, 0, 1e20]\nb = [0, 0, 1]\nradius = 1\n", "geometry.capsule[0].a[2]",
     "outside the allowed range"),
    ("[[geometry.capsule]]\nbody = \"J1\"\na = [0, 0, 0]\nb = [0, 0, 1]\nradius = 0\n", "geometry.capsule[0].radius",
     "positive"),
    ("[[geometry.capsule]]\nbody = \"J1\"\na = [0, 0, 0]\nb = [0, 0, 1]\nradius = 1\nrpy = [0, 0, 0]\n",
     "geometry.capsule[0].rpy", "unknown field"),
    ("[[geometry.sphere]]\nbody = \"J1\"\ncenter = [0, 0, 0]\nradius = true\n", "geometry.sphere[0].radius",
     "must be a number"),
    ("[[geometry.box]]\nbody = \"J1\"\ncenter = [0, 0, 0]\nsize = [1, 0, 1]\n", "geometry.box[0].size[1]", "positive"),
    ("[[geometry.box]]\nbody = \"J1\"\ncenter = [0, 0, 0]\nsize = [1, 1, 1]\nrpy = [0, 0, 5000]\n",
     "geometry.box[0].rpy[2]", "exceeds"),
    ("[[geometry.cylinder]]\nbody = \"tool\"\ncenter = [0, 0, 0]\nradius = 1\n", "geometry.cylinder[0].length",
     "missing required field"),
    ("[[geometry.cylinder]]\nbody = \"tool\"\ncenter = [0, 0, 0]\nradius = 1\nlength = -1\n",
     "geometry.cylinder[0].length", "positive"),
    ("[[geometry.sphere]]\nbody = \"tool\"\ncenter = [0, 0, 0]\nradius = 1\nname = 3\n", "geometry.sphere[0].name",
     "must be a string"),
])
def test_bad_geometry(extra, field, words):
    e = bad(ARM + "\n" + extra)
    assert e.field == field, str(e)
    assert words in str(e)


def test_reserved_and_duplicate_body_names():
    # base, tool and link k always mean those bodies, whatever the joints are called
    text = ARM.replace('name = "J1"', 'name = "base"').replace('name = "J2"', 'name = "link 3"')
    for body, k in (("base", 0), ("link 1", 1), ("link 3", 3), ("link 2", 2)):
        chain = loads_robot(text + f'\n[[geometry.sphere]]\nbody = "{body}"\ncenter = [0, 0, 0]\nradius = 1\n')
        assert chain.geometry.capsules[0].body == k
        assert loads_robot(dumps_robot(chain)) == chain      # the dump never writes a name meaning another body
    text = ARM.replace('name = "J2"', 'name = "J1"')
    e = bad(text + '\n[[geometry.sphere]]\nbody = "J1"\ncenter = [0, 0, 0]\nradius = 1\n')
    assert e.field == "geometry.sphere[0].body" and "names joints 1, 2; use 'link k'" in str(e)


def test_too_many_shapes():
    sphere = '[[geometry.sphere]]\nbody = "base"\ncenter = [0, 0, 0]\nradius = 1\n'
    e = bad(ARM + "\n" + sphere * (MAX_SHAPES + 1))
    assert e.field == "geometry" and f"at most {MAX_SHAPES}" in str(e)


def test_geometry_mutations_only_ever_raise_robot_file_error():
    lines = SHAPES.splitlines()
    start = lines.index("[geometry]")
    values = ['"x"', "1", "-2.5", "true", "[]", "[1.0, 2.0]", '["a", 1]', "{}", "nan", '[["base"]]', "1e400"]
    for i in range(start, len(lines)):
        line = lines[i]
        variants = ["\n".join(lines[:i] + lines[i + 1:])]
        if " = " in line:
            key = line.split(" = ")[0]
            variants += ["\n".join(lines[:i] + [f"{key} = {v}"] + lines[i + 1:]) for v in values]
        for text in variants:
            try:
                loads_robot(text, "m.toml")
            except kin.RobotFileError as e:
                assert str(e).startswith("m.toml")


def test_chain_refuses_capsules_on_missing_bodies():
    from dataclasses import replace

    from kin.geometry import LinkCapsule, RobotGeometry
    chain = loads_robot(ARM)
    with pytest.raises(kin.ChainError, match="body 5"):
        replace(chain, geometry=RobotGeometry((LinkCapsule(5, (0, 0, 0), (0, 0, 0), 0.1),)))


def test_sub_nanometre_coordinates_read_as_zero():
    text = ARM + '\n[[geometry.capsule]]\nbody = "J1"\na = [1e-9, -3e-7, 5.0]\nb = [0, 0, 0]\nradius = 1\n'
    (c,) = loads_robot(text).geometry.capsules
    assert c.a == (0.0, 0.0, 0.005)              # mm: 1e-9 mm and 3e-7 mm are below 1 nm
