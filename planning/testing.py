"""Assertions for users' own test suites, like :mod:`numpy.testing`: a planned or taught joint path,
or a Cartesian tool path, is safe for a robot — or the test fails with a message naming the first
violation.

    from planning.testing import assert_path_valid

    def test_pick_move_is_safe():
        robot = kin.load_robot("fanuc_m16ib20")
        windows = build_windows(robot, margin=0.05)
        assert_path_valid(robot, np.loadtxt("pick_move.csv", delimiter=","), windows=windows,
                          sigma_floor=0.02)

A joint path (M, n) is in SI units (rad, m), the rows joined by straight segments.  The message of
the :class:`AssertionError` gives the row (or the segment and how far along it), the joint values in
the robot file's units, the kind of violation, how deep it goes, and for a window its expression.

What is checked, and how:

* joint limits: exactly (the joints are linear along a segment: the rows decide);
* singular windows: proven for every segment (:func:`planning.certify.certify_path`); a segment
  the proof cannot settle is checked densely as well, and the assertion says which was used;
* a σ_min floor: proven along every segment (:func:`planning.certify.certify_sigma`), sampled where
  the bound cannot settle a segment;
* keep-out boxes: densely, at ``step`` (default 0.1° / 0.1 mm between states);
* collisions with a work cell and self-collisions (``world``, a
  :class:`planning.collision.CollisionWorld`): proven for every segment
  (:func:`planning.certify.collision.certify_collision`), the message naming the link, the obstacle
  (or other link) and how deep; a segment the proof cannot settle is checked densely.
"""
from __future__ import annotations

import math

import numpy as np

from kin.errors import ConfigurationError
from kin.validation import is_real
from planning.certify import certify_path, certify_sigma
from planning.certify.collision import certify_collision
from planning.ompl.validity import JointSpaceChecker
from planning.toolpath.check import validate_toolpath
from planning.validate import DEFAULT_STEP_ANGLE, DEFAULT_STEP_LENGTH, check_path, densify

__all__ = ["assert_path_valid", "assert_toolpath_valid"]


def _q_text(chain, q) -> str:
    vals = chain.from_si(np.asarray(q, dtype=float))
    units = ", ".join(sorted({chain.angle_unit if j.is_revolute else chain.length_unit for j in chain.joints}))
    return "[" + ", ".join(f"{v:.6g}" for v in vals) + f"] ({units})"


def _where(segment: int, t: float, last: int) -> str:
    if t == 0.0:
        return f"row {segment}"
    if t == 1.0 and segment + 1 == last:
        return f"row {segment + 1}"
    return f"segment {segment} → {segment + 1} at {t:.4f} of its length"


def assert_path_valid(robot, path, windows=None, sigma_floor: float | None = None, keep_out=(),
                      step: float | None = None, limit_tol: float = 1e-9, world=None) -> None:
    """Raise :class:`AssertionError` naming the first violation of the joint path ``path`` (M, n),
    SI, for ``robot``: joint limits, the singular ``windows`` (a WindowSet; proven segment by
    segment), a ``sigma_floor`` on σ_min, ``keep_out`` boxes (:class:`planning.ompl.KeepOutBox`;
    the tool point, and every joint-frame origin for a box with ``all_frames``).  ``step``: the joint
    step of the dense checks (rad for revolute joints; prismatic joints use ``step`` × 1 m/rad …
    default 0.1° and 0.1 mm); ``world``: a :class:`planning.collision.CollisionWorld` (the robot in
    its work cell) whose obstacles and self-collisions the path must be proven clear of."""
    chain = robot.chain
    P = np.asarray(path, dtype=float)
    if P.ndim != 2 or P.shape[1] != chain.n or len(P) == 0:
        raise AssertionError(f"path has shape {P.shape}; expected (M, {chain.n}) joint rows for {chain.name}")
    bad = ~np.isfinite(P).all(axis=1)
    if bad.any():
        raise AssertionError(f"path row {int(np.argmax(bad))} holds NaN or infinite values")
    step_angle = DEFAULT_STEP_ANGLE if step is None else float(step)
    step_length = DEFAULT_STEP_LENGTH if step is None else float(step) * DEFAULT_STEP_LENGTH / DEFAULT_STEP_ANGLE
    if not (step_angle > 0 and math.isfinite(step_angle)):
        raise ConfigurationError(f"step = {step!r} must be a positive finite number (rad)")
    if sigma_floor is not None and not (is_real(sigma_floor) and math.isfinite(sigma_floor) and sigma_floor >= 0):
        raise ConfigurationError(f"sigma_floor = {sigma_floor!r} must be a finite number ≥ 0 (SI) or None")
    if windows is not None:
        windows.check_robot(robot)
    found = []      # (segment, t, message)
    # limits: linear joints along a segment, so the rows decide
    over = np.maximum(chain.lower - limit_tol - P, P - chain.upper - limit_tol)
    if (over > 0).any():
        i = int(np.argmax((over > 0).any(axis=1)))
        j = int(np.argmax(over[i]))
        s = chain.variable_scale[j]
        found.append((i, 0.0, f"row {i}, q = {_q_text(chain, P[i])}: joint {j + 1} is outside its limits "
                               f"[{chain.lower[j] / s:.6g}, {chain.upper[j] / s:.6g}] by {over[i, j] / s:.3g}"))
    if windows is not None and windows.windows:
        proof = certify_path(windows, P)
        if proof.violation is not None:
            v = proof.violation
            w = next(w for w in windows.windows if w.name == v.window)
            # how deep the segment goes: the entry point found is on the window's edge
            ts = np.linspace(0.0, 1.0, 2001)
            S = P[v.segment] + ts[:, None] * (P[min(v.segment + 1, len(P) - 1)] - P[v.segment])
            depth = float(np.max(-w.distance_out(S)))
            if w.is_interval:
                s = chain.variable_scale[w.joint]
                what = (f"enters the {w.kind} window on joint {w.joints[0]} ({w.expr} = 0): "
                        + ", ".join(f"[{a / s:.6g}, {b / s:.6g}]" for a, b in w.intervals)
                        + f" {chain.angle_unit if chain.joints[w.joint].is_revolute else chain.length_unit}"
                        + f"; up to {depth / s:.3g} deep along this segment")
            else:
                what = (f"enters the {w.kind} window |g| ≤ {w.epsilon:.6g} with g = {w.expr}; "
                        f"up to {depth:.3g} deep in g along this segment")
            found.append((v.segment, v.t, f"{_where(v.segment, v.t, len(P) - 1)}, q = {_q_text(chain, v.q)}: {what} "
                                          "(proven)"))
        elif proof.unproven:
            # the segments the proof could not settle: check them densely
            segs = sorted({k for k, _ in proof.unproven})
            for k in segs:
                chk = check_path(robot, P[k:k + 2], windows, None, step_angle, step_length)
                if not chk.valid:
                    found.append((k, 0.5, f"segment {k} → {k + 1}: {chk.first_violation.detail} (sampled at "
                                          f"{math.degrees(step_angle):.3g}°)"))
                    break
    if sigma_floor is not None:
        sp = certify_sigma(robot, P, sigma_floor)
        if sp.violation is not None:
            k, f, q, s = sp.violation
            found.append((k, f, f"{_where(k, f, len(P) - 1)}, q = {_q_text(chain, q)}: σ_min = {s:.4g} below the floor "
                                f"{sigma_floor:.4g} by {sigma_floor - s:.3g} (proven)"))
        for k in sp.unproven:             # segments the bound could not settle: sampled
            chk = check_path(robot, P[k:k + 2], None, sigma_floor, step_angle, step_length, prove=False)
            if not chk.valid:
                found.append((k, 0.5, f"segment {k} → {k + 1}: {chk.first_violation.detail} (sampled)"))
                break
    if world is not None:
        if world.chain != chain:
            raise ConfigurationError(f"the collision world is for {world.chain.name}, not {chain.name}")
        cp = certify_collision(world, P)
        if cp.violation is not None:
            v = cp.violation
            found.append((v.segment, v.t, f"{_where(v.segment, v.t, len(P) - 1)}, q = {_q_text(chain, v.q)}: "
                                          f"collision: {v.text} (proven)"))
        for k in cp.unproven:             # pieces the bound could not settle (a graze): sampled
            chk = check_path(robot, P[k:k + 2], None, None, step_angle, step_length, prove=False, world=world)
            if not chk.valid:
                found.append((k, 0.5, f"segment {k} → {k + 1}: {chk.first_violation.detail} (sampled)"))
                break
    if keep_out:
        Q, seg, frac = densify(P, chain.revolute_mask, step_angle, step_length)
        for b, box in enumerate(keep_out):
            hit = JointSpaceChecker(robot, boxes=[box])._in_box(Q)
            if hit.any():
                k = int(np.argmax(hit))
                where = "a joint-frame origin or the tool point" if box.all_frames else "the tool point"
                found.append((int(seg[k]), float(frac[k]),
                              f"{_where(int(seg[k]), float(frac[k]), len(P) - 1)}, q = {_q_text(chain, Q[k])}: "
                              f"{where} inside keep-out box {b} {list(box.lower)} … {list(box.upper)} m (sampled)"))
    if found:
        msg = min(found, key=lambda f: (f[0], f[1]))[2]
        raise AssertionError(f"{chain.name}: path is not valid: {msg}")


def assert_toolpath_valid(robot, toolpath, windows=None, sigma_floor: float | None = None, **options) -> None:
    """Raise :class:`AssertionError` naming the first problem of a Cartesian ``toolpath``
    (:class:`planning.toolpath.ToolPath`) for ``robot``: an unreachable waypoint, a branch jump, a
    limit, a window, σ_min below ``sigma_floor``, a joint speed (see
    :func:`planning.toolpath.validate_toolpath`, which takes the other ``options``)."""
    report = validate_toolpath(robot, toolpath, windows=windows, sigma_min=sigma_floor, **options)
    if report.first_problem is not None:
        p = report.first_problem
        q = report.q[p.index] if getattr(report, "q", None) is not None else None
        qtxt = "" if q is None or not np.isfinite(q).all() else f", q = {_q_text(robot.chain, q)}"
        raise AssertionError(f"{robot.chain.name}: tool path is not valid: {p.where(len(toolpath.poses))}{qtxt}: "
                             f"{p.kind}: {p.detail}")
