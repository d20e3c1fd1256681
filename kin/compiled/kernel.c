/* rmtkit batch kernel: forward kinematics, Jacobian and dexterity measures of one chain, vectorised
   across configurations.  Specialised by rmt_generated.h (kin/compiled/evaluator.py): RMT_N joints,
   RMT_M task rows RMT_ROWS, RMT_NP design parameters, RMT_B lanes per block, RMT_REVOLUTE,
   RMT_PRISMATIC_MAX and the chain's graph as the instruction table RMT_GRAPH (kin/native/graph.py).

   A batch is cut into blocks of RMT_B configurations.  Each block is transposed to structure of
   arrays (joint j of lane l at [j*B + l]), then every stage is a plain loop over the lanes that the
   compiler vectorises:
   1. sin and cos of every revolute joint value (rmt_sincos.h);
   2. the chain's tool pose T and geometric Jacobian J from the graph table (rmt_graph.h);
   3. the dexterity measures of the task Jacobian (measures.h): manipulability and det by a
      Householder QR, sigma_min and the condition number by a one-sided Jacobi SVD;
   4. the block is transposed back into the caller's row-major (N, 4, 4), (N, 6, n) and measure arrays.

   Threads: rmt_eval runs the blocks through rmt_parallel_for (POSIX threads for the call; none
   below 8192 configurations; at least 4096 configurations per thread).

   The single-call path: rmt_eval_g works on library-owned buffers (through ctypes); compiled with
   RMT_PYEXT the library is also a CPython extension module (pyext.h). */
#include "rmt_generated.h"
#include "rmt_common.h"
#include "rmt_graph.h"
#include "rmt_parallel.h"
#include "rmt_sincos.h"
#include "measures.h"
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#define RMT_NP1 (RMT_NP > 0 ? RMT_NP : 1)
#define RMT_CHUNK 8              /* blocks taken by a thread at a time */
#define RMT_STREAM_BYTES (8LL << 20)
#define RMT_MIN_PER_THREAD 4096

#define RMT_WANT_T 1
#define RMT_WANT_J 2
#define RMT_WANT_MANIP 4
#define RMT_WANT_SIGMA 8

/* T (4x4) and J (6xn), column-major, of nl lanes from cos, sin, q (joint-major) and p. */
RMT_INLINE void rmt_graph(int nl, int ld, const double* restrict c, const double* restrict s,
                          const double* restrict q, const double* restrict p, double* restrict T,
                          double* restrict J) {
  (void)c; (void)s; (void)q; (void)p;
  RMT_SIMD
  for (int l = 0; l < nl; ++l) {
    RMT_GRAPH_EVAL(RMT_GRAPH)
  }
}

/* Lane-minor scratch of one block, and the block's outputs in the caller's layout. */
typedef struct {
  double q[RMT_N * RMT_B], c[RMT_N * RMT_B], s[RMT_N * RMT_B], p[RMT_NP1 * RMT_B];
  double T[16 * RMT_B], J[6 * RMT_N * RMT_B], a[RMT_R * RMT_C * RMT_B];
  double m[4 * RMT_B];
  double Tout[16 * RMT_B] __attribute__((aligned(64)));
  double Jout[6 * RMT_N * RMT_B] __attribute__((aligned(64)));
} rmt_scratch;

typedef struct {
  const double* q; const double* p; long long N, pstride;
  double* T; double* J; double* mo[4]; long long mstride; int flags, stream;
} rmt_args;

/* Copy cnt doubles to dst; with stream set, by non-temporal stores (no read-for-ownership of the
   destination lines, which would double the memory traffic of a batch far larger than the caches). */
static void rmt_put(double* restrict dst, const double* restrict src, long long cnt, int stream) {
#if defined(__SSE2__)
  if (stream && !((uintptr_t)dst & 15)) {
    long long i = 0;
    for (; i + 1 < cnt; i += 2) _mm_stream_pd(dst + i, _mm_load_pd(src + i));
    if (i < cnt) dst[i] = src[i];
    return;
  }
#endif
  memcpy(dst, src, (size_t)cnt * sizeof(double));
}

/* Evaluate rows [i0, i0 + cnt) of the batch (cnt <= RMT_B).  Not inlined into rmt_blocks: inlined,
   the block's code is register-allocated worse (FK + J 20 % slower with GCC 12). */
static __attribute__((noinline)) void rmt_block(const rmt_args* A, long long i0, int cnt, rmt_scratch* S) {
  const int B = RMT_B;
  const double* q = A->q + i0 * RMT_N;
  for (int l = 0; l < B; ++l) {
    const double* ql = q + (long long)(l < cnt ? l : 0) * RMT_N;
    for (int j = 0; j < RMT_N; ++j) S->q[j*B + l] = ql[j];
  }
  if (RMT_NP > 0) {
    for (int l = 0; l < B; ++l) {
      const double* pl = A->p + (i0 + (l < cnt ? l : 0)) * A->pstride;
      for (int j = 0; j < RMT_NP; ++j) S->p[j*B + l] = pl[j];
    }
  }
  rmt_sincos(B, B, S->q, S->c, S->s);
  rmt_graph(B, B, S->c, S->s, S->q, S->p, S->T, S->J);
  int flags = A->flags;
  if (flags & RMT_WANT_T) {
    for (int l = 0; l < cnt; ++l) for (int r = 0; r < 4; ++r) for (int k = 0; k < 4; ++k)
      S->Tout[l*16 + r*4 + k] = S->T[(k*4 + r)*B + l];
    rmt_put(A->T + i0 * 16, S->Tout, 16LL * cnt, A->stream);
  }
  if (flags & RMT_WANT_J) {
    for (int l = 0; l < cnt; ++l) for (int r = 0; r < 6; ++r) for (int k = 0; k < RMT_N; ++k)
      S->Jout[(l*6 + r)*RMT_N + k] = S->J[(k*6 + r)*B + l];
    rmt_put(A->J + i0 * 6 * RMT_N, S->Jout, 6LL * RMT_N * cnt, A->stream);
  }
  if (flags & RMT_WANT_MANIP) rmt_qr_measures(B, B, S->J, S->m, S->m + 3*B);
  if (flags & RMT_WANT_SIGMA) rmt_sigma(B, B, S->J, S->a, S->m + B, S->m + 2*B);
  for (int col = 0; col < 4; ++col) {
    double* out = A->mo[col];
    if (!out) continue;
    out += i0 * A->mstride;
    for (int l = 0; l < cnt; ++l) out[l * A->mstride] = S->m[col*B + l];
  }
}

/* Blocks [b0, b1) of the batch ctx (an rmt_args), on one thread. */
static void rmt_blocks(void* ctx, long long b0, long long b1) {
  const rmt_args* A = (const rmt_args*)ctx;
  rmt_scratch S;
  for (long long b = b0; b < b1; ++b) {
    long long i0 = b * RMT_B;
    rmt_block(A, i0, (int)(A->N - i0 < RMT_B ? A->N - i0 : RMT_B), &S);
  }
#if defined(__SSE2__)
  _mm_sfence();  /* the non-temporal stores are visible before the join */
#endif
}

/* Evaluate a batch.  q: N x n row-major; p: n_p values per row, advanced by pstride (0: shared);
   T: N x 4 x 4, J: N x 6 x n (row-major; NULL when not wanted); m0..m3: manipulability, sigma_min,
   condition, det, element i at [i*mstride] (any NULL).  Returns the number of threads that ran (>= 1). */
int rmt_eval(const double* q, const double* p, long long N, long long pstride, double* T, double* J,
             double* m0, double* m1, double* m2, double* m3, long long mstride, int flags, int nthreads) {
  /* outputs beyond RMT_STREAM_BYTES go around the caches */
  rmt_args A = { q, p, N, pstride, T, J, { m0, m1, m2, m3 }, mstride, flags,
                 N * (16 + 6 * RMT_N) * 8 > RMT_STREAM_BYTES };
  if (!T) A.flags &= ~RMT_WANT_T;
  if (!J) A.flags &= ~RMT_WANT_J;
  if (!m0 && !m3) A.flags &= ~RMT_WANT_MANIP;
  if (!m1 && !m2) A.flags &= ~RMT_WANT_SIGMA;
  if (!(A.flags & RMT_WANT_MANIP)) A.mo[0] = A.mo[3] = NULL;
  if (!(A.flags & RMT_WANT_SIGMA)) A.mo[1] = A.mo[2] = NULL;
  long long nb = (N + RMT_B - 1) / RMT_B;
  long long chunks = (nb + RMT_CHUNK - 1) / RMT_CHUNK;
  /* a thread costs tens of us to start: each must have RMT_MIN_PER_THREAD configurations of work */
  long long most = N / RMT_MIN_PER_THREAD;
  if (most > chunks / 2) most = chunks / 2;  /* and >= 2 chunks, so the dynamic split can balance */
  if (nthreads > most) nthreads = (int)(most > 1 ? most : 1);
  return rmt_parallel_for(nb, RMT_CHUNK, nthreads, rmt_blocks, &A);
}

/* One configuration, lanes of width 1: T (4x4 row-major), J (6xn row-major), m (4 measures). */
static void rmt_one(const double* q, const double* p, double* T, double* J, double* m, int flags) {
  double c[RMT_N], s[RMT_N], Tc[16], Jc[6 * RMT_N], a[RMT_R * RMT_C];
  rmt_sincos(1, 1, q, c, s);
  rmt_graph(1, 1, c, s, q, p, Tc, Jc);
  if (flags & RMT_WANT_T) for (int r = 0; r < 4; ++r) for (int k = 0; k < 4; ++k) T[r*4 + k] = Tc[k*4 + r];
  if (flags & RMT_WANT_J) for (int r = 0; r < 6; ++r) for (int k = 0; k < RMT_N; ++k) J[r*RMT_N + k] = Jc[k*6 + r];
  if (flags & RMT_WANT_MANIP) rmt_qr_measures(1, 1, Jc, m, m + 3);
  if (flags & RMT_WANT_SIGMA) rmt_sigma(1, 1, Jc, a, m + 1, m + 2);
}

/* 1 when joint value v of joint i is one the evaluators accept: finite, and within
   +-RMT_PRISMATIC_MAX for a prismatic joint (kin.chain.MAX_PRISMATIC; the validating Python path
   says why not). */
RMT_INLINE int rmt_q_ok(int i, double v) {
  return RMT_REVOLUTE[i] ? isfinite(v) : fabs(v) <= RMT_PRISMATIC_MAX;
}

/* Single configuration through library-owned buffers (no pointer marshalling from Python):
   rmt_gq, rmt_gp (parameters, written by the caller with each call) in; rmt_gT, rmt_gJ, rmt_gm out.
   Returns 0, or -(1 + i) when joint i is not finite or, prismatic, beyond +-RMT_PRISMATIC_MAX. */
double rmt_gq[RMT_N], rmt_gp[RMT_NP1], rmt_gT[16], rmt_gJ[6 * RMT_N], rmt_gm[4];
int rmt_eval_g(int flags) {
  for (int i = 0; i < RMT_N; ++i) if (!rmt_q_ok(i, rmt_gq[i])) return -1 - i;
  rmt_one(rmt_gq, rmt_gp, rmt_gT, rmt_gJ, rmt_gm, flags);
  return 0;
}

#ifdef RMT_PYEXT
#include "pyext.h"
#endif
