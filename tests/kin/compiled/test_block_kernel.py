"""The block kernel (kin/compiled/kernel.c and its headers, kin/native/graph.py, evaluator.py):
native and portable builds against the numpy DH reference and numpy's SVD/det, against each other
and against CasADi's VM; blocks cut at every lane count; out= buffers; the thread count; the
single-call extension path.  Nothing is timed."""
from __future__ import annotations

import math
import os

import casadi as ca
import numpy as np
import pytest

import kin
from kin.compiled import (
    WANT_ALL,
    WANT_J,
    WANT_MANIP,
    WANT_SIGMA,
    WANT_T,
    CompiledEvaluator,
    default_threads,
    find_compiler,
)
from kin.native import c_double, graph_table, python_extension_flags
from tests.chain_factory import fd_jacobian, random_chain, random_q
from tests.dh_numpy import fk_numpy, jacobian_numpy

_built: dict = {}


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("kernel_cache")


def build(chain, arch: str, cache_path, block: int = 16) -> CompiledEvaluator:
    key = (chain.name, id(chain), arch, block)
    if key not in _built:
        _built[key] = CompiledEvaluator(kin.Robot(chain).symbolic, find_compiler(), directory=cache_path, arch=arch,
                                        block=block)
    return _built[key]


def reference(chain, rows, Q):
    """numpy: T, J, and (manipulability, σ_min, condition, det) of the task rows, per configuration."""
    T = np.array([fk_numpy(chain, q) for q in Q])
    J = np.array([jacobian_numpy(chain, q) for q in Q])
    Jt = J[:, list(rows), :]
    s = np.linalg.svd(Jt, compute_uv=False)
    square = Jt.shape[1] == Jt.shape[2]
    det = np.linalg.det(Jt) if square else np.full(len(Q), np.nan)
    with np.errstate(divide="ignore"):
        cond = np.where(s[:, -1] > 0, s[:, 0] / s[:, -1], np.inf)
    return T, J, np.column_stack([np.prod(s, axis=1), s[:, -1], cond, det])


CHAINS = [kin.load_chain(n) for n in ("fanuc_m16ib20", "scara_rrp", "stanford_arm", "planar_2r")] + \
         [random_chain(s, n=n, convention=c, params=p, name=f"blk{s}")
          for s, n, c, p in ((80, 7, "standard", True), (81, 3, "modified", False), (82, 5, "standard", True),
                             (83, 4, "modified", True))]


@pytest.mark.parametrize("arch", ["native", "portable"])
@pytest.mark.parametrize("chain", CHAINS, ids=lambda c: c.name)
def test_kernel_vs_numpy_reference(chain, arch, cache):
    ev = build(chain, arch, cache)
    assert ev.arch == arch
    rows = kin.Robot(chain).task_rows
    Q = random_q(chain, 37, 5)  # two full blocks of 16 and a partial one
    res = ev.evaluate(Q, chain.parameter_values, WANT_ALL)
    T, J, M = reference(chain, rows, Q)
    np.testing.assert_allclose(res["T"], T, atol=1e-12, rtol=0)
    np.testing.assert_allclose(res["J"], J, atol=1e-12, rtol=0)
    np.testing.assert_allclose(res["measures"][:, 0], M[:, 0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(res["measures"][:, 1], M[:, 1], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(res["measures"][:, 2], M[:, 2], rtol=1e-8)
    np.testing.assert_allclose(res["measures"][:, 3], M[:, 3], rtol=1e-9, atol=1e-12)  # NaN where not square
    # J against central differences of the kernel's own FK
    fk = lambda q: ev.evaluate(np.atleast_2d(q), chain.parameter_values, WANT_T)["T"][0]
    for k in (0, 17, 36):
        np.testing.assert_allclose(res["J"][k], fd_jacobian(fk, Q[k], 1e-6), atol=1e-7, rtol=0)


@pytest.mark.parametrize("chain", CHAINS, ids=lambda c: c.name)
def test_native_portable_and_vm_agree(chain, cache):
    nat, por = build(chain, "native", cache), build(chain, "portable", cache)
    vm = kin.Robot(chain, backend="vm").evaluator
    rng = np.random.default_rng(1)
    Q = random_q(chain, 50, 9)
    P = chain.parameter_values + rng.uniform(-0.2, 0.2, (50, len(chain.parameters)))
    a, b, c = (e.evaluate(Q, P, WANT_ALL) for e in (nat, por, vm))
    for k in ("T", "J"):
        np.testing.assert_allclose(a[k], b[k], atol=1e-13, rtol=0)
        np.testing.assert_allclose(a[k], c[k], atol=1e-12, rtol=0)
    for col in (0, 1, 3):
        np.testing.assert_allclose(a["measures"][:, col], b["measures"][:, col], rtol=1e-10, atol=1e-13)
        np.testing.assert_allclose(a["measures"][:, col], c["measures"][:, col], rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("block", [4, 16, 64])
def test_every_batch_size_and_block_size(block, cache):
    """Block boundaries and partial blocks: row k of any batch equals the single evaluation of row k."""
    chain = kin.load_chain("puma560")
    ev = build(chain, "native", cache, block=block)
    Q = random_q(chain, 3 * block + 5, 2)
    T_ref, J_ref, M_ref = reference(chain, kin.Robot(chain).task_rows, Q)
    for N in (1, 2, block - 1, block, block + 1, 2 * block + 3, len(Q)):
        res = ev.evaluate(Q[:N], chain.parameter_values, WANT_ALL)
        np.testing.assert_allclose(res["T"], T_ref[:N], atol=1e-12, rtol=0)
        np.testing.assert_allclose(res["J"], J_ref[:N], atol=1e-12, rtol=0)
        np.testing.assert_allclose(res["measures"][:, 1], M_ref[:N, 1], rtol=1e-9, atol=1e-12)


def test_sigma_min_lanes_of_very_different_conditioning():
    """One block mixing exactly singular, nearly singular and well-conditioned lanes (the Jacobi
    sweeps run until the slowest lane converges; converged lanes must not drift)."""
    r = kin.load_robot("fanuc_m16ib20")
    Q = random_q(r.chain, 16, 4)
    Q[0::4, 4] = 0.0            # wrist singular
    Q[1::4, 4] = 1e-9           # nearly singular
    Q[2::4, 4] = 1e-4
    _, _, M = reference(r.chain, r.task_rows, Q)
    smin = r.sigma_min(Q)
    assert np.all(smin[0::4] <= 1e-12)
    regular = np.ones(16, bool)
    regular[0::4] = False
    # small σ are as accurate as the Jacobian's entries allow: ~eps·‖J‖ absolute
    np.testing.assert_allclose(smin[regular], M[regular, 1], rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(r.det(Q)[regular], M[regular, 3], rtol=1e-9, atol=1e-14)


# ================================================================================ out= buffers
def test_out_buffers_are_filled_and_returned():
    r = kin.load_robot("fanuc_m16ib20")
    Q = random_q(r.chain, 40, 6)
    T, J = np.full((40, 4, 4), 7.0), np.full((40, 6, 6), 7.0)
    w, s, M = np.full(40, 7.0), np.full(40, 7.0), np.full((40, 4), 7.0)
    assert r.fk(Q, out=T) is T
    assert r.jacobian(Q, out=J) is J
    assert r.manipulability(Q, out=w) is w
    assert r.sigma_min(Q, out=s) is s
    meas = r.measures(Q, out=M)
    T_ref, J_ref, M_ref = reference(r.chain, r.task_rows, Q)
    np.testing.assert_allclose(T, T_ref, atol=1e-12)
    np.testing.assert_allclose(J, J_ref, atol=1e-12)
    np.testing.assert_allclose(w, M_ref[:, 0], rtol=1e-9)
    np.testing.assert_allclose(s, M_ref[:, 1], rtol=1e-9)
    np.testing.assert_allclose(M, M_ref, rtol=1e-8)
    assert np.shares_memory(meas.sigma_min, M)
    T2, J2 = np.empty((40, 4, 4)), np.empty((40, 6, 6))
    assert r.fk_jacobian(Q, out=(T2, J2))[0] is T2
    np.testing.assert_array_equal(J2, J)
    # a single configuration: arrays without the batch axis
    T1 = np.empty((4, 4))
    assert r.fk(Q[3], out=T1) is T1
    np.testing.assert_allclose(T1, T_ref[3], atol=1e-12)


@pytest.mark.parametrize("backend", ["auto", "vm"])
def test_out_buffers_validated(backend):
    r = kin.Robot(kin.load_chain("fanuc_m16ib20"), backend=backend)
    Q = random_q(r.chain, 10, 7)
    bad = [np.empty((10, 4)), np.empty((9, 4, 4)), np.empty((10, 4, 4), np.float32), np.empty((4, 4, 10)).T,
           [[0.0] * 4] * 4, np.empty((10, 4, 4), complex)]
    ro = np.empty((10, 4, 4))
    ro.flags.writeable = False
    for arr in bad + [ro]:
        with pytest.raises(kin.OutBufferError):
            r.fk(Q, out=arr)
    with pytest.raises(kin.OutBufferError):
        r.sigma_min(Q, out=np.empty((10, 1)))
    with pytest.raises(kin.OutBufferError):
        r.fk_jacobian(Q, out=np.empty((10, 4, 4)))
    with pytest.raises(kin.OutBufferError, match="unknown"):
        r.evaluate(Q, WANT_T, out={"pose": np.empty((10, 4, 4))})
    with pytest.raises(kin.OutBufferError, match="one or the other"):
        r.evaluate(Q, WANT_MANIP, out={"measures": np.empty((10, 4)), "det": np.empty(10)})
    # the VM fills out= buffers too
    w = np.empty(10)
    assert r.manipulability(Q, out=w) is w
    np.testing.assert_allclose(w, reference(r.chain, r.task_rows, Q)[2][:, 0], rtol=1e-9)


# ================================================================================== threads
def test_thread_count_from_environment(monkeypatch):
    r = kin.load_robot("ur5e")
    ev = r.evaluator
    Q = random_q(r.chain, 20_000, 8)   # 4 threads' worth of work (at least 4096 configurations each)
    ref = r.evaluate(Q[:300], WANT_T | WANT_J | WANT_SIGMA)[0]
    for k in ("1", "2", "3"):
        monkeypatch.setenv("RMTKIT_THREADS", k)
        res = r.evaluate(Q, WANT_T | WANT_J | WANT_SIGMA)[0]
        assert ev.last_threads == int(k)
        np.testing.assert_array_equal(res["J"][:300], ref["J"])
        np.testing.assert_array_equal(res["measures"][:300], ref["measures"])
    r.fk(Q[:8000])
    assert ev.last_threads == 1  # a small batch runs on the calling thread
    monkeypatch.delenv("RMTKIT_THREADS")
    assert default_threads() == len(os.sched_getaffinity(0))
    for bad in ("0", "-2", "two", "1e3", "100000"):
        monkeypatch.setenv("RMTKIT_THREADS", bad)
        with pytest.raises(kin.SettingError, match="RMTKIT_THREADS"):
            r.fk(Q)


def test_arch_setting(monkeypatch, tmp_path):
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path))
    monkeypatch.setenv("RMTKIT_ARCH", "portable")
    r = kin.Robot(kin.load_chain("planar_2r"))
    assert r.evaluator.arch == "portable" and "_portable-" in r.evaluator.path.name
    np.testing.assert_allclose(r.fk([0.3, 0.4])[:2, 3], [math.cos(0.3) + 0.8 * math.cos(0.7),
                                                         math.sin(0.3) + 0.8 * math.sin(0.7)], atol=1e-15)
    monkeypatch.setenv("RMTKIT_ARCH", "fastest")
    with pytest.raises(kin.SettingError, match="RMTKIT_ARCH"):
        kin.Robot(kin.load_chain("planar_2r")).evaluator


# ========================================================================== single-call path
def test_single_call_extension_matches_batch():
    r = kin.load_robot("stanford_arm")
    if not python_extension_flags():
        pytest.skip("no Python/numpy C headers: the ctypes single path is used")
    ext = r.evaluator.single
    assert ext is not None
    Q = random_q(r.chain, 5, 3)
    T, J = r.fk_jacobian(Q)
    M = r.measures(Q)
    p = r.evaluator.p_nominal
    for k, q in enumerate(Q):
        Ts, Js = ext.fk_jacobian(q, p)
        np.testing.assert_array_equal(Ts, T[k])
        np.testing.assert_array_equal(Js, J[k])
        np.testing.assert_array_equal(ext.fk(q, p), T[k])
        np.testing.assert_array_equal(ext.jacobian(q, p), J[k])
        m = ext.measures(q, p, WANT_MANIP | WANT_SIGMA)
        np.testing.assert_allclose(m, [x[k] for x in M], rtol=1e-14, atol=1e-16)
    # anything but a finite float64 (n,) array is handed back to the validating Python path
    strided = np.repeat(Q[0], 2)[::2]
    for q in (list(Q[0]), Q[0].astype(np.float32), Q[:1], Q[0][:5], np.full(6, np.nan), strided, "q"):
        assert ext.fk(q, p) is None and ext.fk_jacobian(q, p) is None and ext.measures(q, p, WANT_SIGMA) is None
    with pytest.raises(TypeError):
        ext.fk(Q[0])
    np.testing.assert_allclose(r.fk(list(Q[0])), T[0], atol=1e-15)


@pytest.mark.parametrize("extension", [True, False])
def test_same_structure_different_nominal_parameters(extension):
    """Chains that differ only in nominal parameter values share one library; each Robot's single
    calls must still use its own values."""
    base = kin.Chain(name="shared_lib", joints=(kin.Joint("revolute", a="L1"), kin.Joint("revolute", a=0.5)),
                     parameters={"L1": kin.Parameter(1.0, (0.5, 2.0))})
    robots = [kin.Robot(base), kin.Robot(base.with_parameters({"L1": 1.7}))]
    assert robots[0].evaluator.path == robots[1].evaluator.path
    if not extension:
        for r in robots:
            r.evaluator.single = None
    q = np.array([0.3, 0.4])
    for r, L1 in zip(robots * 2, (1.0, 1.7, 1.0, 1.7)):
        expect = [L1 * math.cos(0.3) + 0.5 * math.cos(0.7), L1 * math.sin(0.3) + 0.5 * math.sin(0.7)]
        np.testing.assert_allclose(r.fk(q)[:2, 3], expect, atol=1e-15)
        np.testing.assert_allclose(r.fk_jacobian(q)[0][:2, 3], expect, atol=1e-15)
        np.testing.assert_allclose(r.fk(q[None])[0, :2, 3], expect, atol=1e-15)


# ============================================================================ code generation
def test_c_double_is_exact():
    for x in (0.1, -1e-300, 1.5e308, 2.0 ** -1074, math.pi):
        assert float.fromhex(c_double(x).strip("()")) == x
    assert c_double(math.inf) == "INFINITY" and c_double(-math.inf) == "(-INFINITY)" and c_double(math.nan) == "NAN"


def test_graph_table_refuses_unknown_operations():
    x = ca.SX.sym("x")
    f = ca.Function("f", [x], [ca.erf(x)])
    with pytest.raises(kin.CompileError, match="operation code"):
        graph_table(f, "g", ["x"], ["y"])
    with pytest.raises(kin.CompileError, match="names"):
        graph_table(ca.Function("f", [x], [x * 2]), "g", ["x", "z"], ["y"])


def test_single_call_without_extension_uses_library_buffers():
    """Without Python/numpy headers the single path goes through ctypes and the library's buffers."""
    chain = kin.load_chain("puma560")
    r = kin.Robot(chain)
    r.evaluator.single = None          # as when built without the extension
    assert r._fast is None
    Q = random_q(chain, 4, 12)
    T_ref, J_ref, M_ref = reference(chain, r.task_rows, Q)
    for k, q in enumerate(Q):
        T, J = r.fk_jacobian(q)
        np.testing.assert_allclose(T, T_ref[k], atol=1e-12)
        np.testing.assert_allclose(J, J_ref[k], atol=1e-12)
        np.testing.assert_allclose(r.fk(q), T_ref[k], atol=1e-12)
        np.testing.assert_allclose(r.jacobian(q), J_ref[k], atol=1e-12)
        m = r.measures(q)
        assert isinstance(m.sigma_min, float)
        np.testing.assert_allclose(list(m), M_ref[k], rtol=1e-9)
        assert r.sigma_min(q) == m.sigma_min
    bad = Q[0].copy()
    bad[2] = np.nan
    with pytest.raises(kin.ConfigurationError, match="joint 3"):
        r.fk(bad)


def test_each_library_keeps_its_own_extension_module():
    """Robots of different chains, each built twice (a second Robot of the same chain reloads the
    same library), must each evaluate with their own library's functions."""
    names = ["puma560", "solar_concentrator", "scara_rrp"]
    robots = [kin.load_robot(n) for n in names for _ in range(2)]
    for r in robots:
        q = random_q(r.chain, 1, 21)[0]
        np.testing.assert_allclose(r.fk(q), fk_numpy(r.chain, q), atol=1e-12)
        if r.evaluator.single is not None:
            assert r.evaluator.single.__name__ == r.evaluator.path.stem.replace("-", "_")
