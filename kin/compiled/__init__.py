"""Fast evaluators of a chain's kinematics: the chain's CasADi graph written into a block kernel that
vectorises across configurations (:mod:`kin.compiled.graph_c`, :mod:`kin.compiled.kernel_source`),
compiled once and cached on disk (:mod:`kin.compiled.build`), with CasADi's virtual machine as the
fallback (:mod:`kin.compiled.evaluator`)."""
from kin.compiled.build import cache_dir, default_threads, find_compiler, requested_arch
from kin.compiled.evaluator import (MEASURE_NAMES, WANT_ALL, WANT_J, WANT_MANIP, WANT_SIGMA, WANT_T, CompiledEvaluator,
                                    VMEvaluator, check_out, make_evaluator, numpy_measures)

__all__ = ["MEASURE_NAMES", "WANT_ALL", "WANT_J", "WANT_MANIP", "WANT_SIGMA", "WANT_T", "CompiledEvaluator",
           "VMEvaluator", "cache_dir", "check_out", "default_threads", "find_compiler", "make_evaluator",
           "numpy_measures", "requested_arch"]
