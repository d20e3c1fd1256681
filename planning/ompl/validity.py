"""State and motion validity in joint space: limits, singular windows, a σ_min floor, keep-out
boxes, collisions with the work cell and the robot itself.

:class:`JointSpaceChecker` answers OMPL's two questions.  ``state_valid`` is on the planner's hot
path and works on plain Python floats (interval windows are interval tests, other windows the
scalar closure of their expression tree, :func:`kin.singular.evaluate.scalar_function`; σ_min only
when a floor is set).  ``motion_valid`` checks a straight motion:
its end states, the interval windows and limits exactly, point-set windows by proof (segment–point
distances, :mod:`planning.certify.points`), and the other constraints as one numpy batch at a joint
step finer than the narrowest window, so no window can be jumped.  With a
:class:`planning.collision.CollisionWorld` a state must be clear by its margin (one call of the
compiled clearance kernel) and a motion is valid only when it is *proven* clear
(:func:`planning.certify.collision.certify_collision`), so every edge a planner keeps is proven.

Where a C compiler is available (almost always), limits, interval windows and collisions are answered
by the native :class:`planning.motion.MotionChecker` — one C call per state and per motion, its proof
between samples stated in ``planning/motion/motion.c`` — and only the rest (formula and point-set
windows, a σ_min floor, keep-out boxes: :attr:`JointSpaceChecker.extras`) is checked in Python after it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kin.display import joint_interval, joint_label, joint_value
from kin.singular.evaluate import scalar_function
from planning import motion as native_motion
from planning.certify.collision import certify_collision
from planning.certify.points import PointSetProver
from planning.certify.segments import window_expression
from planning.errors import PlanningError

MAX_MOTION_STEP_ANGLE = math.radians(1.0)
MAX_MOTION_STEP_LENGTH = 1e-3


@dataclass(frozen=True)
class KeepOutBox:
    """An axis-aligned box (base frame, m) that the tool point — and with ``all_frames`` every
    joint-frame origin — must stay out of."""

    lower: tuple[float, float, float]
    upper: tuple[float, float, float]
    all_frames: bool = False

    def contains(self, P: np.ndarray) -> np.ndarray:
        P = np.atleast_2d(P)
        return np.all((P >= np.asarray(self.lower)) & (P <= np.asarray(self.upper)), axis=1)


#: the kinds of :meth:`JointSpaceChecker.refusal`, in the order they are checked
REFUSALS = ("limits", "window", "sigma_floor", "keep_out", "collision")


class JointSpaceChecker:
    """Validity of configurations and straight motions for one robot and set of constraints."""

    def __init__(self, robot, windows=None, sigma_floor: float | None = None, boxes=(),
                 motion_step: float | None = None, world=None, native: bool = True):
        self.robot = robot
        self.world = world
        if world is not None and world.robot.chain != robot.chain:
            raise PlanningError(f"the collision world is for {world.robot.chain.name}, not {robot.chain.name}")
        self.chain = robot.chain
        self.n = robot.n
        self.windows = windows
        self.sigma_floor = sigma_floor
        self.boxes = tuple(boxes)
        self.lower = [float(x) for x in self.chain.lower]
        self.upper = [float(x) for x in self.chain.upper]
        self.revolute = self.chain.revolute_mask
        self._intervals: list[tuple[int, list[tuple[float, float]]]] = []
        self._interval_names: list[str] = []      # the interval windows' names, in the order of _intervals
        self._predicates = []
        self._predicate_windows = []    # the same windows, for batches (Window.contains, numpy)
        widths_rev, widths_len = [MAX_MOTION_STEP_ANGLE * 5], [MAX_MOTION_STEP_LENGTH * 5]
        if windows is not None:
            windows.check_robot(robot)
            for w in windows.windows:
                revolute = any(self.revolute[j - 1] for j in w.joints)
                (widths_rev if revolute else widths_len).append(2 * w.width if w.width > 0 else math.inf)
                if w.is_interval:
                    self._intervals.append((w.joint, list(w.intervals)))
                    self._interval_names.append(w.name)
                elif getattr(w, "is_point_set", False):     # planning.windows.sampled: 0 exactly inside
                    self._predicates.append((PointSetProver(w).excess, 0.0))
                    self._predicate_windows.append(w)
                else:
                    self._predicates.append((scalar_function(window_expression(w)), float(w.epsilon)))
                    self._predicate_windows.append(w)
        #: point-set windows: motions proven clear by segment–point distances (planning.certify.points)
        self._point_sets = [PointSetProver(w) for w in self._predicate_windows if getattr(w, "is_point_set", False)]
        # the motion step: a fifth of the narrowest window, at most 1° / 1 mm
        self.step_angle = min(MAX_MOTION_STEP_ANGLE, min(widths_rev) / 5)
        self.step_length = min(MAX_MOTION_STEP_LENGTH, min(widths_len) / 5)
        if motion_step is not None:
            self.step_angle = self.step_length = float(motion_step)
        self._frames = None
        #: whether anything is checked in Python (formula and point-set windows, a σ_min floor, boxes)
        self.extras = bool(self._predicates or self.sigma_floor is not None or self.boxes)
        #: motions checked by :meth:`motion_valid` so far (a planner's budget with hulls: see plan)
        self.motions = 0
        #: the native checker of limits, interval windows and collisions (None: all in Python)
        self.native = None
        if native and native_motion.available() and (world is None or world.model.backend == "compiled"):
            intervals = [(j, lo, hi) for j, ivs in self._intervals for lo, hi in ivs]
            self.native = native_motion.MotionChecker(robot, None, intervals) if world is None \
                else native_motion.checker_for(world, intervals)

    @property
    def motion_step(self) -> float:
        return self.step_angle

    @motion_step.setter
    def motion_step(self, value: float) -> None:
        scale = value / self.step_angle
        self.step_angle = value
        self.step_length *= scale

    # ---- single states ------------------------------------------------------------------------
    def sigma(self, q) -> float:
        return self.robot.sigma_min(np.asarray(q, dtype=float))

    def refusal(self, q) -> tuple[str, str, str] | None:
        """Why a configuration (SI) is invalid: (kind, detail, sentence) — kind one of :data:`REFUSALS`,
        detail the window's name or the colliding bodies (else the sentence), sentence as
        :meth:`reason` gives it; None when valid.  The checks run in the order of :data:`REFUSALS`."""
        c = self.chain
        for i, v in enumerate(q):
            if v < self.lower[i] or v > self.upper[i]:
                why = (f"{joint_label(c, i)} = {joint_value(c, i, v)} is outside its limits "
                       f"{joint_interval(c, i, self.lower[i], self.upper[i])}")
                return "limits", why, why
        for k, (j, ivs) in enumerate(self._intervals):
            v = q[j]
            for lo, hi in ivs:
                if lo <= v <= hi:
                    name = self._interval_names[k]
                    return "window", name, (f"{joint_label(c, j)} = {joint_value(c, j, v)} is inside the singular "
                                            f"window '{name}' {joint_interval(c, j, lo, hi)}")
        for k, (g, eps) in enumerate(self._predicates):
            if abs(g(q)) <= eps:
                name = self._predicate_windows[k].name
                return "window", name, f"inside the singular window '{name}'"
        if self.sigma_floor is not None:
            s = self.sigma(q)
            if s < self.sigma_floor:
                why = f"σ_min = {s:.3g} (SI) is below the floor {self.sigma_floor:.3g} (SI)"
                return "sigma_floor", why, why
        if self.boxes and self._in_box(np.asarray(q, dtype=float)[None]).any():
            return "keep_out", "inside a keep-out box", "inside a keep-out box"
        if self.world is not None and not self.world.state_clear(q):
            ct = self.world.nearest(np.asarray(q, dtype=float)[None])
            what = self.world.describe(int(ct.body[0]), int(ct.other[0]), float(ct.clearance[0]))
            return "collision", what, "in collision: " + what
        return None

    def reason(self, q) -> str | None:
        """Why a configuration (SI) is invalid, in words — joint values in the robot file's units with
        the unit named, σ_min in SI (None when valid)."""
        r = self.refusal(q)
        return None if r is None else r[2]

    @property
    def hulls(self) -> bool:
        """Whether the world refines its capsules by hulls (what the native checker cannot prove clear
        is then proven again in Python)."""
        return self.world is not None and self.world.refiner is not None

    def state_valid(self, q) -> bool:
        if self.native is not None:
            st = self.native.state_status(np.asarray(q, dtype=float))
            if st != "clear" and not (st == "collision" and self.hulls and self.world.state_clear(q)):
                return False
            return not self.extras or self._extras_valid(q)
        for i in range(self.n):
            if q[i] < self.lower[i] or q[i] > self.upper[i]:
                return False
        for j, ivs in self._intervals:
            v = q[j]
            for lo, hi in ivs:
                if lo <= v <= hi:
                    return False
        if not self._extras_valid(q):
            return False
        return self.world is None or bool(self.world.state_clear(q))

    def _extras_valid(self, q) -> bool:
        """The Python part of :meth:`state_valid` (with the native checker)."""
        for g, eps in self._predicates:
            if abs(g(q)) <= eps:
                return False
        if self.sigma_floor is not None and self.sigma(q) < self.sigma_floor:
            return False
        if self.boxes and self._in_box(np.asarray(q, dtype=float)[None]).any():
            return False
        return True

    def require_valid(self, q, what: str) -> None:
        """Raise :class:`PlanningError` naming why ``q`` (the start or goal) is invalid."""
        why = self.reason([float(x) for x in q])
        if why is not None:
            raise PlanningError(f"{what} configuration is invalid: {why}")

    # ---- motions ------------------------------------------------------------------------------
    def motion_states(self, a, b) -> np.ndarray:
        a = np.asarray(a, dtype=float)
        b = np.asarray(b, dtype=float)
        d = np.abs(b - a) / np.where(self.revolute, self.step_angle, self.step_length)
        k = max(int(math.ceil(d.max())), 1)
        t = np.linspace(0.0, 1.0, k + 1)[:, None]
        return a + t * (b - a)

    def batch_valid(self, Q: np.ndarray) -> np.ndarray:
        """Validity of many configurations (K, n) at once."""
        ok = np.all((Q >= self.chain.lower) & (Q <= self.chain.upper), axis=1)
        if self.windows is not None and self.windows.windows:
            ok &= ~self.windows.contains(Q)
        if self.sigma_floor is not None and ok.any():
            ok[ok] = self.robot.sigma_min(Q[ok]) >= self.sigma_floor
        if self.boxes and ok.any():
            ok[ok] = ~self._in_box(Q[ok])
        if self.world is not None and ok.any():
            ok[ok] = self.world.clearance(Q[ok]) > self.world.margin
        return ok

    def motion_valid(self, a, b) -> bool:
        """Whether the straight motion a → b is valid.

        The end states are checked as single states (cheap; most rejected motions end inside a
        window).  Joint limits then hold along the whole motion (the limit box is convex) and an
        interval window [lo, hi] on joint j is entered exactly when the range of q_j along the motion
        overlaps it (q_j is linear in the motion parameter), so neither needs sampling; nor do
        point-set windows (proven clear by segment–point distances, or the motion is invalid).  Only
        the formula windows, the σ_min floor and the keep-out boxes are checked at the states of
        :meth:`motion_states` (a step finer than the narrowest window), as one numpy batch; the
        collision world by proof (unproven counts as invalid).
        """
        a = [float(x) for x in a]
        b = [float(x) for x in b]
        self.motions += 1
        if self.native is not None:
            r = self.native.check(np.array(a), np.array(b))
            if r.status != "clear":
                # the capsules could not prove it: with hulls, the end states and the motion again in Python
                if not (self.hulls and r.status in ("collision", "unproven")
                        and self.world.state_clear(a) and self.world.state_clear(b)
                        and certify_collision(self.world, [a, b], stop_at_first=True, explain=False,
                                              native=False).proven):
                    return False
            if not self.extras:
                return True
            if not (self._extras_valid(b) and self._extras_valid(a)):
                return False
            return self._extras_motion(a, b)
        if not (self.state_valid(b) and self.state_valid(a)):
            return False
        for j, ivs in self._intervals:
            u, v = (a[j], b[j]) if a[j] <= b[j] else (b[j], a[j])
            for lo, hi in ivs:
                if lo <= v and u <= hi:
                    return False
        if self.world is not None and \
                not certify_collision(self.world, [a, b], stop_at_first=True, explain=False).proven:
            return False
        return self._extras_motion(a, b)

    def _extras_motion(self, a, b) -> bool:
        """Point-set windows by proof (:class:`planning.certify.points.PointSetProver`, no sampling: a
        motion it cannot prove clear is invalid); formula windows, the σ_min floor and the boxes at
        the states of :meth:`motion_states` (the end states are checked already)."""
        if not self.extras:
            return True
        if self._point_sets:
            qa, qb = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
            if not all(p.clear(qa, qb) for p in self._point_sets):
                return False
        if len(self._point_sets) == len(self._predicate_windows) and self.sigma_floor is None and not self.boxes:
            return True
        Q = self.motion_states(a, b)[1:-1]
        if len(Q) == 0:
            return True
        for w in self._predicate_windows:
            if not getattr(w, "is_point_set", False) and w.contains(Q).any():
                return False
        if self.sigma_floor is not None and (self.robot.sigma_min(Q) < self.sigma_floor).any():
            return False
        if self.boxes and self._in_box(Q).any():
            return False
        return True

    # ---- keep-out boxes -------------------------------------------------------------------------
    def _in_box(self, Q: np.ndarray) -> np.ndarray:
        T = self.robot.fk(Q)
        pts = [T[:, :3, 3]]
        if any(b.all_frames for b in self.boxes):
            if self._frames is None:
                self._frames = self.robot.symbolic.frames_function
            P = self.chain.parameter_values
            F = np.array([np.array(self._frames(q, P)[0]) for q in Q])      # (K, 4, 4(n+1))
            origins = F[:, :3, 3::4]                                         # (K, 3, n+1)
            pts_all = origins.transpose(0, 2, 1)
        hit = np.zeros(len(Q), bool)
        for box in self.boxes:
            hit |= box.contains(pts[0])
            if box.all_frames:
                hit |= box.contains(pts_all.reshape(-1, 3)).reshape(len(Q), -1).any(axis=1)
        return hit
