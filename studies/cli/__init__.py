"""The ``rmt`` command line: the parser and entry point (:mod:`~studies.cli.main`), shared argument
helpers (:mod:`~studies.cli.common`) and one module per command group."""
import sys

try:
    from studies.cli.main import main
except KeyboardInterrupt:          # Ctrl-C while the command line starts: one line, no traceback
    print("rmt: interrupted", file=sys.stderr)
    sys.exit(130)

__all__ = ["main"]
