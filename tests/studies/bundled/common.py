"""What every bundled study's tests share: one quick run of the study — copied alone into an empty
directory and run there as a script, as the README says a copied study runs — with its results.json
read as strict JSON, and the browser check of its report — it renders in headless Chromium with no
console error and no network request, every figure it lists loads, its 3-D views draw, and its
findings and key numbers are on the page as a reader sees it (``innerText``)."""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import NamedTuple

import studies

#: the source tree under test (the copy imports rmtkit from here, as it would from an installed rmtkit)
ROOT = Path(studies.__file__).resolve().parent.parent
#: a quick run takes seconds to a minute; a hung one fails instead of stalling the suite
TIMEOUT_S = 600


def strict_json(text: str):
    """json.loads that fails on NaN and infinities (results.json must be strict JSON)."""
    def bad(c):
        raise AssertionError(f"non-strict JSON constant {c}")
    return json.loads(text, parse_constant=bad)


class QuickRun(NamedTuple):
    """A bundled study's quick run as a copied script: the process, its report and its results."""
    copied: subprocess.CompletedProcess      # ``python my_NAME.py --quick --out out`` in the copy's directory
    report: Path                             # out/NAME-quick/report.html beside the copy
    results: dict                            # out/NAME-quick/results.json, read as strict JSON


def quick_run(name: str, tmp_path_factory) -> QuickRun:
    """Copy ``studies/bundled/NAME.py`` alone into an empty directory, run the copy there with
    ``--quick --out out`` in a subprocess, and check that it exits 0 and writes its report.html and
    results.json: a bundled study is a plain script that needs nothing beside it."""
    here = tmp_path_factory.mktemp(f"{name}_copied")
    assert not any(here.iterdir())
    script = here / f"my_{name}.py"
    shutil.copyfile(ROOT / "studies" / "bundled" / f"{name}.py", script)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    copied = subprocess.run([sys.executable, script.name, "--quick", "--out", "out"], cwd=here, env=env,
                            capture_output=True, text=True, timeout=TIMEOUT_S)
    out = here / "out" / f"{name}-quick"          # a quick run is written beside the full report
    assert copied.returncode == 0, f"{script.name} exited {copied.returncode}:\n{copied.stderr[-4000:]}"
    assert (out / "report.html").is_file() and (out / "results.json").is_file(), sorted(here.rglob("*"))
    assert str((out / "report.html").resolve()) in copied.stdout       # the terminal summary names the report
    return QuickRun(copied, out / "report.html", strict_json((out / "results.json").read_text(encoding="utf-8")))


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
