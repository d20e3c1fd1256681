/* Sine and cosine of the revolute joints of nl lanes, vectorised across lanes.

   Cody-Waite reduction to |r| <= pi/4 and fdlibm's minimax kernels, branch-free; |x| > 1e6, where
   the 3-part reduction loses bits, goes to libm.  Needs RMT_N and RMT_REVOLUTE (rmt_generated.h).
   Shared by the FK kernel (kin/compiled/kernel.c) and the dynamics kernel (kin/dynamics/kernel.c). */
#ifndef RMT_SINCOS_H
#define RMT_SINCOS_H
#include "rmt_common.h"

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

#endif
