"""Studies: the context a study writes into (:class:`Study`), running a study module
(:func:`run_module`, :func:`main`) or a study file (:func:`run_study`, :func:`load_study`), the
sections several studies share (:mod:`~studies.study.sections`) and the text report of a study file."""
from studies.study.context import Study, run_study_function
from studies.study.kinematics import StudyFileError, load_study
from studies.study.report import study_report
from studies.study.run import file_study, run_study
from studies.study.script import main, run_module, terminal_summary

__all__ = ["Study", "run_study_function", "load_study", "run_study", "file_study", "study_report",
           "StudyFileError", "run_module", "main", "terminal_summary"]
