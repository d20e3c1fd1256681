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
    Q = robot.random_configurations(2000, seed=3).reshape(-1, 2, 6)
    t = np.linspace(0.0, 1.0, 4001)
    proven = violated = 0
    for i, (a, b) in enumerate(Q):
        s = robot.sigma_min(a + t[:, None] * (b - a))
        if s.min() < 0.02:                 # through a singularity: σ_min reaches 0, nothing to prove
            continue
        floor = float(np.quantile(s, 0.3)) if i % 2 else float(s.min()) * 0.5
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
        if proven >= 10 and violated >= 10:
            break
    assert proven >= 10 and violated >= 10
