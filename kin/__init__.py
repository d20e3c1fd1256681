"""rmtkit kinematics: chain model, robot files, CasADi kinematics, fast evaluators, IK.

>>> import kin
>>> robot = kin.load_robot("fanuc_m16ib20")
>>> robot.fk([0, 0, 0, 0, 0, 0])[:3, 3]        # doctest: +SKIP
array([1.02 , 0.   , 1.365])
"""
from kin.chain import Chain, Joint, Parameter, Placement
from kin.errors import (ChainError, CompileError, ConfigurationError, JointLimitError, OutputError, ParameterError,
                        RmtError, RobotFileError, SettingError, UnknownRobotError)
from kin.robot import Measures, Robot, load_robot
from kin.robotfile import bundled_robots, dumps_robot, load_chain, loads_robot, save_robot

__all__ = ["Chain", "Joint", "Parameter", "Placement", "Robot", "Measures", "load_robot", "load_chain",
           "loads_robot", "dumps_robot", "save_robot", "bundled_robots", "RmtError", "RobotFileError",
           "UnknownRobotError", "ChainError", "ConfigurationError", "JointLimitError", "ParameterError",
           "CompileError", "OutputError", "SettingError"]
