"""The study context and its run directory: results.json is strict JSON listing every file the run
wrote, figures are written and embedded, a failed finding fails the study, file names cannot escape
the directory, a rerun replaces only what a run wrote, an interrupted run leaves the old one alone."""
from __future__ import annotations

import json
import sys
import types

import numpy as np
import pytest
from matplotlib.figure import Figure

from kin.output import OutputError
from planning.errors import PlanningError
from studies.study import Study, main, run_study_function


def _strict(text):
    def bad(c):
        raise AssertionError(f"non-strict JSON constant {c}")
    return json.loads(text, parse_constant=bad)


def _study(s: Study):
    s.input("seed", 7)
    with s.section("Numbers"):
        s.text("some `code`")
        s.table(["x (m)"], [[1.5], [None]])
        fig = Figure()
        ax = fig.add_subplot()
        ax.plot([0, 1], [0, 1])
        ax.set_xlabel("t (s)")
        s.figure(fig, "line", "a line")
        s.file("data.csv", "a,b\n1,2\n")
        s.results["values"] = {"nan": float("nan"), "inf": np.inf, "arr": np.arange(3), "f32": np.float32(0.5)}
    s.finding("all good")


def test_run_writes_report_results_and_files(tmp_path):
    s, results = run_study_function(_study, "demo", "Demo", tmp_path / "demo")
    d = _strict((tmp_path / "demo" / "results.json").read_text())
    assert d == results
    assert d["values"] == {"nan": None, "inf": None, "arr": [0, 1, 2], "f32": 0.5}
    assert d["ok"] is True and d["study"] == "demo" and d["meta"]["inputs"] == {"seed": 7}
    assert sorted(p.name for p in (tmp_path / "demo").iterdir()) == d["meta"]["files"] == \
        ["data.csv", "line.png", "report.html", "results.json"]
    assert (tmp_path / "demo" / "line.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "demo" / "data.csv").read_text() == "a,b\n1,2\n"
    page = (tmp_path / "demo" / "report.html").read_text()
    assert "all good" in page and "Numbers" in page and "numpy" in d["meta"]["versions"]
    assert set(d["meta"]["timings"]) == {"Numbers"} and d["meta"]["timings"]["Numbers"] >= 0


def test_failed_finding_fails_the_study(tmp_path):
    def run(s):
        with s.section("x"):
            s.finding("the plan found no path", ok=False)
    s, d = run_study_function(run, "f", "F", tmp_path / "f")
    assert s.ok is False and d["ok"] is False and d["findings"] == [{"text": "the plan found no path", "ok": False}]


@pytest.mark.parametrize("name", ["../escape.csv", "a/b.csv", ".hidden", "report.html", "results.json", ""])
def test_file_names_are_checked(tmp_path, name):
    def run(s):
        s.file(name, "x")
    with pytest.raises(ValueError):
        run_study_function(run, "n", "N", tmp_path / "n")
    assert not (tmp_path / "n").exists() and not (tmp_path / "escape.csv").exists()


def test_blocks_need_a_section(tmp_path):
    with pytest.raises(RuntimeError, match="section"):
        run_study_function(lambda s: s.text("x"), "n", "N", tmp_path / "n")


def test_rerun_replaces_its_own_files_but_refuses_foreign_ones(tmp_path):
    run_study_function(_study, "demo", "Demo", tmp_path / "demo")

    def smaller(s):
        with s.section("only"):
            s.text("x")
    run_study_function(smaller, "demo", "Demo", tmp_path / "demo")      # the old files were listed: replaced
    assert sorted(p.name for p in (tmp_path / "demo").iterdir()) == ["report.html", "results.json"]
    (tmp_path / "demo" / "mine.txt").write_text("keep")
    with pytest.raises(OutputError, match="mine.txt"):
        run_study_function(smaller, "demo", "Demo", tmp_path / "demo")
    assert (tmp_path / "demo" / "mine.txt").read_text() == "keep"


def test_interrupted_run_leaves_the_previous_one(tmp_path):
    run_study_function(_study, "demo", "Demo", tmp_path / "demo")
    before = {p.name: p.read_bytes() for p in (tmp_path / "demo").iterdir()}

    def interrupted(s):
        with s.section("x"):
            s.file("new.csv", "x")
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        run_study_function(interrupted, "demo", "Demo", tmp_path / "demo")
    assert {p.name: p.read_bytes() for p in (tmp_path / "demo").iterdir()} == before
    assert [p.name for p in tmp_path.iterdir()] == ["demo"]


def test_a_copied_study_runs_as_a_script(tmp_path, capsys):
    mod = types.ModuleType("my_study")
    mod.__doc__ = "My study.\n\nMore."
    mod.NAME, mod.TITLE, mod.run = "my_study", "My study", _study
    sys.modules["my_study"] = mod
    try:
        assert main(mod, ["--out", str(tmp_path)]) == 0
        full = (tmp_path / "my_study" / "report.html").read_bytes()
        assert main(mod, ["--quick", "--out", str(tmp_path)]) == 0
    finally:
        del sys.modules["my_study"]
    out = capsys.readouterr().out
    # the quick run goes beside the full report, which it leaves as it was
    assert "✓ all good" in out and str(tmp_path / "my_study-quick" / "report.html") in out
    assert (tmp_path / "my_study" / "report.html").read_bytes() == full
    assert _strict((tmp_path / "my_study" / "results.json").read_text())["quick"] is False
    d = _strict((tmp_path / "my_study-quick" / "results.json").read_text())
    assert d["quick"] is True
    assert "My study." in (tmp_path / "my_study-quick" / "report.html").read_text()


def test_an_input_recorded_twice_is_listed_once(tmp_path):
    def run(s):
        s.input("workspace: samples", 20_000)      # the study records it …
        s.input("workspace: samples", 20_000)      # … and so does a shared section
        s.input("workspace: seed", 0)
        with s.section("x"):
            s.text("nothing")
    s, d = run_study_function(run, "i", "I", tmp_path / "i")
    page = (tmp_path / "i" / "report.html").read_text()
    assert page.count("workspace: samples") == 1 and page.count("workspace: seed") == 1
    assert d["meta"]["inputs"] == {"workspace: samples": 20_000, "workspace: seed": 0}


@pytest.mark.parametrize("raised, code, line", [
    (PlanningError("goal configuration is invalid: inside the singular window 'wrist'"), 2,
     "error: goal configuration is invalid: inside the singular window 'wrist'"),
    (KeyboardInterrupt(), 130, "interrupted"),
])
def test_a_study_script_reports_an_error_in_one_line(tmp_path, capsys, raised, code, line):
    def run(s):
        with s.section("x"):
            raise raised
    mod = types.ModuleType("my_study")
    mod.NAME, mod.TITLE, mod.run = "my_study", "My study", run
    assert main(mod, ["--out", str(tmp_path)]) == code
    err = capsys.readouterr().err
    assert err.splitlines()[-1].endswith(line) and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []            # no partial run directory


def test_a_study_script_refuses_foreign_files_in_one_line(tmp_path, capsys):
    (tmp_path / "my_study").mkdir()
    (tmp_path / "my_study" / "notes.txt").write_text("mine")
    mod = types.ModuleType("my_study")
    mod.NAME, mod.TITLE, mod.run = "my_study", "My study", _study
    assert main(mod, ["--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "notes.txt" in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert (tmp_path / "my_study" / "notes.txt").read_text() == "mine"


def test_progress_shows_sections_and_steps_but_the_report_does_not(tmp_path):
    lines = []

    def run(s):
        with s.section("Long work"):
            s.say("step 1 of 2")
            s.text("done")
    run_study_function(run, "p", "P", tmp_path / "p", progress=lines.append)
    assert lines[0].startswith("Long work") and lines[1].startswith("  step 1 of 2") and "writing" in lines[-1]
    assert "step 1 of 2" not in (tmp_path / "p" / "report.html").read_text()
