"""DH extraction (kin/urdf/dh.py) on synthetic URDFs: every corner case of the common-normal
construction gives the URDF's FK (yourdfpy's scene graph and the plain numpy DH code of
tests/dh_numpy.py, not rmtkit's kinematics) and the DH values the geometry dictates."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.urdf import import_urdf
from tests.chain_factory import fd_jacobian
from tests.dh_numpy import fk_numpy
from tests.kin.urdf.reference import YourdfpyFk
from tests.kin.urdf.synthetic import random_urdf, serial, write_urdf

H = math.pi / 2
TOL = 1e-12


def check_fk(path, chain, base="l0", tip=None, n_q=50, seed=0):
    """The chain's FK (numpy DH and kin.Robot) equals yourdfpy's at random configurations."""
    tip = tip or f"l{max(int(name[1:]) for name in _links(path))}"
    ref = YourdfpyFk(path, base, tip)
    robot = kin.Robot(chain)
    rng = np.random.default_rng(seed)
    for q in rng.uniform(chain.lower, chain.upper, size=(n_q, chain.n)):
        T = ref(chain.joint_names(), q)
        np.testing.assert_allclose(fk_numpy(chain, q), T, atol=TOL, rtol=0)
        np.testing.assert_allclose(robot.fk(q), T, atol=TOL, rtol=0)


def _links(path):
    import re
    return set(re.findall(r'<link name="(l\d+)"', path.read_text()))


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_parallel_axes_planar_arm(tmp_path, convention):
    """Three parallel z axes 0.5 and 0.4 m apart: α = 0, a = the distances, d = 0 (the normal through o_{i-1}),
    the heights (0.2 + 0.1 m) in the last frame's d."""
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0.2), (0, 0, 0), (0, 0, 1)),
                                        ("revolute", (0.5, 0, 0), (0, 0, 0), (0, 0, 1)),
                                        ("revolute", (0.4, 0, 0.1), (0, 0, 0), (0, 0, 1)),
                                        ("fixed", (0.3, 0, 0), (0, 0, 0), (0, 0, 1))]))
    chain = import_urdf(str(path), convention=convention)
    check_fk(path, chain)
    std = chain.to_standard() if convention == "modified" else chain
    np.testing.assert_allclose(std.dh_table()[:2, 0], [0.5, 0.4], atol=1e-15)      # a
    np.testing.assert_allclose(std.dh_table()[:, 1], 0.0, atol=1e-15)              # alpha
    np.testing.assert_allclose(std.dh_table()[:, 2], [0.0, 0.0, 0.3], atol=1e-15)  # d


def test_antiparallel_axes_give_alpha_pi(tmp_path):
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1)),
                                        ("revolute", (0, 0.3, 0), (0, 0, 0), (0, 0, -1)),
                                        ("fixed", (0.1, 0, 0), (0, 0, 0), (0, 0, 1))]))
    chain = import_urdf(str(path))
    check_fk(path, chain)
    assert abs(chain.dh_table()[0, 1]) == pytest.approx(math.pi, abs=1e-15)
    assert abs(chain.dh_table()[0, 0]) == pytest.approx(0.3, abs=1e-15)


def test_coincident_axes(tmp_path):
    """Two joints on one line: the normal is anywhere; a = 0, α = 0, the frames stay put."""
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1)),
                                        ("revolute", (0, 0, 0.25), (0, 0, 0), (0, 0, 1)),
                                        ("revolute", (0, 0, 0.25), (H, 0, 0), (0, 0, 1)),
                                        ("fixed", (0.1, 0.05, 0), (0, 0, 0), (0, 0, 1))]))
    chain = import_urdf(str(path))
    check_fk(path, chain)
    np.testing.assert_allclose(chain.dh_table()[0, :2], [0.0, 0.0], atol=1e-15)


def test_intersecting_axes_spherical_wrist(tmp_path):
    """Three axes through one point (z, then y, then z): a = 0, |α| = π/2, d = 0 between them."""
    path = write_urdf(tmp_path, serial([("revolute", (0.1, 0.2, 0.3), (0, 0, 0), (0, 0, 1)),
                                        ("revolute", (0, 0, 0), (0, 0, 0), (0, 1, 0)),
                                        ("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1)),
                                        ("fixed", (0, 0, 0.08), (0, 0, 0), (0, 0, 1))]))
    chain = import_urdf(str(path))
    check_fk(path, chain)
    np.testing.assert_allclose(chain.dh_table()[:2, 0], 0.0, atol=1e-15)
    np.testing.assert_allclose(np.abs(chain.dh_table()[:2, 1]), H, atol=1e-15)
    np.testing.assert_allclose(chain.dh_table()[1, 2], 0.0, atol=1e-15)
    np.testing.assert_allclose(chain.dh_table()[2, 2], 0.08, atol=1e-15)
    assert chain.tool.is_identity


def test_axes_along_x_and_skew(tmp_path):
    """Joint axes along x and y of their links (not z), and a skew pair: a is the common normal's length."""
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0), (0, 0, 0), (1, 0, 0)),
                                        ("revolute", (0, 0.2, 0.3), (0, 0, 0), (0, 0, 1)),   # skew to x, 0.2 m apart
                                        ("revolute", (0.1, 0, 0), (0.3, -0.2, 0.5), (0, 1, 0)),
                                        ("fixed", (0, 0, 0.1), (0, 0, 0), (1, 0, 0))]))
    chain = import_urdf(str(path))
    check_fk(path, chain)
    # axis 1 is the x line through the origin, axis 2 the z line through (0, 0.2, ·): normal along y, length 0.2
    assert abs(chain.dh_table()[0, 0]) == pytest.approx(0.2, abs=1e-15)
    assert abs(chain.dh_table()[0, 1]) == pytest.approx(H, abs=1e-15)


def test_prismatic_joint(tmp_path):
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0.4), (0, 0, 0), (0, 0, 1)),
                                        ("prismatic", (0.3, 0, 0), (0, 0, 0), (0, 1, 0)),
                                        ("revolute", (0, 0.2, 0), (0, 0, 0), (0, 0, 1)),
                                        ("fixed", (0.05, 0, 0), (0, 0, 0), (0, 0, 1))]))
    chain = import_urdf(str(path))
    assert chain.joint_types == ("revolute", "prismatic", "revolute")
    assert chain.joints[1].limits == (-0.3, 0.4)
    check_fk(path, chain)


def test_fixed_joints_in_the_middle_fold(tmp_path):
    path = write_urdf(tmp_path, serial([("fixed", (0.1, 0, 0.05), (0, 0, 0.3), (0, 0, 1)),
                                        ("revolute", (0, 0, 0.3), (0, 0, 0), (0, 0, 1)),
                                        ("fixed", (0.2, 0, 0), (0.4, 0, 0), (0, 0, 1)),
                                        ("fixed", (0, 0.1, 0), (0, 0.5, 0), (0, 0, 1)),
                                        ("revolute", (0, 0, 0.1), (0, 0, 0), (0, 1, 0)),
                                        ("fixed", (0, 0, 0.2), (0, 0, 0), (0, 0, 1))]))
    chain = import_urdf(str(path))
    assert chain.n == 2 and chain.joint_names() == ["j1", "j2"]
    check_fk(path, chain)


def test_nearly_parallel_axes_stay_exact(tmp_path):
    """rpy written 1.5708 for π/2 makes two 'parallel' axes 3.7e-6 rad apart: the far-away common normal
    keeps FK exact."""
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0), (1.5708, 0, 0), (0, 0, 1)),
                                        ("revolute", (0.4, 0, 0), (-H, 0, 0), (0, 1, 0)),
                                        ("revolute", (0.3, 0, 0.05), (0, 0, 0), (0, 1, 0)),
                                        ("fixed", (0.1, 0, 0), (0, 0, 0), (0, 0, 1))]))
    check_fk(path, import_urdf(str(path)))


@pytest.mark.parametrize("seed", range(12))
def test_random_chains(tmp_path, seed):
    """Random origins, axes (coordinate, parallel, general), prismatic and fixed joints; both conventions;
    the Jacobian against central differences of yourdfpy's FK."""
    joints = random_urdf(seed)
    path = write_urdf(tmp_path, joints, f"random_{seed}")
    tip = joints[-1]["child"]
    for convention in ("standard", "modified"):
        chain = import_urdf(str(path), convention=convention)
        check_fk(path, chain, tip=tip, n_q=20, seed=seed)
    ref = YourdfpyFk(path, "l0", tip)
    q = np.random.default_rng(seed).uniform(chain.lower, chain.upper)
    J_fd = fd_jacobian(lambda x: ref(chain.joint_names(), x), q)
    np.testing.assert_allclose(kin.Robot(chain).jacobian(q), J_fd, atol=1e-7)


def test_base_below_the_root(tmp_path):
    """--base: the chain starts at an inner link; FK is the tip in that link's frame."""
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0.3), (0, 0, 0), (0, 0, 1)),
                                        ("fixed", (0.1, 0, 0.2), (0.3, 0.2, 0.1), (0, 0, 1)),
                                        ("revolute", (0, 0, 0.1), (0, 0, 0), (1, 0, 0)),
                                        ("revolute", (0.3, 0, 0), (0, 0, 0), (0, 1, 0)),
                                        ("fixed", (0.1, 0, 0), (0, 0, 0), (0, 0, 1))]))
    chain = import_urdf(str(path), base="l2")
    assert chain.joint_names() == ["j2", "j3"]
    check_fk(path, chain, base="l2")


def test_unknown_convention_refused(tmp_path):
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0), (0, 0, 0), (0, 0, 1))]))
    with pytest.raises(kin.RmtError, match="convention 'craig' unknown; allowed: standard, modified"):
        import_urdf(str(path), convention="craig")
