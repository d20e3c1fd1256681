"""A robot's clearance in its work cell: along joint paths (:func:`plot_clearance`) and over a plane of
two joints (:func:`plot_collision_map`).

Clearances come from a :class:`planning.collision.CollisionWorld` (signed, m; negative: how deep a
collision goes) and are shown in mm.  matplotlib's Figure API (no pyplot state).
"""
from __future__ import annotations

import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from studies.jointpath import densify

__all__ = ["plot_clearance", "plot_collision_map", "PATH_COLOURS", "MAP_COLOURS"]

#: one colour per path, in the order given
PATH_COLOURS = ["#d62728", "#1f4e79", "#2ca02c", "#9467bd"]
#: clear, in collision with the cell, with itself, with both
MAP_COLOURS = ["#f4f4f4", "#f2a65a", "#5b8fd9", "#8e5bb5"]
#: states along each path
POINTS = 600
#: bodies whose clearance to the cell comes within this (m) are drawn in the per-body panel
NEAR = 0.15


def plot_clearance(world, paths, *, bounds=None, points: int = POINTS, title: str = "") -> Figure:
    """The clearance along each joint path of ``paths`` — (label, path (M, n), SI) pairs — against the
    fraction of its joint-space length: the smallest over everything ``world`` checks, with the
    collision region shaded, each path's deepest (or closest) state marked, and ``bounds`` (label →
    a proven lower bound on the clearance along that path, m) as dashed lines; below it, for the
    first path that collides (else the first), the clearance of each body to the cell's obstacles."""
    bounds = bounds or {}
    names = world.body_names
    fig = Figure(figsize=(11, 7.2), dpi=100, layout="constrained")
    ax, axb = fig.subplots(2, 1, sharex=True, height_ratios=[1.2, 1.0])
    x = np.linspace(0.0, 1.0, points)
    per_path = []
    for k, (label, P) in enumerate(paths):
        Q = densify(np.asarray(P, float), points)
        c = np.asarray(world.clearance(Q), float)
        per_path.append((label, Q, c))
        colour = PATH_COLOURS[k % len(PATH_COLOURS)]
        ax.plot(x, 1e3 * c, color=colour, linewidth=1.6, label=label)
        i = int(np.argmin(c))
        ct = world.nearest(Q[i:i + 1])
        what = world.describe(int(ct.body[0]), int(ct.other[0]), float(ct.clearance[0]))
        ax.plot(x[i], 1e3 * c[i], "o", color=colour, markersize=6)
        ax.annotate(what, (x[i], 1e3 * c[i]), textcoords="offset points", xytext=(8, -14 if c[i] < 0 else 8),
                    fontsize=8, color=colour)
        if label in bounds and bounds[label] is not None and np.isfinite(bounds[label]):
            ax.axhline(1e3 * bounds[label], color=colour, linestyle="--", linewidth=1.0,
                       label=f"{label}: proven lower bound {1e3 * bounds[label]:.3g} mm")
    lo = min(float(c.min()) for _, _, c in per_path)
    ax.axhspan(min(1e3 * lo * 1.15, -5.0), 0.0, color="#d62728", alpha=0.08, linewidth=0)
    ax.axhline(0.0, color="#444444", linewidth=0.8)
    if world.margin > 0:
        ax.axhline(1e3 * world.margin, color="#444444", linestyle=":", linewidth=0.8,
                   label=f"required clearance {1e3 * world.margin:g} mm")
    ax.set_ylabel("clearance (mm)\nto the cell and itself", fontsize=9)
    ax.grid(True, linewidth=0.5, alpha=0.4)
    ax.legend(fontsize=8, loc="upper right")
    if title:
        ax.set_title(title, fontsize=10)
    # per body, to the obstacles, along the path that collides
    hit = next(((lbl, Q, c) for lbl, Q, c in per_path if c.min() <= world.margin), per_path[0])
    obs, _ = world.per_body(hit[1])
    obs = np.asarray(obs, float)
    shown = [b for b in range(obs.shape[1]) if obs[:, b].min() < NEAR]
    cmap = ["#e377c2", "#8c564b", "#17becf", "#bcbd22", "#7f7f7f", "#ff7f0e", "#9467bd", "#1f77b4", "#2ca02c"]
    for j, b in enumerate(shown):
        axb.plot(x, 1e3 * obs[:, b], color=cmap[j % len(cmap)], linewidth=1.3, label=names[b])
    axb.axhline(0.0, color="#444444", linewidth=0.8)
    axb.axhspan(min(1e3 * float(obs.min()) * 1.15, -5.0), 0.0, color="#d62728", alpha=0.08, linewidth=0)
    top = max(1e3 * NEAR, 1e3 * float(obs[:, shown].min()) + 20) if shown else 1e3 * NEAR
    axb.set_ylim(min(1e3 * float(obs.min()) * 1.15, -5.0), top)
    axb.set_ylabel(f"clearance (mm) of each body\nto the cell ({hit[0]})", fontsize=9)
    axb.set_xlabel("fraction of the path's joint-space length", fontsize=10)
    axb.grid(True, linewidth=0.5, alpha=0.4)
    if shown:
        axb.legend(fontsize=8, loc="upper right", ncol=2)
    else:
        axb.text(0.5, 0.5, f"no body comes within {1e3 * NEAR:g} mm of the cell", transform=axb.transAxes,
                 ha="center", fontsize=9)
    return fig


def plot_collision_map(world, q, joints: tuple[int, int] = (1, 2), n: tuple[int, int] = (121, 211),
                       marks=()) -> tuple[Figure, dict]:
    """Which configurations of the plane of two joints (0-based indices ``joints``; the other joints
    held at ``q``, SI) are clear, in collision with the cell, with the robot itself, or both — on an
    ``n`` grid over the joint limits.  ``marks``: (label, (x, y) in the plane's joint values, SI)
    points to mark.  Returns the figure and the shares of the plane (``clear``, ``cell``, ``self``,
    ``both``) with the grid's size."""
    chain = world.chain
    i, j = joints
    a = np.linspace(chain.lower[i], chain.upper[i], n[0])
    b = np.linspace(chain.lower[j], chain.upper[j], n[1])
    A, B = np.meshgrid(a, b, indexing="ij")
    Q = np.tile(np.asarray(q, float), (A.size, 1))
    Q[:, i], Q[:, j] = A.ravel(), B.ravel()
    obs, slf = world.per_body(Q)
    cell = (np.asarray(obs).min(axis=1) <= world.margin).reshape(A.shape)
    own = (np.asarray(slf).min(axis=1) <= world.margin).reshape(A.shape)
    code = cell.astype(int) + 2 * own.astype(int)
    revolute = chain.revolute_mask
    sx = np.degrees(1.0) if revolute[i] else 1e3
    sy = np.degrees(1.0) if revolute[j] else 1e3
    names = chain.joint_names()
    fig = Figure(figsize=(8.5, 6.2), dpi=100, layout="constrained")
    ax = fig.subplots()
    ax.pcolormesh(a * sx, b * sy, code.T, cmap=ListedColormap(MAP_COLOURS), vmin=-0.5, vmax=3.5, shading="nearest")
    for label, (u, v) in marks:
        ax.plot(u * sx, v * sy, "k*", markersize=11)
        ax.annotate(label, (u * sx, v * sy), textcoords="offset points", xytext=(7, 5), fontsize=8)
    ax.set_xlabel(f"{names[i]} ({'deg' if revolute[i] else 'mm'})")
    ax.set_ylabel(f"{names[j]} ({'deg' if revolute[j] else 'mm'})")
    shares = {"clear": float(np.mean(code == 0)), "cell": float(np.mean(code == 1)),
              "self": float(np.mean(code == 2)), "both": float(np.mean(code == 3)), "grid": [int(n[0]), int(n[1])]}
    labels = ["clear", "in collision with the cell", "in collision with itself", "both"]
    fig.legend(handles=[Patch(color=MAP_COLOURS[k], label=f"{labels[k]} ({100 * shares[key]:.1f} %)")
                       for k, key in enumerate(("clear", "cell", "self", "both"))],
              loc="outside lower center", ncol=2, fontsize=8)
    held = ", ".join(f"{names[k]} = {np.asarray(q)[k] * (np.degrees(1.0) if revolute[k] else 1e3):.4g}"
                     for k in range(chain.n) if k not in joints)
    ax.set_title(f"{names[i]}–{names[j]} plane over the joint limits ({held})", fontsize=9)
    return fig, shares
