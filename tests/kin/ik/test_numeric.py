"""kin.ik.numeric (the numpy solver, forced here by ``method="numeric"``): FK → IK → FK round trips on
every bundled robot (targets made and results checked by the numpy FK of tests/dh_numpy.py),
position-only IK, unreachable targets with closed-form residuals, joint limits, determinism,
continuity from q0, batch shapes and bad inputs.  tests/kin/ik/test_solve.py runs the same checks
through the default (compiled) solver."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.chain import Chain, Joint
from tests.chain_factory import random_q, rotvec
from tests.dh_numpy import fk_numpy

ROBOTS = sorted(kin.bundled_robots())
POSITION_ONLY = {"planar_2r", "scara_rrp", "spherical_rrp"}
TOL = 1e-6

_robots: dict[str, kin.Robot] = {}


@pytest.fixture(autouse=True, params=["numeric"])
def method(request, monkeypatch):
    """Every ``robot.ik`` call of this module goes to the numpy solver (the compiled one is
    unavailable, as with ``RMTKIT_CC=none``); test_solve.py imports these tests with "compiled"."""
    if request.param == "numeric":
        monkeypatch.setattr("kin.ik.solve.compiled_ik", lambda robot: None)
    return request.param


def robot(name: str) -> kin.Robot:
    if name not in _robots:
        _robots[name] = kin.load_robot(name)
    return _robots[name]


def errors_numpy(chain: Chain, q: np.ndarray, T_target: np.ndarray) -> tuple[float, float]:
    """Position (m) and orientation (rad) error of fk_numpy(q) against a target, independently."""
    T = fk_numpy(chain, q)
    return (float(np.linalg.norm(T[:3, 3] - T_target[:3, 3])),
            float(np.linalg.norm(rotvec(T_target[:3, :3] @ T[:3, :3].T))))


# ================================================================================ round trips
@pytest.mark.parametrize("name", ROBOTS)
def test_round_trip_every_bundled_robot(name):
    r = robot(name)
    c = r.chain
    Q_true = random_q(c, 30, seed=2024)
    targets = np.array([fk_numpy(c, q) for q in Q_true])
    res = r.ik(targets, seed=0)
    assert res.success.shape == (30,) and res.q.shape == (30, c.n)
    assert res.success.all(), f"{name}: {np.count_nonzero(~res.success)} of 30 reachable targets not solved"
    assert np.all(res.position_error <= TOL)
    assert np.all(res.orientation_error <= TOL)
    assert c.within_limits(res.q, 1e-12).all()
    for q, T in zip(res.q, targets):
        pe, oe = errors_numpy(c, q, T)
        assert pe <= TOL
        if name not in POSITION_ONLY:
            assert oe <= TOL
    if name in POSITION_ONLY:
        assert np.all(res.orientation_error == 0.0)


@pytest.mark.parametrize("name", sorted(POSITION_ONLY))
def test_position_only_targets(name):
    r = robot(name)
    c = r.chain
    Q_true = random_q(c, 15, seed=7)
    P = np.array([fk_numpy(c, q)[:3, 3] for q in Q_true])
    res = r.ik(P, seed=1)
    assert res.success.all() and res.q.shape == (15, c.n)
    for q, p in zip(res.q, P):
        assert np.linalg.norm(fk_numpy(c, q)[:3, 3] - p) <= TOL
    one = r.ik(P[0], seed=1)
    assert one.success is True and one.q.shape == (c.n,) and isinstance(one.position_error, float)


def test_position_mode_on_a_six_axis_arm():
    r = robot("puma560")
    c = r.chain
    q_true = random_q(c, 1, seed=3)[0]
    T = fk_numpy(c, q_true)
    T_rot = T.copy()
    T_rot[:3, :3] = np.eye(3)  # an orientation the arm may not reach at that point: ignored
    res = r.ik(T_rot, mode="position", seed=0)
    assert res.success and res.orientation_error == 0.0
    assert np.linalg.norm(fk_numpy(c, res.q)[:3, 3] - T[:3, 3]) <= TOL
    res2 = r.ik(T[:3, 3], seed=0)  # a position target selects position mode by itself
    assert res2.success and np.linalg.norm(fk_numpy(c, res2.q)[:3, 3] - T[:3, 3]) <= TOL


# =========================================================================== unreachable targets
@pytest.mark.parametrize("target", [(3.0, 1.0), (-2.0, 0.5), (0.0, -5.0), (1.5, 1.5)])
def test_planar_far_target_residual_closed_form(target):
    """Beyond the outer circle the best the arm can do is stretch towards the target: |t| − (a1 + a2)."""
    t = np.array([*target, 0.0])
    res = robot("planar_2r").ik(t, seed=0)
    assert res.success is False
    assert res.position_error == pytest.approx(np.linalg.norm(t) - 1.8, abs=1e-7)


@pytest.mark.parametrize("target", [(0.05, 0.0), (-0.1, 0.1), (0.0, 0.0)])
def test_planar_inner_hole_residual_closed_form(target):
    """Inside the inner circle (radius a1 − a2 = 0.2) the residual is 0.2 − |t|."""
    t = np.array([*target, 0.0])
    res = robot("planar_2r").ik(t, seed=0)
    assert res.success is False
    assert res.position_error == pytest.approx(0.2 - np.linalg.norm(t), abs=1e-7)


def test_far_target_six_axis():
    r = robot("puma560")
    c = r.chain
    bound = np.abs(c.dh_table()[:, [0, 2]]).sum()  # |p| ≤ Σ|a| + Σ|d|
    T = np.eye(4)
    T[:3, 3] = [3.0, -1.0, 2.0]
    res = r.ik(T, seed=0)
    assert res.success is False
    assert res.position_error >= np.linalg.norm(T[:3, 3]) - bound
    pe, _ = errors_numpy(c, res.q, T)
    assert res.position_error == pytest.approx(pe, rel=1e-9)  # the reported residual is the real one


def test_scara_target_needs_prismatic_joint_beyond_its_limit():
    """z = d1 + d2 + q3 = 2 mm + q3 with q3 ∈ [−297, −97] mm: z = +100 mm needs q3 = 98 mm."""
    r = robot("scara_rrp")
    res = r.ik(np.array([0.3, 0.2, 0.1]), seed=0)
    assert res.success is False
    assert r.chain.within_limits(res.q)
    assert res.position_error == pytest.approx(0.1 - (0.002 - 0.097), abs=1e-7)


def test_planar_target_reachable_only_outside_limits():
    """Both IK branches of a planar 2R target lie outside the joint limits."""
    c = Chain(name="planar_limited", task=("x", "y"),
              joints=(Joint("revolute", a=1.0, limits=(0.0, 1.0)), Joint("revolute", a=0.8, limits=(0.0, 2.0))))
    r = kin.Robot(c)
    q_elbow_up = np.array([-1.0, 0.5])
    phi = math.atan2(0.8 * math.sin(0.5), 1.0 + 0.8 * math.cos(0.5))
    q_elbow_down = np.array([-1.0 + 2 * phi, -0.5])
    t = fk_numpy(c, q_elbow_up)[:3, 3]
    np.testing.assert_allclose(fk_numpy(c, q_elbow_down)[:3, 3], t, atol=1e-14)  # really the other branch
    assert not c.within_limits(q_elbow_up) and not c.within_limits(q_elbow_down)
    res = r.ik(t, seed=0)
    assert res.success is False and res.position_error > 1e-3
    assert c.within_limits(res.q)
    # widening the limits makes the same target solvable
    wide = Chain(name="planar_wide", task=("x", "y"),
                 joints=(Joint("revolute", a=1.0, limits=(-2.0, 1.0)), Joint("revolute", a=0.8, limits=(0.0, 2.0))))
    res2 = kin.Robot(wide).ik(t, seed=0)
    assert res2.success is True
    np.testing.assert_allclose(res2.q, q_elbow_up, atol=1e-6)


# ==================================================================== determinism and continuity
@pytest.mark.parametrize("name", ["fanuc_m16ib20", "stanford_arm", "scara_rrp"])
def test_same_seed_same_result(name):
    r = robot(name)
    Q_true = random_q(r.chain, 8, seed=5)
    T = np.array([fk_numpy(r.chain, q) for q in Q_true])
    T[0, :3, 3] += 10.0  # one unreachable target too
    a, b = r.ik(T, seed=3, rounds=3), r.ik(T, seed=3, rounds=3)
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.success, b.success)
    np.testing.assert_array_equal(a.position_error, b.position_error)
    np.testing.assert_array_equal(a.orientation_error, b.orientation_error)
    # a fresh Robot (new evaluator) gives the same answer too
    c = kin.load_robot(name).ik(T, seed=3, rounds=3)
    np.testing.assert_array_equal(a.q, c.q)


@pytest.mark.parametrize("name", ["puma560", "fanuc_m16ib20", "ur5e", "abb_irb120"])
def test_q0_continuity(name):
    """Seeded next to a known solution, IK returns that solution (its branch), not another one."""
    r = robot(name)
    c = r.chain
    rng = np.random.default_rng(11)
    Q_true = random_q(c, 10, seed=13)
    Q_true = Q_true[r.sigma_min(Q_true) > 0.05]  # away from singularities, where branches are distinct
    assert len(Q_true) >= 4
    T = np.array([fk_numpy(c, q) for q in Q_true])
    span = c.upper - c.lower
    q0 = np.clip(Q_true + rng.uniform(-0.01, 0.01, Q_true.shape) * span, c.lower, c.upper)
    res = r.ik(T, q0=q0, seed=0)
    assert res.success.all()
    np.testing.assert_allclose(res.q, Q_true, atol=1e-5)
    # one q0 for a path: the previous solution seeds the next target
    one = r.ik(T[0], q0=q0[0], seed=0)
    np.testing.assert_allclose(one.q, Q_true[0], atol=1e-5)


def test_q0_selects_the_planar_branch():
    r = robot("planar_2r")
    c = r.chain
    q_up = np.array([0.3, 1.0])
    phi = math.atan2(0.8 * math.sin(1.0), 1.0 + 0.8 * math.cos(1.0))
    q_down = np.array([0.3 + 2 * phi, -1.0])
    t = fk_numpy(c, q_up)[:3, 3]
    np.testing.assert_allclose(fk_numpy(c, q_down)[:3, 3], t, atol=1e-14)
    for branch in (q_up, q_down):
        for seed in range(3):
            res = r.ik(t, q0=branch + np.array([0.05, -0.05]), seed=seed)
            assert res.success
            np.testing.assert_allclose(res.q, branch, atol=1e-6)


# ================================================================================ shapes, errors
def test_batch_shapes():
    r = robot("ur5e")
    c = r.chain
    Q = random_q(c, 4, seed=1)
    T = np.array([fk_numpy(c, q) for q in Q])
    res = r.ik(T, seed=0)
    assert res.success.shape == (4,) and res.success.dtype == bool
    assert res.q.shape == (4, 6) and res.position_error.shape == (4,) and res.orientation_error.shape == (4,)
    res1 = r.ik(T[0], seed=0)
    assert isinstance(res1.success, bool) and res1.q.shape == (6,)
    assert isinstance(res1.position_error, float) and isinstance(res1.orientation_error, float)
    res_q0 = r.ik(T, q0=Q[0], seed=0)  # one q0 for every target
    assert res_q0.q.shape == (4, 6) and res_q0.success.all()
    with pytest.raises(kin.ConfigurationError, match="q0"):
        r.ik(T, q0=Q[:3], seed=0)
    empty = r.ik(np.zeros((0, 4, 4)), seed=0)
    assert empty.q.shape == (0, 6) and empty.success.shape == (0,)


@pytest.mark.parametrize("name", ["puma560", "scara_rrp", "cnc_rrrppp"])
@pytest.mark.parametrize("far", [1e308, -1e308, 1e200, 1e3])
def test_absurdly_far_targets_fail_with_a_defined_configuration(name, far):
    """A target whose squared error overflows (1e200, 1e308 m) fails like any unreachable one: success
    False, the seed (q0, clipped to the limits) or a finite configuration inside the limits, and its
    true position error — never uninitialised memory (6.9e-310 …), never a RuntimeWarning."""
    import warnings
    r = robot(name)
    c = r.chain
    lo, hi = c.lower, c.upper
    q0 = np.clip(lo + 0.3 * (hi - lo), lo, hi)
    p = np.array([far, -0.5 * far, 0.25 * far])
    T = np.eye(4)
    T[:3, 3] = p
    targets = [p] + ([T] if len(r.task_rows) == 6 else [])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for tgt in targets:
            for batch in (False, True):
                t = np.stack([tgt, tgt]) if batch else tgt
                for kw in ({}, {"q0": q0}):
                    res = r.ik(t, seed=3, **kw)
                    Q, pe = np.atleast_2d(res.q), np.atleast_1d(res.position_error)
                    assert not np.any(res.success)
                    assert np.all(np.isfinite(Q)) and np.all(c.within_limits(Q)), Q
                    if abs(far) >= 1e200:          # no step lowers an infinite cost: the start comes back
                        assert pe == pytest.approx(np.linalg.norm(p / far) * abs(far), rel=1e-9)
                        if kw:
                            np.testing.assert_array_equal(Q, np.broadcast_to(q0, Q.shape))
                    else:                          # an ordinary unreachable target: the residual is the real one
                        for q, e in zip(Q, pe):
                            assert e == pytest.approx(np.linalg.norm(fk_numpy(c, q)[:3, 3] - p), rel=1e-9)


@pytest.mark.parametrize("shape", [(4, 5), (3, 3), (2,), (4,), (3, 4), (4, 4, 4, 4), (2, 3, 3), ()])
def test_bad_target_shapes(shape):
    with pytest.raises(kin.ConfigurationError, match="IK target has shape"):
        robot("puma560").ik(np.zeros(shape))


def test_non_finite_target_and_bad_options():
    r = robot("puma560")
    T = np.eye(4)
    T[0, 3] = math.nan
    with pytest.raises(kin.ConfigurationError, match="NaN"):
        r.ik(T)
    with pytest.raises(kin.ConfigurationError, match="pose"):
        r.ik(np.array([0.3, 0.1, 0.5]), mode="pose")
    with pytest.raises(ValueError, match="auto, pose, position"):
        r.ik(np.eye(4), mode="joint")
    with pytest.raises(kin.ConfigurationError):
        r.ik(np.eye(4), q0=np.full(6, math.nan))
    with pytest.raises(kin.ConfigurationError):
        r.ik(np.eye(4), q0=np.zeros(5))
