"""Trajectories robots read: the trajectory file rmtkit writes and reads
(:mod:`~studies.export.trajectory`), its interpolation and resampling
(:mod:`~studies.export.interpolate`), the check against the robot's limits
(:mod:`~studies.export.limits`), and the exports — a ROS 2 JointTrajectory
(:mod:`~studies.export.ros`) and a URScript program (:mod:`~studies.export.urscript`)."""
from studies.export.trajectory import MAX_TRAJECTORY_BYTES, Trajectory, TrajectoryFileError, read_trajectory

__all__ = ["Trajectory", "TrajectoryFileError", "read_trajectory", "MAX_TRAJECTORY_BYTES"]
