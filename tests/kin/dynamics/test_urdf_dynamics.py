"""A URDF imported by rmtkit keeps its inertias: inverse dynamics of the imported chain equals
pinocchio's ``rnea`` and ``crba`` on the original URDF file (example-robot-data's UR5), in both DH
conventions — the independent check that the inertial values landed in the right DH frames."""
import numpy as np
import pytest

import kin
from kin.urdf import import_urdf
from tests.kin.urdf.reference import erd_urdf

pin = pytest.importorskip("pinocchio")


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_imported_ur5_matches_pinocchio_on_the_original_urdf(convention):
    path = str(erd_urdf("ur_description/urdf/ur5_robot.urdf"))
    robot = kin.Robot(import_urdf(path, tip="tool0", convention=convention, collision=False))
    model = pin.buildModelFromUrdf(path)
    data = model.createData()
    assert model.nq == robot.n
    rng = np.random.default_rng(7)
    for _ in range(20):
        q = rng.uniform(robot.chain.lower, robot.chain.upper)
        qd, qdd = rng.normal(size=robot.n), rng.normal(size=robot.n)
        tau = pin.rnea(model, data, q, qd, qdd)
        np.testing.assert_allclose(robot.inverse_dynamics(q, qd, qdd), tau, rtol=1e-10, atol=1e-10 * np.abs(tau).max())
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        np.testing.assert_allclose(robot.mass_matrix(q), M, rtol=1e-10, atol=1e-12)
