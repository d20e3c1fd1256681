"""Figure of a tool-path validation (:func:`planning.toolpath.check.validate_toolpath`).

One panel per joint — its trajectory along the path in the robot file's unit, the joint limits as
dashed lines, and the singular windows shaded: an interval window as a horizontal band on the
joint it concerns, a predicate window (a factor of several joints) as vertical bands over the
waypoints inside it — then a panel of σ_min along the path with the σ_min floor.  Problems are
marked: the first problem by a vertical line through every panel, the waypoints of each kind by
markers on the σ_min panel, unreachable waypoints as gaps in the joint curves.  matplotlib's
Figure API (Agg, no pyplot state); the file is written atomically.
"""
from __future__ import annotations

import os
import textwrap
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from kin.errors import ArgumentError
from planning.toolpath.check import KINDS, ToolPathReport
from studies.plots.figure import save_figure

__all__ = ["plot_toolpath_report"]

WINDOW_COLOURS = ["#d62728", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#bcbd22"]
KIND_STYLE = {"unreachable": ("x", "#000000"), "branch_jump": ("D", "#9467bd"), "limits": ("s", "#8c564b"),
              "window": ("o", "#d62728"), "sigma_min": ("v", "#ff7f0e"), "speed": ("^", "#17becf")}
LINE_COLOUR = "#1f4e79"


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of every run of True in a boolean array."""
    m = np.asarray(mask, dtype=bool)
    if not m.any():
        return []
    d = np.diff(np.concatenate([[0], m.astype(np.int8), [0]]))
    return list(zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0] - 1))


def plot_toolpath_report(report: ToolPathReport, robot, path: str | os.PathLike, x: str = "auto",
                         title: str = "") -> Path:
    """Write the joint trajectories (windows shaded) and σ_min along the path to a PNG; returns the path.

    ``x``: ``"s"`` (arc length, robot file length unit), ``"t"`` (time, s) or ``"auto"`` (arc length);
    a path along which the tool point does not move is drawn against the waypoint index.
    """
    if not isinstance(report, ToolPathReport):
        raise ArgumentError(f"report must be a ToolPathReport; got {type(report).__name__}")
    chain = robot.chain
    n = chain.n
    if x not in ("auto", "s", "t"):
        raise ArgumentError(f"x {x!r} unknown; allowed: auto, s, t")
    if x == "t" and report.t is None:
        x = "s"
    if x == "t":
        X, xlabel = report.t, "time t (s)"
    else:
        X, xlabel = report.s / chain.length_scale, f"arc length s ({chain.length_unit})"
    N = len(X)
    if N > 1 and not X[-1] > X[0]:     # the tool does not move (orientation-only path): by index
        X, xlabel = np.arange(N, dtype=float), "waypoint"
    span = float(X[-1] - X[0]) if N > 1 else 1.0
    half = 0.5 * span / max(N - 1, 1)          # half a waypoint spacing: a one-waypoint run stays visible
    scale = chain.variable_scale
    units = [chain.angle_unit if j.is_revolute else chain.length_unit for j in chain.joints]
    names = chain.joint_names()
    Qf = report.q / scale
    Qf = np.where(report.reachable[:, None], Qf, np.nan)     # unreachable: gaps (their q is only a best try)

    fig = Figure(figsize=(11, 1.55 * n + 3.2), dpi=100, layout="constrained")
    gs = fig.add_gridspec(n + 1, 1, height_ratios=[1.0] * n + [1.5])
    axes = [fig.add_subplot(gs[0])]
    axes += [fig.add_subplot(gs[k], sharex=axes[0]) for k in range(1, n + 1)]
    ws = report.windows.windows if report.windows is not None else []
    colours = {k: WINDOW_COLOURS[k % len(WINDOW_COLOURS)] for k in range(len(ws))}
    legend: list = []

    # predicate windows: the waypoints inside them, across every panel
    for k, w in enumerate(ws):
        if w.is_interval:
            continue
        inside = np.asarray(w.contains(report.q), dtype=bool) & report.reachable
        runs = _runs(inside)
        for ax in axes:
            for a, b in runs:
                ax.axvspan(X[a] - half, X[b] + half, color=colours[k], alpha=0.13, linewidth=0)
        if inside.any():
            legend.append(Patch(color=colours[k], alpha=0.3, label=f"inside window {w.name} "
                                                                  f"({int(inside.sum())} waypoints)"))

    shown: set[int] = set()      # interval windows whose band is in view
    for j in range(n):
        ax = axes[j]
        ax.plot(X, Qf[:, j], color=LINE_COLOUR, linewidth=1.2)
        lo, hi = chain.lower[j] / scale[j], chain.upper[j] / scale[j]
        data = Qf[:, j][np.isfinite(Qf[:, j])]
        dlo, dhi = (float(data.min()), float(data.max())) if len(data) else (lo, hi)
        pad = 0.15 * max(dhi - dlo, 1e-3 * max(abs(dlo), abs(dhi), 1.0))
        ylo, yhi = dlo - pad, dhi + pad
        # interval windows on this joint: horizontal bands (only the part near the trajectory is in view)
        for k, w in enumerate(ws):
            if w.is_interval and w.joint == j:
                for a, b in w.intervals:
                    ax.axhspan(a / scale[j], b / scale[j], color=colours[k], alpha=0.18, linewidth=0)
                    if a / scale[j] <= yhi and b / scale[j] >= ylo:
                        ylo, yhi = min(ylo, a / scale[j] - pad), max(yhi, b / scale[j] + pad)
                        shown.add(k)
        for lim in (lo, hi):
            if ylo - pad <= lim <= yhi + pad:
                ax.axhline(lim, color="#555555", linestyle="--", linewidth=0.9)
                ylo, yhi = min(ylo, lim - pad), max(yhi, lim + pad)
        ax.set_ylim(ylo, yhi)
        ax.set_ylabel(f"{names[j]} ({units[j]})", fontsize=9)
        ax.tick_params(labelsize=8, labelbottom=False)
        ax.grid(True, linewidth=0.5, alpha=0.4)
    for k, w in enumerate(ws):
        if w.is_interval and k in shown:
            legend.append(Patch(color=colours[k], alpha=0.35, label=f"window {w.name} (band on "
                                                                    f"{names[w.joint]})"))

    # σ_min along the path, the floor, the problems
    ax = axes[n]
    sig = np.where(report.reachable, report.sigma_min, np.nan)
    ax.plot(X, sig, color=LINE_COLOUR, linewidth=1.2)
    floor = report.thresholds.get("sigma_min")
    if floor is not None:
        ax.axhline(floor, color=KIND_STYLE["sigma_min"][1], linestyle="--", linewidth=1.0)
        legend.append(Line2D([], [], color=KIND_STYLE["sigma_min"][1], linestyle="--",
                             label=f"σ_min floor {floor:.3g}"))
    fin = sig[np.isfinite(sig)]
    base = 0.0 if not len(fin) else float(fin.min())
    for kind in KINDS:
        idx = report.problems(kind)
        if not len(idx):
            continue
        marker, colour = KIND_STYLE[kind]
        y = np.where(np.isfinite(report.sigma_min[idx]) & report.reachable[idx], report.sigma_min[idx], base)
        if len(idx) > 400:        # thin the markers out; the count in the legend stays exact
            idx, y = idx[:: len(idx) // 400 + 1], y[:: len(idx) // 400 + 1]
        ax.plot(X[idx], y, linestyle="none", marker=marker, markersize=4, color=colour, alpha=0.8)
        legend.append(Line2D([], [], linestyle="none", marker=marker, color=colour,
                             label=f"{kind}: {int(report.flags[kind].sum())} waypoints"))
    ax.set_ylabel("σ_min (SI)", fontsize=9)
    ax.set_xlabel(xlabel, fontsize=10)
    ax.tick_params(labelsize=8)
    ax.grid(True, linewidth=0.5, alpha=0.4)
    p = report.first_problem
    if p is not None:
        xp = X[p.index]
        for a in axes:
            a.axvline(xp, color="#000000", linestyle=":", linewidth=1.2)
        legend.append(Line2D([], [], color="#000000", linestyle=":",
                             label=f"first problem: {p.kind} at waypoint {p.index}"))
    if N > 1:
        axes[0].set_xlim(X[0] - half, X[-1] + half)

    head = title or f"{chain.title or chain.name}: tool path {Path(report.source).name or report.source}"
    verdict = report.verdict()
    if len(verdict) > 360:
        verdict = verdict[:357] + "…"
    fig.suptitle("\n".join(textwrap.wrap(head, 120) + textwrap.wrap(verdict, 130)), fontsize=10.5)
    if legend:
        fig.legend(handles=legend, loc="outside lower center", ncol=2, fontsize=8.5, frameon=False)
    return save_figure(fig, path)
