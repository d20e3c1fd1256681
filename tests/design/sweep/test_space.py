"""Design-space sampling: the grid against itertools/numpy, Latin-hypercube strata, Sobol balance,
and stable keys of normalised designs."""
import itertools

import numpy as np
import pytest

from design.sweep import Design, design_key, load_sweep, sample_designs
from tests.design.sweep.helpers import write_sweep


def test_grid_is_the_product_of_the_ranges(tmp_path):
    sw = load_sweep(write_sweep(tmp_path, counts=(4, 3)))
    got = np.array([d.vector() for d in sample_designs(sw)])
    expect = np.array(list(itertools.product(np.linspace(0.1, 0.4, 4), np.linspace(0.1, 0.4, 3))))
    assert got.shape == (12, 2)
    np.testing.assert_allclose(got, expect, rtol=0, atol=1e-12)


def test_lhs_hits_every_stratum_once_and_is_seeded(tmp_path):
    p = write_sweep(tmp_path, sampling='[sampling]\nmethod = "lhs"\ncount = 20\nseed = 3')
    a = np.array([d.vector() for d in sample_designs(load_sweep(p))])
    b = np.array([d.vector() for d in sample_designs(load_sweep(p))])
    np.testing.assert_array_equal(a, b)
    strata = np.floor((a - 0.1) / 0.3 * 20).astype(int)
    for j in range(2):
        assert sorted(strata[:, j]) == list(range(20))


def test_sobol_points_are_balanced(tmp_path):
    p = write_sweep(tmp_path, sampling='[sampling]\nmethod = "sobol"\ncount = 64\nseed = 1')
    a = np.array([d.vector() for d in sample_designs(load_sweep(p))])
    u = (a - 0.1) / 0.3
    assert len(a) == 64
    for j in range(2):                      # a (0, m, 2)-net: every eighth of each axis holds 8 points
        assert np.bincount(np.floor(u[:, j] * 8).astype(int), minlength=8).tolist() == [8] * 8


def test_keys_are_stable_under_normalisation():
    a = Design.make("", {"A1": 0.2, "A2": 0.3})
    b = Design.make("", {"A1": 0.2 + 1e-15, "A2": 0.3})
    c = Design.make("", {"A1": 0.2 + 1e-9, "A2": 0.3})
    d = Design.make("RRP", {"A1": 0.2, "A2": 0.3})
    assert a.key == b.key and a.key != c.key and a.key != d.key
    assert a.key == design_key("", {"A2": 0.3, "A1": 0.2})      # parameter order does not matter
    assert len(a.key) == 64


def test_grid_points_are_unique_designs(tmp_path):
    p = write_sweep(tmp_path, counts=(1, 5), extra='', name="one")
    ds = sample_designs(load_sweep(p))
    assert len({d.key for d in ds}) == len(ds) == 5
    assert all(d.values["A1"] == pytest.approx(0.25) for d in ds)
