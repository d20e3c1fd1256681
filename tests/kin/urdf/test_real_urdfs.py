"""Real URDFs (shipped by example-robot-data) imported, against pinocchio's and yourdfpy's own models.

For each URDF the imported chain's FK and geometric Jacobian (``kin.Robot``, compiled CasADi) must
equal pinocchio's model of the same file within 1e-12 on 1000 random configurations inside the
limits, in both DH conventions; yourdfpy's scene-graph FK (always installed) is checked on fewer
configurations so that these tests never all skip.
"""
from __future__ import annotations

import numpy as np
import pytest

import kin
from kin.urdf import import_urdf, read_serial_chain
from tests.kin.urdf.reference import PinocchioModel, YourdfpyFk, erd_urdf

# (file inside example-robot-data's robots/, tip link) — UR's parallel axes, Panda's offsets, the
# xArm 7 and Unitree Z1, the Jaco 2's 60° wrist, a two-joint pendulum with continuous joints
CASES = [
    ("ur_description/urdf/ur3_robot.urdf", "tool0"),
    ("ur_description/urdf/ur5_robot.urdf", "tool0"),
    ("ur_description/urdf/ur10_robot.urdf", "tool0"),
    ("panda_description/urdf/panda.urdf", "panda_link8"),
    ("xarm_description/urdf/xarm7.urdf", "link_eef"),
    ("z1_description/urdf/z1.urdf", "gripperMover"),
    ("kinova_description/robots/kinova.urdf", "j2s6s200_end_effector"),
    ("double_pendulum_description/urdf/double_pendulum_continuous.urdf", "link2"),
]
IDS = [c[0].rsplit("/", 1)[-1].removesuffix(".urdf") for c in CASES]
TOL = 1e-12


def _imported(relative: str, tip: str, convention: str):
    path = erd_urdf(relative)
    chain = import_urdf(str(path), tip=tip, convention=convention, collision=False)   # kinematics only here
    return path, chain, kin.Robot(chain)


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("relative, tip", CASES, ids=IDS)
def test_fk_and_jacobian_match_pinocchio(relative, tip, convention):
    path, chain, robot = _imported(relative, tip, convention)
    pin = PinocchioModel(path, tip)
    Q = robot.random_configurations(1000, seed=13)
    T, J = robot.fk(Q), robot.jacobian(Q)
    names = chain.joint_names()
    worst_T = worst_J = 0.0
    for q, Tq, Jq in zip(Q, T, J):
        Tp, Jp = pin.fk_and_jacobian(names, q)
        worst_T = max(worst_T, float(np.abs(Tq - Tp).max()))
        worst_J = max(worst_J, float(np.abs(Jq - Jp).max()))
    assert worst_T < TOL, f"FK differs from pinocchio's by {worst_T:.3g}"
    assert worst_J < TOL, f"Jacobian differs from pinocchio's by {worst_J:.3g}"


@pytest.mark.parametrize("relative, tip", CASES, ids=IDS)
def test_fk_matches_yourdfpy(relative, tip):
    path, chain, robot = _imported(relative, tip, "standard")
    ref = YourdfpyFk(path, read_serial_chain(str(path), tip=tip).base, tip)
    Q = robot.random_configurations(100, seed=7)
    worst = max(float(np.abs(robot.fk(q) - ref(chain.joint_names(), q)).max()) for q in Q)
    assert worst < TOL, f"FK differs from yourdfpy's by {worst:.3g}"


def test_panda_modified_table_is_frankas():
    """Imported in modified DH, the Panda URDF gives Franka's published table (a, d in m, alpha in rad),
    with the flange's 0.107 m in d7 (frame 7 is level with the tip) and no tool transform."""
    _, chain, _ = _imported("panda_description/urdf/panda.urdf", "panda_link8", "modified")
    h = np.pi / 2
    np.testing.assert_allclose(chain.dh_table()[:, 0], [0, 0, 0, 0.0825, -0.0825, 0, 0.088], atol=1e-15)
    np.testing.assert_allclose(chain.dh_table()[:, 1], [0, -h, h, h, -h, h, h], atol=1e-15)
    np.testing.assert_allclose(chain.dh_table()[:, 2], [0.333, 0, 0.316, 0, 0.384, 0, 0.107], atol=1e-15)
    np.testing.assert_array_equal(chain.dh_table()[:, 3], np.zeros(7))
    assert chain.base.is_identity and chain.tool.is_identity


def test_continuous_joints_get_one_turn():
    _, chain, _ = _imported("double_pendulum_description/urdf/double_pendulum_continuous.urdf", "link2", "standard")
    np.testing.assert_array_equal(chain.limits, [[-np.pi, np.pi]] * 2)
