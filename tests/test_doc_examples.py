"""The examples of the manual work as printed, in README.md and every page of docs/.

Every fenced block of those pages is checked by its language:

* ``python``: the block runs (in a fresh namespace, from an empty temporary directory, so that an
  example works from any directory); a block that defines ``test_*`` functions (a test file shown to
  the reader) has them called too;
* ``console``: every ``$ rmt ...`` line runs through ``studies.cli.main`` — the lines of one page in
  order, in one temporary directory per page, so later commands read what earlier ones wrote — and
  exits 0 (or the code a trailing ``# exit N`` comment names); output shown below a command must
  match what it prints (``...`` stands for any text, as in doctest).  ``$ python -m MODULE`` lines
  must name a module that exists and ``$ make TARGET`` lines a target of the Makefile; they are not
  run (benchmarks take minutes);
* ``toml``: the block is a file of a documented kind, read by rmtkit's own reader for that kind
  (robot file, module catalogue, study file, design task, sweep file, tool path, keep-out boxes, work cell);
* ``text`` and unlabelled blocks are printed output or a listing: not run.

Any other language fails, so that no new block goes unchecked.
"""
from __future__ import annotations

import doctest
import importlib.util
import re
import shlex
from pathlib import Path

import pytest

from studies.cli import main

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```([\w-]*)[ \t]*\n(.*?)^```[ \t]*$", re.M | re.S)
LANGUAGES = {"python", "console", "toml", "text", ""}


def _rel(page: Path) -> str:
    return str(page.relative_to(ROOT))


def blocks(page: Path) -> list[tuple[str, str, int]]:
    """(language, text, line number of the opening fence) of every fenced block of a page."""
    src = page.read_text(encoding="utf-8")
    return [(m.group(1), m.group(2), src.count("\n", 0, m.start()) + 1) for m in FENCE.finditer(src)]


BLOCKS = [(page, lang, text, line) for page in PAGES for lang, text, line in blocks(page)]


def _id(page: Path, line: int) -> str:
    return f"{_rel(page)}:{line}"


# ---- every block is of a checked kind ------------------------------------------------------------
def test_pages_have_examples():
    assert len(PAGES) >= 8
    langs = [lang for _, lang, _, _ in BLOCKS]
    assert langs.count("python") >= 8 and langs.count("console") >= 8 and langs.count("toml") >= 5


@pytest.mark.parametrize("page, lang, line", [(p, lang, ln) for p, lang, _, ln in BLOCKS],
                         ids=[_id(p, ln) for p, _, _, ln in BLOCKS])
def test_block_language_is_checked(page, lang, line):
    assert lang in LANGUAGES, f"{_id(page, line)}: a ```{lang} block is not checked by any test; " \
                              f"use one of {sorted(LANGUAGES - {''})}"


# ---- python ---------------------------------------------------------------------------------------
PYTHON = [(p, text, ln) for p, lang, text, ln in BLOCKS if lang == "python"]


@pytest.mark.parametrize("page, code, line", PYTHON, ids=[_id(p, ln) for p, _, ln in PYTHON])
def test_python_block_runs(page, code, line, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)          # not the repository: examples must not depend on the cwd
    namespace: dict = {"__name__": f"doc_block_{line}"}
    exec(compile(code, _id(page, line), "exec"), namespace)
    # a block that is a test file (the planning.testing example): its tests must pass as shown
    for name, fn in list(namespace.items()):
        if name.startswith("test_") and callable(fn):
            fn()


# ---- console --------------------------------------------------------------------------------------
def _commands(page: Path):
    """(line, kind, argv, expected exit code, shown output or None) of every `$ ` line of a page."""
    out = []
    for lang, text, start in blocks(page):
        if lang != "console":
            continue
        lines = text.splitlines()
        for i, line in enumerate(lines):
            if not line.startswith("$ "):
                continue
            cmd, _, comment = line[2:].partition(" #")
            m = re.match(r"\s*exit (\d+)\b", comment)
            shown = []
            for nxt in lines[i + 1:]:
                if nxt.startswith("$ "):
                    break
                shown.append(nxt)
            text_shown = "\n".join(shown).strip()
            argv = shlex.split(cmd)
            out.append((start + 1 + i, argv[0], argv[1:], int(m.group(1)) if m else 0, text_shown or None))
    return out


COMMANDS = [(p, *c) for p in PAGES for c in _commands(p)]
RMT = [c for c in COMMANDS if c[2] == "rmt"]
OTHER = [c for c in COMMANDS if c[2] != "rmt"]


@pytest.fixture(scope="module")
def page_dirs(tmp_path_factory):
    """One temporary directory per page, shared by that page's commands (run in order)."""
    made: dict[Path, Path] = {}

    def get(page: Path) -> Path:
        if page not in made:
            made[page] = tmp_path_factory.mktemp(page.stem.lower())
        return made[page]
    return get


@pytest.mark.parametrize("page, line, prog, argv, code, shown", RMT,
                         ids=[f"{_id(p, ln)} rmt {' '.join(a)}" for p, ln, _, a, _, _ in RMT])
def test_cli_example(page, line, prog, argv, code, shown, capsys, page_dirs, monkeypatch):
    monkeypatch.chdir(page_dirs(page))   # `rmt study` writes out/ here, `rmt plan --out` its CSV
    rc = main(argv)
    out = capsys.readouterr().out
    assert rc == code, f"{_id(page, line)}: exit {rc}, the page says {code}"
    if shown is not None:
        checker = doctest.OutputChecker()
        assert checker.check_output(shown + "\n", out.strip() + "\n", doctest.ELLIPSIS), \
            f"{_id(page, line)}: the page shows\n{shown}\nbut the command printed\n{out}"


MAKE_TARGETS = set(re.findall(r"^([\w-]+):", (ROOT / "Makefile").read_text(), re.M))


@pytest.mark.parametrize("page, line, prog, argv, code, shown", OTHER,
                         ids=[f"{_id(p, ln)} {prog} {' '.join(a)}" for p, ln, prog, a, _, _ in OTHER])
def test_other_command_names_something_real(page, line, prog, argv, code, shown):
    if prog == "make":
        assert argv and argv[0] in MAKE_TARGETS, f"{_id(page, line)}: no make target {argv[:1]}"
    elif prog == "python" and argv[:1] == ["-m"]:
        assert importlib.util.find_spec(argv[1]) is not None, f"{_id(page, line)}: no module {argv[1]}"
    elif prog in ("python", "pytest"):
        pass                             # a file of the reader's own (`python my_study.py`, `pytest`)
    else:
        pytest.fail(f"{_id(page, line)}: `{prog}` commands are not checked; show `rmt`, `python`, `pytest` "
                    "or `make` commands")


# ---- toml -----------------------------------------------------------------------------------------
TOML = [(p, text, ln) for p, lang, text, ln in BLOCKS if lang == "toml"]


def _read_toml_example(text: str, tmp_path: Path):
    """Read a TOML example with the reader of its kind (told by the tables it has)."""
    import kin
    if "[[joints]]" in text:
        return kin.loads_robot(text, "<robot file example>")
    if "[[modules]]" in text:
        from kin.modules import loads_catalogue
        return loads_catalogue(text, "<module catalogue example>")
    if "[[configurations]]" in text:
        from studies.study.kinematics import load_study
        path = tmp_path / "study.toml"
        path.write_text(text)
        return load_study(path)
    if "[target]" in text and not re.search(r"^robot = ", text, re.M):      # a part file (no robot)
        from design.compose import loads_part
        from studies.cli.compose import PARTS_DIR
        return loads_part(text, "<part file example>", base=PARTS_DIR)
    if "[target]" in text:
        from design.task import loads_task
        from studies.cli.design import TASK_DIR
        return loads_task(text, "<task file example>", base=TASK_DIR)
    if "[sampling]" in text:
        from design.sweep import loads_sweep
        from studies.cli.sweep import SWEEP_DIR
        return loads_sweep(text, "<sweep file example>", base=SWEEP_DIR)
    if "[[segments]]" in text:
        from planning.toolpath import parse_toolpath_toml
        robot = re.search(r'^robot = "(\w+)"', text, re.M)
        return parse_toolpath_toml(text, kin.load_robot(robot.group(1) if robot else "fanuc_m16ib20"))
    if "[[obstacle]]" in text or "[[tool]]" in text:
        # a cell's meshes are named as the bundled cell names its own: next to it
        from planning.cell import parse_cell
        return parse_cell(text, "<cell file example>", base_dir=ROOT / "studies" / "cells")
    if "[[box]]" in text:
        from planning.ompl.keep_out import parse_keep_out
        return parse_keep_out(text, "m")
    if "[[move]]" in text:               # an rmt time cycle file (docs/cli.md's is for the ur5e)
        from studies.cli.timecycle import read_cycle_file
        path = tmp_path / "cycle.toml"
        path.write_text(text)
        return read_cycle_file(kin.load_robot("ur5e"), path)
    raise AssertionError("a TOML example of no known kind (robot, module catalogue, study, task, sweep, tool path, "
                         "keep-out, cell, cycle)")


@pytest.mark.parametrize("page, text, line", TOML, ids=[_id(p, ln) for p, _, ln in TOML])
def test_toml_example_is_valid(page, text, line, tmp_path):
    assert _read_toml_example(text, tmp_path) is not None
