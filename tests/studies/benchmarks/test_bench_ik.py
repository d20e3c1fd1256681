"""The IK benchmark's helpers (studies/benchmarks/bench_ik.py) measure what they claim: its
independent FK agrees with tests/dh_numpy.py, a false success is flagged exactly when the answer
misses the target, and its "unreachable" targets have no IK solution (none of the numpy solver's
starts reaches them, and the far ones lie beyond Σ|a| + Σ|d|).  No timing here."""
from __future__ import annotations

import numpy as np

import kin
from studies.benchmarks import bench_ik
from tests.chain_factory import random_chain, random_q
from tests.dh_numpy import fk_numpy


def test_numpy_fk_is_the_chain_fk():
    for chain in (kin.load_chain("fanuc_m16ib20"), random_chain(4), random_chain(7, convention="modified")):
        for q in random_q(chain, 5, seed=1):
            np.testing.assert_allclose(bench_ik.numpy_fk(chain, q), fk_numpy(chain, q), atol=1e-12)


def test_false_success_flag():
    chain = kin.load_chain("puma560")
    q = random_q(chain, 1, seed=3)[0]
    T = fk_numpy(chain, q)
    assert not bench_ik.false_success(chain, True, q, T)
    assert bench_ik.false_success(chain, True, q + np.array([0, 0, 0, 0, 0, 1e-3]), T)   # tool turned: wrong
    assert not bench_ik.false_success(chain, False, q + 0.1, T)                        # not claimed


def test_unreachable_targets_are_unreachable():
    robot = kin.load_robot("fanuc_m16ib20")
    T = bench_ik.reachable_targets(robot, 40, seed=2)
    sets = bench_ik.unreachable_targets(robot, T, seed=3, count=12)
    assert set(sets) == {"pushed", "orientation", "far"} and all(len(v) for v in sets.values())
    U = np.concatenate(list(sets.values()))
    res = robot.ik(U, seed=0, method="numeric")
    assert not res.success.any()
    bound = np.abs(robot.chain.dh_table()[:, [0, 2]]).sum()
    assert (np.linalg.norm(sets["far"][:, :3, 3], axis=1) > bound).all()
