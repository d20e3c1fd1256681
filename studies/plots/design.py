"""Design figures: targets coloured by their dexterity score (covered / not), the optimiser's
objective history, the architecture ranking, and the plane of two design parameters with where
every target is covered (:func:`design_plane_figure`)."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from studies.plots.figure import save_figure

__all__ = ["plot_coverage", "plot_history", "plot_ranking", "design_plane_figure"]


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


def design_plane_figure(axis: np.ndarray, share: np.ndarray, grid_P: np.ndarray, grid_feasible: np.ndarray,
                        grid_check: np.ndarray, marks: list[tuple[str, float, float, str, str]], fixed_length: float,
                        best_length: float, names: tuple[str, str] = ("A1", "A2"), unit: str = "mm") -> Figure:
    """The plane of two length parameters (``names``, in ``unit``) whose sum plus ``fixed_length`` is
    the design's structural length: the share of targets an independent check covers (``share``
    over ``axis`` × ``axis``, first parameter along the first index) with its 100 % boundary, the
    grid designs ``grid_P`` (D, 2) a verified metric finds feasible (``grid_feasible``; crossed
    where the check ``grid_check`` disagrees), the line of equal length ``best_length``, and the
    optimisers' answers ``marks`` (label, first, second, marker, colour).  Returns the Figure."""
    from matplotlib.lines import Line2D
    a1, a2 = names
    fig = Figure(figsize=(7.4, 6.2))
    ax = fig.add_subplot(111)
    m = ax.pcolormesh(axis, axis, 100 * share.T, shading="nearest", cmap="Greys_r", vmin=0, vmax=100)
    fig.colorbar(m, ax=ax, label="targets covered, closed form (%)", shrink=0.8)
    ax.contour(axis, axis, share.T, levels=[1 - 1e-9], colors=["tab:green"], linewidths=1.5)
    handles = [Line2D([], [], c="tab:green", lw=1.5, label="100 % covered (closed form)")]
    feas = grid_feasible
    handles.append(ax.scatter(grid_P[feas, 0], grid_P[feas, 1], s=4, c="tab:cyan",
                              label=f"grid design feasible by IK ({int(feas.sum())})"))
    bad = feas != grid_check
    if bad.any():
        handles.append(ax.scatter(grid_P[bad, 0], grid_P[bad, 1], s=24, c="red", marker="x",
                                  label=f"IK and closed form disagree ({int(bad.sum())})"))
    a = np.array([axis[0], axis[-1]])
    handles.append(ax.plot(a, best_length - fixed_length - a, "--", c="tab:orange", lw=1.0,
                           label=f"{a1} + {a2} = {best_length - fixed_length:.1f} {unit}")[0])
    for label, x, y, marker, colour in marks:
        handles.append(ax.scatter([x], [y], marker=marker, s=90, c=colour, edgecolors="k", zorder=5, label=label))
    ax.set_xlim(axis[0], axis[-1])
    ax.set_ylim(axis[0], axis[-1])
    ax.set_aspect("equal")
    ax.set_xlabel(f"{a1} ({unit})")
    ax.set_ylabel(f"{a2} ({unit})")
    ax.ticklabel_format(useOffset=False)
    ax.set_title("the design plane: where every target is covered")
    ax.legend(handles=handles, loc="upper right", fontsize=7.5)
    return fig
