/* The dexterity measures of the task Jacobian Jt = J[task rows] for nl lanes, vectorised across lanes.

   Jt (m x n) is handled through its tall form A (R x C, R >= C): the columns of Jt when m >= n, else
   the columns of Jt^T.  Element (k, i) of A for lane l is J[RMT_SRC(i, k)*ld + l] of the lane-minor,
   column-major 6 x n Jacobian block.  Every loop over the lanes vectorises; the loops inside it
   have the chain's constant bounds and are written out by the compiler (RMT_UNROLL); "skip this
   rotation" is a select, not a branch, so all lanes run in step.

   * rmt_qr_measures - Householder QR of A: manipulability sqrt(det(Jt Jt^T)) = |prod r_ii| and, for a
     square Jt, det Jt = prod sign * r_ii (each reflection has determinant -1).  Backward stable, hence
     accurate at a singularity, where the Gram determinant would be rounding noise;
   * rmt_jacobi_sweep / rmt_jacobi_finish - one-sided (Hestenes) Jacobi SVD: a sweep rotates every
     column pair of every lane whose columns are not yet orthogonal to working precision
     (|gamma| > 1e-15 |x||y|); rmt_sigma repeats sweeps until no lane rotates; the singular values
     are the final column norms.  High relative accuracy for small sigma (down to ~1e-15 sigma_max).

   Needs RMT_N, RMT_M, RMT_ROWS and RMT_B (rmt_generated.h). */
#ifndef RMT_MEASURES_H
#define RMT_MEASURES_H
#include "rmt_common.h"

#define RMT_R (RMT_M >= RMT_N ? RMT_M : RMT_N)
#define RMT_C (RMT_M >= RMT_N ? RMT_N : RMT_M)
#if RMT_M >= RMT_N
#define RMT_SRC(i, k) ((i) * 6 + RMT_ROWS[k])
#else
#define RMT_SRC(i, k) ((k) * 6 + RMT_ROWS[i])
#endif

RMT_INLINE void rmt_qr_measures(int nl, int ld, const double* restrict J, double* restrict manip,
                                double* restrict det) {
  RMT_SIMD
  for (int l = 0; l < nl; ++l) {
    double a[RMT_C][RMT_R];
    RMT_UNROLL for (int i = 0; i < RMT_C; ++i) RMT_UNROLL for (int k = 0; k < RMT_R; ++k) a[i][k] = J[RMT_SRC(i, k)*ld + l];
    double prod = 1.0, sgn = 1.0;
    RMT_UNROLL for (int c = 0; c < RMT_C; ++c) {
      double tail = c + 1 < RMT_R ? a[c][c + 1] * a[c][c + 1] : 0.0;
      RMT_UNROLL for (int k = c + 2; k < RMT_R; ++k) tail += a[c][k] * a[c][k];
      double acc = a[c][c], norm = sqrt(acc * acc + tail);
      prod *= norm;
      sgn = acc > 0 ? sgn : -sgn;
      if (c == RMT_C - 1) break;
      double v0 = acc > 0 ? acc + norm : acc - norm, vn = v0 * v0 + tail, f2 = vn > 0 ? 2.0 / vn : 0.0;
      RMT_UNROLL for (int j = c + 1; j < RMT_C; ++j) {
        double f = v0 * a[j][c];
        RMT_UNROLL for (int k = c + 1; k < RMT_R; ++k) f += a[c][k] * a[j][k];
        f = f2 * f;
        a[j][c] -= f * v0;
        RMT_UNROLL for (int k = c + 1; k < RMT_R; ++k) a[j][k] -= f * a[c][k];
      }
    }
    manip[l] = prod;
    det[l] = (RMT_R == RMT_C && RMT_M == RMT_N) ? sgn * prod : NAN;
  }
}

/* A of nl lanes into a, element (k, i) at a[(i*R + k)*ld + l]. */
RMT_INLINE void rmt_task_matrix(int nl, int ld, const double* restrict J, double* restrict a) {
  RMT_SIMD
  for (int l = 0; l < nl; ++l)
    RMT_UNROLL for (int i = 0; i < RMT_C; ++i) RMT_UNROLL for (int k = 0; k < RMT_R; ++k)
      a[(i*RMT_R + k)*ld + l] = J[RMT_SRC(i, k)*ld + l];
}

/* One sweep over every column pair of nl <= RMT_B lanes; returns the number of lanes that rotated.
   Each pair is one vector loop over the lanes, on its two columns of a (in L1): with the pair loops
   inside the lane loop instead, the whole matrix is live at once and spills (GCC 12: 4-7 % slower). */
RMT_INLINE int rmt_jacobi_sweep(int nl, int ld, double* restrict a) {
  double d[RMT_C * RMT_B];
  int any[RMT_B];
  for (int i = 0; i < RMT_C; ++i) {
    const double* restrict x = a + i*RMT_R*ld;
    RMT_SIMD
    for (int l = 0; l < nl; ++l) {
      double s = x[l] * x[l];
      RMT_UNROLL for (int k = 1; k < RMT_R; ++k) s += x[k*ld + l] * x[k*ld + l];
      d[i*RMT_B + l] = s;
    }
  }
  for (int l = 0; l < nl; ++l) any[l] = 0;
  for (int i = 0; i < RMT_C - 1; ++i) for (int j = i + 1; j < RMT_C; ++j) {
    double* restrict x = a + i*RMT_R*ld;
    double* restrict y = a + j*RMT_R*ld;
    double* restrict di = d + i*RMT_B;
    double* restrict dj = d + j*RMT_B;
    RMT_SIMD
    for (int l = 0; l < nl; ++l) {
      double gamma = x[l] * y[l];
      RMT_UNROLL for (int k = 1; k < RMT_R; ++k) gamma += x[k*ld + l] * y[k*ld + l];
      int rot = gamma * gamma > 1e-30 * (di[l] * dj[l]);
      any[l] |= rot;
      double da = dj[l] - di[l], b = rot ? 2.0 * gamma : 1.0;
      double t = (da >= 0 ? b : -b) / (fabs(da) + sqrt(da * da + b * b));
      t = rot ? t : 0.0;
      double cs = 1.0 / sqrt(1.0 + t * t), sn = cs * t;
      RMT_UNROLL for (int k = 0; k < RMT_R; ++k) {
        double u = x[k*ld + l], v = y[k*ld + l];
        x[k*ld + l] = cs * u - sn * v;
        y[k*ld + l] = sn * u + cs * v;
      }
      di[l] -= t * gamma;
      dj[l] += t * gamma;
    }
  }
  int rotated = 0;
  for (int l = 0; l < nl; ++l) rotated += any[l];
  return rotated;
}

/* sigma_min and sigma_max/sigma_min from the column norms after the sweeps. */
RMT_INLINE void rmt_jacobi_finish(int nl, int ld, const double* restrict a, double* restrict smin,
                                  double* restrict cond) {
  RMT_SIMD
  for (int l = 0; l < nl; ++l) {
    double lo = INFINITY, hi = 0.0;
    RMT_UNROLL for (int i = 0; i < RMT_C; ++i) {
      double s2 = a[(i*RMT_R)*ld + l] * a[(i*RMT_R)*ld + l];
      RMT_UNROLL for (int k = 1; k < RMT_R; ++k) s2 += a[(i*RMT_R + k)*ld + l] * a[(i*RMT_R + k)*ld + l];
      double sv = sqrt(s2);
      lo = sv < lo ? sv : lo;
      hi = sv > hi ? sv : hi;
    }
    smin[l] = lo;
    cond[l] = lo > 0 ? hi / lo : INFINITY;
  }
}

/* sigma_min and sigma_max/sigma_min of the task Jacobian of nl lanes: sweeps until no lane rotates. */
RMT_INLINE void rmt_sigma(int nl, int ld, const double* restrict J, double* restrict a, double* restrict smin,
                          double* restrict cond) {
  rmt_task_matrix(nl, ld, J, a);
  for (int sweep = 0; sweep < 60; ++sweep) if (!rmt_jacobi_sweep(nl, ld, a)) break;
  rmt_jacobi_finish(nl, ld, a, smin, cond);
}

#endif
