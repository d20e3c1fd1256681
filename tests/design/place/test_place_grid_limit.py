"""``place`` refuses a grid cross-check it could not hold in memory (it is built whole), before any work."""
import time

import numpy as np
import pytest

import kin
from design.place import MAX_GRID, PlacementRegion, place
from design.task import Targets, TaskError


def test_a_grid_too_large_for_its_free_coordinates_is_refused_at_once():
    robot = kin.load_robot("planar_2r")
    targets = Targets(np.array([[1.0, 0.0, 0.0]]))
    t0 = time.perf_counter()
    with pytest.raises(TaskError, match=r"grid = 1000 values on each of the 3 free coordinates \(x, y, yaw\)"):
        place(robot, targets, grid=1000)                   # the default region: x, y and yaw free
    assert time.perf_counter() - t0 < 1.0
    region = PlacementRegion((-1, 1), (-1, 1), (0, 1))                 # x, y, z and yaw free
    with pytest.raises(TaskError, match=f"is 1.05e\\+06 placements; at most {MAX_GRID}"):
        place(robot, targets, region=region, grid=32)
