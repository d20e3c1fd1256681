"""Study reports: the document model (:mod:`~studies.report.document`), the self-contained HTML
renderer (:func:`render`), the interactive 3-D view of a robot (:func:`robot_view`) and of a robot in
its work cell (:func:`cell_view`)."""
from studies.report.cell_view import cell_view
from studies.report.document import Document
from studies.report.html import render
from studies.report.view3d import robot_view

__all__ = ["Document", "render", "robot_view", "cell_view"]
