"""The σ_min floor of ``rmt plan``, ``check-path`` and ``validate-toolpath``: on by default (the
robot's floor, :mod:`kin.singular.floor`), ``--sigma-floor S`` to set it (SI, 0 allowed) and
``--no-singularity-check`` to turn it off; the output says which floor was used and where it came from."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kin.singular.floor import sigma_floor
from studies.cli.common import MAX_SIGMA, CliInputError, bounded


@dataclass(frozen=True)
class FloorChoice:
    """The floor a command applies: ``value`` (SI; None: off), ``source`` ("robot file", "rule",
    "--sigma-floor", "--sigma-min" or "off") and ``text``, the words the output prints."""

    value: float | None
    source: str
    text: str

    @property
    def active(self) -> float | None:
        """The floor to compute with: None when off or 0 (σ_min ≥ 0 always holds)."""
        return self.value if self.value else None

    def to_dict(self) -> dict:
        return {"value": self.value, "source": self.source, "text": self.text, "unit": "SI"}


def sigma_floor_args(sp, what: str = "fail where σ_min (SI) drops below S") -> None:
    """``--sigma-floor S`` and ``--no-singularity-check``, mutually exclusive."""
    g = sp.add_mutually_exclusive_group()
    g.add_argument("--sigma-floor", type=bounded(0, MAX_SIGMA, "(SI)"), metavar="S",
                   help=f"{what} (SI, 0 allowed; default: the robot's floor — its robot file's sigma_floor, else "
                        "10⁻³ · min(L / 1 m, 1) for a robot of length scale L: docs/robot-files.md)")
    g.add_argument("--no-singularity-check", action="store_true",
                   help="no σ_min floor (the robot's default floor is applied otherwise)")


def floor_from_args(robot, args, sigma_min: float | None = None) -> FloorChoice:
    """The floor of ``--sigma-floor``/``--no-singularity-check``, else the robot's; ``sigma_min`` (a
    ``--sigma-min`` threshold that is also a floor) raises it when larger."""
    name = robot.chain.name
    if getattr(args, "no_singularity_check", False):
        choice = FloorChoice(None, "off", "off (--no-singularity-check)")
    elif getattr(args, "sigma_floor", None) is not None:
        choice = FloorChoice(float(args.sigma_floor), "--sigma-floor", f"--sigma-floor {args.sigma_floor:g} (SI)")
    else:
        f = sigma_floor(robot.chain)
        choice = FloorChoice(f.value, f.source, f.describe(name))
    if sigma_min is not None and (choice.value is None or sigma_min > choice.value):
        choice = FloorChoice(float(sigma_min), "--sigma-min", f"--sigma-min {sigma_min:g} (SI)")
    return choice


def require_above_floor(robot, floor: FloorChoice, configurations, what: str) -> None:
    """Refuse (:class:`CliInputError`) a given configuration (SI) whose σ_min is below the floor: one
    line naming the argument, the value, the floor and how to change it."""
    if floor.active is None:
        return
    s = float(np.asarray(robot.sigma_min(np.asarray(configurations, dtype=float))))
    if s < floor.active:
        raise CliInputError(f"{what}: σ_min = {s:.3g} (SI) is below the floor ({floor.text}): a (nearly) singular "
                            "configuration; move it, or lower the floor with --sigma-floor S or turn it off with "
                            "--no-singularity-check")
