"""kin.Robot's public calls refuse hostile joint values and parameters with an RmtError (issue 8 §4):
strings, complex numbers, booleans, None, ragged nestings, NaN/inf and wrong shapes — on the compiled
backend (whose single-call fast path must not let them through) and on the VM backend."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.chain import Chain, Joint, Parameter

_robots: dict = {}


def robot(backend: str) -> kin.Robot:
    if backend not in _robots:
        _robots[backend] = kin.Robot(kin.load_chain("fanuc_m16ib20"), backend=backend)
    return _robots[backend]


CALLS = ["fk", "jacobian", "fk_jacobian", "manipulability", "sigma_min", "condition", "det", "measures",
         "within_limits", "check_limits"]
Q0 = [0.1, 0.2, -0.3, 0.4, 0.5, 0.6]

BAD_VALUES = {
    "strings": ["0.1", "0.2", "0.3", "0.4", "0.5", "0.6"],
    "string array": np.array(Q0).astype(str),
    "one string": [0.1, 0.2, "x", 0.4, 0.5, 0.6],
    "complex": [0.1, 0.2, 0.3 + 1j, 0.4, 0.5, 0.6],
    "complex array": np.array(Q0, dtype=complex),
    "complex batch": np.zeros((3, 6), dtype=complex),
    "booleans": [True, False, True, False, True, False],
    "None": None,
    "Nones": [None] * 6,
    "ragged": [[0.1] * 6, [0.2] * 5],
    "dict": {"q1": 0.1},
}


@pytest.mark.parametrize("backend", ["auto", "vm"])
@pytest.mark.parametrize("call", CALLS)
@pytest.mark.parametrize("label", list(BAD_VALUES))
def test_non_real_joint_values_refused(backend, call, label):
    f = getattr(robot(backend), call)
    with pytest.raises(kin.ConfigurationError) as e:
        f(BAD_VALUES[label])
    assert "q" in str(e.value)


@pytest.mark.parametrize("backend", ["auto", "vm"])
@pytest.mark.parametrize("call", CALLS[:8])
def test_non_finite_and_wrong_shapes_refused(backend, call):
    f = getattr(robot(backend), call)
    for bad in (math.nan, math.inf, -math.inf):
        q = np.array(Q0)
        q[4] = bad
        with pytest.raises(kin.ConfigurationError, match="joint 5"):
            f(q)
        with pytest.raises(kin.ConfigurationError, match="joint 5"):
            f(list(q))
    for shape in ((5,), (7,), (2, 5), (2, 3, 6), (), (0,), (6, 1)):
        with pytest.raises(kin.ConfigurationError, match=r"expected \(6,\) or \(N, 6\)"):
            f(np.zeros(shape))
    # float32 and integer arrays are fine (converted), and agree with float64
    as_list = lambda x: [np.asarray(v, float) for v in (x if isinstance(x, tuple) else (x,))]
    for a, b in zip(as_list(f(np.zeros(6, np.int64))), as_list(f(np.zeros(6)))):
        np.testing.assert_allclose(a, b)


_cnc: dict = {}


def cnc(backend: str) -> kin.Robot:
    """cnc_rrrppp: three revolute joints, then three prismatic ones."""
    if backend not in _cnc:
        _cnc[backend] = kin.Robot(kin.load_chain("cnc_rrrppp"), backend=backend)
    return _cnc[backend]


@pytest.mark.parametrize("backend", ["auto", "vm"])
@pytest.mark.parametrize("call", CALLS[:8])
def test_prismatic_values_beyond_the_evaluators_range_refused(backend, call):
    """A prismatic joint at 1e308 m overflowed the FK, Jacobian and measures: NaN manipulability,
    σ_min 0 or 1, numpy RuntimeWarnings (the VM's det), LAPACK lines on stderr.  Beyond
    ±MAX_PRISMATIC it is refused naming the joint and the range, on the fast single path too;
    within it, and for revolute joints at any finite angle, the answer is finite and warning-free."""
    import warnings

    from kin.chain import MAX_PRISMATIC
    r = cnc(backend)
    f = getattr(r, call)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for v in (1e308, -1e308, 1e200, math.nextafter(MAX_PRISMATIC, math.inf)):
            q = np.zeros(6)
            q[4] = v
            for arg in (q, list(q)):
                with pytest.raises(kin.ConfigurationError, match=r"joint 5 = .* m is beyond ±1e\+06 m"):
                    f(arg)
            with pytest.raises(kin.ConfigurationError, match=r"joint 5 = .* m \(row 1\) is beyond ±1e\+06 m"):
                f(np.stack([np.zeros(6), q]))
        for q in (np.array([1e308, -1e308, 1e200, 0.1, 0.2, 0.3]),
                  np.array([0.1, 0.2, 0.3, MAX_PRISMATIC, -MAX_PRISMATIC, 1e5])):
            for res in (f(q), f(np.stack([q, q]))):
                for x in (res if isinstance(res, tuple) else (res,)):
                    x = np.asarray(x, dtype=float)
                    assert np.all(np.isfinite(x) | np.isinf(x)) and not np.any(np.isnan(x)), (call, q, x)
    # the limit checks still answer for any finite value
    q = np.array([0.0, 0.0, 0.0, 0.0, 1e308, 0.0])
    assert r.within_limits(q) is False
    with pytest.raises(kin.JointLimitError, match="joint 5"):
        r.check_limits(q)


def test_real_values_of_other_types_still_work():
    r = robot("auto")
    ref = r.fk(np.array(Q0))
    np.testing.assert_allclose(r.fk(Q0), ref, atol=1e-15)
    np.testing.assert_allclose(r.fk(tuple(Q0)), ref, atol=1e-15)
    np.testing.assert_allclose(r.fk(np.array(Q0, np.float32)), r.fk(np.array(Q0, np.float32).astype(float)))
    np.testing.assert_allclose(r.fk(np.array(Q0)[None])[0], ref, atol=1e-15)


def param_robot() -> kin.Robot:
    return kin.Robot(Chain(name="p2r", joints=(Joint("revolute", a="L1"), Joint("revolute", a=0.5)),
                           parameters={"L1": Parameter(1.0, (0.5, 2.0))}))


@pytest.mark.parametrize("params", [["1.0"], np.array(["1.0"]), [1.0 + 0j], np.array([1 + 2j]), [True], [None],
                                    {"L1": "1.0"}, {"L1": 1 + 0j}, {"L1": True}, {"L1": None}, [math.nan],
                                    {"L1": math.inf}, [1.0, 2.0], {"L2": 1.0}, [1e308], {"L1": -1e200}])
def test_bad_parameters_refused(params):
    r = param_robot()
    with pytest.raises(kin.ParameterError):
        r.fk([0.1, 0.2], params=params)
    with pytest.raises(kin.ParameterError):
        r.sigma_min(np.zeros((3, 2)), params=params)


def test_good_parameters_agree():
    r = param_robot()
    a = r.fk([0.1, 0.2], params={"L1": 1.5})
    np.testing.assert_allclose(r.fk([0.1, 0.2], params=[1.5]), a)
    np.testing.assert_allclose(r.fk([0.1, 0.2], params=np.array([1.5], np.float32)), a)
    np.testing.assert_allclose(a[:2, 3], [1.5 * math.cos(0.1) + 0.5 * math.cos(0.3),
                                          1.5 * math.sin(0.1) + 0.5 * math.sin(0.3)], atol=1e-15)


@pytest.mark.parametrize("N, seed", [(-1, 0), (1.5, 0), ("10", 0), (True, 0), (10**9, 0), (None, 0), (10, -1),
                                     (10, 1.0), (10, "1"), (10, 1 + 0j)])
def test_random_configurations_refuses(N, seed):
    with pytest.raises(kin.ConfigurationError, match="random_configurations"):
        robot("auto").random_configurations(N, seed=seed)


def test_random_configurations_within_limits():
    r = robot("auto")
    Q = r.random_configurations(np.int64(200), seed=np.uint8(3))
    assert Q.shape == (200, 6) and np.all(r.within_limits(Q))
    assert r.random_configurations(0).shape == (0, 6)
    np.testing.assert_array_equal(r.random_configurations(5, seed=3), Q[:5])
