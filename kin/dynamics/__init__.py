"""Dynamics of the chain: the inertial model of its links (:mod:`kin.dynamics.inertia`) and inverse
dynamics by recursive Newton-Euler in CasADi (:mod:`kin.dynamics.rnea`, imported on its own: it needs
:mod:`kin.symbolic`, which needs :mod:`kin.chain`, which needs this package)."""
from kin.dynamics.inertia import MAX_MASS, InertiaError, LinkInertia

__all__ = ["LinkInertia", "InertiaError", "MAX_MASS"]
