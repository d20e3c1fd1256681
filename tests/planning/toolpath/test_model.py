"""planning.toolpath.model: :meth:`ToolPath.from_poses` refuses what is not (N, 4, 4) poses of
numbers within the tool-path range with a ToolPathError naming ``poses`` and the expected shape —
never an IndexError or a RuntimeWarning; :func:`robot_units` names a missing robot."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import kin
from planning.toolpath import ToolPath, ToolPathError
from planning.toolpath.model import robot_units


@pytest.mark.parametrize("poses, words", [
    (np.zeros((3, 3, 3)), "poses has shape (3, 3, 3); expected (N, 4, 4)"),
    (np.zeros((3, 3)), "poses has shape (3, 3); expected (N, 4, 4)"),
    (np.zeros((0, 4, 4)), "poses has shape (0, 4, 4); expected (N, 4, 4) with N ≥ 1"),
    (np.zeros((2, 4, 4, 1)), "poses has shape (2, 4, 4, 1)"),
    (np.zeros(16), "poses has shape (16,)"),
    (3.0, "poses has shape ()"),
    ([[1.0, 2.0], [3.0]], "poses is not an array of numbers"),
    ("abc", "poses must hold real numbers"),
    (np.eye(4, dtype=complex), "poses must hold real numbers"),
    (None, "poses must hold real numbers"),
    (np.full((2, 4, 4), math.nan), "poses hold NaN or infinite values"),
])
def test_from_poses_refuses_bad_arrays(poses, words):
    with pytest.raises(ToolPathError) as e:
        ToolPath.from_poses(poses)
    assert words in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("coordinate", [1e308, -1e308, 1e5])
def test_from_poses_refuses_coordinates_beyond_the_range(coordinate):
    """Chord lengths of poses at ±1e308 m overflowed (RuntimeWarning, inf arc length)."""
    T = np.tile(np.eye(4), (3, 1, 1))
    T[2, :3, 3] = [coordinate, -coordinate, 0.0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ToolPathError, match=r"poses\[2\] has a coordinate beyond ±10000 m"):
            ToolPath.from_poses(T, feed=0.1)


def test_from_poses_accepts_one_pose_and_a_batch():
    assert len(ToolPath.from_poses(np.eye(4))) == 1
    T = np.tile(np.eye(4), (3, 1, 1))
    T[:, 0, 3] = [0.0, 1.0, 3.0]
    tp = ToolPath.from_poses(T.tolist(), feed=0.5)
    np.testing.assert_allclose(tp.s, [0.0, 1.0, 3.0])
    np.testing.assert_allclose(tp.t, [0.0, 2.0, 6.0])


@pytest.mark.parametrize("robot, words", [(None, "robot is None"), ("scara_rrp", "robot is 'scara_rrp'"),
                                          (3, "robot is 3")])
def test_robot_units_names_a_missing_robot(robot, words):
    with pytest.raises(ToolPathError) as e:
        robot_units(robot)
    assert words in str(e.value) and "kin.Robot or kin.Chain" in str(e.value)


def test_robot_units_of_a_robot_and_a_chain():
    chain = kin.load_chain("scara_rrp")
    assert robot_units(chain) == robot_units(kin.Robot(chain)) == (chain.length_unit, chain.angle_unit)
