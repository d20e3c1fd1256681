"""Cycle time and motor torque as design metrics: a task's motion cycle (:mod:`~design.cycle.model`),
the link mass model that follows each design's lengths (:mod:`~design.cycle.masses`), the cycle of one
design — IK, branches, joint path, timing, torques (:mod:`~design.cycle.evaluate`) — and the
task file's ``[cycle]`` table (:mod:`~design.cycle.file`)."""
from design.cycle.evaluate import CycleResult, evaluate_cycle, rest_to_rest_time
from design.cycle.masses import LinkMasses, chain_with_masses
from design.cycle.model import TORQUE_MODES, CycleSpec

__all__ = ["CycleSpec", "TORQUE_MODES", "LinkMasses", "chain_with_masses", "CycleResult", "evaluate_cycle",
           "rest_to_rest_time"]
