"""``rmt study``: run a study file (default: the bundled FANUC M-16iB/20 study) and print its report.
Exit 0 when every section succeeded, 1 when the plan found no path, 2 on bad input."""
from __future__ import annotations

import sys
from pathlib import Path

from studies.cli.common import EXIT_FAIL, EXIT_OK, dump


def cmd_study(args, load_robot) -> int:
    from studies.study import kinematics as ks
    from studies.study import run_study, study_report
    study = ks.load_study(args.study or ks.DEFAULT_STUDY)
    out_dir = Path(args.out) / study["name"]
    quiet = args.quiet or args.json
    progress = None if quiet or not sys.stderr.isatty() else (lambda t: print(f"… {t}", file=sys.stderr))
    results = run_study(study, out_dir, progress)
    if args.json:
        print(dump(results))
    elif not args.quiet:
        print(study_report(results, out_dir / "results.json"))
    return EXIT_OK if results.get("ok", True) else EXIT_FAIL


def add_commands(add) -> None:
    sp = add("study", cmd_study, "run a study (default: the bundled FANUC M-16iB/20 study); exit 1 if its plan "
                                 "finds no path")
    sp.add_argument("study", metavar="STUDY", nargs="?", help="study .toml file (default: bundled)")
    sp.add_argument("--out", default="out", help="output directory; the run goes to OUT/NAME (default: out)")
    sp.add_argument("--quiet", action="store_true", help="print nothing but errors")
