"""Helpers of the ``cnc_rrrppp`` study (kept here so that the study reads as a script): the angle
between two rotations, and the figures comparing the correct model with the slipped one."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

__all__ = ["rotation_angle_deg", "det_across_q2", "workspace_overlay", "COLOURS"]

COLOURS = {"correct": "#4c6a8a", "slipped": "#ff7f0e"}


def rotation_angle_deg(R1: np.ndarray, R2: np.ndarray) -> np.ndarray:
    """The angle (degrees) of the rotation R1ᵀ·R2 that turns R1 into R2; (…, 3, 3) batches."""
    c = (np.einsum("...ij,...ij->...", R1, R2) - 1.0) / 2.0      # (trace(R1ᵀ R2) − 1) / 2
    return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))


def det_across_q2(q2: dict[str, np.ndarray], det: dict[str, np.ndarray], coeff: dict[str, float]) -> Figure:
    """det J of each chain at random configurations against θ2 (rad), with the curve coeff·sin θ2."""
    fig = Figure(figsize=(9, 4.4), layout="constrained")
    ax = fig.add_subplot()
    ax.ticklabel_format(useOffset=False, style="plain")
    x = np.linspace(min(v.min() for v in q2.values()), max(v.max() for v in q2.values()), 400)
    for key in q2:
        ax.scatter(q2[key], det[key], s=6, color=COLOURS[key], alpha=0.35, lw=0,
                   label=f"{key}: det J at {len(q2[key]):,} random configurations")
        ax.plot(x, coeff[key] * np.sin(x), color=COLOURS[key], lw=1.4, ls="--",
                label=f"{key}: {coeff[key]:.4g} · sin θ2")
    ax.axhline(0, color="0.4", lw=0.8)
    ax.axvline(0, color="#d62728", lw=1.0, label="θ2 = 0 (the singularity)")
    ax.set_xlabel("θ2 (rad)")
    # det J = −det Z · det W: unit axis vectors only (prismatic linear rows, revolute angular rows)
    ax.set_ylabel("det J of the 6×6 Jacobian (dimensionless)")
    ax.set_title("det J against θ2: the other five joints change nothing")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    return fig


def workspace_overlay(P: dict[str, np.ndarray], max_points: int = 20_000, seed: int = 0) -> Figure:
    """Top (x–y) and front (x–z) views of the tool-position clouds (m) of both chains over the same
    joint samples, and the histogram of the distance between the two tool positions of each sample."""
    fig = Figure(figsize=(15, 5.2), layout="constrained")
    axes = fig.subplots(1, 3, width_ratios=[1, 1, 0.8])
    rng = np.random.default_rng(seed)
    n = min(len(C) for C in P.values())
    idx = np.sort(rng.choice(n, max_points, replace=False)) if n > max_points else np.arange(n)
    for (i, j, title), ax in zip(((0, 1, "top view (x–y)"), (0, 2, "front view (x–z)")), axes):
        for key, C in P.items():
            ax.scatter(C[idx, i], C[idx, j], s=1.5, color=COLOURS[key], alpha=0.2, lw=0)
            ax.scatter(*C.mean(axis=0)[[i, j]], s=90, marker="x", color=COLOURS[key], lw=2.5)
        ax.ticklabel_format(useOffset=False, style="plain")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel(f"{'xyz'[i]} (m)")
        ax.set_ylabel(f"{'xyz'[j]} (m)")
        ax.set_title(title)
        ax.grid(alpha=0.3)
    C1, C2 = P.values()
    d = np.linalg.norm(C1[:n] - C2[:n], axis=1)
    ax = axes[2]
    ax.hist(d, bins=60, color="0.45")
    ax.ticklabel_format(useOffset=False, style="plain")
    ax.set_xlabel("|p correct − p slipped| at the same joint values (m)")
    ax.set_ylabel("joint samples")
    ax.set_title("how far the slip moves the tool")
    ax.grid(alpha=0.3)
    handles = [Line2D([], [], ls="", marker="o", color=COLOURS[k], label=f"{k} model: tool positions") for k in P]
    handles += [Line2D([], [], ls="", marker="x", mew=2.5, color=COLOURS[k], label=f"{k} model: centroid") for k in P]
    fig.legend(handles=handles, loc="outside upper center", ncols=4, fontsize=9)
    return fig
