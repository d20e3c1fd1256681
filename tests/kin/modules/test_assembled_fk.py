"""Issue 32: an assembled robot's forward kinematics is the product of its modules' transforms — checked
against a plain numpy product of the catalogue's own numbers (tests/kin/modules/plain.py: tomllib,
no kin.modules) to 1e-12 at random configurations, for assemblies with a prismatic module, bent and
offset links, an elbow whose axis is off its faces' z, twists, a tilted base and a rotated tool centre
point; and again after the robot file is written and read back.  Its bodies carry the modules' parts:
mass, centre of mass and inertia of each body equal the hand sum of its parts (parallel-axis), and a
part without an inertia gets its mass spread over its capsules as solid cylinders (closed form)."""
from __future__ import annotations

import numpy as np
import pytest

import kin
from kin.modules import Assembly, assemble, load_catalogue, loads_catalogue
from tests.dh_numpy import fk_numpy, frames_numpy
from tests.kin.modules.plain import FIXTURE, Plain

ASSEMBLIES = [
    "stand R80 L200@90 E80 L300b@180 P80 A80_63 R63@180 grip63",      # prismatic, bend, offset, adapter
    "wall R80@270 E80@90 L300b R80 grip",                              # tilted base, rotated TCP
    "stand P80 E80@90 E80@180 R80 L200@270 R80 grip",                  # 6 joints, parallel elbows
    "stand R80 R80@90 R80",                                            # coaxial joints, no tool
    "wall P80@180 P80@90 A80_63 R63",                                  # two prismatic modules
    "stand R80",                                                       # one joint
]


@pytest.fixture(scope="module")
def cat():
    return load_catalogue(FIXTURE)


@pytest.fixture(scope="module")
def plain():
    return Plain(FIXTURE)


def _random_q(plain, items, rng, k):
    lim = plain.limits(items)
    return rng.uniform(lim[:, 0], lim[:, 1], size=(k, len(lim)))


def _si(plain, items, q_file):
    scale = np.array([plain.as_ if m["type"] == "revolute" else plain.ls for m in plain.joints(items)])
    return np.asarray(q_file) * scale


@pytest.mark.parametrize("text", ASSEMBLIES)
def test_fk_is_the_product_of_the_modules_transforms(cat, plain, text, tmp_path):
    items = text.split()
    chain = assemble(cat, Assembly.parse(items, cat), name="arm", check_holding=False)
    robot = kin.Robot(chain, backend="vm")
    path = kin.save_robot(chain, tmp_path / "arm.toml")
    back = kin.Robot(kin.load_chain(path), backend="vm")
    assert chain.n == len(plain.joints(items))
    rng = np.random.default_rng(32)
    for qf in [np.zeros(chain.n), *_random_q(plain, items, rng, 12)]:
        ref = plain.tip(items, qf)                       # the modules' product, file units in, SI out
        q = _si(plain, items, qf)
        np.testing.assert_allclose(chain.to_si(qf), q, rtol=1e-15, atol=1e-15)
        for T in (robot.fk(q), fk_numpy(chain, q), back.fk(q), fk_numpy(back.chain, q)):
            np.testing.assert_allclose(np.asarray(T), ref, rtol=0, atol=1e-12)


def test_the_modules_product_is_not_the_identity_mapping(cat, plain):
    """The check above compares two different computations: a wrong twist or a left-out bend shows."""
    items = ASSEMBLIES[0].split()
    other = [*items[:3], "E80@180", *items[4:]]
    q = _random_q(plain, items, np.random.default_rng(1), 1)[0]
    chain = assemble(cat, Assembly.parse(items, cat), check_holding=False)
    assert np.abs(fk_numpy(chain, _si(plain, items, q)) - plain.tip(other, q)).max() > 1e-3


def _world_inertia(parts):
    """(mass, com, 3×3 inertia about the com) of parts given as (mass, world com, world inertia about
    their com): the sum by the parallel-axis theorem."""
    m = sum(p[0] for p in parts)
    c = sum(p[0] * p[1] for p in parts) / m
    inertia = np.zeros((3, 3))
    for mi, ci, Ii in parts:
        d = ci - c
        inertia += Ii + mi * (d @ d * np.eye(3) - np.outer(d, d))
    return m, c, inertia


def _tensor(v):
    ixx, iyy, izz, ixy, ixz, iyz = v
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


def _part(plain, raw, F):
    """A catalogue part's (mass, world com, world inertia) at frame F (its inertia in kg·mm²)."""
    ls = plain.ls
    m, local, com = raw["mass"], _tensor(raw["inertia"]) * ls * ls, np.array(raw["com"]) * ls
    R = F[:3, :3]
    return m, (F @ np.r_[com, 1.0])[:3], R @ local @ R.T


def test_bodies_carry_the_hand_sum_of_their_parts(cat, plain):
    """stand R80 L200 R80@90 grip: body 1 = R80's distal part + L200 (its mass spread over one capsule:
    a solid cylinder r = 40, length 200 mm along z) + the second R80's proximal part; body 2 = the second
    R80's distal part; the payload = grip.  Compared in the world at a random configuration."""
    items = "stand R80 L200 R80@90 grip".split()
    chain = assemble(cat, Assembly.parse(items, cat), check_holding=False)
    rng = np.random.default_rng(5)
    qf = _random_q(plain, items, rng, 1)[0]
    q = _si(plain, items, qf)
    fr = plain.frames(items, qf)
    R80, L200 = plain.mod["R80"], plain.mod["L200"]
    # L200: 1.2 kg over one capsule from (0,0,0) to (0,0,200) mm, radius 40 mm: a solid cylinder
    cap = L200["capsule"][0]
    assert cap["a"] == [0, 0, 0] and cap["b"] == [0, 0, 200] and "com" not in L200["inertial"]
    m, r, L = L200["inertial"]["mass"], cap["radius"] * plain.ls, 0.200
    link_local = np.diag([m * (3 * r * r + L * L) / 12, m * (3 * r * r + L * L) / 12, m * r * r / 2])
    F_link = fr[2][0]
    link = (m, (F_link @ np.array([0, 0, 0.1, 1.0]))[:3], F_link[:3, :3] @ link_local @ F_link[:3, :3].T)
    body1 = [_part(plain, R80["distal_inertial"], fr[1][1]), link, _part(plain, R80["inertial"], fr[3][0])]
    body2 = [_part(plain, R80["distal_inertial"], fr[3][1])]
    tool = [_part(plain, plain.mod["grip"]["inertial"], fr[4][0])]
    frames = frames_numpy(chain, q)
    for k, parts in ((1, body1), (2, body2)):
        li = chain.joints[k - 1].inertia
        F = frames[k]
        mass, com, inertia = _world_inertia(parts)
        assert li.mass == pytest.approx(mass, rel=1e-14)
        np.testing.assert_allclose((F @ np.r_[li.com, 1.0])[:3], com, atol=1e-14)
        R = F[:3, :3]
        np.testing.assert_allclose(R @ li.tensor @ R.T, inertia, atol=1e-14)
    mass, com, inertia = _world_inertia(tool)
    T = fk_numpy(chain, q)
    p = chain.payload
    assert p.mass == pytest.approx(mass, rel=1e-14)
    np.testing.assert_allclose((T @ np.r_[p.com, 1.0])[:3], com, atol=1e-14)
    np.testing.assert_allclose(T[:3, :3] @ p.tensor @ T[:3, :3].T, inertia, atol=1e-14)
    # the standing parts (stand, the first R80's proximal part) are on no moving body
    assert sum(j.inertia.mass for j in chain.joints) + p.mass == pytest.approx(0.6 + 1.2 + 2.0 + 0.6 + 0.9)


MINI = """
name = "mini"
length_unit = "mm"
angle_unit = "deg"
[connectors.F]
twists = [0]
[[modules]]
name = "b"
kind = "base"
cost = 0
output = "F"
out = {{ xyz = [0, 0, 0] }}
[[modules]]
name = "j"
kind = "joint"
cost = 0
input = "F"
output = "F"
type = "revolute"
axis = {{ xyz = [0, 0, 0] }}
out = {{ xyz = [0, 0, 10] }}
limits = [-90, 90]
max_velocity = 90
max_torque = 10
{inertial}
[[modules.capsule]]
a = {a}
b = {b}
radius = {radius}
"""


@pytest.mark.parametrize("a, b", [([0, 0, 0], [200, 0, 0]), ([10, 20, 30], [10, 20, 330]),
                                  ([0, 0, 0], [120, 160, 0])])
def test_a_part_without_inertia_is_a_solid_cylinder(a, b):
    """m = 3 kg over one capsule (r = 50 mm): com at the segment's middle, I about the com =
    m r²/2 along the segment and m (3r² + L²)/12 across it (the closed form of a solid cylinder)."""
    cat = loads_catalogue(MINI.format(inertial="[modules.inertial]\nmass = 3", a=a, b=b, radius=50))
    part = cat.modules["j"].proximal
    pa, pb = np.array(a) * 1e-3, np.array(b) * 1e-3
    L, r, m = np.linalg.norm(pb - pa), 0.05, 3.0
    u = (pb - pa) / L
    closed = m * (3 * r * r + L * L) / 12 * (np.eye(3) - np.outer(u, u)) + m * r * r / 2 * np.outer(u, u)
    np.testing.assert_allclose(part.com, (pa + pb) / 2, atol=1e-15)
    np.testing.assert_allclose(_tensor(part.inertia), closed, atol=1e-15)


def test_a_stated_com_moves_the_cylinder_by_the_parallel_axis_theorem():
    cat = loads_catalogue(MINI.format(inertial="[modules.inertial]\nmass = 2\ncom = [0, 0, 0]", a=[0, 0, 0],
                                      b=[0, 0, 100], radius=20))
    part = cat.modules["j"].proximal
    m, r, L = 2.0, 0.02, 0.1
    own = np.diag([m * (3 * r * r + L * L) / 12, m * (3 * r * r + L * L) / 12, m * r * r / 2])
    d = np.array([0, 0, 0.05])
    np.testing.assert_allclose(_tensor(part.inertia), own + m * (d @ d * np.eye(3) - np.outer(d, d)), atol=1e-15)


def test_a_point_capsule_is_a_solid_ball():
    cat = loads_catalogue(MINI.format(inertial="[modules.inertial]\nmass = 5", a=[0, 0, 40], b=[0, 0, 40],
                                      radius=30))
    part = cat.modules["j"].proximal
    np.testing.assert_allclose(part.com, [0, 0, 0.04], atol=1e-15)
    np.testing.assert_allclose(_tensor(part.inertia), 0.4 * 5 * 0.03 ** 2 * np.eye(3), atol=1e-15)
