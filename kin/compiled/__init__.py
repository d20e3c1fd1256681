"""Fast evaluators of a chain's kinematics: CasADi's generated C plus a batch kernel of our own
(:mod:`kin.compiled.kernel_source`), compiled once and cached on disk, with CasADi's virtual machine
as the fallback (:mod:`kin.compiled.evaluator`)."""
from kin.compiled.evaluator import (WANT_ALL, WANT_J, WANT_MANIP, WANT_SIGMA, WANT_T, CompiledEvaluator, VMEvaluator,
                                    cache_dir, find_compiler, make_evaluator, numpy_measures)

__all__ = ["WANT_ALL", "WANT_J", "WANT_MANIP", "WANT_SIGMA", "WANT_T", "CompiledEvaluator", "VMEvaluator", "cache_dir",
           "find_compiler", "make_evaluator", "numpy_measures"]
