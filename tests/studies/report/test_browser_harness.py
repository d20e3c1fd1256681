"""The headless-Chromium harness (tests/browser.py) passes a good page and catches each defect a
report can have: a broken image, a console error, an uncaught exception, a request to the network,
a plotly graph that never drew, a 3-D view whose WebGL canvas stayed blank or had no WebGL at all."""
from __future__ import annotations

import base64
import io

import numpy as np
import plotly.graph_objects as go
import plotly.io as pio
import plotly.offline
import pytest
from PIL import Image

from tests.browser import drawing_seen

W, H = 40, 30                                  # the embedded PNG's size, checked against naturalWidth/Height


def _png_uri(w=W, h=H) -> str:
    buf = io.BytesIO()
    Image.new("RGB", (w, h), (200, 30, 30)).save(buf, "PNG")
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode()


def _fig3d():
    t = np.linspace(0, 4 * np.pi, 40)
    return go.Figure(go.Scatter3d(x=np.cos(t), y=np.sin(t), z=t / 10, mode="markers+lines", name="helix"),
                     layout=dict(scene=dict(xaxis_title="x (m)", yaxis_title="y (m)", zaxis_title="z (m)")))


def _page(tmp_path, name, body, head=""):
    p = tmp_path / name
    p.write_text(f"<!DOCTYPE html><html><head><meta charset='utf-8'>{head}</head><body>{body}</body></html>")
    return p


@pytest.fixture(scope="module")
def plotly_dir(tmp_path_factory):
    """A folder holding plotly.min.js, for pages that load it as a local file (quicker than embedding)."""
    d = tmp_path_factory.mktemp("plotly")
    (d / "plotly.min.js").write_text(plotly.offline.get_plotlyjs())
    return d


def _local_plot3d(plotly_dir, name, pre_script):
    """A 3-D scatter drawn by the local plotly.min.js, after `pre_script` ran."""
    div = pio.to_html(_fig3d(), include_plotlyjs="directory", full_html=False)
    return _page(plotly_dir, name, div, head=f"<script>{pre_script}</script>")


def test_good_page_passes(report_browser, tmp_path):
    """Self-contained: plotly embedded by to_html, a PNG data URI, a 2-D graph besides the 3-D one."""
    page = pio.to_html(_fig3d(), include_plotlyjs=True, full_html=True, div_id="view3d")
    page2d = pio.to_html(go.Figure(go.Scatter(x=[0, 1, 2], y=[1, 3, 2])), include_plotlyjs=False,
                         full_html=False, div_id="plot2d")
    extra = f"<h1>Study</h1><p>Key number: 0.7747 m</p><img src='{_png_uri()}' alt='red block'>{page2d}"
    path = tmp_path / "good.html"
    path.write_text(page.replace("</body>", extra + "</body>", 1))     # after the embedded plotly.js
    check = report_browser.open_report(path, screenshot=tmp_path / "good.png")
    assert check.problems() == []
    assert (check.images[0].loaded, check.images[0].width, check.images[0].height) == (True, W, H)
    assert [(g.id, g.laid_out, g.scenes, g.drew) for g in check.graphs] == [("view3d", True, 1, True),
                                                                            ("plot2d", True, 0, True)]
    assert "Key number: 0.7747 m" in check.text
    assert check.external_requests == [] and check.console_errors == [] and check.page_errors == []
    assert check.screenshot.stat().st_size > 0


def test_broken_images_are_caught(report_browser, tmp_path):
    """A missing file, a corrupt data URI; the good image sits far below the fold and loads lazily."""
    path = _page(tmp_path, "broken.html", f"<div style='height:3000px'></div><img src='{_png_uri()}' alt='fine' "
                                          "loading='lazy'><img src='missing.png' alt='missing'>"
                                          "<img src='data:image/png;base64,iVBORw0KGgoAAAA=' alt='corrupt'>")
    check = report_browser.open_report(path)
    assert [(i.alt, i.loaded) for i in check.images] == [("fine", True), ("missing", False), ("corrupt", False)]
    assert [i.alt for i in check.broken_images] == ["missing", "corrupt"]
    assert any("missing.png" in r and "ERR_FILE_NOT_FOUND" in r for r in check.failed_requests)
    assert sum("image not loaded" in p for p in check.problems()) == 2


def test_console_errors_and_exceptions_are_caught(report_browser, tmp_path):
    """console.error, a thrown error, an unhandled rejection; and a graph div whose plot never ran."""
    path = _page(tmp_path, "errors.html",
                 "<p>text</p><div class='plotly-graph-div' id='never'></div>"
                 "<script>console.error('rmt console error 42')</script>"
                 "<script>throw new Error('rmt thrown 43')</script>"
                 "<script>Promise.reject(new Error('rmt rejected 44'))</script>"
                 "<script>console.log('only a log'); console.warn('only a warning')</script>")
    check = report_browser.open_report(path, graph_timeout=1)
    assert [e.split(" (")[0] for e in check.console_errors] == ["rmt console error 42"]
    assert any("rmt thrown 43" in e for e in check.page_errors)
    assert any("rmt rejected 44" in e for e in check.page_errors)
    assert check.console_warnings == ["only a warning"]
    assert [(g.id, g.laid_out, g.drew) for g in check.graphs] == [("never", False, False)]
    assert "graph never did not draw" in " ".join(check.problems())


def test_external_requests_are_caught_and_blocked(report_browser, tmp_path):
    path = _page(tmp_path, "external.html",
                 "<img src='http://example.invalid/logo.png' alt='logo'>"
                 "<script src='https://cdn.plot.ly/plotly.min.js'></script>"
                 "<script>fetch('https://example.com/data.json').catch(() => {})</script>")
    check = report_browser.open_report(path)
    assert sorted(check.external_requests) == ["http://example.invalid/logo.png", "https://cdn.plot.ly/plotly.min.js",
                                               "https://example.com/data.json"]
    assert check.broken_images[0].alt == "logo"         # blocked, so not loaded
    assert sum("external request" in p for p in check.problems()) == 3


def test_blank_webgl_canvas_is_caught(report_browser, plotly_dir):
    """WebGL works but draws nothing (draw calls are no-ops): plotly lays out, the canvas stays blank."""
    noop = ("for (const C of [WebGLRenderingContext, WebGL2RenderingContext]) for (const m of "
            "['drawArrays', 'drawElements', 'drawArraysInstanced', 'drawElementsInstanced', 'clear']) "
            "if (C.prototype[m]) C.prototype[m] = function () {};")
    check = report_browser.open_report(_local_plot3d(plotly_dir, "blank.html", noop), graph_timeout=2)
    [g] = check.graphs
    assert (g.laid_out, g.scenes, g.drew) == (True, 1, False)
    assert "blank" in g.detail and "did not draw" in " ".join(check.problems())


def test_missing_webgl_is_caught(report_browser, plotly_dir):
    """No WebGL context to be had: plotly shows its apology instead of the scene."""
    nogl = ("const get = HTMLCanvasElement.prototype.getContext; HTMLCanvasElement.prototype.getContext = "
            "function (t, a) { return /webgl/.test(t) ? null : get.call(this, t, a); };")
    check = report_browser.open_report(_local_plot3d(plotly_dir, "nogl.html", nogl), graph_timeout=2)
    [g] = check.graphs
    assert not g.drew
    assert check.problems()


def test_report_renderer_page_passes(report_browser, tmp_path):
    """A page of studies.report.html (its own 3-D view divs, figures, tables) is recognised and passes."""
    from studies.report.document import Document, Figure, Section, Table, View3D
    from studies.report.html import render
    png = base64.b64decode(_png_uri().split(",", 1)[1])
    doc = Document("Harness check", sections=[Section("S", [Table(["q (rad)"], [[1.2345]]),
                                                            Figure("f.png", png, "a red block"),
                                                            View3D("v", _fig3d(), "a helix")])])
    path = tmp_path / "report.html"
    path.write_text(render(doc))
    check = report_browser.open_report(path)
    assert check.problems() == []
    assert [(i.width, i.height) for i in check.images] == [(W, H)]
    assert [(g.scenes, g.drew) for g in check.graphs] == [(1, True)]
    assert "1.234" in check.text


def test_flat_and_drawn_pictures():
    """The pixel test itself: one flat colour is blank; a picture with lines and colours is a drawing."""
    def png(img):
        buf = io.BytesIO()
        img.save(buf, "PNG")
        return buf.getvalue()
    assert not drawing_seen(png(Image.new("RGB", (100, 80), (255, 255, 255))))
    rng = np.random.default_rng(1)
    arr = np.full((80, 100, 3), 229, np.uint8)
    arr[::10] = rng.integers(0, 255, (8, 100, 3))          # grid-like lines of many colours
    assert drawing_seen(png(Image.fromarray(arr)))


def test_missing_file_is_refused(report_browser, tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.html"):
        report_browser.open_report(tmp_path / "nope.html")


def test_a_hung_page_is_reported_not_waited_for(report_browser, tmp_path):
    """A script that never returns after load: the watchdog kills the browser; the next page still works."""
    hung = _page(tmp_path, "hung.html", "<p>hi</p><script>addEventListener('load', "
                                        "() => setTimeout(() => { while (true) {} }, 0))</script>")
    check = report_browser.open_report(hung, timeout=2)
    assert check.harness_errors and "did not answer" in check.problems()[0]
    fine = report_browser.open_report(_page(tmp_path, "fine.html", "<p>fine 17</p>"))
    assert fine.problems() == [] and "fine 17" in fine.text


class _Ran:
    def __init__(self, returncode):
        self.returncode, self.stdout, self.stderr = returncode, "", f"exit {returncode}"


@pytest.fixture
def fresh_browser_module(monkeypatch):
    """tests.browser with its cached answer forgotten and no Chromium on PATH (until apt 'installs' it)."""
    import tests.browser as tb
    monkeypatch.setattr(tb, "_chromium", None)
    monkeypatch.setattr(tb, "_skip_reason", None)
    monkeypatch.delenv("RMTKIT_CHROMIUM", raising=False)
    return tb


def test_missing_chromium_is_installed_with_apt(fresh_browser_module, monkeypatch):
    """apt-get install fails (stale lists), apt-get update, install again: then Chromium is found."""
    tb = fresh_browser_module
    installed, ran = [], []

    def run(cmd, **kw):
        ran.append(cmd[cmd.index("apt-get"):])
        ok = "update" in cmd or ("install" in cmd and any("update" in c for c in ran))
        if "install" in cmd and ok:
            installed.append(True)
        return _Ran(0 if ok else 100)
    monkeypatch.setattr(tb.os, "geteuid", lambda: 0)
    monkeypatch.setattr(tb.shutil, "which", lambda n: {"apt-get": "/usr/bin/apt-get"}.get(n) or (
        "/usr/bin/chromium" if n == "chromium" and installed else None))
    monkeypatch.setattr(tb.subprocess, "run", run)
    assert tb.ensure_chromium() == "/usr/bin/chromium"
    assert [c[-2:] for c in ran] == [["-y", "chromium"], ["apt-get", "update"], ["-y", "chromium"]]


def test_chromium_that_cannot_be_installed_skips_with_the_command(fresh_browser_module, monkeypatch):
    tb = fresh_browser_module
    monkeypatch.setattr(tb.os, "geteuid", lambda: 1000)
    monkeypatch.setattr(tb.shutil, "which", lambda n: None)
    with pytest.raises(pytest.skip.Exception, match=r"no Chromium found .*no apt-get.*apt-get install -y chromium"):
        tb.ensure_chromium()
    with pytest.raises(pytest.skip.Exception, match="no Chromium found"):      # the answer is kept
        tb.ensure_chromium()
    monkeypatch.setattr(tb, "_skip_reason", None)
    monkeypatch.setenv("RMTKIT_CHROMIUM", "/nonexistent/chromium")
    with pytest.raises(pytest.skip.Exception, match="RMTKIT_CHROMIUM=/nonexistent/chromium is not an executable"):
        tb.ensure_chromium()
