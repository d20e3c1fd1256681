"""The motion bound of the collision proofs (kin.geometry.reach_radii) against finite differences of
the body frames, and the default geometry's capsules against the DH frames (tests/dh_numpy.py)."""
from __future__ import annotations

import numpy as np
import pytest

import kin
from kin.geometry import body_frames, default_geometry, reach_radii
from tests.dh_numpy import fk_numpy

ROBOTS = kin.bundled_robots()


@pytest.mark.parametrize("name", ROBOTS)
def test_no_point_moves_faster_than_the_bound(name):
    """|p(q + h·e) − p(q)| / h ≤ Σ_j R[j, k]·|e_j| for every capsule end of every body, at random
    configurations and random directions e (a central difference, h = 1e-6)."""
    robot = kin.load_robot(name)
    chain = robot.chain
    geo = robot.geometry
    R = reach_radii(chain, geo)
    rng = np.random.default_rng(7)
    Q = rng.uniform(chain.lower, chain.upper, size=(300, chain.n))
    E = rng.normal(size=(300, chain.n))
    E /= np.linalg.norm(E, axis=1, keepdims=True)
    h = 1e-6
    Fp, Fm = body_frames(chain, Q + h * E), body_frames(chain, Q - h * E)
    worst = 0.0
    for c in geo.capsules:
        bound = np.abs(E) @ R[:, c.body]
        for p in (c.a, c.b):
            ph = np.array([*p, 1.0])
            speed = np.linalg.norm((Fp[:, c.body] - Fm[:, c.body]) @ ph, axis=1) / (2 * h)
            assert np.all(speed <= bound * (1 + 1e-6) + 1e-9), f"{name}: {c.name} point {p} moves faster than bound"
            worst = max(worst, float(np.max(speed / np.maximum(bound, 1e-12))))
    assert worst > 0.05, "the bound is so loose that proofs would need needless subdivisions"


@pytest.mark.parametrize("name", ["fanuc_lrmate200id", "franka_panda", "ur5e", "cnc_rrrppp", "scara_rrp"])
def test_body_frames_match_plain_dh_products(name):
    robot = kin.load_robot(name)
    Q = robot.random_configurations(50, seed=3)
    F = body_frames(robot.chain, Q)
    for q, f in zip(Q, F):
        assert np.allclose(f[-1], fk_numpy(robot.chain, q), atol=1e-12)


@pytest.mark.parametrize("name", ["fanuc_lrmate200id", "franka_panda", "ur5e", "puma560"])
def test_default_capsules_follow_the_links(name):
    """Consecutive frame origins are joined: every origin of frames 0 … n lies on some capsule's
    segment (at q = 0 and at random configurations), and no capsule leaves the hull of the chain."""
    chain = kin.load_robot(name).chain
    geo = default_geometry(chain)
    Q = np.vstack([np.zeros(chain.n), kin.Robot(chain).random_configurations(20, seed=1)])
    F = body_frames(chain, Q)
    for f in F:
        segs = [((f[c.body] @ [*c.a, 1])[:3], (f[c.body] @ [*c.b, 1])[:3]) for c in geo.capsules]
        for k in range(chain.n + 1):
            o = f[k, :3, 3]
            d = min(_point_segment(o, a, b) for a, b in segs)
            assert d < 1e-9, f"{name}: frame {k}'s origin is {d:.3g} m from every capsule"
    assert geo.radius == pytest.approx(max(0.01, 0.05 * _length(chain)))


def _length(chain) -> float:
    D = chain.dh_table()
    total = float(np.abs(D[:, 0]).sum() + np.abs(D[:, 2]).sum())
    return total + float(np.linalg.norm(chain.tool.matrix[:3, 3]))


def _point_segment(p, a, b) -> float:
    d = b - a
    L = d @ d
    t = 0.0 if L == 0 else float(np.clip((p - a) @ d / L, 0, 1))
    return float(np.linalg.norm(a + t * d - p))


@pytest.mark.parametrize("name", ROBOTS)
def test_no_capsule_point_moves_faster_than_its_own_bound(name):
    """capsule_radii: the per-capsule bound holds for every point of the capsule's segment (central
    differences of the body frames at random configurations and directions), and is never larger than
    the body's (reach_radii)."""
    from kin.geometry.motion import capsule_radii
    robot = kin.load_robot(name)
    chain, geo = robot.chain, robot.geometry
    C, R = capsule_radii(chain, geo), reach_radii(chain, geo)
    rng = np.random.default_rng(11)
    Q = rng.uniform(chain.lower, chain.upper, size=(200, chain.n))
    E = rng.normal(size=(200, chain.n))
    E /= np.linalg.norm(E, axis=1, keepdims=True)
    h = 1e-6
    Fp, Fm = body_frames(chain, Q + h * E), body_frames(chain, Q - h * E)
    for k, c in enumerate(geo.capsules):
        assert np.all(C[k] <= R[:, c.body] + 1e-12)
        bound = np.abs(E) @ C[k]
        for s in (0.0, 0.5, 1.0):
            p = np.array([*(np.add(c.a, s * np.subtract(c.b, c.a))), 1.0])
            speed = np.linalg.norm((Fp[:, c.body] - Fm[:, c.body]) @ p, axis=1) / (2 * h)
            assert np.all(speed <= bound * (1 + 1e-6) + 1e-9), f"{name}: {c.name} at {s} moves faster than its bound"


@pytest.mark.parametrize("name", ["franka_panda", "ur5e", "puma560", "cnc_rrrppp", "stanford_arm", "scara_rrp",
                                  "kuka_iiwa14"])
def test_points_stay_within_the_curvature_bound_of_their_chords(name):
    """curvature_bound: along random straight joint motions, every capsule point stays within
    (t − t0)(t1 − t)/2 · M of the chord between its positions at t0 and t1 (checked on a fine grid of
    the whole motion, t0 = 0, t1 = 1), and M bounds a central second difference of the point's path."""
    from kin.geometry.motion import capsule_radii, curvature_bound
    robot = kin.load_robot(name)
    chain, geo = robot.chain, robot.geometry
    C = capsule_radii(chain, geo)
    rng = np.random.default_rng(5)
    ts = np.linspace(0.0, 1.0, 401)
    tight = 0.0
    for _ in range(12):
        a, b = rng.uniform(chain.lower, chain.upper, size=(2, chain.n))
        b = a + rng.uniform(0.05, 1.0) * (b - a)
        M = curvature_bound(C, b - a, chain.revolute_mask)
        F = body_frames(chain, a + ts[:, None] * (b - a))
        for k, c in enumerate(geo.capsules):
            for s in (0.0, 1.0):
                p = np.array([*(np.add(c.a, s * np.subtract(c.b, c.a))), 1.0])
                P = F[:, c.body] @ p                                     # (T, 4)
                chord = P[0] + ts[:, None] * (P[-1] - P[0])
                dev = np.linalg.norm((P - chord)[:, :3], axis=1)
                allowed = ts * (1 - ts) / 2 * M[k]
                assert np.all(dev <= allowed * (1 + 1e-9) + 1e-12), f"{name}: {c.name} leaves its chord's bound"
                d2 = np.linalg.norm((P[2:] - 2 * P[1:-1] + P[:-2])[:, :3], axis=1) / (ts[1] - ts[0]) ** 2
                assert np.all(d2 <= M[k] * (1 + 1e-6) + 1e-6)
                if M[k] > 0:
                    tight = max(tight, float(d2.max() / M[k]))
    assert tight > 0.02, "the curvature bound is so loose that proofs would cut intervals needlessly"
