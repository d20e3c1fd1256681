"""Running a study: a failed plan exits 1 and results.json stays strict JSON (no NaN); a run that is
interrupted leaves the previous run's files untouched and nothing new beside them."""
from __future__ import annotations

import json

from studies.cli import main

# scara_rrp: the boundary window around q2 = 0 splits the joint space; start q2 > 0, goal q2 < 0
STUDY = '''name = "scara_split"
robot = "scara_rrp"
[[configurations]]
q = [0.0, 0.5, -100.0]
[windows]
margin = 0.05
[workspace]
samples = 2000
[plan]
start = [0.0, 1.0, -100.0]
goal = [0.0, -1.0, -100.0]
time_limit = 0.2
'''


def _strict(text):
    def bad(c):
        raise AssertionError(f"non-strict JSON constant {c}")
    return json.loads(text, parse_constant=bad)


def _tree(root):
    return sorted(str(p.relative_to(root)) for p in root.rglob("*"))


def test_failed_plan_exits_1_with_strict_json(tmp_path, capsys):
    p = tmp_path / "s.toml"
    p.write_text(STUDY)
    code = main(["study", str(p), "--out", str(tmp_path / "out")])
    out, err = capsys.readouterr()
    assert code == 1, err
    d = _strict((tmp_path / "out" / "scara_split" / "results.json").read_text())
    assert d["ok"] is False and d["plan"]["success"] is False
    assert d["plan"]["length"] is None and d["plan"]["min_sigma"] is None
    assert "plan: no path found" in out
    # the split is real: no configuration with q2 in the window is valid, so no path can cross it
    [w] = [w for w in d["windows"]["windows"] if w["joints"] == [2]]
    assert w["intervals"][0][0] <= 0.0 <= w["intervals"][0][1]
    assert _tree(tmp_path / "out") == ["scara_split", "scara_split/report.html", "scara_split/results.json",
                                       "scara_split/workspace.png"]


def test_interrupted_run_keeps_the_old_results(tmp_path, capsys, monkeypatch):
    p = tmp_path / "s.toml"
    p.write_text(STUDY.replace("[plan]", "[plan_off]").split("[plan_off]")[0])
    assert main(["study", str(p), "--out", str(tmp_path / "out")]) == 0
    run = tmp_path / "out" / "scara_split"
    before = {f: (run / f).read_bytes() for f in ("report.html", "results.json", "workspace.png")}

    import design.workspace

    def interrupted(*a, **k):
        raise KeyboardInterrupt
    monkeypatch.setattr(design.workspace, "compute_workspace", interrupted)
    assert main(["study", str(p), "--out", str(tmp_path / "out")]) == 130
    capsys.readouterr()
    assert {f: (run / f).read_bytes() for f in before} == before
    assert _tree(tmp_path / "out") == ["scara_split", "scara_split/report.html", "scara_split/results.json",
                                       "scara_split/workspace.png"]


def test_study_refuses_to_replace_foreign_files(tmp_path, capsys):
    p = tmp_path / "s.toml"
    p.write_text(STUDY.split("[windows]")[0])
    run = tmp_path / "out" / "scara_split"
    run.mkdir(parents=True)
    (run / "notes.txt").write_text("mine")
    assert main(["study", str(p), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "notes.txt" in err and err.count("\n") == 1
    assert _tree(run) == ["notes.txt"]
