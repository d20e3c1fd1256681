"""``rmt view`` in a browser: the server started as a user starts it (a subprocess, the bundled weld cell,
a path planned by ``rmt plan``), the page loaded in headless Chromium (tests/browser.py), the 3-D canvas
drawn (pixel statistics of a screenshot), a joint moved through the page and the readout compared with
``rmt fk`` (and the cell's placement, read from the cell file), then the server stopped with Ctrl-C
(exit 0, port free again).  ``RMT_DOCS_SCREENSHOTS=1`` also writes docs/img/view-weld-cell.png."""
from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("viser")

ROOT = Path(__file__).resolve().parents[3]
CELL = ROOT / "studies" / "cells" / "fanuc_weld_cell.toml"
ROBOT = "fanuc_lrmate200id"
START = ["0", "0", "0", "0", "-90", "0"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def rmt(*argv, cwd=None, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "studies.cli", *argv], capture_output=True, text=True, cwd=cwd,
                          timeout=timeout)


def start_view(argv, cwd, timeout=240.0):
    """Start ``rmt view`` and wait for the line with its URL; returns (process, url)."""
    p = subprocess.Popen([sys.executable, "-m", "studies.cli", "view", *argv], cwd=cwd, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = p.stdout.readline()
        if not line:
            if p.poll() is not None:
                raise AssertionError(f"rmt view exited {p.returncode}: {p.stderr.read()}")
            continue
        m = re.search(r" at (http://\S+) \(Ctrl-C stops\)", line)
        if m:
            return p, m.group(1)
    p.kill()
    raise AssertionError("rmt view printed no URL in time")


def stop_view(p) -> tuple[int, str]:
    p.send_signal(signal.SIGINT)
    try:
        out, _ = p.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        p.kill()
        raise
    return p.returncode, out


def expected_position(q_deg) -> np.ndarray:
    """The tool position in the cell frame (mm): ``rmt fk`` (base frame) moved by the cell's [robot]
    placement, read from the cell file (rotation about z, y, x by its rpy in degrees)."""
    r = rmt("fk", ROBOT, *[str(v) for v in q_deg], "--json")
    assert r.returncode == 0, r.stderr
    p = np.array(json.loads(r.stdout)["position"])
    cell = tomllib.loads(CELL.read_text())
    assert cell["length_unit"] == "mm" and cell["angle_unit"] == "deg"
    roll, pitch, yaw = np.radians(cell["robot"]["rpy"])
    rz = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    ry = np.array([[np.cos(pitch), 0, np.sin(pitch)], [0, 1, 0], [-np.sin(pitch), 0, np.cos(pitch)]])
    rx = np.array([[1, 0, 0], [0, np.cos(roll), -np.sin(roll)], [0, np.sin(roll), np.cos(roll)]])
    return rz @ ry @ rx @ p + np.array(cell["robot"]["xyz"], float)


def shown_position(text: str) -> np.ndarray | None:
    m = re.search(r"tool \(cell frame, mm\): x (\S+)\s+y (\S+)\s+z (\S+)", text)
    return None if m is None else np.array([float(v) for v in m.groups()])


def joint_input(page, label: str):
    """The number box of the slider labelled ``label`` (viser puts it beside the slider)."""
    row = page.get_by_text(label, exact=True).first.locator("xpath=ancestor::div[.//input][1]")
    return row.locator("input:not([type=hidden])").first


@pytest.mark.slow
def test_weld_cell_view_draws_moves_and_stops(tmp_path, report_browser):
    # the session's one Chromium (tests/studies/conftest.py): a second Playwright in this thread would refuse
    from tests.browser import canvas_stats, drawing_seen
    r = rmt("plan", ROBOT, "--start", *START, "--goal", "40", "20", "-10", "0", "-80", "0", "--margin", "3",
            "--cell", "fanuc_weld_cell", "--out", "weld.csv", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    port = free_port()
    proc, url = start_view([ROBOT, "--cell", "fanuc_weld_cell", "--path", "weld.csv", "--margin", "3", "--port",
                            str(port), "--no-browser"], tmp_path)
    try:
        assert url == f"http://127.0.0.1:{port}"
        # listening on the loopback address only: this machine's other address is refused
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as u:
            u.connect(("10.255.255.255", 1))
            own = u.getsockname()[0]
        if not own.startswith("127."):
            with socket.socket() as s:
                s.settimeout(2)
                assert s.connect_ex((own, port)) != 0
        context = report_browser._launch().new_context(viewport={"width": 1300, "height": 850})
        try:
            page = context.new_page()
            page.goto(url, timeout=60_000)
            page.wait_for_selector("text=tool (cell frame", timeout=60_000)
            text = page.inner_text("body")
            # the start configuration (the path's first row) as rmt fk gives it
            assert np.allclose(shown_position(text), expected_position([0, 0, 0, 0, -90, 0]), atol=1e-3), text
            assert "σ_min" in text and "nearest obstacle" in text and "nearest self pair" in text
            assert "windows" in text
            canvas = page.locator("canvas").first
            deadline = time.monotonic() + 30
            while True:                               # WebGL in software: the first frames may be blank
                png = canvas.screenshot()
                if drawing_seen(png) or time.monotonic() > deadline:
                    break
                time.sleep(0.5)
            share, colours = canvas_stats(png)
            assert drawing_seen(png), f"blank canvas: {colours} colours, top colour {share:.0%}"
            if os.environ.get("RMT_DOCS_SCREENSHOTS") == "1":
                # the browser's "software WebGL" notice is this machine's, not the view's
                page.add_style_tag(content=".mantine-Notification-root { display: none !important; }")
                time.sleep(0.5)
                import io

                from PIL import Image
                shot = Image.open(io.BytesIO(page.screenshot())).convert("RGB")
                shot.quantize(256, dither=Image.Dither.NONE).save(ROOT / "docs" / "img" / "view-weld-cell.png",
                                                                  optimize=True)
            # J1 to 30° through the page: the readout follows, to rmt fk's value
            box = joint_input(page, "J1 [deg]")
            box.fill("30")
            box.press("Enter")
            want = expected_position([30, 0, 0, 0, -90, 0])
            deadline = time.monotonic() + 30
            while True:
                got = shown_position(page.inner_text("body"))
                if (got is not None and np.allclose(got, want, atol=1e-3)) or time.monotonic() > deadline:
                    break
                time.sleep(0.2)
            assert got is not None and np.allclose(got, want, atol=1e-3), (got, want)
        finally:
            context.close()
    finally:
        code, out = stop_view(proc)
    assert code == 0, out
    assert "rmt view: stopped" in out
    with socket.socket() as s:                             # nothing listens there any more
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.bind(("127.0.0.1", port))
        s.listen(1)
