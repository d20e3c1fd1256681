"""The manual stays true to the code: the mkdocs site builds without a warning (no broken link or
anchor, no page left out of the nav), every rmtkit name and repository path written in backticks
exists, and docs/cli.md describes every command with exactly the options it has.

(The examples themselves run in tests/test_doc_examples.py.)
"""
from __future__ import annotations

import argparse
import importlib
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```[\w-]*[ \t]*\n.*?^```[ \t]*$", re.M | re.S)
#: a dotted rmtkit name: kin.X, planning.x.Y, design.x.Y, studies.x.Y
NAME = re.compile(r"(?<![\w./-])((?:kin|planning|design|studies)(?:\.[A-Za-z_]\w*)+)")
#: a path inside the repository
PATH = re.compile(r"^(?:kin|planning|design|studies|tests|docs)/[\w./*-]*$")
OPTION = r"(?<![\w-])--[a-z][a-z0-9-]*"
FILE_SUFFIXES = {"json", "toml", "csv", "png", "py", "html", "sqlite", "urdf", "md", "txt"}


def _rel(page: Path) -> str:
    return str(page.relative_to(ROOT))


def inline_code(text: str) -> list[str]:
    """The `code spans` of a Markdown text outside its fenced blocks."""
    prose = FENCE.sub("", text)
    return [" ".join(span.split()) for span in re.findall(r"`([^`]+)`", prose)]   # a span may wrap


# ---- the site builds ------------------------------------------------------------------------------
def test_mkdocs_builds_without_a_warning(tmp_path):
    try:
        import mkdocs  # noqa: F401 - only probes that mkdocs is installed
    except ImportError:
        pytest.fail("mkdocs is not installed: pip install -e '.[test]' (make test does)")
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=ROOT, capture_output=True, text=True, timeout=300)
    log = run.stdout + run.stderr
    assert run.returncode == 0 and "WARNING" not in log, log
    assert (tmp_path / "site" / "index.html").is_file()


def test_every_page_is_in_the_nav():
    nav = (ROOT / "mkdocs.yml").read_text()
    for page in PAGES[1:]:
        assert f": {page.name}" in nav, f"{_rel(page)} is not in mkdocs.yml's nav"


def test_readme_stays_short_and_links_every_page():
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 250, "the README is the front page; details go to docs/"
    for page in PAGES[1:]:
        assert f"](docs/{page.name})" in readme, f"the README does not link {_rel(page)}"


# ---- names and paths ------------------------------------------------------------------------------
def _resolve(dotted: str):
    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:k]))
        except ModuleNotFoundError as e:
            if e.name is not None and not ".".join(parts[:k]).startswith(e.name):
                raise                       # the module exists but imports something missing
            continue
        for attr in parts[k:]:
            obj = getattr(obj, attr)
        return obj
    raise ModuleNotFoundError(dotted)


def _names():
    out = []
    for page in PAGES:
        for span in inline_code(page.read_text()):
            for m in NAME.finditer(span):
                name = m.group(1)
                if name.rsplit(".", 1)[1] in FILE_SUFFIXES and len(name.split(".")) == 2:
                    continue                # a file name such as design.json
                out.append((page, name))
    return sorted(set(out))


NAMES = _names()


def test_the_pages_name_rmtkit_objects():
    assert len(NAMES) >= 40


@pytest.mark.parametrize("page, name", NAMES, ids=[f"{_rel(p)}:{n}" for p, n in NAMES])
def test_name_in_backticks_resolves(page, name):
    try:
        _resolve(name)
    except (ImportError, AttributeError) as e:
        pytest.fail(f"{_rel(page)} names `{name}`, which does not exist ({e})")


def _paths():
    out = []
    for page in PAGES:
        text = page.read_text()
        out += [(page, span) for span in inline_code(text) if PATH.match(span)]
        # the README's tree of folders: the first word of every line of its unlabelled block
        for block in re.findall(r"^```\n(.*?)^```", text, re.M | re.S):
            out += [(page, line.split()[0]) for line in block.splitlines() if line.split()
                    and PATH.match(line.split()[0].rstrip("/") + "/")]
    return sorted(set(out))


PATHS = _paths()


@pytest.mark.parametrize("page, path", PATHS, ids=[f"{_rel(p)}:{x}" for p, x in PATHS])
def test_path_in_backticks_exists(page, path):
    assert list(ROOT.glob(path.rstrip("/"))), f"{_rel(page)} names `{path}`, which is not in the repository"


# ---- the command line -----------------------------------------------------------------------------
def _commands() -> dict[str, set[str]]:
    from studies.cli.main import build_parser
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return {name: {o for a in p._actions for o in a.option_strings if o.startswith("--") and o != "--help"}
            for name, p in sub.choices.items()}


def _cli_sections() -> dict[str, str]:
    text = (ROOT / "docs" / "cli.md").read_text()
    return {m.group(1): m.group(2)
            for m in re.finditer(r"^### `rmt ([a-z-]+)`\n(.*?)(?=^#)", text + "\n#", re.M | re.S)}


def test_cli_page_describes_every_command():
    assert set(_cli_sections()) == set(_commands())


@pytest.mark.parametrize("command", sorted(_commands()))
def test_cli_page_gives_exactly_the_options(command):
    section = _cli_sections().get(command, "")
    spans = [s for s in inline_code(section) if not re.match(r"rmt [a-z]", s) or s.startswith(f"rmt {command} ")]
    written = {o for span in spans for o in re.findall(OPTION, span)}
    options = _commands()[command]
    assert written - options == set(), f"docs/cli.md, rmt {command}: no such option {sorted(written - options)}"
    assert options - written == set(), f"docs/cli.md, rmt {command}: options not described {sorted(options - written)}"


def test_commands_in_backticks_exist():
    commands = _commands()
    for page in PAGES:
        for span in inline_code(page.read_text()):
            m = re.match(r"rmt ([a-z][a-z-]*)(.*)", span)
            if not m:
                continue
            assert m.group(1) in commands, f"{_rel(page)}: `{span}`: no command rmt {m.group(1)}"
            unknown = set(re.findall(OPTION, m.group(2))) - commands[m.group(1)]
            assert not unknown, f"{_rel(page)}: `{span}`: rmt {m.group(1)} has no option {sorted(unknown)}"
