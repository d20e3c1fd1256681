"""C source of the batch kernel: structure-of-arrays blocks, vectorised across configurations.

A batch is cut into blocks of ``RMT_B`` configurations.  Each block is transposed to structure of
arrays (joint j of lane l at ``[j*B + l]``), then every stage is a plain loop over the lanes that the
compiler vectorises (``#pragma omp simd``, built with ``-fopenmp-simd``, no OpenMP runtime):

1. sin and cos of every revolute joint value (Cody–Waite reduction to |r| ≤ π/4 and fdlibm's
   minimax kernels, branch-free; |x| > 1e6, where the 3-part reduction loses bits, goes to libm);
2. the chain's tool pose T and geometric Jacobian J, from the CasADi graph written lane by lane
   (:mod:`kin.compiled.graph_c`);
3. the dexterity measures of the task Jacobian Jt = J[task_rows]: manipulability √det(Jt·Jtᵀ) and
   det Jt (square Jt only, NaN otherwise) as |Π r_ii| and Π sign·r_ii of a Householder QR of the
   tall one of Jt, Jtᵀ — backward stable, so accurate at a singularity, where the Gram determinant
   would be rounding noise; σ_min and the condition number σ_max/σ_min from a one-sided (Hestenes)
   Jacobi SVD, which keeps high relative accuracy for small σ (σ_min down to ~1e-15·σ_max).
   Both are unrolled for the chain's task size (:mod:`kin.compiled.measures_c`); "skip this
   rotation" is a select, not a branch, so all lanes run in step; the sweeps stop when no lane of
   the block rotates any more;
4. the block is transposed back into the caller's row-major (N, 4, 4), (N, 6, n) and measure arrays.

Threads: ``rmt_eval`` starts ``nthreads − 1`` POSIX threads per call (none below 8192
configurations; at least 4096 configurations per thread),
which take chunks of blocks from an atomic counter and are joined before it returns.  Waiting is a
blocking join — no spinning thread pool is left behind to compete with other processes, and
dynamic chunks keep a thread that the scheduler delays from holding up the call.

The single-call path: compiled with ``RMT_PYEXT`` (Python and numpy headers found), the library is
also a CPython extension module (named after the library file) whose functions take the configuration array and
return new result arrays in one C call; ``rmt_eval_g`` (library-owned buffers, through ctypes) is
the path without those headers.
"""
from __future__ import annotations

from kin.chain import MAX_PRISMATIC
from kin.compiled.measures_c import jacobi_c, qr_measures_c

_TEMPLATE = r"""
/* ---- rmtkit batch kernel (generated) ---- */
#include <math.h>
#include <string.h>
#include <pthread.h>
#include <stdint.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#define RMT_N %%N%%
#define RMT_M %%M%%
#define RMT_NP %%NP%%
#define RMT_NP1 (RMT_NP > 0 ? RMT_NP : 1)
#define RMT_B %%B%%
#define RMT_CHUNK 8              /* blocks taken by a thread at a time */
#define RMT_MAX_THREADS 256
#define RMT_STREAM_BYTES (8LL << 20)
#define RMT_MIN_PER_THREAD 4096
#define RMT_R (RMT_M >= RMT_N ? RMT_M : RMT_N)
#define RMT_C (RMT_M >= RMT_N ? RMT_N : RMT_M)
#define RMT_INLINE static inline __attribute__((always_inline))
#define RMT_SIMD _Pragma("omp simd")
#define RMT_PRISMATIC_MAX %%PRISMATIC_MAX%%
static const int RMT_ROWS[RMT_M] = { %%ROWS%% };
static const int RMT_REVOLUTE[RMT_N] = { %%REVOLUTE%% };

#define RMT_WANT_T 1
#define RMT_WANT_J 2
#define RMT_WANT_MANIP 4
#define RMT_WANT_SIGMA 8

%%GRAPH%%

RMT_INLINE void rmt_sincos(int nl, int ld, const double* restrict x, double* restrict c, double* restrict s) {
  const double magic = 6755399441055744.0, two_over_pi = 6.36619772367581382433e-01;
  const double p1 = 1.57079632673412561417e+00, p2 = 6.07710050630396597660e-11, p3 = 2.02226624871116645580e-21;
  for (int j = 0; j < RMT_N; ++j) {
    if (!RMT_REVOLUTE[j]) continue;
    const double* restrict xj = x + j*ld;
    double* restrict cj = c + j*ld;
    double* restrict sj = s + j*ld;
    int big = 0;
    _Pragma("omp simd reduction(|:big)")
    for (int l = 0; l < nl; ++l) {
      double v = xj[l];
      double k = (v * two_over_pi + magic) - magic;
      double r = ((v - k * p1) - k * p2) - k * p3;
      double z = r * r;
      double sr = r + r * z * (-1.66666666666666324348e-01 + z * (8.33333333332248946124e-03 + z * (-1.98412698298579493134e-04
                  + z * (2.75573137070700676789e-06 + z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)))));
      double cr = 1.0 - 0.5 * z + z * z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03 + z * (2.48015872894767294178e-05
                  + z * (-2.75573143513906633035e-07 + z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
      long long qd = (long long)k & 3;
      double ss = (qd & 1) ? cr : sr, cc = (qd & 1) ? sr : cr;
      sj[l] = (qd & 2) ? -ss : ss;
      cj[l] = ((qd + 1) & 2) ? -cc : cc;
      big |= !(fabs(v) <= 1e6);
    }
    if (big) for (int l = 0; l < nl; ++l) if (!(fabs(xj[l]) <= 1e6)) { sj[l] = sin(xj[l]); cj[l] = cos(xj[l]); }
  }
}

%%MEASURES%%

/* σ_min and σ_max/σ_min of the task Jacobian of nl lanes: sweeps until no lane rotates. */
RMT_INLINE void rmt_sigma(int nl, int ld, const double* restrict J, double* restrict a, double* restrict smin,
                          double* restrict cond) {
  rmt_task_matrix(nl, ld, J, a);
  for (int sweep = 0; sweep < 60; ++sweep) if (!rmt_jacobi_sweep(nl, ld, a)) break;
  rmt_jacobi_finish(nl, ld, a, smin, cond);
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

/* Evaluate rows [i0, i0 + cnt) of the batch (cnt <= RMT_B). */
static void rmt_block(const rmt_args* A, long long i0, int cnt, rmt_scratch* S) {
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

typedef struct { const rmt_args* args; long long nb; long long* next; } rmt_job;

static void* rmt_worker(void* arg) {
  const rmt_job* job = (const rmt_job*)arg;
  rmt_scratch S;
  for (;;) {
    long long b0 = __atomic_fetch_add(job->next, RMT_CHUNK, __ATOMIC_RELAXED);
    if (b0 >= job->nb) break;
    long long b1 = b0 + RMT_CHUNK < job->nb ? b0 + RMT_CHUNK : job->nb;
    for (long long b = b0; b < b1; ++b) {
      long long i0 = b * RMT_B;
      rmt_block(job->args, i0, (int)(job->args->N - i0 < RMT_B ? job->args->N - i0 : RMT_B), &S);
    }
  }
#if defined(__SSE2__)
  _mm_sfence();  /* the non-temporal stores are visible before the join */
#endif
  return NULL;
}

/* Evaluate a batch.  q: N×n row-major; p: n_p values per row, advanced by pstride (0: shared);
   T: N×4×4, J: N×6×n (row-major; NULL when not wanted); m0..m3: manipulability, σ_min, condition,
   det, element i at [i*mstride] (any NULL).  Returns the number of threads that ran (>= 1). */
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
  long long nb = (N + RMT_B - 1) / RMT_B, next = 0;
  long long chunks = (nb + RMT_CHUNK - 1) / RMT_CHUNK;
  if (nthreads < 1) nthreads = 1;
  if (nthreads > RMT_MAX_THREADS) nthreads = RMT_MAX_THREADS;
  /* a thread costs tens of µs to start: each must have RMT_MIN_PER_THREAD configurations of work */
  long long most = N / RMT_MIN_PER_THREAD;
  if (most > chunks / 2) most = chunks / 2;  /* and >= 2 chunks, so the dynamic split can balance */
  if (nthreads > most) nthreads = (int)(most > 1 ? most : 1);
  rmt_job job = { &A, nb, &next };
  pthread_t tid[RMT_MAX_THREADS];
  int started = 0;
  for (int t = 1; t < nthreads; ++t) {
    if (pthread_create(&tid[started], NULL, rmt_worker, &job) != 0) break;
    ++started;
  }
  rmt_worker(&job);
  for (int t = 0; t < started; ++t) pthread_join(tid[t], NULL);
  return started + 1;
}

/* One configuration, lanes of width 1: T (4×4 row-major), J (6×n row-major), m (4 measures). */
static void rmt_one(const double* q, const double* p, double* T, double* J, double* m, int flags) {
  double c[RMT_N], s[RMT_N], Tc[16], Jc[6 * RMT_N], a[RMT_R * RMT_C];
  rmt_sincos(1, 1, q, c, s);
  rmt_graph(1, 1, c, s, q, p, Tc, Jc);
  if (flags & RMT_WANT_T) for (int r = 0; r < 4; ++r) for (int k = 0; k < 4; ++k) T[r*4 + k] = Tc[k*4 + r];
  if (flags & RMT_WANT_J) for (int r = 0; r < 6; ++r) for (int k = 0; k < RMT_N; ++k) J[r*RMT_N + k] = Jc[k*6 + r];
  if (flags & RMT_WANT_MANIP) rmt_qr_measures(1, 1, Jc, m, m + 3);
  if (flags & RMT_WANT_SIGMA) rmt_sigma(1, 1, Jc, a, m + 1, m + 2);
}

/* 1 when joint value v of joint i is one the evaluators accept: finite, and within ±RMT_PRISMATIC_MAX for a
   prismatic joint (kin.chain.MAX_PRISMATIC; the validating Python path says why not). */
RMT_INLINE int rmt_q_ok(int i, double v) {
  return RMT_REVOLUTE[i] ? isfinite(v) : fabs(v) <= RMT_PRISMATIC_MAX;
}

/* Single configuration through library-owned buffers (no pointer marshalling from Python):
   rmt_gq, rmt_gp (parameters, written by the caller with each call) in; rmt_gT, rmt_gJ, rmt_gm out.  Returns 0, or −(1 + i)
   when joint i is not finite or, prismatic, beyond ±RMT_PRISMATIC_MAX. */
double rmt_gq[RMT_N], rmt_gp[RMT_NP1], rmt_gT[16], rmt_gJ[6 * RMT_N], rmt_gm[4];
int rmt_eval_g(int flags) {
  for (int i = 0; i < RMT_N; ++i) if (!rmt_q_ok(i, rmt_gq[i])) return -1 - i;
  rmt_one(rmt_gq, rmt_gp, rmt_gT, rmt_gJ, rmt_gm, flags);
  return 0;
}

#ifdef RMT_PYEXT
/* The single-call path as a CPython extension module: one C call from Python per evaluation, the
   result arrays created here.  Each function takes q, a float64 C-contiguous ndarray of shape (n,)
   whose values rmt_q_ok accepts, and p, the design parameters (float64 (n_p,); ignored when n_p = 0 — the
   library is shared by every chain of the same structure, so the nominal values are the caller's),
   and returns None for anything else (the Python caller then validates and reports).  Runs with
   the GIL held, on stack buffers. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

static const double* rmt_py_vec(PyObject* o, int n, int joints) {
  if (!PyArray_CheckExact(o)) return NULL;
  PyArrayObject* a = (PyArrayObject*)o;
  if (PyArray_TYPE(a) != NPY_DOUBLE || PyArray_NDIM(a) != 1 || PyArray_DIM(a, 0) != n
      || !PyArray_ISCARRAY_RO(a) || PyArray_ISBYTESWAPPED(a)) return NULL;
  const double* v = (const double*)PyArray_DATA(a);
  if (joints) for (int i = 0; i < n; ++i) if (!rmt_q_ok(i, v[i])) return NULL;
  return v;
}

/* (q, p) of a call: q float64 (n,) accepted by rmt_q_ok, p float64 (n_p,) (the caller's nominal parameters). */
static int rmt_py_qp(PyObject* const* args, Py_ssize_t nargs, Py_ssize_t want_args, const double** q,
                     const double** p) {
  if (nargs != want_args) { PyErr_SetString(PyExc_TypeError, "wrong number of arguments"); return -1; }
  *q = rmt_py_vec(args[0], RMT_N, 1);
  *p = RMT_NP > 0 ? rmt_py_vec(args[1], RMT_NP, 0) : rmt_gp;
  return (*q && *p) ? 1 : 0;
}

static PyObject* rmt_py_new(int rows, int cols) {
  npy_intp dims[2] = { rows, cols };
  return PyArray_SimpleNew(2, dims, NPY_DOUBLE);
}

#define RMT_PY_ARGS(k) const double *q, *p; int ok = rmt_py_qp(args, nargs, k, &q, &p); \
  if (ok < 0) return NULL; if (!ok) Py_RETURN_NONE;

static PyObject* rmt_py_fk(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  RMT_PY_ARGS(2)
  PyObject* T = rmt_py_new(4, 4);
  if (!T) return NULL;
  rmt_one(q, p, (double*)PyArray_DATA((PyArrayObject*)T), NULL, NULL, RMT_WANT_T);
  return T;
}

static PyObject* rmt_py_jacobian(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  RMT_PY_ARGS(2)
  PyObject* J = rmt_py_new(6, RMT_N);
  if (!J) return NULL;
  rmt_one(q, p, NULL, (double*)PyArray_DATA((PyArrayObject*)J), NULL, RMT_WANT_J);
  return J;
}

static PyObject* rmt_py_fk_jacobian(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  RMT_PY_ARGS(2)
  PyObject* T = rmt_py_new(4, 4);
  PyObject* J = T ? rmt_py_new(6, RMT_N) : NULL;
  if (!J) { Py_XDECREF(T); return NULL; }
  rmt_one(q, p, (double*)PyArray_DATA((PyArrayObject*)T), (double*)PyArray_DATA((PyArrayObject*)J), NULL,
          RMT_WANT_T | RMT_WANT_J);
  PyObject* res = PyTuple_Pack(2, T, J);
  Py_DECREF(T); Py_DECREF(J);
  return res;
}

/* measures(q, p, flags) -> (manipulability, sigma_min, condition, det) floats (NaN where not wanted) */
static PyObject* rmt_py_measures(PyObject* self, PyObject* const* args, Py_ssize_t nargs) {
  RMT_PY_ARGS(3)
  long flags = PyLong_AsLong(args[2]);
  if (flags == -1 && PyErr_Occurred()) return NULL;
  double m[4] = { NAN, NAN, NAN, NAN };
  rmt_one(q, p, NULL, NULL, m, (int)flags & (RMT_WANT_MANIP | RMT_WANT_SIGMA));
  return Py_BuildValue("(dddd)", m[0], m[1], m[2], m[3]);
}

static PyMethodDef rmt_py_methods[] = {
#define RMT_PY_FN(f) (PyCFunction)(void(*)(void))(f), METH_FASTCALL
  { "fk", RMT_PY_FN(rmt_py_fk), "fk(q, p): T (4, 4) of one configuration, or None" },
  { "jacobian", RMT_PY_FN(rmt_py_jacobian), "jacobian(q, p): J (6, n) of one configuration, or None" },
  { "fk_jacobian", RMT_PY_FN(rmt_py_fk_jacobian), "fk_jacobian(q, p): (T, J) of one configuration, or None" },
  { "measures", RMT_PY_FN(rmt_py_measures), "measures(q, p, flags): 4 measures of one configuration, or None" },
  { NULL, NULL, 0, NULL }
};

/* The module is named after the library file (RMT_PYEXT_NAME, set by the build): CPython keeps
   single-phase extension modules by name, so two libraries must never share one. */
#define RMT_CAT2(a, b) a##b
#define RMT_CAT(a, b) RMT_CAT2(a, b)
#define RMT_STR2(a) #a
#define RMT_STR(a) RMT_STR2(a)
static struct PyModuleDef rmt_py_module = { PyModuleDef_HEAD_INIT, RMT_STR(RMT_PYEXT_NAME), NULL, -1, rmt_py_methods };

PyMODINIT_FUNC RMT_CAT(PyInit_, RMT_PYEXT_NAME)(void) {
  import_array();
  return PyModule_Create(&rmt_py_module);
}
#endif
"""


def kernel_source(n: int, m: int, n_p: int, rows: tuple[int, ...], revolute: tuple[bool, ...], graph: str,
                  block: int = 16) -> str:
    """The whole kernel's C source; ``graph`` is the ``rmt_graph`` function of :mod:`kin.compiled.graph_c`."""
    measures = qr_measures_c(rows, n) + "\n" + jacobi_c(rows, n)
    subs = {"MEASURES": measures, "N": str(n), "M": str(m), "NP": str(n_p), "B": str(block), "ROWS": ", ".join(map(str, rows)),
            "REVOLUTE": ", ".join("1" if r else "0" for r in revolute), "GRAPH": graph,
            "PRISMATIC_MAX": repr(float(MAX_PRISMATIC))}
    src = _TEMPLATE
    for k, v in subs.items():
        src = src.replace(f"%%{k}%%", v)
    return src
