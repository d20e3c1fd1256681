"""Deliberate errors are RmtError subclasses (one line at the CLI, catchable as one family in the API),
and argument errors still derive from ValueError for code that caught them before."""
from __future__ import annotations

import numpy as np
import pytest

import kin
from planning.certify import certify_path
from planning.testing import assert_path_valid


@pytest.fixture(scope="module")
def fanuc():
    return kin.load_robot("fanuc_m16ib20")


@pytest.mark.parametrize("call, cls", [
    (lambda r: r.ik(r.fk(np.zeros(6)), method="newton-raphson"), kin.ArgumentError),
    (lambda r: r.ik(r.fk(np.zeros(6)), method="numeric", mode="velocity"), kin.ArgumentError),
    (lambda r: certify_path(None, np.zeros((2, 6, 1))), kin.ConfigurationError),
    (lambda r: certify_path(None, np.full((2, 6), np.nan)), kin.ConfigurationError),
    (lambda r: assert_path_valid(r, np.zeros((2, 6)), step=-1.0), kin.ConfigurationError),
])
def test_deliberate_errors_are_rmt_errors(fanuc, call, cls):
    with pytest.raises(cls) as e:
        call(fanuc)
    assert isinstance(e.value, kin.RmtError) and isinstance(e.value, ValueError)
    assert "\n" not in str(e.value)
