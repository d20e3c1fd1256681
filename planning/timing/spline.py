"""A smooth path through every waypoint for :func:`planning.timing.time_parameterize` (``shape="spline"``):
:func:`spline_path`.

The blends of :mod:`planning.timing.shaping` keep the straight segments between waypoints and cut each
corner within ``blend``; through many closely spaced waypoints (a sampled smooth motion, a taught
path) that concentrates all the turning in short blends, and the trajectory slows down at every one.
A spline spreads the turning over the whole span between two waypoints instead.

The shape.  The waypoints W_0 … W_{M−1} get parameter values s_i (uniform: equal steps, the mean
joint-space distance between waypoints; or ``"chord"``: the cumulative joint-space distance) and the
cubic spline with not-a-knot ends through them (``scipy.interpolate.CubicSpline``; the shape TOPP-RA's
documentation times, ``toppra.SplineInterpolator``) is the intended curve.  The path actually timed is
the C¹ piecewise-quadratic spline that interpolates that cubic at ``sub`` equally spaced points of
every span (``scipy.interpolate.make_interp_spline`` with k = 2), written as the quadratic Bézier
pieces of :class:`~planning.timing.trajectory.BlendedPath` — the form whose speed and acceleration
limits :mod:`planning.timing.stages` enforces on the whole continuous trajectory.  The waypoints are
among the interpolation points, so the path passes through every one exactly
(``max_deviation`` = 0); it differs from the cubic between them by :attr:`SplineShape.cubic_deviation`
(reported, of order h⁴ of the span).

Between waypoints the path leaves the straight segments (by ``segment_deviation``) and may leave the
joint limits: :func:`spline_path` returns the exact range of every joint along the path
(:meth:`BlendedPath.joint_range`), and a caller with a robot checks it (and, for a path that was
certified segment by segment, checks the shaped path again against windows and collisions).

SI units throughout: rad for revolute joints, m for prismatic ones.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline, make_interp_spline

from planning.timing.trajectory import BlendedPath, TimingError

__all__ = ["spline_path", "SplineShape", "PARAMETERS", "DEFAULT_SUB"]

PARAMETERS = ("uniform", "chord")
#: quadratic pieces per span between two waypoints
DEFAULT_SUB = 2
#: samples per quadratic piece of the deviation checks
_CHECK = 8


@dataclass(frozen=True)
class SplineShape:
    """What :func:`spline_path` built besides the path: the parameter values of the waypoints ``s``
    (M,), the largest joint-space distance between the timed path and the cubic through the
    waypoints (``cubic_deviation``) and between the path and the straight segments joining the
    waypoints (``segment_deviation``), estimated on :data:`_CHECK` samples per piece."""

    s: np.ndarray
    cubic_deviation: float
    segment_deviation: float


def _pieces(spl, s_end: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bézier control points (m, 3, n), start and length of every polynomial piece of a quadratic
    B-spline ``spl`` over the breakpoints ``s_end``."""
    x0, ell = s_end[:-1], np.diff(s_end)
    P0 = spl(x0)
    P1 = P0 + 0.5 * ell[:, None] * spl(x0, 1)
    P2 = spl(s_end[1:])
    return np.stack([P0, P1, P2], axis=1), x0, ell


def spline_path(path, parameter: str = "uniform", sub: int = DEFAULT_SUB) -> tuple[BlendedPath, SplineShape]:
    """The C¹ piecewise-quadratic spline through every waypoint of ``path`` (M, n) (module docstring)
    and its :class:`SplineShape`.  ``parameter``: ``"uniform"`` (TOPP-RA's documented use) or
    ``"chord"``; ``sub``: quadratic pieces per span, 1 … 16.  Consecutive duplicate waypoints are
    dropped; one waypoint gives a zero-length path, two a straight line."""
    W = np.asarray(path, dtype=float)
    if W.ndim != 2 or len(W) < 1 or W.shape[1] < 1:
        raise TimingError(f"path has shape {W.shape}; expected (M, n) joint waypoints with M ≥ 1")
    if not np.all(np.isfinite(W)):
        raise TimingError("path holds NaN or infinite values")
    if parameter not in PARAMETERS:
        raise TimingError(f"parameter = {parameter!r} unknown; allowed: {', '.join(PARAMETERS)}")
    if isinstance(sub, bool) or not isinstance(sub, (int, np.integer)) or not 1 <= sub <= 16:
        raise TimingError(f"sub = {sub!r} must be an integer 1 … 16 (quadratic pieces per span)")
    W = W[np.r_[True, np.linalg.norm(np.diff(W, axis=0), axis=1) > 1e-12]]
    M, n = W.shape
    if M == 1:
        return (BlendedPath(np.zeros((0, 3, n)), np.zeros(0), np.zeros(0), np.zeros(0), 0.0, W),
                SplineShape(np.zeros(1), 0.0, 0.0))
    d = np.linalg.norm(np.diff(W, axis=0), axis=1)
    s = np.r_[0.0, np.cumsum(d)] if parameter == "chord" else np.arange(M) * float(d.mean())
    if M == 2:
        ctrl = np.stack([W[0], 0.5 * (W[0] + W[1]), W[1]])[None]
        return (BlendedPath(ctrl, np.zeros(1), np.array([s[-1]]), np.zeros(0), 0.0, W),
                SplineShape(s, 0.0, 0.0))
    cubic = CubicSpline(s, W, bc_type="not-a-knot")
    u = (s[:-1, None] + np.diff(s)[:, None] * (np.arange(sub) / sub)[None, :]).ravel()
    u = np.r_[u, s[-1]]
    quad = make_interp_spline(u, cubic(u), k=2)
    knots = np.unique(quad.t)
    ctrl, s0, ell = _pieces(quad, knots)
    ctrl[0, 0], ctrl[-1, 2] = W[0], W[-1]                      # exact ends despite rounding
    bp = BlendedPath(ctrl, s0, ell, np.zeros(0), 0.0, W)
    # deviations, on samples of every piece
    frac = (np.arange(_CHECK) + 0.5) / _CHECK
    ss = (s0[:, None] + ell[:, None] * frac[None, :]).ravel()
    q = bp.evaluate(ss)[0]
    cub = float(np.max(np.linalg.norm(q - cubic(ss), axis=1)))
    span = np.clip(np.searchsorted(s, ss, side="right") - 1, 0, M - 2)
    t = np.clip((ss - s[span]) / np.diff(s)[span], 0.0, 1.0)[:, None]
    seg = float(np.max(np.linalg.norm(q - ((1 - t) * W[span] + t * W[span + 1]), axis=1)))
    return bp, SplineShape(s, cub, seg)
