"""Importing OMPL the way rmtkit uses it: quiet logs, reproducible seeds, no leak noise at exit.

OMPL's Python wheels (nanobind) report "leaked" objects when the interpreter shuts down; those
lines are noise for a user, so stderr is closed just before the interpreter finalises (atexit
handlers run first, so everything a program writes itself is already out).
"""
from __future__ import annotations

import atexit
import os
import sys

from ompl import base as ob  # noqa: F401 - re-exported for the planner modules
from ompl import geometric as og  # noqa: F401 - re-exported for the planner modules
from ompl import util as ou

ou.setLogLevel(ou.LogLevel.LOG_WARN)


def quiet_rng_seed(seed: int) -> None:
    """Seed OMPL's random number generation (every RNG created afterwards derives from it).

    OMPL logs an error when the seed changes after the first RNG was made; the new seed still
    governs the RNGs made afterwards (planners and samplers are made per query), so the log is
    silenced for this call.
    """
    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    try:
        ou.RNG.setSeed(int(seed) % (2**31 - 1) + 1)   # 0 would mean "random"
    finally:
        ou.setLogLevel(ou.LogLevel.LOG_WARN)


def _silence_leak_report() -> None:
    if os.environ.get("RMTKIT_SHOW_LEAKS"):
        return
    try:
        sys.stderr.flush()
        sys.stdout.flush()
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 2)
    except OSError:
        pass


atexit.register(_silence_leak_report)
