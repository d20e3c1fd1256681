"""The benchmark's peer models (studies/benchmarks/peers.py) are the same machines as rmtkit's.

``bench_kin`` rebuilds each arm from its DH table in pinocchio (a ``pin.Model`` joint by joint, with
an operational frame at the tool) and in roboticstoolbox-python (``DHRobot``).  Its speed and
agreement figures only mean something if those conversions are right, so these tests compare the
peers' tool pose and geometric Jacobian (base frame, tool point) with rmtkit's for every bundled
6-joint robot, in standard DH and converted to modified DH (``chain.to_modified()``), and for
variants with non-zero joint offsets and a non-trivial base and tool — through the calls the
benchmark times (pinocchio's ``computeFrameJacobian``, roboticstoolbox's C++ ETS path).  No timing here.

rmtkit is evaluated with the CasADi-VM backend (same numbers as the compiled one, no compiler or
cache needed).  Tests skip when pinocchio / roboticstoolbox are not installed (``bench`` extra).
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import kin
from kin.chain import Placement
from kin.compiled import WANT_J, WANT_T
from studies.benchmarks import peers

TOL = 1e-12

SIX_JOINT = [name for name in kin.bundled_robots() if kin.load_chain(name).n == 6]


def _with_offsets(chain):
    """The chain with non-zero joint offsets (θ for revolute, θ and d for prismatic), base and tool."""
    joints = []
    for i, j in enumerate(chain.joints):
        extra = {"theta": float(j.theta) + 0.3 * (i + 1) - 0.7}
        if j.type == "prismatic":
            extra["d"] = float(j.d) + 0.05 * (i + 1)
        joints.append(dataclasses.replace(j, **extra))
    return dataclasses.replace(chain, name=chain.name + "_offsets", joints=tuple(joints),
                               base=Placement(xyz=(0.1, -0.2, 0.3), rpy=(0.2, -0.4, 1.1)),
                               tool=Placement(xyz=(0.01, 0.02, 0.15), rpy=(-0.3, 0.5, 0.7)))


def _chains():
    for name in SIX_JOINT:
        std = kin.load_chain(name)
        off = _with_offsets(std)
        for label, chain in (("standard", std), ("modified", std.to_modified()),
                             ("offsets-standard", off), ("offsets-modified", off.to_modified())):
            yield pytest.param(chain, id=f"{name}-{label}")


def _rmtkit(chain, count=25, seed=7):
    robot = kin.Robot(chain, backend="vm")
    Q = robot.random_configurations(count, seed=seed)
    res, _ = robot.evaluate(Q, WANT_T | WANT_J)
    return Q, res["T"], res["J"]


def test_six_joint_robots_present():
    assert {"fanuc_m16ib20", "ur5e", "puma560"} <= set(SIX_JOINT)


def test_conventions_covered():
    conventions = {c.values[0].convention for c in _chains()}
    assert conventions == {"standard", "modified"}
    types = {t for c in _chains() for t in c.values[0].joint_types}
    assert types == {"revolute", "prismatic"}


@pytest.mark.parametrize("chain", list(_chains()))
def test_pinocchio_model_matches_rmtkit(chain):
    pytest.importorskip("pinocchio")
    Q, T, J = _rmtkit(chain)
    model, fid = peers.pinocchio_model(chain)
    assert model.nq == chain.n
    np.testing.assert_allclose(model.lowerPositionLimit, chain.lower)
    np.testing.assert_allclose(model.upperPositionLimit, chain.upper)
    data = model.createData()
    for q, Tk, Jk in zip(Q, T, J):
        Tp, Jp = peers.pinocchio_fk_jacobian(model, data, fid, q)
        np.testing.assert_allclose(Tp, Tk, rtol=0, atol=TOL)
        np.testing.assert_allclose(Jp, Jk, rtol=0, atol=TOL)


@pytest.mark.parametrize("chain", list(_chains()))
def test_rtb_ets_fast_path_matches_rmtkit(chain):
    """The C++ ETS path the benchmark times: batch ``eval``, ``jacob0``, and the timed loops' values."""
    pytest.importorskip("roboticstoolbox")
    Q, T, J = _rmtkit(chain)
    assert peers.rtb_robot(chain).mdh == (chain.convention == "modified")
    ets = peers.rtb_ets(chain)
    assert ets.n == chain.n
    Tb, Jb = peers.rtb_batch(chain, Q)
    np.testing.assert_allclose(Tb, T, rtol=0, atol=TOL)
    np.testing.assert_allclose(Jb, J, rtol=0, atol=TOL)
    np.testing.assert_allclose(peers.rtb_batch(chain, Q[:1])[0], T[:1], rtol=0, atol=TOL)  # single-row batch
    loops = peers.rtb_loops(chain, Q)
    np.testing.assert_allclose(loops.fk_j_manip(), np.abs(np.linalg.det(J)), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(loops.fk_batch(), T, rtol=0, atol=TOL)
    Ts, Js = loops.single_fk_j()
    np.testing.assert_allclose(Ts, T[0], rtol=0, atol=TOL)
    np.testing.assert_allclose(Js, J[0], rtol=0, atol=TOL)


@pytest.mark.parametrize("chain", list(_chains())[:4])
def test_pinocchio_loops_compute_the_same(chain):
    """The timed pinocchio loop (computeFrameJacobian, hoisted frame placement) gives rmtkit's values."""
    pytest.importorskip("pinocchio")
    Q, T, J = _rmtkit(chain)
    loops = peers.pinocchio_loops(chain, Q)
    np.testing.assert_allclose(loops.fk_j_manip(), np.abs(np.linalg.det(J)), rtol=1e-9, atol=1e-12)
    J0, T0 = loops.single_fk_j()
    np.testing.assert_allclose(T0, T[0], rtol=0, atol=TOL)
    np.testing.assert_allclose(J0, J[0], rtol=0, atol=TOL)


@pytest.mark.parametrize("name", ["fanuc_m16ib20", "stanford_arm", "cnc_rrrppp"])
def test_finite_difference_jacobian_helper(name):
    """The benchmark's central-difference Jacobian (position and rotation rows) matches rmtkit's J."""
    chain = kin.load_chain(name)
    robot = kin.Robot(chain, backend="vm")
    Q, _, J = _rmtkit(chain, count=10)
    fk = lambda X: robot.evaluate(X, WANT_T)[0]["T"]
    Jfd = peers.fd_jacobian(fk, Q, 1e-5)
    np.testing.assert_allclose(Jfd, J, rtol=0, atol=1e-8)


def test_log_so3_small_and_large_angles():
    axis = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    for angle in (0.0, 1e-9, 1e-4, 0.5, 2.5):
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        R = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
        np.testing.assert_allclose(peers._log_so3(R), angle * axis, rtol=0, atol=1e-14)
