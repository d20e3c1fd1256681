/* Placing states (included by motion.c): the frames of eight configurations at once (clearance.c's
   frames(), vectorised across them), then every capsule's segment and every body's and group's ball
   centre in the world, lane fastest; and the accessors the exact (scalar) tests read a lane through. */
#ifndef RMT_MOTION_PLACE_H
#define RMT_MOTION_PLACE_H

static size_t block_doubles(const rmt_clear_model *m, long long n, long long ngroup)
{
  return (size_t)LANES * (size_t)(12 * m->nbody + 2 * (n > 0 ? n : 1) + 6 * m->ncap + 3 * m->nbody + 3 * ngroup);
}

static void block_layout(const rmt_clear_model *m, long long n, long long ngroup, double *buf, block *B)
{
  B->F = buf;
  B->cs = B->F + 12 * LANES * m->nbody;
  B->A = B->cs + 2 * LANES * (n > 0 ? n : 1);
  B->W = B->A + 6 * LANES * m->ncap;
  B->G = B->W + 3 * LANES * m->nbody;
  (void)ngroup;
}

/* p = O + X s0 + Y s1 + Z s2 for NL lanes of body frame F (lane-fastest columns X Y Z O) */
RMT_INLINE void frame_point(const double *F, const double *s, double *out, const int NL)
{
  for (int i = 0; i < 3; ++i) {
    const double *X = F + i * LANES, *Y = F + (3 + i) * LANES, *Z = F + (6 + i) * LANES, *O = F + (9 + i) * LANES;
    RMT_SIMD
    for (int l = 0; l < NL; ++l) out[i * LANES + l] = O[l] + X[l] * s[0] + Y[l] * s[1] + Z[l] * s[2];
  }
}

/* the capsules' segments and the balls' centres in the world, from the frames, for NL lanes, of the
   bodies in X->placed (bit b: body b; after a motion's first block only the bodies some open strip still
   needs are placed) */
RMT_INLINE void place_soa(const rmt_motion *X, block *B, const int NL)
{
  const rmt_clear_model *m = X->m;
  for (long long b = 0; b <= m->last; ++b) {
    long long c0 = m->body_cap[b], c1 = m->body_cap[b + 1];
    if (c0 == c1 || !((X->placed >> b) & 1)) continue;
    const double *F = B->F + 12 * LANES * b;
    frame_point(F, m->body_sphere + 4 * b, B->W + 3 * LANES * b, NL);
    for (long long g = X->gbeg[b]; g < X->gbeg[b + 1]; ++g) frame_point(F, X->gball + 4 * g, B->G + 3 * LANES * g, NL);
    for (long long c = c0; c < c1; ++c) {
      const double *K = m->cap + RMT_CAP_STRIDE * c;
      double *Ac = B->A + 6 * LANES * c;
      frame_point(F, K, Ac, NL);
      if (K[7] == 0.0) {                 /* a ball: no direction */
        for (int i = 0; i < 3; ++i)
          for (int l = 0; l < NL; ++l) Ac[(3 + i) * LANES + l] = 0.0;
        continue;
      }
      double d[3] = { K[3] - K[0], K[4] - K[1], K[5] - K[2] };
      for (int i = 0; i < 3; ++i) {
        const double *Xc = F + i * LANES, *Yc = F + (3 + i) * LANES, *Zc = F + (6 + i) * LANES;
        RMT_SIMD
        for (int l = 0; l < NL; ++l) Ac[(3 + i) * LANES + l] = Xc[l] * d[0] + Yc[l] * d[1] + Zc[l] * d[2];
      }
    }
  }
}

/* the states at B->t[0 … LANES) of the motion a + t dq into B */
static void place_states(const rmt_motion *X, const double *a, const double *dq, block *B)
{
  long long n = X->n;
  double q[LANES * MAX_JOINTS];
  for (int l = 0; l < LANES; ++l)
    for (long long j = 0; j < n; ++j) q[l * n + j] = a[j] + B->t[l] * dq[j];
  scratch s;
  s.F = B->F;
  s.cs = B->cs;
  frames(X->m, q, LANES, &s, LANES);
  place_soa(X, B, LANES);
}

/* one state q into lane 0 of B */
static void place_one(const rmt_motion *X, const double *q, double t, block *B)
{
  scratch s;
  s.F = B->F;
  s.cs = B->cs;
  frames(X->m, q, 1, &s, 1);
  place_soa(X, B, 1);
  B->t[0] = t;
}

/* lane `to` of block D := lane `from` of block S (every placed array) */
static void copy_lane(const rmt_motion *X, const block *S, int from, block *D, int to)
{
  const rmt_clear_model *m = X->m;
  size_t rows = block_doubles(m, X->n, X->ngroup) / LANES;
  for (size_t k = 0; k < rows; ++k) D->F[k * LANES + to] = S->F[k * LANES + from];
  D->t[to] = S->t[from];
}

/* lane l of block B: capsule c as a wcap (world) */
RMT_INLINE void cap_of(const rmt_clear_model *m, const block *B, int l, long long c, wcap *w)
{
  const double *K = m->cap + RMT_CAP_STRIDE * c, *Ac = B->A + 6 * LANES * c;
  for (int i = 0; i < 3; ++i) {
    w->a[i] = Ac[i * LANES + l];
    w->d[i] = Ac[(3 + i) * LANES + l];
    w->m[i] = w->a[i] + 0.5 * w->d[i];
  }
  w->r = K[6]; w->dd = K[7]; w->idd = K[8]; w->rb = K[9]; w->body = 0;
}

/* component i of column col (0 X, 1 Y, 2 Z, 3 O) of body b's frame in lane l */
RMT_INLINE double Fv(const block *B, long long b, int col, int i, int l) { return B->F[(12 * b + 3 * col + i) * LANES + l]; }

/* x (world) in body b's frame, lane l of block B */
RMT_INLINE void to_frame(const block *B, int l, long long b, const double *x, double *out)
{
  double r[3] = { x[0] - Fv(B, b, 3, 0, l), x[1] - Fv(B, b, 3, 1, l), x[2] - Fv(B, b, 3, 2, l) };
  for (int c = 0; c < 3; ++c) out[c] = Fv(B, b, c, 0, l) * r[0] + Fv(B, b, c, 1, l) * r[1] + Fv(B, b, c, 2, l) * r[2];
}

/* the points (x, y, z)[l] (world) in body b's frame of lane l, all lanes */
RMT_INLINE void frame_lanes(const block *B, long long b, const double *x, const double *y, const double *z,
                            double *ox, double *oy, double *oz)
{
  const double *F = B->F + 12 * LANES * b;
  RMT_SIMD
  for (int l = 0; l < LANES; ++l) {
    double rx = x[l] - F[9 * LANES + l], ry = y[l] - F[10 * LANES + l], rz = z[l] - F[11 * LANES + l];
    ox[l] = F[l] * rx + F[LANES + l] * ry + F[2 * LANES + l] * rz;
    oy[l] = F[3 * LANES + l] * rx + F[4 * LANES + l] * ry + F[5 * LANES + l] * rz;
    oz[l] = F[6 * LANES + l] * rx + F[7 * LANES + l] * ry + F[8 * LANES + l] * rz;
  }
}

RMT_INLINE void fill_cap(wcap *w, const double *a, const double *d, double r)
{
  for (int i = 0; i < 3; ++i) { w->a[i] = a[i]; w->d[i] = d[i]; w->m[i] = a[i] + 0.5 * d[i]; }
  w->dd = dot3(d, d);
  w->idd = w->dd > 0.0 ? 1.0 / w->dd : 0.0;
  w->r = r;
  w->rb = 0.5 * sqrt(w->dd) + r + 1e-12;
  w->body = 0;
}

/* a capsule's ball (the middle of its segment, its half length plus radius: the ball itself for a
   ball) in every lane, into (cx, cy, cz), and its radius */
RMT_INLINE double cap_balls(const rmt_clear_model *m, const block *B, long long c, double *cx, double *cy, double *cz)
{
  const double *K = m->cap + RMT_CAP_STRIDE * c, *A = B->A + 6 * LANES * c;
  double h = K[7] == 0.0 ? 0.0 : 0.5;
  RMT_SIMD
  for (int l = 0; l < LANES; ++l) {
    cx[l] = A[l] + h * A[3 * LANES + l];
    cy[l] = A[LANES + l] + h * A[4 * LANES + l];
    cz[l] = A[2 * LANES + l] + h * A[5 * LANES + l];
  }
  return K[7] == 0.0 ? K[6] : K[9];
}

/* the ball around the middle of each lane's chord p -> q (lane-fastest triples), of radius r0 plus half
   the chord's length */
RMT_INLINE void chord_balls(const double *p, const double *q, double r0, double *cx, double *cy, double *cz,
                            double *rad)
{
  RMT_SIMD
  for (int l = 0; l < LANES; ++l) {
    double dx = q[l] - p[l], dy = q[LANES + l] - p[LANES + l], dz = q[2 * LANES + l] - p[2 * LANES + l];
    cx[l] = p[l] + 0.5 * dx; cy[l] = p[LANES + l] + 0.5 * dy; cz[l] = p[2 * LANES + l] + 0.5 * dz;
    rad[l] = r0 + 0.5 * sqrt(dx * dx + dy * dy + dz * dz);
  }
}

#endif
