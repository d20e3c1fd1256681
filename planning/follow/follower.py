"""Singularity-robust path following: one OSQP quadratic program per step.

A tool path is a sequence of target poses T*_k (N, 4, 4) at times t_k.  From a start configuration
q_0 the follower chooses, at every step k → k+1 (Δt = t_{k+1} − t_k), a joint velocity q̇ (n,) held
over the step (q_{k+1} = q_k + q̇·Δt) by solving

    minimise    ‖S·(J·q̇ − ẋ_ref)‖² + q̇ᵀ·Λ·q̇
    subject to  max(lo − q_k, −v_max·Δt) ≤ q̇·Δt ≤ min(hi − q_k, v_max·Δt)       joint + speed limits
                ∇d_w(q_k)·q̇·Δt ≥ −γ·(d_w(q_k) − m_w)                for every window w (barrier)

* J (6, n) is the geometric Jacobian at q_k (rows vx vy vz ωx ωy ωz, base frame, tool point).
* ẋ_ref = ẋ_des + K·e_k/Δt: the feed-forward twist of the path, ẋ_des = [p*_{k+1} − p*_k;
  log(R*_{k+1}·R*_kᵀ)]/Δt, plus a feedback term on the tracking error e_k = [p*_k − p(q_k);
  log(R*_k·R(q_k)ᵀ)] (K = ``feedback``, the fraction of the error removed per step), so that errors do
  not drift as they would with the feed-forward term alone.
* S (m, 6) selects and weights the task (``mode``):
  ``"pose"``      S = diag(w_p·I₃, w_o·I₃): position and full orientation (6 DOF);
  ``"axis"``      position and the direction of the tool z axis (5 DOF): the orientation rows are
                  E·Rᵀ with E = the first two rows of I₃ — rotation about the tool's own z axis (a
                  pen's or a spindle's axis) is free, and the orientation error is the angle between
                  the tool z axis and its target;
  ``"position"``  S = w_p·I₃: the tool point only (3 DOF).
  ``weights = (w_p, w_o)`` put metres and radians on one scale (w_o is a length, m/rad).
* Λ is singular-value-filtered damping (Maciejewski–Klein / Chiaverini): with the SVD S·J = U·Σ·Vᵀ,
  Λ = λ_min·I + Σ_i λ_i·v_i·v_iᵀ with λ_i = λ_max·(1 − (σ_i/σ₀)²) for σ_i < σ₀ (and for the
  directions J cannot move at all), 0 otherwise.  Well-conditioned directions are tracked without
  lag; a direction whose singular value goes to zero gets a bounded gain σ/(σ² + λ) ≤ 1/(2√λ)
  instead of 1/σ — the joint speeds stay finite at and near a singularity.  ``damping`` = λ_max
  (m²/rad² with the default weights), ``singular_value_threshold`` = σ₀.
* The windows of :mod:`planning.windows` are kept with a discrete barrier on each window's signed
  margin d_w (> 0 outside; joint distance for an interval window, |g| − ε for a predicate window,
  linearised as sign(g)·∇g): d_w(q_{k+1}) − m_w ≥ (1 − γ)·(d_w(q_k) − m_w), γ = Δt/τ
  (``barrier_time`` = τ).  Outside a window this only bites when the configuration approaches it
  (it may approach at most at the rate (d − m)/τ and stops a buffer m_w short of the boundary);
  inside a window the same inequality asks the follower to climb out at that rate.
  m_w = ``window_buffer`` × the window's half-width (interval) or × ε (predicate).

Entering a window only when the path forces it.  Two tests decide when a barrier is dropped:

* inside a window (or its buffer), a probe QP over a joint displacement Δ (same P, same sparsity:
  minimise ‖S·(J·Δ − e_next)‖² + ΔᵀΛΔ within the joint limits, with d_w + ∇d_w·Δ ≥ m_w) asks
  whether some configuration outside the window still meets the next target within ``window_slack``
  × ``tolerance`` (linearised).  If not, the path forces the window and its barrier is dropped for
  this step — the follower does not push out, in vain, step after step; if so, the barrier pushes
  the configuration out;
* the step's QP is then solved with the remaining barriers (stage 1).  It is accepted when it is
  solved and its predicted tracking error after the step, e_k + ẋ_des·Δt − J·q̇·Δt, stays within
  ``window_slack`` × ``tolerance``, or when no barrier is active.  Otherwise keeping out of a window
  would cost more tracking than that, and the step is solved again without the active barriers
  (stage 2): the path forces the follower into the window.

Steps where a barrier was dropped are marked in ``FollowResult.forced``.

Everything is set up once: the sparsity of P (upper triangle, dense n×n) and of A (identity rows for
the joints, one row per window with its joints' entries) is fixed, and every step only ``update``s
P, q, A, l and u of the same OSQP object (warm started).  Polishing is off (OSQP prints a line on
stdout when there is nothing to polish); the solver runs to tight tolerances (1e-9) on joint
velocities (rad/s or m/s), and the solution is projected onto the joint box so that joint and speed
limits hold exactly.

Default joint-speed limit when the robot file gives none (``Joint.max_velocity`` is None):
:data:`DEFAULT_V_MAX_REVOLUTE` = π rad/s (180°/s, the speed of a UR arm's base joints) and
:data:`DEFAULT_V_MAX_PRISMATIC` = 0.5 m/s.

This module holds :func:`follow_path`; its pieces live in their own modules of
:mod:`planning.follow`, the place to import from: :class:`FollowResult` and :func:`window_ranges`
(:mod:`planning.follow.result`); :class:`FollowError`, the speed-limit defaults,
:func:`joint_velocity_limits` and the checks of path and start (:mod:`planning.follow.inputs`); the
window margins d_w (:mod:`planning.follow.barriers`); :func:`tracking_errors`
(:mod:`planning.follow.tracking`).

:func:`resolved_rate` (:mod:`planning.follow.resolved_rate`) is the naive method the
follower is compared with: open-loop resolved-rate control q_{k+1} = q_k + J⁻¹·ẋ_des·Δt, with
``np.linalg.solve`` — and, where ``solve`` raises because J is exactly singular, the pseudo-inverse
(``np.linalg.pinv``), recorded per step together with the condition number of J.
"""
from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence

import numpy as np
import osqp
import scipy.sparse as sps

from planning.follow.barriers import _Barrier
from planning.follow.inputs import (
    MODES,
    FollowError,
    _check_mode,
    _check_start,
    _path_arrays,
    joint_velocity_limits,
)
from planning.follow.result import FollowResult
from planning.follow.tracking import (
    _any_perpendicular,
    _log_rot,
    _task_error_norms,
    tracking_errors,
)
from planning.windows import Window, WindowSet

__all__ = ["follow_path", "MODES"]

LAMBDA_MIN = 1e-9                    # always-on regularisation: P stays positive definite
OSQP_SETTINGS = dict(verbose=False, eps_abs=1e-9, eps_rel=1e-9, eps_prim_inf=1e-7, eps_dual_inf=1e-7,
                     max_iter=20000, polishing=False, warm_starting=True, adaptive_rho=True)
_OK = ("solved", "solved inaccurate")


# ---- the follower ----------------------------------------------------------------------------------
def follow_path(robot, path, q0, windows: WindowSet | Sequence[Window] | None = None, *, mode: str = "pose",
                weights: tuple[float, float] = (1.0, 0.1), damping: float = 1e-3,
                singular_value_threshold: float = 0.02, feedback: float = 0.5, dt: float | None = None,
                v_max=None, tolerance: tuple[float, float] = (1e-3, math.radians(1.0)),
                window_slack: float = 0.1, barrier_time: float = 0.2, window_buffer: float = 0.05
                ) -> FollowResult:
    """Follow a tool path with one OSQP QP per step (see the module docstring for the formulation).

    Parameters
    ----------
    robot : kin.Robot
    path : (N, 4, 4) target poses (base frame, SI), optionally with times: a ``(poses, times)`` pair or
        an object with ``poses`` and ``times`` attributes (a ToolPath).  In position mode positions
        (N, 3) are accepted too.
    q0 : (n,) start configuration, inside the joint limits.  The path is followed from wherever
        fk(q0) is: the initial error is removed by the feedback term.
    windows : a :class:`~planning.windows.WindowSet` (or list of windows) to keep out of; None: none.
    mode : ``"pose"`` (6 DOF), ``"axis"`` (position + tool z axis, 5 DOF) or ``"position"`` (3 DOF).
    weights : (w_p, w_o) task weights: 1/m and m/rad·(1/m) — w_o is the length that equates 1 rad to
        w_o metres of position error.
    damping : λ_max of the singular-value-filtered damping (same units as ‖S·J‖²).
    singular_value_threshold : σ₀ below which a singular direction of S·J is damped.
    feedback : K in (0, 1], the fraction of the tracking error corrected per step.
    dt : step (s) when the path has no times.
    v_max : joint speed limits (None: the robot file's, else the documented defaults).
    tolerance : (position m, orientation rad) — used to accept window-respecting steps (× window_slack)
        and for :attr:`FollowResult.within_tolerance`.
    window_slack : fraction of the tolerance a window-respecting step may cost before the window is
        treated as forced by the path.
    barrier_time : τ (s) of the discrete window barrier.
    window_buffer : buffer m_w as a fraction of each window's half-width (or of ε).
    """
    _check_mode(mode)
    poses, t = _path_arrays(path, dt, mode)
    q = _check_start(robot, q0)
    n = robot.n
    wp, wo = (float(x) for x in weights)
    checks = {"weights[0] (position)": (wp, wp > 0), "weights[1] (orientation)": (wo, wo >= 0),
              "damping": (damping, damping >= 0), "singular_value_threshold": (singular_value_threshold,
                                                                                singular_value_threshold > 0),
              "feedback": (feedback, 0 < feedback <= 1), "window_slack": (window_slack, window_slack > 0),
              "barrier_time": (barrier_time, barrier_time > 0), "window_buffer": (window_buffer, window_buffer >= 0),
              "tolerance[0] (m)": (tolerance[0], tolerance[0] > 0), "tolerance[1] (rad)": (tolerance[1],
                                                                                         tolerance[1] > 0)}
    for name, (value, ok) in checks.items():
        if not (math.isfinite(float(value)) and ok):
            raise FollowError(f"{name} = {value!r} is out of range (weights > 0 / ≥ 0, damping ≥ 0, threshold > 0, "
                              "0 < feedback ≤ 1, window_slack > 0, barrier_time > 0, window_buffer ≥ 0, "
                              "tolerances > 0)")
    vmax = joint_velocity_limits(robot, v_max)
    lo, hi = robot.chain.lower, robot.chain.upper
    if isinstance(windows, WindowSet):
        windows.check_robot(robot)
    wlist = list(windows.windows if isinstance(windows, WindowSet) else (windows or []))
    for w in wlist:
        if w.n != n:
            raise FollowError(f"window {w.name!r} is for a {w.n}-joint robot; {robot.name} has {n} joints")
    barriers = [_Barrier(w, n, window_buffer) for w in wlist]
    nw = len(barriers)

    # ---- fixed sparsity: P dense upper triangle, A = [I_n; one row per window over its joints]
    iu = np.triu_indices(n)
    order = np.lexsort((iu[0], iu[1]))                 # CSC order: by column, then row
    p_rows, p_cols = iu[0][order], iu[1][order]
    P0 = sps.csc_matrix((np.ones(len(p_rows)), (p_rows, p_cols)), shape=(n, n))
    a_r = list(range(n))
    a_c = list(range(n))
    for i, b in enumerate(barriers):
        for j in b.joints:
            a_r.append(n + i)
            a_c.append(j)
    a_r, a_c = np.array(a_r), np.array(a_c)
    A0 = sps.csc_matrix((np.ones(len(a_r)), (a_r, a_c)), shape=(n + nw, n))
    A0.sort_indices()
    # positions of our entries in the CSC data array (csc sorts by column, then row)
    a_order = np.lexsort((a_r, a_c))
    a_rows_csc, a_cols_csc = a_r[a_order], a_c[a_order]
    Adense = np.zeros((n + nw, n))
    Adense[np.arange(n), np.arange(n)] = 1.0
    solver = osqp.OSQP()
    solver.setup(P0, np.zeros(n), A0, -np.ones(n + nw), np.ones(n + nw), **OSQP_SETTINGS)

    N = len(poses)
    Q = np.empty((N, n))
    Q[0] = q
    forced = np.zeros(N, bool)
    status: Counter = Counter()
    tol_p, tol_o = float(tolerance[0]) * window_slack, float(tolerance[1]) * window_slack
    gamma_scale = 1.0 / barrier_time
    E = np.eye(3)[:2]

    for k in range(N - 1):
        h = t[k + 1] - t[k]
        T, J = robot.fk_jacobian(q)
        R = T[:3, :3]
        # feed-forward twist and tracking error (base frame)
        ff = np.empty(6)
        ff[:3] = (poses[k + 1, :3, 3] - poses[k, :3, 3]) / h
        ff[3:] = _log_rot(poses[k + 1, :3, :3], poses[k, :3, :3]) / h
        e = np.empty(6)
        e[:3] = poses[k, :3, 3] - T[:3, 3]
        if mode == "axis":
            z, zt = R[:, 2], poses[k, :3, 2]
            ax = np.cross(z, zt)
            s = np.linalg.norm(ax)
            ang = math.atan2(s, float(np.clip(z @ zt, -1.0, 1.0)))
            e[3:] = ax * (ang / s) if s > 1e-15 else (np.zeros(3) if ang < 1.0 else _any_perpendicular(z) * ang)
        else:
            e[3:] = _log_rot(poses[k, :3, :3], R)
        if mode == "pose":
            S = np.zeros((6, 6))
            S[:3, :3] = wp * np.eye(3)
            S[3:, 3:] = wo * np.eye(3)
        elif mode == "axis":
            S = np.zeros((5, 6))
            S[:3, :3] = wp * np.eye(3)
            S[3:, 3:] = wo * (E @ R.T)
        else:
            S = np.zeros((3, 6))
            S[:, :3] = wp * np.eye(3)
        xref = ff + feedback * e / h
        SJ = S @ J
        # singular-value-filtered damping over all n right singular directions
        _, sig, Vt = np.linalg.svd(SJ, full_matrices=True)
        sig_full = np.zeros(n)
        sig_full[:min(len(sig), n)] = sig[:n]
        lam = np.where(sig_full < singular_value_threshold,
                       damping * (1.0 - (sig_full / singular_value_threshold) ** 2), 0.0)
        Pm = SJ.T @ SJ + (Vt.T * lam) @ Vt + LAMBDA_MIN * np.eye(n)
        qlin = -(SJ.T @ (S @ xref))
        # joint box (velocity units)
        lb = np.maximum((lo - q) / h, -vmax)
        ub = np.minimum((hi - q) / h, vmax)
        lb = np.minimum(lb, 0.0)   # q inside its limits: 0 is always feasible
        ub = np.maximum(ub, 0.0)
        low = np.empty(n + nw)
        u = np.full(n + nw, np.inf)
        low[:n], u[:n] = lb, ub
        dval = np.full(nw, np.inf)
        for i, b in enumerate(barriers):
            d, g = b(q)
            Adense[n + i, b.joints] = g
            dval[i] = d
            if not math.isfinite(d):
                low[n + i] = -np.inf
                continue
            need = -gamma_scale * (d - b.m)
            # never ask for more outward speed than the joint box allows (keeps stage 1 feasible)
            reach = float(np.sum(np.maximum(g * ub[b.joints], g * lb[b.joints])))
            low[n + i] = min(need, 0.5 * reach) if need > 0 else need
        solver.update(Px=Pm[p_rows, p_cols], Ax=Adense[a_rows_csc, a_cols_csc])
        # inside a window (or its buffer): is there a configuration outside it that still meets the
        # next target within the slack?  (one QP over a joint displacement Δ within the joint limits,
        # linearised: minimise ‖S·(J·Δ − e_next)‖² + ΔᵀΛΔ with d_w + ∇d_w·Δ ≥ m_w.)  If not, the path
        # forces the window: its barrier is dropped instead of pushing out at every step in vain.
        probe_forced = np.zeros(nw, bool)
        e_next = e + ff * h
        for i in np.flatnonzero(dval - np.array([b.m for b in barriers]) < 0):
            lp = np.full(n + nw, -np.inf)
            up_ = np.full(n + nw, np.inf)
            lp[:n], up_[:n] = np.minimum(lo - q, 0.0), np.maximum(hi - q, 0.0)
            lp[n + i] = barriers[i].m - dval[i]
            solver.update(q=-(SJ.T @ (S @ e_next)), l=lp, u=up_)
            res = solver.solve(raise_error=False)
            if res.info.status in _OK:
                rp, ro = _task_error_norms(e_next - J @ res.x, R, mode)
                probe_forced[i] = rp > tol_p or ro > tol_o
            else:
                probe_forced[i] = True
        low[n:][probe_forced] = -np.inf
        solver.update(q=qlin, l=low, u=u)
        res = solver.solve(raise_error=False)
        st = res.info.status
        qd = None
        if st in _OK:
            qd = np.clip(res.x, lb, ub)
            if nw:
                r = e + (ff - J @ qd) * h
                rp, ro = _task_error_norms(r, R, mode)
                if rp > tol_p or ro > tol_o:
                    # which barriers bind?  If none, the windows are not what limits the tracking
                    lw = np.where(np.isfinite(low[n:]), low[n:], 0.0)      # dropped barriers: low = −∞
                    act = Adense[n:] @ res.x <= lw + 1e-7 * np.maximum(1.0, np.abs(lw))
                    act |= np.abs(res.y[n:]) > 1e-9
                    act &= np.isfinite(low[n:])
                    if act.any():
                        qd = None
            if qd is not None:
                status[st] += 1
        else:
            act = np.ones(nw, bool)
        forced[k + 1] = bool(probe_forced.any())
        if qd is None and nw:
            # stage 2: the path forces the follower into the windows whose barriers bound stage 1
            l2 = low.copy()
            l2[n:][act] = -np.inf
            solver.update(l=l2)
            res = solver.solve(raise_error=False)
            st = res.info.status
            forced[k + 1] = True
            if st in _OK:
                qd = np.clip(res.x, lb, ub)
                status[st] += 1
        if qd is None:
            # solver failure: damped least squares, projected onto the joint box
            qd = np.clip(np.linalg.solve(Pm, -qlin), lb, ub)
            status[f"fallback ({st})"] += 1
        q = q + qd * h
        q = np.clip(q, lo, hi)   # rounding only: qd·h ≤ hi − q by construction
        Q[k + 1] = q

    pe, oe, ae = tracking_errors(robot, Q, poses)
    vel = np.zeros_like(Q)
    vel[1:] = np.diff(Q, axis=0) / np.diff(t)[:, None]
    ws = WindowSet(robot=robot.name, n=n, windows=wlist)
    in_w = ws.which(Q) if wlist else np.full(N, -1)
    return FollowResult(mode=mode, t=t, q=Q, position_error=pe, orientation_error=oe, axis_error=ae,
                        joint_velocity=vel, joint_speed=np.abs(vel), in_window=in_w, forced=forced,
                        sigma_min=np.asarray(robot.sigma_min(Q), dtype=float), v_max=vmax,
                        tolerance=(float(tolerance[0]), float(tolerance[1])), qp_status=dict(status),
                        window_names=[w.name for w in wlist])
