"""planning.certify.sigma: the Jacobian's Lipschitz bound holds (finite differences on random
configurations of several robots), and proofs agree with dense sampling."""
import numpy as np
import pytest

import kin
from planning.certify.sigma import certify_sigma, jacobian_lipschitz


@pytest.mark.parametrize("name", ["fanuc_m16ib20", "puma560", "scara_rrp", "stanford_arm", "cnc_rrrppp"])
def test_lipschitz_bound_holds(name):
    robot = kin.load_robot(name)
    L = jacobian_lipschitz(robot)
    rows = robot.task_rows
    Q = robot.random_configurations(300, seed=1)
    h = 1e-6
    for k in range(robot.n):
        dq = np.zeros(robot.n)
        dq[k] = h
        dJ = (robot.jacobian(Q + dq)[:, rows] - robot.jacobian(Q - dq)[:, rows]) / (2 * h)
        assert np.linalg.norm(dJ, axis=(1, 2)).max() <= L[k] * (1 + 1e-6)


def test_proofs_agree_with_dense_sampling():
    robot = kin.load_robot("fanuc_m16ib20")
    Q = robot.random_configurations(120, seed=3).reshape(-1, 2, 6)
    proven = violated = 0
    for a, b in Q:
        t = np.linspace(0.0, 1.0, 4001)
        s = robot.sigma_min(a + t[:, None] * (b - a))
        floor = float(np.quantile(s, 0.3)) if violated < proven else float(s.min()) * 0.5
        pr = certify_sigma(robot, np.array([a, b]), floor)
        if pr.proven:
            proven += 1
            assert s.min() >= floor
        else:
            assert pr.violation is not None and not pr.unproven
            violated += 1
            k, f, q, sv = pr.violation
            assert sv < floor and robot.sigma_min(q) == pytest.approx(sv)
            assert np.allclose(q, a + f * (b - a))
            assert not (s[t < f - 1e-3] < floor - 1e-9).any()       # nothing clearly earlier was below
    assert proven >= 10 and violated >= 10
