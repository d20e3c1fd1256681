"""The compiled inverse-dynamics evaluator (kin/dynamics/kernel.c through kin.dynamics.evaluator)
against CasADi's VM and the independent numpy Newton–Euler of test_rnea (pinocchio too when it is
installed): random revolute/prismatic chains in both DH conventions, with design parameters in their
DH rows, Coulomb friction at q̇ = 0, batch sizes across the kernel's blocks and threads, the
single-configuration fast lane and its refusals, and the fallback without a compiler."""
import dataclasses

import numpy as np
import pytest

import kin
from kin.chain import Parameter
from kin.dynamics import LinkInertia
from kin.dynamics.evaluator import FUNCTIONS, STATES, CompiledDynamics, VMDynamics, make_dynamics_evaluator
from kin.errors import CompileError, ConfigurationError, ParameterError
from kin.native import find_compiler
from tests.kin.dynamics.test_rnea import numpy_rnea, pinocchio_dynamics_model, random_chain, rel_err, rods_2r

needs_cc = pytest.mark.skipif(find_compiler() is None, reason="no C compiler (RMTKIT_CC=none or none installed)")


def parametrised(chain):
    """The chain with a, d (lengths) and theta (an angle) of every other joint made design parameters,
    their nominal values the numbers they replace — the same robot, symbolic in p."""
    params, joints = {}, []
    for k, j in enumerate(chain.joints):
        if k % 2 == 0:
            for f, kind in (("a", "length"), ("d", "length"), ("theta", "angle")):
                v = getattr(j, f)
                params[f"{f}{k}"] = Parameter(v, (v - 1.0, v + 1.0), kind)
            j = dataclasses.replace(j, a=f"a{k}", d=f"d{k}", theta=f"theta{k}")
        joints.append(j)
    return dataclasses.replace(chain, joints=tuple(joints), parameters=params)


def with_friction(chain, rng):
    joints = tuple(j if j.inertia is None else dataclasses.replace(
        j, inertia=dataclasses.replace(j.inertia, viscous=rng.uniform(0, 2), coulomb=rng.uniform(0.1, 3)))
        for j in chain.joints)
    return dataclasses.replace(chain, joints=joints)


def states(chain, rng, N):
    Q = rng.uniform(chain.lower, chain.upper, (N, chain.n))
    QD, QDD = rng.uniform(-2, 2, (N, chain.n)), rng.uniform(-5, 5, (N, chain.n))
    QD[::3, 0] = 0.0       # Coulomb friction's sign(0) = 0, and -0
    QD[1::3, -1] = -0.0
    return Q, QD, QDD


def all_functions(ev, Q, QD, QDD, P):
    S = [Q, QD, QDD]
    return {name: ev.evaluate(name, S[:STATES[name]], P) for name in FUNCTIONS}


@needs_cc
@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("seed", [30, 31])
def test_compiled_matches_the_vm_and_numpy_newton_euler(seed, convention):
    rng = np.random.default_rng(seed)
    chain = parametrised(with_friction(random_chain(seed, convention, n=5, motor=True), rng))
    assert chain.parameters and ("prismatic" in chain.joint_types) == (seed != 31)   # 31: all revolute
    robot = kin.Robot(chain)
    ev = robot.dynamics_evaluator
    assert isinstance(ev, CompiledDynamics) and ev.backend == "compiled"
    vm = VMDynamics(robot.dynamics)
    for N in (1, 7, 4099):
        Q, QD, QDD = states(chain, rng, N)
        # design parameters: nominal (shared), other shared values, one row each
        p0 = chain.parameter_values
        for P in (p0, p0 + rng.uniform(-0.3, 0.3, p0.shape), p0 + rng.uniform(-0.3, 0.3, (N, len(p0)))):
            got, ref = all_functions(ev, Q, QD, QDD, P), all_functions(vm, Q, QD, QDD, P)
            for name in FUNCTIONS:
                assert got[name].shape == ref[name].shape
                assert rel_err(got[name], ref[name]) < 1e-12, (name, N)
        # the independent numpy Newton–Euler, on rows spread over the batch (nominal parameters)
        tau = robot.inverse_dynamics(Q, QD, QDD)
        M = robot.mass_matrix(Q)
        flat = dataclasses.replace(chain, gravity=(0.0, 0.0, 0.0))
        for k in sorted({0, N // 2, N - 1}):
            assert rel_err(tau[k], numpy_rnea(chain, Q[k], QD[k], QDD[k])) < 1e-10
            Mn = np.column_stack([numpy_rnea(flat, Q[k], 0 * Q[k], e, friction=False) for e in np.eye(chain.n)])
            assert rel_err(M[k], Mn) < 1e-10


@needs_cc
def test_threads_and_blocks_give_the_same_rows():
    chain = random_chain(32, "standard", n=6, motor=True)
    ev = kin.Robot(chain).dynamics_evaluator
    rng = np.random.default_rng(2)
    Q, QD, QDD = states(chain, rng, 8193)
    ev.threads = 1
    one = ev.evaluate("tau", [Q, QD, QDD], chain.parameter_values)
    assert ev.last_threads == 1
    ev.threads = 2
    two = ev.evaluate("tau", [Q, QD, QDD], chain.parameter_values)
    assert ev.last_threads == 2
    np.testing.assert_array_equal(one, two)
    # a row's answer does not depend on its place in a block or on the batch around it
    for k in (0, 5, 8, 4096, 8192):
        np.testing.assert_array_equal(ev.evaluate("tau", [Q[k:k + 1], QD[k:k + 1], QDD[k:k + 1]],
                                                  chain.parameter_values)[0], one[k])
    assert ev.evaluate("mass_matrix", [Q[:0]], chain.parameter_values).shape == (0, 6, 6)


@needs_cc
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_single_configuration_lane_matches_the_batch(convention):
    rng = np.random.default_rng(4)
    chain = parametrised(with_friction(random_chain(33, convention, n=5, motor=True), rng))
    robot = kin.Robot(chain)
    assert robot.dynamics_evaluator.single is not None
    Q, QD, QDD = states(chain, rng, 5)
    tau, M = robot.inverse_dynamics(Q, QD, QDD), robot.mass_matrix(Q)
    G, C = robot.gravity(Q), robot.coriolis(Q, QD)
    A, B, Cp = robot.path_torque_coefficients(Q, QD, QDD)
    for k in range(len(Q)):
        q, qd, qdd = Q[k], QD[k], QDD[k]
        t1 = robot.inverse_dynamics(q, qd, qdd)
        assert t1.shape == (chain.n,) and t1.dtype == np.float64 and t1.flags.c_contiguous
        np.testing.assert_array_equal(t1, tau[k])
        np.testing.assert_array_equal(robot.mass_matrix(q), M[k])
        np.testing.assert_array_equal(robot.gravity(q), G[k])
        np.testing.assert_array_equal(robot.coriolis(q, qd), C[k])
        for x, y in zip(robot.path_torque_coefficients(q, qd, qdd), (A[k], B[k], Cp[k])):
            np.testing.assert_array_equal(x, y)
        assert rel_err(t1, numpy_rnea(chain, q, qd, qdd)) < 1e-10
        # inputs the lane does not take as they come give the same answer through the validating path
        np.testing.assert_array_equal(robot.inverse_dynamics(list(q), tuple(qd), qdd.astype(np.float32)),
                                      robot.inverse_dynamics(q, qd, qdd.astype(np.float32).astype(float)))
        wide = np.repeat(q[:, None], 2, axis=1)[:, 0]          # not contiguous
        np.testing.assert_array_equal(robot.mass_matrix(wide), M[k])
    # other design parameters bypass the lane
    p = chain.parameter_values + 0.1
    np.testing.assert_array_equal(robot.gravity(Q[0], params=p), robot.gravity(Q[:1], params=p)[0])
    assert rel_err(robot.gravity(Q[0], params=p), robot.gravity(Q[0])) > 1e-6


@needs_cc
@pytest.mark.parametrize("q, qd, match", [
    ([np.nan, 0.0], [0.0, 0.0], "q holds a non-finite"),
    ([0.0, 0.0], [0.0, np.inf], "qd holds a non-finite"),
    ([0.0, 0.0], [0.0, 0.0, 0.0], "qd has shape"),
    ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], "q has shape"),
])
def test_the_fast_lane_refuses_like_the_batch_path(q, qd, match):
    robot = kin.Robot(rods_2r())
    assert robot.dynamics_evaluator.backend == "compiled"
    q, qd = np.array(q), np.array(qd)
    with pytest.raises(ConfigurationError, match=match) as e:
        robot.inverse_dynamics(q, qd, np.zeros_like(qd))
    assert "\n" not in str(e.value)
    with pytest.raises(ParameterError, match="design parameter"):
        robot.gravity(np.zeros(2), params={"nope": 1.0})


@needs_cc
def test_prismatic_beyond_the_range_is_refused_on_both_paths():
    chain = random_chain(34, "standard", n=4)
    j = chain.joint_types.index("prismatic")
    robot = kin.Robot(chain)
    q = np.zeros(chain.n)
    q[j] = 1e9
    for x in (q, q[None]):
        with pytest.raises(ConfigurationError, match=f"prismatic joint {j + 1}"):
            robot.inverse_dynamics(x, np.zeros_like(x), np.zeros_like(x))


def test_without_a_compiler_the_vm_evaluates(monkeypatch):
    monkeypatch.setenv("RMTKIT_CC", "none")
    chain = dataclasses.replace(rods_2r(), payload=LinkInertia(0.5))
    robot = kin.Robot(chain)
    assert robot.dynamics_evaluator.backend == "vm" and robot.dynamics_evaluator.single is None
    q, qd, qdd = np.array([0.3, -0.8]), np.array([1.0, 0.0]), np.array([0.5, 2.0])
    tau = robot.inverse_dynamics(q, qd, qdd)
    assert tau.shape == (2,) and rel_err(tau, numpy_rnea(chain, q, qd, qdd)) < 1e-12
    assert robot.mass_matrix(np.zeros((3, 2))).shape == (3, 2, 2)
    with pytest.raises(CompileError, match="no C compiler"):
        make_dynamics_evaluator(robot.dynamics, "compiled")
    assert kin.Robot(chain, backend="vm").dynamics_evaluator.backend == "vm"


@needs_cc
def test_backend_vm_forces_the_vm_with_the_same_numbers():
    chain = rods_2r()
    vm, cc = kin.Robot(chain, backend="vm"), kin.Robot(chain, backend="compiled")
    assert vm.dynamics_evaluator.backend == "vm" and cc.dynamics_evaluator.backend == "compiled"
    Q, QD, QDD = states(chain, np.random.default_rng(5), 7)
    assert rel_err(cc.inverse_dynamics(Q, QD, QDD), vm.inverse_dynamics(Q, QD, QDD)) < 1e-14
    assert rel_err(cc.mass_matrix(Q[0]), vm.mass_matrix(Q[0])) < 1e-14


@needs_cc
def test_compiled_matches_pinocchio():
    pin = pytest.importorskip("pinocchio")
    chain = random_chain(12, "modified", n=6)
    model = pinocchio_dynamics_model(chain)
    data = model.createData()
    robot = kin.Robot(chain, backend="compiled")
    Q, QD, QDD = states(chain, np.random.default_rng(6), 9)
    tau, M = robot.inverse_dynamics(Q, QD, QDD), robot.mass_matrix(Q)
    for k in range(len(Q)):
        assert rel_err(tau[k], pin.rnea(model, data, Q[k], QD[k], QDD[k])) < 1e-10
        Mp = pin.crba(model, data, Q[k]).copy()
        assert rel_err(M[k], np.triu(Mp) + np.triu(Mp, 1).T) < 1e-10
        assert rel_err(robot.inverse_dynamics(Q[k], QD[k], QDD[k]), tau[k]) < 1e-15
