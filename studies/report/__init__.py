"""Study reports: the document model (:mod:`~studies.report.document`), the self-contained HTML
renderer (:func:`render`) and the interactive 3-D view (:func:`robot_view`)."""
from studies.report.document import Document
from studies.report.html import render
from studies.report.view3d import robot_view

__all__ = ["Document", "render", "robot_view"]
