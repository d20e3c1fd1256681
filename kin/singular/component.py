"""What every component of a singular set offers, however it was found: :class:`SingularSet`, the
interface that windows, planning, studies and the CLI rely on.

Two kinds implement it: :class:`kin.singular.SingularFactor` (an irreducible factor g of det J
found by the exact analysis: a formula) and :class:`kin.singular.SingularComponent` (a component
found by the numeric analysis: sample points, no formula; ``expr`` is then a label).  A numeric
component's ``multiplicity`` is 1 because its order is not known.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

__all__ = ["SingularSet"]


@runtime_checkable
class SingularSet(Protocol):
    """One component of a chain's singular set (SI units).

    ``kind``: wrist, elbow, shoulder, boundary, prismatic or other; ``joints``: the 1-based joints
    it depends on; ``expr``: g with numbers (a label for a numeric component); ``meaning``: one line
    of geometry; ``solutions``: the joint values of a one-joint component (``{"type": "values",
    "values": [...]}``) or a summary of the sampled set; ``n``: the chain's number of joints;
    ``multiplicity``: the factor's power in det J (1 for a numeric component).
    """

    kind: str
    joints: tuple[int, ...]
    meaning: str
    solutions: dict
    n: int
    multiplicity: int

    @property
    def expr(self) -> str: ...

    @property
    def samples(self) -> np.ndarray:
        """Configurations on the set (K, n)."""

    @property
    def single_joint(self) -> int | None:
        """The 0-based joint when the component depends on one joint only, else None."""

    def to_dict(self) -> dict:
        """Plain JSON data describing the component."""
