"""The verdict cache (design.compose.store): a stored verdict comes back equal without judging again,
keyed by content (a copy of the catalogue or part at another path hits, any changed value misses),
foreign files are refused with one line, and a judge's failure is named."""
from __future__ import annotations

import dataclasses
import sqlite3
from dataclasses import replace

import numpy as np
import pytest

from design.compose.store import JudgeError, VerdictJudge, VerdictStore, content_hash
from design.sweep.store import StoreError
from tests.design.compose import store_helpers as h

PARTS = ([[0.3, 0.0, 0.4]], [[0.5, 0.1, 0.3], [0.2, 0.2, 0.2]])


def _judge(cat, store):
    return VerdictJudge(cat, settings={"samples": 3}, store=store, judge=h.stand_in_judge)


def test_a_cached_verdict_is_returned_equal_without_judging_again(tmp_path):
    cat = h.catalogue()
    parts = [h.part(f"p{i}", pts) for i, pts in enumerate(PARTS)]
    pairs = h.pairs(cat, parts) + h.pairs(cat, parts)[:3]          # repeats are judged once
    before = h.CALLS[0]
    with VerdictStore(tmp_path / "v.sqlite", h.StandInVerdict) as store:
        first = _judge(cat, store)(pairs)
        assert h.CALLS[0] - before == 10 and len(store) == 10
    assert first == [h.stand_in_judge(cat, a, p, None) for a, p in pairs]
    before = h.CALLS[0]
    with VerdictStore(tmp_path / "v.sqlite", h.StandInVerdict) as store:     # another run
        j = _judge(cat, store)
        again = j(pairs)
        assert h.CALLS[0] == before and (j.hits, j.judged) == (13, 0)
    assert again == first
    assert any(v.feasible for v in again) and not all(v.feasible for v in again)


def test_the_key_is_content_not_where_it_was_read(tmp_path):
    cat = h.catalogue()
    p = h.part("p0", PARTS[0])
    pairs = h.pairs(cat, [p])
    with VerdictStore(tmp_path / "v.sqlite", h.StandInVerdict) as store:
        _judge(cat, store)(pairs)
        moved = replace(cat, path="/elsewhere/copy.toml")
        copy = h.part("p0", PARTS[0])
        copy = replace(copy, source="/elsewhere/p0.toml")
        j = _judge(moved, store)
        j([(a, copy) for a, _ in pairs])
        assert (j.hits, j.judged) == (5, 0)
        # a target moved by 1e-9 m, a module's cost changed, other settings: judged again
        nudged = h.part("p0", np.asarray(PARTS[0]) + [1e-9, 0, 0])
        j = _judge(cat, store)
        j([(a, nudged) for a, _ in pairs])
        assert (j.hits, j.judged) == (0, 5)
        dear = replace(cat, modules={**cat.modules, "T": replace(cat.modules["T"], cost=501.0)})
        j = _judge(dear, store)
        j(pairs)
        assert (j.hits, j.judged) == (0, 5)
        j = VerdictJudge(cat, settings={"samples": 4}, store=store, judge=h.stand_in_judge)
        j(pairs)
        assert (j.hits, j.judged) == (0, 5)
    assert content_hash(cat) == content_hash(moved) != content_hash(dear)
    assert content_hash({"a": 1.0, "b": (1, 2)}) == content_hash({"b": (1, 2), "a": 1.0})
    assert content_hash(np.zeros(3)) != content_hash(np.zeros(4)) != content_hash(1.0) != content_hash(1)


def test_a_verdict_of_another_shape_is_judged_again(tmp_path):
    cat = h.catalogue()
    pairs = h.pairs(cat, [h.part("p0", PARTS[0])])[:2]
    with VerdictStore(tmp_path / "v.sqlite", h.StandInVerdict) as store:
        _judge(cat, store)(pairs)
    fields = [f.name for f in dataclasses.fields(h.StandInVerdict)]
    Narrower = dataclasses.make_dataclass("Narrower", fields[:-1])
    with VerdictStore(tmp_path / "v.sqlite", Narrower) as store:
        assert store.get_many([(content_hash(cat), pairs[0][0].text(cat), "x", "y")]) == {}
        key = next(iter(store.con.execute("SELECT catalogue, assembly, part, settings FROM verdicts")))
        assert store.get_many([tuple(key)]) == {}


def test_foreign_files_are_refused_with_one_line(tmp_path):
    text = tmp_path / "notes.sqlite"
    text.write_text("not a database\n")
    with pytest.raises(StoreError, match=r"notes.sqlite: not an SQLite database; refusing .*--store") as e:
        VerdictStore(text, h.StandInVerdict)
    assert "\n" not in str(e.value)
    assert text.read_text() == "not a database\n"
    other = tmp_path / "other.sqlite"
    con = sqlite3.connect(other)
    con.execute("CREATE TABLE t (x)")
    con.commit()
    con.close()
    with pytest.raises(StoreError, match="another application"):
        VerdictStore(other, h.StandInVerdict)
    with pytest.raises(StoreError, match="directory"):
        VerdictStore(tmp_path, h.StandInVerdict)
    newer = tmp_path / "newer.sqlite"
    VerdictStore(newer, h.StandInVerdict).close()
    con = sqlite3.connect(newer)
    con.execute("UPDATE schema_version SET version = 99")
    con.commit()
    con.close()
    with pytest.raises(StoreError, match="composition verdict cache schema 99; this rmtkit reads schema 1"):
        VerdictStore(newer, h.StandInVerdict)


def test_a_sweep_database_is_not_a_verdict_cache(tmp_path):
    from design.sweep.store import Store
    db = tmp_path / "sweep.sqlite"
    Store(db, {"fingerprint": "x"}).close()
    with pytest.raises(StoreError, match="another application"):
        VerdictStore(db, h.StandInVerdict)


def test_a_judge_that_raises_is_named():
    cat = h.catalogue()
    p = h.part("p0", PARTS[0])
    j = VerdictJudge(cat, store=None, judge=h.failing_judge)
    with pytest.raises(JudgeError, match=r"judging B JS LS JL T for part 'p0' failed: ValueError: no verdict here"):
        j(h.pairs(cat, [p])[:1])
