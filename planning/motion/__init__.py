"""The planner's hot loop, native: state checks and motion checks proven between their samples
(:class:`MotionChecker`, ``motion.c``)."""
from planning.motion.checker import DEFAULT_STEP, MotionCheck, MotionChecker, available, checker_for

__all__ = ["DEFAULT_STEP", "MotionCheck", "MotionChecker", "available", "checker_for"]
