"""The default grid resolves every piece of the path (planning.timing.grid): a zig-zag of many short
rest-to-rest moves is timed within 1 % of its closed form (issue 30)."""
from __future__ import annotations

import math

import numpy as np

from planning.timing import blend_path, time_parameterize
from planning.timing.grid import MIN_INTERVALS_PER_PIECE, default_grid
from planning.timing.parameterize import DEFAULT_INTERVALS

SQUARE = [(0.0, 0.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5)]


def square_zigzag(m: int = 200) -> np.ndarray:
    """m waypoints around a 0.5 rad square: m − 1 moves of 0.5 rad on one joint, a right angle between."""
    return np.array([SQUARE[i % 4] for i in range(m)])


def rest_to_rest(d: float, v: float, a: float) -> float:
    """Closed-form minimum time of a rest-to-rest move of length d under |v| ≤ v, |a| ≤ a."""
    return 2 * math.sqrt(d / a) if d * a <= v * v else d / v + v / a


def test_zigzag_stopping_at_every_corner_is_within_1_percent_of_the_closed_form():
    exact = 199 * rest_to_rest(0.5, 10.0, 1.0)                  # 281.43 s
    tr = time_parameterize(square_zigzag(), 10.0, 1.0, blend=0.0)
    assert exact <= tr.duration <= 1.01 * exact                 # was 317.4 s on path length / 300
    assert tr.overshoot <= 1e-9


def test_zigzag_blended_is_no_slower_than_stopping():
    exact = 199 * rest_to_rest(0.5, 10.0, 1.0)
    tr = time_parameterize(square_zigzag(), 10.0, 1.0)          # default blend 0.05
    assert tr.duration <= exact                                 # was 399.9 s
    assert tr.overshoot <= 1e-9


def test_every_piece_gets_the_minimum_number_of_intervals():
    bp = blend_path(square_zigzag(), 0.05)
    s = default_grid(bp, DEFAULT_INTERVALS, 10**6)
    ends = np.r_[bp.s0, bp.length]
    for a, b in zip(ends[:-1], ends[1:]):
        inside = np.count_nonzero((s > a + 1e-12) & (s < b - 1e-12))
        assert inside + 1 >= MIN_INTERVALS_PER_PIECE


def test_a_path_of_long_pieces_keeps_the_uniform_grid():
    W = np.array([[0.0, 0.0], [1.0, 0.5], [2.0, 0.0]])
    bp = blend_path(W, 0.2)
    assert default_grid(bp, DEFAULT_INTERVALS, 10**6) is None
    tr = time_parameterize(W, 1.0, 2.0, blend=0.2)
    assert np.allclose(tr.grid, np.linspace(0.0, bp.length, DEFAULT_INTERVALS + 1))


def test_the_budget_bounds_the_refinement():
    bp = blend_path(square_zigzag(), 0.0)                        # 199 pieces
    s = default_grid(bp, DEFAULT_INTERVALS, DEFAULT_INTERVALS + 4 * 199)
    assert len(s) - 1 <= DEFAULT_INTERVALS + 4 * 199
    assert np.all(np.isin(np.r_[bp.s0, bp.length], s))          # every piece boundary a grid point
    assert default_grid(bp, DEFAULT_INTERVALS, DEFAULT_INTERVALS + 100) is None   # not even one per piece


def test_a_zigzag_back_and_forth_along_one_line_is_not_thinned_away():
    """0, 0.5, 0, 0.5 … on one joint: every interior waypoint lies on the chord, and the distance test
    of the thinning dropped them all (1.41 s for 199 moves); reversals are kept."""
    W = np.array([(0.5 * (i % 2), 0.0) for i in range(200)])
    exact = 199 * rest_to_rest(0.5, 10.0, 1.0)
    tr = time_parameterize(W, 10.0, 1.0, blend=0.0)
    assert len(tr.path.waypoints) == 200
    assert exact <= tr.duration <= 1.01 * exact
