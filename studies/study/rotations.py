"""How far apart two orientations are: :func:`rotation_angle_deg`, the angle of the rotation that
turns one into the other — one number to compare a tool orientation with a reference (a document's
matrix, another model of the same machine)."""
from __future__ import annotations

import numpy as np

__all__ = ["rotation_angle_deg"]


def rotation_angle_deg(R1: np.ndarray, R2: np.ndarray) -> np.ndarray:
    """The angle (degrees, 0 … 180) of the rotation R1ᵀ·R2 that turns R1 into R2: arccos of
    (trace(R1ᵀ·R2) − 1) / 2.  Batches (…, 3, 3) give (…); two 3 × 3 matrices give a 0-d value."""
    c = (np.einsum("...ij,...ij->...", R1, R2) - 1.0) / 2.0      # (trace(R1ᵀ R2) − 1) / 2
    return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))
