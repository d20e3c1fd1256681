"""The numeric singular set (kin.singular.numeric) against independent values: σ_min and det(J·Jᵀ)
from the plain numpy Jacobian of tests.dh_numpy, and the exact factors of the bundled arms.

General chains (a 6R without spherical wrist, a KUKA iiwa-like 7R, a 12R) must answer under the
budget: the exact path is cut at 2 s and the numeric one answers; the bound is the budget
mechanism's, so the answer is asserted, not the time (the 12R's peak memory, measured by the
kernel for the process and its worker, is asserted below 2 GiB).
"""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kin
from kin.singular import analyse_singularities, cache
from tests.dh_numpy import jacobian_numpy

H = math.pi / 2


def chain_robot(name: str, rows, limit: float = 3.0) -> kin.Robot:
    """A revolute chain in standard DH from (a, alpha, d) rows."""
    text = f'name = "{name}"\nconvention = "standard"\nlength_unit = "m"\nangle_unit = "rad"\n'
    for a, alpha, d in rows:
        text += (f'[[joints]]\ntype = "revolute"\na = {a!r}\nalpha = {alpha!r}\nd = {d!r}\n'
                 f'limits = [{-limit}, {limit}]\n')
    return kin.Robot(kin.loads_robot(text))


GENERAL_6R = [(0.1, 1.2, 0.3), (0.45, -0.7, 0.05), (0.12, 0.9, 0.2), (0.05, -1.1, 0.35), (0.08, 0.6, 0.1),
              (0.02, 0.4, 0.15)]
IIWA = [(0.0, -H if i % 2 == 0 else H, d) for i, d in enumerate([0.34, 0, 0.4, 0, 0.4, 0, 0.126])]
_rng = np.random.default_rng(3)
CHAIN_12R = [(round(float(_rng.uniform(0.05, 0.3)), 3), round(float(_rng.uniform(-1.5, 1.5)), 3),
              round(float(_rng.uniform(0, 0.2)), 3)) for _ in range(12)]


def task_sigma(robot, Q) -> np.ndarray:
    """Smallest singular value of the task rows of the numpy Jacobian (independent of kin's evaluators)."""
    rows = list(robot.task_rows)
    return np.array([np.linalg.svd(jacobian_numpy(robot.chain, q)[rows], compute_uv=False)[-1] for q in Q])


@pytest.fixture(autouse=True)
def private_cache(tmp_path, monkeypatch):
    monkeypatch.setattr(cache, "cache_dir", lambda: tmp_path)


_GENERAL: dict[str, tuple] = {}


def general(name: str):
    if name not in _GENERAL:
        robot = chain_robot(name, {"general_6r": GENERAL_6R, "iiwa_7r": IIWA}[name])
        _GENERAL[name] = (robot, analyse_singularities(robot, exact_timeout=2.0, numeric_time=25.0))
    return _GENERAL[name]


@pytest.mark.parametrize("name", ["general_6r", "iiwa_7r"])
def test_general_chains_answer_numerically(name):
    robot, a = general(name)
    check_on_the_set(robot, a)


def check_on_the_set(robot, a):
    assert a.method == "numeric" and a.budget["exact_status"] in ("timeout", "memory")
    assert a.budget["exact_timeout"] == 2.0 and a.factors
    for c in a.factors:
        P = c.points[np.random.default_rng(0).choice(len(c.points), min(20, len(c.points)), replace=False)]
        assert robot.within_limits(P).all()
        scale = np.median(task_sigma(robot, robot.random_configurations(20, seed=1)))
        assert task_sigma(robot, P).max() < 1e-7 * scale           # on the singular set
        if robot.n > 6:                                            # redundant: J·Jᵀ singular there
            for q in P[:5]:
                J = jacobian_numpy(robot.chain, q)
                ev = np.linalg.eigvalsh(J @ J.T)
                assert ev[0] < 1e-12 * ev[-1]


MEASURE_12R = """
import json, resource, sys
import numpy as np
import kin
from kin.singular import analyse_singularities, cache
from tests.kin.singular.test_numeric import CHAIN_12R, chain_robot
cache.cache_dir = lambda: __import__("pathlib").Path(sys.argv[1])
robot = chain_robot("chain_12r", CHAIN_12R)
a = analyse_singularities(robot, exact_timeout=2.0, numeric_time=25.0)
kib = max(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
print(json.dumps({"method": a.method, "budget": a.budget, "peak_kib": kib,
                  "components": [{"joints": list(c.joints), "points": c.points[:20].tolist()} for c in a.factors]}))
"""


def test_12_joint_chain_answers_within_2_gb(tmp_path):
    """In a fresh process, so that its peak memory (the process and its exact-path worker) is its own."""
    proc = subprocess.run([sys.executable, "-c", MEASURE_12R, str(tmp_path)], capture_output=True, text=True,
                          cwd=Path(__file__).resolve().parents[3], timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    d = json.loads(proc.stdout.strip().splitlines()[-1])
    assert d["method"] == "numeric" and d["budget"]["exact_status"] in ("timeout", "memory")
    assert d["peak_kib"] < 2 * 1024 * 1024
    robot = chain_robot("chain_12r", CHAIN_12R)
    scale = np.median(task_sigma(robot, robot.random_configurations(20, seed=1)))
    assert d["components"]
    for c in d["components"]:
        P = np.array(c["points"])
        assert robot.within_limits(P).all() and task_sigma(robot, P).max() < 1e-7 * scale
        for q in P[:5]:                                            # J·Jᵀ singular (12 joints, 6 rows)
            J = jacobian_numpy(robot.chain, q)
            ev = np.linalg.eigvalsh(J @ J.T)
            assert ev[0] < 1e-12 * ev[-1]


def test_general_6r_depends_on_the_middle_joints_only():
    robot, a = general("general_6r")
    assert [c.joints for c in a.factors] == [(2, 3, 4, 5)]
    c = a.factors[0]
    rng = np.random.default_rng(4)
    P = c.points[rng.choice(len(c.points), 20, replace=False)]
    scale = np.median(task_sigma(robot, robot.random_configurations(20, seed=1)))
    moved = P.copy()
    moved[:, [0, 5]] = rng.uniform(-3, 3, size=(20, 2))            # q1, q6: the set does not depend on them
    assert task_sigma(robot, moved).max() < 1e-6 * scale
    off = P + 0.05 * c.normal_at(P)                                 # along the normal: off the set
    assert np.median(task_sigma(robot, off)) > 1e-3 * scale


def test_lost_motion_is_not_in_the_range_of_the_jacobian():
    robot, a = general("general_6r")
    c = a.factors[0]
    lm = c.lost_motion
    assert lm["frame"] == "tool" and 0 <= lm["linear_share"] <= 1 and abs(np.linalg.norm(lm["direction"]) - 1) < 1e-6
    q = c.points[0]
    J = jacobian_numpy(robot.chain, q)
    U = np.linalg.svd(J)[0][:, -1]
    assert np.linalg.norm(U @ J) < 1e-7 * np.linalg.norm(J)


# ---- bundled arms: numeric against exact ----------------------------------------------------------
BUNDLED = ["puma560", "fanuc_m16ib20", "scara_rrp", "ur5e"]


@pytest.fixture(scope="module")
def both():
    out = {}

    def get(name):
        if name not in out:
            robot = kin.load_robot(name)
            out[name] = (robot, analyse_singularities(robot, use_cache=False),
                         analyse_singularities(robot, exact_timeout=0.0, use_cache=False))
        return out[name]
    return get


#: the stated distance (rad or m, joint space) within which 90 % of an exact factor's samples must
#: lie from the numeric component: curves (components on ≤ 2 joints) are sampled finely, surfaces
#: (≥ 3 joints) only as finely as ~4000 points allow
AGREE = {1: 0.05, 2: 0.05, 3: 0.15}


@pytest.mark.parametrize("name", BUNDLED)
def test_numeric_finds_the_exact_components(both, name):
    robot, exact, numeric = both(name)
    assert exact.method == "exact" and numeric.method == "numeric"
    # every numeric point lies on the zero set of some exact factor: |g| / |∇g| (first-order distance)
    for c in numeric.factors:
        P = c.points[:: max(1, len(c.points) // 50)]
        d = np.min([np.abs(f(P)) / np.maximum(np.linalg.norm(f.gradient(P), axis=1), 1e-12)
                    for f in exact.factors], axis=0)
        assert d.max() < 1e-6, (c.joints, d.max())
    # every exact factor's zero set is within AGREE of a numeric component, and σ_min vanishes there
    for f in exact.factors:
        S = f.samples[:: max(1, len(f.samples) // 50)]
        if len(S) == 0:
            continue
        scale = np.median(task_sigma(robot, robot.random_configurations(20, seed=1)))
        assert task_sigma(robot, S).max() < 1e-7 * scale
        d = np.min([c.distance(S) if c.single_joint is None else
                    np.min(np.abs(S[:, c.single_joint][:, None] - np.array(c.solutions["values"])[None]), axis=1)
                    for c in numeric.factors], axis=0)
        assert np.quantile(d, 0.9) < AGREE[min(len(f.joints), 3)], (f.expr, np.quantile(d, 0.9))


@pytest.mark.parametrize("name", ["puma560", "fanuc_m16ib20"])
def test_numeric_names_and_roots_match_the_exact_factors(both, name):
    _, exact, numeric = both(name)
    assert sorted(c.kind for c in numeric.factors) == sorted(f.kind for f in exact.factors)
    for f in exact.factors:
        if f.single_joint is None:
            continue
        c = [c for c in numeric.factors if c.joints == f.joints]
        assert len(c) == 1
        assert np.allclose(sorted(c[0].solutions["values"]), sorted(f.solutions["values"]), atol=1e-6)


def test_iiwa_stretched_elbow_is_found_and_named():
    robot, a = general("iiwa_7r")
    elbow = [c for c in a.factors if c.joints == (4,)]
    assert len(elbow) == 1 and elbow[0].kind == "elbow" and np.allclose(elbow[0].solutions["values"], [0.0], atol=1e-9)
    # independent: any configuration with q4 = 0 (arm stretched) has J·Jᵀ singular
    Q = robot.random_configurations(10, seed=7)
    Q[:, 3] = 0.0
    for q in Q:
        J = jacobian_numpy(robot.chain, q)
        ev = np.linalg.eigvalsh(J @ J.T)
        assert ev[0] < 1e-12 * ev[-1]


def test_progress_is_reported_through_the_callback():
    seen = []
    robot = chain_robot("general_6r", GENERAL_6R)
    analyse_singularities(robot, exact_timeout=0.5, numeric_time=5.0,
                          progress=lambda stage, done, total: seen.append((stage, done, total)))
    stages = [s for s, _, _ in seen]
    assert "projecting samples onto the singular set" in stages and "describing components" in stages
    assert all(0 <= d <= t for _, d, t in seen)
