"""The 3-D view of a reach comparison (:func:`design.reach.compare_studies`): the targets coloured
by what changed, with both robots' base origins (plotly)."""
from __future__ import annotations

import numpy as np

__all__ = ["comparison_view"]

#: the change classes' colours (as in studies.plots.reach_compare)
CHANGE_COLOURS = {"gained": "#2ca02c", "lost": "#d62728", "both": "#1f77b4", "neither": "#9e9e9e"}


def comparison_view(cmp, length_scale: float = 1.0, length_unit: str = "m"):
    """A plotly 3-D view of the targets coloured by change class, with both robots' base origins."""
    import plotly.graph_objects as go
    P = cmp.a.positions / length_scale
    cls = cmp.classes()
    fig = go.Figure()
    for name, colour in CHANGE_COLOURS.items():
        m = cls == name
        if m.any():
            ds = cmp.b.score[m] - cmp.a.score[m]
            fig.add_trace(go.Scatter3d(x=P[m, 0], y=P[m, 1], z=P[m, 2], mode="markers", name=f"{name} ({int(m.sum())})",
                                       marker={"size": 4, "color": colour},
                                       text=[f"target {t}: score {a:.3f} → {b:.3f} ({d:+.3f})"
                                             for t, a, b, d in zip(np.flatnonzero(m), cmp.a.score[m], cmp.b.score[m],
                                                                   ds)],
                                       hoverinfo="text"))
    for st, label, symbol in ((cmp.a, cmp.labels[0], "diamond"), (cmp.b, cmp.labels[1], "square")):
        o = st.placement[:3, 3] / length_scale
        fig.add_trace(go.Scatter3d(x=[o[0]], y=[o[1]], z=[o[2]], mode="markers", name=f"base: {label}",
                                   marker={"size": 7, "symbol": symbol, "color": "black"}))
    fig.update_layout(scene={"aspectmode": "data", "xaxis_title": f"x ({length_unit})",
                             "yaxis_title": f"y ({length_unit})", "zaxis_title": f"z ({length_unit})"},
                      margin={"l": 0, "r": 0, "t": 30, "b": 0}, title="What changed, target by target")
    return fig
