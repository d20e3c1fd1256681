"""Tests of torque-limited timing (``time_parameterize(..., robot=, tau_max=)``,
planning/timing/torque.py): closed forms for a vertical prismatic lift (constant gravity: an
asymmetric bang-bang) and a pendulum (energy integrals), torques recomputed independently (m·(q̈ + g)
by hand, ``Robot.inverse_dynamics`` for the Panda), dense limits, errors, and TOPP-RA's
``JointTorqueConstraint`` as a peer when toppra is installed."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

import kin
from kin.chain import Chain, Joint
from kin.dynamics import LinkInertia
from planning.timing import TimingError, blend_path, time_parameterize

G = 9.81
PANDA_TAU = np.array([87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0])
PANDA_V = np.array([2.175] * 4 + [2.61] * 3)
PANDA_A = np.array([15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0])


def lift(m: float, viscous: float = 0.0) -> kin.Robot:
    """One prismatic joint along the base z axis (gravity −z) carrying a point mass m: τ = m·(q̈ + g)
    + viscous·q̇."""
    j = Joint("prismatic", limits=(-2.0, 2.0), inertia=LinkInertia(m, viscous=viscous))
    return kin.Robot(Chain("lift", (j,)))


def pendulum(m: float, length: float) -> kin.Robot:
    """One revolute joint about a horizontal axis (gravity −y of the base, the joint turns about z)
    with a point mass m at distance ``length``: τ = m·l²·q̈ + m·g·l·cos q."""
    j = Joint("revolute", a=length, limits=(-3.0, 3.0), inertia=LinkInertia(m))
    return kin.Robot(Chain("pendulum", (j,), gravity=(0.0, -G, 0.0)))


def bang_bang_lift(L: float, a_up: float, a_down: float) -> float:
    """Rest-to-rest time over L accelerating at a_up and braking at a_down (no speed limit)."""
    v = math.sqrt(2 * L * a_up * a_down / (a_up + a_down))
    return v / a_up + v / a_down


def panda_path(seed: int = 1, m: int = 6) -> np.ndarray:
    lim = kin.load_chain("franka_panda").limits
    rng = np.random.default_rng(seed)
    return lim.mean(1) + 0.5 * (lim[:, 1] - lim[:, 0]) / 2 * rng.uniform(-1, 1, (m, 7))


@pytest.mark.parametrize("up", [True, False])
@pytest.mark.parametrize("method", ["reach", "qp"])
def test_vertical_lift_is_the_asymmetric_bang_bang(up, method):
    m, tmax, L = 2.0, 40.0, 0.6
    W = np.array([[0.0], [L]]) if up else np.array([[L], [0.0]])
    K = 2000 if method == "reach" else 300       # OSQP's first-order iterations: a coarser grid
    tr = time_parameterize(W, 100.0, 1000.0, robot=lift(m), tau_max=tmax, method=method, ds=L / K)
    a1, a2 = tmax / m - G, tmax / m + G          # up: accelerate against gravity, brake with it (reversed down)
    T = bang_bang_lift(L, a1, a2)
    assert tr.duration == pytest.approx(T, rel=2e-3 if method == "reach" else 1e-2)
    assert tr.duration >= T * (1 - 1e-6)
    # the torque by hand: m·(q̈ + g), at the samples and densely
    assert np.allclose(tr.tau[:, 0], m * (tr.qdd[:, 0] + G), atol=1e-9 * tmax)
    _, qd, qdd = tr.sample(np.linspace(0, tr.duration, 20001))
    assert np.max(np.abs(m * (qdd[:, 0] + G))) <= tmax * (1 + 1e-6)
    assert tr.max_torque_ratio <= 1 + 1e-6 and tr.max_torque_ratio > 0.999
    assert tr.tau_max.tolist() == [tmax]


def test_viscous_friction_is_bounded_conservatively():
    m, tmax, L, c = 2.0, 40.0, 0.6, 6.0
    tr = time_parameterize(np.array([[0.0], [L]]), 100.0, 1000.0, robot=lift(m, viscous=c), tau_max=tmax,
                           ds=L / 1000)
    _, qd, qdd = tr.sample(np.linspace(0, tr.duration, 20001))
    tau = m * (qdd[:, 0] + G) + c * qd[:, 0]
    assert np.max(np.abs(tau)) <= tmax * (1 + 1e-6)
    assert np.max(tau) > 0.97 * tmax                   # the tangent bound costs little
    T0 = bang_bang_lift(L, tmax / m - G, tmax / m + G)
    assert T0 < tr.duration < 1.15 * T0


def test_pendulum_matches_the_energy_integrals():
    m, ell, tmax = 1.5, 0.7, 15.0                     # m·g·l = 10.3 N·m
    q0, qf = -1.0, 1.2
    tr = time_parameterize(np.array([[q0], [qf]]), 100.0, 1000.0, robot=pendulum(m, ell), tau_max=tmax,
                           ds=(qf - q0) / 2000)
    inertia, mgl = m * ell ** 2, m * G * ell

    def speed2_acc(q):          # ½·m·l²·q̇² after accelerating with +tmax from q0 at rest
        return 2 * (tmax * (q - q0) - mgl * (math.sin(q) - math.sin(q0))) / inertia

    def speed2_brake(q):        # before braking with −tmax to rest at qf
        return 2 * (tmax * (qf - q) + mgl * (math.sin(qf) - math.sin(q))) / inertia
    lo, hi = q0, qf
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if speed2_acc(mid) < speed2_brake(mid) else (lo, mid)
    qs = 0.5 * (lo + hi)
    T = (quad(lambda q: 1 / math.sqrt(speed2_acc(q)), q0, qs)[0]
         + quad(lambda q: 1 / math.sqrt(speed2_brake(q)), qs, qf)[0])
    assert tr.duration == pytest.approx(T, rel=3e-3)
    assert tr.duration >= T * (1 - 1e-6)
    _, qd, qdd = tr.sample(np.linspace(0, tr.duration, 20001))
    q = tr.sample(np.linspace(0, tr.duration, 20001))[0]
    tau = inertia * qdd[:, 0] + mgl * np.cos(q[:, 0])
    assert np.max(np.abs(tau)) <= tmax * (1 + 1e-6)


@pytest.mark.parametrize("method", ["reach", "qp"])
def test_panda_torques_are_the_inverse_dynamics_and_hold_densely(method):
    robot = kin.load_robot("franka_panda")
    W = panda_path()
    tmax = 0.6 * PANDA_TAU
    free = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=np.inf)
    tr = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=tmax, method=method)
    assert np.allclose(tr.tau, robot.inverse_dynamics(tr.q, tr.qd, tr.qdd), rtol=1e-9, atol=1e-9)
    assert free.tau is not None and free.tau_max is None and free.max_torque_ratio is None
    # without tau_max the file's published limits (87 N·m on joints 1–4, 12 N·m on 5–7) apply
    filed = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, method=method)
    assert filed.tau_max.tolist() == [87.0] * 4 + [12.0] * 3 and filed.max_torque_ratio <= 1 + 1e-6
    assert np.max(np.abs(free.tau) / tmax) > 1.0       # the limit matters on this path
    assert tr.duration > free.duration
    ts = np.linspace(0, tr.duration, 30001)
    tau = robot.inverse_dynamics(*tr.sample(ts))
    assert np.max(np.abs(tau) / tmax) <= 1 + 1e-3      # far denser than the code's own re-check
    assert tr.max_torque_ratio <= 1 + 1e-6
    assert max(tr.max_velocity_ratio, tr.max_acceleration_ratio) <= 1 + 1e-9 and tr.overshoot <= 1e-9


def test_reach_and_qp_agree_with_torque_limits():
    robot = kin.load_robot("franka_panda")
    W = panda_path(seed=3)
    # on the default grid (300 intervals) the greedy forward pass is 2.4 % slower than the QP here: the
    # torque rows' ṡ² terms couple b_i and b_{i+1} so that the stage sets have no greatest element; on a
    # finer grid the coupling fades (reachability.py)
    ds = blend_path(W, 0.05).length / 1000 * (1 + 1e-12)
    a = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=0.6 * PANDA_TAU, ds=ds)
    b = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=0.6 * PANDA_TAU, method="qp", ds=ds)
    assert b.duration == pytest.approx(a.duration, rel=1e-3)


def test_holding_against_gravity_is_checked_in_one_line():
    with pytest.raises(TimingError) as e:
        time_parameterize(np.array([[0.0], [0.5]]), 1.0, 1.0, robot=lift(3.0), tau_max=20.0)
    msg = str(e.value)
    assert "\n" not in msg and "joint 1" in msg and "29.43 N" in msg and "s = 0" in msg


def test_bad_torque_arguments_are_one_line_errors():
    W = np.array([[0.0], [0.5]])
    for kw, what in (({"tau_max": 5.0}, "needs robot"), ({"robot": lift(1.0), "tau_max": -1.0}, "positive"),
                     ({"robot": lift(1.0), "tau_max": [1.0, 2.0]}, "positive"),
                     ({"robot": kin.load_robot("planar_2r")}, "joints")):
        with pytest.raises(TimingError, match=what) as e:
            time_parameterize(W, 1.0, 1.0, **kw)
        assert "\n" not in str(e.value)
    with pytest.raises(kin.DynamicsError) as e:
        time_parameterize(np.zeros((2, 6)) + [[0.0] * 6, [0.1] * 6], 1.0, 1.0, robot=kin.load_robot("fanuc_m16ib20"),
                          tau_max=100.0)
    assert "\n" not in str(e.value)


def test_against_toppra_joint_torque_constraint():
    pytest.importorskip("toppra")
    import toppra
    import toppra.algorithm
    import toppra.constraint

    from studies.benchmarks.bench_timing import ToppraPath
    robot = kin.load_robot("franka_panda")
    W = panda_path()
    tmax = 0.6 * PANDA_TAU
    bp = blend_path(W, 0.05)
    # a uniform grid of 300 intervals (the default grid refines the blends, where toppra's interpolation
    # scheme is then the more conservative one): the comparison is of the torque rows on one grid
    tr = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=tmax, blend=0.05, ds=bp.length / 300)
    cons = [toppra.constraint.JointVelocityConstraint(np.c_[-PANDA_V, PANDA_V]),
            toppra.constraint.JointAccelerationConstraint(np.c_[-PANDA_A, PANDA_A]),
            toppra.constraint.JointTorqueConstraint(robot.inverse_dynamics, np.c_[-tmax, tmax], np.zeros(7))]
    inst = toppra.algorithm.TOPPRA(cons, ToppraPath(bp), gridpoints=tr.grid, parametrizer="ParametrizeConstAccel")
    jt = inst.compute_trajectory()
    assert jt is not None
    # rmtkit imposes the limits at both ends of every segment and re-checks densely: never much faster
    assert 0.995 * jt.duration <= tr.duration <= 1.02 * jt.duration


def test_numpy_backend_and_jerk_limits_with_torque():
    robot = kin.load_robot("franka_panda")
    W = panda_path()
    tmax = 0.6 * PANDA_TAU
    a = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=tmax)
    b = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=tmax, backend="numpy")
    assert b.duration == pytest.approx(a.duration, rel=1e-9)
    c = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=tmax, j_max=200.0)
    assert c.duration >= a.duration * (1 - 1e-9)
    assert c.max_torque_ratio <= 1 + 1e-6 and c.max_jerk_ratio <= 1 + 1e-9
    assert np.allclose(c.tau, robot.inverse_dynamics(c.q, c.qd, c.qdd), rtol=1e-9, atol=1e-9)


def test_a_greedy_stop_mid_path_is_repaired():
    """On this Panda path with 0.6 × the published torques the greedy forward pass comes to rest at
    an interior grid point after the tightening round (found while merging the jerk pass); the local
    LP repair (planning.timing.repair) must remove the rest and come within 0.2 % of the QP's
    duration on the same grid."""
    robot = kin.load_robot("franka_panda")
    W = panda_path()
    ds = blend_path(W, 0.05).length / 300          # the uniform grid the stop was found on
    tr = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=0.6 * PANDA_TAU, ds=ds)
    qp = time_parameterize(W, PANDA_V, PANDA_A, robot=robot, tau_max=0.6 * PANDA_TAU, method="qp", ds=ds)
    assert np.min(tr.sd[1:-1]) > 0.1 and "mid-path repaired" in tr.qp_status
    assert tr.duration <= qp.duration * (1 + 2e-3)
    assert tr.max_torque_ratio <= 1 + 1e-6
