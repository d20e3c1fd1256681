"""Reading a sweep database back: one table of every design, as a pandas ``DataFrame`` when pandas
is installed or a numpy record array otherwise, and written as CSV or (with pyarrow) Parquet.

Columns: ``id``, ``key``, ``architecture``, ``origin``, ``status``, ``attempts``, one column per
design parameter named ``NAME_UNIT`` in the robot file's units (``A1_mm``), ``objective``,
``score``, ``feasible`` and the sweep's metrics (SI: ``structural_length`` in m, coverage and
reach as fractions, ``cycle_time`` in s, ``peak_torque`` in N·m — followed by one
``peak_torque_JOINT`` column per joint, N·m or N), ``error``, ``time_s``, ``seed``, ``worker``.
Metrics of rows not done are NaN.
"""
from __future__ import annotations

import csv
import io
import math
import os
import sqlite3
from pathlib import Path

import numpy as np

from design.sweep.store import StoreError, check_existing, read_rows
from kin.output import write_output

__all__ = ["read_sweep", "sweep_table", "write_csv", "write_parquet", "best_row", "write_atomic", "pareto_front",
           "pareto_rows"]

_MAXIMISE = ("coverage", "gci")


def write_atomic(path: str | os.PathLike, data: str | bytes) -> Path:
    """Write a result file through the project's safe writer (:func:`kin.output.write_output`)."""
    return write_output(path, data)


def read_sweep(db: str | os.PathLike) -> tuple[dict, list[dict]]:
    """(meta, rows) of a sweep database, read-only; a foreign or corrupt file raises StoreError."""
    import json
    path = Path(db)
    if not path.is_file():
        raise StoreError(f"{path}: no such sweep database")
    if not check_existing(path):
        raise StoreError(f"{path}: an empty sweep database (its run was killed while creating it)")
    con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    try:
        meta = {k: json.loads(v) for k, v in con.execute("SELECT key, value FROM meta")}
        rows = read_rows(con)
    finally:
        con.close()
    return meta, rows


def best_row(rows: list[dict], objective: str) -> dict | None:
    """The done row with the best objective among the feasible ones (else the lowest score)."""
    done = [r for r in rows if r["status"] == "done" and r["metrics"]]
    if not done:
        return None
    feas = [r for r in done if r["metrics"].get("feasible")]
    if feas:
        sign = -1.0 if objective in _MAXIMISE else 1.0
        b = min(feas, key=lambda r: (sign * r["metrics"]["objective"], r["id"]))
    else:
        b = min(done, key=lambda r: (r["metrics"]["score"], r["id"]))
    return {"id": b["id"], "key": b["key"], "architecture": b["architecture"], "origin": b["origin"],
            "params": b["params"], "objective": b["metrics"]["objective"], "feasible": b["metrics"]["feasible"],
            "coverage": b["metrics"].get("coverage")}


def _columns(meta: dict, rows: list[dict]) -> dict[str, list]:
    names = meta["parameters"]
    units, scales = meta["units"], meta["scales"]
    metric_names = ["objective", "score", "feasible"] + [m for m in meta["metrics"]]
    if "length_index" in metric_names and "volume" not in metric_names:
        metric_names.append("volume")
    if "peak_torque" in metric_names:            # then the per-joint peaks, in the order the rows hold them
        per = dict.fromkeys(k for r in rows for k in (r["metrics"] or {}) if k.startswith("peak_torque_"))
        at = metric_names.index("peak_torque") + 1
        metric_names[at:at] = list(per)
    cols: dict[str, list] = {k: [] for k in ("id", "key", "architecture", "origin", "status", "attempts")}
    pcols = {n: f"{n}_{units[n]}" for n in names}
    for c in pcols.values():
        cols[c] = []
    for m in metric_names:
        cols[m] = []
    for k in ("error", "time_s", "seed", "worker"):
        cols[k] = []
    for r in rows:
        for k in ("id", "key", "architecture", "origin", "status", "attempts", "error", "time_s", "seed", "worker"):
            cols[k].append(r[k])
        for n in names:
            cols[pcols[n]].append(r["params"][n] / scales[n])
        met = r["metrics"] or {}
        for m in metric_names:
            v = met.get(m)
            cols[m].append(math.nan if v is None else v)
    return cols


def sweep_table(db: str | os.PathLike):
    """Every row of a sweep database: a pandas DataFrame if pandas is installed, else a numpy
    record array (same columns; see the module docstring)."""
    meta, rows = read_sweep(db)
    cols = _columns(meta, rows)
    try:
        import pandas as pd
    except ImportError:
        pd = None
    if pd is not None:
        return pd.DataFrame(cols)
    arrays = []
    for k, v in cols.items():
        if k in ("key", "architecture", "origin", "status", "error", "worker"):
            arrays.append(np.array(["" if x is None else x for x in v], dtype=str))
        elif k == "feasible":
            arrays.append(np.array([bool(x) if not (isinstance(x, float) and math.isnan(x)) else False for x in v]))
        elif k in ("id", "attempts", "seed"):
            arrays.append(np.array(v, dtype=np.int64))
        else:
            arrays.append(np.array([math.nan if x is None else x for x in v], dtype=float))
    return np.rec.fromarrays(arrays, names=list(cols)) if rows else np.rec.fromarrays(
        [np.array(a) for a in arrays], names=list(cols))


def write_csv(db: str | os.PathLike, path: str | os.PathLike) -> Path:
    """The sweep's table as CSV (header line; NaN written as empty)."""
    meta, rows = read_sweep(db)
    cols = _columns(meta, rows)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    for i in range(len(rows)):
        w.writerow(["" if v is None or (isinstance(v, float) and math.isnan(v)) else
                    (repr(v) if isinstance(v, float) else v) for v in (c[i] for c in cols.values())])
    return write_atomic(path, buf.getvalue())


def write_parquet(db: str | os.PathLike, path: str | os.PathLike) -> Path:
    """The sweep's table as Parquet (needs pyarrow)."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        raise StoreError("Parquet export needs pyarrow (pip install pyarrow); CSV works without it") from None
    meta, rows = read_sweep(db)
    table = pa.table(_columns(meta, rows))
    buf = pa.BufferOutputStream()
    pq.write_table(table, buf)
    return write_atomic(path, buf.getvalue().to_pybytes())


def pareto_front(length: np.ndarray, coverage: np.ndarray) -> np.ndarray:
    """Mask (N,) of the designs no other design dominates (shorter or equal structural length and
    higher or equal coverage, one of them strictly)."""
    L, C = np.asarray(length, float), np.asarray(coverage, float)
    order = np.lexsort((-C, L))                 # by length, then by coverage descending
    mask = np.zeros(len(L), bool)
    best = -np.inf
    for i in order:
        if C[i] > best:
            mask[i] = True
            best = C[i]
    return mask


def pareto_rows(rows: list[dict], maximise=("coverage", "mean_score"), minimise=("structural_length",)) -> list[int]:
    """Indices of the rows (metric name → number) no other row dominates — at least as good in every
    metric of ``maximise`` and ``minimise``, better in one; rows missing a metric are left out.  The
    co-design front: coverage, mean reach score and structural length."""
    keys = list(maximise) + list(minimise)
    ok = [i for i, r in enumerate(rows)
          if all(isinstance(r.get(k), (int, float)) and not isinstance(r.get(k), bool) and np.isfinite(r.get(k))
                 for k in keys)]
    if not ok:
        return []
    A = np.array([[rows[i][k] for k in maximise] + [-rows[i][k] for k in minimise] for i in ok], float)
    return [i for a, i in zip(A, ok) if not np.any(np.all(A >= a, axis=1) & np.any(A > a, axis=1))]
