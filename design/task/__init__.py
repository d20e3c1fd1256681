"""Design tasks: targets with orientation requirements, dexterity, objective and constraints
(:mod:`design.task.model`), target shapes (:mod:`design.task.targets`) and task files
(:mod:`design.task.file`)."""
from design.task.file import SHAPES, load_task, loads_task
from design.task.model import DEXTERITY_KINDS, OBJECTIVES, ORIENTATIONS, Dexterity, Targets, Task, TaskError

__all__ = ["Task", "Targets", "Dexterity", "TaskError", "load_task", "loads_task", "SHAPES", "OBJECTIVES",
           "ORIENTATIONS", "DEXTERITY_KINDS"]
