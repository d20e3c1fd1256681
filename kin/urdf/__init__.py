"""URDF import and export: a URDF's serial chain as an rmtkit chain (DH rows, base and tool
transforms, same FK), and any chain as a URDF with simple cylinder visuals.

>>> from kin.urdf import import_urdf, chain_to_urdf
>>> chain = import_urdf("ur5_robot.urdf", tip="tool0", convention="standard")   # doctest: +SKIP
"""
from kin.urdf.dh import chain_from_serial, dh_frames, import_urdf
from kin.urdf.errors import UrdfError, UrdfWarning
from kin.urdf.read import SerialChain, UrdfJoint, read_serial_chain
from kin.urdf.write import chain_to_urdf, save_urdf

__all__ = ["import_urdf", "chain_from_serial", "dh_frames", "read_serial_chain", "SerialChain", "UrdfJoint",
           "chain_to_urdf", "save_urdf", "UrdfError", "UrdfWarning"]
