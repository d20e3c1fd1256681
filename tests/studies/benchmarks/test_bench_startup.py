"""Tests of studies.benchmarks.bench_startup: every command it times runs as a real process with the
exit code it expects, and the JSON report holds every figure (no timing asserted)."""
from __future__ import annotations

import json

import studies.benchmarks.bench_startup as bench


def test_the_report_holds_every_command(capsys):
    assert bench.main(["--json", "--runs", "1"]) == 0
    d = json.loads(capsys.readouterr().out)
    names = set(d["results"])
    assert {"rmt plan (separated query)", "rmt plan (around the shoulder window)", "rmt check-path (that path)",
            "rmt plan --cell (the weld cell)", "python -c 'import numpy' (floor)"} <= names
    for r in d["results"].values():
        assert r["runs"] == 1 and 0 < r["min_s"] <= r["median_s"] <= r["max_s"]
    assert d["target_s"] == 0.5 and d["verdict"] in ("PASS", "MISS")
    assert set(d["verdicts"]) == {"rmt plan (separated query)", "rmt plan --cell (the weld cell)"}
