"""``plot_workspace`` draws the sampled workspace of :func:`design.workspace.compute_workspace` — the
singularity thesis's "functional workspace": top (x–y), front (x–z), side (y–z) and isometric views
of the tool-position cloud, dexterous samples in a neutral colour, near-singular ones in red.
Lengths are shown in the robot file's length unit.  Files are written atomically
(:func:`studies.plots.figure.save_figure`).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from design.workspace import Workspace
from kin.errors import ArgumentError
from studies.plots.figure import save_figure

__all__ = ["plot_workspace", "MAX_DRAWN_POINTS"]

#: At most this many samples are drawn (a uniform random subset, seed 0); counts stay exact.
MAX_DRAWN_POINTS = 200_000
DEXTEROUS_COLOUR = "#4c6a8a"   # muted slate blue: neutral, and red stands out against it
SINGULAR_COLOUR = "#d62728"

_MEASURE_SYMBOL = {"sigma_min": "σ_min", "manipulability": "w", "inverse_condition": "1/κ"}



def _fmt_length(x_m: float, ws: Workspace) -> str:
    v = x_m / ws.length_scale
    return f"{v:.4g} {ws.length_unit}"


def _fmt_content(value_m: float, power: int, ws: Workspace) -> str:
    """A volume (power 3) or area (power 2) in m^power, and in the file unit when that differs."""
    sup = {2: "²", 3: "³"}[power]
    text = f"{value_m:.4g} m{sup}"
    if ws.length_unit != "m":
        text += f" ({value_m / ws.length_scale ** power:.4g} {ws.length_unit}{sup})"
    return text


def _style(n_drawn: int) -> tuple[float, float]:
    """(marker size in points, alpha) for the dexterous cloud: smaller and fainter as it grows."""
    if n_drawn > 100_000:
        return 1.2, 0.14
    if n_drawn > 30_000:
        return 1.6, 0.2
    if n_drawn > 5_000:
        return 2.0, 0.30
    return 3.0, 0.6


def plot_workspace(ws: Workspace, path: str | os.PathLike, title: str = "") -> Path:
    """Four-view PNG of a sampled workspace (top x–y, front x–z, side y–z, isometric); returns the path.
    A planar workspace is drawn in one view of its plane (the others would show a line).

    At most :data:`MAX_DRAWN_POINTS` samples are drawn (uniform random subset with seed 0, stated in
    the caption); the legend gives the exact counts of all samples.  Axes are in the robot file's
    length unit with equal aspect.
    """
    if not isinstance(ws, Workspace):
        raise ArgumentError(f"ws must be a design.workspace.Workspace; got {type(ws).__name__}")
    P = ws.positions / ws.length_scale
    near = np.asarray(ws.near_singular, dtype=bool)
    N = len(P)
    if N > MAX_DRAWN_POINTS:
        idx = np.sort(np.random.default_rng(0).choice(N, MAX_DRAWN_POINTS, replace=False))
        P, near = P[idx], near[idx]
    n_drawn = len(P)
    Pd, Ps = P[~near], P[near]
    ms, alpha = _style(n_drawn)
    ms_s, alpha_s = max(ms * 1.4, 1.6), 0.55
    unit = ws.length_unit

    lo, hi = ws.bbox_min / ws.length_scale, ws.bbox_max / ws.length_scale
    if ws.dimension == 2:
        fig = _plane_view(ws, Pd, Ps, (ms, alpha, ms_s, alpha_s), title)
        return _finish(fig, ws, N, n_drawn, path)
    ext = hi - lo
    span = float(np.max(ext)) or 1.0
    pad = 0.05 * span
    # Drafting layout: top view above the front view (x columns aligned), side view beside the
    # front view (z rows aligned), the isometric view in the free corner.  Cell sizes follow the
    # extents so that equal-aspect panels fill them; a flat axis keeps a readable minimum.
    rel = np.clip((ext + 2 * pad) / (span + 2 * pad), 0.4, 1.0)
    fig = Figure(figsize=(12.5, 6.2 + 5.6 * rel[2] / max(rel[1], rel[2])), dpi=100, layout="constrained")
    fig.suptitle(title or f"{ws.robot_name}: sampled workspace", fontsize=15)
    # row 0: a thin strip for the legend (a figure legend would collide with the suptitle)
    gs = fig.add_gridspec(3, 2, width_ratios=[rel[0], rel[1]], height_ratios=[0.05, rel[1], rel[2]])
    views = [("Top view (x–y)", 0, 1, gs[1, 0]), ("Front view (x–z)", 0, 2, gs[2, 0]),
             ("Side view (y–z)", 1, 2, gs[2, 1])]
    names = "xyz"
    for label, i, j, spec in views:
        ax = fig.add_subplot(spec)
        ax.plot(Pd[:, i], Pd[:, j], linestyle="none", marker=".", markersize=ms, markeredgewidth=0,
                color=DEXTEROUS_COLOUR, alpha=alpha, rasterized=True)
        ax.plot(Ps[:, i], Ps[:, j], linestyle="none", marker=".", markersize=ms_s, markeredgewidth=0,
                color=SINGULAR_COLOUR, alpha=alpha_s, rasterized=True)
        ax.margins(0.05)
        ax.set_aspect("equal", adjustable="datalim")   # true proportions; limits grow to fill the cell
        ax.set_xlabel(f"{names[i]} ({unit})", fontsize=11)
        ax.set_ylabel(f"{names[j]} ({unit})", fontsize=11)
        ax.set_title(label, fontsize=12)
        ax.grid(True, linewidth=0.5, alpha=0.4)
        ax.tick_params(labelsize=9)

    ax3 = fig.add_subplot(gs[1, 1], projection="3d")
    ax3.plot(Pd[:, 0], Pd[:, 1], Pd[:, 2], linestyle="none", marker=".", markersize=ms * 0.9,
             markeredgewidth=0, color=DEXTEROUS_COLOUR, alpha=alpha, rasterized=True)
    ax3.plot(Ps[:, 0], Ps[:, 1], Ps[:, 2], linestyle="none", marker=".", markersize=ms_s,
             markeredgewidth=0, color=SINGULAR_COLOUR, alpha=alpha_s, rasterized=True)
    box = np.maximum(ext, 0.02 * span)   # a planar cloud keeps a thin, visible box
    mid = 0.5 * (lo + hi)
    ax3.set_xlim(mid[0] - box[0] / 2, mid[0] + box[0] / 2)
    ax3.set_ylim(mid[1] - box[1] / 2, mid[1] + box[1] / 2)
    ax3.set_zlim(mid[2] - box[2] / 2, mid[2] + box[2] / 2)
    ax3.set_box_aspect(tuple(box), zoom=0.95)
    ax3.set_proj_type("ortho")
    ax3.view_init(elev=35.264, azim=-45)      # isometric: equal foreshortening of x, y and z
    for axis, k in ((ax3.xaxis, 0), (ax3.yaxis, 1), (ax3.zaxis, 2)):
        if "xyz"[k] in ws.degenerate_axes:
            axis.set_ticks([mid[k]])           # a flat axis: one tick at its constant value
        else:
            axis.set_major_locator(MaxNLocator(max(2, int(round(5 * box[k] / span)))))
    ax3.set_xlabel(f"x ({unit})", fontsize=10, labelpad=4)
    ax3.set_ylabel(f"y ({unit})", fontsize=10, labelpad=4)
    ax3.set_zlabel(f"z ({unit})", fontsize=10, labelpad=4)
    ax3.tick_params(labelsize=8, pad=1)
    ax3.set_title("Isometric view", fontsize=12)

    lax = fig.add_subplot(gs[0, :])
    lax.axis("off")
    lax.legend(handles=_handles(ws), loc="center", ncol=2, fontsize=11, frameon=False, borderaxespad=0)
    return _finish(fig, ws, N, n_drawn, path)


def _plane_view(ws: Workspace, Pd: np.ndarray, Ps: np.ndarray, style: tuple, title: str) -> Figure:
    """A planar workspace in one panel, its plane seen face on: views along the flat axis would be
    lines, so they are not drawn."""
    ms, alpha, ms_s, alpha_s = style
    i, j = [k for k in range(3) if "xyz"[k] not in ws.degenerate_axes]
    flat = [k for k in range(3) if k not in (i, j)][0]
    level = 0.5 * (ws.bbox_min[flat] + ws.bbox_max[flat]) / ws.length_scale
    fig = Figure(figsize=(9.0, 9.4), dpi=100, layout="constrained")
    fig.suptitle(title or f"{ws.robot_name}: sampled workspace", fontsize=15)
    gs = fig.add_gridspec(2, 1, height_ratios=[0.05, 1.0])
    ax = fig.add_subplot(gs[1, 0])
    ax.plot(Pd[:, i], Pd[:, j], linestyle="none", marker=".", markersize=ms, markeredgewidth=0,
            color=DEXTEROUS_COLOUR, alpha=alpha, rasterized=True)
    ax.plot(Ps[:, i], Ps[:, j], linestyle="none", marker=".", markersize=ms_s, markeredgewidth=0,
            color=SINGULAR_COLOUR, alpha=alpha_s, rasterized=True)
    ax.margins(0.05)
    ax.set_aspect("equal", adjustable="datalim")
    ax.ticklabel_format(useOffset=False)
    unit = ws.length_unit
    ax.set_xlabel(f"{'xyz'[i]} ({unit})", fontsize=11)
    ax.set_ylabel(f"{'xyz'[j]} ({unit})", fontsize=11)
    ax.set_title(f"The plane of motion ({'xyz'[i]}–{'xyz'[j]}, {'xyz'[flat]} = {level:.4g} {unit})", fontsize=12)
    ax.grid(True, linewidth=0.5, alpha=0.4)
    lax = fig.add_subplot(gs[0, 0])
    lax.axis("off")
    lax.legend(handles=_handles(ws), loc="center", ncol=1, fontsize=11, frameon=False, borderaxespad=0)
    return fig


def _handles(ws: Workspace) -> list[Line2D]:
    """The legend: exact counts of dexterous and near-singular samples."""
    sym = _MEASURE_SYMBOL.get(ws.measure_name, ws.measure_name)
    thr = f"{ws.threshold:.3g}"
    pct = 100.0 * ws.near_singular_fraction
    return [
        Line2D([], [], linestyle="none", marker="o", markersize=8, color=DEXTEROUS_COLOUR,
               label=f"dexterous ({sym} ≥ {thr}): {ws.n_dexterous:,} samples"),
        Line2D([], [], linestyle="none", marker="o", markersize=8, color=SINGULAR_COLOUR,
               label=f"near-singular ({sym} < {thr}): {ws.n_near_singular:,} samples ({pct:.1f} %)"),
    ]


def _finish(fig: Figure, ws: Workspace, N: int, n_drawn: int, path) -> Path:
    """The caption (sampling, threshold, size, reach) and the file."""
    drawn = (f"all {N:,} samples drawn" if n_drawn == N
             else f"{n_drawn:,} of {N:,} samples drawn (uniform random subset)")
    grid = f", {ws.points_per_joint} points per joint" if ws.points_per_joint else ""
    sampling = f"{ws.method} sampling{grid}" + ("" if ws.method == "grid" else f", seed {ws.seed}")
    if ws.dimension == 3:
        size = (f"Volume ≈ {_fmt_content(ws.volume, 3, ws)}, functional {_fmt_content(ws.functional_volume, 3, ws)}"
                f" (voxel {_fmt_length(ws.voxel, ws)}: {ws.occupied:,} occupied)")
    elif ws.dimension == 2:
        size = (f"Planar workspace (flat in {', '.join(ws.degenerate_axes)}): area ≈ "
                f"{_fmt_content(ws.area, 2, ws)}, functional {_fmt_content(ws.functional_area, 2, ws)}"
                f" (pixel {_fmt_length(ws.voxel, ws)}: {ws.occupied:,} occupied)")
    else:
        size = f"Degenerate workspace ({ws.dimension}-D): no area or volume"
    if ws.dimension >= 2 and not ws.converged:
        size += (f" — not converged: half the samples fill {100 * ws.half_ratio:.0f} % of these cells, so the "
                 f"{'volume' if ws.dimension == 3 else 'area'} is a lower bound; sample more")
    caption = "\n".join([
        f"{N:,} samples: {sampling}; {drawn}.",
        f"Near-singular threshold: {ws.threshold_rule}.",
        f"{size}.",
        f"Reach {_fmt_length(ws.reach, ws)} from the base origin, {_fmt_length(ws.radial_reach, ws)} "
        f"from the base z axis.",
    ])
    fig.supxlabel(caption, fontsize=9.5, linespacing=1.5)   # supxlabel: constrained layout reserves room
    return save_figure(fig, path)
