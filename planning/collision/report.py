"""Who is nearest: the nearest obstacle and the nearest self pair of one configuration or of many,
reported apart.

A single "minimum clearance" mixes two different things: how close the robot comes to its cell, and
how close two of its own bodies come — a gripper hugging the wrist is the nearest pair in every pose
and would hide every obstacle.  :class:`ClearanceTally` keeps the two apart over a batch (a path's
dense states, a set of configurations): the nearest obstacle (its name, the robot body, the distance,
the row) and the nearest self pair (the two bodies, the distance, the row), each from a clearance
model that holds only its own kind (:meth:`planning.collision.CollisionWorld.split_models`).
:func:`nearest_obstacle_per_body` names, for one configuration, the obstacle nearest each body.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Nearest", "ClearanceTally", "nearest_obstacle_per_body", "nearest_json"]


@dataclass(frozen=True)
class Nearest:
    """The nearest pair of one kind (``"obstacle"`` or ``"self"``): ``distance`` (m, signed: < 0 is a
    penetration depth), ``body`` the robot body, ``other`` the obstacle's name (kind obstacle) or the
    other body's (kind self), ``index`` the row (configuration or path segment) where it is nearest,
    ``points`` (robot, other) the witness points (world frame, m)."""

    kind: str
    distance: float
    body: str
    other: str
    index: int
    points: tuple[tuple[float, ...], tuple[float, ...]]

    def to_dict(self) -> dict:
        key = "obstacle" if self.kind == "obstacle" else "other_body"
        return {"distance": self.distance, "body": self.body, key: self.other, "index": self.index,
                "point_robot": list(self.points[0]), "point_other": list(self.points[1])}

    def text(self, row: str = "row") -> str:
        """E.g. ``nearest obstacle 'table' to link 3: 41.2 mm (row 7)``."""
        d = f"{self.distance * 1e3:.4g} mm" if self.distance >= 0 else f"{-self.distance * 1e3:.4g} mm deep"
        where = f" ({row} {self.index})" if row else ""
        if self.kind == "obstacle":
            return f"nearest obstacle '{self.other}' to {self.body}: {d}{where}"
        return f"nearest self pair {self.body} – {self.other}: {d}{where}"


class ClearanceTally:
    """The nearest obstacle and the nearest self pair over batches of configurations, kept apart.

    ``add(Q, rows)`` takes configurations (N, n, SI) and the row each belongs to, and returns their
    clearance (N,) — the smaller of the two kinds', which is the world's own
    (:meth:`CollisionWorld.clearance`: the same pairs, split in two); ``obstacle`` and ``self_pair``
    are then the nearest of each kind over everything added (None when the world has none of that
    kind, or nothing of it comes within the world's cap)."""

    def __init__(self, world):
        self.world = world
        self.obstacle: Nearest | None = None
        self.self_pair: Nearest | None = None
        self._models = world.split_models()

    def add(self, Q, rows=None) -> np.ndarray:
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        clearance = np.full(len(Q), self.world.cap)
        if not len(Q):
            return clearance
        rows = np.arange(len(Q)) if rows is None else np.asarray(rows)
        w = self.world
        # with hulls the distances are the world's refined ones (the capsules' where nothing comes close);
        # the other body or obstacle and the witness points are the capsules' nearest pair of that row
        refined = w.per_body(Q) if getattr(w, "refiner", None) is not None else None
        for kind, model in zip(("obstacle", "self"), self._models):
            if model is None:
                continue
            ct = model.nearest(Q)
            body = np.asarray(ct.body)
            values = np.asarray(ct.clearance, dtype=float)
            if refined is not None:
                R = refined[0] if kind == "obstacle" else refined[1]
                values, body = R.min(axis=1), np.where(R.min(axis=1) < w.cap, R.argmin(axis=1), -1)
            clearance = np.minimum(clearance, values)
            have = body >= 0
            if not have.any():
                continue
            d = np.where(have, values, math.inf)
            k = int(np.argmin(d))
            best = self.obstacle if kind == "obstacle" else self.self_pair
            if best is not None and d[k] >= best.distance:
                continue
            other = int(ct.other[k])
            name = w.obstacles[other].name if other >= 0 else w.body_names[-1 - other]
            found = Nearest(kind, float(d[k]), w.body_names[int(body[k])], name, int(rows[k]),
                            (tuple(float(v) for v in ct.point_robot[k]), tuple(float(v) for v in ct.point_other[k])))
            if kind == "obstacle":
                self.obstacle = found
            else:
                self.self_pair = found
        return clearance

    def to_dict(self) -> dict:
        """``{"nearest_obstacle": …, "nearest_self": …}`` (each :meth:`Nearest.to_dict` or None), m."""
        return {"nearest_obstacle": None if self.obstacle is None else self.obstacle.to_dict(),
                "nearest_self": None if self.self_pair is None else self.self_pair.to_dict()}

    def lines(self, row: str = "row") -> list[str]:
        """One line per kind; a kind with nothing within the cap says so."""
        cap = f"≥ {self.world.cap * 1e3:.0f} mm"
        out = []
        if self._models[0] is None:
            out.append("nearest obstacle: none (the cell has no obstacles)")
        else:
            out.append(self.obstacle.text(row) if self.obstacle is not None else f"nearest obstacle: {cap}")
        if self._models[1] is None:
            out.append("nearest self pair: none checked")
        else:
            out.append(self.self_pair.text(row) if self.self_pair is not None else f"nearest self pair: {cap}")
        return out


def nearest_obstacle_per_body(world, q) -> list[tuple[str, float] | None]:
    """For one configuration (n,): per body 0 … n + 1, the nearest obstacle's name and its distance (m),
    or None (no capsule on the body, no obstacle checked against it, nothing within the cap)."""
    from kin.geometry import ClearanceModel, RobotGeometry
    q = np.asarray(q, dtype=float).reshape(1, -1)
    out: list[tuple[str, float] | None] = [None] * (world.chain.n + 2)
    if not world.obstacles:
        return out
    g = world.geometry
    for b in g.bodies():
        caps = tuple(c for c in g.capsules if c.body == b)
        model = ClearanceModel(world.chain, RobotGeometry(caps, g.allowed, g.source, g.radius, g.over_estimate),
                               world.obstacles, base=world.base, self_pairs=(), cap=world.cap)
        ct = model.nearest(q)
        if int(ct.body[0]) >= 0:
            out[b] = (world.obstacles[int(ct.other[0])].name, float(ct.clearance[0]))
    return out


def nearest_json(tally: ClearanceTally | None) -> dict:
    """``{"nearest_obstacle", "nearest_self"}`` of a tally (a path check's ``nearest``), both None
    without one: the keys a command's JSON always has."""
    return tally.to_dict() if tally is not None else {"nearest_obstacle": None, "nearest_self": None}
