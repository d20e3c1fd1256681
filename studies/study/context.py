"""The study context: what a study script writes into.

A study is a function ``run(s: Study)`` (see :mod:`studies.bundled`).  It computes with the public
API and records what it finds: ``s.results`` (a dict that becomes ``results.json``), sections of
paragraphs, tables, figures and 3-D views (the report), findings (the report's top and the terminal
summary), and its inputs.  :func:`run_study_function` runs it inside a fresh directory
(:func:`kin.output.fresh_directory`) and writes, when it has finished:

* ``report.html`` — one self-contained file (figures embedded, plotly.js embedded, no network);
* ``results.json`` — strict JSON (NaN and infinities become ``null``), with ``meta``: versions,
  inputs, seeds, timings and the list of files;
* every figure as ``NAME.png``, and any data file the study added (``s.file``).

A rerun replaces a previous run's directory only when it holds nothing but the files that run listed
in its ``results.json``; anything else there is refused, never deleted.
"""
from __future__ import annotations

import json
import platform
import re
import time
from contextlib import contextmanager
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path
from typing import Any, Callable

import kin
from kin.errors import ArgumentError
from kin.output import fresh_directory, write_output
from kin.robotfile import robot_path
from studies.jsonio import jsonable
from studies.report import document as rd
from studies.report.html import render

__all__ = ["Study", "run_study_function", "previous_run_files", "VERSIONED_PACKAGES"]

#: packages whose versions every report lists
VERSIONED_PACKAGES = ("rmtkit", "numpy", "scipy", "casadi", "sympy", "ompl", "osqp", "scikit-learn", "matplotlib",
                      "plotly", "dask")
_FILE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,80}$")


def _versions() -> list[tuple[str, str]]:
    out = [("python", platform.python_version())]
    for name in VERSIONED_PACKAGES:
        try:
            out.append((name, metadata.version(name)))
        except metadata.PackageNotFoundError:
            out.append((name, "not installed"))
    out.append(("platform", f"{platform.system()} {platform.machine()}"))
    return out


class Study:
    """What a running study writes into; made by :func:`run_study_function`.

    ``quick`` asks for the reduced version of the study (CI, a first look): fewer samples, shorter
    budgets, the same sections.  Figures are matplotlib ``Figure`` objects; 3-D views are plotly figures.
    """

    def __init__(self, name: str, title: str, quick: bool = False, progress: Callable[[str], None] | None = None,
                 summary: str = ""):
        self.name = name
        self.quick = bool(quick)
        self.results: dict[str, Any] = {}
        self.ok = True
        self.doc = rd.Document(title=title, summary=summary)
        self.files: dict[str, bytes] = {}
        self._say = progress or (lambda text: None)
        self._t0 = time.perf_counter()
        self._current: rd.Section | None = None
        self._robot_paths: set[str] = set()

    # ----------------------------------------------------------------------------------- inputs
    def input(self, label: str, value: Any) -> Any:
        """Record one input (shown in the report's Inputs table and ``meta.inputs``); returns ``value``.
        The same label with the same value recorded again (a study and a shared section) is listed once."""
        entry = (label, value if isinstance(value, (int, float, str, bool)) or value is None
                 else json.dumps(jsonable(value)))
        if entry not in self.doc.inputs:
            self.doc.inputs.append(entry)
        return value

    def robot(self, name_or_path: str | Path) -> kin.Robot:
        """Load a robot (bundled name or file) and record its file in the report."""
        robot = kin.load_robot(name_or_path)
        src = robot_path(name_or_path).resolve()
        if str(src) not in self._robot_paths:
            self._robot_paths.add(str(src))
            self.doc.robot_files.append((_shown_path(src), src.read_text(encoding="utf-8")))
        return robot

    # --------------------------------------------------------------------------------- sections
    @contextmanager
    def section(self, title: str):
        """A timed report section; progress shows its title when it starts."""
        sec = rd.Section(title)
        self.doc.sections.append(sec)
        prev, self._current = self._current, sec
        self._say(f"{title} …  ({time.perf_counter() - self._t0:.0f} s)")
        t = time.perf_counter()
        try:
            yield sec
        finally:
            sec.seconds = time.perf_counter() - t
            self._current = prev

    def say(self, text: str) -> None:
        """A progress line inside a long section (shown like a section's title; never in the report)."""
        self._say(f"  {text}  ({time.perf_counter() - self._t0:.0f} s)")

    def _add(self, block) -> None:
        if self._current is None:
            raise RuntimeError("report blocks go inside `with s.section(title):`")
        self._current.blocks.append(block)

    def text(self, text: str) -> None:
        """Paragraphs (blank-line separated) with ``code`` and **bold**."""
        self._add(rd.Paragraph(text))

    def heading(self, text: str) -> None:
        self._add(text)

    def table(self, header: list[str], rows: list[list[Any]], caption: str = "", fmt: str = ".4g") -> None:
        self._add(rd.Table(list(header), [list(r) for r in rows], caption, fmt))

    def code(self, text: str, caption: str = "", collapsed: bool = False) -> None:
        self._add(rd.Code(text, caption, collapsed))

    def figure(self, fig, name: str, caption: str = "", dpi: int | None = None) -> str:
        """Add a matplotlib figure as ``NAME.png`` (written beside the report and embedded in it)."""
        from studies.plots.figure import png_bytes

        fname = self._file_name(f"{name}.png")
        self.files[fname] = png_bytes(fig, dpi)
        self._add(rd.Figure(fname, self.files[fname], caption))
        return fname

    def image(self, png_path: str | Path, caption: str = "", name: str | None = None) -> str:
        """Add a PNG a plotting function already wrote (embedded, and copied beside the report as
        ``NAME.png``, by default under its own file name)."""
        p = Path(png_path)
        fname = self._file_name(f"{name}.png" if name else p.name)
        self.files[fname] = p.read_bytes()
        self._add(rd.Figure(fname, self.files[fname], caption))
        return fname

    def view3d(self, fig, name: str, caption: str = "") -> None:
        """Add an interactive plotly figure (see :func:`studies.report.view3d.robot_view`)."""
        self._add(rd.View3D(name, fig, caption))

    def file(self, name: str, data: str | bytes) -> str:
        """A data file written beside the report (e.g. a planned path as CSV)."""
        fname = self._file_name(name)
        self.files[fname] = data.encode("utf-8") if isinstance(data, str) else bytes(data)
        return fname

    def finding(self, text: str, ok: bool = True) -> None:
        """One sentence for the top of the report and the terminal summary; ``ok=False`` also marks
        the study as failed (exit 1)."""
        self.doc.findings.append(rd.Finding(text, ok))
        if not ok:
            self.ok = False

    def _file_name(self, name: str) -> str:
        if not _FILE_NAME.match(name) or name in ("report.html", "results.json"):
            raise ArgumentError(f"study file name {name!r}: letters, digits, '_', '.', '-' only, not a reserved name")
        if name in self.files:
            raise ArgumentError(f"study file name {name!r} is used twice")
        return name

    # ---------------------------------------------------------------------------------- output
    def finish(self, seconds: float) -> tuple[dict, str]:
        """results.json's dict and the report's HTML."""
        files = sorted(["report.html", "results.json", *self.files])
        created = datetime.now(timezone.utc).replace(microsecond=0).isoformat()
        self.doc.meta = {"seconds": seconds,
                         "line": [f"study `{self.name}`", "quick mode" if self.quick else "full mode",
                                  f"{created} UTC", f"{seconds:.1f} s"]}
        self.doc.versions = _versions()
        results = {"study": self.name, "title": self.doc.title, "quick": self.quick, "ok": self.ok,
                   **self.results,
                   "findings": [{"text": f.text, "ok": f.ok} for f in self.doc.findings],
                   "meta": {"created": created, "seconds": seconds,
                            "timings": {s.title: s.seconds for s in self.doc.sections},
                            "inputs": {k: v for k, v in self.doc.inputs},
                            "robot_files": [p for p, _ in self.doc.robot_files],
                            "versions": dict(self.doc.versions), "files": files}}
        return jsonable(results), render(self.doc)


def _shown_path(p: Path) -> str:
    """A bundled file by its place in the package, a user's file as given."""
    root = Path(kin.__file__).parent.parent
    try:
        return str(p.resolve().relative_to(root.resolve()))
    except ValueError:
        return str(p)


def previous_run_files(out_dir: Path) -> set[str]:
    """The files a previous run listed in its ``results.json`` (an unreadable or foreign file lists none)."""
    try:
        meta = json.loads((out_dir / "results.json").read_text(encoding="utf-8")).get("meta", {})
        names = meta.get("files", []) if isinstance(meta, dict) else []
    except (OSError, ValueError, AttributeError):
        return {"results.json"} if (out_dir / "results.json").is_file() else set()
    return {n for n in names if isinstance(n, str) and _FILE_NAME.match(n)} | {"results.json"}


def run_study_function(run: Callable[[Study], None], name: str, title: str, out_dir: str | Path,
                       quick: bool = False, progress: Callable[[str], None] | None = None,
                       summary: str = "") -> tuple[Study, dict]:
    """Run a study function into ``out_dir`` (replaced as a whole when the study has finished);
    returns the study context and the results dict written to ``results.json``."""
    out_dir = Path(out_dir)
    s = Study(name, title, quick=quick, progress=progress, summary=summary)
    with fresh_directory(out_dir, previous_run_files(out_dir)) as tmp:
        t0 = time.perf_counter()
        run(s)
        if progress:
            progress(f"writing the report  ({time.perf_counter() - t0:.0f} s)")
        results, page = s.finish(time.perf_counter() - t0)
        for fname, data in s.files.items():
            write_output(tmp / fname, data)
        write_output(tmp / "results.json", json.dumps(results, indent=2, allow_nan=False) + "\n")
        write_output(tmp / "report.html", page)
    return s, results
