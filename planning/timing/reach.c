/* TOPP-RA's two reachability passes over the stages of planning/timing/reachability.py, loaded by
   planning/timing/native.py (built by kin.native.build; no generated header).

   Stage i holds half-planes A x + C y <= R in (x, y) = (b_i, b_{i+1}), rows off[i] ... off[i+1].
   rmt_reach writes hi (K+1,), the upper ends of the controllable sets [0, hi_i] (backward pass, one
   two-variable LP per stage, solved exactly by Seidel's incremental algorithm inside the box
   0 <= x <= xcap_i, 0 <= y <= hi_{i+1}), then b (K+1,), the greedy forward pass (b_0 = 0, b_{i+1} the
   largest y feasible with x = b_i and y <= hi_{i+1}).  It returns the number of stages where the
   forward pass found no feasible y beyond rounding (0 when all is well). */
#include <math.h>

/* max x subject to a[k] x + c[k] y <= r[k], k < m (the first four: the box) -- Seidel's incremental
   2-D LP in the fixed order given (m is tiny: O(m^2) at worst).  The problem is feasible ((0, 0) is:
   every row has R >= 0, torque rows included -- see reachability.py) and bounded (the box). */
static double lp_max_x(int m, const double *a, const double *c, const double *r)
{
    double vx = r[0], vy = 0.0;                               /* optimum of the box: x = xcap, y = 0 */
    for (int k = 4; k < m; ++k) {
        double ak = a[k], ck = c[k], rk = r[k];
        double lhs = ak * vx + ck * vy;
        if (lhs - rk <= 1e-12 * (fabs(ak * vx) + fabs(ck * vy) + fabs(rk))) continue;
        /* the optimum moves onto the line ak x + ck y = rk: a 1-D LP over constraints 0 .. k-1 */
        double tlo = -HUGE_VAL, thi = HUGE_VAL;
        int by_x = fabs(ck) >= fabs(ak);
        for (int j = 0; j < k; ++j) {
            double coef, rhs, size;
            if (by_x) {        /* t = x, y = (rk - ak t)/ck */
                coef = a[j] - c[j] * ak / ck;
                rhs = r[j] - c[j] * rk / ck;
                size = fabs(a[j]) + fabs(c[j] * ak / ck);
            } else {           /* t = y, x = (rk - ck t)/ak */
                coef = c[j] - a[j] * ck / ak;
                rhs = r[j] - a[j] * rk / ak;
                size = fabs(c[j]) + fabs(a[j] * ck / ak);
            }
            if (fabs(coef) <= 1e-13 * size) continue;        /* parallel: feasible here (or rounding) */
            double t = rhs / coef;
            if (coef > 0) { if (t < thi) thi = t; }
            else          { if (t > tlo) tlo = t; }
        }
        double t;
        if (by_x) {
            t = thi;                                          /* maximise x = t */
            if (t < tlo) t = 0.5 * (t + tlo);                 /* rounding only */
            vx = t; vy = (rk - ak * t) / ck;
        } else {
            double dir = -ck / ak;                            /* dx/dt */
            if (dir > 0) t = thi; else if (dir < 0) t = tlo; else t = 0.5 * (tlo + thi);
            if (tlo > thi) t = 0.5 * (tlo + thi);
            vy = t; vx = (rk - ck * t) / ak;
        }
    }
    return vx;
}

int rmt_reach(long long K, const long long *off, const double *A, const double *C, const double *R,
              const double *xcap, double *hi, double *b, double *wa, double *wc, double *wr)
{
    hi[K] = xcap[K];
    for (long long i = K - 1; i >= 0; --i) {
        int m = 4;
        double ycap = hi[i + 1];
        wa[0] = 1.0;  wc[0] = 0.0;  wr[0] = xcap[i];
        wa[1] = -1.0; wc[1] = 0.0;  wr[1] = 0.0;
        wa[2] = 0.0;  wc[2] = 1.0;  wr[2] = ycap;
        wa[3] = 0.0;  wc[3] = -1.0; wr[3] = 0.0;
        for (long long k = off[i]; k < off[i + 1]; ++k, ++m) { wa[m] = A[k]; wc[m] = C[k]; wr[m] = R[k]; }
        double x = lp_max_x(m, wa, wc, wr);
        if (x < 0.0) x = 0.0;
        if (x > xcap[i]) x = xcap[i];
        hi[i] = x;
    }
    int bad = 0;
    b[0] = 0.0;                                               /* at rest */
    for (long long i = 0; i < K; ++i) {
        double x = b[i], ycap = hi[i + 1], ylo = 0.0, yhi = ycap;
        for (long long k = off[i]; k < off[i + 1]; ++k) {
            double num = R[k] - A[k] * x;
            if (fabs(C[k]) * ycap <= 1e-12 * (fabs(A[k] * x) + fabs(R[k]))) continue;   /* y has no effect */
            double y = num / C[k];
            if (C[k] > 0) { if (y < yhi) yhi = y; }
            else          { if (y > ylo) ylo = y; }
        }
        if (yhi < ylo && ylo - yhi > 1e-9 * (fabs(ylo) + fabs(yhi))) ++bad;
        b[i + 1] = yhi < 0.0 ? 0.0 : yhi;
    }
    return bad;
}
