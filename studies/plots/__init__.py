"""Plots: the safe figure writer (:mod:`~studies.plots.figure`), the workspace views
(:mod:`~studies.plots.workspace`), the drawing study (:mod:`~studies.plots.drawing`), tool-path
reports (:mod:`~studies.plots.toolpath`), a tool path followed (:mod:`~studies.plots.follow`), a
planned path beside the straight line (:mod:`~studies.plots.plan`), windows against the dexterity
they leave (:mod:`~studies.plots.windows`), and design figures (:mod:`~studies.plots.design`,
:mod:`~studies.plots.sweep`)."""
from studies.plots.figure import save_figure
from studies.plots.workspace import plot_workspace

__all__ = ["save_figure", "plot_workspace"]
