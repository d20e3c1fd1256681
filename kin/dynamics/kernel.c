/* rmtkit inverse-dynamics kernel: the Newton-Euler functions of one chain (kin/dynamics/rnea.py),
   vectorised across configurations.  Specialised by rmt_generated.h (kin/dynamics/evaluator.py):
   RMT_N joints, RMT_NP design parameters, RMT_B lanes per block, RMT_REVOLUTE, RMT_PRISMATIC_MAX
   and one instruction table (kin/native/graph.py) per function (InverseDynamics.cs_functions),
   inputs named c, s (cos q, sin q of the revolute joints), q (read for prismatic joints), qd, qdd,
   p and the output o (dense, column-major):

     RMT_TAU   tau(q, qd, qdd, p)            n x 1   (inverse dynamics, friction included)
     RMT_MASS  M(q, p)                       n x n
     RMT_GRAV  g(q, p)                       n x 1
     RMT_CORI  c(q, qd, p)                   n x 1
     RMT_PATH  [A B C](q, d1 = qd, d2 = qdd, p)  n x 3  (path torque coefficients)

   A batch is cut into blocks of RMT_B configurations, transposed to structure of arrays (joint j of
   lane l at [j*B + l]), the sines and cosines computed vectorised (rmt_sincos.h: libm's sin and cos
   would keep the compiler from vectorising), then every statement of the table is a vector
   operation across the lanes (rmt_graph.h inside `omp simd`), and the block's output is transposed back into the caller's
   row-major (N, rows, cols).  Threads: rmt_parallel_for (rmt_parallel.h), none below
   2 * RMT_MIN_PER_THREAD configurations.

   The single-call path: compiled with RMT_PYEXT the library is also a CPython extension module
   (pyext.h), which evaluates one configuration straight from the caller's arrays. */
#include "rmt_generated.h"
#include "rmt_common.h"
#include "rmt_graph.h"
#include "rmt_parallel.h"
#include "rmt_sincos.h"

#define RMT_NP1 (RMT_NP > 0 ? RMT_NP : 1)
#define RMT_CHUNK 8               /* blocks taken by a thread at a time */
#define RMT_MIN_PER_THREAD 1024   /* configurations a started thread must have (a thread costs ~tens of us) */
#define RMT_OUT_MAX (RMT_N * RMT_N > 3 * RMT_N ? RMT_N * RMT_N : 3 * RMT_N)

/* the functions, numbered as kin/dynamics/evaluator.py's FUNCTIONS */
enum { RMT_F_TAU, RMT_F_MASS, RMT_F_GRAV, RMT_F_CORI, RMT_F_PATH, RMT_NF };
static const int rmt_cols[RMT_NF] = { 1, RMT_N, 1, 1, 3 };

typedef void (*rmt_dyn_fn)(const double* restrict c, const double* restrict s, const double* restrict q, const double* restrict qd, const double* restrict qdd,
                           const double* restrict p, double* restrict o);

/* For table G: NAME##_block, B lanes of lane stride B, and NAME##_one, one configuration (a lane of
   width 1: plain straight-line code).  Each is a function of its own (noinline): the compiler
   allocates the registers of one table at a time. */
#define RMT_DYN_FUNCTION(NAME, G) \
  RMT_INLINE void NAME##_lanes(int nl, int ld, const double* restrict c, const double* restrict s, \
      const double* restrict q, const double* restrict qd, const double* restrict qdd, const double* restrict p, \
      double* restrict o) { \
    (void)c; (void)s; (void)q; (void)qd; (void)qdd; (void)p; \
    RMT_SIMD \
    for (int l = 0; l < nl; ++l) { RMT_GRAPH_EVAL(G) } \
  } \
  static __attribute__((noinline)) void NAME##_block(const double* restrict c, const double* restrict s, \
      const double* restrict q, const double* restrict qd, const double* restrict qdd, const double* restrict p, \
      double* restrict o) { \
    NAME##_lanes(RMT_B, RMT_B, c, s, q, qd, qdd, p, o); \
  } \
  static __attribute__((noinline)) void NAME##_one(const double* restrict c, const double* restrict s, \
      const double* restrict q, const double* restrict qd, const double* restrict qdd, const double* restrict p, \
      double* restrict o) { \
    NAME##_lanes(1, 1, c, s, q, qd, qdd, p, o); \
  }

RMT_DYN_FUNCTION(rmt_tau, RMT_TAU)
RMT_DYN_FUNCTION(rmt_mass, RMT_MASS)
RMT_DYN_FUNCTION(rmt_grav, RMT_GRAV)
RMT_DYN_FUNCTION(rmt_cori, RMT_CORI)
RMT_DYN_FUNCTION(rmt_path, RMT_PATH)

static const rmt_dyn_fn rmt_blocks_fn[RMT_NF] = { rmt_tau_block, rmt_mass_block, rmt_grav_block, rmt_cori_block,
                                                  rmt_path_block };
static const rmt_dyn_fn rmt_one_fn[RMT_NF] = { rmt_tau_one, rmt_mass_one, rmt_grav_one, rmt_cori_one, rmt_path_one };

typedef struct {
  int fun;
  const double *q, *qd, *qdd, *p;
  long long N, pstride;
  double* out;
} rmt_dyn_args;

/* Rows [i0, i0 + cnt) of x (row length k, row stride stride) into the lanes of s (lanes beyond cnt
   repeat row i0, so that every lane computes on valid numbers). */
RMT_INLINE void rmt_lanes_in(const double* x, long long i0, int cnt, int k, long long stride, double* s) {
  for (int l = 0; l < RMT_B; ++l) {
    const double* xl = x + (i0 + (l < cnt ? l : 0)) * stride;
    for (int j = 0; j < k; ++j) s[j * RMT_B + l] = xl[j];
  }
}

/* Blocks [b0, b1) of the batch ctx (an rmt_dyn_args), on one thread. */
static void rmt_dyn_blocks(void* ctx, long long b0, long long b1) {
  const rmt_dyn_args* A = (const rmt_dyn_args*)ctx;
  double c[RMT_N * RMT_B], s[RMT_N * RMT_B], q[RMT_N * RMT_B], qd[RMT_N * RMT_B], qdd[RMT_N * RMT_B], p[RMT_NP1 * RMT_B];
  double o[RMT_OUT_MAX * RMT_B];
  const int R = RMT_N, C = rmt_cols[A->fun];
  const rmt_dyn_fn f = rmt_blocks_fn[A->fun];
  for (long long b = b0; b < b1; ++b) {
    long long i0 = b * RMT_B;
    int cnt = (int)(A->N - i0 < RMT_B ? A->N - i0 : RMT_B);
    rmt_lanes_in(A->q, i0, cnt, RMT_N, RMT_N, q);
    if (A->qd) rmt_lanes_in(A->qd, i0, cnt, RMT_N, RMT_N, qd);
    if (A->qdd) rmt_lanes_in(A->qdd, i0, cnt, RMT_N, RMT_N, qdd);
    if (RMT_NP > 0) rmt_lanes_in(A->p, i0, cnt, RMT_NP, A->pstride, p);
    rmt_sincos(RMT_B, RMT_B, q, c, s);
    f(c, s, q, qd, qdd, p, o);
    double* out = A->out + i0 * R * C;
    for (int l = 0; l < cnt; ++l)
      for (int r = 0; r < R; ++r)
        for (int c = 0; c < C; ++c) out[(l * R + r) * C + c] = o[(c * R + r) * RMT_B + l];
  }
}

/* Evaluate function fun (RMT_F_*) on a batch.  q, qd, qdd: N x n row-major (qd, qdd NULL when fun
   does not take them); p: n_p values per row, advanced by pstride (0: shared); out: N x n x cols
   row-major.  Returns the number of threads that ran (>= 1), or -1 for an unknown fun. */
int rmt_dyn_eval(int fun, const double* q, const double* qd, const double* qdd, const double* p, long long N,
                 long long pstride, double* out, int nthreads) {
  if (fun < 0 || fun >= RMT_NF) return -1;
  rmt_dyn_args A = { fun, q, qd, qdd, p, N, pstride, out };
  long long nb = (N + RMT_B - 1) / RMT_B;
  long long chunks = (nb + RMT_CHUNK - 1) / RMT_CHUNK;
  long long most = N / RMT_MIN_PER_THREAD;
  if (most > chunks / 2) most = chunks / 2;  /* and >= 2 chunks each, so the dynamic split can balance */
  if (nthreads > most) nthreads = (int)(most > 1 ? most : 1);
  return rmt_parallel_for(nb, RMT_CHUNK, nthreads, rmt_dyn_blocks, &A);
}

/* One configuration of function fun into out (n x cols row-major); inputs as in rmt_dyn_eval, one row. */
static void rmt_dyn_one(int fun, const double* q, const double* qd, const double* qdd, const double* p,
                        double* out) {
  const int C = rmt_cols[fun];
  double c[RMT_N], s[RMT_N];
  rmt_sincos(1, 1, q, c, s);
  if (C == 1) {  /* a column: column-major is row-major */
    rmt_one_fn[fun](c, s, q, qd, qdd, p, out);
    return;
  }
  double o[RMT_OUT_MAX];
  rmt_one_fn[fun](c, s, q, qd, qdd, p, o);
  for (int r = 0; r < RMT_N; ++r) for (int c = 0; c < C; ++c) out[r * C + c] = o[c * RMT_N + r];
}

/* 1 when joint value v of joint i is one the evaluators accept: finite, and within
   +-RMT_PRISMATIC_MAX for a prismatic joint (kin.chain.MAX_PRISMATIC). */
RMT_INLINE int rmt_q_ok(int i, double v) {
  return RMT_REVOLUTE[i] ? isfinite(v) : fabs(v) <= RMT_PRISMATIC_MAX;
}

#ifdef RMT_PYEXT
#include "pyext.h"
#endif
