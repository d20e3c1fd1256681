"""The one rule for choosing between a compiled evaluator and its CasADi-VM twin: :func:`with_fallback`."""
from __future__ import annotations

import warnings
from typing import Callable, TypeVar

from kin.errors import ArgumentError, CompileError
from kin.native.settings import find_compiler

__all__ = ["with_fallback", "BACKENDS"]

BACKENDS = ("auto", "compiled", "vm")
T = TypeVar("T")


def with_fallback(backend: str, compiled: Callable[[str], T], vm: Callable[[], T], what: str) -> T:
    """``compiled(compiler)`` when a C compiler works, else ``vm()``.

    ``backend``: ``"auto"`` (compiled, falling back to the VM with a warning naming ``what`` when
    compiling fails), ``"compiled"`` (raise :class:`CompileError` instead of falling back) or ``"vm"``.
    """
    if backend not in BACKENDS:
        raise ArgumentError(f"backend {backend!r} unknown; allowed: {', '.join(BACKENDS)}")
    if backend == "vm":
        return vm()
    compiler = find_compiler()
    if compiler is None:
        if backend == "compiled":
            raise CompileError("no C compiler found (set CC or RMTKIT_CC)")
        return vm()
    try:
        return compiled(compiler)
    except (CompileError, OSError) as e:
        if backend == "compiled":
            raise CompileError(str(e)) from None
        warnings.warn(f"rmtkit: compiling {what} failed, using CasADi's VM instead ({e})", RuntimeWarning,
                      stacklevel=3)
        return vm()
