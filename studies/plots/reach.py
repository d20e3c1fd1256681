"""Reach-study figures: the targets coloured by their score (a heat map on the part) or by the reason
they are missed, in 3-D — or in the plane when the targets lie in one — with the robot's base."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from studies.plots.figure import save_figure

__all__ = ["plot_reach", "REASON_COLOURS"]

#: a fixed colour per verdict, so that figures of different studies compare
REASON_COLOURS = {"reached": "#2ca02c", "out_of_reach": "#7f7f7f", "joint_limits": "#ff7f0e",
                  "collision": "#d62728", "window": "#9467bd", "dexterity": "#8c564b"}


def plot_reach(study, path, by: str = "score", length_scale: float = 1.0, length_unit: str = "m", title: str = ""):
    """Write the figure of ``study`` (a :class:`design.reach.ReachStudy`) to ``path`` (PNG): ``by`` =
    "score" (reached targets coloured 0 … 1, missed ones grey ×) or "reason" (one colour per verdict).
    Positions in ``length_unit`` (SI ÷ ``length_scale``)."""
    if by not in ("score", "reason"):
        raise ValueError(f"by={by!r}: 'score' or 'reason'")
    P = study.positions / length_scale
    base = study.placement[:3, 3] / length_scale
    flat = np.ptp(P, axis=0) <= 1e-9 * max(1.0, float(np.abs(P).max()))
    planar = bool(flat.any())
    axes2 = [i for i in range(3) if not flat[i]][:2] if planar else []
    if planar and len(axes2) < 2:
        axes2 = [i for i in range(3) if i not in axes2][:2 - len(axes2)] + axes2
        axes2 = sorted(axes2)
    fig = Figure(figsize=(7.0, 5.6))
    ax = fig.add_subplot(111) if planar else fig.add_subplot(111, projection="3d")
    coords = (lambda M: (M[:, axes2[0]], M[:, axes2[1]])) if planar else (lambda M: (M[:, 0], M[:, 1], M[:, 2]))
    ok = study.reached
    if by == "score":
        if ok.any():
            sc = ax.scatter(*coords(P[ok]), c=study.score[ok], cmap="viridis", vmin=0, vmax=1, s=28, edgecolor="k",
                            linewidths=0.3)
            fig.colorbar(sc, ax=ax, label="score (0 … 1)", shrink=0.8)
        if (~ok).any():
            ax.scatter(*coords(P[~ok]), marker="x", color="0.5", s=26, label=f"missed ({int((~ok).sum())})")
    else:
        for reason, colour in REASON_COLOURS.items():
            m = study.reason == reason
            if m.any():
                ax.scatter(*coords(P[m]), color=colour, s=26, label=f"{reason.replace('_', ' ')} ({int(m.sum())})")
    ax.scatter(*coords(base[None]), marker="P", s=120, color="black", label="robot base")
    names = "xyz"
    if planar:
        ax.set_xlabel(f"{names[axes2[0]]} ({length_unit})")
        ax.set_ylabel(f"{names[axes2[1]]} ({length_unit})")
        ax.set_aspect("equal", adjustable="datalim")
    else:
        ax.set_xlabel(f"x ({length_unit})")
        ax.set_ylabel(f"y ({length_unit})")
        ax.set_zlabel(f"z ({length_unit})")
    ax.legend(fontsize=7, loc="best")
    head = title or f"{study.robot}" + (f" in {study.cell}" if study.cell else "")
    ax.set_title(f"{head}: {100 * study.coverage:.1f} % reached, mean score {study.mean_score:.3f}", fontsize=9)
    return save_figure(fig, path)
