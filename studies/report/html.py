"""One self-contained HTML file from a :class:`~studies.report.document.Document`: styles inline,
figures as PNG data URIs, plotly.js embedded once (offline), no request to any network.

Text is escaped before the small inline markup (``code``, **bold**) is applied, so nothing a study or
a user's file says can inject markup or script into the page.
"""
from __future__ import annotations

import base64
import html
import json
import math
import re
from numbers import Real

from studies.report.document import Code, Document, Figure, Paragraph, Table, View3D

__all__ = ["render", "format_value"]

_STYLE = """
:root { --ink:#1d2733; --muted:#5b6775; --line:#d9dee4; --accent:#2f5d8a; --bad:#b42318; --good:#1f7a3f; }
* { box-sizing: border-box; }
body { font: 15px/1.55 system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif; color: var(--ink);
       margin: 0; background: #f6f7f9; }
main { max-width: 1180px; margin: 0 auto; padding: 24px 32px 64px; background: #fff; }
h1 { font-size: 28px; margin: 8px 0 4px; } h2 { font-size: 21px; margin: 36px 0 10px; padding-top: 10px;
     border-top: 1px solid var(--line); } h3 { font-size: 16px; margin: 22px 0 6px; }
.meta { color: var(--muted); font-size: 13px; }
.summary { font-size: 15.5px; }
ul.findings { list-style: none; padding: 0; margin: 14px 0; }
ul.findings li { padding: 8px 12px; margin: 6px 0; border-left: 4px solid var(--good); background: #f2f8f4; }
ul.findings li.bad { border-left-color: var(--bad); background: #fdf3f2; }
nav.toc { font-size: 14px; } nav.toc a { color: var(--accent); text-decoration: none; margin-right: 14px; }
table { border-collapse: collapse; margin: 10px 0 4px; font-size: 13.5px; }
th, td { padding: 4px 10px; border-bottom: 1px solid var(--line); text-align: right; vertical-align: top; }
th { background: #eef1f4; font-weight: 600; } td:first-child, th:first-child { text-align: left; }
td.text { text-align: left; }
.caption { color: var(--muted); font-size: 13px; margin: 2px 0 16px; white-space: pre-line; }
figure { margin: 14px 0 18px; } figure img { max-width: 100%; height: auto; border: 1px solid var(--line); }
.plot3d { width: 100%; height: 640px; border: 1px solid var(--line); }
pre { background: #f3f5f7; padding: 10px 12px; overflow-x: auto; font-size: 12.5px; }
code { background: #f0f2f5; padding: 0 3px; border-radius: 3px; font-size: 90%; }
details summary { cursor: pointer; color: var(--accent); }
.seconds { color: var(--muted); font-size: 12.5px; font-weight: normal; }
"""


def _minus(t: str) -> str:
    """A hyphen that is a minus sign (before a digit, not inside a word or a date; in an exponent)
    becomes the true minus sign "−" that the report's numbers use."""
    t = re.sub(r"(?<=\d)e-(?=\d)", "e−", t)
    return re.sub(r"(?<![\w.−])-(?=\.?\d)", "−", t)


def _inline(text: str) -> str:
    """Escaped text with ``code`` and **bold**; minus signs outside code made true minus signs."""
    parts = html.escape(text, quote=False).split("`")
    out = []
    for k, part in enumerate(parts):
        if k % 2 == 1 and k < len(parts) - 1:           # inside a closed `code` span: verbatim
            out.append(f"<code>{part}</code>")
        else:
            out.append(_minus(part) if k % 2 == 0 else "`" + _minus(part))
    return re.sub(r"\*\*([^*]+)\*\*", r"<strong>\1</strong>", "".join(out))


def format_value(v, fmt: str = ".4g") -> str:
    """A table cell: numbers with ``fmt`` (−0 shown as 0), None/NaN as an em dash, booleans as yes/no."""
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, Real):
        x = float(v)
        if not math.isfinite(x):
            return "—" if math.isnan(x) else ("∞" if x > 0 else "−∞")
        if isinstance(v, int) and not fmt.endswith("%"):
            return f"{v:,}"
        s = format(x, fmt)
        return "0" if re.fullmatch(r"-0(\.0*)?(e[+-]?0+)?", s) else s.replace("-", "−")
    return str(v)


def _slug(title: str, used: set) -> str:
    base = re.sub(r"[^a-z0-9]+", "-", title.lower()).strip("-") or "section"
    slug, k = base, 2
    while slug in used:
        slug, k = f"{base}-{k}", k + 1
    used.add(slug)
    return slug


def _table(t: Table) -> str:
    head = "".join(f"<th>{_inline(h)}</th>" for h in t.header)
    body = []
    for row in t.rows:
        cells = []
        for v in row:
            cls = ' class="text"' if isinstance(v, str) else ""
            cells.append(f"<td{cls}>{_inline(format_value(v, t.fmt))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    cap = f'<div class="caption">{_inline(t.caption)}</div>' if t.caption else ""
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>{cap}"


def _figure(f: Figure) -> str:
    data = base64.b64encode(f.png).decode("ascii")
    alt = html.escape(f.caption or f.name)
    cap = f'<figcaption class="caption">{_inline(f.caption)}</figcaption>' if f.caption else ""
    return (f'<figure><img src="data:image/png;base64,{data}" alt="{alt}" data-name="{html.escape(f.name)}">'
            f'{cap}</figure>')


def figure_json(fig) -> str:
    """A plotly figure's data, layout and frames as strict JSON to hold in a ``<script>`` element (numpy
    values as lists and numbers; ``</`` escaped, so the data never closes the element)."""
    spec = fig.to_plotly_json()
    payload = json.dumps({"data": spec.get("data", []), "layout": spec.get("layout", {}),
                          "frames": spec.get("frames", [])}, allow_nan=False, default=_json_default)
    return payload.replace("</", "<\\/")


def _view3d(v: View3D, idx: int) -> str:
    payload = figure_json(v.figure)
    div = f"plot3d-{idx}"
    cap = f'<div class="caption">{_inline(v.caption)}</div>' if v.caption else ""
    return (f'<div id="{div}" class="plot3d" data-name="{html.escape(v.name)}"></div>{cap}'
            f'<script type="application/json" id="{div}-data">{payload}</script>'
            f"<script>rmtPlot({json.dumps(div)});</script>")


def _json_default(o):
    import numpy as np
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    raise TypeError(f"not JSON-serialisable: {type(o).__name__}")


_PLOT_JS = """
function rmtPlot(id) {
  var el = document.getElementById(id);
  var spec = JSON.parse(document.getElementById(id + '-data').textContent);
  Plotly.newPlot(el, spec.data, spec.layout, {responsive: true, displaylogo: false}).then(function () {
    if (spec.frames && spec.frames.length) { return Plotly.addFrames(el, spec.frames); }
  }).then(function () { el.setAttribute('data-drawn', 'yes'); });
}
"""


def _code(c: Code) -> str:
    pre = f"<pre>{html.escape(c.text)}</pre>"
    if c.collapsed:
        return f"<details><summary>{_inline(c.caption or 'show')}</summary>{pre}</details>"
    cap = f'<div class="caption">{_inline(c.caption)}</div>' if c.caption else ""
    return pre + cap


def render(doc: Document) -> str:
    """The whole report as one HTML string."""
    import plotly.offline

    used: set = set()
    views = 0
    parts = []
    toc = []
    for sec in doc.sections:
        slug = _slug(sec.title, used)
        toc.append(f'<a href="#{slug}">{_inline(sec.title)}</a>')
        secs = f' <span class="seconds">({sec.seconds:.1f} s)</span>' if sec.seconds is not None else ""
        parts.append(f'<section id="{slug}"><h2>{_inline(sec.title)}{secs}</h2>')
        for b in sec.blocks:
            if isinstance(b, Paragraph):
                parts += [f"<p>{_inline(p.strip())}</p>" for p in b.text.split("\n\n") if p.strip()]
            elif isinstance(b, Table):
                parts.append(_table(b))
            elif isinstance(b, Figure):
                parts.append(_figure(b))
            elif isinstance(b, View3D):
                views += 1
                parts.append(_view3d(b, views))
            elif isinstance(b, Code):
                parts.append(_code(b))
            elif isinstance(b, str):
                parts.append(f"<h3>{_inline(b)}</h3>")
            else:                                   # pragma: no cover - a programming error
                raise TypeError(f"unknown report block {type(b).__name__}")
        parts.append("</section>")
    appendix = _appendix(doc)
    toc.append('<a href="#inputs-and-software">Inputs, software, timings</a>')
    findings = "".join(f'<li class="{"" if f.ok else "bad"}">{_inline(f.text)}</li>' for f in doc.findings)
    meta = " · ".join(_inline(str(x)) for x in doc.meta.get("line", []))
    plotly_js = plotly.offline.get_plotlyjs() if views else ""
    summary = "".join(f'<p class="summary">{_inline(p.strip())}</p>' for p in doc.summary.split("\n\n") if p.strip())
    return "\n".join([
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{html.escape(doc.title)}</title><style>{_STYLE}</style>",
        f"<script>{plotly_js}</script><script>{_PLOT_JS}</script>" if views else "",
        "</head><body><main>",
        f"<h1>{_inline(doc.title)}</h1>", f'<div class="meta">{meta}</div>', summary,
        f'<ul class="findings">{findings}</ul>' if findings else "",
        f'<nav class="toc">{" ".join(toc)}</nav>',
        *parts, appendix, "</main></body></html>",
    ])


def _appendix(doc: Document) -> str:
    out = ['<section id="inputs-and-software"><h2>Inputs, software, timings</h2>']
    if doc.inputs:
        out += ["<h3>Inputs</h3>", _table(Table(["input", "value"], [[k, v] for k, v in doc.inputs]))]
    for path, text in doc.robot_files:
        out.append(_code(Code(text, caption=f"robot file `{path}`", collapsed=True)))
    timings = [[s.title, s.seconds] for s in doc.sections if s.seconds is not None]
    if timings:
        total = doc.meta.get("seconds")
        out += ["<h3>Timings</h3>", _table(Table(["section", "wall time (s)"],
                                                 timings + ([["total", total]] if total is not None else []),
                                                 fmt=".2f"))]
    if doc.versions:
        out += ["<h3>Software</h3>", _table(Table(["package", "version"], [list(v) for v in doc.versions]))]
    out.append("</section>")
    return "\n".join(out)
