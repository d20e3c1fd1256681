"""Composition: the least-cost assembly of catalogue modules that serves every part of a family.

Part files (:mod:`~design.compose.parts`: a task without a robot), the space of assemblies in cost
order (:mod:`~design.compose.space`), the proven bounds that empty parts of it
(:mod:`~design.compose.bounds`), the verdict of one assembly for one part
(:mod:`~design.compose.verdict`), the search (:mod:`~design.compose.search`) and its answer
(:mod:`~design.compose.result`).  docs/modules.md, "Composition"."""
from design.compose.bounds import PartGeometry, dof_bound, holding_bound, module_extent, reach_bound, sketch
from design.compose.parts import Part, PartCycle, load_part, loads_part
from design.compose.result import ComposeResult, Found, Verification
from design.compose.search import cheapest, compose, serial_judge
from design.compose.space import ComposeSpace, Partial, Pruned, axisymmetric, full_turn_coaxial
from design.compose.verdict import STAGES, ComposeSettings, Verdict, assembled, judge, verify

__all__ = ["Part", "PartCycle", "load_part", "loads_part", "ComposeSpace", "Partial", "Pruned", "axisymmetric",
           "full_turn_coaxial", "PartGeometry", "sketch", "module_extent", "dof_bound", "reach_bound", "holding_bound",
           "ComposeSettings", "Verdict", "STAGES", "judge", "assembled", "verify", "ComposeResult", "Found",
           "Verification", "compose", "cheapest", "serial_judge"]
