"""Loading a built library as a CPython extension module (a kernel compiled with
:func:`~kin.native.settings.python_extension_flags` defines ``PyInit_<RMT_LIBRARY_NAME>``)."""
from __future__ import annotations

import importlib.machinery
import importlib.util
from pathlib import Path

_EXTENSIONS: dict[str, object] = {}


def load_extension(path: Path, name: str):
    """The library's extension module (named ``name``, not entered in ``sys.modules``), or
    None.  Loaded once per file: CPython re-creates a single-phase module it has seen from a cached
    copy, by name, which must never hand one library's functions to another."""
    key = str(path)
    if key not in _EXTENSIONS:
        try:
            loader = importlib.machinery.ExtensionFileLoader(name, key)
            spec = importlib.util.spec_from_file_location(name, key, loader=loader)
            module = importlib.util.module_from_spec(spec)
            loader.exec_module(module)
        except ImportError:
            module = None
        _EXTENSIONS[key] = module
    return _EXTENSIONS[key]


def build_with_extension(name: str, source: Path, header: str, *, arch, compiler, directory, what: str,
                         include_dirs=()):
    """Build ``source`` with ``header`` as a CPython extension module (the single-call entry), or, when
    that does not compile (no Python or numpy headers), as a plain library: the
    :class:`~kin.native.builder.Library` and its extension module (None for a plain one).  An extension
    module is tied to the Python and numpy ABIs, which are part of its cache key."""
    import sys

    import numpy as np

    from kin.errors import CompileError
    from kin.native.builder import build
    from kin.native.settings import python_extension_flags
    variants = list(dict.fromkeys([python_extension_flags(), ()]))
    for k, extra in enumerate(variants):
        abi = (sys.version, np.__version__) if extra else ()
        try:
            lib = build(name, source, header, flags=extra, key=abi, arch=arch, compiler=compiler,
                        directory=directory, what=what, include_dirs=include_dirs)
        except CompileError:
            if k == len(variants) - 1:
                raise
            continue
        return lib, (load_extension(lib.path, lib.module_name) if extra else None)
    raise CompileError(f"{what}: nothing to build")          # unreachable: variants is never empty
