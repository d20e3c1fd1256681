"""kin.ik.compiled: the reach bound never refuses a reachable target (FK of random configurations of
random chains, both DH conventions, prismatic joints, base and tool placements) and matches the
closed-form wrist reach of the FANUC; the solver's per-target record; the on-disk cache; design
parameters.  Answers are checked with the numpy FK of tests/dh_numpy.py."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.compiled import find_compiler
from kin.ik.compiled import CompiledIK, ReachBound, compiled_ik
from tests.chain_factory import random_chain, random_q
from tests.dh_numpy import fk_numpy

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="no C compiler")


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_reach_bound_never_refuses_a_reachable_target(seed, convention):
    chain = random_chain(seed, convention=convention)
    r = kin.Robot(chain)
    solver = compiled_ik(r)
    Q = random_q(chain, 3000, seed=seed)
    lo, hi = chain.lower, chain.upper
    Q[:200] = np.where(np.random.default_rng(seed).uniform(size=(200, chain.n)) < 0.5, lo, hi)  # corners
    T = r.fk(Q)
    assert not solver.beyond(T[:, :3, 3], T[:, :3, :3]).any()
    assert not solver.beyond(T[:, :3, 3]).any()
    # far away, it does refuse
    reach = ReachBound(chain).between(0, chain.n) + np.linalg.norm(chain.tool.matrix[:3, 3])
    far = T[:50].copy()
    u = far[:, :3, 3] - chain.base.matrix[:3, 3]
    far[:, :3, 3] = chain.base.matrix[:3, 3] + (reach + 0.01) * u / np.linalg.norm(u, axis=1, keepdims=True)
    assert solver.beyond(far[:, :3, 3]).all() and solver.beyond(far[:, :3, 3], far[:, :3, :3]).all()


def test_wrist_bound_is_the_closed_form_reach_of_the_fanuc():
    """Wrist centre w = p − 0.1·z_tool; from the shoulder circle (radius 0.15 at height 0.525) the arm
    reaches at most 0.77 + √(0.1² + 0.74²) = 1.5167 m (upper arm, then elbow offset and forearm)."""
    r = kin.load_robot("fanuc_m16ib20")
    solver = compiled_ik(r)
    reach = 0.77 + math.hypot(0.1, 0.74)
    rng = np.random.default_rng(3)
    for _ in range(40):
        R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        R *= np.sign(np.linalg.det(R))
        phi, el = rng.uniform(-math.pi, math.pi), rng.uniform(-1.2, 1.2)
        for dist, expect in ((reach * 1.001, True), (reach * 0.999, False)):
            # a wrist centre at `dist` from the nearest point of the shoulder circle, in direction (phi, el)
            w = np.array([(0.15 + dist * math.cos(el)) * math.cos(phi), (0.15 + dist * math.cos(el)) * math.sin(phi),
                          0.525 + dist * math.sin(el)])
            p = w + 0.1 * R[:, 2]
            assert bool(solver.beyond(p[None], R[None])[0]) is expect


def test_solver_record_and_honest_flags():
    r = kin.load_robot("puma560")
    c = r.chain
    solver = compiled_ik(r)
    Q = random_q(c, 30, seed=1)
    T = np.array([fk_numpy(c, q) for q in Q])
    T[-5:, :3, 3] *= 10.0                           # out of reach
    out = solver.solve(T[:, :3, 3], T[:, :3, :3], None, seed=3)
    assert out["success"][:-5].all() and not out["success"][-5:].any()
    assert (out["starts"] >= 1).all() and (out["starts"][-5:] <= 8).all()
    for ok, q, Tk, pe, oe in zip(out["success"], out["q"], T, out["position_error"], out["orientation_error"]):
        F = fk_numpy(c, q)
        assert pe == pytest.approx(np.linalg.norm(F[:3, 3] - Tk[:3, 3]), rel=1e-9, abs=1e-15)
        assert ok == (pe <= 1e-6 and oe <= 1e-6)
    assert c.within_limits(out["q"]).all()


def test_library_is_cached_on_disk(tmp_path, monkeypatch):
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path))
    r = kin.load_robot("planar_2r")
    a = CompiledIK(r, find_compiler())
    mtime = a.path.stat().st_mtime_ns
    b = CompiledIK(kin.load_robot("planar_2r"), find_compiler())
    assert a.path == b.path and a.path.parent == tmp_path / "native" and b.path.stat().st_mtime_ns == mtime


def test_design_parameters_per_target():
    chain = random_chain(5, n=6, params=True, types=("revolute",) * 6)
    r = kin.Robot(chain)
    names = chain.parameter_names
    rng = np.random.default_rng(2)
    P = chain.parameter_values + rng.uniform(-0.05, 0.05, size=(10, len(names)))
    Q = random_q(chain, 10, seed=9)
    T = np.array([fk_numpy(chain.frozen(p), q) for p, q in zip(P, Q)])
    res = r.ik(T, params=P, seed=0)
    assert res.success.all()
    for p, q, Tk in zip(P, res.q, T):
        F = fk_numpy(chain.frozen(p), q)
        assert np.linalg.norm(F[:3, 3] - Tk[:3, 3]) <= 1e-6
    one = r.ik(T[0], params=P[0], seed=0)          # one parameter vector: the reach test uses it too
    assert one.success
