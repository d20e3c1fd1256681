"""Issue 32: whether each joint holds the rest of the chain at rest.  The proven bound is at least the
largest |g_j| a dense grid over the joint limits finds (the gravity torques themselves are checked
against pinocchio in test_assembled_dynamics.py), the witness is a torque that occurs, a vertical
first axis is proven to carry 0, and an assembly whose weak joint provably cannot hold a heavy tool
is refused in one line naming the joint."""
from __future__ import annotations

import numpy as np
import pytest

import kin
from kin.modules import Assembly, AssemblyError, assemble, gravity_bound, holding, load_catalogue
from tests.kin.modules.plain import FIXTURE


@pytest.fixture(scope="module")
def cat():
    return load_catalogue(FIXTURE)


def _grid_max(chain, per_axis):
    robot = kin.Robot(chain, backend="vm")
    axes = [np.linspace(lo, hi, per_axis) for lo, hi in zip(chain.lower, chain.upper)]
    Q = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, chain.n)
    G = np.abs(np.asarray(robot.gravity(Q)).reshape(-1, chain.n))
    return G.max(axis=0), robot


@pytest.mark.parametrize("text, per_axis", [("wall R80 L300b E80 L200 grip", 241),
                                            ("wall E80@90 L200 R80@90 L300b R80 grip", 41),
                                            ("wall R80 P80@90 L200 grip", 121)])
def test_the_bound_is_above_every_torque_of_a_dense_grid(cat, text, per_axis):
    chain = assemble(cat, Assembly.parse(text, cat), check_holding=False)
    rep = holding(chain)
    grid, robot = _grid_max(chain, per_axis)
    assert grid.max() > 1.0                                  # gravity acts across these axes
    assert np.all(rep.bound >= grid - 1e-12), (rep.bound, grid)
    np.testing.assert_array_equal(rep.bound, gravity_bound(chain))
    for j in range(chain.n):
        # the witness occurs: its configuration is within the limits and gives that torque
        qj = rep.witness_q[j]
        assert np.all(qj >= chain.lower) and np.all(qj <= chain.upper)
        assert abs(float(np.asarray(robot.gravity(qj))[j])) == pytest.approx(rep.witness[j], rel=1e-9, abs=1e-12)
        assert rep.witness[j] <= rep.bound[j] + 1e-12
        assert rep.witness[j] >= 0.99 * grid[j]               # the search finds the grid's best, or better
        assert rep.verdict[j] == ("holds" if rep.bound[j] <= rep.max_torque[j] else
                                  "fails" if rep.witness[j] > rep.max_torque[j] else "unproven")


def test_a_vertical_first_axis_is_proven_to_carry_nothing(cat):
    chain = assemble(cat, Assembly.parse("stand R80 L300b E80 L200 grip", cat), check_holding=False)
    rep = holding(chain)
    assert rep.bound[0] == 0.0 and rep.verdict[0] == "holds"
    assert rep.bound[1] > 0.0
    grid, _ = _grid_max(chain, 61)
    assert grid[0] < 1e-9 < grid[1] <= rep.bound[1]


def test_a_heavy_tool_on_a_weak_joint_is_refused_naming_the_joint(cat):
    """R63 (8 N·m) turns a 20 kg tool whose centre of mass is 120 mm off its horizontal axis: 23.5 N·m."""
    a = Assembly.parse("wall A80_63 R63 L63 heavy", cat)
    with pytest.raises(AssemblyError) as e:
        assemble(cat, a)
    msg = str(e.value)
    assert "\n" not in msg and "joint 1 (j1_r63)" in msg and "cannot hold" in msg and "8 N·m" in msg
    chain = assemble(cat, a, check_holding=False)
    rep = holding(chain)
    assert rep.fails == [0] and rep.witness[0] == pytest.approx(20 * 9.81 * 0.120, rel=1e-6)
    # the light tool on the same joint holds
    assert holding(assemble(cat, Assembly.parse("wall A80_63 R63 L63 grip63", cat))).verdict == ("holds",)
