"""Time parameterisation of joint paths under speed, acceleration and optional jerk limits: the shared
types (:mod:`~planning.timing.trajectory`), path shaping (:mod:`~planning.timing.shaping`), the
discretised problem (:mod:`~planning.timing.stages`), its solvers — TOPP-RA's reachability passes
(:mod:`~planning.timing.reachability`, compiled by :mod:`~planning.timing.native`) and OSQP
(:mod:`~planning.timing.qp`) — the jerk pass (:mod:`~planning.timing.jerk`), the entry point
(:mod:`~planning.timing.parameterize`), the limit checks (:mod:`~planning.timing.limits`) and
jerk-limited point-to-point moves (:mod:`~planning.timing.ptp`)."""
from planning.timing.limits import LimitCheck, check_limits, dense_ratios
from planning.timing.parameterize import DEFAULT_INTERVALS, MAX_INTERVALS, METHODS, time_parameterize
from planning.timing.ptp import PTPTrajectory, ptp_move
from planning.timing.shaping import blend_path, simplify_path
from planning.timing.trajectory import BlendedPath, TimedTrajectory, TimingError

__all__ = ["time_parameterize", "ptp_move", "PTPTrajectory", "check_limits",
           "dense_ratios", "blend_path", "simplify_path", "BlendedPath",
           "TimedTrajectory", "LimitCheck", "TimingError", "DEFAULT_INTERVALS", "MAX_INTERVALS", "METHODS"]
