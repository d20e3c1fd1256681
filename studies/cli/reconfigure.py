"""The reconfiguration options of ``rmt compose`` (:mod:`studies.cli.compose` calls these):

* ``--swap-cost C`` plans a base assembly plus per-part swaps instead of one assembly for every part
  (:func:`design.compose.reconfigure.reconfigure`), with ``--candidates K`` per part;
* ``--store DB`` keeps every verdict in an SQLite cache that later runs read
  (:class:`design.compose.store.VerdictStore`);
* ``--dask ADDRESS|local`` judges on a Dask scheduler, or a LocalCluster of this machine's cores
  (:class:`design.sweep.DaskExecutor`).

docs/modules.md, "Reconfiguration".
"""
from __future__ import annotations

import os
import re
from pathlib import Path

from studies.cli.common import EXIT_FAIL, EXIT_OK, CliInputError, bounded
from studies.jsonio import dump

#: a LocalCluster of ``--dask local`` has at most this many workers
MAX_LOCAL_WORKERS = 64
DEFAULT_CANDIDATES = 5


#: the largest --candidates and --swap-cost (design.compose.reconfigure's MAX_K and MAX_SWAP_COST, written
#: here so that `rmt --help` imports no design module; tests/studies/cli/test_reconfigure_limits.py holds them equal)
MAX_K = 50
MAX_SWAP_COST = 1e12


def add_args(sp) -> None:
    sp.add_argument("--swap-cost", type=bounded(0, MAX_SWAP_COST, "(catalogue currency)"), metavar="C",
                    help="plan a base assembly plus per-part swaps instead of one assembly for all parts: the least "
                         "modules owned + C × swaps (C in the catalogue's currency)")
    sp.add_argument("--candidates", type=bounded(1, MAX_K, "", integer=True), metavar="K",
                    help=f"with --swap-cost: each part's K cheapest feasible assemblies are the candidates (1-{MAX_K}, "
                         f"default {DEFAULT_CANDIDATES}; K × parts ≤ 60, K lowered and said beyond)")
    sp.add_argument("--store", metavar="DB", help="SQLite verdict cache: verdicts are taken from it and added to it "
                                                  "(created when missing; shared by runs and by --swap-cost)")
    sp.add_argument("--dask", metavar="ADDRESS|local",
                    help="judge on Dask: a scheduler address (tcp://HOST:PORT) or local (a LocalCluster, one worker "
                         "process per core)")


def _executor(spec: str):
    from design.sweep import DaskExecutor
    if spec == "local":
        return DaskExecutor(local_workers=max(1, min(MAX_LOCAL_WORKERS, os.cpu_count() or 1)))
    if not spec.startswith(("tcp://", "tls://", "inproc://")):
        raise CliInputError(f"--dask {spec!r} must be local or a scheduler address like tcp://HOST:PORT")
    return DaskExecutor(scheduler=spec)


def judge_hook(args, catalogue, settings):
    """The run's ``judge_many`` (:class:`design.compose.store.VerdictJudge`: the cache of ``--store``,
    the workers of ``--dask``), or None (serial, in this process) without either."""
    if args.swap_cost is None and args.candidates is not None:
        raise CliInputError("rmt compose: --candidates needs --swap-cost (the candidates of a reconfiguration)")
    if args.store is None and args.dask is None:
        return None
    from design.compose.store import VerdictJudge, VerdictStore
    executor = _executor(args.dask) if args.dask is not None else None
    store = VerdictStore(args.store) if args.store is not None else None
    return VerdictJudge(catalogue, settings, store=store, executor=executor, owns_store=True)


def close(judge_many) -> None:
    """Stop the workers and close the cache of :func:`judge_hook`'s judge."""
    if judge_many is not None and hasattr(judge_many, "close"):
        judge_many.close()


def _robot_name(catalogue: str, what: str) -> str:
    return re.sub(r"[^a-z0-9_]+", "_", f"{catalogue}_{what}".lower()).strip("_") or "assembly"


def _write(args, cat, plan) -> dict:
    """reconfiguration.json and a robot file per configuration (the base, each part's) into ``--out``."""
    if args.out is None:
        return {}
    from kin import dumps_robot
    from kin.modules import assemble
    from kin.output import check_output, write_output
    d = Path(args.out)
    written = {}
    if plan.found:
        for what, a in [("base", plan.base), *zip(plan.parts, plan.assemblies)]:
            name = _robot_name(cat.name, what)
            path = check_output(d / f"{name}.toml")
            write_output(path, dumps_robot(assemble(cat, a, name=name), path.parent))
            written[f"robot {what}"] = str(path)
    path = check_output(d / "reconfiguration.json")
    write_output(path, dump({**plan.to_json(), "files": written}) + "\n")
    written["json"] = str(path)
    return written


def run(args, catalogue, parts, space, settings, judge_many, progress) -> int | None:
    """The reconfiguration when ``--swap-cost`` is given (its exit code: 0 a plan, 1 none), else None."""
    if args.swap_cost is None:
        return None
    from design.compose.reconfigure import reconfigure
    from kin.output import check_output
    if args.out is not None:
        check_output(Path(args.out) / "reconfiguration.json")
    plan = reconfigure(catalogue, parts, space, swap_cost=float(args.swap_cost),
                       k=args.candidates or DEFAULT_CANDIDATES, settings=settings, judge_many=judge_many,
                       budget_s=args.budget, max_judged=args.max_judged, progress=progress)
    written = _write(args, catalogue, plan)
    if args.json:
        print(dump({**plan.to_json(), "files": written}))
    else:
        for line in plan.lines():
            print(line)
        if getattr(judge_many, "store", None) is not None:
            print(f"verdict cache {args.store}: {judge_many.hits} taken, {judge_many.judged} judged and added")
        for what, path in written.items():
            print(f"wrote {what}: {path}")
    return EXIT_OK if plan.found else EXIT_FAIL
