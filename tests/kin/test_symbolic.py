"""kin.symbolic: the CasADi graph (FK, geometric Jacobian, frames, manipulability, derivatives with
respect to design parameters) against independent values — the numpy DH implementation of
tests/dh_numpy.py, central finite differences and closed forms.  No compiled code is involved here
except where the product's ``Robot.fk`` supplies the finite differences of a parameter derivative."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

import kin
from kin.chain import Chain, Joint, Parameter, Placement
from kin.symbolic import SymbolicChain, exact_cos_sin
from tests.chain_factory import fd_jacobian, random_chain, random_q
from tests.dh_numpy import fk_numpy, frames_numpy, jacobian_numpy

ROBOTS = sorted(kin.bundled_robots())
H = 1e-6
FD_TOL = 1e-7


def sym_fk(sym: SymbolicChain, p=None):
    p = sym.chain.parameter_values if p is None else p
    return lambda q: np.array(sym.fk_function(q, p))


def sym_jac(sym: SymbolicChain, q, p=None) -> np.ndarray:
    p = sym.chain.parameter_values if p is None else p
    return np.array(sym.jacobian_function(q, p))


RANDOM_CASES = [(seed, conv, params) for seed in range(6) for conv in ("standard", "modified")
                for params in (False, True)]


# ===================================================================================== FK
@pytest.mark.parametrize("seed, convention, params", RANDOM_CASES)
def test_fk_matches_numpy_random_chains(seed, convention, params):
    c = random_chain(seed, convention=convention, params=params)
    sym = SymbolicChain(c)
    for q in random_q(c, 5, seed):
        np.testing.assert_allclose(sym_fk(sym)(q), fk_numpy(c, q), atol=1e-12, rtol=0)


@pytest.mark.parametrize("name", ROBOTS)
def test_fk_and_frames_match_numpy_bundled(name):
    c = kin.load_chain(name)
    sym = SymbolicChain(c)
    for q in random_q(c, 4, 7):
        F, T = sym.frames_function(q, c.parameter_values)
        F = np.array(F)
        ref = frames_numpy(c, q)
        for i in range(c.n + 1):
            np.testing.assert_allclose(F[:, 4 * i:4 * i + 4], ref[i], atol=1e-12)
        np.testing.assert_allclose(np.array(T), fk_numpy(c, q), atol=1e-12)


def test_fk_with_parameters_other_than_nominal():
    c = random_chain(4, params=True)
    sym = SymbolicChain(c)
    rng = np.random.default_rng(4)
    for q in random_q(c, 3, 4):
        p = c.parameter_values + rng.uniform(-0.5, 0.5, len(c.parameters))
        ref = fk_numpy(c.with_parameters(dict(zip(c.parameter_names, p))), q)
        np.testing.assert_allclose(sym_fk(sym, p)(q), ref, atol=1e-12)


# =============================================================================== Jacobian
@pytest.mark.parametrize("name", ROBOTS)
def test_jacobian_vs_finite_differences_bundled(name):
    c = kin.load_chain(name)
    sym = SymbolicChain(c)
    for q in random_q(c, 4, 11):
        J = sym_jac(sym, q)
        np.testing.assert_allclose(J, fd_jacobian(sym_fk(sym), q, H), atol=FD_TOL, rtol=0)
        np.testing.assert_allclose(J, jacobian_numpy(c, q), atol=1e-12, rtol=0)


@pytest.mark.parametrize("seed, convention, params", RANDOM_CASES)
def test_jacobian_vs_finite_differences_random(seed, convention, params):
    c = random_chain(seed + 50, convention=convention, params=params)
    sym = SymbolicChain(c)
    for q in random_q(c, 4, seed):
        J = sym_jac(sym, q)
        assert J.shape == (6, c.n)
        np.testing.assert_allclose(J, fd_jacobian(sym_fk(sym), q, H), atol=FD_TOL, rtol=0)


def test_jacobian_of_planar_2r_closed_form():
    sym = SymbolicChain(kin.load_chain("planar_2r"))
    for t1, t2 in [(0.3, -1.2), (2.0, 0.5)]:
        J = sym_jac(sym, [t1, t2])
        s1, c1, s12, c12 = math.sin(t1), math.cos(t1), math.sin(t1 + t2), math.cos(t1 + t2)
        expected = [[-s1 - 0.8 * s12, -0.8 * s12], [c1 + 0.8 * c12, 0.8 * c12], [0, 0], [0, 0], [0, 0], [1, 1]]
        np.testing.assert_allclose(J, expected, atol=1e-15)


def test_prismatic_column_is_its_axis():
    """A prismatic joint's column is [z; 0] whatever the other joints do (spherical RRP)."""
    c = kin.load_chain("spherical_rrp")
    sym = SymbolicChain(c)
    for q in random_q(c, 5, 3):
        J = sym_jac(sym, q)
        t1, t2 = q[0], q[1]
        # p = (-d3 c1 s2, -d3 s1 s2, 3 - d3 c2): ∂p/∂d3 = (-c1 s2, -s1 s2, -c2)
        np.testing.assert_allclose(J[:, 2], [-math.cos(t1) * math.sin(t2), -math.sin(t1) * math.sin(t2),
                                             -math.cos(t2), 0, 0, 0], atol=1e-15)


# ============================================================================ cos/sin graph
def test_fkj_cs_equals_fkj():
    c = random_chain(9, params=True)
    sym = SymbolicChain(c)
    for q in random_q(c, 3, 9):
        T1, J1 = sym.fkj_function(q, c.parameter_values)
        T2, J2 = sym.fkj_cs_function(np.cos(q), np.sin(q), q, c.parameter_values)
        np.testing.assert_allclose(np.array(T2), np.array(T1), atol=1e-15)
        np.testing.assert_allclose(np.array(J2), np.array(J1), atol=1e-15)


def test_exact_cos_sin_snaps_right_angles():
    for k, (c, s) in enumerate([(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]):
        assert exact_cos_sin(k * math.pi / 2) == (c, s)
        assert exact_cos_sin(k * math.pi / 2 - 2 * math.pi) == (c, s)
    assert exact_cos_sin(math.radians(-90.0)) == (0.0, -1.0)
    c, s = exact_cos_sin(0.3)
    assert (c, s) == (math.cos(0.3), math.sin(0.3))


def test_right_angle_twists_leave_no_spurious_terms():
    """FANUC's ±90° twists: at q = 0 the pose is exactly R = I, p = (1.02, 0, 1.365) (docs/machines.md §3)."""
    sym = SymbolicChain(kin.load_chain("fanuc_m16ib20"))
    T = sym_fk(sym)(np.zeros(6))
    assert np.array_equal(T[:3, :3], np.eye(3))
    assert T[1, 3] == 0.0
    np.testing.assert_allclose(T[:3, 3], [1.02, 0.0, 1.365], atol=1e-15)


# ================================================================================ task rows
@pytest.mark.parametrize("name, rows", [("planar_2r", (0, 1)), ("scara_rrp", (0, 1, 2)),
                                        ("spherical_rrp", (0, 1, 2)), ("puma560", tuple(range(6))),
                                        ("cnc_rrrppp", tuple(range(6)))])
def test_task_rows(name, rows):
    assert SymbolicChain(kin.load_chain(name)).task_rows == rows


def test_zero_rows_of_a_planar_chain_without_task():
    joints = (Joint("revolute", a=1.0), Joint("revolute", a=0.5), Joint("prismatic", a=0.2, alpha=0.0, limits=(0, 1)))
    sym = SymbolicChain(Chain(name="planar", joints=joints))
    # z and the rx, ry rows vanish; the prismatic joint moves along z so z is NOT zero here
    assert 3 in sym.zero_rows and 4 in sym.zero_rows and 2 not in sym.zero_rows
    assert sym.task_rows == (0, 1, 2)
    joints2 = joints[:2]
    sym2 = SymbolicChain(Chain(name="planar2", joints=joints2))
    assert set(sym2.zero_rows) == {2, 3, 4}
    assert sym2.task_rows == (0, 1)


# ========================================================================== manipulability
@pytest.mark.parametrize("name", ROBOTS)
def test_manipulability_function_vs_numpy(name):
    c = kin.load_chain(name)
    sym = SymbolicChain(c)
    rows = list(sym.task_rows)
    for q in random_q(c, 4, 21):
        s = np.linalg.svd(jacobian_numpy(c, q)[rows], compute_uv=False)
        w = float(sym.manipulability_function(q, c.parameter_values))
        assert w == pytest.approx(np.prod(s), rel=1e-8, abs=1e-14)


def test_manipulability_function_at_fanuc_wrist_singularity():
    c = kin.load_chain("fanuc_m16ib20")
    sym = SymbolicChain(c)
    q = np.array([0.3, 0.4, 0.5, 0.6, 0.0, 0.8])
    assert float(sym.manipulability_function(q, [])) <= 1e-12


# ==================================================================== design-parameter derivatives
def param_chain() -> Chain:
    params = {"L2": Parameter(0.7, (0.3, 1.2)), "TW": Parameter(0.4, (-1.0, 1.0), "angle"),
              "D3": Parameter(0.1, (0.0, 0.5))}
    joints = (Joint("revolute", a=0.3, alpha=-math.pi / 2, d=0.4),
              Joint("revolute", a="L2", alpha="TW"),
              Joint("revolute", a=0.05, alpha=math.pi / 2, d="D3"),
              Joint("prismatic", a=0.1, alpha=-0.3, theta=0.2, limits=(0.0, 0.4)))
    return Chain(name="param_chain", joints=joints, parameters=params,
                 tool=Placement(xyz=(0.0, 0.05, 0.1), rpy=(0.1, 0.2, 0.3)))


@pytest.mark.parametrize("pname", ["L2", "TW", "D3"])
def test_fk_derivative_wrt_design_parameter(pname):
    c = param_chain()
    robot = kin.Robot(c)
    sym = robot.symbolic
    k = c.parameter_names.index(pname)
    dT_dp = ca.Function("dT", [sym.q, sym.p], [ca.jacobian(sym.fk_function(sym.q, sym.p), sym.p)])
    v = c.parameters[pname].value
    h = 1e-6
    for q in random_q(c, 4, 2):
        D = np.array(dT_dp(q, c.parameter_values))          # (16, n_p), column-major 4×4
        analytic = D[:, k].reshape(4, 4, order="F")
        fd = (robot.fk(q, params={pname: v + h}) - robot.fk(q, params={pname: v - h})) / (2 * h)
        np.testing.assert_allclose(analytic, fd, atol=1e-8)
        assert np.abs(analytic).max() > 1e-3  # the parameter really moves the tool


def test_jacobian_derivative_wrt_design_parameter():
    c = param_chain()
    robot = kin.Robot(c)
    sym = robot.symbolic
    dJ = ca.Function("dJ", [sym.q, sym.p], [ca.jacobian(sym.J, sym.p)])
    h = 1e-6
    for q in random_q(c, 3, 5):
        D = np.array(dJ(q, c.parameter_values))
        for k, pname in enumerate(c.parameter_names):
            v = c.parameters[pname].value
            fd = (robot.jacobian(q, params={pname: v + h}) - robot.jacobian(q, params={pname: v - h})) / (2 * h)
            np.testing.assert_allclose(D[:, k].reshape(6, c.n, order="F"), fd, atol=1e-8)


def test_manipulability_is_differentiable_wrt_parameters():
    c = param_chain()
    sym = SymbolicChain(c)
    w = sym.manipulability_function(sym.q, sym.p)
    dw = ca.Function("dw", [sym.q, sym.p], [ca.jacobian(w, sym.p)])
    q = np.array([0.3, 0.9, -0.4, 0.2])
    h = 1e-6
    for k in range(len(c.parameters)):
        e = np.zeros(len(c.parameters))
        e[k] = h
        p = c.parameter_values
        fd = (float(sym.manipulability_function(q, p + e)) - float(sym.manipulability_function(q, p - e))) / (2 * h)
        assert float(np.array(dw(q, p))[0, k]) == pytest.approx(fd, abs=1e-7)
