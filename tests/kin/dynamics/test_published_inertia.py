"""The published inertial data of the bundled arms, checked against independent values.

* UR e-Series: the centres of mass in the DH frames equal Universal Robots' article table (support
  article 45257, dynamics columns) as printed there; the gravity torque of the UR5e's shoulder with the
  arm stretched out (q = 0) equals the sum worked out by hand from that table; and, with pinocchio,
  inverse dynamics, mass matrix and gravity of the bundled DH files equal pinocchio's on the URDF that
  Universal Robots' ROS 2 description makes of the same numbers in its own link frames.
* Panda: the bundled values are the identified feasible parameters of Gaz et al. (RA-L 2019).
"""
from __future__ import annotations

import numpy as np
import pytest

import kin
from tests.kin.dynamics.ur_ros_description import ARMS, JOINT_NAMES, urdf_text

G = 9.81

# Universal Robots, 'DH parameters for calculations of kinematics and dynamics', mass [kg] and centre of
# mass [m] of links 1 … 6 as printed (UR10e's link 6 and the UR16e's rows are not quoted here)
UR_TABLE = {
    "ur3e": [(1.98, (0, -0.02, 0)), (3.4445, (0.13, 0, 0.1157)), (1.437, (0.05, 0, 0.0238)),
             (0.871, (0, 0, 0.01)), (0.805, (0, 0, 0.01)), (0.261, (0, 0, -0.02))],
    "ur5e": [(3.761, (0, -0.02561, 0.00193)), (8.058, (0.2125, 0, 0.11336)), (2.846, (0.15, 0.0, 0.0265)),
             (1.37, (0, -0.0018, 0.01634)), (1.3, (0, 0.0018, 0.01634)), (0.365, (0, 0, -0.001159))],
    "ur10e": [(7.369, (0.021, 0.000, 0.027)), (13.051, (0.38, 0.000, 0.158)), (3.989, (0.24, 0.000, 0.068)),
              (2.1, (0.000, 0.007, 0.018)), (1.98, (0.000, 0.007, 0.018))],
}


@pytest.mark.parametrize("arm", sorted(UR_TABLE))
def test_ur_masses_and_centres_of_mass_are_the_article_table(arm):
    chain = kin.load_chain(arm)
    for j, (m, com) in zip(chain.joints, UR_TABLE[arm]):
        assert j.inertia.mass == m
        np.testing.assert_allclose(j.inertia.com, com, rtol=0, atol=1e-12)


def test_ur5e_shoulder_gravity_torque_stretched_out_by_hand():
    """At q = 0 the UR5e lies stretched along −x of the base, every axis but the first horizontal.
    The shoulder (joint 2, axis −y) holds links 2 … 6, whose centres of mass lie at x = a2 + 0.2125
    (link 2, table x in frame 2, whose x axis points back to the shoulder), a2 + a3 + 0.15 (link 3) and
    a2 + a3 (links 4 … 6: their table x is 0 and their frames sit on the wrist axis x = a2 + a3).
    Holding them takes τ2 = −g Σ m_i |x_i|; the elbow holds links 3 … 6 about x = a2."""
    a2, a3 = -0.425, -0.3922
    links = [(8.058, a2 + 0.2125), (2.846, a2 + a3 + 0.15), (1.37, a2 + a3), (1.3, a2 + a3), (0.365, a2 + a3)]
    tau2 = -G * sum(m * abs(x) for m, x in links)
    tau3 = -G * sum(m * abs(x - a2) for m, x in links[1:])
    robot = kin.Robot(kin.load_chain("ur5e"))
    g = robot.gravity(np.zeros(6))
    assert tau2 == pytest.approx(-59.75, abs=0.01)          # the number itself, for the reader
    np.testing.assert_allclose(g[[1, 2]], [tau2, tau3], rtol=1e-12)
    np.testing.assert_allclose(g[[0, 3, 4, 5]], 0.0, atol=1e-9)   # axis 1 vertical; wrist COMs on their axes' plane
    np.testing.assert_allclose(robot.inverse_dynamics(np.zeros(6), np.zeros(6), np.zeros(6)), g, rtol=1e-12)


@pytest.mark.parametrize("arm", ["ur3e", "ur5e", "ur10e", "ur16e"])
def test_ur_torque_limits(arm):
    tau = {"ur3e": [54, 54, 28, 9, 9, 9], "ur5e": [150, 150, 150, 28, 28, 28],
           "ur10e": [330, 330, 150, 54, 54, 54], "ur16e": [330, 330, 150, 54, 54, 54]}[arm]
    assert [j.max_torque for j in kin.load_chain(arm).joints] == tau


@pytest.mark.parametrize("arm", sorted(ARMS))
def test_ur_dynamics_match_pinocchio_on_the_ros_description(tmp_path, arm):
    pin = pytest.importorskip("pinocchio")
    path = tmp_path / f"{arm}.urdf"
    path.write_text(urdf_text(arm))
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    assert [model.names[i] for i in range(1, model.njoints)] == list(JOINT_NAMES)
    robot = kin.Robot(kin.load_chain(arm))
    rng = np.random.default_rng(3)
    # the description's calibrated origins carry roll 1.570796327 (π/2 + 3e-10) and 2e-11 m residues: 1e-8
    for _ in range(20):
        q = rng.uniform(-np.pi, np.pi, 6)
        qd, qdd = rng.normal(size=6), rng.normal(size=6)
        tau = pin.rnea(model, data, q, qd, qdd)
        np.testing.assert_allclose(robot.inverse_dynamics(q, qd, qdd), tau, rtol=1e-8, atol=1e-8 * np.abs(tau).max())
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        np.testing.assert_allclose(robot.mass_matrix(q), M, rtol=1e-8, atol=1e-8 * np.abs(M).max())
        np.testing.assert_allclose(robot.gravity(q), pin.computeGeneralizedGravity(model, data, q), rtol=1e-8,
                                   atol=1e-8)


# Gaz, Cognetti, Oliva, Robuffo Giordano, De Luca, RA-L 2019, supplementary material tables VIII and IX, as in
# github.com/marcocognetti/FrankaEmikaPandaDynModel matlab/ConvertDynPars2VREP/DynPars2VREP.m: mass, centre of
# mass and (Ixx, Ixy, Ixz, Iyy, Iyz, Izz) about it, in Craig's (modified) DH frames of Franka's table
GAZ = [
    (4.970684, (3.875e-03, 2.081e-03, 0), (7.0337e-01, -1.3900e-04, 6.7720e-03, 7.0661e-01, 1.9169e-02, 9.1170e-03)),
    (0.646926, (-3.141e-03, -2.872e-02, 3.495e-03),
     (7.9620e-03, -3.9250e-03, 1.0254e-02, 2.8110e-02, 7.0400e-04, 2.5995e-02)),
    (3.228604, (2.7518e-02, 3.9252e-02, -6.6502e-02),
     (3.7242e-02, -4.7610e-03, -1.1396e-02, 3.6155e-02, -1.2805e-02, 1.0830e-02)),
    (3.587895, (-5.317e-02, 1.04419e-01, 2.7454e-02),
     (2.5853e-02, 7.7960e-03, -1.3320e-03, 1.9552e-02, 8.6410e-03, 2.8323e-02)),
    (1.225946, (-1.1953e-02, 4.1065e-02, -3.8437e-02),
     (3.5549e-02, -2.1170e-03, -4.0370e-03, 2.9474e-02, 2.2900e-04, 8.6270e-03)),
    (1.666555, (6.0149e-02, -1.4117e-02, -1.0517e-02),
     (1.9640e-03, 1.0900e-04, -1.1580e-03, 4.3540e-03, 3.4100e-04, 5.4330e-03)),
    (7.35522e-01, (1.0517e-02, -4.252e-03, 6.1597e-02),
     (1.2516e-02, -4.2800e-04, -1.1960e-03, 1.0027e-02, -7.4100e-04, 4.8150e-03)),
]


def test_panda_inertias_are_the_identified_parameters():
    chain = kin.load_chain("franka_panda")
    for k, (j, (m, com, (ixx, ixy, ixz, iyy, iyz, izz))) in enumerate(zip(chain.joints, GAZ), 1):
        assert j.inertia.mass == pytest.approx(m, rel=1e-12)
        np.testing.assert_allclose(j.inertia.inertia, (ixx, iyy, izz, ixy, ixz, iyz), rtol=1e-12, atol=0)
        # link 1's centre of mass along its own (vertical) axis moves no joint: not identifiable, so Gaz
        # et al. give 0 and the file keeps example-robot-data's -0.04762 m
        n = 2 if k == 1 else 3
        np.testing.assert_allclose(j.inertia.com[:n], com[:n], rtol=1e-12, atol=0)
