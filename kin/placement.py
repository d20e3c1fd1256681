"""`Placement`: a fixed rigid transform (a robot's base or tool, a mesh's pose on its body), kept in the
form it was written (xyz + rpy, or a matrix) so that a file saves back as it was.  SI units."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kin.transforms import make_transform, rpy_to_matrix

__all__ = ["Placement", "IDENTITY"]


@dataclass(frozen=True)
class Placement:
    """A fixed rigid transform (base or tool).

    Given either as ``xyz`` + ``rpy`` (fixed-axis roll-pitch-yaw) or as a full 4×4 ``matrix``; the
    form is kept so that a robot file saves back the way it was written.  SI units.
    """

    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    matrix_: tuple[tuple[float, ...], ...] | None = None

    @property
    def matrix(self) -> np.ndarray:
        """The 4×4 homogeneous transform (SI)."""
        if self.matrix_ is not None:
            return np.array(self.matrix_, dtype=float)
        return make_transform(rpy_to_matrix(self.rpy), np.array(self.xyz, dtype=float))

    @property
    def is_identity(self) -> bool:
        return bool(np.array_equal(self.matrix, np.eye(4)))

    @classmethod
    def from_matrix(cls, T: np.ndarray) -> "Placement":
        T = np.asarray(T, dtype=float)
        return cls(matrix_=tuple(tuple(float(x) for x in row) for row in T))


IDENTITY = Placement()
