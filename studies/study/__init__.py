"""Study files: reading and the kinematics tables (:mod:`~studies.study.kinematics`), running a whole
study (:mod:`~studies.study.run`) and its text report (:mod:`~studies.study.report`)."""
from studies.study.kinematics import StudyFileError, load_study
from studies.study.report import study_report
from studies.study.run import run_study

__all__ = ["load_study", "run_study", "study_report", "StudyFileError"]
