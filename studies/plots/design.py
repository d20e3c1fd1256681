"""Design figures: targets coloured by their dexterity score (covered / not), the optimiser's
objective history, the architecture ranking."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from studies.plots.figure import save_figure

__all__ = ["plot_coverage", "plot_history", "plot_ranking"]


def plot_coverage(positions: np.ndarray, cov, path, unit: str, title: str):
    """Targets (N, 3) in ``unit``: covered ones coloured by their best measure, the others as red crosses."""
    fig = Figure(figsize=(6.4, 5.2))
    planar = np.ptp(positions[:, 2]) < 1e-9
    ax = fig.add_subplot(111) if planar else fig.add_subplot(111, projection="3d")
    xyz = (positions[:, 0], positions[:, 1]) if planar else (positions[:, 0], positions[:, 1], positions[:, 2])
    ok = cov.covered
    if ok.any():
        sc = ax.scatter(*(c[ok] for c in xyz), c=cov.best[ok], cmap="viridis", s=14, label="covered")
        fig.colorbar(sc, ax=ax, label=f"best {cov.measure}")
    if (~ok).any():
        ax.scatter(*(c[~ok] for c in xyz), c="red", marker="x", s=14, label="not covered")
    ax.set_xlabel(f"x ({unit})")
    ax.set_ylabel(f"y ({unit})")
    if not planar:
        ax.set_zlabel(f"z ({unit})")
    else:
        ax.set_aspect("equal")
    ax.set_title(f"{title}: {100 * cov.fraction:.1f} % covered")
    ax.legend(loc="upper right", fontsize=8)
    return save_figure(fig, path)


def plot_history(history: list[list[float]], path, label: str, title: str):
    """Objective value per IPOPT iteration, one line per start."""
    fig = Figure(figsize=(6.4, 4.0))
    ax = fig.add_subplot(111)
    for i, h in enumerate(history):
        ax.plot(np.arange(len(h)), h, label=f"start {i}")
    ax.set_xlabel("iteration")
    ax.set_ylabel(label)
    ax.ticklabel_format(useOffset=False)
    ax.set_title(title)
    if len(history) <= 10:
        ax.legend(fontsize=8)
    return save_figure(fig, path)


def plot_ranking(names: list[str], objective: list[float], coverage: list[float], path, label: str):
    """Architectures ranked: objective bars, verified coverage on a second axis."""
    fig = Figure(figsize=(max(5.0, 0.6 * len(names) + 2), 4.0))
    ax = fig.add_subplot(111)
    x = np.arange(len(names))
    ax.bar(x, [v if v is not None else 0 for v in objective], color="tab:blue")
    ax.set_xticks(x, names, rotation=45 if len(names) > 8 else 0)
    ax.set_ylabel(label)
    ax2 = ax.twinx()
    ax2.plot(x, [100 * c for c in coverage], "o-", color="tab:orange")
    ax2.set_ylabel("verified coverage (%)")
    ax2.set_ylim(0, 105)
    ax.set_title("architectures by objective")
    return save_figure(fig, path)
