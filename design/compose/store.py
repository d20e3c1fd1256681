"""Verdicts kept and verdicts in parallel: an SQLite cache of composition verdicts, so re-runs and
larger searches reuse what was judged, and a ``judge_many`` that judges what the cache lacks in
worker processes — locally or on Dask — through the sweep's executors.

The cache (:class:`VerdictStore`) holds one row per (catalogue, assembly, part, settings): the
catalogue's and the part's *content* hashes (:func:`content_hash`: every field, numpy arrays in full;
not the file's path, so a copy of a file shares its verdicts and an edit of any value does not), the
assembly's text, and the judge settings' hash; the verdict as JSON.  It reuses the sweep store's
checks (:func:`design.sweep.store.check_existing`: an existing file that is not this cache — not
SQLite, another application's, a newer schema, failing its integrity check — is refused with one
line, never overwritten), its WAL journal and :func:`kin.output.check_output`'s path rules.  Several
runs may share one cache: rows are only inserted, in short transactions.

:class:`VerdictJudge` is the ``judge_many`` hook of :func:`design.compose.search.compose` and
:func:`design.compose.reconfigure.reconfigure`: the cache first, then the misses (each distinct pair
once) judged in this process, or on an executor of :mod:`design.sweep` (:class:`~design.sweep.LocalExecutor`,
:class:`~design.sweep.DaskExecutor`) opened on the first miss and kept for later calls.  Verdicts do
not depend on where they are judged (a verdict is a pure function of its inputs), so serial, local
and Dask runs give the same verdicts.
"""
from __future__ import annotations

import dataclasses
import enum
import hashlib
import json
import math
import os
import sqlite3
import time
import traceback
from dataclasses import dataclass
from typing import Callable

import numpy as np

from design.sweep.store import StoreError, check_existing
from kin.errors import RmtError

__all__ = ["VerdictStore", "VerdictJudge", "VerdictJob", "JudgeError", "content_hash", "APPLICATION_ID",
           "SCHEMA_VERSION"]

#: SQLite's application_id of an rmtkit verdict cache ("RMTC")
APPLICATION_ID = 0x524D5443
SCHEMA_VERSION = 1
_SCHEMA = """
CREATE TABLE schema_version (version INTEGER NOT NULL);
CREATE TABLE verdicts (
    catalogue TEXT NOT NULL,
    assembly TEXT NOT NULL,
    part TEXT NOT NULL,
    settings TEXT NOT NULL,
    verdict TEXT NOT NULL,
    feasible INTEGER NOT NULL,
    stage TEXT NOT NULL,
    catalogue_name TEXT NOT NULL,
    part_name TEXT NOT NULL,
    created REAL NOT NULL,
    PRIMARY KEY (catalogue, assembly, part, settings)
) WITHOUT ROWID;
"""
#: fields left out of a content hash: where a value was read from, not what it is
_NOT_CONTENT = {"Catalogue": ("path",), "Task": ("source",), "Part": ("source",)}


class JudgeError(RmtError):
    """A verdict could not be had: the judge raised, or its worker died every time it was tried."""


# ---- content hashes ------------------------------------------------------------------------------
def _feed(h, x, seen: set, depth: int) -> None:
    if depth > 64:
        raise ValueError("content_hash: nested deeper than 64 levels")
    if x is None or isinstance(x, (bool, int, str, bytes)):
        h.update(f"{type(x).__name__}:{x!r};".encode())
    elif isinstance(x, float):
        h.update(f"f:{x!r};".encode())
    elif isinstance(x, (np.generic, np.ndarray)):
        a = np.ascontiguousarray(x)
        if a.dtype == object:
            h.update(f"O{a.shape}[".encode())
            for v in a.ravel():
                _feed(h, v, seen, depth + 1)
            h.update(b"]")
        else:
            h.update(f"nd:{a.dtype.str}:{a.shape}:".encode())
            h.update(a.tobytes())
    elif isinstance(x, enum.Enum):
        h.update(f"enum:{type(x).__qualname__}.{x.name};".encode())
    elif isinstance(x, (list, tuple)):
        h.update(f"{type(x).__name__}{len(x)}[".encode())
        for v in x:
            _feed(h, v, seen, depth + 1)
        h.update(b"]")
    elif isinstance(x, (set, frozenset)):
        subs = sorted(content_hash(v) for v in x)
        h.update(f"set{len(subs)}[{','.join(subs)}]".encode())
    elif isinstance(x, dict):
        subs = sorted(((content_hash(k), v) for k, v in x.items()), key=lambda kv: kv[0])
        h.update(f"dict{len(subs)}[".encode())
        for k, v in subs:
            h.update(k.encode())
            _feed(h, v, seen, depth + 1)
        h.update(b"]")
    elif callable(x) and hasattr(x, "__qualname__"):
        h.update(f"fn:{getattr(x, '__module__', '')}.{x.__qualname__};".encode())
    else:
        if id(x) in seen:
            raise ValueError(f"content_hash: {type(x).__name__} refers back to itself")
        seen.add(id(x))
        name = type(x).__qualname__
        skip = _NOT_CONTENT.get(type(x).__name__, ())
        if dataclasses.is_dataclass(x):
            items = [(f.name, getattr(x, f.name)) for f in dataclasses.fields(x) if f.name not in skip]
        elif hasattr(x, "__dict__"):
            items = sorted((k, v) for k, v in vars(x).items() if not k.startswith("_") and k not in skip)
        else:            # no fields to walk: its text (an address in it only costs cache hits)
            items = [("repr", repr(x))]
        h.update(f"obj:{type(x).__module__}.{name}[".encode())
        for k, v in items:
            h.update(f"{k}=".encode())
            _feed(h, v, seen, depth + 1)
        h.update(b"]")
        seen.discard(id(x))


def content_hash(x) -> str:
    """SHA-256 (hex) of a value's content: dataclasses and objects by their fields (a catalogue's
    ``path`` and a task's or part's ``source`` left out), numpy arrays by dtype, shape and bytes,
    floats by their exact text.  Equal content gives equal hashes in any process."""
    h = hashlib.sha256()
    _feed(h, x, set(), 0)
    return h.hexdigest()


# ---- the cache -----------------------------------------------------------------------------------
def _verdict_json(v) -> str:
    return json.dumps(dataclasses.asdict(v), sort_keys=True)


def _verdict_from(text: str, cls):
    try:
        d = json.loads(text)
        names = {f.name for f in dataclasses.fields(cls)}
        if set(d) != names:
            return None           # written by another version of the verdict: judged again
        return cls(**d)
    except (ValueError, TypeError):
        return None


class VerdictStore:
    """An open verdict cache at ``path`` (created, with its folder, when missing).  ``verdict_cls``:
    the verdict dataclass (default :class:`design.compose.verdict.Verdict`)."""

    def __init__(self, path: str | os.PathLike, verdict_cls=None):
        from kin.output import OutputError, check_output
        if verdict_cls is None:
            from design.compose.verdict import Verdict
            verdict_cls = Verdict
        self.verdict_cls = verdict_cls
        try:
            self.path = check_output(path)
        except OutputError as e:
            raise StoreError(f"--store {e}") from None
        exists = os.path.lexists(self.path) and check_existing(
            self.path, APPLICATION_ID, SCHEMA_VERSION, what="composition verdict cache", option="--store")
        if not exists:
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
            except OSError as e:
                raise StoreError(f"{self.path}: cannot create its folder ({e.strerror})") from None
        try:
            self.con = sqlite3.connect(self.path, isolation_level=None, timeout=30.0)
            self.con.execute("PRAGMA journal_mode = WAL")
            self.con.execute("PRAGMA synchronous = NORMAL")
            if not exists:
                self.con.execute("BEGIN IMMEDIATE")
                if self.con.execute("PRAGMA application_id").fetchone()[0] == 0:    # not made meanwhile
                    self.con.execute(f"PRAGMA application_id = {APPLICATION_ID}")
                    for stmt in _SCHEMA.strip().split(";"):
                        if stmt.strip():
                            self.con.execute(stmt)
                    self.con.execute("INSERT INTO schema_version VALUES (?)", (SCHEMA_VERSION,))
                self.con.execute("COMMIT")
        except sqlite3.Error as e:
            raise StoreError(f"{self.path}: cannot open the verdict cache ({e})") from None

    def close(self) -> None:
        if getattr(self, "con", None) is not None:
            self.con.close()
            self.con = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __len__(self) -> int:
        return self.con.execute("SELECT COUNT(*) FROM verdicts").fetchone()[0]

    def get_many(self, keys: list[tuple[str, str, str, str]]) -> dict:
        """The stored verdicts of these keys (catalogue hash, assembly text, part hash, settings hash)."""
        out = {}
        for k in dict.fromkeys(keys):
            row = self.con.execute("SELECT verdict FROM verdicts WHERE catalogue = ? AND assembly = ? AND part = ? "
                                   "AND settings = ?", k).fetchone()
            if row is not None and (v := _verdict_from(row[0], self.verdict_cls)) is not None:
                out[k] = v
        return out

    def put_many(self, rows: list[tuple[tuple[str, str, str, str], object, str, str]]) -> None:
        """Store (key, verdict, catalogue name, part name) rows in one transaction."""
        if not rows:
            return
        now = time.time()
        self.con.execute("BEGIN IMMEDIATE")
        try:
            self.con.executemany("INSERT OR REPLACE INTO verdicts VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                                 [(*k, _verdict_json(v), int(bool(v.feasible)), str(v.stage), cn, pn, now)
                                  for k, v, cn, pn in rows])
        except BaseException:
            self.con.execute("ROLLBACK")
            raise
        self.con.execute("COMMIT")


# ---- judging, here or on workers -----------------------------------------------------------------
#: fields of the composition settings that do not change a verdict (how many are judged at once,
#: how an answer is verified afterwards): left out of the cache key, so compose and reconfigure share
_NOT_JUDGED = ("batch", "verify")


def _judged(settings):
    if dataclasses.is_dataclass(settings) and type(settings).__name__ == "ComposeSettings":
        return {f.name: getattr(settings, f.name) for f in dataclasses.fields(settings) if f.name not in _NOT_JUDGED}
    return settings


@dataclass(frozen=True)
class _Item:
    key: str                 # the item's number in its call (executors name lost chunks by it)
    assembly: object
    part: object


@dataclass(frozen=True)
class VerdictJob:
    """What a worker needs to judge (picklable): the catalogue, the judge settings and the judge
    (a module-level function; None: :func:`design.compose.verdict.judge`)."""

    catalogue: object
    settings: object
    judge: Callable | None = None

    def run_chunk(self, items: list[_Item]) -> list[tuple[str, object, str | None]]:
        """(key, verdict, None) per item, or (key, None, error) where the judge raised."""
        fn = self.judge
        if fn is None:
            from design.compose.verdict import judge as fn
        out = []
        for it in items:
            try:
                out.append((it.key, fn(self.catalogue, it.assembly, it.part, self.settings), None))
            except Exception as e:          # said by the driver, with the assembly and the part
                last = traceback.extract_tb(e.__traceback__)[-1] if e.__traceback__ else None
                where = f" ({os.path.basename(last.filename)}:{last.lineno})" if last else ""
                out.append((it.key, None, f"{type(e).__name__}: {(str(e).splitlines() or [''])[0]}{where}"))
        return out


class VerdictJudge:
    """``judge_many(pairs)`` → verdicts, in order: each (assembly, part) looked up in ``store``
    (a :class:`VerdictStore`, or None), the rest judged once each — in this process, or on
    ``executor`` (an unopened :class:`design.sweep.LocalExecutor` / :class:`design.sweep.DaskExecutor`;
    opened on the first miss, closed by :meth:`close`) — and stored.  ``hits`` and ``judged`` count
    the verdicts taken from the cache and judged.  ``owns_store``: :meth:`close` closes the store too."""

    def __init__(self, catalogue, settings=None, store: VerdictStore | None = None, executor=None,
                 judge: Callable | None = None, owns_store: bool = False):
        self.catalogue, self.settings, self.store, self.executor = catalogue, settings, store, executor
        self.owns_store = owns_store
        self.job = VerdictJob(catalogue, settings, judge)
        self._cat_hash = content_hash(catalogue)
        self._set_hash = content_hash(_judged(settings))
        self._part_hash: dict[int, tuple[object, str]] = {}
        self._open = False
        self.hits = self.judged = 0

    def _key(self, assembly, part) -> tuple[str, str, str, str]:
        ph = self._part_hash.get(id(part))
        if ph is None or ph[0] is not part:
            ph = self._part_hash[id(part)] = (part, content_hash(part))
        return (self._cat_hash, assembly.text(self.catalogue), ph[1], self._set_hash)

    def __call__(self, pairs) -> list:
        pairs = list(pairs)
        keys = [self._key(a, p) for a, p in pairs]
        found = self.store.get_many(keys) if self.store is not None else {}
        self.hits += sum(k in found for k in keys)
        todo = {}
        for k, (a, p) in zip(keys, pairs):
            if k not in found and k not in todo:
                todo[k] = (a, p)
        if todo:
            new = self._judge(list(todo.items()))
            found.update(new)
            if self.store is not None:
                self.store.put_many([(k, v, self.catalogue.name, str(getattr(todo[k][1], "name", "")))
                                     for k, v in new.items()])
        return [found[k] for k in keys]

    def _judge(self, todo: list) -> dict:
        items = [_Item(str(i), a, p) for i, (_, (a, p)) in enumerate(todo)]
        if self.executor is None:
            results = self.job.run_chunk(items)
        else:
            results = self._on_executor(items)
        out = {}
        for key, v, err in results:
            i = int(key)
            if v is None:
                a, p = todo[i][1]
                raise JudgeError(f"judging {a.text(self.catalogue)} for part {getattr(p, 'name', '?')!r} "
                                 f"failed: {err}")
            out[todo[i][0]] = v
        self.judged += len(out)
        return out

    def _on_executor(self, items: list[_Item]) -> list:
        from design.sweep.evaluate import Outcome
        if not self._open:
            self.executor.open(self.job)
            self._open = True
        workers = max(1, getattr(self.executor, "workers", 1))
        size = max(1, min(8, math.ceil(len(items) / (4 * workers))))
        chunks = iter([items[i:i + size] for i in range(0, len(items), size)])
        results = []
        for out in self.executor.run(lambda: next(chunks, None), lambda chunk: None):
            for o in out:
                if isinstance(o, Outcome):        # the chunk's worker died every time it was sent
                    results.append((o.key, None, o.error))
                else:
                    results.append(o)
        return results

    def close(self) -> None:
        """Stop the executor's workers (and close the cache if it is owned)."""
        if self._open:
            self._open = False
            self.executor.close()
        if self.owns_store and self.store is not None:
            self.store.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

