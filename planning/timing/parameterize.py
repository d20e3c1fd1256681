"""Time parameterisation of a joint path under joint speed and acceleration limits (and optionally
jerk limits): :func:`time_parameterize`.

A geometric joint path q(s) (s a path parameter, here joint-space arc length) becomes a trajectory
once s(t) is chosen.  With b(s) = ṡ² and a(s) = s̈ (so that b′(s) = 2a):

    q̇  = q′(s)·ṡ                 |q̇_j| ≤ v_j   ⇔   q′_j(s)²·b ≤ v_j²           (a bound on b)
    q̈  = q′(s)·a + q″(s)·b       |q̈_j| ≤ A_j   ⇔   −A_j ≤ q′_j·a + q″_j·b ≤ A_j   (linear in a, b)

and b ≥ 0, b(0) = b(end) = 0 (rest to rest) — all linear in (a, b).  The grid, the constraint points
(both ends of every segment, so the limits hold on the whole continuous trajectory, not only at grid
points) and the rows are built by :mod:`planning.timing.stages`.  Two solvers give the same b:

* ``method="reach"`` (default): TOPP-RA's reachability analysis, a backward pass of two-variable LPs
  and a greedy forward pass, in C compiled on first use, or numpy without a compiler
  (:mod:`planning.timing.reachability`);
* ``method="qp"``: the whole problem as one sparse OSQP QP (:mod:`planning.timing.qp`) — slower, kept
  for comparison.

With ``robot`` and torque limits, torque rows join them (:mod:`planning.timing.torque`: exact at the
constraint points, viscous friction by a conservative tangent, then a dense re-check with the
actual inverse dynamics and re-solves with locally tightened limits).

After the solve, b is scaled by one factor c ≤ 1 (b = 0 meets every row and the feasible set is
convex) so that every constraint holds exactly despite rounding or the solver's tolerance.  The result is re-checked
densely between its samples (``overshoot`` of :class:`TimedTrajectory`, see
:func:`planning.timing.limits.dense_ratios`).  With ``j_max`` the profile is then tightened for jerk
(:mod:`planning.timing.jerk`).

Corners.  The path is made C¹ by blending its corners with quadratic Bézier pieces, or stops at
every corner with ``blend=0``; a dense path is first thinned.  See :mod:`planning.timing.shaping`.

SI units throughout: rad and rad/s, rad/s², rad/s³, N·m for revolute joints, m, m/s, m/s², m/s³, N
for prismatic ones.
"""
from __future__ import annotations

import math
import time

import numpy as np

from planning.timing.grid import MIN_INTERVALS_PER_PIECE, default_grid
from planning.timing.jerk import jerk_limit
from planning.timing.limits import _limits, dense_ratios
from planning.timing.qp import solve_qp
from planning.timing.reachability import BACKENDS, reach
from planning.timing.repair import repair_rests
from planning.timing.shaping import blend_path
from planning.timing.spline import spline_path
from planning.timing.stages import build_stages, sample_profile
from planning.timing.torque import BUDGET, ROUNDS, TOL, dense_torque, path_model, tighten, torque_limits, torque_rows
from planning.timing.trajectory import TimedTrajectory, TimingError

__all__ = ["time_parameterize", "DEFAULT_INTERVALS", "MIN_INTERVALS_PER_PIECE", "MAX_INTERVALS", "QP_MAX_INTERVALS",
           "DEFAULT_BUDGET", "METHODS", "SHAPES",
           "SPLINE_INTERVALS_PER_SPAN"]

#: default grid: this many intervals over the whole path (plus every piece boundary)
DEFAULT_INTERVALS = 300
#: largest default grid of the reachability passes: the uniform grid refined so that every piece of the path
#: has at least :data:`~planning.timing.grid.MIN_INTERVALS_PER_PIECE` intervals (:func:`~planning.timing.grid.
#: default_grid`; fewer per piece when more would not fit, the uniform grid when not even one would)
DEFAULT_BUDGET = 20_000
#: largest grid of the reachability passes (O(K) work and memory)
MAX_INTERVALS = 100_000
#: largest grid of ``method="qp"`` and of the jerk pass (one variable per grid point; OSQP's first-order
#: iterations and the LP take seconds beyond a few thousand)
QP_MAX_INTERVALS = 5000
METHODS = ("reach", "qp")
SHAPES = ("blend", "spline")
#: default grid of ``shape="spline"``: this many intervals per span between two waypoints (at least
#: :data:`DEFAULT_INTERVALS`); the time converges from above as the grid is refined
SPLINE_INTERVALS_PER_SPAN = 20
#: samples per trajectory interval of the dense re-check (fewer on fine grids: at most
#: :data:`DENSE_SAMPLES` in all, at least one inside every interval)
DENSE_PER_INTERVAL = 8
DENSE_SAMPLES = 8000


def time_parameterize(path, v_max, a_max, ds: float | None = None, blend: float = 0.05,
                      simplify: float = 1e-4, method: str = "reach", j_max=None,
                      backend: str = "auto", shape: str = "blend", robot=None, tau_max=None) -> TimedTrajectory:
    """Minimum-time (on the grid), rest-to-rest trajectory along a joint path under per-joint limits.

    Parameters
    ----------
    path : (M, n) joint waypoints (SI): with ``shape="blend"`` joined by straight segments whose
        corners are blended (``blend``); with ``shape="spline"`` by the C¹ spline through every
        waypoint of :func:`planning.timing.spline.spline_path` (``blend`` and ``simplify`` unused).
    v_max, a_max : per-joint speed and acceleration limits, scalars or (n,) arrays, > 0.
    ds : grid step in s (joint-space arc length); None: path length / :data:`DEFAULT_INTERVALS` (blends),
        or :data:`SPLINE_INTERVALS_PER_SPAN` intervals per span between waypoints (spline), with every
        piece (segment, blend, span) holding fewer than :data:`MIN_INTERVALS_PER_PIECE` intervals divided
        into that many, within :data:`DEFAULT_BUDGET` intervals in all (:data:`QP_MAX_INTERVALS` with
        ``j_max`` or ``method="qp"``; :func:`planning.timing.grid.default_grid`).
        The constraints are imposed at the grid points and at every piece boundary (both sides).
    blend : corner blend half-length r (rad or m, joint-space distance); 0: stop at every corner.
    simplify : waypoint thinning tolerance (rad or m; 0: off), see :func:`blend_path`.
    method : ``"reach"`` (TOPP-RA's reachability passes, default) or ``"qp"`` (one OSQP QP).
    j_max : optional per-joint jerk limits (scalar or (n,), > 0; rad/s³ or m/s³): the profile is then
        tightened so that the change of q̈ sampled at the grid points is at most j_max·Δt between
        consecutive ones (see :mod:`planning.timing.jerk` for exactly what is guaranteed).
    backend : for ``method="reach"``: ``"auto"`` (C when a compiler is available), ``"c"`` or ``"numpy"``.
    shape : ``"blend"`` (default: straight segments, corners cut within ``blend``) or ``"spline"``
        (through every waypoint exactly; faster through many closely spaced waypoints).
    robot : a :class:`kin.Robot` with inertial data (SI): the result then carries the joint torques
        ``tau`` at its samples, and torque limits apply (``tau_max``, or the joints' ``max_torque``).
    tau_max : per-joint torque limits (scalar or (n,), > 0; N·m or N), needs ``robot``; None: the
        joints' ``max_torque`` where known (none known: no torque limit).  See
        :mod:`planning.timing.torque` for what is guaranteed between constraint points.

    Returns a :class:`TimedTrajectory` sampled at the grid points and piece boundaries (see the module
    docstring).  Raises :class:`TimingError` for bad input or when the solver fails.
    """
    if method not in METHODS:
        raise TimingError(f"method = {method!r} unknown; allowed: {', '.join(METHODS)}")
    if backend not in BACKENDS:
        raise TimingError(f"backend = {backend!r} unknown; allowed: {', '.join(BACKENDS)}")
    if shape not in SHAPES:
        raise TimingError(f"shape = {shape!r} unknown; allowed: {', '.join(SHAPES)}")
    if shape == "spline":
        bp, _ = spline_path(path)
    else:
        bp = blend_path(path, blend, simplify)
    n = bp.n
    vmax = _limits(v_max, n, "v_max")
    amax = _limits(a_max, n, "a_max")
    jmax = None if j_max is None else _limits(j_max, n, "j_max")
    if robot is None and tau_max is not None:
        raise TimingError("tau_max needs robot= (a kin.Robot with inertial data)")
    tmax = None if robot is None else torque_limits(robot, tau_max, n)
    if bp.length == 0.0:
        z = np.zeros((1, n))
        tr = TimedTrajectory(np.zeros(1), bp.waypoints[:1].copy(), z, z.copy(), np.zeros(1), np.zeros(1),
                             np.zeros(1), 0.0, 0.0, 0.0, bp, vmax, amax, "trivial (zero-length path)", method=method)
        if robot is not None:
            tr.tau = np.atleast_2d(robot.inverse_dynamics(tr.q, z, z))
            if tmax is not None:
                tr.tau_max, tr.max_torque_ratio = tmax, float(np.max(np.abs(tr.tau) / tmax[None, :]))
        return tr
    if ds is None:
        K = DEFAULT_INTERVALS if shape == "blend" else max(DEFAULT_INTERVALS, SPLINE_INTERVALS_PER_SPAN
                                                               * (len(bp.waypoints) - 1))
        if jmax is not None or method == "qp":
            K = min(K, QP_MAX_INTERVALS)
        grid = default_grid(bp, K, DEFAULT_BUDGET if method == "reach" and jmax is None else QP_MAX_INTERVALS)
    else:
        if not (isinstance(ds, (int, float, np.floating, np.integer)) and math.isfinite(ds) and ds > 0):
            raise TimingError(f"ds = {ds!r} must be a positive finite grid step (rad or m of path length)")
        K = max(1, int(math.ceil(bp.length / ds - 1e-9)))
        grid = None
        most = MAX_INTERVALS if method == "reach" and jmax is None else QP_MAX_INTERVALS
        if K > most:
            raise TimingError(f"ds = {ds:g} gives {K} grid intervals; at most {most} with method={method!r}"
                              f"{' and j_max' if jmax is not None else ''} (choose a larger ds)")
    st = build_stages(bp, K, vmax, amax, full_mvc=(method == "qp"), grid=grid)
    if robot is None:
        return _finish(_solve(st, method, backend, jmax, bp), st, bp, vmax, amax, jmax, method)
    tm = None if tmax is None else path_model(robot, st, bp, tmax)
    if tm is None:
        tr = _finish(_solve(st, method, backend, jmax, bp), st, bp, vmax, amax, jmax, method)
        _, _, tr.tau = dense_torque(robot, tr, st.samples(bp.length)[2])
        return tr
    ki = st.samples(bp.length)[2]
    w = np.ones((st.K, n))
    b_ref = None
    if tm.viscous:              # a first estimate of ṡ for the viscous tangent (not conservative itself)
        b_ref = _solve(torque_rows(st, tm, w, None), method, backend, None, bp, torque=True)[0]
    deadline = time.monotonic() + BUDGET
    rounds = 0
    while True:
        sol = _solve(torque_rows(st, tm, w, b_ref), method, backend, jmax, bp, torque=True)
        tr = _finish(sol, st, bp, vmax, amax, jmax, method)
        tau_d, where, tr.tau = dense_torque(robot, tr, ki)
        ratio = float(np.max(np.abs(tau_d) / tmax[None, :]))
        if ratio <= 1.0 + TOL or rounds >= ROUNDS or time.monotonic() > deadline:
            break
        if not tighten(w, tau_d, where, tm, st):
            break
        rounds += 1
        b_ref = sol[0] if tm.viscous else None
    tr.tau_max, tr.max_torque_ratio, tr.torque_rounds = tmax, ratio, rounds
    tr.qp_status += f", torque-limited ({rounds} tightening round{'' if rounds == 1 else 's'})"
    return tr


def _solve(st, method: str, backend: str, jmax, bp, torque: bool = False):
    """b (K+1,) of the rows of ``st`` (scaled to meet them exactly), the scale, the solver's status and
    the jerk ratio (None without ``jmax``)."""
    if method == "qp":
        b, status = solve_qp(st)
    else:
        _, b, used = reach(st, backend)
        status = f"reachability ({used})"
        if torque:
            # the greedy pass can come to rest where nothing requires it under torque rows
            b, fixed = repair_rests(st, b * st.residual_scale(b))
            if fixed:
                status += f", {fixed} rest{'' if fixed == 1 else 's'} mid-path repaired"
    # one common scale c ≤ 1 makes every row hold exactly (b = 0 meets every row; the set is convex)
    c = st.residual_scale(b)
    b = b * c
    jr = None
    if jmax is not None:
        b, jr, jused = jerk_limit(st, b, bp, jmax, backend)
        status += f", jerk-limited ({jused})"
    return b, c, status, jr


def _finish(sol, st, bp, vmax, amax, jmax, method: str) -> TimedTrajectory:
    """The :class:`TimedTrajectory` of a solution of :func:`_solve`, with its dense speed and
    acceleration re-check."""
    b, c, status, jr = sol
    t, q, qd, qdd, ks, sd, sdd = sample_profile(st, b, bp)
    vr = float(np.max(np.abs(qd) / vmax[None, :]))
    ar = float(np.max(np.abs(qdd) / amax[None, :]))
    tr = TimedTrajectory(t=t, q=q, qd=qd, qdd=qdd, s=ks, sd=sd, sdd=sdd, duration=float(t[-1]),
                         max_velocity_ratio=vr, max_acceleration_ratio=ar, path=bp, v_max=vmax, a_max=amax,
                         qp_status=status, scale=c, grid=st.s, method=method, j_max=jmax, max_jerk_ratio=jr)
    dv, da = dense_ratios(tr, vmax, amax, max(2, min(DENSE_PER_INTERVAL, DENSE_SAMPLES // max(len(t) - 1, 1))))
    tr.overshoot = max(dv - 1.0, da - 1.0, 0.0)
    return tr
