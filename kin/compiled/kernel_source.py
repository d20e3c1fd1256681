"""C source of the batch kernel wrapped around CasADi's generated FK/Jacobian function.

The kernel evaluates, for each configuration of a batch, the tool pose T (row-major 4×4), the
geometric Jacobian J (row-major 6×n) and up to four dexterity measures of the task Jacobian
Jt = J[task_rows]: manipulability √det(Jt·Jtᵀ), σ_min, condition number σ_max/σ_min, det Jt
(square Jt only, NaN otherwise).  Singular values come from a one-sided (Hestenes) Jacobi SVD,
which keeps high relative accuracy for small σ (σ_min down to ~1e-15·σ_max, where the Gram-matrix
eigenvalue route would stop at ~1e-8).
"""
from __future__ import annotations

KERNEL_TEMPLATE = r"""
/* ---- rmtkit batch kernel (appended to CasADi's generated code) ---- */
#include <math.h>
#include <string.h>
#define RMT_N {n}
#define RMT_M {m}
#define RMT_NP {np_}
#define RMT_SZ_W {sz_w}
#define RMT_SZ_IW {sz_iw}
static const int RMT_ROWS[RMT_M] = {{ {rows} }};

#define RMT_WANT_T 1
#define RMT_WANT_J 2
#define RMT_WANT_MANIP 4
#define RMT_WANT_SIGMA 8

/* determinant of a k×k row-major matrix (destroyed), Gaussian elimination with partial pivoting */
static double rmt_det(double* a, int k) {{
  double det = 1.0;
  for (int c = 0; c < k; ++c) {{
    int piv = c; double best = fabs(a[c*k+c]);
    for (int r = c+1; r < k; ++r) {{ double v = fabs(a[r*k+c]); if (v > best) {{ best = v; piv = r; }} }}
    if (best == 0.0) return 0.0;
    if (piv != c) {{ for (int j = 0; j < k; ++j) {{ double t = a[c*k+j]; a[c*k+j] = a[piv*k+j]; a[piv*k+j] = t; }} det = -det; }}
    double d = a[c*k+c]; det *= d;
    for (int r = c+1; r < k; ++r) {{
      double f = a[r*k+c] / d;
      if (f != 0.0) for (int j = c+1; j < k; ++j) a[r*k+j] -= f * a[c*k+j];
    }}
  }}
  return det;
}}

/* singular values of an r×c column-major matrix (r >= c), destroyed; sorted descending into s.
   One-sided Jacobi: rotate column pairs until all are orthogonal to working precision; the
   squared column norms are carried along (d_i − t·γ, d_j + t·γ) and recomputed every sweep. */
static void rmt_svals(double* a, int r, int c, double* s) {{
  double d[8];
  for (int sweep = 0; sweep < 40; ++sweep) {{
    for (int i = 0; i < c; ++i) {{ double acc = 0; for (int k = 0; k < r; ++k) acc += a[i*r+k]*a[i*r+k]; d[i] = acc; }}
    int rotated = 0;
    for (int i = 0; i < c - 1; ++i) for (int j = i + 1; j < c; ++j) {{
      double *x = a + i*r, *y = a + j*r, gamma = 0;
      for (int k = 0; k < r; ++k) gamma += x[k]*y[k];
      if (!(fabs(gamma) > 1e-15 * sqrt(d[i] * d[j]))) continue;
      rotated = 1;
      double zeta = (d[j] - d[i]) / (2.0 * gamma);
      double t = (zeta >= 0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta*zeta));
      double cs = 1.0 / sqrt(1.0 + t*t), sn = cs * t;
      for (int k = 0; k < r; ++k) {{ double u = x[k], v = y[k]; x[k] = cs*u - sn*v; y[k] = sn*u + cs*v; }}
      d[i] -= t * gamma; d[j] += t * gamma;
    }}
    if (!rotated) break;
  }}
  for (int i = 0; i < c; ++i) {{ double acc = 0; for (int k = 0; k < r; ++k) acc += a[i*r+k]*a[i*r+k]; s[i] = sqrt(acc); }}
  for (int i = 1; i < c; ++i) {{ double v = s[i]; int j = i - 1; while (j >= 0 && s[j] < v) {{ s[j+1] = s[j]; --j; }} s[j+1] = v; }}
}}

/* measures of the task Jacobian; J column-major 6×n; out: manip, sigma_min, cond, det */
static void rmt_measures(const double* J, int flags, double* out) {{
  double jt[RMT_M * RMT_N];  /* row-major m×n */
  for (int r = 0; r < RMT_M; ++r) for (int c = 0; c < RMT_N; ++c) jt[r*RMT_N + c] = J[c*6 + RMT_ROWS[r]];
  if (flags & RMT_WANT_MANIP) {{
    if (RMT_M == RMT_N) {{
      double a[RMT_M * RMT_N]; memcpy(a, jt, sizeof a);
      double d = rmt_det(a, RMT_N);
      out[0] = fabs(d); out[3] = d;
    }} else {{
      /* √det(Jt·Jtᵀ) = |Π r_ii| of the QR factor of the tall matrix (Jt or Jtᵀ): Householder QR is
         backward stable, so the product stays accurate at a singularity, where the Gram
         determinant would be rounding noise (≈1e-16) and its square root ≈1e-8. */
      enum {{ R = RMT_M >= RMT_N ? RMT_M : RMT_N, C = RMT_M >= RMT_N ? RMT_N : RMT_M }};
      double a[R * C];  /* column-major R×C */
      for (int i = 0; i < C; ++i) for (int k = 0; k < R; ++k)
        a[i*R + k] = (RMT_M >= RMT_N) ? jt[k*RMT_N + i] : jt[i*RMT_N + k];
      double prod = 1.0;
      for (int c = 0; c < C; ++c) {{
        double norm = 0;
        for (int k = c; k < R; ++k) norm += a[c*R + k] * a[c*R + k];
        norm = sqrt(norm);
        prod *= norm;                       /* |r_cc| = norm of the remaining column */
        if (norm == 0.0) break;
        double alpha = a[c*R + c] > 0 ? -norm : norm;
        double v0 = a[c*R + c] - alpha, vn = v0 * v0;
        for (int k = c + 1; k < R; ++k) vn += a[c*R + k] * a[c*R + k];
        if (vn == 0.0) continue;
        for (int j = c + 1; j < C; ++j) {{  /* apply H = I − 2vvᵀ/vᵀv to the remaining columns */
          double dot = v0 * a[j*R + c];
          for (int k = c + 1; k < R; ++k) dot += a[c*R + k] * a[j*R + k];
          double f = 2.0 * dot / vn;
          a[j*R + c] -= f * v0;
          for (int k = c + 1; k < R; ++k) a[j*R + k] -= f * a[c*R + k];
        }}
      }}
      out[0] = prod; out[3] = NAN;
    }}
  }}
  if (flags & RMT_WANT_SIGMA) {{
    enum {{ R = RMT_M >= RMT_N ? RMT_M : RMT_N, C = RMT_M >= RMT_N ? RMT_N : RMT_M }};
    double a[R * C], s[C];
    /* column-major R×C: columns of Jt when m >= n, else columns of Jtᵀ (= rows of Jt) */
    for (int i = 0; i < C; ++i) for (int k = 0; k < R; ++k)
      a[i*R + k] = (RMT_M >= RMT_N) ? jt[k*RMT_N + i] : jt[i*RMT_N + k];
    rmt_svals(a, R, C, s);
    out[1] = s[C-1];
    out[2] = s[C-1] > 0 ? s[0] / s[C-1] : INFINITY;
  }}
}}

/* sin and cos of n values: Cody–Waite reduction to |r| <= π/4 and fdlibm's minimax kernels,
   branch-free so that the compiler vectorises the loop (libm's sin/cos are ~80 % of FK's cost);
   |x| > 1e6, where the 3-part reduction loses bits, goes to libm afterwards. */
static void rmt_sincos(const double* restrict x, double* restrict c, double* restrict s, int n) {{
  const double magic = 6755399441055744.0, two_over_pi = 6.36619772367581382433e-01;
  const double p1 = 1.57079632673412561417e+00, p2 = 6.07710050630396597660e-11, p3 = 2.02226624871116645580e-21;
  int big = 0;
  for (int i = 0; i < n; ++i) {{
    double v = x[i];
    double k = (v * two_over_pi + magic) - magic;
    double r = ((v - k * p1) - k * p2) - k * p3;
    double z = r * r;
    double sr = r + r * z * (-1.66666666666666324348e-01 + z * (8.33333333332248946124e-03 + z * (-1.98412698298579493134e-04
                + z * (2.75573137070700676789e-06 + z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)))));
    double cr = 1.0 - 0.5 * z + z * z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03 + z * (2.48015872894767294178e-05
                + z * (-2.75573143513906633035e-07 + z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
    long long qd = (long long)k & 3;
    double ss = (qd & 1) ? cr : sr, cc = (qd & 1) ? sr : cr;
    s[i] = (qd & 2) ? -ss : ss;
    c[i] = ((qd + 1) & 2) ? -cc : cc;
    big |= !(fabs(v) <= 1e6);
  }}
  if (big) for (int i = 0; i < n; ++i) if (!(fabs(x[i]) <= 1e6)) {{ s[i] = sin(x[i]); c[i] = cos(x[i]); }}
}}

static void rmt_one_cs(const double* c, const double* s, const double* q, const double* p,
                       double* T, double* J, double* meas, int flags) {{
  const casadi_real* arg[{sz_arg}];
  casadi_real* res[{sz_res}];
  casadi_int iw[RMT_SZ_IW > 0 ? RMT_SZ_IW : 1];
  casadi_real w[RMT_SZ_W > 0 ? RMT_SZ_W : 1];
  double Tc[16], Jc[6 * RMT_N];
  arg[0] = c; arg[1] = s; arg[2] = q; arg[3] = p; res[0] = Tc; res[1] = Jc;
  fkj_cs(arg, res, iw, w, 0);
  if (flags & RMT_WANT_T) for (int r = 0; r < 4; ++r) for (int k = 0; k < 4; ++k) T[r*4 + k] = Tc[k*4 + r];
  if (flags & RMT_WANT_J) for (int r = 0; r < 6; ++r) for (int k = 0; k < RMT_N; ++k) J[r*RMT_N + k] = Jc[k*6 + r];
  if (flags & (RMT_WANT_MANIP | RMT_WANT_SIGMA)) rmt_measures(Jc, flags, meas);
}}

#define RMT_B 64
static void rmt_block(const double* q, const double* p, long long pstride, int cnt,
                      double* T, double* J, double* meas, int flags) {{
  double c[RMT_B * RMT_N], s[RMT_B * RMT_N], dummy[6 * RMT_N + 16];
  rmt_sincos(q, c, s, cnt * RMT_N);
  for (int i = 0; i < cnt; ++i)
    rmt_one_cs(c + i*RMT_N, s + i*RMT_N, q + i*RMT_N, p + i*pstride, T ? T + i*16 : dummy,
               J ? J + i*6*RMT_N : dummy, meas ? meas + i*4 : dummy, flags);
}}

/* Evaluate a batch.  q: N×n row-major; p: n_p values, advanced by pstride (0: shared) per row;
   T: N×4×4, J: N×6×n, meas: N×4 (any may be NULL when not wanted); nthreads <= 0: all cores. */
int rmt_eval(const double* q, const double* p, long long N, long long pstride,
             double* T, double* J, double* meas, int flags, int nthreads) {{
  if (!T) flags &= ~RMT_WANT_T;
  if (!J) flags &= ~RMT_WANT_J;
  if (!meas) flags &= ~(RMT_WANT_MANIP | RMT_WANT_SIGMA);
  long long nb = (N + RMT_B - 1) / RMT_B;
#ifdef _OPENMP
  if (nthreads <= 0) nthreads = omp_get_max_threads();
  #pragma omp parallel for schedule(static) num_threads(nthreads) if(nb >= 8 && nthreads > 1)
#endif
  for (long long b = 0; b < nb; ++b) {{
    long long i = b * RMT_B;
    int cnt = (int)(N - i < RMT_B ? N - i : RMT_B);
    rmt_block(q + i*RMT_N, p + i*pstride, pstride, cnt, T ? T + i*16 : NULL, J ? J + i*6*RMT_N : NULL,
              meas ? meas + i*4 : NULL, flags);
  }}
  return 0;
}}

/* Single configuration through library-owned buffers (no pointer marshalling from Python). */
double rmt_gq[RMT_N], rmt_gp[RMT_NP > 0 ? RMT_NP : 1], rmt_gT[16], rmt_gJ[6 * RMT_N], rmt_gm[4];
int rmt_eval_g(int flags) {{
  for (int i = 0; i < RMT_N; ++i) if (!isfinite(rmt_gq[i])) return -1 - i;
  rmt_block(rmt_gq, rmt_gp, 0, 1, rmt_gT, rmt_gJ, rmt_gm, flags);
  return 0;
}}
"""
