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
