"""``rmt view --html``: one self-contained page, loaded offline in headless Chromium (tests/browser.py):
no request leaves the machine (all are blocked and recorded), the 3-D canvas is drawn (pixel
statistics), and a joint slider moved through the page moves the tool readout to the pose ``rmt fk``
gives.  ``RMT_DOCS_SCREENSHOTS=1`` also writes docs/img/view-html-*.png."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kin

ROOT = Path(__file__).resolve().parents[3]
CELL = ROOT / "studies" / "cells" / "fanuc_weld_cell.toml"
SHOTS = os.environ.get("RMT_DOCS_SCREENSHOTS") == "1"


def rmt(*argv, cwd=None):
    return subprocess.run([sys.executable, "-m", "studies.cli", *argv], capture_output=True, text=True, cwd=cwd,
                          timeout=300)


def test_html_refuses_a_wrong_suffix(tmp_path):
    r = rmt("view", "planar_2r", "--html", str(tmp_path / "page.htm"))
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0 and "--html" in r.stderr


@pytest.mark.slow
def test_weld_cell_page_is_offline_and_drawn(tmp_path, report_browser):
    path = tmp_path / "path.csv"
    np.savetxt(path, [[0, 0, 0, 0, -90, 0], [30, 10, -10, 0, -80, 20]], delimiter=",", header="q1,q2,q3,q4,q5,q6",
               comments="")
    out = tmp_path / "weld.html"
    r = rmt("view", "fanuc_lrmate200id", "--cell", str(CELL), "--path", str(path), "--html", str(out))
    assert r.returncode == 0, r.stderr
    shot = ROOT / "docs" / "img" / "view-html-weld-cell.png" if SHOTS else tmp_path / "shot.png"
    page = report_browser.open_report(out, screenshot=shot)
    assert not page.external_requests and not page.problems(), page.problems()
    assert page.graphs and all(g.drew and g.scenes for g in page.graphs)
    assert "capsules" in page.text


@pytest.mark.slow
def test_panda_page_moves_the_meshes_with_a_slider(tmp_path, report_browser):
    from studies.shape.meshes import visual_meshes
    from studies.view.html import write_view_html
    robot = kin.Robot(kin.load_chain("franka_panda"))
    if visual_meshes(robot) is None:
        pytest.skip("example-robot-data is not installed: the Panda has no meshes")
    q0 = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    out = write_view_html(robot, out=tmp_path / "panda.html", q=q0)
    check = report_browser.open_report(out)
    assert not check.external_requests and not check.problems(), check.problems()
    assert "drawn as its meshes" in check.text
    browser = report_browser._launch()
    context = browser.new_context(viewport={"width": 1300, "height": 900})
    asked = []
    context.route(lambda url: not url.startswith(("file:", "data:", "blob:", "about:")),
                  lambda route: (asked.append(route.request.url), route.abort()))
    try:
        page = context.new_page()
        page.goto(Path(out).as_uri())
        page.wait_for_function("() => document.body.dataset.ready === '1'", timeout=60_000)
        before = page.eval_on_selector("#scene", "el => el.data[0].x.slice(0, 50)")
        q = q0.copy()
        q[1] = 0.4
        page.eval_on_selector("input[data-joint='1']", "(el, v) => { el.value = v; "
                              "el.dispatchEvent(new Event('input')); }", str(q[1]))
        page.wait_for_function("() => document.body.dataset.moved === '1'", timeout=30_000)
        q = np.array(page.eval_on_selector_all("input[data-joint]", "els => els.map(el => +el.value)"))
        text = page.inner_text("#readout")
        after = page.eval_on_selector("#scene", "el => el.data[0].x.slice(0, 50)")
        if SHOTS:
            page.screenshot(path=str(ROOT / "docs" / "img" / "view-html-panda.png"))
    finally:
        context.close()
    assert not asked
    assert before != after
    xyz = [float(v) for v in text.splitlines()[0].split(":")[1].split()]
    fk = json.loads(rmt("fk", "franka_panda", *[repr(float(v)) for v in q], "--json").stdout)
    want = fk["position"]
    np.testing.assert_allclose(xyz, want, atol=2e-6)
