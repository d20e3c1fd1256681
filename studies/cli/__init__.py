"""The ``rmt`` command line: the parser and entry point (:mod:`~studies.cli.main`), shared argument
helpers (:mod:`~studies.cli.common`) and one module per command group."""
from studies.cli.main import main

__all__ = ["main"]
