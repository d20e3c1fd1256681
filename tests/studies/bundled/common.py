"""What every bundled study's tests share: one quick run of the study with its results.json read as
strict JSON, and the browser check of its report — it renders in headless Chromium with no console
error and no network request, every figure it lists loads, its 3-D views draw, and its findings and
key numbers are on the page as a reader sees it (``innerText``)."""
from __future__ import annotations

import json
import re
from pathlib import Path

import studies.bundled
from studies.study import run_module


def strict_json(text: str):
    """json.loads that fails on NaN and infinities (results.json must be strict JSON)."""
    def bad(c):
        raise AssertionError(f"non-strict JSON constant {c}")
    return json.loads(text, parse_constant=bad)


def quick_run(name: str, tmp_path_factory):
    """Run a bundled study in --quick mode: (study, results, report path, results.json as read back)."""
    out = tmp_path_factory.mktemp(name)
    s, results, report = run_module(studies.bundled.load(name), out, quick=True)
    return s, results, report, strict_json((report.parent / "results.json").read_text(encoding="utf-8"))


def _plain(text: str) -> str:
    """A finding as the page shows it: the inline markup gone, whitespace collapsed, minus signs as
    hyphens (the page prints "−" where results.json's text has "-")."""
    return re.sub(r"\s+", " ", text.replace("**", "").replace("`", "").replace("−", "-")).strip()


def assert_report_renders(report_browser, report: Path, results: dict, numbers: tuple[str, ...] = ()) -> None:
    c = report_browser.open_report(report)
    assert c.problems() == [], c.problems()
    pngs = [f for f in results["meta"]["files"] if f.endswith(".png")]
    assert len(c.images) == len(pngs) and pngs, (len(c.images), pngs)
    assert all(i.loaded and i.width > 0 for i in c.images)
    assert c.graphs and all(g.drew for g in c.graphs), [g.detail for g in c.graphs]
    text = re.sub(r"\s+", " ", c.text).replace("−", "-")
    for f in results["findings"]:
        assert _plain(f["text"]) in text, f["text"]
    for n in numbers:
        assert n.replace("−", "-") in text, n
    assert results["title"] in c.title


def assert_report_holds(report: Path, results: dict, texts, pngs) -> None:
    """The report's HTML holds each of ``texts``; each of ``pngs`` is a PNG file beside it, listed in
    results.json's ``meta.files`` and embedded in the page."""
    page = report.read_text(encoding="utf-8")
    for text in texts:
        assert text in page, text
    for png in pngs:
        assert (report.parent / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", png
        assert png in results["meta"]["files"], png
    assert page.count("data:image/png;base64,") >= len(pngs)
