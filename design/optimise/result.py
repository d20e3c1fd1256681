"""The result of a design optimisation: the design, its independently verified coverage, the
solver's statistics and history, and the time."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import kin
from design.coverage import Coverage

__all__ = ["DesignResult"]


@dataclass
class DesignResult:
    """An optimised design.  ``params`` SI (name → value); ``objective`` the task's objective at the
    design, computed from the verified metric (coverage fraction for "coverage", GCI for "gci", m for
    "length"); ``feasible``: the verified coverage meets ``min_coverage``; ``verification``: the
    independent coverage check; ``solver``: method-specific statistics (IPOPT's per start, or the
    DE run's); ``metrics``: further metrics of the design (:func:`design.metrics.design_metrics`);
    ``history``: objective per iteration (one list per start); ``time_s``: wall time; ``cycle``: the
    design's motion cycle (:class:`design.cycle.CycleResult`) when the task has one."""

    task: str
    method: str
    robot: kin.Robot
    params: dict[str, float]
    objective_name: str
    objective: float
    feasible: bool
    verification: Coverage
    solver: dict[str, Any] = field(default_factory=dict)
    history: list[list[float]] = field(default_factory=list)
    time_s: float = 0.0
    length_unit: str = "m"
    architecture: str = ""
    metrics: dict[str, Any] = field(default_factory=dict)
    cycle: Any = None

    @property
    def chain(self) -> kin.Chain:
        """The robot's chain with the optimised parameter values as nominal values."""
        return self.robot.chain.with_parameters(self.params)

    def params_in_file_units(self) -> dict[str, float]:
        c = self.robot.chain
        return {k: v / (c.length_scale if c.parameters[k].kind == "length" else c.angle_scale)
                for k, v in self.params.items()}

    def to_dict(self) -> dict[str, Any]:
        """Plain values (JSON-ready after NaN → None): parameters in the robot file's units."""
        c = self.robot.chain
        v = self.verification
        return {"task": self.task, "method": self.method, "robot": c.name, "architecture": self.architecture,
                "parameters": self.params_in_file_units(),
                "units": {"parameters": c.length_unit,
                          "objective": {"length": "m", "cycle_time": "s"}.get(self.objective_name, "1")},
                "objective": {"name": self.objective_name, "value": self.objective},
                "feasible": self.feasible, "verified": v.to_dict(), "metrics": self.metrics,
                "solver": self.solver, "history": self.history, "time_s": self.time_s,
                **({"cycle": self.cycle.to_dict()} if self.cycle is not None else {})}
