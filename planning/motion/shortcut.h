/* Path shortening against the motion checker (included by motion.c): the planner's simplification in C,
   every new motion proven by rmt_motion_check before it replaces part of the path, so a proven path stays
   proven.

   * reduce: from each kept row, jump to the farthest later row that a proven straight motion reaches
     (the rows in between go);
   * shortcut: two points drawn at random along the path's length (on different segments) are joined by
     a straight motion when it is proven and shorter than the path between them; the draws stop after
     `tries` attempts or `patience` failures in a row (both at most a few per row left after reduce: a
     path of three rows has little to gain), and reduce runs again.

   Lengths are Euclidean in joint space (what rmtkit and VAMP call a path's length).  The random draws
   come from a splitmix64 generator seeded by the caller: the same seed and path give the same result. */
#ifndef RMT_MOTION_SHORTCUT_H
#define RMT_MOTION_SHORTCUT_H

#define MAX_ROWS 4096     /* the longest path shortened */

RMT_INLINE unsigned long long splitmix64(unsigned long long *s)
{
  unsigned long long z = (*s += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

RMT_INLINE double uniform01(unsigned long long *s) { return (double)(splitmix64(s) >> 11) * 0x1.0p-53; }

RMT_INLINE double joint_dist(const double *a, const double *b, long long n)
{
  double s = 0.0;
  for (long long j = 0; j < n; ++j) s += (b[j] - a[j]) * (b[j] - a[j]);
  return sqrt(s);
}

static int proven_motion(rmt_motion *X, const double *a, const double *b, long long *checks)
{
  rmt_motion_result r;
  ++*checks;
  return rmt_motion_check(X, a, b, 0, 0, &r) == RMT_MOTION_CLEAR;
}

/* reduce (see above) rows P[0 .. M) in place (M <= MAX_ROWS); returns the rows kept */
static long long reduce_rows(rmt_motion *X, double *P, long long M, long long *checks)
{
  long long n = X->n, keep[MAX_ROWS], k = 1, i = 0;
  keep[0] = 0;
  while (i < M - 1) {
    long long j = M - 1;
    while (j > i + 1 && !proven_motion(X, P + n * i, P + n * j, checks)) --j;
    keep[k++] = j;
    i = j;
  }
  for (long long t = 0; t < k; ++t)            /* keep[t] >= t, increasing: copying forwards is safe */
    if (keep[t] != t) memmove(P + n * t, P + n * keep[t], sizeof(double) * (size_t)n);
  return k;
}

/* Shorten path P (M rows of n, room for cap rows) in place; returns the new row count.  `tries` random
   shortcuts at most, stopping after `patience` failures in a row; *checks counts the motions checked. */
long long rmt_motion_shortcut(rmt_motion *X, double *P, long long M, long long cap, unsigned long long seed,
                              long long tries, long long patience, long long *checks)
{
  long long n = X->n;
  *checks = 0;
  if (cap > MAX_ROWS) cap = MAX_ROWS;
  if (M < 3 || M > cap) return M;
  M = reduce_rows(X, P, M, checks);
  if (tries > 4 * M + 4) tries = 4 * M + 4;
  if (patience > 2 * M + 2) patience = 2 * M + 2;
  unsigned long long s = seed;
  double L[MAX_ROWS];
  long long fails = 0;
  for (long long k = 0; k < tries && fails < patience && M >= 2; ++k) {
    L[0] = 0.0;
    for (long long i = 1; i < M; ++i) L[i] = L[i - 1] + joint_dist(P + n * (i - 1), P + n * i, n);
    double total = L[M - 1];
    if (!(total > 0.0)) break;
    double s1 = uniform01(&s) * total, s2 = uniform01(&s) * total;
    if (s1 > s2) { double x = s1; s1 = s2; s2 = x; }
    long long i = 0, j = 0;
    while (i + 2 < M && L[i + 1] <= s1) ++i;            /* s1 on segment i: rows i .. i + 1 */
    j = i;
    while (j + 2 < M && L[j + 1] <= s2) ++j;
    if (j == i) { ++fails; continue; }
    double qa[64], qb[64];
    double fa = (s1 - L[i]) / (L[i + 1] - L[i]), fb = (s2 - L[j]) / (L[j + 1] - L[j]);
    for (long long c = 0; c < n; ++c) {
      qa[c] = P[n * i + c] + fa * (P[n * (i + 1) + c] - P[n * i + c]);
      qb[c] = P[n * j + c] + fb * (P[n * (j + 1) + c] - P[n * j + c]);
    }
    double direct = joint_dist(qa, qb, n);
    if (!(direct < (s2 - s1) * (1.0 - 1e-9))) { ++fails; continue; }
    /* the new rows: 0 .. i, qa, qb, j + 1 .. M − 1 */
    long long M2 = (i + 1) + 2 + (M - j - 1);
    if (M2 > cap || !proven_motion(X, qa, qb, checks)) { ++fails; continue; }
    memmove(P + n * (i + 3), P + n * (j + 1), sizeof(double) * (size_t)(n * (M - j - 1)));
    memcpy(P + n * (i + 1), qa, sizeof(double) * (size_t)n);
    memcpy(P + n * (i + 2), qb, sizeof(double) * (size_t)n);
    M = M2;
    fails = 0;
  }
  return reduce_rows(X, P, M, checks);
}
#endif
