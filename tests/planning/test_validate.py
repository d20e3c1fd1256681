"""Dense path validation (planning.validate) against independent values.

Expected violation rows and fractions are worked out by hand from the constructed paths (a joint
crossing a bound at a known fraction of a segment); σ_min along a path is recomputed with the plain
numpy DH Jacobian of ``tests/dh_numpy.py`` and numpy's SVD; state counts from the stated rule (no
joint moves more than the step between checked states).
"""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

import kin
from kin.errors import ConfigurationError
from planning.validate import DEFAULT_STEP_ANGLE, DEFAULT_STEP_LENGTH, check_path, densify
from planning.windows import build_windows
from tests.dh_numpy import jacobian_numpy

MARGIN = 0.05
ELBOW_ROOT = math.atan2(0.74, 0.1)      # FANUC: 0.1 sin q3 − 0.74 cos q3 = 0


@pytest.fixture(scope="module")
def fanuc():
    robot = kin.load_robot("fanuc_m16ib20")
    return robot, build_windows(robot, margin=MARGIN)


def _base(q5: float = 0.5) -> np.ndarray:
    # far from the elbow (q3 = 0.2 vs 1.44) and shoulder (wrist centre 1.33 m off the axis) windows
    return np.array([0.0, 0.3, 0.2, 0.0, q5, 0.0])


def _fraction(detail: str) -> float:
    m = re.search(r"at ([0-9.]+) of the segment", detail)
    assert m, detail
    return float(m.group(1))


def _sigma_numpy(chain, Q: np.ndarray, rows=slice(None)) -> np.ndarray:
    return np.array([np.linalg.svd(jacobian_numpy(chain, q)[rows], compute_uv=False).min() for q in Q])


def test_window_crossing_reported_at_the_segment_start(fanuc):
    robot, ws = fanuc
    P = np.array([_base(0.5), _base(0.3), _base(-0.4)])   # segment 1 crosses q5 = 0
    chk = check_path(robot, P, ws)
    assert not chk.valid
    v = chk.first_violation
    assert (v.index, v.kind) == (1, "window")
    assert "wrist" in v.detail and "between rows 1 and 2" in v.detail
    # q5 = 0.3 − 0.7 t enters [−0.05, 0.05] at t = 0.25 / 0.7; the first dense state inside lies
    # within one 0.1° step (of 0.7 rad) after it
    t_in = 0.25 / 0.7
    assert t_in <= _fraction(v.detail) <= t_in + DEFAULT_STEP_ANGLE / 0.7 + 1e-3


def test_state_on_a_row_inside_a_window_is_that_row(fanuc):
    robot, ws = fanuc
    q = _base(0.5)
    q_in = q.copy()
    q_in[2] = ELBOW_ROOT + 0.5 * MARGIN               # inside the elbow interval
    P = np.array([q, q + 0.01, q_in])
    v = check_path(robot, P, ws).first_violation
    assert v.kind == "window" and "elbow" in v.detail
    # q3 goes 0.21 → 1.461; it enters [root − w, root + w] inside segment 1 already
    assert v.index == 1


def test_limit_violation_in_the_middle_of_a_segment(fanuc):
    robot, ws = fanuc
    P = np.array([_base(), _base(), _base()])
    P[:, 0] = [0.0, 2.5, 3.5]                          # joint 1 limit 2.97 crossed at t = 0.47
    chk = check_path(robot, P, ws)
    v = chk.first_violation
    assert (v.index, v.kind) == (1, "limits")
    assert "joint 1" in v.detail and "between rows 1 and 2" in v.detail
    assert 0.47 <= _fraction(v.detail) <= 0.47 + DEFAULT_STEP_ANGLE + 1e-3


def test_continuity_with_max_step(fanuc):
    robot, ws = fanuc
    P = np.array([_base() + d for d in (0.0, 0.05, 0.10, 0.10)])
    P[3, 2] += 0.3                                     # joint 3 jumps 0.3 rad between rows 2 and 3
    free = check_path(robot, P, ws)
    assert free.valid and math.isclose(free.max_step, 0.3, rel_tol=1e-12)
    v = check_path(robot, P, ws, max_step=0.1).first_violation
    assert (v.index, v.kind) == (2, "continuity")
    assert "joint 3" in v.detail


def test_earliest_row_wins(fanuc):
    robot, ws = fanuc
    P = np.array([_base(0.5), _base(0.5), _base(0.3), _base(-0.4)])
    P[1, 0] += 0.5                                     # continuity at row 0, window in segment 2
    v = check_path(robot, P, ws, max_step=0.2).first_violation
    assert (v.index, v.kind) == (0, "continuity")
    assert check_path(robot, P, ws).first_violation.index == 2


def test_nonfinite_row(fanuc):
    robot, ws = fanuc
    P = np.array([_base(), _base(), _base()])
    P[1, 3] = np.nan
    chk = check_path(robot, P, ws)
    assert not chk.valid and (chk.first_violation.index, chk.first_violation.kind) == (1, "nonfinite")


def test_sigma_floor_and_min_sigma_against_numpy_svd(fanuc):
    robot, _ = fanuc
    P = np.array([_base(0.3), _base(-0.3)])            # through the wrist singularity q5 = 0
    chk = check_path(robot, P, None, sigma_min=0.01)
    assert (chk.first_violation.index, chk.first_violation.kind) == (0, "sigma_min")
    # independent densification: K = ⌈0.6 rad / 0.1°⌉ sub-steps, states at t = k/K
    K = math.ceil(0.6 / DEFAULT_STEP_ANGLE)
    t = np.arange(K + 1) / K
    Q = P[0] + t[:, None] * (P[1] - P[0])
    sig = _sigma_numpy(robot.chain, Q)
    assert chk.checked_states == K + 1
    assert math.isclose(chk.min_sigma, sig.min(), rel_tol=1e-9, abs_tol=1e-12)
    assert chk.min_sigma_index == 0
    assert _sigma_numpy(robot.chain, _base(0.0)[None])[0] < 1e-12   # the singularity itself


def test_valid_path_and_state_count(fanuc):
    robot, ws = fanuc
    P = np.array([_base(0.5), _base(0.6) + 0.02, _base(0.4) - 0.03])
    chk = check_path(robot, P, ws)
    assert chk.valid and chk.first_violation is None
    d = np.abs(np.diff(P, axis=0)).max(axis=1)
    assert chk.checked_states == int(sum(math.ceil(x / DEFAULT_STEP_ANGLE) for x in d)) + 1
    assert check_path(robot, P[:1], ws).checked_states == 1


def test_prismatic_joints_use_the_length_step():
    robot = kin.load_robot("scara_rrp")
    P = np.array([[0.3, 0.8, -0.2], [0.3, 0.8, -0.19]])   # 10 mm of the prismatic joint only
    chk = check_path(robot, P)
    # ⌈Δd / 0.1 mm⌉ + 1 (≈ 101; Δd is 0.01 m up to rounding) — the 0.1° angle step would give 7
    assert chk.valid and chk.checked_states == math.ceil(abs(P[1, 2] - P[0, 2]) / DEFAULT_STEP_LENGTH) + 1
    assert 100 < chk.checked_states <= 102
    # σ_min of the position rows (SCARA task x, y, z), numpy SVD
    sig = _sigma_numpy(robot.chain, P, rows=slice(0, 3))
    assert math.isclose(chk.min_sigma, sig.min(), rel_tol=1e-9)


def test_prismatic_rows_beyond_the_evaluators_range_refused():
    """A prismatic joint at 1e305 m (a CSV's 1e308 mm) had its σ_min evaluated there (NaN-born values
    on other chains, RuntimeWarnings on the VM); such a row is refused naming it and the range."""
    import warnings
    robot = kin.load_robot("scara_rrp")
    P = np.array([[0.0, 0.5, -0.15], [0.0, 0.5, 1e305], [0.0, 0.5, 1e305]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ConfigurationError,
                           match=r"path: prismatic joint 3 = 1e\+305 m \(row 1\) is beyond ±1e\+06 m"):
            check_path(robot, P, None)
        P[1:, 2] = -1e6                       # within the range: far outside the limits, reported as such
        res = check_path(robot, P[1:], None)
    assert not res.valid and res.first_violation.kind == "limits" and res.first_violation.index == 0


def test_densify_respects_the_step_and_keeps_the_rows():
    rng = np.random.default_rng(7)
    P = rng.uniform(-1, 1, size=(6, 4))
    revolute = np.array([True, True, False, True])
    Q, seg, frac = densify(P, revolute, 0.01, 0.002)
    steps = np.abs(np.diff(Q, axis=0))
    assert (steps[:, revolute] <= 0.01 + 1e-12).all() and (steps[:, ~revolute] <= 0.002 + 1e-12).all()
    rows = Q[frac == 0]
    np.testing.assert_array_equal(rows, P)
    np.testing.assert_array_equal(seg[frac == 0], np.arange(len(P)))


@pytest.mark.parametrize("bad", [np.zeros((0, 6)), np.zeros((3, 5)), np.zeros(6)])
def test_bad_shapes_raise(fanuc, bad):
    robot, ws = fanuc
    with pytest.raises(ConfigurationError, match="expected"):
        check_path(robot, bad, ws)


def test_steps_outside_their_range_raise(fanuc):
    robot, ws = fanuc
    for step in (0.0, -1.0, 1e-300, 1e308, math.inf, math.nan):
        with pytest.raises(ConfigurationError, match=r"outside the allowed range \[1e-06, 0.0872665\] rad"):
            check_path(robot, np.array([_base()]), ws, step_angle=step)
    # the fanuc has no prismatic joint: its length step is not used, hence not checked
    assert check_path(robot, np.array([_base()]), ws, step_length=1e308).valid in (True, False)


def test_state_budget_is_enforced_before_any_work(fanuc):
    robot, ws = fanuc
    P = _base() + np.outer(np.arange(22) % 2, np.full(6, 0.5))  # 21 segments of 0.5 rad on every joint
    # at 1e-6 rad: 21 × 500 000 + 1 = 10 500 001 states, within the budget of 2·10⁷ …
    assert check_path(robot, P[:2], ws, step_angle=1e-6).checked_states == 500_001
    # … at 1e-6 rad over 21 segments of 1 rad: 2.1·10⁷ + 1 states, refused at once
    with pytest.raises(ConfigurationError, match=r"would evaluate 2.1e\+07 states; at most 2e\+07"):
        check_path(robot, _base() + np.outer(np.arange(22) % 2, np.full(6, 1.0)) * [1, 0.1, 0.1, 0.1, 0.1, 0.1],
                   ws, step_angle=1e-6)


def test_chunked_check_equals_the_dense_one(fanuc):
    """Chunks of 7 states give the same verdict, minimum and count as one chunk holding everything,
    and the count is the closed form Σ ceil(max |Δq| / step) + 1."""
    robot, ws = fanuc
    rng = np.random.default_rng(3)
    P = _base() + rng.uniform(-0.02, 0.02, (6, 6)).cumsum(axis=0)
    one = check_path(robot, P, ws, chunk=10**9)
    many = check_path(robot, P, ws, chunk=7)
    assert one == many
    expected = int(np.ceil(np.abs(np.diff(P, axis=0)).max(axis=1) / DEFAULT_STEP_ANGLE).sum()) + 1
    assert one.checked_states == expected
    Q, seg, frac = densify(P, robot.chain.revolute_mask)
    assert one.min_sigma == pytest.approx(robot.sigma_min(Q).min(), rel=1e-12)


def test_messages_in_the_robot_file_units():
    """ur5e is written in degrees: a violation names the joint and gives its values in degrees with
    the unit (the limit ±360°, the step allowed 30°); σ_min in SI, said so."""
    robot = kin.load_robot("ur5e")
    P = np.radians([[0, -90, 90, -90, -90, 0], [370, -90, 90, -90, -90, 0]])
    v = check_path(robot, P, max_step=math.radians(30)).first_violation
    assert v.kind == "continuity" and v.detail == "joint 1 (base) moves 370° between rows 0 and 1; allowed 30°"
    v = check_path(robot, P).first_violation
    assert v.kind == "limits"
    assert re.match(r"joint 1 \(base\) = 360\.\d+° outside \[-360°, 360°\] between rows 0 and 1", v.detail), v.detail
    Q = np.radians([[0, -90, 90, -90, -90, 0], [0, -90, 90, -90, 90, 0]])     # q5 through 0: the wrist singularity
    v = check_path(robot, Q, sigma_min=1e-3).first_violation
    assert v.kind == "sigma_min" and re.match(r"σ_min = \S+ < 0\.001 \(SI\) between rows 0 and 1", v.detail), v.detail
