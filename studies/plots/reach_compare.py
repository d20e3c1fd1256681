"""The figure of a reach comparison (:func:`design.reach.compare_studies`): both studies' scores on
the targets side by side, and what changed (gained, lost, reached by both, by neither)."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

__all__ = ["comparison_figure", "CHANGE_COLOURS"]

#: colours of the change classes (also the 3-D view's, studies.report.reach_compare)
CHANGE_COLOURS = {"gained": "#2ca02c", "lost": "#d62728", "both": "#1f77b4", "neither": "#9e9e9e"}


def _plane(P: np.ndarray) -> tuple[int, int]:
    """The two coordinates the targets spread over most (the maps' axes)."""
    order = np.argsort(-np.ptp(P, axis=0))
    return tuple(sorted(order[:2].tolist()))


def comparison_figure(cmp, length_scale: float = 1.0, length_unit: str = "m") -> Figure:
    """Both studies' scores on the targets, side by side, and the change classes (gained, lost, …)."""
    P = cmp.a.positions / length_scale
    i, j = _plane(cmp.a.positions)
    names = "xyz"
    fig = Figure(figsize=(15, 4.6))
    for k, (st, label) in enumerate(((cmp.a, cmp.labels[0]), (cmp.b, cmp.labels[1]))):
        ax = fig.add_subplot(1, 3, k + 1)
        ok = st.reached
        sc = ax.scatter(P[ok, i], P[ok, j], c=st.score[ok], cmap="viridis", vmin=0, vmax=1, s=36, edgecolor="k",
                        linewidths=0.3)
        ax.scatter(P[~ok, i], P[~ok, j], marker="x", color="0.55", s=30, label="missed")
        ax.set_title(f"{label}: {100 * st.coverage:.1f} % reached, mean score {st.mean_score:.3f}", fontsize=9)
        ax.set_xlabel(f"{names[i]} ({length_unit})")
        ax.set_ylabel(f"{names[j]} ({length_unit})")
        ax.set_aspect("equal", adjustable="datalim")
    fig.colorbar(sc, ax=fig.axes[:2], label="score", shrink=0.85)
    ax = fig.add_subplot(1, 3, 3)
    cls = cmp.classes()
    for name, colour in CHANGE_COLOURS.items():
        m = cls == name
        if m.any():
            ax.scatter(P[m, i], P[m, j], color=colour, s=36, label=f"{name} ({int(m.sum())})")
    ax.set_title(f"{cmp.labels[0]} → {cmp.labels[1]}", fontsize=9)
    ax.set_xlabel(f"{names[i]} ({length_unit})")
    ax.set_ylabel(f"{names[j]} ({length_unit})")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=7, loc="best")
    return fig
