"""The singular set of a chain: det J computed exactly and factored (:mod:`kin.singular.determinant`
on the sympy model of :mod:`kin.singular.sympy_model`), each factor's solutions inside the limits
(:mod:`kin.singular.solve`) and its kind (:mod:`kin.singular.kinds`); :func:`analyse_singularities`
(:mod:`kin.singular.analysis`) puts them together, under a time and memory budget
(:mod:`kin.singular.budget`) with a disk cache (:mod:`kin.singular.cache`), and falls back to the
numeric analysis of :mod:`kin.singular.numeric` for chains whose determinant is too big to factor."""
from kin.singular.analysis import (DEFAULT_EXACT_TIMEOUT, KINDS, SingularFactor, SingularityAnalysis,
                                   analyse_singularities)
from kin.singular.budget import BudgetError
from kin.singular.numeric import SingularComponent

__all__ = ["DEFAULT_EXACT_TIMEOUT", "KINDS", "BudgetError", "SingularComponent", "SingularFactor",
           "SingularityAnalysis", "analyse_singularities"]
