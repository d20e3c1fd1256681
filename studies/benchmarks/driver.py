"""The end of every benchmark's ``main``: measure, then print the report (or its JSON).

A benchmark's ``run`` takes ``log`` (progress lines on stderr; None with ``--json``, whose stdout is
one JSON object) and returns the report dictionary; a measurement that fails is an error (exit 1,
one line naming the benchmark), never a MISS.
"""
from __future__ import annotations

import sys
from typing import Callable

from studies.jsonio import dump

__all__ = ["measure_and_print"]


def measure_and_print(name: str, as_json: bool, run: Callable[[Callable[[str], None] | None], dict],
                      format_report: Callable[[dict], str]) -> int:
    """``run(log)`` then print ``format_report(R)`` (or ``dump(R)`` with ``as_json``); the exit code."""
    log = None if as_json else (lambda msg: print(msg, file=sys.stderr, flush=True))
    try:
        R = run(log)
    except Exception as e:  # a failed measurement is an error, not a MISS
        print(f"{name}: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    print(dump(R) if as_json else format_report(R))
    return 0


def repeats_main(prog: str, doc: str, run: Callable[[bool], dict], format_report: Callable[[dict], str],
                 quick_repeats: int, repeats: int, argv: list[str] | None = None) -> int:
    """The ``main`` of a benchmark whose ``run(quick)`` takes the median of repeats: ``--json`` prints
    one JSON object, ``--quick`` takes ``quick_repeats`` repeats instead of ``repeats``."""
    import argparse
    ap = argparse.ArgumentParser(prog=prog, description=doc.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--quick", action="store_true", help=f"{quick_repeats} repeats instead of {repeats}")
    args = ap.parse_args(argv)
    R = run(args.quick)
    print(dump(R) if args.json else format_report(R))
    return 0
