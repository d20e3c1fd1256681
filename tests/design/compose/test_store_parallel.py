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


@pytest.mark.slow
def test_the_composition_verdicts_on_a_dask_local_cluster_equal_serial_ones():
    from dataclasses import replace
    from pathlib import Path

    from design.compose import ComposeSettings, load_part
    from design.reach import ReachSettings
    from kin.modules import Assembly
    cat = h.catalogue()
    folder = Path(__file__).resolve().parent / "reconfigure_parts"
    parts = [load_part(folder / "near.toml"), load_part(folder / "far.toml")]
    settings = ComposeSettings(reach=ReachSettings(starts=4, samples=1024), verify=None)
    texts = ["B JL JL LS T", "B JS LL JL T", "B JL LE JL LL T", "B JS JS T", "B JL LL JL@90 LS T"]
    pairs = [(Assembly.parse(t, cat), p) for t in texts for p in parts]
    serial = VerdictJudge(cat, settings)(pairs)
    with VerdictJudge(cat, settings, executor=DaskExecutor(local_workers=2)) as j:
        dask = j(pairs)
    assert [replace(v, seconds=0.0) for v in dask] == [replace(v, seconds=0.0) for v in serial]
    assert {v.stage for v in serial} == {"ok", "reach", "reach_bound", "holding"}     # every kind of verdict
