"""The HTML renderer: text is escaped before markup, numbers are formatted without lying (−0, NaN,
None), figures are embedded byte for byte, plotly.js is embedded once and only when a 3-D view is
there, and nothing in a view's data can close its script element."""
from __future__ import annotations

import base64
import re

import numpy as np
import plotly.graph_objects as go
import pytest

from studies.report.document import Document, Figure, Finding, Paragraph, Section, Table, View3D
from studies.report.html import format_value, render


def _doc(*blocks, findings=()):
    return Document(title="T <1>", summary="a & b", findings=list(findings), sections=[Section("S", list(blocks), 1.5)])


def test_text_is_escaped_before_markup():
    page = render(_doc(Paragraph("x <script>alert(1)</script> `a<b` **bold**"),
                       findings=[Finding("<img src=x onerror=alert(1)>", ok=False)]))
    assert "<script>alert(1)</script>" not in page and "&lt;script&gt;alert(1)&lt;/script&gt;" in page
    assert "<code>a&lt;b</code>" in page and "<strong>bold</strong>" in page
    assert "<img src=x" not in page and 'class="bad"' in page
    assert "<title>T &lt;1&gt;</title>" in page


@pytest.mark.parametrize("value, fmt, text", [
    (None, ".4g", "—"), (float("nan"), ".4g", "—"), (float("inf"), ".4g", "∞"), (-float("inf"), ".3f", "−∞"),
    (-0.0, ".3f", "0"), (-1e-20, ".3f", "0"), (-2.5, ".3g", "−2.5"), (True, ".4g", "yes"), (12345, ".4g", "12,345"),
    (np.float64(0.123456), ".3g", "0.123"), ("text", ".4g", "text"),
])
def test_format_value(value, fmt, text):
    assert format_value(value, fmt) == text


def test_table_cells_and_caption():
    page = render(_doc(Table(["joint", "a (m)"], [["q1", 0.15], ["q2", None]], caption="DH `x`")))
    rows = re.findall(r"<tr>(.*?)</tr>", page)
    assert '<td class="text">q1</td><td>0.15</td>' in rows[1] and "<td>—</td>" in rows[2]
    assert "DH <code>x</code>" in page


def test_figure_embedded_byte_for_byte():
    png = bytes(range(256)) * 3
    page = render(_doc(Figure("plot.png", png, "cap")))
    [data] = re.findall(r'src="data:image/png;base64,([^"]+)"', page)
    assert base64.b64decode(data) == png


def test_plotly_embedded_once_only_with_views():
    assert "Plotly.newPlot" not in render(_doc(Paragraph("no view")))
    fig = go.Figure(go.Scatter3d(x=[0, 1], y=[0, 1], z=[0, 1], name="</script><script>alert(1)</script>"))
    page = render(_doc(View3D("a", fig), View3D("b", fig)))
    import plotly.offline
    assert page.count(plotly.offline.get_plotlyjs()[:2000]) == 1        # the library, once
    assert page.count('class="plot3d"') == 2
    assert "</script><script>alert(1)" not in page


def test_no_network_references_outside_plotly():
    fig = go.Figure(go.Scatter3d(x=[0], y=[0], z=[0]))
    page = render(_doc(View3D("a", fig), Figure("f.png", b"\x89PNG")))
    import plotly.offline
    rest = page.replace(plotly.offline.get_plotlyjs(), "")
    assert not re.search(r'(src|href)="(https?:)?//', rest)


@pytest.mark.parametrize("text, shown", [
    ("deviation 2e-16 m", "deviation 2e−16 m"), ("q = (0, -0.8)", "q = (0, −0.8)"), ("[-0.05, 0.05]", "[−0.05, 0.05]"),
    ("L-shaped, learned-IK", "L-shaped, learned-IK"), ("2026-11-23", "2026-11-23"), ("q1-3", "q1-3"),
    ("`q-1 -2` and -3", "<code>q-1 -2</code> and −3"),
])
def test_minus_signs_outside_code(text, shown):
    from studies.report.html import _inline
    assert _inline(text) == shown
