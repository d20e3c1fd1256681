"""Dynamics of the chain: the inertial model of its links (:mod:`kin.dynamics.inertia`)."""
from kin.dynamics.inertia import MAX_MASS, InertiaError, LinkInertia

__all__ = ["LinkInertia", "InertiaError", "MAX_MASS"]
