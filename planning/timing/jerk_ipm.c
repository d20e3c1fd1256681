/* The jerk pass of planning/timing/jerk.py (see its docstring for the problem), loaded by
   planning/timing/native.py (built by kin.native.build; no generated header).

   Variables b_0 .. b_K (b = sdot^2); b_i with free[i] == 0 stay at 0 (the ends and stops).  Every row
   is  g0 b_c + g1 b_{c+1} + g2 b_{c+2} <= r  on a window of three consecutive b (c = col0, c + 2 <= K):
   the stage rows (given, pruned by rmt_prune), b_i >= 0 and b_i <= xcap_i, and the jerk rows of the
   convex-concave procedure, rebuilt at every pass from the reference profile bh:

       +-D_mj . b  <=  jmax_j * dt_k(b),   dt_k(b) = 2 h_k / (sqrt b_k + sqrt b_{k+1})  (convex in b)

   with dt_k replaced by its tangent at bh (below dt_k everywhere, equal at bh), a linear row.  Each pass
   minimises the exact duration T(b) = sum_k dt_k(b) (convex) under these rows by a primal-dual
   interior-point method (Boyd and Vandenberghe, Convex Optimization, 11.7) whose Newton systems are
   pentadiagonal (banded Cholesky, O(K)).  Every iterate is strictly inside its rows, so it meets the
   true jerk rows (the tangent is below dt_k) and the next pass's rows (tangent there is exact): T never
   increases from one pass to the next. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- pruning: the stage rows that touch the stage polygon ------------------------------------------- */

/* clip the convex polygon (px, py, *np) by a x + c y <= r (Sutherland-Hodgman); tx, ty scratch */
static void clip(double *px, double *py, int *np, double a, double c, double r, double *tx, double *ty)
{
    int m = 0, k = *np;
    for (int i = 0; i < k; ++i) {
        int j = (i + 1) % k;
        double fi = a * px[i] + c * py[i] - r, fj = a * px[j] + c * py[j] - r;
        if (fi <= 0) { tx[m] = px[i]; ty[m] = py[i]; ++m; }
        if ((fi < 0 && fj > 0) || (fi > 0 && fj < 0)) {
            double u = fi / (fi - fj);
            tx[m] = px[i] + u * (px[j] - px[i]); ty[m] = py[i] + u * (py[j] - py[i]); ++m;
        }
    }
    memcpy(px, tx, m * sizeof(double)); memcpy(py, ty, m * sizeof(double));
    *np = m;
}

/* keep[k] = 1 for the stage rows (half-planes A x + C y <= R of stage i, rows off[i] .. off[i+1], in
   (x, y) = (b_i, b_{i+1}), inside the box [0, xcap_i] x [0, xcap_{i+1}]) that reach the stage polygon
   to within 1e-9 of their right-hand side; the others cannot bind (the polygon holds (0, 0), so a
   half-plane that misses it contains every other row's intersection).  wx, wy: 2 (rows + 4) each. */
void rmt_prune(long long K, const long long *off, const double *A, const double *C, const double *R,
               const double *xcap, unsigned char *keep, double *wx, double *wy)
{
    for (long long i = 0; i < K; ++i) {
        long long m = off[i + 1] - off[i];
        double *px = wx, *py = wy, *tx = wx + m + 4, *ty = wy + m + 4;
        int np = 4;
        double X = xcap[i], Y = xcap[i + 1];
        px[0] = 0; py[0] = 0; px[1] = X; py[1] = 0; px[2] = X; py[2] = Y; px[3] = 0; py[3] = Y;
        for (long long k = off[i]; k < off[i + 1] && np > 0; ++k) clip(px, py, &np, A[k], C[k], R[k], tx, ty);
        for (long long k = off[i]; k < off[i + 1]; ++k) {
            double top = -HUGE_VAL;
            for (int v = 0; v < np; ++v) { double f = A[k] * px[v] + C[k] * py[v]; if (f > top) top = f; }
            keep[k] = (np == 0 || top >= R[k] * (1.0 - 1e-9)) ? 1 : 0;
        }
    }
}

/* ---- the interior-point method ------------------------------------------------------------------------ */

typedef struct {
    long long K, M;                 /* K + 1 variables, M rows */
    const double *h;                /* (K) grid steps */
    const unsigned char *free_;     /* (K + 1) */
    long long *c0;                  /* (M) first column of each row */
    double *g;                      /* (M, 3) */
    double *r;                      /* (M) */
} Problem;

/* dt of interval k at b and its first and second derivatives (zero in a variable fixed at 0) */
static double interval(const double *b, double h, double *gx, double *gy, double *hxx, double *hyy, double *hxy)
{
    double u = sqrt(b[0] > 0 ? b[0] : 0), w = sqrt(b[1] > 0 ? b[1] : 0), S = u + w;
    double S2 = S * S, S3 = S2 * S;
    *gx = u > 0 ? -h / (S2 * u) : 0;
    *gy = w > 0 ? -h / (S2 * w) : 0;
    if (hxx) {
        *hxx = u > 0 ? h / (S3 * u * u) + h / (2 * S2 * u * u * u) : 0;
        *hyy = w > 0 ? h / (S3 * w * w) + h / (2 * S2 * w * w * w) : 0;
        *hxy = (u > 0 && w > 0) ? h / (S3 * u * w) : 0;
    }
    return 2 * h / S;
}

/* duration and its gradient */
static double duration(const Problem *P, const double *b, double *grad)
{
    double T = 0, gx, gy;
    if (grad) memset(grad, 0, (P->K + 1) * sizeof(double));
    for (long long k = 0; k < P->K; ++k) {
        T += interval(b + k, P->h[k], &gx, &gy, NULL, NULL, NULL);
        if (grad) { grad[k] += gx; grad[k + 1] += gy; }
    }
    return T;
}

static double row_value(const Problem *P, long long q, const double *x)
{
    const double *g = P->g + 3 * q, *v = x + P->c0[q];
    return g[0] * v[0] + g[1] * v[1] + g[2] * v[2];
}

/* pentadiagonal Cholesky in place (d0 diagonal, d1, d2 the first and second subdiagonals) */
static int band_factor(long long n, double *d0, double *d1, double *d2)
{
    for (long long i = 0; i < n; ++i) {
        double v = d0[i] - (i >= 1 ? d1[i - 1] * d1[i - 1] : 0) - (i >= 2 ? d2[i - 2] * d2[i - 2] : 0);
        if (!(v > 0)) return -1;
        d0[i] = sqrt(v);
        if (i + 1 < n) d1[i] = (d1[i] - (i >= 1 ? d2[i - 1] * d1[i - 1] : 0)) / d0[i];
        if (i + 2 < n) d2[i] = d2[i] / d0[i];
    }
    return 0;
}

static void band_solve(long long n, const double *d0, const double *d1, const double *d2, double *x)
{
    for (long long i = 0; i < n; ++i)
        x[i] = (x[i] - (i >= 1 ? d1[i - 1] * x[i - 1] : 0) - (i >= 2 ? d2[i - 2] * x[i - 2] : 0)) / d0[i];
    for (long long i = n - 1; i >= 0; --i)
        x[i] = (x[i] - (i + 1 < n ? d1[i] * x[i + 1] : 0) - (i + 2 < n ? d2[i] * x[i + 2] : 0)) / d0[i];
}

/* x = -grad - G' (e / s) on free variables (e = NULL: -grad), 0 on fixed ones; is = 1 / s */
static void newton_rhs(const Problem *P, const double *grad, const double *e, const double *is, double *x)
{
    long long n = P->K + 1;
    for (long long i = 0; i < n; ++i) x[i] = -grad[i];
    if (e) for (long long q = 0; q < P->M; ++q) {
        const double *g = P->g + 3 * q;
        double w = e[q] * is[q], *v = x + P->c0[q];
        v[0] -= w * g[0]; v[1] -= w * g[1]; v[2] -= w * g[2];
    }
    for (long long i = 0; i < n; ++i) if (!P->free_[i]) x[i] = 0;
}

/* the step along (ds, dl) that keeps s and lam positive (fraction 0.99 of the way to the boundary) */
static double max_step(long long M, const double *s, const double *ds, const double *lam, const double *dl,
                       double frac)
{
    double alpha = 1;
    for (long long q = 0; q < M; ++q) {
        if (dl[q] < 0 && -frac * lam[q] / dl[q] < alpha) alpha = -frac * lam[q] / dl[q];
        if (ds[q] < 0 && -frac * s[q] / ds[q] < alpha) alpha = -frac * s[q] / ds[q];
    }
    return alpha;
}

/* ds = -G db, dl = (e - lam s) / s + (lam / s) G db with e = sigma mu - corrector (e = NULL: 0); is = 1 / s */
static void directions(const Problem *P, const double *db, const double *e, const double *is, const double *lam,
                       double *ds, double *dl)
{
    for (long long q = 0; q < P->M; ++q) {
        double gd = row_value(P, q, db);
        ds[q] = -gd;
        dl[q] = ((e ? e[q] : 0) + lam[q] * gd) * is[q] - lam[q];
    }
}

/* minimise T(b) under the rows from a strictly feasible b by Mehrotra's predictor-corrector (primal
   feasibility is kept exactly: s = r - G b > 0 at every iterate); returns the iterations (negative on
   failure).  Stops when the gap s'lam <= gap_tol T and the dual residual on free b <= 1e-6 max |grad T|,
   or when the step (0.99 of the way to the boundary) falls below 1e-4 (rounding).  warm: lam (in ws)
   is the previous pass's, raised to at least 1e-3 T / (M s). */
static int ipm(const Problem *P, double *b, int maxit, double gap_tol, int warm, double *ws)
{
    long long n = P->K + 1, M = P->M;
    double *s = ws, *lam = s + M, *ds = lam + M, *dl = ds + M, *sn = dl + M, *ln = sn + M, *e = ln + M;
    double *dsa = e + M, *dla = dsa + M, *is = dla + M;
    double *grad = is + M, *d0 = grad + n, *d1 = d0 + n, *d2 = d1 + n, *db = d2 + n, *bn = db + n, *work = bn + n;
    double T = duration(P, b, NULL);
    for (long long q = 0; q < M; ++q) {
        s[q] = P->r[q] - row_value(P, q, b);
        if (!(s[q] > 0)) return -1;
        if (!warm) lam[q] = T / (M * s[q]);
        else if (lam[q] < 1e-3 * T / (M * s[q])) lam[q] = 1e-3 * T / (M * s[q]);
    }
    int it;
    for (it = 0; it < maxit; ++it) {
        double eta = 0;
        for (long long q = 0; q < M; ++q) { eta += s[q] * lam[q]; is[q] = 1.0 / s[q]; }
        T = duration(P, b, grad);
        double gmax = 0, rmax = 0;
        memcpy(work, grad, n * sizeof(double));
        for (long long q = 0; q < M; ++q) {
            const double *g = P->g + 3 * q;
            double *w = work + P->c0[q];
            w[0] += g[0] * lam[q]; w[1] += g[1] * lam[q]; w[2] += g[2] * lam[q];
        }
        for (long long i = 0; i < n; ++i) if (P->free_[i]) {
            if (fabs(grad[i]) > gmax) gmax = fabs(grad[i]);
            if (fabs(work[i]) > rmax) rmax = fabs(work[i]);
        }
        if (eta <= gap_tol * T && rmax <= 1e-6 * gmax) break;
        double mu = eta / M;
        /* Newton matrix: hess T + G' diag(lam/s) G, fixed variables held */
        memset(d0, 0, n * sizeof(double)); memset(d1, 0, n * sizeof(double)); memset(d2, 0, n * sizeof(double));
        for (long long k = 0; k < P->K; ++k) {
            double gx, gy, hxx, hyy, hxy;
            interval(b + k, P->h[k], &gx, &gy, &hxx, &hyy, &hxy);
            d0[k] += hxx; d0[k + 1] += hyy; d1[k] += hxy;
        }
        for (long long q = 0; q < M; ++q) {
            const double *g = P->g + 3 * q;
            long long c = P->c0[q];
            double w = lam[q] * is[q];
            d0[c] += w * g[0] * g[0]; d0[c + 1] += w * g[1] * g[1]; d0[c + 2] += w * g[2] * g[2];
            d1[c] += w * g[0] * g[1]; d1[c + 1] += w * g[1] * g[2]; d2[c] += w * g[0] * g[2];
        }
        double big = 0;
        for (long long i = 0; i < n; ++i) if (d0[i] > big) big = d0[i];
        for (long long i = 0; i < n; ++i) {
            d0[i] += 1e-14 * big;
            if (!P->free_[i]) {
                d0[i] = 1; d1[i] = 0; d2[i] = 0;
                if (i >= 1) d1[i - 1] = 0;
                if (i >= 2) d2[i - 2] = 0;
            }
        }
        if (band_factor(n, d0, d1, d2)) return -2;
        /* predictor (affine scaling), then the centring parameter and the corrector */
        newton_rhs(P, grad, NULL, is, db);
        band_solve(n, d0, d1, d2, db);
        directions(P, db, NULL, is, lam, dsa, dla);
        double aa = max_step(M, s, dsa, lam, dla, 1.0), mua = 0;
        for (long long q = 0; q < M; ++q) mua += (s[q] + aa * dsa[q]) * (lam[q] + aa * dla[q]);
        mua /= M;
        double sigma = mua / mu;
        sigma = sigma * sigma * sigma;
        for (long long q = 0; q < M; ++q) e[q] = sigma * mu - dsa[q] * dla[q];
        newton_rhs(P, grad, e, is, db);
        band_solve(n, d0, d1, d2, db);
        directions(P, db, e, is, lam, ds, dl);
        double alpha = max_step(M, s, ds, lam, dl, 0.99);
        if (alpha < 1e-4) break;                   /* stalled (rounding): the current point is feasible anyway */
        int pos = 1;
        for (long long i = 0; i < n; ++i) bn[i] = b[i] + alpha * db[i];
        for (long long q = 0; q < M; ++q) {
            sn[q] = P->r[q] - row_value(P, q, bn);
            ln[q] = lam[q] + alpha * dl[q];
            pos &= sn[q] > 0;
        }
        if (!pos) break;
        memcpy(b, bn, n * sizeof(double)); memcpy(s, sn, M * sizeof(double)); memcpy(lam, ln, M * sizeof(double));
    }
    return it;
}

/* The jerk pass.  Stage rows (ns): siv the stage, sa, sc, sr (a b_i + c b_{i+1} <= r, r > 0); free (K+1);
   xcap (K+1) the box (>= 1e12: none); jerk changes m = 0 .. K+1: jc0 (K+2) the window, jd (K+2, n, 3) the
   coefficients of the change of qdd_j, kch (K+2) the interval whose dt bounds it; jmax (n).  b (K+1): in,
   the reference profile (meeting every row, positive where free); out, the last pass's profile.
   info: [passes, Newton iterations, status (0 ok, < 0 failed), duration].  Passes stop when T improves
   by less than tol (relative) or after max_passes. */
int rmt_jerk(long long K, long long n, const double *h, const unsigned char *free_, const double *xcap,
             long long ns, const long long *siv, const double *sa, const double *sc, const double *sr,
             const long long *jc0, const double *jd, const long long *kch, const double *jmax,
             double *b, long long max_passes, double tol, long long maxit, double *info)
{
    long long nv = K + 1, nb = 0, nj = 2 * n * (K + 2);
    for (long long i = 0; i < nv; ++i) nb += free_[i] + (free_[i] && xcap[i] < 1e12);
    long long M = ns + nb + nj;
    Problem P = {K, M, h, free_, malloc(M * sizeof(long long)), malloc(3 * M * sizeof(double)),
                 malloc(M * sizeof(double))};
    double *ws = malloc((10 * M + 7 * nv) * sizeof(double)), *bh = malloc(2 * nv * sizeof(double)), *bt = bh + nv;
    if (!P.c0 || !P.g || !P.r || !ws || !bh) { free(P.c0); free(P.g); free(P.r); free(ws); free(bh); return -9; }
    long long q = 0, last = K - 2;
    for (long long k = 0; k < ns; ++k, ++q) {          /* stage rows, scaled to r = 1 */
        long long c = siv[k] < last ? siv[k] : last, p = siv[k] - c;
        double *g = P.g + 3 * q;
        g[0] = g[1] = g[2] = 0;
        g[p] = sa[k] / sr[k]; g[p + 1] = sc[k] / sr[k];
        P.c0[q] = c; P.r[q] = 1;
    }
    for (long long i = 0; i < nv; ++i) {                /* the box */
        if (!free_[i]) continue;
        long long c = i < last ? i : last;
        for (int up = 0; up < 2; ++up) {
            if (up && !(xcap[i] < 1e12)) continue;
            double *g = P.g + 3 * q;
            g[0] = g[1] = g[2] = 0;
            g[i - c] = up ? 1.0 / xcap[i] : -1.0;
            P.c0[q] = c; P.r[q] = up ? 1 : 0; ++q;
        }
    }
    memcpy(bh, b, nv * sizeof(double));
    double T_prev = duration(&P, bh, NULL);
    int status = 0, passes = 0, iters = 0;
    while (passes < max_passes) {
        ++passes;
        long long qj = q;                            /* jerk rows at the tangent of bh */
        for (long long m = 0; m < K + 2; ++m) {
            long long k = kch[m], c = jc0[m];
            double gx, gy, dt = interval(bh + k, h[k], &gx, &gy, NULL, NULL, NULL);
            double rhs0 = dt - gx * bh[k] - gy * bh[k + 1];
            for (long long j = 0; j < n; ++j) for (int sg = -1; sg <= 1; sg += 2, ++qj) {
                const double *d = jd + 3 * (m * n + j);
                double *g = P.g + 3 * qj, rhs = jmax[j] * rhs0;
                for (int p = 0; p < 3; ++p) g[p] = sg * d[p];
                g[k - c] -= jmax[j] * gx; g[k + 1 - c] -= jmax[j] * gy;
                for (int p = 0; p < 3; ++p) g[p] /= rhs;
                P.c0[qj] = c; P.r[qj] = 1;
            }
        }
        /* strictly inside: bh meets every row, c * bh (c < 1) strictly (every row is homogeneous in b but
           the tangent's, which holds 1.5 dt(bh) against c (+-D bh + dt(bh) / 2) there) */
        double cs = 0.99;
        int inside = 0;
        for (int tries = 0; tries < 60 && !inside; ++tries, cs *= 0.7) {
            for (long long i = 0; i < nv; ++i) bt[i] = cs * bh[i];
            inside = 1;
            for (long long r = 0; r < M && inside; ++r) inside = P.r[r] - row_value(&P, r, bt) > 0;
        }
        if (!inside) { status = -3; break; }
        int it = ipm(&P, bt, (int)maxit, 1e-7, passes > 1, ws);
        if (it < 0) { status = it; break; }
        iters += it;
        double T = duration(&P, bt, NULL);
        if (!(T < T_prev)) break;
        memcpy(bh, bt, nv * sizeof(double));
        int improved = T < T_prev * (1 - tol);
        T_prev = T;
        if (!improved) break;
    }
    memcpy(b, bh, nv * sizeof(double));
    info[0] = passes; info[1] = iters; info[2] = status; info[3] = T_prev;
    free(P.c0); free(P.g); free(P.r); free(ws); free(bh);
    return status;
}
