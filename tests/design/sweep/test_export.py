"""Export: the table (pandas DataFrame or numpy record array) against the rows written, CSV values,
Parquet when pyarrow is there, the best row and the Pareto front against a brute-force dominance
check."""
import csv
import sys

import numpy as np
import pytest

from design.sweep import Design, Store, StoreError, best_row, read_sweep, sweep_table, write_csv, write_parquet
from design.sweep.evaluate import Outcome
from design.sweep.export import pareto_front

META = {"name": "e", "fingerprint": "f", "parameters": ["A1", "A2"], "swept": ["A1", "A2"],
        "units": {"A1": "mm", "A2": "mm"}, "scales": {"A1": 1e-3, "A2": 1e-3}, "objective": "length",
        "metrics": ["coverage", "structural_length"]}


def make_db(path):
    rng = np.random.default_rng(4)
    ds = [Design.make("", {"A1": float(a), "A2": float(b)}) for a, b in rng.uniform(0.1, 0.4, (30, 2))]
    with Store(path, META) as s:
        s.add(ds, seed=0)
        outs = []
        for i, d in enumerate(ds):
            if i == 7:
                outs.append(Outcome(d.key, False, None, "ValueError: x", 0.01, "w"))
                continue
            L = d.values["A1"] + d.values["A2"]
            cov = float(rng.integers(0, 10)) / 9
            outs.append(Outcome(d.key, True, {"objective": L, "score": L if cov >= 0.8 else 10 + L,
                                              "feasible": cov >= 0.8, "coverage": cov, "structural_length": L},
                                None, 0.01, "w"))
        s.record(outs)
    return ds


def test_record_array_without_pandas(tmp_path, monkeypatch):
    ds = make_db(tmp_path / "e.sqlite")
    monkeypatch.setitem(sys.modules, "pandas", None)          # as if pandas were not installed
    t = sweep_table(tmp_path / "e.sqlite")
    assert isinstance(t, np.recarray) and len(t) == 30
    np.testing.assert_allclose(t.A1_mm, [d.values["A1"] * 1e3 for d in ds])
    assert t.status[7] == "failed" and np.isnan(t.coverage[7]) and t.error[7] == "ValueError: x"
    assert np.all(t.feasible == (t.coverage >= 0.8))


def test_dataframe_with_pandas(tmp_path):
    pd = pytest.importorskip("pandas")
    make_db(tmp_path / "e.sqlite")
    df = sweep_table(tmp_path / "e.sqlite")
    assert isinstance(df, pd.DataFrame) and len(df) == 30 and "A2_mm" in df


def test_csv_matches_the_rows_and_best_row(tmp_path):
    make_db(tmp_path / "e.sqlite")
    write_csv(tmp_path / "e.sqlite", tmp_path / "o" / "e.csv")
    meta, rows = read_sweep(tmp_path / "e.sqlite")
    with open(tmp_path / "o" / "e.csv") as fh:
        table = list(csv.DictReader(fh))
    for t, r in zip(table, rows):
        assert t["key"] == r["key"] and float(t["A2_mm"]) == pytest.approx(r["params"]["A2"] * 1e3, rel=1e-15)
        assert (t["coverage"] == "") == (r["metrics"] is None)
    feas = [r for r in rows if r["metrics"] and r["metrics"]["feasible"]]
    b = best_row(rows, "length")
    assert b["objective"] == min(r["metrics"]["objective"] for r in feas) and b["feasible"]


def test_parquet(tmp_path):
    make_db(tmp_path / "e.sqlite")
    try:
        import pyarrow.parquet as pq
    except ImportError:
        with pytest.raises(StoreError, match="pyarrow"):
            write_parquet(tmp_path / "e.sqlite", tmp_path / "e.parquet")
        assert not (tmp_path / "e.parquet").exists()
        return
    write_parquet(tmp_path / "e.sqlite", tmp_path / "e.parquet")
    assert pq.read_table(tmp_path / "e.parquet").num_rows == 30


def test_pareto_front_against_brute_force():
    rng = np.random.default_rng(2)
    L = rng.uniform(0, 1, 200)
    C = np.round(rng.uniform(0, 1, 200), 1)           # ties in coverage
    mask = pareto_front(L, C)
    dominated = [any((L[j] <= L[i] and C[j] >= C[i]) and (L[j] < L[i] or C[j] > C[i]) for j in range(200))
                 for i in range(200)]
    np.testing.assert_array_equal(mask, ~np.array(dominated))
