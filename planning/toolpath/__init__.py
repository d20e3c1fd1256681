"""Cartesian tool paths: the value (:mod:`~planning.toolpath.model`), the readers of CSV waypoints
(:mod:`~planning.toolpath.csv_reader`) and TOML line/arc segments (:mod:`~planning.toolpath.segments`),
:func:`load_toolpath` (:mod:`~planning.toolpath.load`), the geometry helpers
(:mod:`~planning.toolpath.geometry`), continuous IK along a path (:mod:`~planning.toolpath.ik`) and
the validation with its report (:mod:`~planning.toolpath.check`, :mod:`~planning.toolpath.report`)."""
from planning.toolpath.check import DEFAULT_MAX_STEP_ANGLE, DEFAULT_MAX_STEP_LENGTH, validate_toolpath
from planning.toolpath.csv_reader import CSV_COLUMNS, parse_toolpath_csv, read_toolpath_csv
from planning.toolpath.geometry import (
    QUAT_NORM_TOL,
    chord_length,
    quaternions_to_matrices,
    rpy_to_matrices,
    slerp,
    times_from_feed,
)
from planning.toolpath.ik import MAX_GLOBAL_SOLVES, continuous_ik
from planning.toolpath.load import READERS, load_toolpath
from planning.toolpath.model import MAX_WAYPOINTS, ToolPath, ToolPathError
from planning.toolpath.report import KINDS, Problem, ToolPathReport
from planning.toolpath.segments import (
    ARC_FIELDS,
    ARC_RADIUS_TOL,
    LINE_FIELDS,
    SEGMENT_TYPES,
    START_FIELDS,
    TOP_FIELDS,
    parse_toolpath_toml,
    read_toolpath_toml,
)

__all__ = ["ToolPath", "ToolPathError", "MAX_WAYPOINTS", "load_toolpath", "READERS", "read_toolpath_csv",
           "parse_toolpath_csv", "CSV_COLUMNS", "read_toolpath_toml", "parse_toolpath_toml", "SEGMENT_TYPES",
           "TOP_FIELDS", "START_FIELDS", "LINE_FIELDS", "ARC_FIELDS", "ARC_RADIUS_TOL", "rpy_to_matrices",
           "quaternions_to_matrices", "slerp", "chord_length", "times_from_feed", "QUAT_NORM_TOL", "continuous_ik",
           "MAX_GLOBAL_SOLVES", "validate_toolpath", "ToolPathReport", "Problem", "KINDS", "DEFAULT_MAX_STEP_ANGLE",
           "DEFAULT_MAX_STEP_LENGTH"]
