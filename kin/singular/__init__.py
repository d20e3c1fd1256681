"""The singular set of a chain: det J computed exactly and factored (:mod:`kin.singular.determinant`
on the sympy model of :mod:`kin.singular.sympy_model`), each factor's solutions inside the limits
(:mod:`kin.singular.solve`) and its kind (:mod:`kin.singular.kinds`); :func:`analyse_singularities`
(:mod:`kin.singular.analysis`) puts them together, under a time and memory budget
(:mod:`kin.singular.budget`) with a disk cache (:mod:`kin.singular.cache`), and falls back to the
numeric analysis of :mod:`kin.singular.numeric` for chains whose determinant is too big to factor.

A factor's expression is read by :mod:`kin.singular.expression` into the tree of
:mod:`kin.singular.tree` and evaluated by :mod:`kin.singular.evaluate`, none of which needs sympy.
The names below are imported on first use (PEP 562), so that importing one of those light modules
does not import the symbolic analysis (sympy, scipy)."""
from __future__ import annotations

import importlib

_LAZY = {"DEFAULT_EXACT_TIMEOUT": "kin.singular.analysis", "KINDS": "kin.singular.analysis",
         "SingularFactor": "kin.singular.analysis", "SingularityAnalysis": "kin.singular.analysis",
         "analyse_singularities": "kin.singular.analysis", "BudgetError": "kin.singular.budget",
         "SingularComponent": "kin.singular.numeric", "SingularSet": "kin.singular.component"}

__all__ = ["DEFAULT_EXACT_TIMEOUT", "KINDS", "BudgetError", "SingularComponent", "SingularFactor", "SingularSet",
           "SingularityAnalysis", "analyse_singularities"]


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'kin.singular' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
