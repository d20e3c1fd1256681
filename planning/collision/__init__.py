"""Collisions: a robot in its work cell (:class:`CollisionWorld`), built from a cell file
(:func:`collision_world`), and reports naming the nearest obstacle and self pair apart
(:class:`ClearanceTally`); the proofs that use it are in :mod:`planning.certify.collision`."""
from planning.collision.report import ClearanceTally, Nearest, nearest_obstacle_per_body
from planning.collision.world import MAX_MARGIN, CollisionWorld, collision_world

__all__ = ["CollisionWorld", "MAX_MARGIN", "collision_world", "ClearanceTally", "Nearest", "nearest_obstacle_per_body"]
