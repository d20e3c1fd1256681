/* Shared by rmtkit's kernels: inlining, the SIMD pragma, unrolling, the thread limit. */
#ifndef RMT_COMMON_H
#define RMT_COMMON_H
#include <math.h>
#include <stdint.h>
#include <string.h>

#define RMT_INLINE static inline __attribute__((always_inline))
/* a loop over the lanes of a block: vectorised (built with -fopenmp-simd; no OpenMP runtime) */
#define RMT_SIMD _Pragma("omp simd")
/* a loop of a few, constant, iterations written out by the compiler (GCC and clang) */
#define RMT_UNROLL _Pragma("GCC unroll 64")
#define RMT_MAX_THREADS 256

#endif
