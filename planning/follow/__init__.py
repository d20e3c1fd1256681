"""Following a tool path with one OSQP QP per step (:mod:`~planning.follow.follower`), its inputs and
limits (:mod:`~planning.follow.inputs`), window barriers (:mod:`~planning.follow.barriers`), the result
(:mod:`~planning.follow.result`), tracking errors (:mod:`~planning.follow.tracking`) and the naive
resolved-rate method it is compared with (:mod:`~planning.follow.resolved_rate`)."""
from planning.follow.follower import MODES, follow_path
from planning.follow.inputs import DEFAULT_V_MAX_PRISMATIC, DEFAULT_V_MAX_REVOLUTE, FollowError, joint_velocity_limits
from planning.follow.resolved_rate import ResolvedRateResult, resolved_rate
from planning.follow.result import FollowResult, window_ranges
from planning.follow.tracking import tracking_errors

__all__ = ["follow_path", "resolved_rate", "FollowResult", "ResolvedRateResult", "FollowError", "MODES",
           "DEFAULT_V_MAX_REVOLUTE", "DEFAULT_V_MAX_PRISMATIC", "joint_velocity_limits", "window_ranges",
           "tracking_errors"]
