"""kin.ik.parallel: the closed form of 6R arms with parallel axes 2, 3, 4 (the UR family).  Every branch
reproduces its target by the numpy FK of tests/dh_numpy.py (1e-9), the configuration the pose came
from is one of them, 8 branches at generic poses, every numeric IK solution is one of them, whole-turn
copies are all listed and ranked, the structure is found from the DH values (a renamed UR, twists of
180° folded, modified DH with offsets and placements), and wrist-singular poses do not crash."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import kin
from kin.chain import Placement
from kin.ik.analytic import NoClosedFormError, analytic_ik, closed_form
from kin.ik.parallel import ParallelArm, parallel_arm
from kin.transforms import make_transform, rpy_to_matrix
from tests.chain_factory import random_chain, random_q
from tests.dh_numpy import fk_numpy

UR = ["ur3e", "ur5e", "ur10e", "ur16e"]


def _gap(A: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Largest joint difference of each row of A from q, modulo whole turns."""
    return np.abs((A - q + math.pi) % (2 * math.pi) - math.pi).max(axis=1)


def _check_branches(chain, B, T):
    assert len(B) >= 1                                      # never vacuous: at least one branch to check
    for b in B:
        F = fk_numpy(chain, b)
        assert np.linalg.norm(F[:3, 3] - T[:3, 3]) <= 1e-9
        assert np.abs(F[:3, :3] - T[:3, :3]).max() <= 1e-9


@pytest.mark.parametrize("name", UR)
def test_ur_branches_reproduce_the_target_and_contain_the_configuration(name):
    r = kin.load_robot(name)
    c = r.chain
    arm = closed_form(c)
    assert isinstance(arm, ParallelArm)
    dh = c.to_modified().dh_table()                 # the structure holds the robot's own lengths
    assert np.abs(arm.a - dh[:, 0]).max() <= 1e-12 and np.abs(arm.d - dh[:, 2]).max() <= 1e-12
    for q in random_q(c, 25, seed=11):
        T = fk_numpy(c, q)
        B = analytic_ik(r, T)
        assert 1 <= len(B) <= 8 and c.within_limits(B).all()
        _check_branches(c, B, T)
        assert _gap(B, q).min() <= 1e-7
        # distinct branches, not whole-turn copies of one another
        assert len(B) == 1 or min(_gap(np.delete(B, i, 0), b).min() for i, b in enumerate(B)) > 1e-7


@pytest.mark.parametrize("name", UR)
def test_eight_branches_at_generic_poses(name):
    """2 shoulder (θ₁) × 2 wrist (θ₅) × 2 elbow (θ₃): 8 at tool-down poses well inside the workspace
    (farther out or nearer axis 1 some branches leave the reach; the numeric IK finds no more there)."""
    r = kin.load_robot(name)
    c = r.chain
    reach = abs(c.joints[1].a) + abs(c.joints[2].a)
    rng = np.random.default_rng(1)
    counts = []
    for _ in range(30):
        rad, ang = rng.uniform(0.4, 0.6) * reach, rng.uniform(-math.pi, math.pi)
        xyz = np.array([rad * math.cos(ang), rad * math.sin(ang), rng.uniform(-0.1, 0.3) * reach])
        R = rpy_to_matrix([math.pi + rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(-math.pi, math.pi)])
        T = make_transform(R, xyz)
        B = analytic_ik(r, T)
        _check_branches(c, B, T)
        counts.append(len(B))
    assert counts.count(8) >= 27 and set(counts) <= {4, 6, 8}
    if name in ("ur5e", "ur10e"):
        assert counts == [8] * 30


def test_ur5e_branches_match_the_numeric_solutions():
    """Every solution the numeric IK finds from 30 random warm starts is one of the branches."""
    r = kin.load_robot("ur5e")
    c = r.chain
    for q in random_q(c, 3, seed=4):
        T = fk_numpy(c, q)
        B = analytic_ik(r, T)
        found = set()
        for seed in range(30):
            res = r.ik(T, seed=seed, tol_position=1e-10, tol_orientation=1e-10,
                       q0=random_q(c, 1, seed=200 + seed)[0])
            assert res.success
            gap = _gap(B, res.q)
            assert gap.min() <= 1e-6
            found.add(int(np.argmin(gap)))
        assert len(found) >= 2


def test_all_turns_lists_every_copy_ranked_from_the_reference():
    r = kin.load_robot("ur5e")
    c = r.chain
    q = c.to_si([10, -80, 100, -100, -70, 20])
    T = fk_numpy(c, q)
    ref = c.to_si([-350, -80, 100, -100, -70, 20])
    B = analytic_ik(r, T)
    A = analytic_ik(r, T, q_ref=ref, all_turns=True)
    # every copy of every branch within ±360°: 2 per joint value not a multiple of 360° (3 for 0, 2 for ±180)
    expected = sum(np.prod([3 if abs(x) < 1e-9 else 2 for x in b]) for b in B)
    assert len(A) == expected and c.within_limits(A).all()
    _check_branches(c, A, T)
    d = np.linalg.norm(A - ref, axis=1)
    assert np.all(np.diff(d) >= -1e-12)
    assert np.abs(A[0] - ref).max() <= 1e-7                 # the reference reaches the pose: it comes first
    near = analytic_ik(r, T, q_ref=ref)
    assert np.abs(near[0] - ref).max() <= 1e-7


def test_structure_read_from_the_dh_values_not_the_name():
    """A renamed UR with offsets, base and tool placements, in modified DH, and with a twist α₂ = 180°
    (θ₃, θ₄ and d₃, d₄ folded) — all solved, every branch verified by the numpy FK."""
    c = kin.load_chain("ur10e")
    placed = replace(c, name="arm_x",
                     joints=tuple(replace(j, theta=0.1 * (i + 1) - 0.3) for i, j in enumerate(c.joints)),
                     base=Placement(xyz=(0.1, -0.2, 0.3), rpy=(0.2, -0.4, 1.1)),
                     tool=Placement(xyz=(0.01, 0.02, 0.15), rpy=(-0.3, 0.5, 0.7)))
    m = c.to_modified()
    js = list(m.joints)
    js[2] = replace(js[2], alpha=math.pi, d=0.05)           # a₂ row: α₂ = π
    js[3] = replace(js[3], d=0.07)
    flipped = replace(m, name="arm_flipped", joints=tuple(js))
    js2 = list(m.joints)
    js2[3] = replace(js2[3], alpha=math.pi)                 # α₃ = π
    flipped3 = replace(m, name="arm_flipped3", joints=tuple(js2))
    for chain in (placed, placed.to_modified(), flipped, flipped3):
        r = kin.Robot(chain)
        arm = closed_form(chain)
        assert isinstance(arm, ParallelArm)
        # the link lengths survive the folding of flipped twists (only signs of θ and d move)
        assert np.abs(np.abs(arm.a) - np.abs(chain.to_modified().dh_table()[:, 0])).max() <= 1e-12
        for q in random_q(chain, 8, seed=9):
            T = fk_numpy(chain, q)
            B = analytic_ik(r, T)
            _check_branches(chain, B, T)
            assert _gap(B, q).min() <= 1e-7


def test_ur5e_structure_holds_the_published_lengths():
    """The structure read from the UR5e's DH rows (modified DH) carries Universal Robots' published
    lengths: d1 0.1625, a2 −0.425, a3 −0.3922, d4 0.1333, d5 0.0997, d6 0.0996 m."""
    arm = parallel_arm(kin.load_chain("ur5e"))
    assert isinstance(arm, ParallelArm)
    assert np.allclose(arm.a, [0, 0, -0.425, -0.3922, 0, 0], atol=1e-12)
    assert np.allclose(arm.d, [0.1625, 0, 0, 0.1333, 0.0997, 0.0996], atol=1e-12)
    assert np.allclose(np.abs(np.sin(arm.alpha)), [0, 1, 0, 0, 1, 1], atol=1e-12)


def test_other_structures_are_refused_with_the_reason():
    puma = kin.load_chain("puma560")
    assert abs(math.sin(puma.to_modified().dh_table()[3, 1])) > 0.99    # α3 = ±90°: axes 3 and 4 cross
    assert "parallel" in parallel_arm(puma)
    # the parallelism test's tolerance: a twist 1e-12 rad off 0 is parallel, 1e-6 rad off is not
    m = kin.load_chain("ur5e").to_modified()
    for tilt, parallel in ((1e-12, True), (1e-6, False)):
        js = list(m.joints)
        js[2] = replace(js[2], alpha=tilt)
        arm = parallel_arm(replace(m, joints=tuple(js)))
        assert isinstance(arm, ParallelArm) == parallel, (tilt, arm)
    for name in ("stanford_arm", "planar_2r", "kuka_iiwa14"):
        with pytest.raises(NoClosedFormError, match="spherical wrist|six revolute"):
            analytic_ik(kin.load_robot(name), np.eye(4))
    with pytest.raises(NoClosedFormError, match="nor is it a parallel-axes arm"):
        closed_form(random_chain(3, n=6, types=("revolute",) * 6))


@pytest.mark.parametrize("q5", [0.0, 1e-9, 1e-5, math.pi])
def test_wrist_singular_poses_do_not_crash(q5):
    """θ₅ = 0 or π: axes 4 and 6 align; θ₆ is taken from the reference and the branches still verify."""
    r = kin.load_robot("ur5e")
    c = r.chain
    Q = random_q(c, 6, seed=21)
    Q[:, 4] = q5
    for q in Q:
        T = fk_numpy(c, q)
        B = analytic_ik(r, T, q_ref=q)
        _check_branches(c, B, T)
        assert _gap(B, q).min() <= 1e-6                    # the configuration the pose came from is found
        if q5 in (0.0, math.pi):
            assert np.abs(B[0] - q).max() <= 1e-6          # the reference itself is a solution of the family


def test_out_of_reach_gives_no_branch():
    r = kin.load_robot("ur5e")
    T = np.eye(4)
    T[:3, 3] = (1.5, 0.0, 0.2)
    assert analytic_ik(r, T).shape == (0, 6)
