"""Native kernels: the one helper that compiles and caches C (:func:`build`), the settings it reads
(:mod:`kin.native.settings`), the generated header that specialises a kernel
(:mod:`kin.native.header`, :mod:`kin.native.graph`), and the shared C headers in ``include/``
(``rmt_common.h``; ``rmt_parallel.h``, the one threading model: POSIX threads per call;
``rmt_graph.h``, which evaluates a graph table).

The kernels themselves sit beside the Python that loads them: ``kin/compiled/kernel.c`` (batch
FK/Jacobian/measures and the single-call extension), ``kin/dynamics/kernel.c`` (inverse dynamics,
batch and single call), ``kin/ik/ik.c`` (the batch IK solver) and ``planning/timing/reach.c``
(TOPP-RA's reachability passes); :func:`load_extension` loads a library built as an extension module.
"""
from kin.native.builder import COMMON_FLAGS, NATIVE_TIMEOUT, Library, build, library_dir
from kin.native.extension import build_with_extension, load_extension
from kin.native.fallback import with_fallback
from kin.native.graph import graph_table
from kin.native.header import Header, c_double
from kin.native.settings import cache_dir, default_threads, find_compiler, python_extension_flags, requested_arch

__all__ = ["COMMON_FLAGS", "NATIVE_TIMEOUT", "Header", "Library", "build", "c_double", "cache_dir",
           "default_threads", "find_compiler", "graph_table", "library_dir", "load_extension", "python_extension_flags",
           "requested_arch", "with_fallback", "build_with_extension"]
