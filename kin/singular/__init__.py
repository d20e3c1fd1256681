"""The singular set of a chain: det J computed exactly and factored (:mod:`kin.singular.determinant`
on the sympy model of :mod:`kin.singular.sympy_model`), each factor's solutions inside the limits
(:mod:`kin.singular.solve`) and its kind (:mod:`kin.singular.kinds`); :func:`analyse_singularities`
(:mod:`kin.singular.analysis`) puts them together."""
from kin.singular.analysis import KINDS, SingularFactor, SingularityAnalysis, analyse_singularities

__all__ = ["KINDS", "SingularFactor", "SingularityAnalysis", "analyse_singularities"]
