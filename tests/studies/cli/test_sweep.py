"""``rmt sweep``, ``rmt sweep-export`` and ``rmt sweep-plot``: JSON summary, the CSV against the
database, the plots written, and one-line errors (exit 2) for bad input and foreign databases."""
import csv
import json

import pytest

from design.sweep import read_sweep
from studies.cli.main import main
from tests.design.sweep.helpers import write_sweep


def test_sweep_export_and_plot(tmp_path, capsys):
    p = write_sweep(tmp_path, counts=(3, 3))
    db = tmp_path / "s.sqlite"
    rc = main(["sweep", str(p), "--db", str(db), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["counts"]["done"] == 9 and out["evaluated"] == 9
    meta, rows = read_sweep(db)
    feas = [r for r in rows if r["metrics"]["feasible"]]
    assert out["best"]["objective"] == min(r["metrics"]["objective"] for r in feas)
    assert main(["sweep-export", str(db), "--csv", str(tmp_path / "s.csv")]) == 0
    with open(tmp_path / "s.csv") as fh:
        table = list(csv.DictReader(fh))
    assert len(table) == 9 and set(table[0]) >= {"key", "A1_mm", "A2_mm", "coverage", "objective", "status"}
    by_key = {r["key"]: r for r in rows}
    for t in table:
        r = by_key[t["key"]]
        assert float(t["A1_mm"]) == pytest.approx(r["params"]["A1"] * 1e3)
        assert float(t["coverage"]) == r["metrics"]["coverage"]
    capsys.readouterr()
    assert main(["sweep-plot", str(db), "--out", str(tmp_path / "plots")]) == 0
    assert (tmp_path / "plots" / "pareto.png").stat().st_size > 0
    assert (tmp_path / "plots" / "heatmap.png").stat().st_size > 0
    # a second run without --resume is refused, the database untouched
    before = db.read_bytes()
    assert main(["sweep", str(p), "--db", str(db), "--quiet"]) == 2
    assert db.read_bytes() == before and "--resume" in capsys.readouterr().err


@pytest.mark.parametrize("extra,needle", [
    (["--workers", "0"], "--workers"),
    (["--workers", "2", "--dask-local", "2"], "one of"),
    (["--scheduler", "localhost"], "tcp://"),
    (["--refine", "-1"], "--refine"),
])
def test_bad_options_exit_2(tmp_path, capsys, extra, needle):
    p = write_sweep(tmp_path)
    assert main(["sweep", str(p), "--db", str(tmp_path / "x.sqlite"), *extra]) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1


def test_foreign_database_is_refused(tmp_path, capsys):
    p = write_sweep(tmp_path)
    db = tmp_path / "mine.sqlite"
    db.write_text("not yours")
    assert main(["sweep", str(p), "--db", str(db), "--resume"]) == 2
    assert "not an SQLite database" in capsys.readouterr().err and db.read_text() == "not yours"
    assert main(["sweep-export", str(db), "--csv", str(tmp_path / "o.csv")]) == 2
    assert not (tmp_path / "o.csv").exists()
    assert main(["sweep", "no_such_sweep"]) == 2


def test_progress_bar_on_a_terminal(tmp_path, capsys, monkeypatch):
    p = write_sweep(tmp_path, counts=(2, 2))
    import sys
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    assert main(["sweep", str(p), "--db", str(tmp_path / "b.sqlite")]) == 0
    err = capsys.readouterr().err
    assert "4/4" in err and "failed=0" in err and "design/s" in err
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    assert main(["sweep", str(p), "--db", str(tmp_path / "q.sqlite"), "--quiet"]) == 0
    assert capsys.readouterr() == ("", "")
