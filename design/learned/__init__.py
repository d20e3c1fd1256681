"""The learned-IK window method: IK branches of a singular factor (:mod:`~design.learned.branch`),
the learned inverse model (:mod:`~design.learned.ik`) and the windows it gives (:mod:`~design.learned.windows`)."""
from design.learned.ik import LearnedIK, LearnedIKError, resolve_branch
from design.learned.windows import jsonable_report, learned_window, learned_windows

__all__ = ["LearnedIK", "LearnedIKError", "resolve_branch", "learned_window", "learned_windows",
           "jsonable_report"]
