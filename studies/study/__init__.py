"""Studies: the context a study writes into (:class:`Study`), running a study module
(:func:`run_module`, :func:`main`) or a study file (:func:`run_study`, :func:`load_study`), the
sections several studies share (:mod:`~studies.study.sections`) and the text report of a study file.

Helpers studies share, one module each: the singular set as JSON in file units
(:mod:`~studies.study.singular`), a tool path's validation as JSON (:mod:`~studies.study.toolpath`),
a tool path followed by the OSQP follower and the naive resolved-rate method, summed up
(:mod:`~studies.study.follow`), the drawing task of the ``ur3_drawing`` study with its closed forms
(:mod:`~studies.study.drawing`), window margins in file units (:mod:`~studies.study.windows`), the
angle between two rotations (:mod:`~studies.study.rotations`) and the SCARA in closed form
(:mod:`~studies.study.scara`)."""
from studies.study.context import Study, run_study_function
from studies.study.kinematics import StudyFileError, load_study
from studies.study.report import study_report
from studies.study.run import file_study, run_study
from studies.study.script import main, run_module, terminal_summary

__all__ = ["Study", "run_study_function", "load_study", "run_study", "file_study", "study_report",
           "StudyFileError", "run_module", "main", "terminal_summary"]
