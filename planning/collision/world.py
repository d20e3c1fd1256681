"""`CollisionWorld`: a robot placed in a work cell, ready to answer "how clear is it here?".

It joins the robot's capsules (:attr:`kin.Robot.geometry`, plus the cell's tool), the cell's
obstacles and allowed pairs, and where the cell puts the robot, into one compiled
:class:`kin.geometry.ClearanceModel`; and it holds the motion bound of the proofs
(:func:`kin.geometry.reach_radii`, :mod:`planning.certify.collision`).  ``margin`` is the clearance
a state needs to count as clear (m, ≥ 0): 0 means "not touching".

When the robot's geometry has convex hulls besides its capsules (``[[geometry.hull]]``, e.g. of its
maker's collision meshes), every clearance at most ``margin`` + :data:`kin.geometry.hulls.BAND` is
raised to the hulls' where larger (:class:`kin.geometry.hulls.HullRefiner`): a state or motion the
capsules alone would refuse can then be proven clear of the hulls.  The native motion checker knows
capsules only: what it cannot prove clear is proven again in Python with the hulls
(:mod:`planning.ompl.validity`, :func:`planning.certify.collision.certify_collision`).
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from kin.geometry import ClearanceModel, RobotGeometry, body_names, reach_radii
from kin.geometry.adjacency import always_touching_pairs
from kin.geometry.hulls import HullRefiner
from kin.validation import is_real
from planning.errors import PlanningError

__all__ = ["CollisionWorld", "MAX_MARGIN"]

#: the largest required clearance (m)
MAX_MARGIN = 1.0


class CollisionWorld:
    """A robot in a cell (or alone: self-collision only).

    ``geometry``: the robot's capsules with the tool's (default ``robot.geometry``); ``obstacles``:
    :class:`kin.geometry.Obstacle` in world coordinates; ``base``: the robot's placement in the
    world (4×4; identity by default); ``margin``: the clearance a state needs (m); ``name``: what
    messages call the cell.  Usually built by :func:`planning.collision.collision_world`.
    """

    def __init__(self, robot, geometry: RobotGeometry | None = None, obstacles=(), base=None,
                 margin: float = 0.0, name: str = "", cap: float = 1.0):
        if not (is_real(margin) and math.isfinite(margin) and 0 <= margin <= MAX_MARGIN):
            raise PlanningError(f"required clearance {margin!r} must be a number in [0, {MAX_MARGIN:g}] m")
        self.robot = robot
        self.chain = robot.chain
        geometry = robot.geometry if geometry is None else geometry
        #: pairs found touching in every sampled configuration, and so not checked (see
        #: :mod:`kin.geometry.adjacency`)
        self.auto_allowed = tuple(always_touching_pairs(robot.chain, geometry))
        self.geometry = geometry.with_allowed(self.auto_allowed) if self.auto_allowed else geometry
        self.obstacles = tuple(obstacles)
        self.base = np.eye(4) if base is None else np.asarray(base, dtype=float)
        self.margin = float(margin)
        self.name = name
        self.cap = max(float(cap), 2 * self.margin + 0.1)
        n = self.chain.n
        self.body_names = body_names(self.chain)
        self.model = ClearanceModel(self.chain, self.geometry, self.obstacles, base=self.base, cap=self.cap)
        #: the body pairs (i < j) checked against each other
        self.pairs = list(self.model.self_pairs)
        self.radii = reach_radii(self.chain, self.geometry)              # (n, B)
        # the motion bound of each pair (see planning.certify.collision): only joints i + 1 … j move
        # body j relative to body i, so pair (i, j) gets R[l, j] for those joints and 0 for the others;
        # and which bodies each pair counts for
        P, B = len(self.pairs), n + 2
        self.pair_radii = np.zeros((P, n))
        self.pair_bodies = np.zeros((P, B), bool)
        for p, (i, j) in enumerate(self.pairs):
            rows = slice(i, min(j, n))
            self.pair_radii[p, rows] = self.radii[rows, j]
            self.pair_bodies[p, [i, j]] = True
        #: the hulls' refinement of the capsules' clearances (None: the geometry has no hulls)
        self.refiner = HullRefiner(self.chain, self.geometry, self.obstacles, self.base, self.pairs) \
            if self.geometry.hulls else None

    def __repr__(self) -> str:
        return (f"CollisionWorld({self.chain.name!r}, {len(self.obstacles)} obstacles, "
                f"{len(self.geometry.capsules)} capsules, {len(self.pairs)} self pairs)")

    def move_base(self, base) -> None:
        """Place the robot at ``base`` (4×4, world frame); obstacles, pairs and motion bounds stay (they
        do not depend on where the robot stands).  Reach and placement studies move one world around."""
        self.model.move_base(base)
        self.base = self.model.base
        if self.refiner is not None:
            self.refiner.base = self.base
        self.__dict__.pop("_motion_checkers", None)      # native checkers read the old placement
        self.__dict__.pop("_split", None)

    # ---- evaluation ---------------------------------------------------------------------------
    def clearance(self, Q):
        """Signed clearance (m) of configurations (N, n) → (N,), or of one (n,) → float."""
        if self.refiner is None:
            return self.model.clearance(Q)
        Q = np.asarray(Q, dtype=float)
        obs, slf = self.per_body(Q)
        out = np.minimum(obs.min(axis=1), slf.min(axis=1))
        return float(out[0]) if Q.ndim == 1 else out

    def per_body(self, Q) -> tuple[np.ndarray, np.ndarray]:
        """Per body (N, B): clearance against obstacles and against the other bodies."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        obs, slf = self.model.per_body(Q)
        if self.refiner is not None:
            obs, slf = self.refiner.refine(Q, obs, slf, self.margin, self.cap)
        return obs, slf

    def nearest(self, Q):
        """The closest pair per configuration (:class:`kin.geometry.Contact` of arrays)."""
        return self.model.nearest(np.atleast_2d(np.asarray(Q, dtype=float)))

    def split_models(self) -> tuple:
        """Two clearance models of this world, (obstacles only, self pairs only); None for a kind the
        world does not check (no obstacles, no self pairs).  What reports use to name the nearest
        obstacle and the nearest self pair apart (:mod:`planning.collision.report`)."""
        if "_split" not in self.__dict__:
            kw = dict(base=self.base, cap=self.cap)
            obs = ClearanceModel(self.chain, self.geometry, self.obstacles, self_pairs=(), **kw) \
                if self.obstacles else None
            slf = ClearanceModel(self.chain, self.geometry, (), self_pairs=self.pairs, **kw) if self.pairs else None
            self._split = (obs, slf)
        return self._split

    @property
    def shapes_text(self) -> str:
        """What the clearances are measured on, in words: ``"capsules"``, or the capsules and the hulls."""
        if self.refiner is None:
            return "capsules"
        from kin.geometry.hulls import BAND
        return (f"capsules, and the hulls of {len(self.refiner.hull_bodies)} bodies where the capsules come within "
                f"{(self.margin + BAND) * 1e3:.3g} mm")

    def state_clear(self, q) -> bool:
        """Whether one configuration (a sequence of n floats) is clear by more than the margin."""
        if self.model.clear_one(q) > self.margin:
            return True
        return self.refiner is not None and self.clearance(np.asarray(q, dtype=float)) > self.margin

    # ---- words --------------------------------------------------------------------------------
    def other_name(self, other: int) -> str:
        if other >= 0:
            return f"obstacle '{self.obstacles[other].name}'"
        return self.body_names[-1 - other]

    def describe(self, body: int, other: int, clearance: float) -> str:
        """E.g. ``link 4 (J4) against obstacle 'fixture': 12.3 mm deep``."""
        what = f"{self.body_names[body]} against {self.other_name(other)}"
        if clearance < 0:
            return f"{what}: {-clearance * 1e3:.3g} mm deep"
        if clearance <= self.margin:
            return f"{what}: {clearance * 1e3:.3g} mm apart, within the required {self.margin * 1e3:.3g} mm"
        return f"{what}: {clearance * 1e3:.4g} mm apart"


def collision_world(robot, cell=None, margin: float = 0.0, obstacles=(), keep_out=()) -> CollisionWorld:
    """The robot in ``cell`` (a :class:`planning.cell.Cell`, or a path to a cell file; None: the
    robot alone, self-collision only), plus further ``obstacles`` (world frame) and ``keep_out``
    boxes (:class:`planning.ompl.KeepOutBox`, in the robot's base frame: they move with the robot's
    placement in the cell, and the whole robot must stay clear of them); ``margin``: the clearance a
    state needs (m)."""
    boxes = ()
    if keep_out:
        from planning.cell import cell_from_keep_out
        boxes = cell_from_keep_out(keep_out).obstacles
    if cell is not None:
        from planning.cell import Cell, load_cell
        if not isinstance(cell, Cell):
            cell = load_cell(cell)
    if cell is None:
        return CollisionWorld(robot, obstacles=(*obstacles, *boxes), margin=margin)
    r = cell.resolve(robot)
    boxes = tuple(replace(ob, shapes=tuple(replace(sh, pose=r.base @ sh.pose) for sh in ob.shapes)) for ob in boxes)
    return CollisionWorld(robot, r.geometry, (*r.obstacles, *obstacles, *boxes), r.base, margin, cell.name)
