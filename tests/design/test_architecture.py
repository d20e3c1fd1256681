"""Joint-type architectures: the enumeration, the type change checked against a plain numpy DH
re-implementation, pruning by the orientation requirement, and the 3-joint positioning task where
all 8 strings are evaluated and the PPP gantry covers the box fully (checked in closed form: a PPP
chain's tool position is affine in q, so the box must lie in the image of the stroke cube)."""
from dataclasses import replace

import numpy as np
import pytest

import kin
from design.architecture import all_architectures, optimise_architectures, required_revolute, with_joint_types
from design.optimise import VerifySettings
from design.task import Targets, TaskError, load_task
from tests.dh_numpy import fk_numpy

SKELETON = "studies/tasks/robots/cartesian3_design.toml"


def test_enumeration():
    a = all_architectures(3)
    assert len(a) == 8 == len(set(a)) and a[0] == "RRR" and a[-1] == "PPP"
    assert len(all_architectures(5)) == 32
    with pytest.raises(TaskError):
        all_architectures(0)


@pytest.mark.parametrize("types", ["RRR", "RPR", "PRP"])
def test_type_change_matches_numpy_dh(types):
    chain = with_joint_types(kin.load_chain(SKELETON), types)
    assert "".join("R" if j.is_revolute else "P" for j in chain.joints) == types
    robot = kin.Robot(chain)
    Q = robot.random_configurations(5, seed=1)
    for q in Q:
        assert np.allclose(robot.fk(q), fk_numpy(chain, q), atol=1e-12)


def test_rotation_tasks_prune_chains_without_enough_revolute_joints():
    task = load_task("studies/tasks/arch3_box.toml")
    axis = replace(task, targets=Targets(task.targets.positions[:2], "axis", np.tile([0, 0, 1.0], (2, 1))))
    assert required_revolute(axis) == 2
    rank = optimise_architectures(axis, ["PPP", "PPR", "RPP"], starts=1,
                                  settings=VerifySettings(seeds=1, samples=300), max_iter=50)
    assert set(rank.pruned) == {"PPP", "PPR", "RPP"} and not rank.results


def test_all_eight_evaluated_and_the_gantry_covers_the_box():
    task = load_task("studies/tasks/arch3_box.toml")
    rank = optimise_architectures(task, starts=1, settings=VerifySettings(seeds=2, samples=1000))
    assert sorted(rank.order) == sorted(all_architectures(3)) and not rank.pruned and not rank.errors
    ppp = rank.results["PPP"]
    assert ppp.feasible and ppp.verification.fraction == 1.0
    # closed form: position = FK(0) + M q with M the (constant) prismatic axes; invert for every target
    chain = ppp.chain
    c0 = fk_numpy(chain, np.zeros(3))[:3, 3]
    M = np.column_stack([fk_numpy(chain, e)[:3, 3] - c0 for e in np.eye(3)])
    q = np.linalg.solve(M, (task.targets.positions - c0).T).T
    tol = task.targets.tolerance      # M is orthonormal: a position tolerance is a stroke tolerance
    assert np.all((q >= -tol) & (q <= 0.6 + tol))
    assert "PPP" in rank.table() and rank.feasible[:1] == [True]
