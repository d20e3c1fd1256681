"""kin.ik.analytic: every branch reproduces its target by the numpy FK of tests/dh_numpy.py (1e-9),
random configurations come back as one of the branches, the branch counts are Pieper's (8 for the
PUMA and the ABB IRB 120 at generic poses once the limits allow every branch), every solution the
numeric solver finds from many seeds is one of the branches, and chains without a closed form are
refused."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import kin
from kin.chain import Placement
from kin.ik.analytic import NoClosedFormError, analytic_ik, pieper_arm
from tests.chain_factory import random_chain, random_q
from tests.dh_numpy import fk_numpy

SPHERICAL = ["puma560", "abb_irb120", "fanuc_m16ib20"]


def _wide(chain):
    """The chain with every joint limited to (−π, π]: one representative of each branch."""
    return replace(chain, name=chain.name + "_wide",
                   joints=tuple(replace(j, limits=(-math.pi, math.pi)) for j in chain.joints))


def _angle_gap(A: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Largest joint difference of each row of A from q, modulo whole turns."""
    return np.abs((A - q + math.pi) % (2 * math.pi) - math.pi).max(axis=1)


@pytest.mark.parametrize("name", SPHERICAL)
def test_branches_reproduce_the_target_and_contain_the_configuration(name):
    r = kin.load_robot(name)
    c = r.chain
    Q = random_q(c, 25, seed=17)
    for q in Q:
        T = fk_numpy(c, q)
        B = analytic_ik(r, T)
        assert len(B) in range(1, 9) and c.within_limits(B).all()
        for b in B:
            F = fk_numpy(c, b)
            assert np.linalg.norm(F[:3, 3] - T[:3, 3]) <= 1e-9
            assert np.abs(F[:3, :3] - T[:3, :3]).max() <= 1e-9
        assert _angle_gap(B, q).min() <= 1e-7      # the configuration the pose came from is a branch
        assert len(B) == 1 or min(_angle_gap(np.delete(B, i, 0), b).min() for i, b in enumerate(B)) > 1e-7


@pytest.mark.parametrize("name", ["puma560", "abb_irb120"])
def test_eight_branches_at_generic_poses(name):
    """a₁ = 0: θ₃ from |wrist centre|² (2), θ₂ from its height (2), θ₁ unique, the wrist (2): 2·2·2 = 8."""
    r = kin.Robot(_wide(kin.load_chain(name)))
    c = r.chain
    Q = random_q(c, 30, seed=5)
    Q = Q[r.sigma_min(Q) > 0.02]
    counts = [len(analytic_ik(r, fk_numpy(c, q))) for q in Q]
    assert counts == [8] * len(Q)


def test_fanuc_branches_match_the_numeric_solutions():
    """The FANUC has a shoulder offset (a₁ = 0.15 m): θ₃ solves a quartic, 2, 4, 6 or 8 branches.  Every
    solution the numeric IK finds from 40 random warm starts is one of them."""
    r = kin.Robot(_wide(kin.load_chain("fanuc_m16ib20")))
    c = r.chain
    for q in random_q(c, 4, seed=2):
        T = fk_numpy(c, q)
        B = analytic_ik(r, T)
        assert len(B) % 2 == 0 and 2 <= len(B) <= 8
        found = set()
        for seed in range(40):
            res = r.ik(T, seed=seed, tol_position=1e-10, tol_orientation=1e-10, q0=random_q(c, 1, seed=100 + seed)[0])
            assert res.success
            gap = _angle_gap(B, res.q)
            assert gap.min() <= 1e-6
            found.add(int(np.argmin(gap)))
        assert len(found) >= 2                      # more than one branch is met


def test_modified_dh_placements_and_offsets():
    """The same arm in modified DH, and with joint offsets and a base and tool placement."""
    c = kin.load_chain("puma560")
    offs = replace(c, name="puma_offsets",
                   joints=tuple(replace(j, theta=0.2 * (i + 1) - 0.5) for i, j in enumerate(c.joints)),
                   base=Placement(xyz=(0.1, -0.2, 0.3), rpy=(0.2, -0.4, 1.1)),
                   tool=Placement(xyz=(0.01, 0.02, 0.15), rpy=(-0.3, 0.5, 0.7)))
    for chain in (c.to_modified(), offs, offs.to_modified()):
        r = kin.Robot(chain)
        for q in random_q(chain, 6, seed=8):
            T = fk_numpy(chain, q)
            B = analytic_ik(r, T)
            assert _angle_gap(B, q).min() <= 1e-7
            for b in B:
                assert np.abs(fk_numpy(chain, b) - T).max() <= 1e-9


def test_batch_all_turns_and_out_of_reach():
    r = kin.load_robot("fanuc_m16ib20")
    c = r.chain
    Q = random_q(c, 3, seed=1)
    T = np.array([fk_numpy(c, q) for q in Q])
    out = analytic_ik(r, T)
    assert isinstance(out, list) and len(out) == 3
    # joint 6 spans ±7.85 rad: with all_turns each branch comes with its whole-turn variants in the limits
    many = analytic_ik(r, T[0], all_turns=True)
    assert len(many) > len(out[0]) and c.within_limits(many).all()
    for b in many:
        assert np.abs(fk_numpy(c, b) - T[0]).max() <= 1e-9
    far = T[0].copy()
    far[:3, 3] *= 5.0
    assert analytic_ik(r, far).shape == (0, 6)


@pytest.mark.parametrize("name", ["stanford_arm", "planar_2r", "scara_rrp", "solar_concentrator"])
def test_no_closed_form_is_refused(name):
    with pytest.raises(NoClosedFormError):
        pieper_arm(kin.load_chain(name))
    with pytest.raises(NoClosedFormError):
        analytic_ik(kin.load_robot(name), np.eye(4))


def test_general_6r_is_refused_and_position_targets_too():
    with pytest.raises(NoClosedFormError, match="spherical wrist"):
        pieper_arm(random_chain(3, n=6, types=("revolute",) * 6))
    with pytest.raises(NoClosedFormError, match="pose target"):
        analytic_ik(kin.load_robot("puma560"), np.array([0.3, 0.1, 0.4]))


@pytest.mark.parametrize("name", SPHERICAL)
def test_wrist_singular_poses_still_get_verified_branches(name):
    """θ₅ = 0: axes 4 and 6 align and θ₄ + θ₆ is all that matters; one member of that family per branch."""
    r = kin.load_robot(name)
    c = r.chain
    Q = random_q(c, 10, seed=2)
    Q[:, 4] = 0.0
    for q in Q:
        T = fk_numpy(c, q)
        B = analytic_ik(r, T)
        assert len(B) >= 1
        for b in B:
            assert np.abs(fk_numpy(c, b) - T).max() <= 1e-9
