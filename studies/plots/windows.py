"""Windows of several width sources against the dexterity they leave (:func:`plot_sigma_across_windows`):
for each singular factor, σ_min of random configurations against their joint-space distance from
the factor's zero set (:func:`factor_distance`), with every source's half-width marked — which
windows stop inside the region where σ_min is low, and which reach past it.

matplotlib's Figure API (no pyplot state); SI units (rad, m).
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

__all__ = ["factor_distance", "plot_sigma_across_windows", "SOURCE_COLOURS", "SOURCE_NAMES"]

#: one colour and name per width source (the keys of ``window_sets``); other keys are drawn in grey
SOURCE_COLOURS = {"margin": "#1f77b4", "sigma_min": "#2ca02c", "learned": "#d62728"}
SOURCE_NAMES = {"margin": "margin", "sigma_min": "σ_min threshold", "learned": "learned IK"}


def factor_distance(factor, Q: np.ndarray, limits) -> np.ndarray:
    """Joint-space distance (rad) of configurations ``Q`` (N, n; SI) from a factor's zero set, in its
    window's metric: the distance to the nearest singular value for a one-joint factor, |g| / G
    otherwise, G the window's proven bound of ‖∇g‖ over the joint limits ``(lower, upper)``
    (:mod:`planning.windows`)."""
    j = factor.single_joint
    if j is not None:
        roots = np.asarray(factor.solutions.get("values", []), float)
        return np.abs(Q[:, j][:, None] - roots[None, :]).min(axis=1)
    from planning.windows.build import factor_gradient_bound
    G = factor_gradient_bound(factor.expr, factor.n, tuple(map(float, limits[0])), tuple(map(float, limits[1])))[0]
    return np.abs(factor(Q)) / G


def plot_sigma_across_windows(robot, factors, window_sets: dict, trusted, threshold: float, samples: int,
                              seed: int = 0) -> tuple[Figure, list[dict]]:
    """One panel per singular factor: σ_min of ``samples`` random configurations (outside the
    ``trusted`` windows of the *other* factors) against their distance from this factor, the lowest
    σ_min per distance bin, the ``threshold``, and each source's half-width (``window_sets``: source
    → WindowSet, windows in ``factors`` order) as a vertical line.  Returns the figure and, per
    factor, the distance below which σ_min drops under the threshold in the sample."""
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
                ax.annotate(f"{SOURCE_NAMES.get(label, label)}: {w:.2f} rad →",
                            xy=(0.98, 0.92 - 0.08 * list(window_sets).index(label)),
                            xycoords="axes fraction", ha="right", color=colour, fontsize=8)
        ax.set_xlim(0.0, x_max)
        ax.set_xlabel(f"distance from the {f.kind} singularity (rad)", fontsize=9)
        ax.set_title(f"{f.kind} singularity ({', '.join(f'q{j}' for j in f.joints)})", fontsize=9)
        ax.grid(True, linewidth=0.5, alpha=0.4)
        ax.ticklabel_format(useOffset=False)
    axes[0].set_ylabel("σ_min of J (SI)", fontsize=9)
    handles = [Line2D([], [], marker="o", linestyle="none", color="#9aa9ba", label="random configurations"),
               Line2D([], [], color="#333333", label="lowest σ_min per distance bin"),
               Line2D([], [], color=SOURCE_COLOURS["sigma_min"], linestyle=":",
                      label=f"threshold σ_min = {threshold:g}")]
    handles += [Line2D([], [], color=SOURCE_COLOURS.get(label, "#555555"),
                       label=f"window half-width: {SOURCE_NAMES.get(label, label)}") for label in window_sets]
    fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=8)
    return fig, out
