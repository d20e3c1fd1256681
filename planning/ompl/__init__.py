"""Joint-space planning with OMPL, in OMPL's own roles: the bindings and their quieting
(:mod:`~planning.ompl.bindings`), the state validity checker (:mod:`~planning.ompl.validity`) and the
planner set-up with its motion validator and objectives (:mod:`~planning.ompl.planner`)."""
from planning.ompl.planner import PlanResult, path_length, plan, planner_class
from planning.ompl.validity import JointSpaceChecker, KeepOutBox

__all__ = ["plan", "PlanResult", "planner_class", "path_length", "JointSpaceChecker", "KeepOutBox"]
