"""Design optimisation: the IPOPT NLP over parameters and per-target configurations
(:mod:`~design.optimise.nlp`), differential evolution on the verified metric
(:mod:`~design.optimise.de`), the brute-force grid (:mod:`~design.optimise.grid`), the verified
objective (:mod:`~design.optimise.objective`) and the result (:mod:`~design.optimise.result`)."""
from design.optimise.objective import Evaluation, VerifySettings, evaluate_designs
from design.optimise.result import DesignResult
from design.optimise.run import METHODS, optimise

__all__ = ["optimise", "METHODS", "DesignResult", "VerifySettings", "Evaluation", "evaluate_designs"]
