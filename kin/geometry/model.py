"""`RobotGeometry`: the collision capsules of a robot, per body, and the body pairs never checked.

A chain carries its geometry (:attr:`kin.chain.Chain.geometry`, from the robot file's ``[geometry]``
table or a URDF's ``<collision>`` elements); a chain without any gets :func:`kin.geometry.default_geometry`,
capsules along its DH offsets with a stated radius.  Bodies: ``0`` base, ``k`` = DH frame k
(1 … n), ``n + 1`` the tool (its frame is the tool frame of :meth:`kin.Robot.fk`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

from kin.geometry.shapes import LinkCapsule, LinkHull

__all__ = ["RobotGeometry", "body_names"]


def body_names(chain) -> tuple[str, ...]:
    """Names of bodies 0 … n + 1: ``base``, the joint names' links (``link 1`` … or ``<joint name>``
    when the robot file names its joints), ``tool``."""
    names = ["base"]
    for k, j in enumerate(chain.joints, 1):
        names.append(f"link {k}" + (f" ({j.name})" if j.name else ""))
    names.append("tool")
    return tuple(names)


@dataclass(frozen=True)
class RobotGeometry:
    """Collision capsules of a robot (SI, each in its body's frame).

    ``allowed``: body pairs (i < j) never checked against each other, besides adjacent bodies
    (|i − j| ≤ 1, and the tool with the last link), which are never checked;
    ``source``: where the capsules come from (``"default"``, ``"robot file"``, ``"urdf"``, …);
    ``radius``: the stated radius of a default geometry (m), else None;
    ``over_estimate``: the largest distance (m) by which a capsule stands out of the geometry it
    encloses (a URDF mesh or box), 0 when the capsules are the geometry;
    ``hulls``: convex hulls that hold a body's real shape as well (:class:`LinkHull`, e.g. of its
    maker's collision mesh) — where a body's capsules come too close, the clearance is the larger of
    the capsules' and the hulls' (:mod:`kin.geometry.hulls`): the robot lies inside both.
    """

    capsules: tuple[LinkCapsule, ...]
    allowed: frozenset[tuple[int, int]] = field(default_factory=frozenset)
    source: str = "default"
    radius: float | None = None
    over_estimate: float = 0.0
    hulls: tuple[LinkHull, ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "capsules", tuple(self.capsules))
        object.__setattr__(self, "hulls", tuple(self.hulls))
        object.__setattr__(self, "allowed", frozenset((min(i, j), max(i, j)) for i, j in self.allowed))

    def bodies(self) -> list[int]:
        """The bodies that hold at least one capsule, ascending."""
        return sorted({c.body for c in self.capsules})

    def checked_pairs(self, n: int) -> list[tuple[int, int]]:
        """Body pairs (i < j) checked for self-collision for a chain of ``n`` joints: both hold
        capsules, not adjacent (|i − j| > 1: the tool n + 1 is adjacent to link n only), not in
        :attr:`allowed`."""
        bs = self.bodies()
        return [(i, j) for a, i in enumerate(bs) for j in bs[a + 1:]
                if j - i > 1 and (i, j) not in self.allowed]

    def with_allowed(self, pairs) -> "RobotGeometry":
        """A copy with more allowed pairs."""
        return RobotGeometry(self.capsules, self.allowed | frozenset(pairs), self.source, self.radius,
                             self.over_estimate, self.hulls)
