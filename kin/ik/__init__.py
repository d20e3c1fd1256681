"""Inverse kinematics: the damped least-squares (Levenberg–Marquardt) solver with joint limits and
seeded restarts (:mod:`kin.ik.numeric`)."""
from kin.ik.numeric import IKResult, solve_ik

__all__ = ["IKResult", "solve_ik"]
