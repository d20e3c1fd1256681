"""The bundled studies (``rmt study --list``): each is a module with ``NAME``, ``TITLE``, a docstring
(the report's introduction) and ``run(s: studies.study.Study)``.  Read one, copy it, change it: a copy
runs as ``python my_study.py [--quick] [--out DIR]`` (see :func:`studies.study.script.main`).  A study
is one plain script: it imports the public API (``kin``, ``planning``, ``design``, ``studies.study``,
``studies.plots``, ``studies.report`` and the package's own modules, such as ``studies.toolpaths`` and
``studies.published``) and nothing beside it, so a copy needs no other file.

The modules are imported only when a study is run or listed, so ``rmt --help`` stays fast.
"""
from __future__ import annotations

import importlib
from types import ModuleType

from kin.errors import RmtError

#: the bundled studies in the order ``rmt study --list`` shows them; the first is the default
STUDIES = ("fanuc_singularities", "scara_error_window", "cnc_rrrppp", "ur3_drawing", "puma_configurations",
           "scara_design", "scara_cycle", "fanuc_weld_cell", "fanuc_weld_placement", "module_reconfiguration")
DEFAULT = STUDIES[0]


class UnknownStudyError(RmtError, LookupError):
    """No bundled study has that name."""


def load(name: str) -> ModuleType:
    """The module of a bundled study by name."""
    if name not in STUDIES:
        raise UnknownStudyError(f"unknown study {name!r}; bundled studies: {', '.join(STUDIES)} "
                                "(or give a study .toml file)")
    return importlib.import_module(f"studies.bundled.{name}")
