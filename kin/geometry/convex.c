/* Certified distances between convex solids given by points (GJK), for kin.geometry.convex.
 *
 * A solid is the convex hull of n points (row-major n×3, in its own frame) placed by a 4×4 row-major
 * transform T (NULL: identity), dilated by a radius r.  rmt_convex_distance runs Gilbert–Johnson–Keerthi
 * on the Minkowski difference A − B for its point v nearest the origin and returns a LOWER BOUND of the
 * distance whatever the search's accuracy: for the unit u = v/|v|, min_A u·x − max_B u·x (the support gap,
 * computed from the two support points) bounds every |a − b| from below.  At GJK's optimum the gap is the
 * distance.  Solids that may overlap give a value ≤ 0 (minus the radii; not a penetration depth).
 * The nearest point of the simplex (≤ 4 points) is found by trying every face of it (the affine
 * minimiser of each subset, kept when all its barycentric weights are positive).
 */
#include <math.h>
#include <string.h>

#define REL_TOL 1e-9
#define ABS_TOL 1e-12
#define MAX_ITER 64

static void support(const double *P, long n, const double *T, const double d[3], double out[3]) {
    double dl[3];
    if (T) {            /* direction into the solid's frame: R^T d */
        dl[0] = T[0] * d[0] + T[4] * d[1] + T[8] * d[2];
        dl[1] = T[1] * d[0] + T[5] * d[1] + T[9] * d[2];
        dl[2] = T[2] * d[0] + T[6] * d[1] + T[10] * d[2];
    } else {
        dl[0] = d[0]; dl[1] = d[1]; dl[2] = d[2];
    }
    long best = 0;
    double bv = P[0] * dl[0] + P[1] * dl[1] + P[2] * dl[2];
    for (long i = 1; i < n; i++) {
        double v = P[3 * i] * dl[0] + P[3 * i + 1] * dl[1] + P[3 * i + 2] * dl[2];
        if (v > bv) { bv = v; best = i; }
    }
    const double *p = P + 3 * best;
    if (T) {
        out[0] = T[0] * p[0] + T[1] * p[1] + T[2] * p[2] + T[3];
        out[1] = T[4] * p[0] + T[5] * p[1] + T[6] * p[2] + T[7];
        out[2] = T[8] * p[0] + T[9] * p[1] + T[10] * p[2] + T[11];
    } else {
        out[0] = p[0]; out[1] = p[1]; out[2] = p[2];
    }
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* solve the k×k system G x = r (k ≤ 3) by Cramer's rule; 0 when singular */
static int solve(int k, double G[3][3], const double r[3], double x[3]) {
    if (k == 1) {
        if (fabs(G[0][0]) < 1e-300) return 0;
        x[0] = r[0] / G[0][0];
        return 1;
    }
    if (k == 2) {
        double det = G[0][0] * G[1][1] - G[0][1] * G[1][0];
        if (fabs(det) < 1e-300) return 0;
        x[0] = (r[0] * G[1][1] - G[0][1] * r[1]) / det;
        x[1] = (G[0][0] * r[1] - r[0] * G[1][0]) / det;
        return 1;
    }
    double det = G[0][0] * (G[1][1] * G[2][2] - G[1][2] * G[2][1]) - G[0][1] * (G[1][0] * G[2][2] - G[1][2] * G[2][0])
                 + G[0][2] * (G[1][0] * G[2][1] - G[1][1] * G[2][0]);
    if (fabs(det) < 1e-300) return 0;
    for (int c = 0; c < 3; c++) {
        double M[3][3];
        memcpy(M, G, sizeof M);
        for (int i = 0; i < 3; i++) M[i][c] = r[i];
        x[c] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0])
                + M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
    }
    return 1;
}

/* the point of conv(W[0..m)) nearest the origin into v; W reduced to the face it lies in; returns m */
static int nearest(double W[4][3], int m, double v[3]) {
    double best = INFINITY, bp[3] = {0, 0, 0};
    int bmask = 1;
    for (int mask = 1; mask < (1 << m); mask++) {
        int idx[4], k = 0;
        for (int i = 0; i < m; i++)
            if (mask & (1 << i)) idx[k++] = i;
        double lam[4], p[3];
        if (k == 1) {
            lam[0] = 1.0;
        } else {
            double E[3][3], G[3][3], r[3], mu[3];
            for (int i = 1; i < k; i++)
                for (int c = 0; c < 3; c++) E[i - 1][c] = W[idx[i]][c] - W[idx[0]][c];
            for (int i = 0; i < k - 1; i++) {
                for (int j = 0; j < k - 1; j++) G[i][j] = dot3(E[i], E[j]);
                r[i] = -dot3(E[i], W[idx[0]]);
            }
            if (!solve(k - 1, G, r, mu)) continue;
            double s = 0;
            int ok = 1;
            for (int i = 0; i < k - 1; i++) {
                lam[i + 1] = mu[i];
                s += mu[i];
                if (mu[i] <= 0) ok = 0;
            }
            lam[0] = 1.0 - s;
            if (lam[0] <= 0 || !ok) continue;
        }
        p[0] = p[1] = p[2] = 0;
        for (int i = 0; i < k; i++)
            for (int c = 0; c < 3; c++) p[c] += lam[i] * W[idx[i]][c];
        double d = dot3(p, p);
        if (d < best) {
            best = d;
            memcpy(bp, p, sizeof bp);
            bmask = mask;
        }
    }
    double R[4][3];
    int k = 0;
    for (int i = 0; i < m; i++)
        if (bmask & (1 << i)) memcpy(R[k++], W[i], sizeof R[0]);
    memcpy(W, R, sizeof(double) * 3 * k);
    memcpy(v, bp, sizeof bp);
    return k;
}

double rmt_convex_distance(const double *A, long na, const double *TA, double ra,
                           const double *B, long nb, const double *TB, double rb) {
    double W[4][3], v[3], a[3], b[3], d[3], w[3];
    int m = 0;
    double lower = -INFINITY;
    d[0] = 1; d[1] = 0; d[2] = 0;
    support(A, na, TA, d, a);
    d[0] = -1;
    support(B, nb, TB, d, b);
    for (int c = 0; c < 3; c++) v[c] = a[c] - b[c];
    for (int it = 0; it < MAX_ITER; it++) {
        double nv = sqrt(dot3(v, v));
        if (nv <= ABS_TOL) break;
        double u[3] = {v[0] / nv, v[1] / nv, v[2] / nv}, mu[3] = {-u[0], -u[1], -u[2]};
        support(A, na, TA, mu, a);
        support(B, nb, TB, u, b);
        for (int c = 0; c < 3; c++) w[c] = a[c] - b[c];
        double gap = dot3(u, w);
        if (gap > lower) lower = gap;
        if (nv - gap <= REL_TOL * nv + ABS_TOL) break;
        int dup = 0;
        for (int i = 0; i < m; i++)
            if (W[i][0] == w[0] && W[i][1] == w[1] && W[i][2] == w[2]) dup = 1;
        if (dup) break;
        memcpy(W[m++], w, sizeof w);
        m = nearest(W, m, v);
        if (m == 4) break;      /* the origin inside the tetrahedron: they overlap */
    }
    if (!(lower > 0)) lower = 0;
    return lower - ra - rb;
}
