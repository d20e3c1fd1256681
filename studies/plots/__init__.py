"""Plots: the safe figure writer (:mod:`~studies.plots.figure`), the workspace views
(:mod:`~studies.plots.workspace`), the drawing study (:mod:`~studies.plots.drawing`) and tool-path
reports (:mod:`~studies.plots.toolpath`)."""
from studies.plots.figure import save_figure
from studies.plots.workspace import plot_workspace

__all__ = ["save_figure", "plot_workspace"]
