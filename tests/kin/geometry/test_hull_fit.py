"""thin_hull: fewer points, and the dilated hull of the kept ones still holds every point — checked by
coal's distance from each point to the kept points' hull."""
from __future__ import annotations

import numpy as np
import pytest

from kin.geometry.hull_fit import thin_hull
from tests.coal_ref import frame_along, hull, placed_distance

coal = pytest.importorskip("coal")


@pytest.mark.parametrize("seed", range(4))
def test_thin_hull_holds_every_point(seed):
    rng = np.random.default_rng(seed)
    # a cylinder's rim and a box's corners: many hull points on curves
    t = rng.uniform(0, 2 * np.pi, 400)
    rim = np.c_[0.05 * np.cos(t), 0.05 * np.sin(t), rng.choice([-0.04, 0.04], 400)]
    box = rng.choice([-1, 1], (8, 3)) * [0.1, 0.03, 0.02] + [0.1, 0, 0]
    P = np.vstack([rim, box, rng.normal(size=(100, 3)) * 0.01])
    kept, radius = thin_hull(P, 1e-3, decimals=4)
    assert len(kept) < 0.5 * len(rim)
    assert radius == pytest.approx(1e-3 + np.sqrt(3) / 2 * 1e-4)
    H, point = hull(kept), coal.Sphere(1e-9)
    worst = 0.0
    for p in P:
        worst = max(worst, placed_distance(H, np.eye(4), point, frame_along(p, p)))
    assert worst <= radius


def test_few_points_are_kept():
    kept, radius = thin_hull([[0, 0, 0], [1, 0, 0]], 1e-3)
    assert len(kept) == 2 and radius == 0.0
