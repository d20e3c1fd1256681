"""Open an HTML report in headless Chromium and say what a reader would see.

Tests use it through the session fixture ``report_browser`` (tests/studies/conftest.py):

    page = report_browser.open_report(out / "report.html")
    assert not page.problems(), page.problems()
    assert "0.7747" in page.text

`ensure_chromium()` finds Debian's ``chromium`` (installs it with apt-get when running as root, or with
``sudo -n`` where that works) and skips the test with the install command where it cannot.
`PageCheck` holds console errors, uncaught exceptions, failed requests, requests that leave the machine
(a self-contained report makes none; they are blocked, not sent), each image (loaded or not), each plotly
graph (laid out, and for a 3-D scene: the WebGL canvas drew something, judged from its pixels) and the
page text. Every step has a time limit, and a watchdog kills our browser if one is not honoured.

Debug from a shell: ``python -m tests.browser report.html [--screenshot shot.png]``.
"""
from __future__ import annotations

import io
import os
import shutil
import signal
import subprocess
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

# Debian's chromium, no GPU, no sandbox (root), quiet: no background connections. WebGL runs on
# SwiftShader (software); --enable-unsafe-swiftshader keeps it from being refused in newer Chromium.
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
INSTALL_HINT = "install it with `sudo apt-get install -y chromium` (Debian) or set RMTKIT_CHROMIUM=/path/to/chromium"
LOCAL_SCHEMES = ("file:", "data:", "blob:", "about:")
# plotly's graph divs: to_html's, studies/report/html.py's 3-D views, and anything plotly drew into
GRAPH_SELECTOR = ".plotly-graph-div, .plot3d, .js-plotly-plot"

_chromium: str | None = None
_skip_reason: str | None = None


def _skip(reason: str):
    import pytest
    pytest.skip(reason)


def _find_chromium() -> str | None:
    env = os.environ.get("RMTKIT_CHROMIUM")
    if env:
        return env if os.access(env, os.X_OK) else None
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    return None


def _apt_install(deadline: float) -> str:
    """Run apt-get install (and update + install when that fails); returns the output's tail."""
    if not shutil.which("apt-get"):
        return "no apt-get on this machine"
    if os.geteuid() == 0:
        prefix = []
    elif shutil.which("sudo") and subprocess.run(["sudo", "-n", "true"], capture_output=True).returncode == 0:
        prefix = ["sudo", "-n"]
    else:
        return "not root and no password-less sudo"
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    install = prefix + ["apt-get", "-o", "DPkg::Lock::Timeout=120", "install", "-y", "chromium"]
    log = ""
    for cmd in (install, prefix + ["apt-get", "update"], install):
        left = deadline - time.monotonic()
        if left < 5:
            return log + "\n(time limit reached)"
        try:
            r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=left)
        except subprocess.TimeoutExpired:
            return log + f"\n`{' '.join(cmd)}` did not finish in time"
        log = (r.stdout + r.stderr)[-800:]
        if cmd is install and r.returncode == 0:
            return log
    return log


def ensure_chromium(install_timeout: float = 600.0) -> str:
    """The path of a Chromium; installs Debian's `chromium` when missing; otherwise skips the test."""
    global _chromium, _skip_reason
    if _chromium:
        return _chromium
    if _skip_reason:
        _skip(_skip_reason)
    try:
        import playwright.sync_api  # noqa: F401 - only probes that playwright is installed
    except ImportError:
        _skip_reason = "the `playwright` Python package is missing: pip install 'rmtkit[test]' (or playwright)"
        _skip(_skip_reason)
    path = _find_chromium()
    if not path and not os.environ.get("RMTKIT_CHROMIUM"):
        log = _apt_install(time.monotonic() + install_timeout)
        path = _find_chromium()
        if not path:
            _skip_reason = f"no Chromium found and it could not be installed ({log.strip()[-300:]}); {INSTALL_HINT}"
    elif not path:
        _skip_reason = f"RMTKIT_CHROMIUM={os.environ['RMTKIT_CHROMIUM']} is not an executable; {INSTALL_HINT}"
    if _skip_reason:
        _skip(_skip_reason)
    _chromium = path
    return path


@dataclass
class ImageCheck:
    src: str                  # shortened: data URIs as "data:image/png;base64,… (N chars)"
    alt: str
    loaded: bool              # complete and naturalWidth > 0
    width: int                # natural size in pixels
    height: int


@dataclass
class GraphCheck:
    id: str
    laid_out: bool            # plotly ran: the div has _fullLayout
    scenes: int               # 3-D scenes in the layout
    drew: bool                # laid out, and every 3-D scene's WebGL canvas shows a drawing
    detail: str = ""          # why not, or the pixel statistics of the canvases


@dataclass
class PageCheck:
    url: str
    title: str = ""
    text: str = ""            # document.body.innerText
    console_errors: list[str] = field(default_factory=list)
    console_warnings: list[str] = field(default_factory=list)
    page_errors: list[str] = field(default_factory=list)        # uncaught exceptions, unhandled rejections
    failed_requests: list[str] = field(default_factory=list)
    external_requests: list[str] = field(default_factory=list)  # anything not file:/data:/blob: (blocked)
    images: list[ImageCheck] = field(default_factory=list)
    graphs: list[GraphCheck] = field(default_factory=list)
    harness_errors: list[str] = field(default_factory=list)     # time limits hit, browser died
    screenshot: Path | None = None
    seconds: float = 0.0

    @property
    def broken_images(self) -> list[ImageCheck]:
        return [i for i in self.images if not i.loaded]

    @property
    def undrawn_graphs(self) -> list[GraphCheck]:
        return [g for g in self.graphs if not g.drew]

    def problems(self) -> list[str]:
        """One line per defect a reader would meet; empty for a good page."""
        out = [f"harness: {e}" for e in self.harness_errors]
        out += [f"console error: {e}" for e in self.console_errors]
        out += [f"page error: {e}" for e in self.page_errors]
        out += [f"failed request: {e}" for e in self.failed_requests]
        out += [f"external request (a self-contained report makes none): {e}" for e in self.external_requests]
        out += [f"image not loaded: {i.src} (alt {i.alt!r})" for i in self.broken_images]
        out += [f"graph {g.id} did not draw: {g.detail}" for g in self.undrawn_graphs]
        return out


# --- the page side --------------------------------------------------------------------------------

_GRAPHS_JS = """(sel) => [...new Set(document.querySelectorAll(sel))]
  .filter(el => !el.parentElement.closest(sel))
  .map((el, i) => {
    const fl = el._fullLayout, scenes = fl && fl._subplots && fl._subplots.gl3d ? fl._subplots.gl3d : [];
    const canvases = [...el.querySelectorAll('.gl-container canvas')];
    canvases.forEach((c, j) => c.setAttribute('data-rmt-check', `g${i}c${j}`));
    return {id: el.id || `#${i}`, laid_out: !!fl, scenes: scenes.length,
            canvases: canvases.map((c, j) => ({key: `g${i}c${j}`, w: c.clientWidth, h: c.clientHeight})),
            text: (el.innerText || '').slice(0, 200)};
  })"""
_READY_JS = """(sel) => [...document.querySelectorAll(sel)]
  .every(el => el._fullLayout || el.querySelector('.js-plotly-plot'))
  && [...document.images].every(im => im.complete)"""
_IMAGES_JS = """() => [...document.images].map(im => ({src: im.currentSrc || im.getAttribute('src') || '',
  alt: im.alt || '', loaded: im.complete && im.naturalWidth > 0, width: im.naturalWidth, height: im.naturalHeight}))"""
# hidden while a canvas is photographed: plotly's SVG layers and the mode bar sit above the WebGL canvas
_HIDE_OVERLAYS = "svg, .modebar-container { visibility: hidden !important; }"


def _short(url: str) -> str:
    if url.startswith("data:"):
        return f"{url[:30]}… ({len(url)} chars)"
    return url if len(url) <= 200 else url[:200] + "…"


def canvas_stats(png: bytes) -> tuple[float, int]:
    """(share of the most common colour, number of distinct colours) of a PNG screenshot."""
    from PIL import Image
    im = Image.open(io.BytesIO(png)).convert("RGB")
    colours = im.getcolors(maxcolors=im.width * im.height)
    top = max(n for n, _ in colours)
    return top / (im.width * im.height), len(colours)


def drawing_seen(png: bytes) -> bool:
    """A drawn plotly scene has axes panes, grid lines and markers; a blank canvas is one flat colour."""
    share, n = canvas_stats(png)
    return share < 0.98 and n >= 8


def _our_browser_pids() -> list[int]:
    """The chromium processes started by this Python process (through playwright's driver), topmost only."""
    parent: dict[int, int] = {}
    comm: dict[int, str] = {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                stat = Path(f"/proc/{d}/stat").read_text()
            except OSError:
                continue
            name, rest = stat[stat.index("(") + 1:stat.rindex(")")], stat[stat.rindex(")") + 2:].split()
            parent[int(d)], comm[int(d)] = int(rest[1]), name
    ours, me = [], os.getpid()
    for pid in parent:
        chain, p = [], pid
        while p in parent and p not in (0, 1, me):
            chain.append(p)
            p = parent[p]
        if p == me and comm[pid].startswith("chrom") and not comm.get(parent[pid], "").startswith("chrom"):
            ours.append(pid)
    return ours


class ReportBrowser:
    """One headless Chromium for many pages; relaunched when it died."""

    def __init__(self, executable: str | None = None, args: list[str] | None = None, launch_timeout: float = 60.0):
        self.executable = executable or ensure_chromium()
        self.args = list(CHROMIUM_ARGS if args is None else args)
        self.launch_timeout = launch_timeout
        self._pw = None
        self._browser = None

    def _launch(self):
        from playwright.sync_api import sync_playwright
        if self._pw is None:
            self._pw = sync_playwright().start()
        if self._browser is None or not self._browser.is_connected():
            self._browser = self._pw.chromium.launch(executable_path=self.executable, args=self.args,
                                                     timeout=self.launch_timeout * 1000)
        return self._browser

    def close(self):
        for step in (lambda: self._browser and self._browser.close(), lambda: self._pw and self._pw.stop()):
            try:
                step()
            except Exception:
                pass
        self._browser = self._pw = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def open_report(self, path, *, timeout: float = 60.0, graph_timeout: float = 20.0, screenshot=None,
                    viewport: tuple[int, int] = (1300, 900)) -> PageCheck:
        """Load a local HTML file, wait for its images and plotly graphs, and check what it shows.

        timeout bounds each step (the watchdog kills the browser at 1.25 timeout + 5 s); graph_timeout
        bounds the wait for plotly graphs to lay out and for each 3-D canvas to show a drawing.
        screenshot: a PNG path for a full-page screenshot."""
        path = Path(path).resolve()
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no such report file")
        check = PageCheck(url=path.as_uri())
        t0 = time.monotonic()
        limit = 1.25 * timeout + 5.0
        killed = threading.Event()
        watchdog = threading.Timer(limit, lambda: (killed.set(), self._kill()))
        watchdog.daemon = True
        watchdog.start()
        try:
            self._check(check, timeout, graph_timeout, screenshot, viewport)
        except Exception as e:   # time limits, a browser that died: reported, never hung on
            check.harness_errors.append(f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
        finally:
            watchdog.cancel()
            check.seconds = time.monotonic() - t0
        if killed.is_set():
            check.harness_errors.insert(0, f"the page did not answer: browser killed after {limit:.0f} s")
        return check

    def _kill(self):
        for pid in _our_browser_pids():
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass

    def _check(self, check: PageCheck, timeout, graph_timeout, screenshot, viewport):
        from playwright.sync_api import TimeoutError as PwTimeout
        deadline = time.monotonic() + timeout
        left_ms = lambda: max(1000.0, (deadline - time.monotonic()) * 1000)
        context = self._launch().new_context(viewport={"width": viewport[0], "height": viewport[1]})
        try:
            context.set_default_timeout(timeout * 1000)

            def on_request(req):
                if not req.url.startswith(LOCAL_SCHEMES):
                    check.external_requests.append(_short(req.url))

            def on_response(resp):
                if resp.status >= 400:
                    check.failed_requests.append(f"{_short(resp.url)}: HTTP {resp.status}")

            def on_console(msg):
                loc = msg.location or {}
                where = f" ({_short(loc['url'])}:{loc.get('lineNumber')})" if loc.get("url") else ""
                if msg.type == "error":
                    check.console_errors.append(msg.text + where)
                elif msg.type == "warning":
                    check.console_warnings.append(msg.text)

            # nothing leaves the machine: every non-local request is recorded and aborted
            context.route(lambda url: not url.startswith(LOCAL_SCHEMES), lambda route: route.abort())
            page = context.new_page()
            page.on("request", on_request)
            page.on("response", on_response)
            page.on("console", on_console)
            page.on("pageerror", lambda e: check.page_errors.append(f"{e.name}: {e.message}".strip(": ")))
            page.on("requestfailed", lambda r: r.url.startswith(LOCAL_SCHEMES) and check.failed_requests.append(
                f"{_short(r.url)}: {r.failure}"))
            page.goto(check.url, wait_until="load", timeout=left_ms())
            graph_deadline = time.monotonic() + graph_timeout
            page.evaluate("() => document.querySelectorAll('img[loading=lazy]').forEach(im => im.loading = 'eager')")
            try:
                page.wait_for_function(_READY_JS, arg=GRAPH_SELECTOR, polling=100,
                                       timeout=min(graph_timeout * 1000, left_ms()))
            except PwTimeout:
                pass                                  # reported below: graphs not laid out / images incomplete
            check.title = page.title()
            check.images = [ImageCheck(_short(i["src"]), i["alt"], i["loaded"], i["width"], i["height"])
                            for i in page.evaluate(_IMAGES_JS)]
            check.graphs = self._graphs(page, graph_deadline, deadline)
            check.text = page.evaluate("() => document.body ? document.body.innerText : ''")
            if screenshot:
                page.screenshot(path=str(screenshot), full_page=True, timeout=left_ms())
                check.screenshot = Path(screenshot)
        finally:
            try:
                context.close()
            except Exception:
                pass

    def _graphs(self, page, graph_deadline: float, deadline: float) -> list[GraphCheck]:
        out = []
        for g in page.evaluate(_GRAPHS_JS, GRAPH_SELECTOR):
            gc = GraphCheck(g["id"], g["laid_out"], g["scenes"], False)
            if not gc.laid_out:
                gc.detail = "plotly did not lay it out (no _fullLayout)" + (f"; it shows {g['text']!r}"
                                                                           if g["text"].strip() else "")
            elif gc.scenes and len(g["canvases"]) < gc.scenes:
                gc.detail = (f"{gc.scenes} 3-D scene(s) but {len(g['canvases'])} WebGL canvas(es)"
                             + (f"; it shows {g['text']!r}" if g["text"].strip() else ""))
            elif not gc.scenes:
                gc.drew, gc.detail = True, "no 3-D scene (SVG graph)"
            else:
                gc.drew, gc.detail = self._canvases_drew(page, g["canvases"], graph_deadline, deadline)
            out.append(gc)
        return out

    def _canvases_drew(self, page, canvases, graph_deadline, deadline) -> tuple[bool, str]:
        """Photograph each WebGL canvas (overlays hidden) until it shows a drawing or time runs out."""
        details = []
        for c in canvases:
            if not (c["w"] and c["h"]):
                return False, f"canvas {c['key']} has no size ({c['w']}x{c['h']})"
            loc = page.locator(f"[data-rmt-check='{c['key']}']")
            while True:
                left = min(graph_deadline, deadline) - time.monotonic()
                png = loc.screenshot(style=_HIDE_OVERLAYS, animations="disabled",
                                     timeout=max(1000.0, (deadline - time.monotonic()) * 1000))
                share, n = canvas_stats(png)
                if drawing_seen(png):
                    details.append(f"{c['w']}x{c['h']}: {n} colours, top colour {share:.0%}")
                    break
                if left <= 0:
                    return False, (f"WebGL canvas {c['w']}x{c['h']} is blank: {n} colour(s), "
                                   f"top colour covers {share:.0%}")
                time.sleep(0.25)
        return True, "; ".join(details)


def main(argv=None) -> int:
    import argparse
    ap = argparse.ArgumentParser(prog="python -m tests.browser", description="check an HTML report in Chromium")
    ap.add_argument("report")
    ap.add_argument("--screenshot")
    a = ap.parse_args(argv)
    t0 = time.monotonic()
    with ReportBrowser(_find_chromium()) as b:
        page = b.open_report(a.report, screenshot=a.screenshot)
    print(f"{page.url}: {len(page.images)} image(s), {len(page.graphs)} graph(s), {len(page.text)} chars of text, "
          f"check {page.seconds:.1f} s, total {time.monotonic() - t0:.1f} s")
    for g in page.graphs:
        print(f"  graph {g.id}: drew={g.drew} {g.detail}")
    for p in page.problems():
        print("  PROBLEM", p)
    return 1 if page.problems() else 0


if __name__ == "__main__":
    raise SystemExit(main())
