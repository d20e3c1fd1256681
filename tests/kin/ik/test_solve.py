"""kin.ik.solve: the default entry point runs the compiled solver — the round trips, closed-form
residuals, limits, determinism, continuity and input checks of test_numeric.py re-run through it
(imported below with the ``method`` fixture set to "compiled"), plus what is new: agreement of its
verdicts with the numpy solver's, 1e-10 accuracy checked by the numpy FK of tests/dh_numpy.py,
answers independent of the thread count, rigid-target validation (issue 8), the fallback without a
compiler, and the warm-started local solve."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.ik import local_ik, solve_ik
from kin.ik.compiled import compiled_ik
from tests.chain_factory import random_q
from tests.dh_numpy import fk_numpy
from tests.kin.ik import test_numeric
from tests.kin.ik.test_numeric import (  # noqa: F401 - the test_* are test_numeric's checks, collected again here
    errors_numpy,
    robot,
    test_absurdly_far_targets_fail_with_a_defined_configuration,
    test_bad_target_shapes,
    test_batch_shapes,
    test_far_target_six_axis,
    test_non_finite_target_and_bad_options,
    test_planar_far_target_residual_closed_form,
    test_planar_inner_hole_residual_closed_form,
    test_planar_target_reachable_only_outside_limits,
    test_position_mode_on_a_six_axis_arm,
    test_position_only_targets,
    test_q0_continuity,
    test_q0_selects_the_planar_branch,
    test_round_trip_every_bundled_robot,
    test_same_seed_same_result,
    test_scara_target_needs_prismatic_joint_beyond_its_limit,
)


@pytest.fixture(autouse=True, params=["compiled"])
def method(request):
    """Overrides test_numeric's fixture: the imported tests run the compiled solver."""
    if compiled_ik(robot("planar_2r")) is None:
        pytest.skip("no C compiler")
    return request.param


assert test_numeric.ROBOTS  # the shared tests cover every bundled robot


@pytest.mark.parametrize("name", test_numeric.ROBOTS)
def test_verdicts_agree_with_the_numpy_solver(name):
    """Reachable targets solved by both; targets pushed out of reach refused by both."""
    r = robot(name)
    c = r.chain
    Q = random_q(c, 12, seed=99)
    T = np.array([fk_numpy(c, q) for q in Q])
    far = T.copy()                 # beyond Σ|a| + Σ|d| + prismatic strokes + |tool| from the base: out of reach
    reach = (np.abs(c.dh_table()[:, [0, 2]]).sum() + np.abs(c.limits[~c.revolute_mask]).max(axis=1, initial=0).sum()
             + np.linalg.norm(c.tool.matrix[:3, 3]) + 1.0)
    u = far[:, :3, 3] - c.base.matrix[:3, 3]
    far[:, :3, 3] = c.base.matrix[:3, 3] + reach * u / np.linalg.norm(u, axis=1, keepdims=True)
    targets = np.concatenate([T, far])
    a = solve_ik(r, targets, seed=1, method="compiled")
    b = solve_ik(r, targets, seed=1, method="numeric")
    np.testing.assert_array_equal(a.success, b.success)
    assert a.success[:12].all() and not a.success[12:].any()
    # out of reach, both report the residual of their best configuration: the real FK error
    for q, Tk, pe in zip(a.q[12:], far, a.position_error[12:]):
        assert pe == pytest.approx(errors_numpy(c, q, Tk)[0], rel=1e-9)


@pytest.mark.parametrize("name", ["fanuc_m16ib20", "puma560", "ur5e", "stanford_arm"])
def test_accuracy_1e_10_when_asked(name):
    r = robot(name)
    c = r.chain
    Q = random_q(c, 20, seed=4)
    T = np.array([fk_numpy(c, q) for q in Q])
    res = r.ik(T, seed=0, tol_position=1e-10, tol_orientation=1e-10)
    assert res.success.all()
    for q, Tk in zip(res.q, T):
        pe, oe = errors_numpy(c, q, Tk)
        assert pe <= 1.5e-10 and oe <= 1.5e-10      # the numpy FK rounds differently: a little slack
    assert c.within_limits(res.q).all()


def test_thread_count_batch_order_and_single_calls_do_not_change_answers():
    r = robot("fanuc_m16ib20")
    c = r.chain
    T = np.array([fk_numpy(c, q) for q in random_q(c, 40, seed=8)])
    T[3, :3, 3] += 0.4                             # some targets out of reach, too
    a = r.ik(T, seed=5, threads=1)
    b = r.ik(T, seed=5, threads=2)
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.success, b.success)
    c2 = r.ik(T, seed=6, threads=1)                # another seed: other random starts, same verdicts
    np.testing.assert_array_equal(a.success, c2.success)
    perm = np.random.default_rng(0).permutation(len(T))
    d = r.ik(T[perm], seed=5)                      # the same targets in another order
    np.testing.assert_array_equal(d.q, a.q[perm])
    for k in (0, 3, 17):                           # and one at a time
        one = r.ik(T[k], seed=5)
        np.testing.assert_array_equal(one.q, a.q[k])
        assert one.success == a.success[k] and one.position_error == a.position_error[k]


def _rigid(seed=0):
    rng = np.random.default_rng(seed)
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    R *= np.sign(np.linalg.det(R))
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, [0.5, 0.2, 0.6]
    return T


@pytest.mark.parametrize("defect", ["scaled", "sheared", "mirrored", "bottom"])
def test_non_rigid_targets_are_refused(defect):
    T = _rigid()
    if defect == "scaled":
        T[:3, :3] *= 1.01
    elif defect == "sheared":
        T[0, 1] += 1e-3
    elif defect == "mirrored":
        T[:3, 0] *= -1.0
    else:
        T[3, 0] = 0.5
    r = robot("puma560")
    for method in ("compiled", "numeric"):
        with pytest.raises(kin.ConfigurationError, match="not a rigid transform"):
            r.ik(T, method=method)
    batch = np.stack([_rigid(1), T])
    with pytest.raises(kin.ConfigurationError, match=r"target 1\b"):
        r.ik(batch)
    # rounding-level defects are accepted
    ok = _rigid()
    ok[:3, :3] += 1e-9
    r.ik(ok, restarts=1, rounds=1)


@pytest.mark.parametrize("bad", [{"tol_position": 0.0}, {"tol_orientation": -1e-6}, {"tol_position": math.nan},
                                 {"restarts": -1}, {"max_iter": 2.5}, {"method": "magic"}])
def test_bad_options(bad):
    with pytest.raises((kin.ConfigurationError, ValueError)):
        robot("puma560").ik(_rigid(), **bad)


def test_without_a_compiler_the_numpy_solver_answers(monkeypatch):
    monkeypatch.setenv("RMTKIT_CC", "none")
    r = kin.load_robot("ur5e")                      # a fresh robot: its compiled solver is looked up anew
    assert compiled_ik(r) is None
    c = r.chain
    Q = random_q(c, 10, seed=12)
    T = np.array([fk_numpy(c, q) for q in Q])
    res = r.ik(T, seed=0)
    assert res.success.all()
    for q, Tk in zip(res.q, T):
        pe, oe = errors_numpy(c, q, Tk)
        assert pe <= 1e-6 and oe <= 1e-6
    with pytest.raises(kin.CompileError):
        r.ik(T, method="compiled")


@pytest.mark.parametrize("method", ["compiled", "numeric"])
def test_local_ik_stays_on_the_branch_of_its_warm_start(method):
    r = robot("puma560")
    c = r.chain
    Q = random_q(c, 10, seed=21)
    Q = Q[r.sigma_min(Q) > 0.05]
    T = np.array([fk_numpy(c, q) for q in Q])
    res = local_ik(r, T, Q + 0.02, method=method)
    assert res.success.all()
    np.testing.assert_allclose(res.q, Q, atol=1e-6)
    one = local_ik(r, T[0], Q[0] + 0.02, method=method)
    assert one.success is True and np.allclose(one.q, Q[0], atol=1e-6)
    # one run, no restarts: from the far side of the workspace it may fail, and says so honestly
    far = local_ik(r, T[0], np.clip(Q[0] + np.pi, c.lower, c.upper), method=method, max_iter=3)
    assert far.success is (far.position_error <= 1e-6 and far.orientation_error <= 1e-6)
    with pytest.raises(kin.ConfigurationError):
        local_ik(r, T[0], None)
