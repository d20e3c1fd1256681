/* The signed clearance of a robot's capsules against a cell's obstacles and against each other, for a
   batch of configurations: loaded by kin/geometry/clearance.py (built by kin.native.build; no generated
   header — the kernel is generic: the robot and the cell come in at run time as an rmt_clear_model,
   whose data layout clearance.h describes; poses are stored as their columns x, y, z, origin).

   Frames, LANES (8) configurations at a time, vectorised across them (structure of arrays, lane
   fastest): sin/cos once per joint (Cody–Waite reduction, Cephes polynomials, ~1 ulp; libm beyond
   |angle| 1e5), then frame k = frame k−1 · A_k in the convention of kin/geometry/frames.py::body_frames
   (standard Rz·Tz·Tx·Rx or modified Rx·Tx·Rz·Tz), the tool = frame n · tool, no frame past the last body
   holding a capsule; every capsule's segment and every body's bounding ball in the world.  Then, per
   configuration, the pairs:

   * capsule – sphere, capsule – capsule: the distance of the segments (Ericson's closest points,
     without branches; near-parallel segments, where his 2×2 solve loses digits, measured across the
     first one's line) minus the radii; negative = overlap depth;
   * capsule – box, capsule – cylinder: the minimum over the capsule's segment of the solid's signed
     distance function (the distance to the solid outside, minus the depth inside) minus the capsule's
     radius.  f(t) = sdf(a + t·(b − a)) is convex, so each evaluation (value and slope) gives a tangent
     line below f: the two tangent lines of a bracket [lo, hi] (slope < 0 at lo, > 0 at hi) meet at a
     proven LOWER BOUND of min f, widened by the slopes' rounding (bracket_bound), and the best point
     evaluated gives an upper bound.  The bracket shrinks (secant steps on the slope, alternating with
     steps to the tangents' crossing) until the bounds are TOL apart; the kernel reports the lower one.
     Most pairs end at the first or second evaluation (a segment over a face: f is linear);
   * capsule – sphere set: a bounding-volume hierarchy (balls and axis-aligned boxes, built in numpy by
     clearance.py) walked depth first, nearest child first, the capsules nearest the root first.

   The promise: a reported clearance NEVER exceeds the true signed distance (beyond the rounding of the
   frames, ~1e-15 m) and lies within TOL (1e-7 m) of it — the planner's proofs rely on the lower bound.

   Pruning, against the running minimum (or `cap`: values at or above it are reported as cap): a lower
   bound per body and primitive (the bounding balls, and the primitive's world box where the body's
   centre lies outside it: exact for an upright table), computed for all primitives at once in vector
   code; per capsule, its ball, and for a box or a cylinder the segment's box in the solid's frame.  For
   the minimum (modes MIN, NEAREST) the pair of lowest bound is evaluated first — or, when one pair gave
   the minimum of the last two configurations (configurations along a motion), that pair — and then only
   the pairs whose bounds still come below the minimum.

   Modes (clearance.h): RMT_MODE_MIN (N,) minima; RMT_MODE_NEAREST adds the body, the other party
   (obstacle index >= 0, or −1 − other body for a self pair; body = other = −1 and NaN points when
   nothing lies below cap) and the two witness points (p_robot on the capsule, p_other on the other
   party's surface, |p_robot − p_other| = |clearance|; in a penetration of a box or a cylinder p_robot is
   the segment's deepest point moved by the radius along the solid's normal); RMT_MODE_PER_BODY writes
   (N, n + 2) minima per body against obstacles and against other bodies (a self pair counts for both).

   Threads: configurations in chunks of CHUNK over rmt_parallel_for (rmt_parallel.h); a configuration's
   result depends on its chunk only, never on the thread count. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include "rmt_common.h"
#include "rmt_parallel.h"
#include "clearance.h"

#define TOL 1e-7          /* m: a convex minimisation stops when its lower and upper bounds are this close */
#define MAX_STEPS 200     /* ... or after this many steps (rounding only), reporting the lower bound */
#define NEAR_PARALLEL 1e-4  /* sin² of the angle below which two segments take seg_seg_parallel */
#define STACK 128         /* BVH depth limit (clearance.py builds balanced trees, depth < 40) */
#define CHUNK 64          /* configurations per range of rmt_parallel_for */
#define LANES 8           /* configurations whose frames are computed together (one AVX-512 vector) */
#define SINCOS_FAST 1e5   /* |angle| up to which the vector sin/cos reduces by pi/2 exactly enough */

typedef struct {          /* one capsule in the world, for one configuration */
  double a[3], d[3];      /* segment a .. a + d */
  double dd, idd;         /* d·d, 1/(d·d) (0 for a ball) */
  double m[3], rb;        /* bounding ball: midpoint, half length + radius */
  double r;
  long long body;
} wcap;

typedef struct {          /* what one configuration's pairs report to */
  int mode;
  double best;            /* modes MIN, NEAREST: the running minimum (starts at cap) */
  long long body, other;
  double pr[3], po[3];
  double *bo, *bs;        /* PER_BODY: minima per body against obstacles, against bodies */
  long long code;         /* what gave best: b · nprim + p (body b, primitive p), −1 − k (body pair k) */
} sink;

typedef struct { double lb; long long node, cap; } qitem;   /* a capsule to walk a sphere set's tree with */

typedef struct {          /* the scratch space of one thread */
  double *F;              /* nbody × 12 × LANES frames of a block of configurations (lane fastest) */
  double *cs;             /* n × 2 × LANES: cos, sin of each joint's angle */
  double *W;              /* LANES × nbody × 4 bounding balls in the world */
  wcap *C;                /* LANES × ncap */
  const wcap *Cl;         /* the lane whose pairs are evaluated: its capsules ... */
  const double *Wl;       /* ... and its bodies' balls */
  double *pairlb;         /* npair: the body pairs' lower bounds */
  long long hint;         /* the candidate that gave the previous configuration's minimum (NO_HINT: none) */
  int hint_kept;          /* ... and the one before's too (random configurations: rarely) */
  double *plb;            /* nbody × nprim4: the bodies' lower bounds against every primitive */
  qitem *heap;            /* ncap: the capsules to walk a sphere set's tree with, by bound */
  unsigned char *done;    /* nprim: the sets searched for this configuration */
} scratch;

#define NO_HINT (-(1LL << 62))

RMT_INLINE double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
RMT_INLINE double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

/* true when a ball pair at squared distance d2 with radii summing to rr cannot come below thr:
   sqrt(d2) − rr >= thr, without the square root */
RMT_INLINE int far_apart(double d2, double rr, double thr)
{
  double lim = thr + rr;
  return lim <= 0.0 || d2 >= lim * lim;
}

RMT_INLINE double dist2(const double *a, const double *b)
{
  double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return x * x + y * y + z * z;
}

/* the squared gap between [min(a, a + d), max(a, a + d)] and [−h, h] (0 where they overlap).  Small
   three-component loops are written out as here: GCC vectorises a loop of three as two lanes and one,
   through the stack, and the store-to-load stalls cost more than the arithmetic */
RMT_INLINE double gap2(double a, double d, double h)
{
  double e = a + d, lo = a < e ? a : e, hi = a < e ? e : a;
  double g = lo - h > -h - hi ? lo - h : -h - hi;
  return g > 0.0 ? g * g : 0.0;
}

/* ---- frames ---------------------------------------------------------------------------------- */
/* sin and cos of LANES angles, vectorised: reduction by pi/2 in three parts (Cody & Waite, fdlibm's
   constants: exact enough for |x| <= SINCOS_FAST), Cephes' polynomials on [-pi/4, pi/4] (about 1 ulp);
   larger angles go to libm */
static const double PIO2_1 = 1.57079632673412561417e+00, PIO2_2 = 6.07710050630396597660e-11,
                    PIO2_2T = 2.02226624879595063154e-21, TWO_OVER_PI = 6.36619772367581382433e-01;

RMT_INLINE void sincos_lanes(const double *restrict x, double *restrict c, double *restrict s, const int NL)
{
  double big = 0.0;
#pragma omp simd reduction(max:big)
  for (int l = 0; l < NL; ++l) {
    double v = x[l];
    double k = nearbyint(v * TWO_OVER_PI);
    double r = ((v - k * PIO2_1) - k * PIO2_2) - k * PIO2_2T;
    double z = r * r;
    double sr = r + r * z * (((((1.58962301576546568060e-10 * z - 2.50507477628578072866e-8) * z
                + 2.75573136213857245213e-6) * z - 1.98412698295895385996e-4) * z + 8.33333333332211858878e-3) * z
                - 1.66666666666666307295e-1);
    double cr = 1.0 - 0.5 * z + z * z * (((((-1.13585365213876817300e-11 * z + 2.08757008419747316778e-9) * z
                - 2.75573141792967388112e-7) * z + 2.48015872888517045348e-5) * z - 1.38888888888730564116e-3) * z
                + 4.16666666666665929218e-2);
    long long q = (long long)k;                               /* the quadrant: q & 3 */
    double sv = (q & 1) ? cr : sr, cv = (q & 1) ? sr : cr;
    s[l] = (q & 2) ? -sv : sv;
    c[l] = ((q + 1) & 2) ? -cv : cv;
    double a = fabs(v);
    big = a > big ? a : big;
  }
  if (!(big <= SINCOS_FAST))                                  /* a huge angle (or NaN): libm */
    for (int l = 0; l < NL; ++l)
      if (!(fabs(x[l]) <= SINCOS_FAST)) { s[l] = sin(x[l]); c[l] = cos(x[l]); }
}

/* the frames of nl <= NL <= LANES configurations (lane l's joint j at q[l * n + j]; lanes from nl on
   repeat the last) up to body m->last: frame k (columns X Y Z O), component i of column c of lane l at
   F[(12 k + 3 c + i) LANES + l].  NL (LANES for a batch, 1 for one configuration) is a constant where
   the function is inlined, so the lane loops are vector code of that width */
RMT_INLINE void frames(const rmt_clear_model *m, const double *q, int nl, scratch *s, const int NL)
{
  long long n = m->n, last = m->last;
  long long kmax = last < n ? last : n;
  double *F = s->F, *cs = s->cs;
  for (int i = 0; i < 12; ++i)
    for (int l = 0; l < NL; ++l) F[i * LANES + l] = m->base[i];
  double th[LANES], dd[LANES];
  for (long long k = 1; k <= kmax; ++k) {
    const double *row = m->dh + 8 * (k - 1);
    double a = row[0], ca = row[1], sa = row[2], d = row[3], theta = row[4];
    int pris = row[5] != 0.0;
    for (int l = 0; l < NL; ++l) {
      double v = q[(l < nl ? l : nl - 1) * n + k - 1];
      th[l] = pris ? theta : theta + v;
      dd[l] = pris ? d + v : d;
    }
    double *ct = cs + 2 * LANES * (k - 1), *st = ct + LANES;
    sincos_lanes(th, ct, st, NL);
    const double *P = F + 12 * LANES * (k - 1);
    double *G = F + 12 * LANES * k;
    if (m->modified) {        /* Rx(α)·Tx(a)·Rz(θ)·Tz(d) */
      for (int i = 0; i < 3; ++i) {
        const double *X = P + i * LANES, *Y = P + (3 + i) * LANES, *Z = P + (6 + i) * LANES, *O = P + (9 + i) * LANES;
        double *X2 = G + i * LANES, *Y2 = G + (3 + i) * LANES, *Z2 = G + (6 + i) * LANES, *O2 = G + (9 + i) * LANES;
        RMT_SIMD
        for (int l = 0; l < NL; ++l) {
          double y1 = ca * Y[l] + sa * Z[l], z1 = -sa * Y[l] + ca * Z[l];
          X2[l] = ct[l] * X[l] + st[l] * y1;
          Y2[l] = -st[l] * X[l] + ct[l] * y1;
          Z2[l] = z1;
          O2[l] = O[l] + a * X[l] + dd[l] * z1;
        }
      }
    } else {                  /* Rz(θ)·Tz(d)·Tx(a)·Rx(α) */
      for (int i = 0; i < 3; ++i) {
        const double *X = P + i * LANES, *Y = P + (3 + i) * LANES, *Z = P + (6 + i) * LANES, *O = P + (9 + i) * LANES;
        double *X2 = G + i * LANES, *Y2 = G + (3 + i) * LANES, *Z2 = G + (6 + i) * LANES, *O2 = G + (9 + i) * LANES;
        RMT_SIMD
        for (int l = 0; l < NL; ++l) {
          double x1 = ct[l] * X[l] + st[l] * Y[l], y1 = -st[l] * X[l] + ct[l] * Y[l];
          X2[l] = x1;
          Y2[l] = ca * y1 + sa * Z[l];
          Z2[l] = -sa * y1 + ca * Z[l];
          O2[l] = O[l] + dd[l] * Z[l] + a * x1;
        }
      }
    }
  }
  if (last == n + 1) {        /* the tool: frame n · tool */
    const double *P = F + 12 * LANES * n, *T = m->tool;
    double *G = F + 12 * LANES * (n + 1);
    for (int c = 0; c < 4; ++c)
      for (int i = 0; i < 3; ++i) {
        double *g = G + (3 * c + i) * LANES;
        const double *X = P + i * LANES, *Y = P + (3 + i) * LANES, *Z = P + (6 + i) * LANES, *O = P + (9 + i) * LANES;
        double t0 = T[3 * c], t1 = T[3 * c + 1], t2 = T[3 * c + 2], one = c == 3 ? 1.0 : 0.0;
        RMT_SIMD
        for (int l = 0; l < NL; ++l) g[l] = one * O[l] + X[l] * t0 + Y[l] * t1 + Z[l] * t2;
      }
  }
}

/* the capsules and the bodies' balls in the world for the block's NL lanes (computed across the
   lanes, then laid out per lane: capsule c of lane l at C[l ncap + c], body b's ball at W[4 (l nbody + b)]) */
RMT_INLINE void place(const rmt_clear_model *m, scratch *s, const int NL)
{
  long long ncap = m->ncap, nbody = m->nbody;
  double t[9][LANES];
  for (long long b = 0; b <= m->last; ++b) {
    long long c0 = m->body_cap[b], c1 = m->body_cap[b + 1];
    if (c0 == c1) continue;
    const double *F = s->F + 12 * LANES * b;
    const double *ball = m->body_sphere + 4 * b;
    for (int i = 0; i < 3; ++i) {
      const double *X = F + i * LANES, *Y = F + (3 + i) * LANES, *Z = F + (6 + i) * LANES, *O = F + (9 + i) * LANES;
      RMT_SIMD
      for (int l = 0; l < NL; ++l) t[i][l] = O[l] + X[l] * ball[0] + Y[l] * ball[1] + Z[l] * ball[2];
    }
    for (int l = 0; l < NL; ++l) {
      double *W = s->W + 4 * (l * nbody + b);
      W[0] = t[0][l]; W[1] = t[1][l]; W[2] = t[2][l]; W[3] = ball[3];
    }
    for (long long c = c0; c < c1; ++c) {      /* lengths do not change: dd, idd, rb come from Python */
      const double *K = m->cap + RMT_CAP_STRIDE * c;
      for (int i = 0; i < 3; ++i) {
        const double *X = F + i * LANES, *Y = F + (3 + i) * LANES, *Z = F + (6 + i) * LANES, *O = F + (9 + i) * LANES;
        RMT_SIMD
        for (int l = 0; l < NL; ++l) {
          double a = O[l] + X[l] * K[0] + Y[l] * K[1] + Z[l] * K[2];
          double e = O[l] + X[l] * K[3] + Y[l] * K[4] + Z[l] * K[5];
          t[i][l] = a; t[3 + i][l] = e - a; t[6 + i][l] = 0.5 * (e + a);
        }
      }
      for (int l = 0; l < NL; ++l) {
        wcap *w = s->C + l * ncap + c;
        for (int i = 0; i < 3; ++i) { w->a[i] = t[i][l]; w->d[i] = t[3 + i][l]; w->m[i] = t[6 + i][l]; }
        w->r = K[6];
        w->dd = K[7];
        w->idd = K[8];
        w->rb = K[9];
        w->body = b;
      }
    }
  }
}

static void frames_block(const rmt_clear_model *m, const double *q, int nl, scratch *s) { frames(m, q, nl, s, LANES); }
static void place_block(const rmt_clear_model *m, scratch *s) { place(m, s, LANES); }

/* ---- distances --------------------------------------------------------------------------------- */
/* squared distance of point p from segment a .. a + d (idd = 1/(d·d) or 0); *t the segment parameter */
RMT_INLINE double seg_point(const double *a, const double *d, double idd, const double *p, double *t)
{
  double v[3] = { p[0] - a[0], p[1] - a[1], p[2] - a[2] };
  double u = clamp01(dot3(v, d) * idd);
  *t = u;
  double x = v[0] - u * d[0], y = v[1] - u * d[1], z = v[2] - u * d[2];
  return x * x + y * y + z * z;
}

/* the convex functions minimised along a segment: value f and unit (sub)gradient n at point p, and
   *cond, how much rounding the gradient's direction may carry (in units of DBL_EPSILON per unit slope):
   a direction taken from a short vector (a point just outside the solid, or near a cylinder's axis)
   is uncertain, and a tangent line drawn with it may pass above f */
enum { SDF_BOX, SDF_CYLINDER };

RMT_INLINE double sdf(int kind, const double *S, const double *p, double *n, double *cond)
{
  double size = fabs(p[0]) + fabs(p[1]) + fabs(p[2]) + S[0] + S[1] + (kind == SDF_BOX ? S[2] : 0.0);
  if (kind == SDF_BOX) {  /* S: half sizes */
    double q[3] = { fabs(p[0]) - S[0], fabs(p[1]) - S[1], fabs(p[2]) - S[2] };
    double o[3] = { q[0] > 0.0 ? q[0] : 0.0, q[1] > 0.0 ? q[1] : 0.0, q[2] > 0.0 ? q[2] : 0.0 };
    double o2 = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
    if (o2 > 0.0) {
      double r = sqrt(o2), ir = 1.0 / r;
      n[0] = copysign(o[0] * ir, p[0]); n[1] = copysign(o[1] * ir, p[1]); n[2] = copysign(o[2] * ir, p[2]);
      *cond = 8.0 * (1.0 + size * ir);
      return r;
    }
    int k = q[0] >= q[1] ? (q[0] >= q[2] ? 0 : 2) : (q[1] >= q[2] ? 1 : 2);
    n[0] = n[1] = n[2] = 0.0;
    n[k] = copysign(1.0, p[k]);
    *cond = 8.0;
    return q[k];
  }
  /* SDF_CYLINDER: S: radius, half length */
  double rho = sqrt(p[0] * p[0] + p[1] * p[1]);
  double ux = 1.0, uy = 0.0;
  if (rho > 0.0) { ux = p[0] / rho; uy = p[1] / rho; }
  double qr = rho - S[0], qz = fabs(p[2]) - S[1], sz = copysign(1.0, p[2]);
  if (qr > 0.0 || qz > 0.0) {
    double wr = qr > 0.0 ? qr : 0.0, wz = qz > 0.0 ? qz : 0.0;
    double r = sqrt(wr * wr + wz * wz), ir = 1.0 / r;
    n[0] = wr * ir * ux; n[1] = wr * ir * uy; n[2] = wz * ir * sz;
    *cond = 8.0 * (1.0 + size * ir);
    return r;
  }
  if (qr >= qz) {
    n[0] = ux; n[1] = uy; n[2] = 0.0;
    *cond = 8.0 * (1.0 + (rho > 0.0 ? size / rho : HUGE_VAL));
    return qr;
  }
  n[0] = n[1] = 0.0; n[2] = sz;
  *cond = 8.0;
  return qz;
}

typedef struct { double t, f, n[3]; } best_point;  /* the best point evaluated: parameter, value, gradient */

/* a lower bound of min over t in [0, 1] of f(t) = sdf(P + t D) from two evaluations at lo < hi
   (values f, computed slopes g, each within e of the true one), valid on the whole of [0, 1]: the
   true tangent lines at lo and hi lie above lines of slopes g − e and g + e, whose crossing bounds f
   on [lo, hi]; beyond them the lines' ends do.  With exact slopes (e = 0, g_lo < 0 < g_hi) it is the
   crossing of the two tangents. */
RMT_INLINE double bracket_bound(double lo, double flo, double glo, double elo, double hi, double fhi, double ghi,
                                double ehi)
{
  double s1 = glo - elo, s2 = ghi + ehi, w = hi - lo, lb;
  if (s1 >= 0.0) lb = flo;
  else if (s2 <= 0.0) lb = fhi;
  else lb = (s2 * flo - s1 * fhi + s1 * s2 * w) / (s2 - s1);
  double left = flo - lo * (glo + elo > 0.0 ? glo + elo : 0.0);
  double right = fhi - (1.0 - hi) * (ehi - ghi > 0.0 ? ehi - ghi : 0.0);
  lb = left < lb ? left : lb;
  return right < lb ? right : lb;
}

/* a lower bound of min_{t in [0,1]} sdf(P + t D), within TOL of it unless it is >= thr (then the
   search stops as soon as the bound shows it); *bp the best point evaluated */
RMT_INLINE double convex_min(int kind, const double *S, const double *P, const double *D, double thr,
                             best_point *bp)
{
  double p[3], n[3], c;
  double eps = DBL_EPSILON * sqrt(dot3(D, D));               /* slope rounding per unit of cond */
  double f0 = sdf(kind, S, P, n, &c);
  double g0 = dot3(n, D), e0 = eps * c;
  bp->t = 0.0; bp->f = f0; bp->n[0] = n[0]; bp->n[1] = n[1]; bp->n[2] = n[2];
  if (g0 >= 0.0) return g0 - e0 >= 0.0 ? f0 : f0 + (g0 - e0);   /* the minimum is at t = 0 */
  p[0] = P[0] + D[0]; p[1] = P[1] + D[1]; p[2] = P[2] + D[2];
  double f1 = sdf(kind, S, p, n, &c);
  double g1 = dot3(n, D), e1 = eps * c;
  if (f1 < f0) { bp->t = 1.0; bp->f = f1; bp->n[0] = n[0]; bp->n[1] = n[1]; bp->n[2] = n[2]; }
  if (g1 <= 0.0) {                                           /* ... at t = 1 */
    double lb = g1 + e1 <= 0.0 ? f1 : f1 - (g1 + e1);
    double l0 = f0 + (g0 - e0 < 0.0 ? g0 - e0 : 0.0);       /* (rounding: the slope at 0 bounds too) */
    return l0 > lb ? l0 : lb;
  }
  double lo = 0.0, hi = 1.0, flo = f0, glo = g0, elo = e0, fhi = f1, ghi = g1, ehi = e1;
  double lb = bracket_bound(lo, flo, glo, elo, hi, fhi, ghi, ehi);
  for (int step = 0; step < MAX_STEPS; ++step) {
    double w = hi - lo, den = ghi - glo;
    if (lb >= thr || bp->f - lb <= TOL || !(w > 1e-15)) return lb;
    double t = (step & 1) ? lo + (flo - fhi + ghi * w) / den     /* the tangents' crossing */
                          : lo - glo * w / den;                  /* the slope's secant root */
    double margin = 0.02 * w;
    if (t < lo + margin) t = lo + margin;
    if (t > hi - margin) t = hi - margin;
    p[0] = P[0] + t * D[0]; p[1] = P[1] + t * D[1]; p[2] = P[2] + t * D[2];
    double ft = sdf(kind, S, p, n, &c);
    double gt = dot3(n, D), et = eps * c;
    if (ft < bp->f) { bp->t = t; bp->f = ft; bp->n[0] = n[0]; bp->n[1] = n[1]; bp->n[2] = n[2]; }
    if (gt < 0.0) { lo = t; flo = ft; glo = gt; elo = et; }
    else          { hi = t; fhi = ft; ghi = gt; ehi = et; }
    double l = bracket_bound(lo, flo, glo, elo, hi, fhi, ghi, ehi);
    lb = l > lb ? l : lb;                                   /* every bound holds: keep the best */
  }
  return lb;
}

/* distance of two near-parallel segments, exact but for rounding where Ericson's 2×2 solve loses
   digits: the least of (i) the distances of c's end points from segment 2 and (ii) over the points of
   segment 2 whose projection falls on c's segment, their distance from c's line — measured in the plane
   perpendicular to it, where segment 2 is a short segment and the distance is a 2-D point–segment one */
static double seg_seg_parallel(const wcap *c, const double *a2, const double *d2, double ie, double *s_out,
                               double *t_out)
{
  const double *a1 = c->a, *d1 = c->d;
  double t, e1[3] = { a1[0] + d1[0], a1[1] + d1[1], a1[2] + d1[2] };
  double best = seg_point(a2, d2, ie, a1, &t), s = 0.0;
  double v = seg_point(a2, d2, ie, e1, t_out);
  if (v < best) { best = v; s = 1.0; t = *t_out; }
  double L = sqrt(c->dd), u[3] = { d1[0] / L, d1[1] / L, d1[2] / L };
  double r[3] = { a2[0] - a1[0], a2[1] - a1[1], a2[2] - a1[2] };
  double ru = dot3(r, u), du = dot3(d2, u);
  double cp[3], dp[3];
  for (int i = 0; i < 3; ++i) { cp[i] = r[i] - ru * u[i]; dp[i] = d2[i] - du * u[i]; }
  double tlo = 0.0, thi = 1.0;                               /* where 0 <= ru + t du <= L */
  if (du > 0.0) { double x = -ru / du, y = (L - ru) / du; tlo = x > tlo ? x : tlo; thi = y < thi ? y : thi; }
  else if (du < 0.0) { double x = (L - ru) / du, y = -ru / du; tlo = x > tlo ? x : tlo; thi = y < thi ? y : thi; }
  else if (ru < 0.0 || ru > L) thi = -1.0;
  if (tlo <= thi) {
    double pp = dot3(dp, dp), tp = pp > 0.0 ? -dot3(cp, dp) / pp : tlo;
    tp = tp < tlo ? tlo : (tp > thi ? thi : tp);
    double x[3] = { cp[0] + tp * dp[0], cp[1] + tp * dp[1], cp[2] + tp * dp[2] };
    double w2 = dot3(x, x);
    if (w2 < best) { best = w2; t = tp; s = clamp01((ru + tp * du) / L); }
  }
  *s_out = s;
  *t_out = t;
  return sqrt(best);
}

/* distance of two segments (exact but for rounding); *s, *t the closest points' parameters */
RMT_INLINE double seg_seg(const wcap *c, const double *a2, const double *d2, double e, double ie, double *s_out,
                          double *t_out)
{
  const double *d1 = c->d;
  double r[3] = { c->a[0] - a2[0], c->a[1] - a2[1], c->a[2] - a2[2] };
  double a = c->dd, b = dot3(d1, d2), cc = dot3(d1, r), f = dot3(d2, r);
  double den = a * e - b * b;
  if (den <= NEAR_PARALLEL * a * e && a > 0.0 && e > 0.0) return seg_seg_parallel(c, a2, d2, ie, s_out, t_out);
  double s = den > 0.0 ? clamp01((b * f - cc * e) / den) : 0.0;   /* (den = 0: a ball) */
  double t = clamp01((b * s + f) * ie);
  s = clamp01((b * t - cc) * c->idd);
  double x = r[0] + s * d1[0] - t * d2[0], y = r[1] + s * d1[1] - t * d2[1], z = r[2] + s * d1[2] - t * d2[2];
  *s_out = s;
  *t_out = t;
  return sqrt(x * x + y * y + z * z);
}

/* the witness points of a pair whose closest points are p (robot) and o (other), radii r and ro */
static void witness(sink *k, const double *p, const double *o, double r, double ro)
{
  double v[3] = { o[0] - p[0], o[1] - p[1], o[2] - p[2] };
  double l = sqrt(dot3(v, v));
  double u[3] = { 0.0, 0.0, 1.0 };
  if (l > 0.0) for (int i = 0; i < 3; ++i) u[i] = v[i] / l;
  for (int i = 0; i < 3; ++i) { k->pr[i] = p[i] + r * u[i]; k->po[i] = o[i] - ro * u[i]; }
}

/* ---- capsule against one primitive ------------------------------------------------------------- */
/* the clearance of capsule c against primitive P (kind 0..3) when it is below thr, else any value
   >= thr; with want, writes the witness points into k */
static double cap_prim(const wcap *c, const double *P, long long kind, double thr, int want, sink *k)
{
  if (kind == RMT_PRIM_SPHERE || kind == RMT_PRIM_CAPSULE) {
    double R = P[10], s, t;
    double v;
    if (kind == RMT_PRIM_SPHERE) {
      double d2 = seg_point(c->a, c->d, c->idd, P + 4, &s);
      if (far_apart(d2, c->r + R, thr)) return thr;
      v = sqrt(d2) - c->r - R;
      t = 0.0;
    } else {
      double d2[3] = { P[7] - P[4], P[8] - P[5], P[9] - P[6] };
      double e = dot3(d2, d2);
      v = seg_seg(c, P + 4, d2, e, e > 0.0 ? 1.0 / e : 0.0, &s, &t) - c->r - R;
    }
    if (want && v < thr) {
      double p[3], o[3];
      for (int i = 0; i < 3; ++i) { p[i] = c->a[i] + s * c->d[i]; o[i] = P[4 + i] + t * (P[7 + i] - P[4 + i]); }
      if (kind == RMT_PRIM_SPHERE) for (int i = 0; i < 3; ++i) o[i] = P[4 + i];
      witness(k, p, o, c->r, R);
    }
    return v;
  }
  /* box, cylinder: the segment in the solid's frame (pose columns X Y Z O at P + 12) */
  const double *X = P + 12, *Y = P + 15, *Z = P + 18, *O = P + 21;
  double a0[3] = { c->a[0] - O[0], c->a[1] - O[1], c->a[2] - O[2] };
  double A[3] = { dot3(X, a0), dot3(Y, a0), dot3(Z, a0) };
  double D[3] = { dot3(X, c->d), dot3(Y, c->d), dot3(Z, c->d) };
  /* first the distance between the segment's box and the solid's (its own, or the cylinder's): a
     lower bound, exact when the segment lies over one face */
  int box = kind == RMT_PRIM_BOX;
  double g2 = gap2(A[0], D[0], P[4]) + gap2(A[1], D[1], box ? P[5] : P[4]) + gap2(A[2], D[2], box ? P[6] : P[5]);
  if (g2 > 0.0 && far_apart(g2, c->r, thr)) return thr;     /* (g2 = 0 bounds nothing below -r) */
  best_point bp;
  double v = convex_min(kind == RMT_PRIM_BOX ? SDF_BOX : SDF_CYLINDER, P + 4, A, D, thr + c->r, &bp) - c->r;
  if (want && v < thr) {
    double p[3], o[3], nw[3];
    for (int i = 0; i < 3; ++i) {
      p[i] = c->a[i] + bp.t * c->d[i];
      nw[i] = X[i] * bp.n[0] + Y[i] * bp.n[1] + Z[i] * bp.n[2];   /* outward normal in the world */
      k->pr[i] = p[i] - c->r * nw[i];
      k->po[i] = p[i] - bp.f * nw[i];
      (void)o;
    }
  }
  return v;
}

/* a lower bound of capsule w's clearance against anything under node N (its box, where apart from the
   segment's box, and its ball), or HUGE_VAL when that cannot come below thr */
RMT_INLINE double node_bound(const wcap *w, const double *N, double thr)
{
  double g2 = gap2(w->a[0] - N[4], w->d[0], N[7]) + gap2(w->a[1] - N[5], w->d[1], N[8])
            + gap2(w->a[2] - N[6], w->d[2], N[9]);
  if (g2 > 0.0 && far_apart(g2, w->r, thr)) return HUGE_VAL;
  double t, d2 = seg_point(w->a, w->d, w->idd, N, &t);
  if (far_apart(d2, w->r + N[3], thr)) return HUGE_VAL;
  double l1 = sqrt(d2) - w->r - N[3], l2 = g2 > 0.0 ? sqrt(g2) - w->r : -HUGE_VAL;
  return l1 > l2 ? l1 : l2;
}

/* the clearance of capsule c against the sphere set under node root when below thr (else thr);
   *hit the sphere (−1: none below thr) */
static double cap_set(const rmt_clear_model *m, long long root, const wcap *c, double thr, long long *hit)
{
  long long stack[STACK];
  double bound[STACK];
  int sp = 0;
  double best = thr;
  *hit = -1;
  stack[sp] = root; bound[sp] = -HUGE_VAL; ++sp;
  while (sp > 0) {
    --sp;
    if (bound[sp] >= best) continue;
    long long k = stack[sp];
    const long long *L = m->link + 2 * k;
    if (L[1] < 0) {       /* leaf: spheres L[0] … L[0] − L[1] − 1 */
      for (long long i = L[0], e = L[0] - L[1]; i < e; ++i) {
        const double *S = m->sphere + 4 * i;
        double t, d2 = seg_point(c->a, c->d, c->idd, S, &t);
        if (far_apart(d2, c->r + S[3], best)) continue;
        double v = sqrt(d2) - c->r - S[3];
        if (v < best) { best = v; *hit = i; }
      }
      continue;
    }
    double lb0 = node_bound(c, m->node + RMT_NODE_STRIDE * L[0], best);
    double lb1 = node_bound(c, m->node + RMT_NODE_STRIDE * L[1], best);
    int nearer = lb1 < lb0;
    double lbn = nearer ? lb1 : lb0, lbf = nearer ? lb0 : lb1;
    if (lbf < best) { stack[sp] = L[!nearer]; bound[sp] = lbf; ++sp; }
    if (lbn < best) { stack[sp] = L[nearer]; bound[sp] = lbn; ++sp; }
  }
  return best;
}

/* ---- one configuration --------------------------------------------------------------------------- */
/* lower bounds of the clearance of anything inside body b's ball W (centre, radius) against every
   primitive (+inf where b is ignored), vectorised over the primitives: the distance of the bounding
   balls, and where W's centre lies outside a primitive's box in the world (axis-aligned: exact for an
   upright table) the distance to that box minus W's radius — inside it nothing is known (a penetration
   may be deeper than the radius) */
static void body_bounds(const rmt_clear_model *m, const double *W, long long b, double *restrict lb)
{
  long long P4 = m->nprim4;
  const double *S = m->prim_soa;
  const double *cx = S, *cy = S + P4, *cz = S + 2 * P4, *cr = S + 3 * P4;
  const double *ax = S + 4 * P4, *ay = S + 5 * P4, *az = S + 6 * P4;
  const double *hx = S + 7 * P4, *hy = S + 8 * P4, *hz = S + 9 * P4;
  const long long *ign = m->prim_ignore;
  double wx = W[0], wy = W[1], wz = W[2], wr = W[3];
  RMT_SIMD
  for (long long p = 0; p < P4; ++p) {
    double dx = wx - cx[p], dy = wy - cy[p], dz = wz - cz[p];
    double d2 = dx * dx + dy * dy + dz * dz;
    double gx = fabs(wx - ax[p]) - hx[p], gy = fabs(wy - ay[p]) - hy[p], gz = fabs(wz - az[p]) - hz[p];
    gx = gx > 0.0 ? gx : 0.0; gy = gy > 0.0 ? gy : 0.0; gz = gz > 0.0 ? gz : 0.0;
    double g2 = gx * gx + gy * gy + gz * gz;
    /* the larger of sqrt(d2) − r and sqrt(g2) (the box bounds only when g2 > 0), with one square root:
       sqrt(d2) − r >= sqrt(g2)  <=>  x = d2 − r² − g2 >= 0 and x² >= 4 r² g2 */
    double r = cr[p], x = d2 - r * r - g2;
    int ball = g2 <= 0.0 || (x >= 0.0 && x * x >= 4.0 * r * r * g2);
    double l = sqrt(ball ? d2 : g2) - wr - (ball ? r : 0.0);
    lb[p] = ((ign[p] >> b) & 1) ? HUGE_VAL : l;
  }
}

/* capsules of body b against primitive p (not a sphere set: see set_search), reporting to k */
static void body_prim(const rmt_clear_model *m, const scratch *s, long long b, long long p, sink *k)
{
  const double *P = m->prim + RMT_PRIM_STRIDE * p;
  long long kind = m->prim_int[4 * p];
  int want = k->mode == RMT_MODE_NEAREST;
  for (long long c = m->body_cap[b]; c < m->body_cap[b + 1]; ++c) {
    const wcap *w = s->Cl + c;
    double thr = k->mode == RMT_MODE_PER_BODY ? k->bo[b] : k->best;
    if (far_apart(dist2(w->m, P), w->rb + P[3], thr)) continue;
    double v = cap_prim(w, P, kind, thr, want, k);
    if (v < thr) {
      if (k->mode == RMT_MODE_PER_BODY) k->bo[b] = v;
      else { k->best = v; k->body = b; k->other = m->prim_int[4 * p + 1]; k->code = b * m->nprim + p; }
    }
  }
}

/* ---- sphere sets ---------------------------------------------------------------------------------------- */
/* report sphere i of primitive p at clearance v from capsule c */
static void set_hit(const rmt_clear_model *m, const scratch *s, long long p, long long c, long long i, double v,
                    sink *k)
{
  const wcap *w = s->Cl + c;
  if (k->mode == RMT_MODE_PER_BODY) { k->bo[w->body] = v; return; }
  k->best = v; k->body = w->body; k->other = m->prim_int[4 * p + 1]; k->code = w->body * m->nprim + p;
  if (k->mode == RMT_MODE_NEAREST) {
    const double *S = m->sphere + 4 * i;
    double t, q[3];
    seg_point(w->a, w->d, w->idd, S, &t);
    for (int j = 0; j < 3; ++j) q[j] = w->a[j] + t * w->d[j];
    witness(k, q, S, w->r, S[3]);
  }
}


/* every capsule against sphere set p at once: the capsules in the order of their bounds against the root
   (the nearest sets a tight minimum for the others), each walked depth-first (cap_set) */
static void set_search(const rmt_clear_model *m, scratch *s, long long p, sink *k)
{
  const double *P = m->prim + RMT_PRIM_STRIDE * p;
  long long root = m->prim_int[4 * p + 2], mask = m->prim_int[4 * p + 3], n = 0;
  const double *R = m->node + RMT_NODE_STRIDE * root;
  qitem *h = s->heap;
  for (long long b = 0; b <= m->last; ++b) {
    if (m->body_cap[b] == m->body_cap[b + 1] || ((mask >> b) & 1)) continue;
    const double *W = s->Wl + 4 * b;
    double thr = k->mode == RMT_MODE_PER_BODY ? k->bo[b] : k->best;
    if (far_apart(dist2(W, P), W[3] + P[3], thr)) continue;
    for (long long c = m->body_cap[b]; c < m->body_cap[b + 1]; ++c) {
      double lb = node_bound(s->Cl + c, R, thr);
      if (!(lb < thr)) continue;
      long long i = n++;                                   /* insertion by bound */
      while (i > 0 && h[i - 1].lb > lb) { h[i] = h[i - 1]; --i; }
      h[i] = (qitem){ lb, root, c };
    }
  }
  for (long long i = 0; i < n; ++i) {
    const wcap *w = s->Cl + h[i].cap;
    double thr = k->mode == RMT_MODE_PER_BODY ? k->bo[w->body] : k->best;
    if (!(h[i].lb < thr)) continue;
    long long hit;
    double v = cap_set(m, root, w, thr, &hit);
    if (hit >= 0) set_hit(m, s, p, h[i].cap, hit, v, k);
  }
}

/* capsules of body pair pr (bodies bi < bj) against each other, reporting to k */
static void body_pair(const rmt_clear_model *m, const scratch *s, long long pr, sink *k)
{
  long long bi = m->pair[2 * pr], bj = m->pair[2 * pr + 1];
  int per_body = k->mode == RMT_MODE_PER_BODY;
  for (long long ci = m->body_cap[bi]; ci < m->body_cap[bi + 1]; ++ci) {
    const wcap *u = s->Cl + ci;
    for (long long cj = m->body_cap[bj]; cj < m->body_cap[bj + 1]; ++cj) {
      const wcap *w = s->Cl + cj;
      double thr = per_body ? (k->bs[bi] > k->bs[bj] ? k->bs[bi] : k->bs[bj]) : k->best;
      double rr = u->r + w->r;
      if (far_apart(dist2(u->m, w->m), u->rb + w->rb, thr)) continue;
      double sa, tb;
      double v = seg_seg(u, w->a, w->d, w->dd, w->idd, &sa, &tb) - rr;
      if (!(v < thr)) continue;
      if (per_body) {
        if (v < k->bs[bi]) k->bs[bi] = v;
        if (v < k->bs[bj]) k->bs[bj] = v;
        continue;
      }
      k->best = v; k->body = bi; k->other = -1 - bj; k->code = -1 - pr;
      if (k->mode == RMT_MODE_NEAREST) {
        double p[3], o[3];
        for (int i = 0; i < 3; ++i) { p[i] = u->a[i] + sa * u->d[i]; o[i] = w->a[i] + tb * w->d[i]; }
        witness(k, p, o, u->r, w->r);
      }
    }
  }
}

RMT_INLINE int ignores(const rmt_clear_model *m, long long p, long long b)
{
  return (int)((m->prim_int[4 * p + 3] >> b) & 1);
}

RMT_INLINE void candidate(const rmt_clear_model *m, scratch *s, long long code, sink *k)
{
  if (code < 0) { body_pair(m, s, -1 - code, k); return; }
  long long p = code % m->nprim;
  if (m->prim_int[4 * p] != RMT_PRIM_SET) { body_prim(m, s, code / m->nprim, p, k); return; }
  if (!s->done[p]) { s->done[p] = 1; set_search(m, s, p, k); }   /* every body at once */
}

/* every pair of one configuration (the capsules placed in s) */
static void pairs(const rmt_clear_model *m, scratch *s, sink *k)
{
  long long nprim = m->nprim;
  double *plb = s->plb;
  if (k->mode == RMT_MODE_PER_BODY) {
    /* per body: its nearest primitive (by bound) first, then the others whose bounds come below */
    for (long long b = 0; b <= m->last; ++b) {
      if (m->body_cap[b] == m->body_cap[b + 1] || nprim == 0) continue;
      body_bounds(m, s->Wl + 4 * b, b, plb);
      long long first = -1;
      for (long long p = 0; p < nprim; ++p)
        if (m->prim_int[4 * p] != RMT_PRIM_SET && (first < 0 || plb[p] < plb[first])) first = p;
      if (first < 0) continue;
      if (plb[first] < k->bo[b]) body_prim(m, s, b, first, k);
      for (long long p = 0; p < nprim; ++p)
        if (p != first && plb[p] < k->bo[b] && m->prim_int[4 * p] != RMT_PRIM_SET) body_prim(m, s, b, p, k);
    }
    for (long long p = 0; p < nprim; ++p)
      if (m->prim_int[4 * p] == RMT_PRIM_SET) set_search(m, s, p, k);
    for (long long pr = 0; pr < m->npair; ++pr) {
      long long bi = m->pair[2 * pr], bj = m->pair[2 * pr + 1];
      double thr = k->bs[bi] > k->bs[bj] ? k->bs[bi] : k->bs[bj];
      if (far_apart(dist2(s->Wl + 4 * bi, s->Wl + 4 * bj), s->Wl[4 * bi + 3] + s->Wl[4 * bj + 3], thr)) continue;
      body_pair(m, s, pr, k);
    }
    return;
  }
  /* the minimum: first the candidate that gave the previous configuration's when it also gave the one
     before (configurations that come in order, along a motion: a tight start), then the candidates whose
     bounds come below the minimum so far, the lowest bound first */
  long long hint = s->hint_kept ? s->hint : NO_HINT;
  if (m->nset > 0) memset(s->done, 0, (size_t)nprim);
  if (hint != NO_HINT) candidate(m, s, hint, k);
  long long first = NO_HINT, P4 = m->nprim4;
  double lo = HUGE_VAL, *pairlb = s->pairlb;
  /* all the bounds first (reading a bound right after its vector store stalls), the lowest without
     branches (their outcomes are random); then the lowest candidate, then those still below the minimum
     (after a good first one, few: a branch the processor predicts) */
  for (long long b = 0; b <= m->last; ++b)
    if (m->body_cap[b] < m->body_cap[b + 1] && nprim > 0) body_bounds(m, s->Wl + 4 * b, b, plb + P4 * b);
  for (long long pr = 0; pr < m->npair; ++pr) {
    const double *Wi = s->Wl + 4 * m->pair[2 * pr], *Wj = s->Wl + 4 * m->pair[2 * pr + 1];
    double d2 = dist2(Wi, Wj), rr = Wi[3] + Wj[3];
    pairlb[pr] = far_apart(d2, rr, k->best) ? HUGE_VAL : sqrt(d2) - rr;
  }
  for (long long b = 0; b <= m->last; ++b) {
    if (m->body_cap[b] == m->body_cap[b + 1]) continue;
    const double *pb = plb + P4 * b;
    for (long long p = 0; p < nprim; ++p) {
      double lb = pb[p];
      int lower = lb < lo;
      first = lower ? b * nprim + p : first;
      lo = lower ? lb : lo;
    }
  }
  for (long long pr = 0; pr < m->npair; ++pr) {
    int lower = pairlb[pr] < lo;
    first = lower ? -1 - pr : first;
    lo = lower ? pairlb[pr] : lo;
  }
  if (lo < k->best && first != hint) candidate(m, s, first, k);
  for (long long b = 0; b <= m->last; ++b) {
    if (m->body_cap[b] == m->body_cap[b + 1]) continue;
    const double *pb = plb + P4 * b;
    for (long long p = 0; p < nprim; ++p) {
      long long code = b * nprim + p;
      if (pb[p] < k->best && code != first && code != hint) candidate(m, s, code, k);
    }
  }
  for (long long pr = 0; pr < m->npair; ++pr)
    if (pairlb[pr] < k->best && -1 - pr != first && -1 - pr != hint) body_pair(m, s, pr, k);
  s->hint_kept = k->code == s->hint && k->code != NO_HINT;
  s->hint = k->code;
}

static void scratch_layout(const rmt_clear_model *m, double *buf, scratch *s)
{
  s->F = buf;
  s->cs = s->F + 12 * LANES * m->nbody;
  s->W = s->cs + 2 * LANES * (m->n > 0 ? m->n : 1);
  s->plb = s->W + 4 * LANES * m->nbody;
  s->C = (wcap *)(s->plb + m->nbody * m->nprim4);
  s->heap = (qitem *)(s->C + LANES * m->ncap);
  s->pairlb = (double *)(s->heap + m->ncap);
  s->done = (unsigned char *)(s->pairlb + m->npair);
  s->hint = NO_HINT;
  s->hint_kept = 0;
}

static size_t scratch_size(const rmt_clear_model *m)
{
  return sizeof(double) * (size_t)(16 * LANES * m->nbody + 2 * LANES * (m->n > 0 ? m->n : 1) + m->nbody * m->nprim4)
       + sizeof(wcap) * (size_t)(LANES * m->ncap) + sizeof(qitem) * (size_t)m->ncap
       + sizeof(double) * (size_t)m->npair + (size_t)m->nprim;
}
/* ---- entry points ------------------------------------------------------------------------------- */
typedef struct {
  const rmt_clear_model *m;
  const double *Q;
  int mode;
  double cap;
  double *dist, *pr, *po, *bo, *bs;
  long long *body, *other;
  int failed;
} job;

static void run_range(void *ctx, long long begin, long long end)
{
  job *J = (job *)ctx;
  const rmt_clear_model *m = J->m;
  double *buf = (double *)malloc(scratch_size(m));
  if (buf == NULL) { __atomic_store_n(&J->failed, 1, __ATOMIC_RELAXED); return; }
  scratch s;
  scratch_layout(m, buf, &s);
  long long B = m->nbody;
  for (long long i0 = begin; i0 < end; i0 += LANES) {
    int nl = end - i0 < LANES ? (int)(end - i0) : LANES;
    frames_block(m, J->Q + m->n * i0, nl, &s);
    place_block(m, &s);
    for (int l = 0; l < nl; ++l) {
      long long i = i0 + l;
      s.Cl = s.C + l * m->ncap;
      s.Wl = s.W + 4 * l * B;
      sink k = { J->mode, J->cap, -1, -1, { NAN, NAN, NAN }, { NAN, NAN, NAN }, NULL, NULL, NO_HINT };
      if (J->mode == RMT_MODE_PER_BODY) {
        k.bo = J->bo + B * i;
        k.bs = J->bs + B * i;
        for (long long b = 0; b < B; ++b) k.bo[b] = k.bs[b] = J->cap;
      }
      pairs(m, &s, &k);
      if (J->mode == RMT_MODE_PER_BODY) continue;
      J->dist[i] = k.best;
      if (J->mode == RMT_MODE_NEAREST) {
        J->body[i] = k.body;
        J->other[i] = k.other;
        for (int c = 0; c < 3; ++c) { J->pr[3 * i + c] = k.pr[c]; J->po[3 * i + c] = k.po[c]; }
      }
    }
  }
  free(buf);
}

/* clearances of configurations Q (N × n, row-major) in `mode`: dist (N) [, body, other (N), pr, po
   (N × 3)] or bo, bs (N × nbody); returns the threads that ran, or −1 when memory ran out */
int rmt_clearance(const rmt_clear_model *m, const double *Q, long long N, int mode, double cap, int threads,
                  double *dist, long long *body, long long *other, double *pr, double *po, double *bo, double *bs)
{
  job J = { m, Q, mode, cap, dist, pr, po, bo, bs, body, other, 0 };
  long long chunks = (N + CHUNK - 1) / CHUNK;
  if (threads > chunks) threads = (int)(chunks > 0 ? chunks : 1);
  int ran = rmt_parallel_for(N, CHUNK, threads, run_range, &J);
  return J.failed ? -1 : ran;
}

/* the minimum clearance of one configuration q (n): the validity checker's call.  NaN when q holds a
   non-finite value or a prismatic value beyond its bound (the caller then reports why). */
double rmt_clear_one(const rmt_clear_model *m, const double *q, double cap)
{
  for (long long j = 0; j < m->n; ++j)
    if (!(fabs(q[j]) <= m->dh[8 * j + 6])) return NAN;
  double local[4096];
  size_t need = scratch_size(m);
  double *buf = need <= sizeof local ? local : (double *)malloc(need);
  if (buf == NULL) return NAN;
  scratch s;
  scratch_layout(m, buf, &s);
  frames(m, q, 1, &s, 1);
  place(m, &s, 1);
  s.Cl = s.C;
  s.Wl = s.W;
  sink k = { RMT_MODE_MIN, cap, -1, -1, { 0, 0, 0 }, { 0, 0, 0 }, NULL, NULL, NO_HINT };
  pairs(m, &s, &k);
  if (buf != local) free(buf);
  return k.best;
}

/* Per-body clearances (against obstacles: o, against other bodies: s; nbody each) of one configuration
   q, capped at cap. */
static void per_body_one(const rmt_clear_model *m, scratch *s, const double *q, double cap, double *o, double *so)
{
  frames(m, q, 1, s, 1);
  place(m, s, 1);
  s->Cl = s->C;
  s->Wl = s->W;
  for (long long b = 0; b < m->nbody; ++b) o[b] = so[b] = cap;
  sink k = { RMT_MODE_PER_BODY, cap, -1, -1, { 0, 0, 0 }, { 0, 0, 0 }, o, so, NO_HINT };
  pairs(m, s, &k);
}

static double min_of(const double *x, long long B)
{
  double v = HUGE_VAL;
  for (long long b = 0; b < B; ++b) v = x[b] < v ? x[b] : v;
  return v;
}

/* The proof of planning/certify/collision.py for one straight motion a → b (n each), stopping at the
   first answer: every body k's points move at most d_obs[k]·|t1 − t0| along a piece [t0, t1] (and, for
   the self bound, d_self[k]·|t1 − t0|), so a piece whose end clearances satisfy c0 + c1 − 2·margin >
   that bound for every body is clear; other pieces are halved, left first, up to max_depth halvings
   and max_evals evaluated states.  Returns 1 proven clear, 0 a state with clearance <= margin found
   (its parameter in *t_out), -1 not settled within the budget, -2 out of memory or a bad q. */
int rmt_prove_motion(const rmt_clear_model *m, const double *a, const double *b, double cap,
                     const double *d_obs, const double *d_self, double margin, int max_depth, long long max_evals,
                     double *t_out)
{
  long long n = m->n, B = m->nbody;
  for (long long j = 0; j < n; ++j)
    if (!(fabs(a[j]) <= m->dh[8 * j + 6]) || !(fabs(b[j]) <= m->dh[8 * j + 6])) return -2;
  size_t need = scratch_size(m);
  long long depth_cap = max_depth + 2;
  /* the stack of pieces: t0, t1, depth, then o0, s0, o1, s1 (B each) */
  size_t piece = (size_t)(3 + 4 * B);
  double *buf = (double *)malloc(need + sizeof(double) * (piece * (size_t)(depth_cap + 1) + 2 * B + n + 1));
  if (buf == NULL) return -2;
  scratch s;
  scratch_layout(m, buf, &s);
  double *stack = buf + need / sizeof(double) + 1;
  double *om = stack + piece * (size_t)(depth_cap + 1), *sm = om + B, *q = sm + B;
  int result = 1;
  long long top = 0, evals = 2;
  double *p = stack;
  /* a clearance above what a piece of width w can need (both ends together must beat d·w + 2·margin)
     changes no verdict: evaluating with that cap lets the kernel skip the far pairs */
  double dmax = 0.0;
  for (long long k = 0; k < B; ++k) dmax = fmax(dmax, fmax(d_obs[k], d_self[k]));
  double cap1 = fmin(cap, dmax + 2 * margin + 1e-9);
  p[0] = 0.0; p[1] = 1.0; p[2] = 0.0;
  per_body_one(m, &s, a, cap1, p + 3, p + 3 + B);
  per_body_one(m, &s, b, cap1, p + 3 + 2 * B, p + 3 + 3 * B);
  if (fmin(min_of(p + 3, B), min_of(p + 3 + B, B)) <= margin) { *t_out = 0.0; result = 0; goto done; }
  if (fmin(min_of(p + 3 + 2 * B, B), min_of(p + 3 + 3 * B, B)) <= margin) { *t_out = 1.0; result = 0; goto done; }
  top = 1;
  while (top > 0) {
    p = stack + piece * (size_t)(top - 1);
    double t0 = p[0], t1 = p[1], w = t1 - t0;
    int depth = (int)p[2];
    const double *o0 = p + 3, *s0 = o0 + B, *o1 = s0 + B, *s1 = o1 + B;
    int ok = 1;
    for (long long k = 0; k < B && ok; ++k)
      ok = o0[k] + o1[k] - 2 * margin > d_obs[k] * w && s0[k] + s1[k] - 2 * margin > d_self[k] * w;
    if (ok) { --top; continue; }
    if (depth >= max_depth || evals >= max_evals) { result = -1; goto done; }
    double tm = 0.5 * (t0 + t1);
    for (long long j = 0; j < n; ++j) q[j] = a[j] + tm * (b[j] - a[j]);
    per_body_one(m, &s, q, fmin(cap1, dmax * w + 2 * margin + 1e-9), om, sm);
    ++evals;
    if (fmin(min_of(om, B), min_of(sm, B)) <= margin) { *t_out = tm; result = 0; goto done; }
    /* this piece becomes its right half [tm, t1]; its left half [t0, tm] goes on top, to be done first */
    double *r = p, *l = stack + piece * (size_t)top;
    l[0] = t0; l[1] = tm; l[2] = depth + 1;
    for (long long k = 0; k < B; ++k) {
      l[3 + k] = o0[k]; l[3 + B + k] = s0[k];
      l[3 + 2 * B + k] = om[k]; l[3 + 3 * B + k] = sm[k];
    }
    r[0] = tm; r[2] = depth + 1;
    for (long long k = 0; k < B; ++k) { r[3 + k] = om[k]; r[3 + B + k] = sm[k]; }
    ++top;
  }
done:
  free(buf);
  return result;
}
