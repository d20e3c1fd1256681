"""Joint-space planning with OMPL, in OMPL's own roles: the bindings and their quieting
(:mod:`~planning.ompl.bindings`), the state validity checker (:mod:`~planning.ompl.validity`) and the
planner set-up with its motion validator and objectives (:mod:`~planning.ompl.planner`), goals given
as a tool pose (:mod:`~planning.ompl.goals`) and keep-out files (:mod:`~planning.ompl.keep_out`)."""
from planning.ompl.goals import goal_from_pose, wrist_twins
from planning.ompl.planner import PlanResult, path_length, plan, planner_class
from planning.ompl.validity import JointSpaceChecker, KeepOutBox

__all__ = ["plan", "PlanResult", "planner_class", "path_length", "JointSpaceChecker", "KeepOutBox", "goal_from_pose",
           "wrist_twins"]
