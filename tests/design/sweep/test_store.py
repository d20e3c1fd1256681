"""The SQLite store: WAL and schema version, the UNIQUE design key, batched commits seen by another
connection only after they are committed, resets of running rows, and refusal — without writing —
of foreign, corrupt, other-sweep or already-existing databases."""
import sqlite3

import pytest

from design.sweep import Design, Store, StoreError
from design.sweep.evaluate import Outcome
from design.sweep.store import APPLICATION_ID, SCHEMA_VERSION

META = {"name": "t", "fingerprint": "abc"}


def designs(n):
    return [Design.make("", {"A1": 0.1 + 0.01 * i, "A2": 0.2}) for i in range(n)]


def test_new_store_is_wal_with_schema_version(tmp_path):
    db = tmp_path / "s.sqlite"
    with Store(db, META) as s:
        assert s.add(designs(5), seed=0) == 5
        assert s.add(designs(7), seed=0) == 2            # keys already stored are ignored
    con = sqlite3.connect(db)
    assert con.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    assert con.execute("PRAGMA application_id").fetchone()[0] == APPLICATION_ID
    assert con.execute("SELECT version FROM schema_version").fetchall() == [(SCHEMA_VERSION,)]
    assert con.execute("SELECT COUNT(*), COUNT(DISTINCT key) FROM designs").fetchone() == (7, 7)
    with pytest.raises(sqlite3.IntegrityError):
        con.execute("INSERT INTO designs (key, architecture, params, seed) "
                    "SELECT key, '', '[]', 0 FROM designs LIMIT 1")


def test_commits_are_batched_and_running_rows_reset(tmp_path):
    db = tmp_path / "s.sqlite"
    s = Store(db, META, commit_rows=1000, commit_seconds=3600)
    ds = designs(3)
    s.add(ds, seed=0)
    s.mark_running([d.key for d in ds])
    s.record([Outcome(ds[0].key, True, {"objective": 1.0, "score": 1.0, "feasible": True}, None, 0.1, "w"),
              Outcome(ds[1].key, False, None, "ValueError: boom", 0.1, "w")])
    other = sqlite3.connect(db)
    # not yet committed
    assert other.execute("SELECT COUNT(*) FROM designs WHERE status = 'pending'").fetchone()[0] == 3
    assert s.flush(force=True)
    rows = dict(other.execute("SELECT status, COUNT(*) FROM designs GROUP BY status").fetchall())
    assert rows == {"done": 1, "failed": 1, "running": 1}
    assert other.execute("SELECT error, attempts FROM designs WHERE key = ?", (ds[1].key,)).fetchone() == \
        ("ValueError: boom", 1)
    assert s.reset_running() == 1 and s.counts()["pending"] == 1
    assert s.retry_failed() == 1 and s.counts() == {"pending": 2, "running": 0, "done": 1, "failed": 0}
    s.close()


def _refused(path, **kw):
    before = path.read_bytes()
    with pytest.raises(StoreError) as e:
        Store(path, META, resume=True, **kw)
    assert path.read_bytes() == before and "\n" not in str(e.value)
    return str(e.value)


def test_foreign_and_corrupt_files_are_refused_untouched(tmp_path):
    text = tmp_path / "notes.sqlite"
    text.write_text("my notes, not a database\n")
    assert "not an SQLite database" in _refused(text)
    other = tmp_path / "other.sqlite"
    con = sqlite3.connect(other)
    con.execute("CREATE TABLE t (x)")
    con.commit()
    con.close()
    assert "another application" in _refused(other)
    with Store(tmp_path / "ok.sqlite", META) as s:
        s.add(designs(50), seed=0)
    good = (tmp_path / "ok.sqlite").read_bytes()
    bad = tmp_path / "bad.sqlite"
    bad.write_bytes(good[:100] + b"\xff" * (len(good) - 100))      # header intact, pages garbage
    assert "refusing" in _refused(bad)
    empty = tmp_path / "empty.sqlite"
    empty.write_bytes(b"")
    assert "empty file" in _refused(empty)


def test_other_sweep_or_existing_database_is_refused(tmp_path):
    db = tmp_path / "s.sqlite"
    with Store(db, META) as s:
        s.add(designs(2), seed=0)
    with pytest.raises(StoreError, match="--resume"):
        Store(db, META)
    with pytest.raises(StoreError, match="another task"):
        Store(db, {"name": "t", "fingerprint": "different"}, resume=True)
    with Store(db, META, resume=True) as s:
        assert s.counts()["pending"] == 2


def test_an_empty_database_left_by_a_killed_start_is_initialised(tmp_path):
    db = tmp_path / "s.sqlite"
    con = sqlite3.connect(db)
    con.execute("PRAGMA journal_mode = WAL")          # what a run killed right after opening leaves
    con.close()
    with Store(db, META, resume=True) as s:
        assert s.add(designs(3), seed=0) == 3
    assert sqlite3.connect(db).execute("PRAGMA application_id").fetchone()[0] == APPLICATION_ID


def test_one_run_at_a_time(tmp_path):
    db = tmp_path / "s.sqlite"
    first = Store(db, META)
    with pytest.raises(StoreError, match="another sweep run"):
        Store(db, META, resume=True)
    first.close()
    Store(db, META, resume=True).close()                    # the lock is released with the run
