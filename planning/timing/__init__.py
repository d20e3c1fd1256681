"""Time parameterisation of joint paths under speed and acceleration limits: the shared types
(:mod:`~planning.timing.trajectory`), path shaping (:mod:`~planning.timing.shaping`), the OSQP
parameterisation (:mod:`~planning.timing.parameterize`) and the limit check (:mod:`~planning.timing.limits`)."""
from planning.timing.limits import LimitCheck, check_limits
from planning.timing.parameterize import DEFAULT_INTERVALS, MAX_INTERVALS, time_parameterize
from planning.timing.shaping import blend_path, simplify_path
from planning.timing.trajectory import BlendedPath, TimedTrajectory, TimingError

__all__ = ["time_parameterize", "check_limits", "blend_path", "simplify_path", "BlendedPath", "TimedTrajectory",
           "LimitCheck", "TimingError", "DEFAULT_INTERVALS", "MAX_INTERVALS"]
