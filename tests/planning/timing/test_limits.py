"""Tests of planning.timing.limits: the dense re-check between samples against a trajectory whose
ratios are known in closed form (the trapezoid, and the same played twice as fast)."""
from __future__ import annotations

import numpy as np
import pytest

from planning.timing import TimingError, check_limits, time_parameterize
from planning.timing.limits import dense_ratios, dense_times


def test_dense_times_cover_every_interval_up_to_its_end():
    t = np.array([0.0, 1.0, 3.0])
    d = dense_times(t, 4)
    assert len(d) == 2 * 5 + 1 and d[0] == 0.0 and d[-1] == 3.0
    assert np.all(np.diff(d) > 0)
    assert d[4] == pytest.approx(1.0 - 1e-9) and d[5] == 1.0


def test_dense_ratios_of_the_trapezoid_and_of_a_too_fast_copy():
    tr = time_parameterize(np.array([[0.0], [1.0]]), 1.0, 2.0)
    dv, da = dense_ratios(tr, 1.0, 2.0)
    assert dv == pytest.approx(1.0, abs=1e-9) and da == pytest.approx(1.0, abs=1e-9)
    assert tr.overshoot <= 1e-12
    fast = type(tr)(**{**tr.__dict__, "t": tr.t / 2, "sd": tr.sd * 2, "sdd": tr.sdd * 4})
    dv, da = dense_ratios(fast, 1.0, 2.0)
    assert dv == pytest.approx(2.0, rel=1e-9) and da == pytest.approx(4.0, rel=1e-9)
    assert not check_limits(type(tr)(**{**fast.__dict__, "qd": tr.qd * 2, "qdd": tr.qdd * 4}), 1.0, 2.0).ok


def test_dense_ratios_bad_input():
    tr = time_parameterize(np.array([[0.0], [1.0]]), 1.0, 2.0)
    with pytest.raises(TimingError, match="per_interval"):
        dense_ratios(tr, 1.0, 2.0, per_interval=0)
    with pytest.raises(TimingError, match="v_max"):
        dense_ratios(tr, [1.0, 1.0], 2.0)
