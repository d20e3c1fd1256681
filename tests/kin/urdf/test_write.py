"""Export (kin/urdf/write.py): every bundled robot written as URDF loads in yourdfpy with the same FK
as the plain numpy DH code (tests/dh_numpy.py), in pinocchio too when it is installed, and export →
import gives the same FK in both conventions."""
from __future__ import annotations

import xml.etree.ElementTree as ET
import zlib

import numpy as np
import pytest

import kin
from kin.urdf import chain_to_urdf, import_urdf, save_urdf
from tests.dh_numpy import fk_numpy, jacobian_numpy
from tests.kin.urdf.reference import PinocchioModel, YourdfpyFk

TOL = 1e-12


def _configurations(chain, n=25):
    rng = np.random.default_rng(zlib.crc32(chain.name.encode()))
    return rng.uniform(chain.lower, chain.upper, size=(n, chain.n))


@pytest.mark.parametrize("name", kin.bundled_robots())
def test_bundled_robot_exports_with_the_same_fk(tmp_path, name):
    chain = kin.load_chain(name)
    path = save_urdf(chain, tmp_path / f"{name}.urdf")
    ref = YourdfpyFk(path, "base_link", "tool")
    assert ref.urdf.validate(), ref.urdf.errors
    for q in _configurations(chain):
        np.testing.assert_allclose(ref(chain.joint_names(), q), fk_numpy(chain, q), atol=TOL, rtol=0)


@pytest.mark.parametrize("name", ["puma560", "stanford_arm", "solar_concentrator", "cnc_rrrppp"])
def test_export_fk_and_jacobian_in_pinocchio(tmp_path, name):
    chain = kin.load_chain(name)
    path = save_urdf(chain, tmp_path / f"{name}.urdf")
    pin = PinocchioModel(path, "tool")
    for q in _configurations(chain):
        T, J = pin.fk_and_jacobian(chain.joint_names(), q)
        np.testing.assert_allclose(T, fk_numpy(chain, q), atol=TOL, rtol=0)
        np.testing.assert_allclose(J, jacobian_numpy(chain, q), atol=TOL, rtol=0)


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("name", ["fanuc_m16ib20", "scara_rrp", "solar_concentrator", "spherical_rrp", "ur5e"])
def test_export_import_round_trip(tmp_path, name, convention):
    chain = kin.load_chain(name)
    path = save_urdf(chain, tmp_path / f"{name}.urdf")
    again = import_urdf(str(path), convention=convention)
    assert again.convention == convention and again.n == chain.n
    assert again.joint_types == chain.joint_types
    np.testing.assert_allclose(again.limits, chain.limits, rtol=0, atol=0)
    assert [j.max_velocity for j in again.joints] == [j.max_velocity for j in chain.joints]
    for q in _configurations(chain):
        np.testing.assert_allclose(fk_numpy(again, q), fk_numpy(chain, q), atol=TOL, rtol=0)


def test_design_parameters_are_written_at_their_values(tmp_path):
    chain = kin.loads_robot('''
name = "two_link"
title = "two links -- designed"
convention = "modified"
length_unit = "mm"
angle_unit = "deg"
[[joints]]
type = "revolute"
a = 100.0
d = "L1"
limits = [-170, 170]
[[joints]]
type = "prismatic"
a = 500.0
alpha = 90.0
limits = [0, 300]
[parameters.L1]
value = 800.0
bounds = [300, 1200]
''').with_parameters({"L1": 1.0})
    path = save_urdf(chain, tmp_path / "two.urdf")
    ref = YourdfpyFk(path, "base_link", "tool")
    for q in _configurations(chain):
        np.testing.assert_allclose(ref(chain.joint_names(), q), fk_numpy(chain, q), atol=TOL, rtol=0)


def test_links_carry_cylinder_visuals():
    chain = kin.load_chain("puma560")
    root = ET.fromstring(chain_to_urdf(chain))
    assert root.tag == "robot" and root.get("name") == "puma560"
    links = {lk.get("name"): lk for lk in root.findall("link")}
    assert list(links) == ["base_link"] + [f"link_{i}" for i in range(1, 7)] + ["tool"]
    for name in list(links)[1:-1]:          # every moving link shows its joint and its segment, if any
        cylinders = links[name].findall("visual/geometry/cylinder")
        assert cylinders, name
        assert all(float(c.get("radius")) > 0 and float(c.get("length")) > 0 for c in cylinders)
    joints = root.findall("joint")
    assert [j.get("type") for j in joints] == ["revolute"] * 6 + ["fixed"]
    assert [j.get("name") for j in joints[:6]] == kin.load_chain("puma560").joint_names()
