"""A planned joint path beside the straight line between its ends (:func:`plot_plan`): the joint
values with the interval windows near them shaded, each multi-joint window's factor |g| against its
bound ε, and σ_min along both — where the straight line would enter a window and the plan does not.

matplotlib's Figure API (no pyplot state); SI units (rad, m) as the windows hold them.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from studies.jointpath import densify

__all__ = ["plot_plan", "WINDOW_COLOURS"]

#: one colour per window, in the window set's order (repeating)
WINDOW_COLOURS = ["#d62728", "#ff7f0e", "#9467bd", "#8c564b"]
PATH_COLOUR, LINE_COLOUR, FLOOR_COLOUR = "#1f4e79", "#888888", "#2ca02c"
#: points along each path
POINTS = 400


def plot_plan(robot, windows, path: np.ndarray, sigma_floor: float | None = None) -> Figure:
    """Joint values along the planned ``path`` (M, n; SI) and along the straight line between its ends
    (against the fraction of each one's joint-space length), interval windows as bands on their
    joint, a panel per multi-joint window (|g| against its bound ε) and σ_min along both, with the
    floor ``sigma_floor`` when given."""
    chain = robot.chain
    n = chain.n
    names = chain.joint_names()
    Qp, Qs = densify(path, POINTS), densify(np.array([path[0], path[-1]]), POINTS)
    x_p, x_s = np.linspace(0.0, 1.0, len(Qp)), np.linspace(0.0, 1.0, len(Qs))
    preds = [(k, w) for k, w in enumerate(windows.windows) if not w.is_interval]
    rows = n + len(preds) + 1
    fig = Figure(figsize=(11, 1.35 * n + 1.8 * (len(preds) + 1) + 1.2), dpi=100, layout="constrained")
    gs = fig.add_gridspec(rows, 1, height_ratios=[1.0] * n + [1.5] * (len(preds) + 1))
    axes = [fig.add_subplot(gs[0])]
    axes += [fig.add_subplot(gs[r], sharex=axes[0]) for r in range(1, rows)]
    handles = [Line2D([], [], color=PATH_COLOUR, linewidth=1.6, label=f"planned path ({len(path)} waypoints)"),
               Line2D([], [], color=LINE_COLOUR, linestyle="--", label="straight line start → goal")]
    for j in range(n):
        ax = axes[j]
        ax.plot(x_p, Qp[:, j], color=PATH_COLOUR, linewidth=1.4)
        ax.plot(x_s, Qs[:, j], color=LINE_COLOUR, linestyle="--", linewidth=1.1)
        both = np.concatenate([Qp[:, j], Qs[:, j]])
        lo, hi = float(both.min()), float(both.max())
        pad = max(0.15 * (hi - lo), 0.05)
        ylo, yhi = lo - pad, hi + pad
        for k, w in enumerate(windows.windows):
            if w.is_interval and w.joint == j:
                for a, b in w.intervals:
                    if a <= yhi + 0.3 and b >= ylo - 0.3:        # a band near the trajectory: show it
                        ax.axhspan(a, b, color=WINDOW_COLOURS[k % 4], alpha=0.2, linewidth=0)
                        ylo, yhi = min(ylo, a - pad), max(yhi, b + pad)
        ax.set_ylim(ylo, yhi)
        ax.set_ylabel(f"{names[j]} (rad)", fontsize=9)
        ax.tick_params(labelsize=8, labelbottom=False)
        ax.grid(True, linewidth=0.5, alpha=0.4)
        ax.ticklabel_format(axis="y", useOffset=False)
    for k, w in enumerate(windows.windows):
        if w.is_interval:
            handles.append(Patch(color=WINDOW_COLOURS[k % 4], alpha=0.35,
                                 label=f"{w.kind} window on {names[w.joint]} (±{w.width:g} rad)"))
    for r, (k, w) in enumerate(preds):
        ax = axes[n + r]
        gp, gs_ = np.abs(w.g(Qp)), np.abs(w.g(Qs))
        ax.plot(x_p, gp, color=PATH_COLOUR, linewidth=1.4)
        ax.plot(x_s, gs_, color=LINE_COLOUR, linestyle="--", linewidth=1.1)
        ax.axhspan(0.0, w.epsilon, color=WINDOW_COLOURS[k % 4], alpha=0.2, linewidth=0)
        ax.set_ylim(0.0, 1.1 * max(float(gp.max()), float(gs_.max()), w.epsilon))
        ax.set_ylabel(f"|{w.kind} factor| (m)", fontsize=9)
        ax.tick_params(labelsize=8, labelbottom=False)
        ax.grid(True, linewidth=0.5, alpha=0.4)
        handles.append(Patch(color=WINDOW_COLOURS[k % 4], alpha=0.35,
                             label=f"{w.kind} window: |g| ≤ {w.epsilon:.3g} m"))
    ax = axes[-1]
    ax.plot(x_p, robot.sigma_min(Qp), color=PATH_COLOUR, linewidth=1.4)
    ax.plot(x_s, robot.sigma_min(Qs), color=LINE_COLOUR, linestyle="--", linewidth=1.1)
    if sigma_floor is not None:
        ax.axhline(sigma_floor, color=FLOOR_COLOUR, linestyle=":", linewidth=1.2)
        handles.append(Line2D([], [], color=FLOOR_COLOUR, linestyle=":", label=f"σ_min floor {sigma_floor:g}"))
    ax.set_ylim(bottom=0.0)
    ax.set_ylabel("σ_min of J (SI)", fontsize=9)
    ax.set_xlabel("fraction of the path's joint-space length", fontsize=10)
    ax.tick_params(labelsize=8)
    ax.grid(True, linewidth=0.5, alpha=0.4)
    fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=8)
    return fig
