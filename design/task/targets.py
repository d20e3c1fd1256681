"""Target point sets from shapes (SI, m): a box grid, a ring/cylinder sector and a spherical shell.

Ring and shell points are placed at area- and volume-uniform radii (midpoints of equal slices of
r² and r³), so the fraction of targets inside a radial band approximates the band's share of the
area or volume to within one slice.  Points CSV files hold x, y, z and optionally a tool axis.
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from design.task.model import TaskError

#: a points CSV may have at most this many bytes (200 000 targets of six columns need about 20 MB)
MAX_POINTS_BYTES = 50 * 2**20

__all__ = ["box_points", "ring_points", "shell_points", "read_points_csv", "axis_frames", "orientation_variants"]


def box_points(lo, hi, count) -> np.ndarray:
    """Grid of count = (nx, ny, nz) points from lo to hi (both included; a count of 1 takes the middle)."""
    axes = [np.array([(a + b) / 2]) if c == 1 else np.linspace(a, b, c) for a, b, c in zip(lo, hi, count)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])


def ring_points(center, r_inner: float, r_outer: float, count, z=(0.0, 0.0), theta=(0.0, 2 * np.pi)) -> np.ndarray:
    """Points of a ring (annulus) or cylinder about the z axis through ``center``.

    count = (n_r, n_theta, n_z); radii at area-uniform midpoints, angles at midpoints of ``theta``
    (rad), heights from z[0] to z[1] relative to the centre.
    """
    nr, nt, nz = count
    u = (np.arange(nr) + 0.5) / nr
    r = np.sqrt(r_inner ** 2 + u * (r_outer ** 2 - r_inner ** 2))
    t = theta[0] + (np.arange(nt) + 0.5) / nt * (theta[1] - theta[0])
    h = np.array([(z[0] + z[1]) / 2]) if nz == 1 else np.linspace(z[0], z[1], nz)
    R, T, H = np.meshgrid(r, t, h, indexing="ij")
    return np.asarray(center, float) + np.column_stack([(R * np.cos(T)).ravel(), (R * np.sin(T)).ravel(), H.ravel()])


def shell_points(center, r_inner: float, r_outer: float, count) -> np.ndarray:
    """Points of a spherical shell: count = (n_r, n_dir); volume-uniform radii, Fibonacci directions."""
    nr, nd = count
    u = (np.arange(nr) + 0.5) / nr
    r = np.cbrt(r_inner ** 3 + u * (r_outer ** 3 - r_inner ** 3))
    k = np.arange(nd) + 0.5
    zc = 1 - 2 * k / nd
    phi = np.pi * (1 + 5 ** 0.5) * k
    D = np.column_stack([np.sqrt(1 - zc ** 2) * np.cos(phi), np.sqrt(1 - zc ** 2) * np.sin(phi), zc])
    return np.asarray(center, float) + (r[:, None, None] * D[None]).reshape(-1, 3)


def read_points_csv(path: Path, scale: float) -> tuple[np.ndarray, np.ndarray | None]:
    """Points CSV (header optional; columns x, y, z and optionally ax, ay, az) → (positions m, axes or None)."""
    from kin.files import read_text
    text = read_text(path, "points file", MAX_POINTS_BYTES, error=TaskError)
    rows = []
    for ln, row in enumerate(csv.reader(text.splitlines()), 1):
        if not row or not "".join(row).strip() or row[0].lstrip().startswith("#"):
            continue
        try:
            vals = [float(x) for x in row]
        except ValueError:
            if not rows and ln == 1:
                continue   # a header line
            raise TaskError("values must be numbers", str(path), f"line {ln}") from None
        if len(vals) not in (3, 6) or not np.all(np.isfinite(vals)):
            raise TaskError(f"expected 3 (x, y, z) or 6 (x, y, z, ax, ay, az) finite numbers, got {len(vals)}",
                            str(path), f"line {ln}")
        if rows and len(vals) != len(rows[0]):
            raise TaskError("every line needs the same number of columns", str(path), f"line {ln}")
        rows.append(vals)
    if not rows:
        raise TaskError("no points", str(path))
    A = np.array(rows)
    return A[:, :3] * scale, (A[:, 3:] if A.shape[1] == 6 else None)


def axis_frames(axes: np.ndarray, spins: int) -> np.ndarray:
    """Rotations (N, spins, 3, 3) whose z column is each axis, spun about it at ``spins`` equal angles."""
    a = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    ref = np.where(np.abs(a[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    x = np.cross(ref, a)
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    y = np.cross(a, x)
    ang = 2 * np.pi * np.arange(spins) / spins
    c, s = np.cos(ang)[None, :, None], np.sin(ang)[None, :, None]
    X = c * x[:, None] + s * y[:, None]
    Y = -s * x[:, None] + c * y[:, None]
    Z = np.broadcast_to(a[:, None], X.shape)
    return np.stack([X, Y, Z], axis=-1)


def orientation_variants(targets, spins: int) -> np.ndarray | None:
    """The tool orientations (N, V, 3, 3) to try per target of a :class:`design.task.model.Targets`, or None
    for position targets: "pose" its rotation; "axis" ``spins`` rotations about the tool axis;
    "cone" those about the axis and about six axes tilted by the half-angle."""
    if targets.orientation == "free":
        return None
    if targets.orientation == "pose":
        return targets.rotations[:, None]
    axes = targets.axes[:, None]
    if targets.orientation == "cone" and targets.cone_half_angle > 0:
        F = axis_frames(targets.axes, 6)
        a = targets.cone_half_angle
        axes = np.concatenate([axes, np.cos(a) * F[..., 2] + np.sin(a) * F[..., 0]], axis=1)
    N, A = axes.shape[:2]
    return axis_frames(axes.reshape(-1, 3), spins).reshape(N, A * spins, 3, 3)
