"""kin.compiled (through kin.Robot): the compiled and VM evaluators against independent values —
central finite differences of FK, the numpy DH implementation of tests/dh_numpy.py and numpy's
SVD/det — plus the fallback to CasADi's VM, the on-disk cache and input validation."""
from __future__ import annotations

import math
import shutil
import warnings

import numpy as np
import pytest

import kin
from kin.chain import Chain, Joint, Parameter, Placement
from tests.chain_factory import fd_jacobian, random_chain, random_q
from tests.dh_numpy import fk_numpy, jacobian_numpy

ROBOTS = sorted(kin.bundled_robots())
H = 1e-6
FD_TOL = 1e-7

_cache: dict = {}


def robot(name: str, backend: str = "auto") -> kin.Robot:
    """Bundled robot, one per (name, backend) for the whole module (compiling once)."""
    key = (name, backend)
    if key not in _cache:
        _cache[key] = kin.load_robot(name, backend=backend)
    return _cache[key]


def rand_robot(seed: int, backend: str = "auto", **kw) -> kin.Robot:
    key = ("random", seed, backend, tuple(sorted(kw.items())))
    if key not in _cache:
        _cache[key] = kin.Robot(random_chain(seed, name=f"rc_{seed}", **kw), backend=backend)
    return _cache[key]


RANDOM = [(0, "standard", False), (1, "modified", True), (2, "standard", True), (3, "modified", False),
          (4, "standard", False), (5, "modified", True)]


@pytest.fixture(scope="module", autouse=True)
def _compiler_available():
    r = robot("planar_2r")
    assert r.backend == "compiled", "these tests expect a working C compiler (cc/gcc) on the test machine"


def numpy_measures_ref(chain: Chain, rows, q) -> tuple[float, float, float, float]:
    """(manipulability, σ_min, condition, det) of the task rows of the numpy Jacobian."""
    Jt = jacobian_numpy(chain, q)[list(rows)]
    s = np.linalg.svd(Jt, compute_uv=False)
    det = float(np.linalg.det(Jt)) if Jt.shape[0] == Jt.shape[1] else math.nan
    return float(np.prod(s)), float(s[-1]), float(s[0] / s[-1]) if s[-1] > 0 else math.inf, det


# =========================================================================== FK and Jacobian
@pytest.mark.parametrize("name", ROBOTS)
def test_jacobian_vs_finite_differences_bundled(name):
    r = robot(name)
    for q in random_q(r.chain, 4, 31):
        np.testing.assert_allclose(r.jacobian(q), fd_jacobian(r.fk, q, H), atol=FD_TOL, rtol=0)


@pytest.mark.parametrize("seed, convention, params", RANDOM)
def test_jacobian_vs_finite_differences_random(seed, convention, params):
    r = rand_robot(seed, convention=convention, params=params)
    Q = random_q(r.chain, 4, seed)
    J = r.jacobian(Q)
    assert J.shape == (4, 6, r.n)
    for q, Jq in zip(Q, J):
        np.testing.assert_allclose(Jq, fd_jacobian(r.fk, q, H), atol=FD_TOL, rtol=0)


@pytest.mark.parametrize("seed, convention, params", RANDOM)
def test_fk_matches_numpy_random(seed, convention, params):
    r = rand_robot(seed, convention=convention, params=params)
    Q = random_q(r.chain, 20, seed + 1)
    T = r.fk(Q)
    assert T.shape == (20, 4, 4)
    for q, Tq in zip(Q, T):
        np.testing.assert_allclose(Tq, fk_numpy(r.chain, q), atol=1e-12, rtol=0)
    np.testing.assert_allclose(r.fk(Q[0]), fk_numpy(r.chain, Q[0]), atol=1e-12, rtol=0)


@pytest.mark.parametrize("name", ["puma560", "scara_rrp", "solar_concentrator", "cnc_rrrppp"])
def test_batch_and_single_agree(name):
    r = robot(name)
    Q = random_q(r.chain, 70, 3)  # more than one 64-row block of the kernel
    T, J = r.fk_jacobian(Q)
    M = r.measures(Q)
    for k in (0, 1, 63, 64, 69):
        Ts, Js = r.fk_jacobian(Q[k])
        np.testing.assert_allclose(Ts, T[k], atol=1e-14, rtol=0)
        np.testing.assert_allclose(Js, J[k], atol=1e-14, rtol=0)
        np.testing.assert_allclose(r.fk(Q[k]), T[k], atol=1e-14, rtol=0)
        np.testing.assert_allclose(r.jacobian(Q[k]), J[k], atol=1e-14, rtol=0)
        ms = r.measures(Q[k])
        assert isinstance(ms.manipulability, float)
        for i in range(4):
            np.testing.assert_allclose(ms[i], M[i][k], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(r.position_jacobian(Q), J[:, :3, :], atol=0)


def test_empty_batch():
    r = robot("fanuc_m16ib20")
    assert r.fk(np.zeros((0, 6))).shape == (0, 4, 4)
    assert r.jacobian(np.zeros((0, 6))).shape == (0, 6, 6)
    assert r.manipulability(np.zeros((0, 6))).shape == (0,)


# ============================================================================ measures
def _check_measures(r: kin.Robot, Q: np.ndarray) -> None:
    M = r.measures(Q)
    w, smin, cond, det = (np.asarray(x) for x in M)
    np.testing.assert_array_equal(r.manipulability(Q), w)
    np.testing.assert_array_equal(r.sigma_min(Q), smin)
    np.testing.assert_array_equal(r.condition(Q), cond)
    np.testing.assert_array_equal(r.det(Q), det)
    for k, q in enumerate(Q):
        rw, rs, rc, rd = numpy_measures_ref(r.chain, r.task_rows, q)
        if not math.isnan(rd) or rw > 1e-6:
            assert w[k] == pytest.approx(rw, rel=1e-9, abs=1e-12)
        else:  # non-square and (nearly) singular: see test_manipulability_exactly_singular_non_square
            assert w[k] <= 1e-7
        assert smin[k] == pytest.approx(rs, rel=1e-9, abs=1e-12)
        if math.isnan(rd):
            assert math.isnan(det[k])
        else:
            assert det[k] == pytest.approx(rd, rel=1e-9, abs=1e-12)
        if rs > 1e-6:
            assert cond[k] == pytest.approx(rc, rel=1e-9)
        else:
            assert cond[k] > 1e9


@pytest.mark.parametrize("name", ROBOTS)
def test_measures_vs_numpy_bundled(name):
    r = robot(name)
    _check_measures(r, random_q(r.chain, 8, 41))


@pytest.mark.parametrize("seed, n", [(60, 2), (61, 3), (62, 4), (63, 5), (64, 7)])
def test_measures_vs_numpy_random_sizes(seed, n):
    """n < 6 (task rows x y z: m > n, m = n, m < n) and n = 7 (6 rows, m < n): non-square paths."""
    r = rand_robot(seed, n=n)
    _check_measures(r, random_q(r.chain, 8, seed))
    assert len(r.task_rows) == (6 if n >= 6 else 3)
    if len(r.task_rows) != n:
        assert all(math.isnan(d) for d in r.det(random_q(r.chain, 3, 0)))


def test_fanuc_wrist_singularity_exact():
    r = robot("fanuc_m16ib20")
    Q = random_q(r.chain, 10, 5)
    Q[::2, 4] = 0.0  # every other row: θ5 = 0, the wrist singularity
    M = r.measures(Q)
    sing = np.zeros(10, bool)
    sing[::2] = True
    assert np.all(M.sigma_min[sing] <= 1e-12)
    assert np.all(np.abs(M.det[sing]) <= 1e-12)
    assert np.all(M.manipulability[sing] <= 1e-12)
    assert np.all(M.condition[sing] >= 1e12)
    assert np.all(M.sigma_min[~sing] > 1e-6)
    _check_measures(r, Q)
    # single-configuration path
    assert r.sigma_min(Q[0]) <= 1e-12 and abs(r.det(Q[0])) <= 1e-12


def planar_3r() -> Chain:
    return Chain(name="planar_3r", joints=(Joint("revolute", a=0.7), Joint("revolute", a=0.55),
                                           Joint("revolute", a=0.3)), task=("x", "y"))


@pytest.mark.parametrize("backend", ["auto", "vm"])
def test_sigma_min_exactly_singular_non_square(backend):
    """Planar 3R, task rows x y (2×3): stretched (θ2 = θ3 = 0) is exactly singular."""
    r = kin.Robot(planar_3r(), backend=backend)
    rng = np.random.default_rng(0)
    Q = np.column_stack([rng.uniform(-3, 3, 20), np.zeros(20), np.zeros(20)])
    assert np.all(r.sigma_min(Q) <= 1e-12)
    assert np.all(r.condition(Q) >= 1e12)
    assert np.all(np.isnan(r.det(Q)))


# the manipulability of a non-square task Jacobian comes from a QR factor (not the Gram determinant),
# so it stays accurate at an exact singularity
@pytest.mark.parametrize("backend", ["auto", "vm"])
def test_manipulability_exactly_singular_non_square(backend):
    r = kin.Robot(planar_3r(), backend=backend)
    rng = np.random.default_rng(0)
    Q = np.column_stack([rng.uniform(-3, 3, 20), np.zeros(20), np.zeros(20)])
    ref = [numpy_measures_ref(r.chain, r.task_rows, q)[0] for q in Q]
    assert max(ref) <= 1e-15  # numpy: product of the singular values
    assert np.all(r.manipulability(Q) <= 1e-12)


@pytest.mark.parametrize("name, rows", [("planar_2r", (0, 1)), ("scara_rrp", (0, 1, 2))])
def test_small_chains_task_rows_and_measures(name, rows):
    r = robot(name)
    assert r.task_rows == rows
    Q = random_q(r.chain, 10, 8)
    Q[0, 1] = 0.0  # stretched: θ2 = 0 is singular for both
    _check_measures(r, Q)
    assert r.sigma_min(Q[0]) <= 1e-12


def test_planar_2r_det_closed_form():
    r = robot("planar_2r")
    Q = random_q(r.chain, 20, 9)
    np.testing.assert_allclose(r.det(Q), 1.0 * 0.8 * np.sin(Q[:, 1]), rtol=1e-12, atol=1e-15)


def test_scara_det_closed_form():
    # docs/machines.md §2: det Jv = 101250 sin θ2 mm² = 0.10125 sin θ2 m²
    r = robot("scara_rrp")
    Q = random_q(r.chain, 20, 10)
    np.testing.assert_allclose(r.det(Q), 0.10125 * np.sin(Q[:, 1]), rtol=1e-12, atol=1e-16)


# ======================================================================= VM vs compiled
@pytest.mark.parametrize("name", ROBOTS)
def test_vm_backend_same_numbers_bundled(name):
    rc, rv = robot(name), robot(name, "vm")
    assert rv.backend == "vm" and rc.backend == "compiled"
    Q = random_q(rc.chain, 12, 51)
    Tc, Jc = rc.fk_jacobian(Q)
    Tv, Jv = rv.fk_jacobian(Q)
    np.testing.assert_allclose(Tv, Tc, atol=1e-12, rtol=0)
    np.testing.assert_allclose(Jv, Jc, atol=1e-12, rtol=0)
    Mc, Mv = rc.measures(Q), rv.measures(Q)
    for i in (0, 1, 3):
        np.testing.assert_allclose(Mv[i], Mc[i], atol=1e-12, rtol=1e-10)
    np.testing.assert_allclose(Mv.condition, Mc.condition, rtol=1e-8)
    np.testing.assert_allclose(rv.fk(Q[0]), Tc[0], atol=1e-12, rtol=0)
    np.testing.assert_allclose(rv.jacobian(Q[0]), Jc[0], atol=1e-12, rtol=0)


@pytest.mark.parametrize("seed, convention, params", RANDOM)
def test_vm_backend_same_numbers_random(seed, convention, params):
    rc = rand_robot(seed, convention=convention, params=params)
    rv = kin.Robot(rc.chain, backend="vm")
    Q = random_q(rc.chain, 10, seed)
    P = None
    if params:
        rng = np.random.default_rng(seed)
        P = rc.chain.parameter_values + rng.uniform(-0.3, 0.3, (10, len(rc.chain.parameters)))
    np.testing.assert_allclose(rv.fk(Q, P), rc.fk(Q, P), atol=1e-12, rtol=0)
    np.testing.assert_allclose(rv.jacobian(Q, P), rc.jacobian(Q, P), atol=1e-12, rtol=0)
    wv, wc = rv.manipulability(Q, P), rc.manipulability(Q, P)
    regular = (wv > 1e-6) | (wc > 1e-6)
    np.testing.assert_allclose(wv[regular], wc[regular], atol=1e-12, rtol=1e-10)
    np.testing.assert_allclose(wv[~regular], wc[~regular], atol=1e-14)
    np.testing.assert_allclose(rv.sigma_min(Q, P), rc.sigma_min(Q, P), atol=1e-12, rtol=1e-10)


# ==================================================================== fallback and cache
def test_no_compiler_falls_back_to_vm(monkeypatch, tmp_path):
    monkeypatch.setenv("RMTKIT_CC", "none")
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path))
    chain = kin.load_chain("puma560")
    r = kin.Robot(chain)
    assert r.backend == "vm"
    Q = random_q(chain, 5, 1)
    for q in Q:
        np.testing.assert_allclose(r.fk(q), fk_numpy(chain, q), atol=1e-12)
    J = r.jacobian(Q)
    smin = r.sigma_min(Q)
    for k, q in enumerate(Q):
        np.testing.assert_allclose(J[k], jacobian_numpy(chain, q), atol=1e-12)
        assert smin[k] == pytest.approx(numpy_measures_ref(chain, r.task_rows, q)[1], rel=1e-9, abs=1e-12)
    assert list(tmp_path.iterdir()) == []  # nothing compiled, nothing cached
    with pytest.raises(kin.CompileError):
        _ = kin.Robot(chain, backend="compiled").backend


def test_broken_compiler_warns_and_falls_back(monkeypatch, tmp_path):
    false = shutil.which("false")
    assert false is not None
    monkeypatch.setenv("RMTKIT_CC", false)
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path))
    chain = kin.load_chain("planar_2r")
    r = kin.Robot(chain)
    with pytest.warns(RuntimeWarning, match="VM"):
        assert r.backend == "vm"
    np.testing.assert_allclose(r.fk([0.3, 0.4])[:2, 3], [math.cos(0.3) + 0.8 * math.cos(0.7),
                                                         math.sin(0.3) + 0.8 * math.sin(0.7)], atol=1e-15)
    with pytest.raises(kin.CompileError):
        _ = kin.Robot(chain, backend="compiled").backend
    assert not list(tmp_path.rglob("*.so"))


def test_disk_cache(monkeypatch, tmp_path):
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path))
    chain = random_chain(70, name="cache_test")
    r1 = kin.Robot(chain)
    assert r1.backend == "compiled" and r1.evaluator.cached is False
    libs = list((tmp_path / "native").glob("*.so"))
    assert len(libs) == 1 and libs[0].name.startswith("fk_cache_test_")
    assert [p for p in (tmp_path / "native").iterdir() if p.suffix != ".so"] == []  # no temporary build dir left
    r2 = kin.Robot(chain)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert r2.evaluator.cached is True
    q = random_q(chain, 1, 0)[0]
    np.testing.assert_allclose(r2.fk(q), fk_numpy(chain, q), atol=1e-12)
    # a different chain is a different library
    kin.Robot(random_chain(71, name="cache_test")).evaluator
    assert len(list((tmp_path / "native").glob("*.so"))) == 2


def test_any_chain_name_compiles_inside_the_cache(monkeypatch, tmp_path):
    """A programmatic Chain's name is not restricted to [a-z0-9_]; it must not break the cache path."""
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path / "cache"))
    c = Chain(name="../Arm/with spaces", joints=(Joint("revolute", a=1.0), Joint("revolute", a=0.5)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = kin.Robot(c)
        assert r.backend == "compiled"
    assert len(list((tmp_path / "cache" / "native").glob("*.so"))) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cache"]
    np.testing.assert_allclose(r.fk([0.4, 0.2])[:2, 3], [math.cos(0.4) + 0.5 * math.cos(0.6),
                                                         math.sin(0.4) + 0.5 * math.sin(0.6)], atol=1e-15)


def test_unknown_backend():
    with pytest.raises(ValueError, match="auto, compiled, vm"):
        _ = kin.Robot(kin.load_chain("planar_2r"), backend="gpu").backend


# ====================================================================== input validation
@pytest.mark.parametrize("backend", ["auto", "vm"])
@pytest.mark.parametrize("method", ["fk", "jacobian", "fk_jacobian", "measures", "manipulability", "sigma_min",
                                    "condition", "det"])
def test_non_finite_q(backend, method, ):
    r = robot("fanuc_m16ib20", backend)
    f = getattr(r, method)
    for bad in (math.nan, math.inf):
        q = np.array([0.1, 0.2, bad, 0.4, 0.5, 0.6])
        with pytest.raises(kin.ConfigurationError, match="joint 3"):
            f(q)
        Q = np.zeros((4, 6))
        Q[2, 5] = bad
        with pytest.raises(kin.ConfigurationError, match="row 2, joint 6"):
            f(Q)


@pytest.mark.parametrize("backend", ["auto", "vm"])
@pytest.mark.parametrize("shape", [(5,), (7,), (3, 5), (2, 3, 6), (), (6, 1)])
def test_wrong_shapes(backend, shape):
    r = robot("fanuc_m16ib20", backend)
    for f in (r.fk, r.jacobian, r.measures, r.sigma_min):
        with pytest.raises(kin.ConfigurationError, match=r"expected \(6,\) or \(N, 6\)"):
            f(np.zeros(shape))


# ========================================================================= design parameters
def param_chain() -> Chain:
    params = {"L2": Parameter(0.7, (0.3, 1.2)), "TW": Parameter(0.4, (-1.0, 1.0), "angle")}
    joints = (Joint("revolute", a=0.3, alpha=-math.pi / 2, d=0.4),
              Joint("revolute", a="L2", alpha="TW"),
              Joint("prismatic", a=0.1, alpha=-0.3, theta=0.2, limits=(0.0, 0.4)))
    return Chain(name="param_rows", joints=joints, parameters=params, tool=Placement(xyz=(0.0, 0.0, 0.1)))


@pytest.mark.parametrize("backend", ["auto", "vm"])
def test_params_per_row(backend):
    c = param_chain()
    r = kin.Robot(c, backend=backend)
    rng = np.random.default_rng(3)
    N = 70
    Q = random_q(c, N, 3)
    P = np.column_stack([rng.uniform(0.3, 1.2, N), rng.uniform(-1.0, 1.0, N)])
    T, J = r.fk_jacobian(Q, params=P)
    W = r.manipulability(Q, params=P)
    for k in (0, 5, 64, 69):
        ck = c.with_parameters({"L2": P[k, 0], "TW": P[k, 1]})
        np.testing.assert_allclose(T[k], r.fk(Q[k], params=P[k]), atol=1e-14)
        np.testing.assert_allclose(T[k], r.fk(Q[k], params={"L2": P[k, 0], "TW": P[k, 1]}), atol=1e-14)
        np.testing.assert_allclose(T[k], fk_numpy(ck, Q[k]), atol=1e-12)
        np.testing.assert_allclose(J[k], jacobian_numpy(ck, Q[k]), atol=1e-12)
        assert W[k] == pytest.approx(numpy_measures_ref(ck, r.task_rows, Q[k])[0], rel=1e-9, abs=1e-13)
    # one shared parameter vector for the whole batch
    T2 = r.fk(Q, params=P[0])
    np.testing.assert_allclose(T2[5], fk_numpy(c.with_parameters({"L2": P[0, 0], "TW": P[0, 1]}), Q[5]), atol=1e-12)
    # nominal parameters by default
    np.testing.assert_allclose(r.fk(Q[1]), fk_numpy(c, Q[1]), atol=1e-12)


def test_bad_params():
    r = kin.Robot(param_chain())
    Q = random_q(r.chain, 4, 0)
    with pytest.raises(kin.ParameterError, match="rows"):
        r.fk(Q, params=np.full((3, 2), 0.5))
    with pytest.raises(kin.ParameterError):
        r.fk(Q, params=[0.5])
    with pytest.raises(kin.ParameterError):
        r.fk(Q, params=[0.5, math.nan])
    with pytest.raises(kin.ParameterError, match="'L9'"):
        r.fk(Q, params={"L9": 1.0})


# ========================================================================== large angles
@pytest.mark.parametrize("name", ["fanuc_m16ib20", "puma560", "ur5e"])
def test_large_revolute_angles(name):
    """The kernel's own sin/cos (range reduction + polynomials; libm beyond 1e6) against numpy."""
    r = robot(name)
    c = r.chain
    assert all(c.resolve(j.theta) == 0.0 for j in c.joints)  # no offset: numpy's angle is exactly q
    rng = np.random.default_rng(12)
    values = [1e3, -1e3, 1e7, -1e7, 999_999.5, 1_000_000.5, 2.0**40, 123456.789, -654321.123, 1e15, -1e300]
    Q = rng.uniform(-1, 1, (len(values) + 20, 6))
    for k, v in enumerate(values):
        Q[k, k % 6] = v
        Q[k, (k + 3) % 6] = -v / 3
    Q[len(values):] *= 1e6
    scale = 1.0 + np.abs(c.dh_table()[:, [0, 2]]).sum()
    T = r.fk(Q)
    for q, Tq in zip(Q, T):
        np.testing.assert_allclose(Tq, fk_numpy(c, q), atol=1e-9 * scale, rtol=0)
        np.testing.assert_allclose(r.fk(q), fk_numpy(c, q), atol=1e-9 * scale, rtol=0)
    # and to full double accuracy for moderate angles
    Qm = rng.uniform(-50, 50, (40, 6))
    for q, Tq in zip(Qm, r.fk(Qm)):
        np.testing.assert_allclose(Tq, fk_numpy(c, q), atol=1e-13, rtol=0)


def test_sincos_at_quadrant_boundaries():
    """Angles at and next to multiples of π/4 and π/2, where the reduction switches quadrant."""
    r = robot("planar_2r")
    k = np.arange(-40, 41)
    base = np.concatenate([k * np.pi / 4, k * np.pi / 2])
    angles = np.concatenate([base, np.nextafter(base, np.inf), np.nextafter(base, -np.inf)])
    Q = np.column_stack([angles, np.zeros_like(angles)])
    T = r.fk(Q)
    np.testing.assert_allclose(T[:, 0, 0], np.cos(angles), atol=2e-16)
    np.testing.assert_allclose(T[:, 1, 0], np.sin(angles), atol=2e-16)


def test_both_evaluators_are_evaluators_and_only_the_compiled_one_does_single_calls():
    from kin.compiled import CompiledEvaluator, Evaluator, VMEvaluator
    vm = kin.load_robot("fanuc_m16ib20", backend="vm").evaluator
    assert isinstance(vm, VMEvaluator) and isinstance(vm, Evaluator) and not vm.single_call
    robot = kin.load_robot("fanuc_m16ib20")
    if isinstance(robot.evaluator, CompiledEvaluator):
        assert isinstance(robot.evaluator, Evaluator) and robot.evaluator.single_call
    q = np.array([0.1, -0.2, 0.3, 0.4, 0.5, 0.6])
    np.testing.assert_allclose(robot.fk(q), kin.load_robot("fanuc_m16ib20", backend="vm").fk(q), atol=1e-12)
