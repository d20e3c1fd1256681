"""The plot under ``rmt view``'s timeline: σ_min (SI) and the clearance (mm) along the path or trajectory,
the σ_min floor as a dashed line and the stretches inside a window shaded (plotly)."""
from __future__ import annotations

import numpy as np

from studies.view.playback import PLOT_SAMPLES, path_profile

__all__ = ["profile_figure", "window_runs"]


def window_runs(s: np.ndarray, inside: np.ndarray) -> list[tuple[float, float]]:
    """The stretches (start, end) of timeline values ``s`` where ``inside`` holds, each from its first
    to its last sample."""
    runs, start = [], None
    for k, flag in enumerate(np.asarray(inside, bool)):
        if flag and start is None:
            start = k
        if start is not None and (not flag or k == len(s) - 1):
            end = k if flag else k - 1
            runs.append((float(s[start]), float(s[end])))
            start = None
    return runs


def profile_figure(model, timeline, m: int = PLOT_SAMPLES):
    """A plotly figure of σ_min and the clearance at ``m`` values of ``timeline`` (a
    :class:`studies.view.playback.Timeline`) for ``model`` (:class:`studies.view.readouts.LiveModel`)."""
    import plotly.graph_objects as go
    p = path_profile(model, timeline, m)
    s = p["s"]
    fig = go.Figure()
    fig.add_trace(go.Scatter(x=s, y=p["sigma_min"], name="σ_min (SI)", line=dict(color="#1f77b4")))
    if np.isfinite(p["clearance"]).any():
        fig.add_trace(go.Scatter(x=s, y=p["clearance"] * 1e3, name="clearance (mm)", yaxis="y2",
                                 line=dict(color="#2ca02c")))
    if model.floor is not None:
        fig.add_hline(y=model.floor, line=dict(color="#d62728", dash="dash"), annotation_text="σ_min floor")
    for a, b in window_runs(s, p["in_window"]):
        fig.add_vrect(x0=a, x1=b if b > a else a + 1e-9 * max(1.0, abs(a)), fillcolor="#9467bd", opacity=0.25,
                      line_width=0, annotation_text="window")
    fig.update_layout(margin=dict(l=40, r=40, t=10, b=30), height=260, legend=dict(orientation="h", y=-0.25),
                      xaxis=dict(title=f"timeline ({timeline.unit})"),
                      yaxis=dict(title="σ_min (SI)", rangemode="tozero"),
                      yaxis2=dict(title="clearance (mm)", overlaying="y", side="right", showgrid=False))
    return fig
