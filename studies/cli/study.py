"""``rmt study``: run a bundled study by name (default: the FANUC singularity study) or a study file,
write its report, and print its findings and the report's path.
Exit 0 when every finding holds, 1 when one failed (e.g. a plan found no path), 2 on bad input."""
from __future__ import annotations

import sys
from pathlib import Path

from studies.cli.common import EXIT_FAIL, EXIT_OK
from studies.jsonio import dump


def _list() -> str:
    from studies import bundled
    rows = []
    for name in bundled.STUDIES:
        mod = bundled.load(name)
        default = "  (default)" if name == bundled.DEFAULT else ""
        rows.append(f"{name:<22} {mod.TITLE}{default}")
    return "\n".join(rows)


def cmd_study(args, load_robot) -> int:
    from studies import bundled
    from studies.study import study_report, terminal_summary
    if args.list:
        print(_list())
        return EXIT_OK
    quiet = args.quiet or args.json
    # progress lines on a terminal only (a log or a pipe gets the summary alone)
    progress = None if quiet or not sys.stderr.isatty() else (lambda t: print(f"… {t}", file=sys.stderr, flush=True))
    target = args.study or bundled.DEFAULT
    if target.endswith(".toml") or "/" in target or Path(target).is_file():
        from studies.study import kinematics as ks
        from studies.study import run_study
        from studies.study.script import run_directory_name
        study = ks.load_study(target)
        out_dir = Path(args.out) / run_directory_name(study["name"], args.quick)
        results = run_study(study, out_dir, progress, quick=args.quick)
        text = study_report(results, out_dir / "report.html")
        ok = results.get("ok", True)
    else:
        from studies.study import run_module
        s, results, report = run_module(bundled.load(target), args.out, args.quick, progress)
        text = terminal_summary(s, report)
        ok = s.ok
    if args.json:
        print(dump(results))
    elif not args.quiet:
        print(text)
    return EXIT_OK if ok else EXIT_FAIL


def add_commands(add) -> None:
    sp = add("study", cmd_study, "run a bundled study (default: fanuc_singularities) or a study .toml file; writes "
                                 "OUT/NAME/report.html and results.json; exit 1 if a finding failed")
    sp.add_argument("study", metavar="STUDY", nargs="?",
                    help="a bundled study's name (see --list) or a study .toml file (default: fanuc_singularities)")
    sp.add_argument("--list", action="store_true", help="list the bundled studies and exit")
    sp.add_argument("--quick", action="store_true",
                    help="the reduced study: fewer samples, shorter budgets; written to OUT/NAME-quick, beside the "
                         "full report")
    sp.add_argument("--out", default="out", help="output directory; the run goes to OUT/NAME (default: out)")
    sp.add_argument("--quiet", action="store_true", help="print nothing but errors")
