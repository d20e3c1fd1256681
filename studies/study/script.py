"""Running a study module: :func:`run_module` (what ``rmt study NAME`` does) and :func:`main`, the
command line of a study script, so that a copied study runs on its own::

    # my_study.py — a copy of studies/bundled/scara_error_window.py, changed
    ...
    if __name__ == "__main__":
        raise SystemExit(main(sys.modules[__name__]))

and then ``python my_study.py --quick --out results``.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from types import ModuleType

import kin
from studies.study.context import Study, run_study_function

__all__ = ["run_module", "main", "run_directory_name", "terminal_summary"]


def run_directory_name(name: str, quick: bool) -> str:
    """The folder a run of study ``name`` writes: ``NAME``, or ``NAME-quick`` for the reduced run, so
    that a quick look never replaces the full report."""
    return f"{name}-quick" if quick else name


def _check_module(module: ModuleType) -> None:
    for attr in ("NAME", "TITLE", "run"):
        if not hasattr(module, attr):
            raise TypeError(f"study module {module.__name__} lacks {attr} (a study defines NAME, TITLE and run(s))")


def run_module(module: ModuleType, out: str | Path = "out", quick: bool = False, progress=None
               ) -> tuple[Study, dict, Path]:
    """Run a study module into ``OUT/NAME`` (a quick run into ``OUT/NAME-quick``, beside the full
    report, not over it); returns (study, results, report path)."""
    _check_module(module)
    out_dir = Path(out) / run_directory_name(module.NAME, quick)
    s, results = run_study_function(module.run, module.NAME, module.TITLE, out_dir, quick=quick, progress=progress,
                                    summary=(module.__doc__ or "").strip().split("\n\n")[0].replace("\n", " "))
    return s, results, out_dir / "report.html"


def terminal_summary(s: Study, report: Path) -> str:
    """What the terminal shows after a study: the findings, the timings and the report's path."""
    lines = [s.doc.title, ""]
    lines += [("  ✓ " if f.ok else "  ✗ ") + f.text.replace("**", "").replace("`", "") for f in s.doc.findings]
    lines += ["", "  " + ", ".join(f"{sec.title} {sec.seconds:.1f} s" for sec in s.doc.sections), "",
              f"report: {report.resolve()}"]
    return "\n".join(lines)


def main(module: ModuleType, argv: list[str] | None = None) -> int:
    """Command line of a study script: ``[--quick] [--out DIR] [--quiet]``; exit 0, 1 when a finding
    failed, 2 on an error in the study's inputs or output directory (one line, as ``rmt study``
    prints it), 130 on Ctrl-C."""
    _check_module(module)
    prog = Path(sys.argv[0]).name
    try:
        return _main(module, prog, argv)
    except kin.RmtError as e:       # e.g. a changed start or goal inside a window, a foreign file in OUT/NAME
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130


def _main(module: ModuleType, prog: str, argv: list[str] | None) -> int:
    ap = argparse.ArgumentParser(prog=prog, description=module.TITLE)
    ap.add_argument("--quick", action="store_true", help="the reduced study (fewer samples, shorter budgets)")
    ap.add_argument("--out", default="out", help="output directory; the run goes to OUT/NAME (default: out)")
    ap.add_argument("--quiet", action="store_true", help="print nothing but errors")
    args = ap.parse_args(argv)
    progress = None if args.quiet or not sys.stderr.isatty() else \
        (lambda t: print(f"… {t}", file=sys.stderr, flush=True))
    s, _, report = run_module(module, args.out, args.quick, progress)
    if not args.quiet:
        print(terminal_summary(s, report))
    return 0 if s.ok else 1
