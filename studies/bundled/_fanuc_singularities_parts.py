"""Helpers of the FANUC singularity study (``studies/bundled/fanuc_singularities.py``), kept out of the
script so that it reads top to bottom:

* :func:`dh_frames` and :func:`dh_jacobian` — a plain numpy standard-DH product and geometric
  Jacobian, written from the DH table of docs/machines.md §3 and nothing else, to check rmtkit's
  compiled kinematics against;
* :func:`plot_sigma_across_windows` — σ_min against the distance from each singular factor, with
  the windows of every width source marked;
* :func:`plot_plan` — a planned joint path beside the straight line, the windows shaded, σ_min along both.

matplotlib's Figure API (no pyplot state); SI units throughout (the FANUC file is in m and rad).
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

__all__ = ["dh_frames", "dh_jacobian", "factor_distance", "plot_sigma_across_windows", "plot_plan", "densify"]

#: one colour per width source, and for the planned path and the straight line
SOURCE_COLOURS = {"margin": "#1f77b4", "sigma_min": "#2ca02c", "learned": "#d62728"}
SOURCE_NAMES = {"margin": "margin", "sigma_min": "σ_min threshold", "learned": "learned IK"}
WINDOW_COLOURS = ["#d62728", "#ff7f0e", "#9467bd", "#8c564b"]
PATH_COLOUR, LINE_COLOUR = "#1f4e79", "#888888"


# ---- an independent DH product --------------------------------------------------------------------
def dh_frames(dh: list[tuple[float, float, float]], q) -> list[np.ndarray]:
    """Frames 0…n (4×4 each) of an all-revolute standard-DH chain: rows (a, α, d), joint i adds
    A_i = Rz(q_i)·Tz(d_i)·Tx(a_i)·Rx(α_i)."""
    T = np.eye(4)
    frames = [T]
    for (a, alpha, d), th in zip(dh, np.asarray(q, float)):
        ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(alpha), np.sin(alpha)
        A = np.array([[ct, -st * ca, st * sa, a * ct],
                      [st, ct * ca, -ct * sa, a * st],
                      [0.0, sa, ca, d],
                      [0.0, 0.0, 0.0, 1.0]])
        T = T @ A
        frames.append(T)
    return frames


def dh_jacobian(dh: list[tuple[float, float, float]], q, point=None) -> np.ndarray:
    """Geometric Jacobian (6×n, rows vx vy vz wx wy wz) of the point ``point`` (default: the tool
    origin) fixed to the last link; column i = (z_{i−1} × (p − o_{i−1}), z_{i−1})."""
    F = dh_frames(dh, q)
    p = F[-1][:3, 3] if point is None else np.asarray(point, float)
    cols = [np.concatenate([np.cross(T[:3, 2], p - T[:3, 3]), T[:3, 2]]) for T in F[:-1]]
    return np.stack(cols, axis=1)


# ---- σ_min across the windows ---------------------------------------------------------------------
def factor_distance(factor, Q: np.ndarray, limits) -> np.ndarray:
    """Joint-space distance (rad) of configurations from a factor's zero set, in its window's metric:
    the distance to the nearest singular value for a one-joint factor, |g| / G otherwise, G the
    window's proven bound of ‖∇g‖ over the joint limits (:mod:`planning.windows`)."""
    j = factor.single_joint
    if j is not None:
        roots = np.asarray(factor.solutions.get("values", []), float)
        return np.abs(Q[:, j][:, None] - roots[None, :]).min(axis=1)
    from planning.windows.build import factor_gradient_bound
    G = factor_gradient_bound(factor.expr, factor.n, tuple(map(float, limits[0])), tuple(map(float, limits[1])))[0]
    return np.abs(factor(Q)) / G


def plot_sigma_across_windows(robot, factors, window_sets: dict, trusted, threshold: float, samples: int,
                              seed: int = 0) -> tuple[Figure, list[dict]]:
    """One panel per singular factor: σ_min of random configurations (outside the ``trusted``
    windows of the *other* factors) against their distance from this factor, the lowest σ_min per
    distance bin, the threshold, and each source's half-width as a vertical line.  Returns the
    figure and per factor the distance below which σ_min drops under the threshold in the sample."""
    Q = robot.random_configurations(samples, seed=seed)
    sig = robot.sigma_min(Q)
    fig = Figure(figsize=(12, 3.9), dpi=100, layout="constrained")
    axes = fig.subplots(1, len(factors), sharey=True)
    axes = np.atleast_1d(axes)
    out = []
    rng = np.random.default_rng(seed)
    for k, (f, ax) in enumerate(zip(factors, axes)):
        others = np.zeros(len(Q), bool)
        for i, w in enumerate(trusted.windows):
            if i != k:
                others |= w.contains(Q)
        d, s = factor_distance(f, Q[~others], (robot.chain.lower, robot.chain.upper)), sig[~others]
        x_max = float(np.quantile(d, 0.98))
        keep = d <= x_max
        d, s = d[keep], s[keep]
        show = rng.choice(len(d), min(len(d), 4000), replace=False)
        ax.scatter(d[show], s[show], s=2, color="#9aa9ba", alpha=0.5, linewidths=0, rasterized=True)
        edges = np.linspace(0.0, x_max, 61)
        idx = np.clip(np.digitize(d, edges) - 1, 0, 59)
        low = np.array([s[idx == b].min() if np.any(idx == b) else np.nan for b in range(60)])
        ax.step(edges[:-1], low, where="post", color="#333333", linewidth=1.3)
        ax.axhline(threshold, color=SOURCE_COLOURS["sigma_min"], linestyle=":", linewidth=1.2)
        below = d[s < threshold]
        out.append({"factor": f.kind, "samples": int(len(d)),
                    "largest_distance_below_threshold": float(below.max()) if len(below) else 0.0})
        for label, ws in window_sets.items():
            w = ws.windows[k].width
            colour = SOURCE_COLOURS.get(label, "#555555")
            if w <= x_max:
                ax.axvline(w, color=colour, linewidth=1.6)
            else:
                ax.annotate(f"{SOURCE_NAMES.get(label, label)}: {w:.2f} rad →", xy=(0.98, 0.92 - 0.08 * list(window_sets).index(label)),
                            xycoords="axes fraction", ha="right", color=colour, fontsize=8)
        ax.set_xlim(0.0, x_max)
        ax.set_xlabel(f"distance from the {f.kind} singularity (rad)", fontsize=9)
        ax.set_title(f"{f.kind} singularity ({', '.join(f'q{j}' for j in f.joints)})", fontsize=9)
        ax.grid(True, linewidth=0.5, alpha=0.4)
        ax.ticklabel_format(useOffset=False)
    axes[0].set_ylabel("σ_min of J (SI)", fontsize=9)
    handles = [Line2D([], [], marker="o", linestyle="none", color="#9aa9ba", label="random configurations"),
               Line2D([], [], color="#333333", label="lowest σ_min per distance bin"),
               Line2D([], [], color=SOURCE_COLOURS["sigma_min"], linestyle=":", label=f"threshold σ_min = {threshold:g}")]
    handles += [Line2D([], [], color=SOURCE_COLOURS.get(label, "#555555"), label=f"window half-width: {SOURCE_NAMES.get(label, label)}")
                for label in window_sets]
    fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=8)
    return fig, out


# ---- a planned path ------------------------------------------------------------------------------
def densify(path: np.ndarray, points: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """A piecewise-linear joint path resampled evenly by joint-space arc length: (s in [0, 1], Q)."""
    P = np.asarray(path, float)
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.linspace(0.0, cum[-1], points)
    Q = np.stack([np.interp(s, cum, P[:, j]) for j in range(P.shape[1])], axis=1)
    return s / max(cum[-1], 1e-300), Q


def plot_plan(robot, windows, path: np.ndarray, sigma_floor: float | None = None) -> Figure:
    """Joint values along the planned path and along the straight line between its ends (against the
    fraction of each one's joint-space length), interval windows as bands on their joint, a panel per
    multi-joint window (|g| against its bound ε) and σ_min along both."""
    chain = robot.chain
    n = chain.n
    names = chain.joint_names()
    x_p, Qp = densify(path)
    x_s, Qs = densify(np.array([path[0], path[-1]]))
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
        ax.axhline(sigma_floor, color=SOURCE_COLOURS["sigma_min"], linestyle=":", linewidth=1.2)
        handles.append(Line2D([], [], color=SOURCE_COLOURS["sigma_min"], linestyle=":",
                              label=f"σ_min floor {sigma_floor:g}"))
    ax.set_ylim(bottom=0.0)
    ax.set_ylabel("σ_min of J (SI)", fontsize=9)
    ax.set_xlabel("fraction of the path's joint-space length", fontsize=10)
    ax.tick_params(labelsize=8)
    ax.grid(True, linewidth=0.5, alpha=0.4)
    fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=8)
    return fig
