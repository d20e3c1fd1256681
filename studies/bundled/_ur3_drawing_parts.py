"""Figures of the ur3_drawing study: θ5 and σ_min along the drawing with the wrist window shaded, and
the drawn figure of every method against the target (matplotlib Figure API, no pyplot state)."""
from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

__all__ = ["METHODS", "wrist_figure", "drawn_figure"]

#: (series key, label, colour, line style) of every method, in the report's order
METHODS = [("naive_homework", "naive J⁻¹, homework Jacobian (z1…z6)", "#d62728", "-"),
           ("naive", "naive J⁻¹, correct Jacobian (z0…z5)", "k", "--"),
           ("qp_pose", "QP follower, pose mode", "#1f77b4", "-"),
           ("qp_axis", "QP follower, pen-axis mode", "#2ca02c", ":"),
           ("qp_position", "QP follower, position mode", "#9467bd", "-.")]


def _corners(ax, t, corners) -> None:
    for c in corners:
        ax.axvline(t[c], color="grey", lw=0.5, alpha=0.5)


def wrist_figure(result: dict) -> Figure:
    """Two panels over time: θ5 (deg) of every method with the wrist window ±w shaded and the two
    closed-form branches (the start branch θ5 = 0, the other shoulder solution's |θ5|), and σ_min of
    the Jacobian (log scale).  ``result``: :func:`studies.drawing.run_drawing_study` with series."""
    s, fb = result["series"], result["forced_by_path"]
    t, corners = s["t"], result["path"]["corners"]
    w = math.degrees(fb["margin_rad"])
    fig = Figure(figsize=(12, 7.5), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.axhspan(-w, w, color="#f4a582", alpha=0.45, lw=0, label=f"wrist window |θ5| ≤ {w:g}°")
    ob = fb["other_branch"]["abs_sin_theta5"]
    ax1.axhspan(math.degrees(math.asin(ob[0])), math.degrees(math.asin(ob[1])), color="#92c5de", alpha=0.35, lw=0,
                label="|θ5| of the other shoulder solution (closed form)")
    top = 1.3 * math.degrees(math.asin(ob[1]))
    off_scale = []
    for key, label, colour, ls in METHODS:
        if key not in s:
            continue
        q5 = np.degrees(s[key]["q"][:, 4])
        if np.nanmax(np.abs(q5)) > 10 * top:
            k = int(np.argmax(np.abs(q5) > top))
            off_scale.append(f"{label}: |θ5| = {np.nanmax(np.abs(q5)):.1e}° from t = {t[k]:.3g} s (off the plot)")
            continue
        ax1.plot(t, q5, color=colour, ls=ls, lw=1.2, label=label)
    ax1.set_ylim(-2 * w, top)
    ax1.set_ylabel("θ5 (°)")
    ax1.ticklabel_format(axis="y", useOffset=False, style="plain")
    ax1.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    title = "θ5 along the drawing: the start branch lies on θ5 = 0 throughout"
    if off_scale:
        title += "\n" + "; ".join(off_scale)
    ax1.set_title(title, fontsize=9)
    floor = 1e-16
    for key, label, colour, ls in METHODS:
        if key in s:
            sm = np.asarray(s[key]["sigma_min"], float)
            ax2.plot(t, np.maximum(np.where(np.isfinite(sm), sm, np.nan), floor), color=colour, ls=ls, lw=1.1,
                     label=label)
    ax2.set_yscale("log")
    ax2.set_ylim(floor / 3, 3)
    ax2.set_ylabel("σ_min of J (SI; ≤ 1e-16 drawn at 1e-16)")
    ax2.set_xlabel("time (s)")
    ax2.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    for ax in (ax1, ax2):
        _corners(ax, t, corners)
        ax.grid(True, alpha=0.3)
    return fig


def drawn_figure(result: dict, target_yz: np.ndarray, tips_yz: dict[str, np.ndarray]) -> Figure:
    """The drawing in the y–z plane (mm): the target and each method's pen tip (``tips_yz``: series
    key → (N, 2) in m; NaN rows skipped).  Left: zoomed on the target (methods that leave it are named);
    right: the methods that left it, at their own scale."""
    fig = Figure(figsize=(13, 6), layout="constrained")
    ax, ax_far = fig.subplots(1, 2, width_ratios=[1.2, 1])
    ty = target_yz * 1e3
    lo, hi = ty.min(axis=0), ty.max(axis=0)
    pad = 0.25 * (hi - lo).max()
    far_keys = []
    for a in (ax, ax_far):
        a.plot(ty[:, 0], ty[:, 1], color="#bbbbbb", lw=6, solid_capstyle="round", label="target")
    for key, label, colour, ls in METHODS:
        if key not in tips_yz:
            continue
        p = tips_yz[key] * 1e3
        p = p[np.all(np.isfinite(p), axis=1)]
        far = np.any((p < lo - pad) | (p > hi + pad), axis=1)
        if far.mean() > 0.5:
            far_keys.append(f"{label}: {100 * far.mean():.0f} % of its points off this view (right)")
            ax_far.plot(p[:, 0], p[:, 1], ".", color=colour, ms=1.5, label=f"{label} (every waypoint)")
        else:
            ax.plot(p[:, 0], p[:, 1], color=colour, ls=ls, lw=1.2, label=label)
    ax.set_aspect("equal")
    for a in (ax, ax_far):
        a.plot(*ty[0], "o", color="k", ms=5, label="start (singular pose)")
        a.ticklabel_format(useOffset=False, style="plain")
        a.set_xlabel("y (mm)")
        a.set_ylabel("z (mm)")
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8, loc="upper left", bbox_to_anchor=(0.0, -0.16))
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_title("The pen tip in the drawing plane" + ("\n" + "\n".join(far_keys) if far_keys else ""), fontsize=9)
    ax_far.set_title("Where the methods that leave the drawing go (pen tip projected onto y–z)", fontsize=9)
    if not far_keys:
        ax_far.set_title("Every method stays on the drawing (same view)", fontsize=9)
    return fig
