"""The browser check every bundled study's report gets: it renders in headless Chromium with no
console error and no network request, every figure it lists loads, its 3-D views draw, and its
findings and key numbers are on the page as a reader sees it (``innerText``)."""
from __future__ import annotations

import re
from pathlib import Path


def _plain(text: str) -> str:
    """A finding as the page shows it: the inline markup gone, whitespace collapsed."""
    return re.sub(r"\s+", " ", text.replace("**", "").replace("`", "")).strip()


def assert_report_renders(report_browser, report: Path, results: dict, numbers: tuple[str, ...] = ()) -> None:
    c = report_browser.open_report(report)
    assert c.problems() == [], c.problems()
    pngs = [f for f in results["meta"]["files"] if f.endswith(".png")]
    assert len(c.images) == len(pngs) and pngs, (len(c.images), pngs)
    assert all(i.loaded and i.width > 0 for i in c.images)
    assert c.graphs and all(g.drew for g in c.graphs), [g.detail for g in c.graphs]
    text = re.sub(r"\s+", " ", c.text)
    for f in results["findings"]:
        assert _plain(f["text"]) in text, f["text"]
    for n in numbers:
        assert n in text, n
    assert results["title"] in c.title
