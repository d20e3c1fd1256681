"""rmtkit kinematics: chain model, robot files, CasADi kinematics, fast evaluators, IK.

>>> import kin
>>> robot = kin.load_robot("fanuc_m16ib20")
>>> robot.fk([0, 0, 0, 0, 0, 0])[:3, 3]        # doctest: +SKIP
array([1.02 , 0.   , 1.365])

``Robot``, ``Measures`` and ``load_robot`` (which need CasADi) are imported on first use, so that
``import kin`` — and a command line that only parses its arguments — stays light.  Importing kin
changes no environment variable; the compiled kernels' threads are POSIX threads started per call
(:mod:`kin.native`), with no OpenMP runtime to configure.
"""
from kin.chain import Chain, Joint, Parameter, Placement
from kin.errors import (
    ArgumentError,
    ChainError,
    CompileError,
    ConfigurationError,
    DynamicsError,
    GeometryError,
    JointLimitError,
    OutBufferError,
    ParameterError,
    RmtError,
    RobotFileError,
    SettingError,
    UnknownRobotError,
)
from kin.robotfile import bundled_robots, dumps_robot, load_chain, loads_robot, save_robot

_LAZY = {"Robot", "Measures", "load_robot"}

__all__ = ["Chain", "Joint", "Parameter", "Placement", "Robot", "Measures", "load_robot", "load_chain",
           "loads_robot", "dumps_robot", "save_robot", "bundled_robots", "RmtError", "RobotFileError",
           "UnknownRobotError", "ArgumentError", "ChainError", "ConfigurationError", "DynamicsError", "GeometryError",
           "JointLimitError", "ParameterError", "CompileError", "OutBufferError", "SettingError"]


def __getattr__(name: str):
    if name in _LAZY:
        from kin import robot
        return getattr(robot, name)
    raise AttributeError(f"module 'kin' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | _LAZY)
