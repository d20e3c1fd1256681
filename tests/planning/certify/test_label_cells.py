"""planning.certify.cells.label_cells gives the labels of scipy.ndimage.label with full
connectivity (faces, edges and corners), numbered alike, on random and adversarial grids."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from planning.certify.cells import label_cells


def _spiral(R: int) -> np.ndarray:
    g = np.zeros((R, R), bool)
    x0, y0, x1, y1 = 0, 0, R - 1, R - 1
    while x0 <= x1 and y0 <= y1:
        g[y0, x0:x1 + 1] = True
        g[y0:y1 + 1, x1] = True
        if y1 - y0 >= 2:
            g[y1, x0 + 2:x1 + 1] = True
        if x1 - x0 >= 2:
            g[y0 + 2:y1 + 1, x0 + 2] = True
        x0, y0, x1, y1 = x0 + 4, y0 + 4, x1 - 4, y1 - 4
    return g


def _grids():
    rng = np.random.default_rng(0)
    yield "1d", rng.random(500) > 0.3
    for p in (0.3, 0.5, 0.7):
        yield f"2d random {p}", rng.random((64, 80)) > p
        yield f"3d random {p}", rng.random((20, 24, 18)) > p
    yield "2d spiral", _spiral(128)
    diag = np.zeros((40, 40), bool)
    diag[np.arange(40), np.arange(40)] = True             # joined through corners only
    yield "2d diagonal", diag
    d3 = np.zeros((12, 12, 12), bool)
    d3[np.arange(12), np.arange(12), np.arange(12)] = True
    yield "3d diagonal", d3
    bands = np.ones((48, 48, 48), bool)
    bands[:, 20:22, :] = False
    bands[10:12, :, :] = False
    yield "3d bands", bands
    yield "empty", np.zeros((16, 16), bool)
    yield "full", np.ones((16, 16, 16), bool)


@pytest.mark.parametrize("name,free", list(_grids()), ids=[n for n, _ in _grids()])
def test_same_labels_as_ndimage(name, free):
    ref, count = ndimage.label(free, structure=np.ones((3,) * free.ndim, int))
    ours = label_cells(free)
    assert ours.shape == free.shape and ours.max(initial=0) == count
    assert np.array_equal(ours, ref)
