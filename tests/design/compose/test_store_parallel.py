"""judge_many on worker processes and on a Dask LocalCluster gives the verdicts judged in this
process, in the order asked, and fills the cache the same way (several seconds: slow)."""
from __future__ import annotations

import pytest

from design.compose.store import VerdictJudge, VerdictStore
from design.sweep import DaskExecutor, LocalExecutor
from tests.design.compose import store_helpers as h

PARTS = ([[0.3, 0.0, 0.4]], [[0.5, 0.1, 0.3], [0.2, 0.2, 0.2]], [[0.1, 0.6, 0.2]])


@pytest.mark.slow
@pytest.mark.parametrize("executor", [lambda: LocalExecutor(2), lambda: DaskExecutor(local_workers=2)],
                         ids=["processes", "dask-local"])
def test_parallel_verdicts_equal_serial_ones(tmp_path, executor):
    cat = h.catalogue()
    parts = [h.part(f"p{i}", pts) for i, pts in enumerate(PARTS)]
    pairs = h.pairs(cat, parts)
    serial = VerdictJudge(cat, store=None, judge=h.stand_in_judge)(pairs)
    before = h.CALLS[0]
    with VerdictStore(tmp_path / "v.sqlite", h.StandInVerdict) as store, \
            VerdictJudge(cat, store=store, executor=executor(), judge=h.stand_in_judge) as j:
        first = j(pairs[:7])
        rest = j(pairs)                 # the executor stays open; the first seven come from the cache
        assert (j.judged, j.hits) == (len(pairs), 7)
        assert len(store) == len(pairs)
    assert h.CALLS[0] == before         # judged in the workers, not here
    assert first + rest[7:] == serial and rest == serial
