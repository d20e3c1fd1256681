"""Inverse kinematics: :func:`solve_ik` runs the compiled Levenberg–Marquardt solver
(:mod:`kin.ik.compiled`: ``ik.c`` around the chain's CasADi graph) or, without a C compiler, the numpy one
(:mod:`kin.ik.numeric`); :mod:`kin.ik.analytic` gives every branch of a spherical-wrist 6R arm and,
through :mod:`kin.ik.parallel`, of a 6R arm with parallel axes 2, 3, 4 (the UR family)."""
from kin.ik.numeric import IKResult
from kin.ik.solve import METHODS, local_ik, solve_ik

__all__ = ["METHODS", "IKResult", "local_ik", "solve_ik"]
