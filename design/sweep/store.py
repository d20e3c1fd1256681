"""The sweep store: one SQLite database per sweep, the system of record.

* WAL journal (``synchronous = NORMAL``: a committed transaction survives the death of the process,
  kill -9 included; only an operating-system crash may lose the last commits), a ``schema_version``
  table and SQLite's ``application_id`` marking the file as an rmtkit sweep.
* One row per design in ``designs``; ``key`` (the hash of the normalised design) is UNIQUE, so a
  design is never stored twice.  Statuses: ``pending``, ``running``, ``done``, ``failed``.
* Only the driver writes.  Results are buffered and committed in batches (every ``commit_rows`` rows
  or ``commit_seconds``), so throughput is not bound by fsync.
* One run at a time: the driver holds an exclusive lock on ``PATH.lock`` while it runs.
* An existing file is checked before anything is written to it: a file that is not an SQLite
  database, an SQLite database of something else, a newer schema, a failed integrity check or a
  different sweep's database is refused with one line (:class:`StoreError`), never overwritten.
"""
from __future__ import annotations

import json
import math
import os
import sqlite3
import stat
import time
from pathlib import Path
from typing import Iterable

from design.sweep.file import SweepError
from design.sweep.space import Design

__all__ = ["StoreError", "Store", "STATUSES", "SCHEMA_VERSION", "APPLICATION_ID", "read_rows", "check_existing"]

SCHEMA_VERSION = 1
#: SQLite's application_id of an rmtkit sweep database ("RMTS")
APPLICATION_ID = 0x524D5453
STATUSES = ("pending", "running", "done", "failed")
_HEADER = b"SQLite format 3\x00"

_SCHEMA = """
CREATE TABLE schema_version (version INTEGER NOT NULL);
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE designs (
    id INTEGER PRIMARY KEY,
    key TEXT NOT NULL UNIQUE,
    architecture TEXT NOT NULL,
    params TEXT NOT NULL,
    origin TEXT NOT NULL DEFAULT 'sample',
    status TEXT NOT NULL DEFAULT 'pending' CHECK (status IN ('pending', 'running', 'done', 'failed')),
    attempts INTEGER NOT NULL DEFAULT 0,
    metrics TEXT,
    error TEXT,
    time_s REAL,
    seed INTEGER NOT NULL,
    worker TEXT,
    updated REAL
);
CREATE INDEX designs_status ON designs (status);
"""


class StoreError(SweepError):
    """A sweep database cannot be used (foreign, corrupt, another sweep's, or already there)."""


_COLUMNS = "id, key, architecture, params, origin, status, attempts, metrics, error, time_s, seed, worker"


def read_rows(con: sqlite3.Connection) -> list[dict]:
    """Every design row of a store connection as a dict: params (name → SI value) and metrics
    (or None) decoded from JSON."""
    cur = con.execute(f"SELECT {_COLUMNS} FROM designs ORDER BY id")
    cols = [c[0] for c in cur.description]
    out = []
    for r in cur:
        d = dict(zip(cols, r))
        d["params"] = dict(json.loads(d["params"]))
        d["metrics"] = json.loads(d["metrics"]) if d["metrics"] else None
        out.append(d)
    return out


def check_existing(path: Path, application_id: int = APPLICATION_ID, schema_version: int = SCHEMA_VERSION,
                   what: str = "sweep database", option: str = "--db") -> bool:
    """Refuse, without writing, a file that is not an rmtkit sweep database of this schema; returns
    False for an SQLite database without any table (a run killed while creating it), else True.
    Other rmtkit databases (the composition's verdict cache) pass their own ``application_id``,
    ``schema_version``, name (``what``) and command-line ``option``."""
    st = os.stat(path)
    if not stat.S_ISREG(st.st_mode):
        raise StoreError(f"{path}: not a regular file; refusing to use it as a {what}")
    with open(path, "rb") as fh:
        head = fh.read(100)
    if head[:16] != _HEADER:
        kind = "an empty file" if not head else "not an SQLite database"
        raise StoreError(f"{path}: {kind}; refusing to use or overwrite it (choose another {option})")
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            app = con.execute("PRAGMA application_id").fetchone()[0]
            if app == 0 and con.execute("SELECT COUNT(*) FROM sqlite_master").fetchone()[0] == 0:
                return False       # an empty database: a run killed while creating it (nothing to lose)
            if app != application_id:
                raise StoreError(f"{path}: an SQLite database of another application (application_id {app}); "
                                 "refusing to use or overwrite it")
            check = con.execute("PRAGMA quick_check").fetchone()[0]
            if check != "ok":
                raise StoreError(f"{path}: integrity check failed ({check}); refusing to use it")
            ver = con.execute("SELECT version FROM schema_version").fetchone()
        finally:
            con.close()
    except sqlite3.DatabaseError as e:
        raise StoreError(f"{path}: unreadable {what} ({e}); refusing to use or overwrite it") from None
    if ver is None or ver[0] != schema_version:
        raise StoreError(f"{path}: {what} schema {ver[0] if ver else 'missing'}; this rmtkit reads "
                         f"schema {schema_version}")
    return True


def _run_lock(path: Path):
    """An exclusive lock on ``PATH.lock`` for the life of a run (the kernel drops it when the process
    dies, kill -9 included), so two drivers never write one database."""
    import fcntl
    try:
        fh = open(f"{path}.lock", "a")
    except OSError as e:
        raise StoreError(f"{path}.lock: cannot be created ({e.strerror})") from None
    try:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        fh.close()
        raise StoreError(f"{path}: another sweep run is writing it (locked); wait for it or stop it") from None
    return fh


class Store:
    """An open sweep database.  ``meta`` (str → JSON-able) is written when the file is created and
    compared on reopening: its ``fingerprint`` must match (the same task, evaluation and metrics).

    ``resume``: an existing database is continued; without it an existing file is refused.
    """

    def __init__(self, path: str | os.PathLike, meta: dict, resume: bool = False, commit_rows: int = 100,
                 commit_seconds: float = 0.5):
        self.path = Path(path)
        self.commit_rows, self.commit_seconds = commit_rows, commit_seconds
        exists = os.path.lexists(self.path) and check_existing(self.path)
        if exists:
            if not resume:
                raise StoreError(f"{self.path}: a sweep database is already there; give --resume to continue it "
                                 "or another --db")
        else:
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
            except OSError as e:
                raise StoreError(f"{self.path}: cannot create its folder ({e.strerror})") from None
        self._lock = _run_lock(self.path)
        try:
            self.con = sqlite3.connect(self.path, isolation_level=None, timeout=30.0)
            self.con.execute("PRAGMA journal_mode = WAL")
            self.con.execute("PRAGMA synchronous = NORMAL")
        except sqlite3.Error as e:
            self._lock.close()
            raise StoreError(f"{self.path}: cannot open ({e})") from None
        if exists:
            stored = self.meta()
            if stored.get("fingerprint") != meta.get("fingerprint"):
                self.con.close()
                self._lock.close()
                raise StoreError(f"{self.path}: holds sweep {stored.get('name')!r} with another task, evaluation "
                                 "budget or metrics; refusing to mix its rows (choose another --db)")
        else:
            with self._tx():
                self.con.execute(f"PRAGMA application_id = {APPLICATION_ID}")
                for stmt in _SCHEMA.strip().split(";"):
                    if stmt.strip():
                        self.con.execute(stmt)
                self.con.execute("INSERT INTO schema_version VALUES (?)", (SCHEMA_VERSION,))
                self.con.executemany("INSERT INTO meta VALUES (?, ?)",
                                     [(k, json.dumps(v)) for k, v in meta.items()])
        self._buffer: list[tuple] = []
        self._running: list[str] = []
        self._last = time.monotonic()

    # ---- transactions ---------------------------------------------------------------------------
    class _Tx:
        def __init__(self, con):
            self.con = con

        def __enter__(self):
            self.con.execute("BEGIN IMMEDIATE")

        def __exit__(self, exc_type, *_):
            self.con.execute("ROLLBACK" if exc_type else "COMMIT")

    def _tx(self):
        return Store._Tx(self.con)

    def close(self) -> None:
        """Commit what is buffered and close."""
        if getattr(self, "con", None) is not None:
            self.flush(force=True)
            self.con.close()
            self.con = None
            self._lock.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ---- reading --------------------------------------------------------------------------------
    def meta(self) -> dict:
        return {k: json.loads(v) for k, v in self.con.execute("SELECT key, value FROM meta")}

    def counts(self) -> dict[str, int]:
        """Rows per status (every status present, zero when none)."""
        out = dict.fromkeys(STATUSES, 0)
        out.update(dict(self.con.execute("SELECT status, COUNT(*) FROM designs GROUP BY status")))
        return out

    def designs(self, statuses: Iterable[str]) -> list[Design]:
        """The stored designs with these statuses, in insertion order."""
        st = tuple(statuses)
        rows = self.con.execute(f"SELECT architecture, params, key, origin FROM designs WHERE status IN "
                                f"({','.join('?' * len(st))}) ORDER BY id", st)
        return [Design(a, tuple((k, float(v)) for k, v in json.loads(p)), key, o) for a, p, key, o in rows]

    def rows(self) -> list[dict]:
        """Every row as a dict (params and metrics decoded), in insertion order."""
        return read_rows(self.con)

    # ---- writing (the driver only) --------------------------------------------------------------
    def add(self, designs: Iterable[Design], seed: int) -> int:
        """Insert designs not stored yet (by key) as pending; returns how many were new."""
        now = time.time()
        with self._tx():
            before = self.con.total_changes
            self.con.executemany(
                "INSERT OR IGNORE INTO designs (key, architecture, params, origin, status, seed, updated) "
                "VALUES (?, ?, ?, ?, 'pending', ?, ?)",
                [(d.key, d.architecture, json.dumps(list(d.params)), d.origin, seed, now) for d in designs])
            return self.con.total_changes - before

    def reset_running(self) -> int:
        """``running`` rows of a run that died → ``pending``; returns how many."""
        with self._tx():
            return self.con.execute("UPDATE designs SET status = 'pending', worker = NULL "
                                    "WHERE status = 'running'").rowcount

    def retry_failed(self) -> int:
        """``failed`` rows → ``pending`` (their error is kept until they are evaluated again)."""
        with self._tx():
            return self.con.execute("UPDATE designs SET status = 'pending' WHERE status = 'failed'").rowcount

    def mark_running(self, keys: Iterable[str]) -> None:
        """Buffer: these designs were sent to a worker (attempts + 1)."""
        self._running.extend(keys)
        self.flush()

    def record(self, outcomes) -> None:
        """Buffer the outcomes of designs (see :class:`design.sweep.evaluate.Outcome`)."""
        now = time.time()
        for o in outcomes:
            metrics = json.dumps({k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                                  for k, v in o.metrics.items()}) if o.ok else None
            self._buffer.append(("done" if o.ok else "failed", metrics, o.error, o.time_s, o.worker, now, o.key))
        self.flush()

    def flush(self, force: bool = False) -> bool:
        """Commit the buffered changes when ``commit_rows`` are waiting or ``commit_seconds`` have
        passed (or ``force``); returns whether it committed."""
        n = len(self._buffer) + len(self._running)
        due = n >= self.commit_rows or time.monotonic() - self._last >= self.commit_seconds
        if not n or not (force or due):
            return False
        with self._tx():
            if self._running:
                self.con.executemany("UPDATE designs SET status = 'running', attempts = attempts + 1 "
                                     "WHERE key = ? AND status = 'pending'", [(k,) for k in self._running])
            if self._buffer:
                self.con.executemany("UPDATE designs SET status = ?, metrics = ?, error = ?, time_s = ?, "
                                     "worker = ?, updated = ? WHERE key = ?", self._buffer)
        self._buffer.clear()
        self._running.clear()
        self._last = time.monotonic()
        return True
