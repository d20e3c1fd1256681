"""The bundled catalogue keeps its data-sheet numbers, its computed masses and its demonstration arm.

Joint modules against the ROBOTIS e-Manual DYNAMIXEL-Y data sheets (typed here from the pages, not
read from the catalogue); link masses recomputed from the stated design (aluminium 2.70 g/cm³:
Ø80 × 10 and Ø70 × 10 mm flanges, round tubes π(D·t − t²)); the six-joint arm of docs/modules.md
assembles and holds, and the same arm with the 400 mm crank is refused at its shoulder.  The small
test catalogue: its arms reach what its docs say and an all-light arm fails at its first joint.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from kin.modules import Assembly, assemble, holding, load_catalogue
from kin.modules.assembly import AssemblyError, module_frames

SMALL = Path(__file__).with_name("small_catalogue.toml")
RPM = 2 * math.pi / 60

#: model: (module, mass kg, Ø mm, length mm, continuous torque N·m, continuous speed rev/min)
DATA_SHEETS = {
    "YM080-230-R099-RH": ("Y80-99", 1.2, 80, 78.1, 26.0, 20.2),
    "YM080-230-A099-RH": ("Y80-99B", 1.55, 80, 100.1, 26.0, 20.2),
    "YM080-230-R051-RH": ("Y80-51", 1.2, 80, 78.1, 15.8, 39.2),
    "YM070-210-R099-RH": ("Y70-99", 0.79, 70, 71.1, 14.6, 20.2),
    "YM070-210-R051-RH": ("Y70-51", 0.79, 70, 71.1, 8.2, 39.2),
}
ARM = "BASE Y80-99 E80 Y80-99B C200@180 R80-70 Y70-99 F200 Y70-51 E70 Y70-51 E70 Y70-51 GRIP"


@pytest.fixture(scope="module")
def cat():
    return load_catalogue("dynamixel_y")


@pytest.mark.parametrize("model", sorted(DATA_SHEETS))
def test_joint_modules_carry_the_data_sheet(cat, model):
    name, mass, dia, length, torque, speed = DATA_SHEETS[model]
    m = cat.modules[name]
    assert model in m.title
    assert m.kind == "joint" and m.type == "revolute"
    assert m.proximal.mass == pytest.approx(mass, abs=1e-12)
    assert m.max_torque == pytest.approx(torque, abs=1e-12)
    assert m.max_velocity == pytest.approx(speed * RPM, rel=1e-12)
    # in-line: the joint axis is the input z, the output face one housing length along it
    assert np.allclose(m.axis[:3, :3], np.eye(3)) and m.axis[:3, 3] == pytest.approx([0, 0, length / 1000])
    (a, b, r), = m.proximal.capsules
    assert r == pytest.approx(dia / 2000)
    lo, hi = sorted([a[2] - r, b[2] - r, a[2] + r, b[2] + r])[::3]
    assert lo == pytest.approx(0, abs=2e-3) and hi == pytest.approx(length / 1000, abs=2e-3)


def test_link_masses_are_the_stated_design(cat):
    rho = 2700.0                                         # kg/m³
    f80, f70 = rho * math.pi * 0.04 ** 2 * 0.01, rho * math.pi * 0.035 ** 2 * 0.01

    def tube(D, t):  # kg/m of a round tube, D and t in mm
        return rho * math.pi * (D * t - t * t) * 1e-6

    want = {"E80": 2 * f80 + 0.09 * tube(50, 3), "E70": 2 * f70 + 0.08 * tube(40, 3),
            "C200": 2 * f80 + 0.2 * tube(50, 3), "C400": 2 * f80 + 0.4 * tube(50, 3),
            "F200": 2 * f70 + 0.19 * tube(40, 3), "R80-70": rho * math.pi * 0.04 ** 2 * 0.012}
    for name, mass in want.items():
        assert cat.modules[name].proximal.mass == pytest.approx(mass, abs=5e-4), name
    # the shorthand's geometry: a crank is `offset` across and `length` along, an elbow turns 90°
    assert cat.modules["C400"].out[:3, 3] == pytest.approx([0.4, 0, 0.07])
    assert cat.modules["E80"].out[:3, 2] == pytest.approx([1, 0, 0])


def test_the_documented_arm_assembles_and_holds(cat):
    a = Assembly.parse(ARM.split(), cat)
    chain = assemble(cat, a, name="dxl_arm")
    assert chain.n == 6 and a.cost(cat) == 16770
    rep = holding(chain)
    assert rep.fails == []
    # the TCP at q = 0 from the modules' own transforms (base out 20 mm, then the stack), 0.58 m up
    tcp = module_frames(cat, a, np.zeros(6))[-1][1]
    assert tcp[2, 3] == pytest.approx(0.5781, abs=1e-4)


def test_the_long_crank_overloads_the_shoulder(cat):
    a = Assembly.parse(ARM.replace("C200", "C400").split(), cat)
    with pytest.raises(AssemblyError, match="joint 2"):
        assemble(cat, a, name="too_long")
    rep = holding(assemble(cat, a, name="too_long", check_holding=False))
    assert rep.fails == [1]            # joint 2 (index 1) only, against its 26 N·m
    assert rep.max_torque[1] == 26.0 and rep.witness[1] == pytest.approx(33.65, abs=0.05)


def test_small_catalogue_reach_and_a_weak_first_joint():
    cat = load_catalogue(SMALL)
    assert len(cat.of_kind("joint")) == 2 and len(cat.of_kind("link")) == 3
    for text, reach in (("B JS LL JS LL JL T", 1.02), ("B JS LS JL LS JL T", 0.69)):
        a = Assembly.parse(text.split(), cat)
        tcp = module_frames(cat, a, np.zeros(3))[-1][1]
        assert np.linalg.norm(tcp[:3, 3]) == pytest.approx(reach, abs=1e-9)
        assert holding(assemble(cat, a)).fails == []
    weak = assemble(cat, Assembly.parse("B JL LS JL LS JL T".split(), cat), check_holding=False)
    assert 0 in holding(weak).fails
