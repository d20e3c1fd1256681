"""Today's arms in the bundled library, each against a source independent of its DH table.

* Franka Panda: example-robot-data's panda.urdf (yourdfpy's FK; the URDF writes π/2 as 1.57079632679,
  so agreement is to 1e-9), and the published zero pose (flange at (0.088, 0, 0.926) m, pointing down);
* KUKA LBR iiwa 7 / 14: a product-of-exponentials model from the axis lines of KUKA's dimension
  drawing (points and directions in the zero pose), not DH;
* UR3e, UR16e: the flange at q = 0 from UR's table in closed form (a2 + a3, -(d4 + d6), d1 - d5);
* Kinova Gen3: the joint list of Kinova's kortex URDF (its 1.5708 twists, so within 5e-5);
* FANUC LR Mate 200iD: the joint list of the ROS-Industrial URDF (exact numbers, 1e-12) and the
  faceplate in the zero pose.

Every check runs with the plain numpy DH code (tests/dh_numpy.py) and with kin.Robot.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kin
from kin.robotfile import load_chain
from tests.dh_numpy import fk_numpy
from tests.kin.test_robot_library import DEG, MM, assert_printed
from tests.kin.urdf.reference import YourdfpyFk, erd_urdf
from tests.kin.urdf.synthetic import joint, write_urdf

NEW_ARMS = ["franka_panda", "kuka_iiwa7", "kuka_iiwa14", "ur3e", "ur16e", "kinova_gen3", "fanuc_lrmate200id"]


@pytest.fixture(params=["numpy", "product"])
def fk(request):
    if request.param == "numpy":
        return lambda name, q: fk_numpy(load_chain(name), q)
    return lambda name, q: np.asarray(kin.load_robot(name).fk(np.asarray(q, dtype=float)))


def random_q(name: str, n: int = 50, seed: int = 0) -> np.ndarray:
    c = load_chain(name)
    return np.random.default_rng(seed).uniform(c.lower, c.upper, size=(n, c.n))


@pytest.mark.parametrize("name", NEW_ARMS)
def test_cites_its_source_and_has_speeds(name):
    c = load_chain(name)
    assert len(c.source) > 100 and all(j.max_velocity for j in c.joints)


# ================================================================================ Franka Panda
class TestFrankaPanda:
    def test_published_table(self):
        c = load_chain("franka_panda")
        assert (c.convention, c.n) == ("modified", 7)
        assert_printed(c.dh_table()[:, 0], "0 0 0 0.0825 -0.0825 0 0.088", 1.0, "a")
        assert_printed(c.dh_table()[:, 2], "0.333 0 0.316 0 0.384 0 0", 1.0, "d")
        np.testing.assert_allclose(c.dh_table()[:, 1], np.array([0, -1, 1, 1, -1, 1, 1]) * math.pi / 2, atol=1e-15)
        assert_printed(c.tool.matrix[:3, 3], "0 0 0.107", 1.0, "flange")
        assert_printed(c.limits, "-2.8973 2.8973; -1.7628 1.7628; -2.8973 2.8973; -3.0718 -0.0698; "
                                 "-2.8973 2.8973; -0.0175 3.7525; -2.8973 2.8973", 1.0, "limits")
        assert_printed([j.max_velocity for j in c.joints], "2.175 2.175 2.175 2.175 2.61 2.61 2.61", 1.0, "speeds")

    def test_zero_pose(self, fk):
        T = fk("franka_panda", np.zeros(7))
        assert_printed(T[:3, 3], "0.088 0 0.926", 1.0, "flange at q = 0")
        assert_printed(T[:3, :3], "1 0 0; 0 -1 0; 0 0 -1", 1.0, "flange pointing down")

    def test_example_robot_data_urdf(self, fk):
        ref = YourdfpyFk(erd_urdf("panda_description/urdf/panda.urdf"), "panda_link0", "panda_link8")
        names = [f"panda_joint{i}" for i in range(1, 8)]
        for q in random_q("franka_panda"):
            np.testing.assert_allclose(fk("franka_panda", q), ref(names, q), atol=1e-9, rtol=0)


# ================================================================================ KUKA LBR iiwa
def poe_fk(points, dirs, M, q) -> np.ndarray:
    """Product of exponentials (space form): Π_i [R_i, p_i − R_i p_i] · M, R_i = rotation about dir_i by q_i."""
    T = np.eye(4)
    for p, w, v in zip(points, dirs, q):
        E = np.eye(4)
        R = Rotation.from_rotvec(np.asarray(w, float) * v).as_matrix()
        E[:3, :3], E[:3, 3] = R, np.asarray(p, float) - R @ np.asarray(p, float)
        T = T @ E
    return T @ M


@pytest.mark.parametrize("name, h2, h4, h6, flange", [
    ("kuka_iiwa7", 340, 740, 1140, 1266), ("kuka_iiwa14", 360, 780, 1180, 1306)])
class TestKukaIiwa:
    def test_against_axis_lines(self, fk, name, h2, h4, h6, flange):
        """KUKA's drawing: A1, A3, A5, A7 vertical through the base centre, A2, A6 along +y and A4 along −y
        at heights h2, h4, h6 mm; flange at `flange` mm, its frame parallel to the base frame at q = 0."""
        z = lambda h: (0.0, 0.0, h * MM)
        points = [z(0), z(h2), z(0), z(h4), z(0), z(h6), z(0)]
        dirs = [(0, 0, 1), (0, 1, 0), (0, 0, 1), (0, -1, 0), (0, 0, 1), (0, 1, 0), (0, 0, 1)]
        M = np.eye(4)
        M[2, 3] = flange * MM
        for q in random_q(name):
            np.testing.assert_allclose(fk(name, q), poe_fk(points, dirs, M, q), atol=1e-12, rtol=0)

    def test_ranges(self, fk, name, h2, h4, h6, flange):
        c = load_chain(name)
        assert_printed(c.limits, "-170 170; -120 120; -170 170; -120 120; -170 170; -120 120; -175 175", DEG)


def test_iiwa_speeds():
    assert_printed([j.max_velocity for j in load_chain("kuka_iiwa7").joints], "98 98 100 130 140 180 180", DEG)
    assert_printed([j.max_velocity for j in load_chain("kuka_iiwa14").joints], "85 85 100 75 130 135 135", DEG)


# ============================================================================ UR3e and UR16e
class TestUniversalRobotsE:
    def test_ur3e_flange_at_zero(self, fk):
        assert_printed(fk("ur3e", np.zeros(6))[:3, 3], "-0.45675 -0.22315 0.0665", 1.0, "UR3e flange")

    def test_ur16e_flange_at_zero(self, fk):
        assert_printed(fk("ur16e", np.zeros(6))[:3, 3], "-0.8384 -0.2907 0.06085", 1.0, "UR16e flange")

    def test_tables(self):
        c = load_chain("ur3e")
        assert_printed(c.dh_table()[:, 0], "0 -0.24355 -0.2132 0 0 0", 1.0, "UR3e a")
        assert_printed(c.dh_table()[:, 2], "0.15185 0 0 0.13105 0.08535 0.0921", 1.0, "UR3e d")
        assert_printed([j.max_velocity for j in c.joints], "180 180 180 360 360 360", DEG)
        c = load_chain("ur16e")
        assert_printed(c.dh_table()[:, 0], "0 -0.4784 -0.36 0 0 0", 1.0, "UR16e a")
        assert_printed(c.dh_table()[:, 2], "0.1807 0 0 0.17415 0.11985 0.11655", 1.0, "UR16e d")
        assert_printed([j.max_velocity for j in c.joints], "120 120 180 180 180 180", DEG)
        for name in ("ur3e", "ur16e"):
            assert_printed(load_chain(name).dh_table()[:, 1], "90 0 0 90 -90 0", DEG, "alpha")


# ================================================================================ Kinova Gen3
def kortex_gen3_joints() -> list[dict]:
    """The joint list of Kinova's kortex_description GEN3_URDF_V12 (origins, twists of ±1.5708 as written)."""
    r = 1.5708
    spec = [("Actuator1", (0, 0, 0.15643), (3.1416, 0, 0), None),
            ("Actuator2", (0, 0.005375, -0.12838), (r, 0, 0), 2.41),
            ("Actuator3", (0, -0.21038, -0.006375), (-r, 0, 0), None),
            ("Actuator4", (0, 0.006375, -0.21038), (r, 0, 0), 2.66),
            ("Actuator5", (0, -0.20843, -0.006375), (-r, 0, 0), None),
            ("Actuator6", (0, 0.00017505, -0.10593), (r, 0, 0), 2.23),
            ("Actuator7", (0, -0.10593, -0.00017505), (-r, 0, 0), None)]
    links = ["base_link", "shoulder", "half_arm_1", "half_arm_2", "forearm", "wrist_1", "wrist_2", "bracelet"]
    out = [joint(n, "continuous" if lim is None else "revolute", links[i], links[i + 1], xyz, rpy,
                 limits=None if lim is None else (-lim, lim)) for i, (n, xyz, rpy, lim) in enumerate(spec)]
    out.append(joint("EndEffector", "fixed", "bracelet", "end_effector", (0, 0, -0.061525), (math.pi, 0, 0)))
    return out


def test_kinova_gen3_against_kortex_urdf(tmp_path, fk):
    ref = YourdfpyFk(write_urdf(tmp_path, kortex_gen3_joints(), "gen3"), "base_link", "end_effector")
    names = [f"Actuator{i}" for i in range(1, 8)]
    for q in random_q("kinova_gen3"):
        T, Tr = fk("kinova_gen3", q), ref(names, q)
        assert np.abs(T[:3, 3] - Tr[:3, 3]).max() < 5e-5      # m: nine twists off by ≤ 7.3e-6 rad, arm ≤ 1.2 m
        assert np.abs(T[:3, :3] - Tr[:3, :3]).max() < 5e-5


def test_kinova_gen3_limits():
    c = load_chain("kinova_gen3")
    assert_printed(c.limits[[1, 3, 5]], "-2.41 2.41; -2.66 2.66; -2.23 2.23", 1.0, "limits of actuators 2, 4, 6")
    np.testing.assert_allclose(c.limits[[0, 2, 4, 6]], [[-2 * math.pi, 2 * math.pi]] * 4)


# ====================================================================== FANUC LR Mate 200iD
def lrmate_joints() -> list[dict]:
    """The joint list of ROS-Industrial's fanuc_lrmate200id_support (lrmate200id_macro.xacro)."""
    spec = [((0, 0, 0.330), (0, 0, 1), (-2.965, 2.965)), ((0.050, 0, 0), (0, 1, 0), (-1.745329, 2.530727)),
            ((0, 0, 0.330), (0, -1, 0), (-2.450966, 4.886922)), ((0, 0, 0.035), (-1, 0, 0), (-3.315, 3.315)),
            ((0.335, 0, 0), (0, -1, 0), (-2.18, 2.18)), ((0.080, 0, 0), (-1, 0, 0), (-6.285, 6.285))]
    links = ["base_link"] + [f"link_{i}" for i in range(1, 7)]
    out = [joint(f"joint_{i + 1}", "revolute", links[i], links[i + 1], xyz, axis=axis, limits=lim)
           for i, (xyz, axis, lim) in enumerate(spec)]
    out.append(joint("joint_6-tool0", "fixed", "link_6", "tool0", rpy=(math.pi, -math.pi / 2, 0)))
    return out


def test_fanuc_lrmate200id_against_ros_industrial_urdf(tmp_path, fk):
    ref = YourdfpyFk(write_urdf(tmp_path, lrmate_joints(), "lrmate200id"), "base_link", "tool0")
    names = [f"joint_{i}" for i in range(1, 7)]
    for q in random_q("fanuc_lrmate200id"):
        np.testing.assert_allclose(fk("fanuc_lrmate200id", q), ref(names, q), atol=1e-12, rtol=0)


def test_fanuc_lrmate200id_zero_pose(fk):
    T = fk("fanuc_lrmate200id", np.zeros(6))
    assert_printed(T[:3, 3], "465 0 695", MM, "faceplate at q = 0")
    assert_printed(T[:3, 2], "1 0 0", 1.0, "tool z out of the faceplate")
