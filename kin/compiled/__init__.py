"""Fast evaluators of a chain's kinematics: the batch kernel ``kernel.c`` (FK, Jacobian and measures
vectorised across configurations) specialised by the chain's generated header, built and cached by
:func:`kin.native.build`, with CasADi's virtual machine as the fallback (:mod:`kin.compiled.evaluator`)."""
from kin.compiled.evaluator import (
                                    MEASURE_NAMES,
                                    WANT_ALL,
                                    WANT_J,
                                    WANT_MANIP,
                                    WANT_SIGMA,
                                    WANT_T,
                                    CompiledEvaluator,
                                    Evaluator,
                                    VMEvaluator,
                                    check_out,
                                    make_evaluator,
                                    numpy_measures,
)
from kin.native.settings import cache_dir, default_threads, find_compiler, requested_arch

__all__ = ["MEASURE_NAMES", "WANT_ALL", "WANT_J", "WANT_MANIP", "WANT_SIGMA", "WANT_T", "CompiledEvaluator",
           "Evaluator", "VMEvaluator", "cache_dir", "check_out", "default_threads", "find_compiler", "make_evaluator",
           "numpy_measures", "requested_arch"]
