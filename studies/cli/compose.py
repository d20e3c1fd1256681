"""``rmt compose CATALOGUE PART.toml [PART.toml ...]``: the least-cost assembly of a module catalogue's
modules that serves every part — reaches every target (the reach study's verdict, with the part's
cell, clearance, dexterity and windows), within the part's cycle time and the joints' torques where
it has a cycle (:func:`design.compose.compose`).

It prints the assembly (its ``rmt assemble --modules`` text), its cost, each part's verdict, where
every assembly of the space went (never formed, proven empty per bound, judged, not needed) and
the answer's verification by a denser reach study; one line per batch on stderr.  ``--out DIR``
writes the robot file and ``compose.json``.  Exit 0 when an assembly is found, 1 when none is, 2
on bad input.  docs/modules.md, "Composition".
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from studies.cli.common import EXIT_FAIL, EXIT_OK, CliInputError, bounded, bundled_file
from studies.jsonio import dump

#: bundled part files (composition tasks): studies/tasks/parts/NAME.toml
PARTS_DIR = Path(__file__).resolve().parent.parent / "tasks" / "parts"
#: at most this many part files
MAX_PARTS = 64
#: the longest budget accepted (s): a week
MAX_BUDGET = 7 * 86400.0


def _joints(text: str) -> tuple[int, int]:
    """argparse type of ``--joints``: N or LO-HI, within 1 … 8."""
    from kin.modules import MAX_JOINTS
    lo, sep, hi = text.partition("-")
    try:
        a, b = int(lo), int(hi) if sep else int(lo)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not N or LO-HI (joint counts)") from None
    if not 1 <= a <= b <= MAX_JOINTS:
        raise argparse.ArgumentTypeError(f"{text} must satisfy 1 ≤ LO ≤ HI ≤ {MAX_JOINTS}")
    return a, b


def reconfiguration_args(sp) -> None:
    """The reconfiguration options of ``rmt compose`` (base assembly plus per-part swaps, the verdict
    cache, Dask): :mod:`studies.cli.reconfigure`."""
    from studies.cli.reconfigure import add_args
    add_args(sp)


def reconfiguration(args, catalogue, parts, space, settings, judge_many, progress) -> int | None:
    """Run the reconfiguration instead of the single-assembly search when its options ask for it
    (returns the exit code), else None."""
    from studies.cli.reconfigure import run
    return run(args, catalogue, parts, space, settings, judge_many, progress)


def judge_hook(args, catalogue, settings):
    """The ``judge_many`` of the run: None for the default (serial, in this process); a cached or
    distributed one from the reconfiguration/storage options."""
    from studies.cli.reconfigure import judge_hook as hook
    return hook(args, catalogue, settings)


def _space(args, cat, parts):
    from design.compose import ComposeSpace
    tools = None
    if args.tool:
        tools = [None if t.lower() == "none" else t for t in args.tool]
    try:
        return ComposeSpace.for_parts(cat, parts, joints=args.joints, bases=args.base, tools=tools,
                                      links_per_joint=args.links_per_joint, twists=args.twists)
    except ValueError as e:
        raise CliInputError(f"rmt compose: {e}") from None


def _settings(args):
    from design.compose import ComposeSettings
    from design.reach import ReachSettings
    from design.task import TaskError
    try:
        reach = ReachSettings(starts=args.starts, samples=args.samples)
        verify = ReachSettings(starts=min(64, 2 * args.starts), samples=4 * args.samples, spins=12, max_iter=300)
        return ComposeSettings(reach=reach, verify=verify, batch=args.batch)
    except (TaskError, ValueError) as e:
        raise CliInputError(f"rmt compose: {e}") from None


def _outputs(args) -> dict[str, Path]:
    if args.out is None:
        return {}
    from kin.output import check_output
    d = Path(args.out)
    out = {"json": d / "compose.json"}
    for p in out.values():
        check_output(p)
    return out


def _write(args, cat, res, outputs: dict[str, Path]) -> dict:
    """The robot file of the answer and compose.json into ``--out``; what was written."""
    if not outputs:
        return {}
    from kin import dumps_robot
    from kin.modules import assemble
    from kin.output import check_output, write_output
    written = {}
    if res.found:
        name = f"{cat.name}_composed"
        path = check_output(Path(args.out) / f"{name}.toml")
        chain = assemble(cat, res.best, name=name)
        write_output(path, dumps_robot(chain, path.parent))
        written["robot"] = str(path)
    report = {**res.to_dict(), "files": written}
    write_output(outputs["json"], dump(report) + "\n")
    written["json"] = str(outputs["json"])
    return written


def cmd_compose(args, load_robot) -> int:
    from design.compose import compose, load_part
    from kin.modules import load_catalogue

    if len(args.parts) > MAX_PARTS:
        raise CliInputError(f"rmt compose: {len(args.parts)} part files; at most {MAX_PARTS}")
    outputs = _outputs(args)
    cat = load_catalogue(args.catalogue)
    parts = [load_part(bundled_file(p, PARTS_DIR, "part")) for p in args.parts]
    names = [p.name for p in parts]
    dup = next((n for n in names if names.count(n) > 1), None)
    if dup is not None:
        raise CliInputError(f"rmt compose: two part files are named {dup!r}; every part needs its own name")
    space = _space(args, cat, parts)
    settings = _settings(args)

    def progress(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    judge_many = judge_hook(args, cat, settings)
    try:
        # ---- reconfiguration: a base assembly plus per-part swaps (its options decide; see reconfiguration()) ----
        code = reconfiguration(args, cat, parts, space, settings, judge_many, progress)
        if code is not None:
            return code
        # ---- one assembly for every part ----
        res = compose(cat, parts, space, settings, budget_s=args.budget, progress=progress, judge_many=judge_many,
                      max_judged=args.max_judged)
    finally:
        from studies.cli.reconfigure import close
        close(judge_many)      # the workers of --dask, the cache of --store
    written = _write(args, cat, res, outputs)
    if args.json:
        print(dump({**res.to_dict(), "files": written}))
    else:
        for line in res.lines():
            print(line)
        for what, path in written.items():
            print(f"wrote {what}: {path}")
    return EXIT_OK if res.found else EXIT_FAIL


def add_commands(add) -> None:
    sp = add("compose", cmd_compose, "the least-cost assembly of catalogue modules that reaches every target of "
                                     "every part (cycle time and torques where a part has a cycle); exit 1 if none")
    sp.add_argument("catalogue", metavar="CATALOGUE", help="bundled module catalogue name or path to a .toml file")
    sp.add_argument("parts", nargs="+", metavar="PART.toml",
                    help="part files (a task file without robot: targets, cell, clearance, dexterity, windows, cycle, "
                         "max_cycle_time; docs/modules.md) or bundled part names")
    sp.add_argument("--joints", type=_joints, default=(3, 7), metavar="LO-HI",
                    help="joint modules per assembly, N or LO-HI within 1-8 (default 3-7)")
    sp.add_argument("--links-per-joint", type=bounded(0, 4, "", integer=True), default=1, metavar="K",
                    help="link modules after each joint module at most (0-4, default 1)")
    sp.add_argument("--base", action="append", metavar="NAME", help="a base module to use (repeat; default: every "
                                                                    "base of the catalogue)")
    sp.add_argument("--tool", action="append", metavar="NAME|none",
                    help="a tool module to end with, or none (repeat; default: every tool, and none)")
    sp.add_argument("--twists", choices=("reduced", "all"), default="reduced",
                    help="reduced (default): twists proven to give the same machine are tried once; all: every "
                         "twist every connector allows")
    sp.add_argument("--budget", type=bounded(0, MAX_BUDGET, "s", open_low=True), metavar="S",
                    help="seconds: exhaustive for the first half, then a stated heuristic (every s-th assembly)")
    sp.add_argument("--max-judged", type=bounded(1, 10**9, "", integer=True), metavar="N",
                    help="at most this many reach verdicts (like --budget: half exhaustive, then the heuristic)")
    sp.add_argument("--batch", type=bounded(1, 4096, "", integer=True), default=8, metavar="N",
                    help="assemblies judged per batch (one progress line each; default 8)")
    sp.add_argument("--starts", type=bounded(1, 64, "", integer=True), default=8, metavar="N",
                    help="the reach study's IK starts per target (default 8; the verification doubles them)")
    sp.add_argument("--samples", type=bounded(16, 500_000, "", integer=True), default=4096, metavar="N",
                    help="the Halton sample the starts are chosen from (default 4096; the verification's is 4x)")
    sp.add_argument("--out", metavar="DIR", help="write the robot file of the answer and compose.json here")
    reconfiguration_args(sp)
