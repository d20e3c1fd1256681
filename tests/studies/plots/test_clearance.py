"""Clearance figures: the two-joint map's shares are the clearance kernel's verdicts counted, and the
path figure marks each path's closest state with the pair the kernel names."""
from __future__ import annotations

import numpy as np
import pytest

import kin
from planning.cell import parse_cell
from planning.collision import collision_world
from studies.plots.clearance import plot_clearance, plot_collision_map

CELL = """
length_unit = "mm"
[robot]
xyz = [0, 0, 800]
[[obstacle]]
name = "table"
type = "box"
size = [1400, 900, 40]
xyz = [400, 0, 780]
ignore = ["base", "link 1"]
[[obstacle]]
name = "post"
type = "cylinder"
radius = 80
length = 1000
xyz = [-250, -550, 1300]
"""


@pytest.fixture(scope="module")
def world():
    return collision_world(kin.load_robot("fanuc_lrmate200id"), parse_cell(CELL, "c.toml"), margin=0.005)


def test_collision_map_counts_the_kernels_verdicts(world):
    q = np.radians([0, 0, 0, 0, 90, 0])
    fig, shares = plot_collision_map(world, q, (1, 2), (21, 31), marks=[("here", (0.0, 0.0))])
    assert shares["grid"] == [21, 31]
    assert sum(shares[k] for k in ("clear", "cell", "self", "both")) == pytest.approx(1.0)
    c = world.chain
    A, B = np.meshgrid(np.linspace(c.lower[1], c.upper[1], 21), np.linspace(c.lower[2], c.upper[2], 31), indexing="ij")
    Q = np.tile(q, (A.size, 1))
    Q[:, 1], Q[:, 2] = A.ravel(), B.ravel()
    obs, slf = world.per_body(Q)
    cell, own = obs.min(axis=1) <= 0.005, slf.min(axis=1) <= 0.005
    assert shares["both"] == pytest.approx(np.mean(cell & own))
    assert shares["clear"] == pytest.approx(np.mean(~cell & ~own))
    assert shares["self"] > 0 and shares["cell"] > 0            # the folded forearm, the arm in the table
    ax = fig.axes[0]
    assert ax.get_xlabel() == "J2 (deg)" and ax.get_ylabel() == "J3 (deg)"


def test_clearance_along_paths_names_the_closest_pair(world):
    start, goal = np.radians([0, 0, 0, 0, 90, 0]), np.radians([0, 100, 0, 0, 90, 0])
    bent = np.array([start, np.radians([0, 40, -30, 0, 90, 0])])
    fig = plot_clearance(world, [("into the table", np.array([start, goal])), ("bent", bent)],
                         bounds={"bent": 0.02})
    top, per_body = fig.axes
    texts = [t.get_text() for t in top.texts]
    line = start + np.linspace(0, 1, 600)[:, None] * (goal - start)
    k = int(np.argmin(world.clearance(line)))
    c = world.nearest(line[k:k + 1])
    assert world.describe(int(c.body[0]), int(c.other[0]), float(c.clearance[0])) in texts
    labels = [t.get_text() for t in top.get_legend().get_texts()]
    assert "bent: proven lower bound 20 mm" in labels and "required clearance 5 mm" in labels
    assert "into the table" in per_body.get_ylabel()
