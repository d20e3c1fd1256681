"""The content of a study report, independent of how it is rendered: a title, findings, and sections
of blocks (paragraphs, tables, figures, interactive 3-D views).

A study builds a :class:`Document` through :class:`studies.study.Study`; :func:`studies.report.html.render`
turns it into one self-contained HTML file.  Figures are kept as PNG bytes (embedded as data URIs in
the HTML and also written beside it); 3-D views are plotly figures (serialised to JSON, drawn by
the plotly.js embedded once in the page).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass
class Paragraph:
    """Text with a small inline markup: ``code`` and **bold**; a blank line starts a new paragraph."""
    text: str


@dataclass
class Table:
    """A table of values; numbers are formatted with ``fmt`` (a format spec such as ``".4g"``).
    ``None`` prints as an em dash.  Units belong in the header strings."""
    header: list[str]
    rows: list[list[Any]]
    caption: str = ""
    fmt: str = ".4g"


@dataclass
class Figure:
    """A PNG image: ``name`` is its file name (``name.png`` beside the report)."""
    name: str
    png: bytes
    caption: str = ""


@dataclass
class View3D:
    """An interactive plotly figure (a ``plotly.graph_objects.Figure``)."""
    name: str
    figure: Any
    caption: str = ""


@dataclass
class Code:
    """Preformatted text (a robot file, a command line)."""
    text: str
    caption: str = ""
    collapsed: bool = False


@dataclass
class Section:
    title: str
    blocks: list = field(default_factory=list)
    seconds: float | None = None


@dataclass
class Finding:
    """One sentence for the top of the report (and the terminal summary); ``ok`` False marks a
    failure or a defect found."""
    text: str
    ok: bool = True


@dataclass
class Document:
    title: str
    summary: str = ""
    findings: list[Finding] = field(default_factory=list)
    sections: list[Section] = field(default_factory=list)
    #: (label, value) rows of the appendix tables
    inputs: list[tuple[str, Any]] = field(default_factory=list)
    versions: list[tuple[str, str]] = field(default_factory=list)
    robot_files: list[tuple[str, str]] = field(default_factory=list)   # (path, text)
    meta: dict = field(default_factory=dict)
