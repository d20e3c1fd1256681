"""A robot's default σ_min floor: the smallest smallest-singular-value of the task Jacobian (SI) below
which a configuration counts as practically singular.

σ_min in SI.  The task Jacobian maps joint rates (rad/s for a revolute joint, m/s for a prismatic
one) to the tool twist (v in m/s, ω in rad/s).  σ_min is the smallest tool twist a unit joint-rate
vector can produce: the tool moves at least σ_min · ‖q̇‖ whatever the joints do, and a tool twist of
size ‖ẋ‖ in the worst direction needs joint rates of ‖ẋ‖ / σ_min.  The units are mixed — a revolute
column is (m/rad, 1), a prismatic one (1, 0) — so σ_min scales with the robot's size where the
linear rows decide it: the linear part of a revolute column is the axis's distance to the tool,
at most the chain's length scale L (:func:`length_scale`), its angular part has norm 1.  A
well-conditioned configuration therefore has σ_min of the order of min(L / 1 m, 1); the bundled arms'
medians over their joint space are 0.04 … 0.4 (SI).

The rule (:func:`default_sigma_floor`): ``FLOOR_FACTOR · min(L / 1 m, 1)`` with FLOOR_FACTOR = 10⁻³,
a thousandth of that scale.  At the floor a 1 mm/s tool motion in the worst direction of a metre-size
arm needs 1 rad/s (57°/s) of joint rate — a 100 mm/s feed would need 100 rad/s, far beyond any
drive — so a configuration below it cannot follow a Cartesian motion of ordinary speed: practically
singular.  Over random configurations the floor excludes 0.1 % to 3 % of the bundled robots' joint
spaces (UR arms the most: their elbow and wrist singularities are long valleys).  A robot file
replaces the rule with its own ``sigma_floor`` (SI, 0 allowed: docs/robot-files.md).
"""
from __future__ import annotations

from dataclasses import dataclass

#: the default floor as a share of the robot's σ_min scale min(L / 1 m, 1)
FLOOR_FACTOR = 1e-3


@dataclass(frozen=True)
class SigmaFloor:
    """A robot's σ_min floor (SI) and where it comes from: ``"robot file"`` (its ``sigma_floor``
    field) or ``"rule"`` (:func:`default_sigma_floor`)."""

    value: float
    source: str

    def describe(self, robot_name: str) -> str:
        where = "sigma_floor of the robot file" if self.source == "robot file" else "default floor"
        return f"{where} of {robot_name}, {self.value:.3g} (SI)"


def length_scale(chain) -> float:
    """The chain's length scale L (m): Σ (|a_i| + |d_i|) over the joints (parameters at their values),
    plus every prismatic joint's largest travel |q| and the tool offset — a bound on any joint axis's
    distance to the tool point."""
    L = 0.0
    for j in chain.joints:
        L += abs(chain.resolve(j.a)) + abs(chain.resolve(j.d))
        if not j.is_revolute:
            L += max(abs(j.limits[0]), abs(j.limits[1]))
    t = chain.tool.matrix[:3, 3]
    return L + float((t @ t) ** 0.5)


def default_sigma_floor(chain) -> float:
    """``FLOOR_FACTOR · min(L / 1 m, 1)`` (SI), L = :func:`length_scale`; a chain without any length
    (L = 0: it only turns the tool) gets ``FLOOR_FACTOR``.  See the module docstring."""
    L = length_scale(chain)
    return FLOOR_FACTOR * (min(L, 1.0) if L > 0 else 1.0)


def sigma_floor(chain) -> SigmaFloor:
    """The chain's floor: its robot file's ``sigma_floor`` when given, else the rule."""
    if getattr(chain, "sigma_floor", None) is not None:
        return SigmaFloor(float(chain.sigma_floor), "robot file")
    return SigmaFloor(default_sigma_floor(chain), "rule")
