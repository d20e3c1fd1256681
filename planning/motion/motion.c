/* The planner's hot loop: is a joint configuration valid, and is the straight joint motion a -> b
   valid — proven, not sampled.  Loaded by planning/motion/checker.py (built by kin.native.build, as a
   CPython extension module when Python's headers are there, so that OMPL's callbacks reach it in one
   call: pyext.h).  It is compiled together with the clearance kernel (kin/geometry/clearance.c, included
   below: the frames of eight configurations at once, the exact distance functions) and reads the same
   model (clearance.h).

   A configuration is valid when it lies within the joint limits, outside every interval window (a slab
   lo <= q_j <= hi of one joint) and every capsule of the robot is clear of every obstacle and of every
   body it is checked against by more than the required clearance `margin`.

   A straight motion q(t) = a + t (b - a), t in [0, 1], is valid when both ends are, the limits hold (they
   do along the whole motion: the limit box is convex), no interval window is crossed (q_j is linear in
   t: exact), and every state along it is clear — proven as follows.  K + 1 states at t_i = i / K are
   placed, K from the motion's size: no point of the robot moves more than `step` metres between two of
   them by the first-order bound L_c = sum_j R[c, j] |b_j - a_j| (capsule_radii in
   kin/geometry/motion.py).  Between t_i and t_{i+1} a point p of capsule c stays within (h^2 / 8) M_c of
   the chord from p(t_i) to p(t_{i+1}) (h = 1 / K; M_c bounds |p''|: curvature_bound in
   kin/geometry/motion.py derives it), so on that interval

   * a ball (a capsule of zero length) lies inside the capsule whose segment is its centre's chord and
     whose radius is its own plus (h^2 / 8) M_c, and that inside the ball around the chord's middle of
     radius r + (h^2 / 8) M_c + |chord| / 2;
   * a capsule of segment A B (every point within its half length of its middle point m) lies inside the
     ball around the middle of m's chord of radius |B - A| / 2 + r + (h^2 / 8) M_c + |m's chord| / 2, and
     inside the capsule of segment (A_i + A_{i+1}) / 2 .. (B_i + B_{i+1}) / 2 and radius
     r + (h^2 / 8) M_c + max(|A_{i+1} - A_i|, |B_{i+1} - B_i|) / 2;

   and an interval is proven clear of an obstacle when one of those regions is — the balls first, eight
   intervals at once in vector code (the clearance of a ball from a box, cylinder, sphere or capsule is a
   closed form), the capsule (the exact, slower distance of clearance.c, a lower bound) where a ball is
   not clear.  Against another body the same holds in the frame of the lower body i of the pair, where its
   capsules stand still and the other's move with joints i+1 .. j only (their curvature bound counts those
   joints only).  An interval not proven is cut into eight (seven more states placed; a state in
   collision is a collision of the motion), up to `max_depth` times; what is still open then is "not
   proven", which a planner treats as invalid.  SLACK (1e-9 m) on every radius covers the rounding of the
   placed points (~1e-15 m); every distance is a lower bound of the true one.

   Most pairs are settled without any exact distance.  The first block places the motion's two ends and
   six states between them (eight configurations at once, cutting the motion into seven strips) and
   tests them as states — most invalid motions are refuted there, the pair that collided last tried
   first; then every body–primitive pair and body pair whose distance at both ends of a strip exceeds half
   of what can move in the strip (first-order bound, against another body in the lower body's frame) is
   proven on that strip, and when nothing is left the motion is proven after eight states.  What is left
   is walked as VAMP's "rake" walks a motion: lane l of each later block steps along strip l, the bodies
   an open strip needs placed, the intervals tested down the hierarchy body ball → group balls → capsule
   balls → swept capsule (types.h) for the pairs left open on their strip only.  `ordered` (path checks)
   looks at every interval and reports the violation earliest along the motion; `bound` measures every
   interval exactly, a proven lower bound of the clearance along a proven motion.  A single configuration
   (the state validity checker's question) is checked in scalar code (states.h: state_one). */
#include "clearance.c"
#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif
#include "types.h"
#include "place.h"
#include "balls.h"
#include "states.h"
#include "intervals.h"

/* ---- per motion --------------------------------------------------------------------------------- */
/* Joint increments A_j = |dq_j| and W_j, the sum of A_l over the revolute l < j (W has n + 1 entries). */
RMT_INLINE void increments(const rmt_motion *X, const double *dq, double *A, double *W)
{
  W[0] = 0.0;
  for (long long j = 0; j < X->n; ++j) {
    A[j] = fabs(dq[j]);
    W[j + 1] = W[j] + (X->revolute[j] ? A[j] : 0.0);
  }
}

/* The first-order bounds of motion dq: Lb, Lbrel (every point of a ball moves at most this much over the
   motion, in the world and in each body's frame: sum over the joints that move it relative to that frame
   of |dq_j| R_j); returns the largest of a capsule (which sets how many states the motion gets). */
static double first_order(rmt_motion *X, const double *dq)
{
  long long n = X->n, nb = X->m->nbody, ncap = X->m->ncap, nball = nb + X->ngroup;
  double A[MAX_JOINTS], W[MAX_JOINTS + 1], Lmax = 0.0;
  increments(X, dq, A, W);
  for (long long c = 0; c < ncap; ++c) {
    const double *R = X->R + n * c;
    double L = 0.0;
    for (long long j = 0; j < n; ++j) L += A[j] * R[j];
    Lmax = L > Lmax ? L : Lmax;
  }
  for (long long k = 0; k < nball; ++k) {
    const double *R = X->Rb + n * k;
    double *lrel = X->Lbrel + nb * k, T = 0.0;
    for (long long i = n; i < nb; ++i) lrel[i] = 0.0;
    for (long long j = n - 1; j >= 0; --j) { T += A[j] * R[j]; lrel[j] = T; }
    X->Lb[k] = lrel[0];
  }
  return Lmax;
}

/* The curvature bounds of motion dq (what the intervals' tests need, made only when one is tested): Mc,
   Mb (the capsules' and the balls' points, world) and Mrel, Mbrel (the same in the frame of each body i:
   only joints i+1 … move a point relative to body i's frame, so the sums of curvature_bound run over
   those joints and W counts from joint i+1).  With T_j = sum_{l >= j} A_l R_l,
     M^(i) = sum_{j >= i} A_j (rev_j ? 2 (W_j - W_i) R_j + T_j : (W_j - W_i)) = S1_i - W_i S2_i
   with suffix sums S1, S2 (joints 0-based; body i is moved by joints < i). */
static void curvature(rmt_motion *X, const double *dq)
{
  long long n = X->n, nb = X->m->nbody, ncap = X->m->ncap, nball = nb + X->ngroup;
  double A[MAX_JOINTS], W[MAX_JOINTS + 1];
  increments(X, dq, A, W);
  for (long long k = 0; k < ncap + nball; ++k) {
    int ball = k >= ncap;
    long long kb = k - ncap;
    const double *R = ball ? X->Rb + n * kb : X->R + n * k;
    double *mrel = ball ? X->Mbrel + nb * kb : X->Mrel + nb * k;
    double T = 0.0, S1 = 0.0, S2 = 0.0;
    for (long long i = n; i < nb; ++i) mrel[i] = 0.0;
    for (long long j = n - 1; j >= 0; --j) {
      T += A[j] * R[j];
      if (R[j] > 0.0) {
        if (X->revolute[j]) { S1 += A[j] * (2.0 * W[j] * R[j] + T); S2 += 2.0 * A[j] * R[j]; }
        else { S1 += A[j] * W[j]; S2 += A[j]; }
      }
      double v = S1 - W[j] * S2;                 /* in the frame of body j (moved by joints < j) */
      mrel[j] = v > 0.0 ? v : 0.0;
    }
    if (ball) X->Mb[kb] = mrel[0];
    else X->Mc[k] = mrel[0];
  }
}

RMT_INLINE int q_ok(const rmt_motion *X, const double *q)
{
  for (long long j = 0; j < X->n; ++j) {
    if (!isfinite(q[j])) return 0;
    if (X->m && !(fabs(q[j]) <= X->m->dh[8 * j + 6])) return 0;
  }
  return 1;
}

RMT_INLINE int in_limits(const rmt_motion *X, const double *q)
{
  for (long long j = 0; j < X->n; ++j)
    if (q[j] < X->lower[j] || q[j] > X->upper[j]) return 0;
  return 1;
}

/* The first block: states at t = l / STRIPS (lanes 0 … 7: the motion's two ends and six states between,
   the strips' ends).  Which of them are in collision goes into *coll (with `stop`, the search ends at the
   first); which body–primitive pairs and body pairs are proven clear on which strips from those ends
   alone, into X->omask and X->pmask (a bit set: left to the intervals' tests); returns the strips with
   anything left.  A distance changes at most as fast as the points move: over the whole motion L (the
   body ball's first-order bound against obstacles; that of the upper body's ball in the lower body's
   frame against another body), so over a strip it stays above the margin when it is above
   L / (2 STRIPS) + margin at both ends — and where it is not, the state is tested against the margin. */
static unsigned first_block(rmt_motion *X, const block *B0, unsigned *coll, int stop)
{
  const rmt_clear_model *m = X->m;
  long long np = m->nprim, nb = m->nbody;
  unsigned open = 0;
  *coll = 0;
  if (stop && X->hint != NO_HINT) {         /* the pair that collided last, first */
    *coll = code_lanes(X, B0, X->hint, ALL_LANES, X->margin);
    if (*coll) return 0;
  }
  double rad[LANES];
  for (long long b = 0; b <= m->last; ++b) {
    if (m->body_cap[b] == m->body_cap[b + 1]) continue;
    double need = X->Lb[b] / (2 * STRIPS) + X->margin + 2.0 * SLACK;
    const double *Wb = B0->W + 3 * LANES * b;
    fill_rad(rad, m->body_sphere[4 * b + 3] + SLACK);
    for (long long p = 0; p < np; ++p) {
      if ((m->prim_int[4 * p + 3] >> b) & 1) { X->omask[np * b + p] = 0; continue; }
      /* the body's ball (a lower bound of every capsule's distance) decides the strips: cheap, and
         what it leaves open the intervals' tests settle with tighter balls */
      unsigned near = ball_bound(m->prim + RMT_PRIM_STRIDE * p, Wb, Wb + LANES, Wb + 2 * LANES, rad, need);
      unsigned om = (near | near >> 1) & STRIP_LANES;   /* strip l: its start (bit l) or end (bit l + 1) near */
      X->omask[np * b + p] = om;
      open |= om;
      if (near & ~*coll) {
        unsigned h = body_prim_lanes(X, B0, b, p, near & ~*coll, X->margin);
        if (h) { *coll |= h; X->hint = b * np + p; }
      }
      if (stop && *coll) return open;
    }
  }
  for (long long pr = 0; pr < m->npair; ++pr) {
    long long bi = m->pair[2 * pr], bj = m->pair[2 * pr + 1];
    double need = X->Lbrel[nb * bj + bi] / (2 * STRIPS) + X->margin + 2.0 * SLACK;
    const double *Wi = B0->W + 3 * LANES * bi, *Wj = B0->W + 3 * LANES * bj;
    fill_rad(rad, m->body_sphere[4 * bj + 3] + SLACK);
    unsigned near = ball_point(Wj, Wj + LANES, Wj + 2 * LANES, rad, Wi, 1, m->body_sphere[4 * bi + 3] + need);
    if (near) near = pair_lanes(X, B0, pr, near, need);    /* near pairs: their groups and capsules */
    unsigned pm = (near | near >> 1) & STRIP_LANES;
    X->pmask[pr] = pm;
    open |= pm;
    if (near & ~*coll) {
      unsigned h = pair_lanes(X, B0, pr, near & ~*coll, X->margin);
      if (h) { *coll |= h; X->hint = -1 - pr; }
    }
    if (stop && *coll) return open;
  }
  return open;
}

/* ---- refinement ----------------------------------------------------------------------------------- */
/* The interval from lane lp of P to lane lc of C (width h, in strip `strip`) failed its test: cut it into
   eight — seven new states; a state in collision ends the search — and prove the eight pieces, cutting
   again where needed.  CLEAR, COLLISION (r->t) or UNPROVEN (r->t: the open piece's start).  Bound mode
   (lb): every piece measured (interval_exact), *lb lowered to the least bound of the proven ones. */
static int refine(rmt_motion *X, const double *a, const double *dq, const block *P, int lp, const block *C, int lc,
                  double h, int depth, int strip, rmt_motion_result *r, double *lb)
{
  if (depth >= X->max_depth || r->evals + LANES > X->max_evals) { r->t = P->t[lp]; return RMT_MOTION_UNPROVEN; }
  block *R = X->deep + 2 * depth, *S = R + 1;       /* R: the seven new states and the end; S: the starts */
  double t0 = P->t[lp], t1 = C->t[lc];
  for (int l = 0; l < LANES; ++l) R->t[l] = l == LANES - 1 ? t1 : t0 + (t1 - t0) * (double)(l + 1) / LANES;
  place_states(X, a, dq, R);
  r->evals += LANES - 1;
  unsigned coll = block_collisions(X, R, ALL_LANES, 0);
  copy_lane(X, P, lp, S, 0);
  for (int l = 1; l < LANES; ++l) copy_lane(X, R, l - 1, S, l);
  double hk = h / LANES, q8 = 0.125 * hk * hk;
  /* a state in collision: the motion collides; the pieces before it are searched for an earlier one */
  int first = coll ? __builtin_ctz(coll) : LANES;         /* pieces 0 … first end at or before state `first` */
  if (coll && !X->ordered) { r->t = R->t[first]; return RMT_MOTION_COLLISION; }
  unsigned todo = coll ? (ALL_LANES >> (LANES - 1 - first)) : ALL_LANES;
  unsigned bad = lb ? 0 : block_intervals(X, S, R, q8, todo, strip);
  for (int l = 0; l < LANES && l <= first; ++l) {
    int failed;
    if (lb) {
      double least;
      failed = !interval_exact(X, S, l, R, l, q8, &least);
      if (!failed && least < *lb) *lb = least;
    } else failed = (bad >> l) & 1;
    if (!failed) continue;
    int st = refine(X, a, dq, S, l, R, l, hk, depth + 1, strip, r, lb);
    if (st == RMT_MOTION_COLLISION || (st == RMT_MOTION_UNPROVEN && !coll)) return st;
  }
  if (coll) { r->t = R->t[first]; return RMT_MOTION_COLLISION; }
  return RMT_MOTION_CLEAR;
}

/* the first parameter t at which the motion a -> a + dq is inside an interval window, or NAN */
static double window_entry(const rmt_motion *X, const double *a, const double *dq)
{
  double first = NAN;
  for (long long k = 0; k < X->nwin; ++k) {
    const double *w = X->win + 3 * k;
    long long j = (long long)w[0];
    double lo = w[1], hi = w[2], x0 = a[j], x1 = a[j] + dq[j];
    double u = x0 < x1 ? x0 : x1, v = x0 < x1 ? x1 : x0;
    if (!(lo <= v && u <= hi)) continue;
    double t = 0.0;
    if (x0 < lo) t = (lo - x0) / dq[j];
    else if (x0 > hi) t = (x0 - hi) / -dq[j];
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    if (!(t >= first)) first = t;
  }
  return first;
}

/* keep the violation earliest along the motion (ordered mode) */
RMT_INLINE void note(rmt_motion_result *best, int status, double t)
{
  if (best->status == RMT_MOTION_CLEAR || t < best->t) { best->status = status; best->t = t; }
}

/* ---- entry points ----------------------------------------------------------------------------------- */
/* Check the motion a -> b (n each) into r (status: RMT_MOTION_*).

   S blocks of LANES states: lane l < STRIPS walks the l-th seventh ("strip") of the motion, its states
   l (S - 1) + 0 … S - 1 of K = STRIPS (S - 1) intervals, K from the first-order bound and `step`; lane 7
   holds the motion's end.  The first block (t = l / 7) is tested as states — most invalid motions are
   refuted there — and first_block proves what it can of each strip from its ends; the intervals of every
   later block are tested only for the pairs left open on their strip, and an interval that is not proven is cut
   into eight, again and again (refine).  When nothing is left open after the first block, the motion is
   proven without placing another state.  ordered: every interval is looked at and the violation reported
   is the earliest along the motion; bound: every interval is measured (interval_exact), r->bound a proven
   lower bound of the clearance along a proven motion (inf when nothing comes within the cap). */
int rmt_motion_check(rmt_motion *X, const double *a, const double *b, int ordered, int bound, rmt_motion_result *r)
{
  long long n = X->n;
  r->status = RMT_MOTION_CLEAR; r->t = NAN; r->evals = 0; r->states = 0; r->bound = HUGE_VAL;
  if (!q_ok(X, a) || !q_ok(X, b)) return r->status = RMT_MOTION_BAD;
  if (!in_limits(X, a)) { r->t = 0.0; return r->status = RMT_MOTION_LIMITS; }
  if (!in_limits(X, b)) { r->t = 1.0; return r->status = RMT_MOTION_LIMITS; }
  double dq[MAX_JOINTS];
  for (long long j = 0; j < n; ++j) dq[j] = b[j] - a[j];
  double tw = window_entry(X, a, dq);
  if (tw == tw) { r->t = tw; return r->status = RMT_MOTION_WINDOW; }
  const rmt_clear_model *m = X->m;
  if (m == NULL || m->ncap == 0) return r->status;
  double need = ceil(first_order(X, dq) / X->step);
  long long S = (long long)(need / STRIPS) + 2;
  long long most = X->max_states / LANES;
  if (S > most) S = most < 2 ? 2 : most;
  double K = (double)(STRIPS * (S - 1)), h = 1.0 / K, q8 = 0.125 * h * h;
  double *lb = bound ? &r->bound : NULL;
  X->ordered = ordered || bound;
  rmt_motion_result best = { RMT_MOTION_CLEAR, NAN, 0, 0, HUGE_VAL };
  block *B0 = X->blk, *prev = B0;
  for (int l = 0; l < LANES; ++l) B0->t[l] = l < STRIPS ? (double)(l * (S - 1)) / K : 1.0;
  X->placed = ~0ULL;
  place_states(X, a, dq, B0);
  r->evals += STRIPS + 1;
  r->states = STRIPS * (S - 1) + 1;
  unsigned coll;
  unsigned open = first_block(X, B0, &coll, !X->ordered);
  if (coll && !X->ordered) { r->t = B0->t[__builtin_ctz(coll)]; return r->status = RMT_MOTION_COLLISION; }
  for (int k = 0; k < LANES; ++k) if ((coll >> k) & 1) note(&best, RMT_MOTION_COLLISION, B0->t[k]);
  if (open || bound) curvature(X, dq);
  if (!bound) {                       /* the later blocks place only the bodies an open strip needs */
    X->placed = 0;
    for (long long b = 0; b <= m->last; ++b)
      for (long long p = 0; p < m->nprim; ++p)
        if (X->omask[m->nprim * b + p]) { X->placed |= 1ULL << b; break; }
    for (long long p = 0; p < m->npair; ++p)
      if (X->pmask[p]) X->placed |= 1ULL << m->pair[2 * p] | 1ULL << m->pair[2 * p + 1];
  }
  if (bound) {
    open = STRIP_LANES;
    for (long long p = 0; p < m->npair; ++p) X->pmask[p] = STRIP_LANES;
    for (long long k = 0; k < m->nbody * m->nprim; ++k) X->omask[k] = STRIP_LANES;
  }
  for (long long bk = 1; bk < S && open; ++bk) {
    block *cur = X->blk + 1 + (bk & 1);
    for (int l = 0; l < LANES; ++l) cur->t[l] = l < STRIPS ? (double)(l * (S - 1) + bk) / K : 1.0;
    place_states(X, a, dq, cur);
    r->evals += STRIPS;
    unsigned bad = 0;
    if (lb) {
      for (int l = 0; l < STRIPS; ++l) {
        double least;
        if (!interval_exact(X, prev, l, cur, l, q8, &least)) bad |= 1u << l;
        else if (least < *lb) *lb = least;
      }
    } else bad = block_intervals(X, prev, cur, q8, open, -1);
    for (int l = 0; l < STRIPS && bad; ++l) {
      if (!((bad >> l) & 1)) continue;
      if (best.status != RMT_MOTION_CLEAR && best.t <= prev->t[l]) continue;
      rmt_motion_result sub = *r;
      int st = refine(X, a, dq, prev, l, cur, l, h, 0, l, &sub, lb);
      r->evals = sub.evals;
      if (st == RMT_MOTION_CLEAR) continue;
      if (!X->ordered) { r->t = sub.t; return r->status = st; }
      note(&best, st, sub.t);
    }
    prev = cur;
  }
  if (best.status != RMT_MOTION_CLEAR) { r->t = best.t; r->bound = HUGE_VAL; return r->status = best.status; }
  return r->status;
}

/* Whether configuration q (n) is valid: RMT_MOTION_CLEAR, or why not (COLLISION, LIMITS, WINDOW, BAD). */
int rmt_motion_state(rmt_motion *X, const double *q)
{
  if (!q_ok(X, q)) return RMT_MOTION_BAD;
  if (!in_limits(X, q)) return RMT_MOTION_LIMITS;
  for (long long k = 0; k < X->nwin; ++k) {
    const double *w = X->win + 3 * k;
    double v = q[(long long)w[0]];
    if (w[1] <= v && v <= w[2]) return RMT_MOTION_WINDOW;
  }
  if (X->m == NULL || X->m->ncap == 0) return RMT_MOTION_CLEAR;
  return state_one(X, &X->ss, q) ? RMT_MOTION_CLEAR : RMT_MOTION_COLLISION;
}

void rmt_motion_free(rmt_motion *X)
{
  if (X == NULL) return;
  free(X->deep);
  free(X->ssbuf);
  free(X->local);
  free(X->pmask);
  free(X->omask);
  free(X->okp);
  free(X->made);
  free(X->mem);
  free(X);
}

/* A checker for model m (NULL: limits and windows only) with the arrays described in rmt_motion (the
   caller keeps them alive); NULL when out of memory or the arguments are out of range. */
rmt_motion *rmt_motion_new(const rmt_clear_model *m, long long n, double margin, const double *lower,
                           const double *upper, const double *R, const double *Rb, const long long *revolute,
                           long long nwin, const double *win, long long ngroup, const long long *gbeg,
                           const long long *cbeg, const long long *gcap, const double *gball, double step,
                           double cap, long long max_states, int max_depth, long long max_evals)
{
  if (n < 1 || n > MAX_JOINTS || max_depth < 0 || max_depth > MAX_DEPTH_CAP || max_states < 2 * LANES
      || !(step > 0.0) || (m != NULL && m->n != n) || ngroup < 0)
    return NULL;
  rmt_motion *X = (rmt_motion *)calloc(1, sizeof(rmt_motion));
  if (X == NULL) return NULL;
  X->m = m; X->n = n; X->margin = margin; X->tnext = nextafter(margin, HUGE_VAL); X->hint = NO_HINT;
  X->placed = ~0ULL; X->lower = lower; X->upper = upper; X->R = R; X->Rb = Rb;
  X->revolute = revolute; X->nwin = nwin; X->win = win; X->step = step; X->cap = cap;
  X->ngroup = ngroup; X->gbeg = gbeg; X->cbeg = cbeg; X->gcap = gcap; X->gball = gball;
  X->max_states = max_states; X->max_depth = max_depth; X->max_evals = max_evals;
  if (m == NULL) return X;
  long long nb = m->nbody, nc = m->ncap, nball = nb + ngroup;
  size_t per = block_doubles(m, n, ngroup), nblk = 3 + 2 * ((size_t)max_depth + 1) + 1;
  size_t nd = (size_t)(nc + 2 * nball + (2 * nc + 2 * nball) * nb + m->nprim4 + 4 * LANES * (ngroup + nc)) + 8;
  X->mem = (double *)calloc(nd + per * nblk, sizeof(double));
  X->deep = (block *)calloc(2 * ((size_t)max_depth + 1), sizeof(block));
  X->local = (wcap *)calloc((size_t)nc + 1, sizeof(wcap));
  X->ssbuf = (double *)malloc(scratch_size(m) + sizeof(double));
  if (X->ssbuf == NULL) { rmt_motion_free(X); return NULL; }
  scratch_layout(m, X->ssbuf, &X->ss);
  X->pmask = (unsigned *)calloc((size_t)m->npair + 1, sizeof(unsigned));
  X->omask = (unsigned *)calloc((size_t)(nb * m->nprim) + 1, sizeof(unsigned));
  X->okp = (unsigned char *)calloc((size_t)m->nprim + 1, 1);
  X->made = (unsigned char *)calloc((size_t)nc + 1, 1);
  if (!X->mem || !X->deep || !X->local || !X->pmask || !X->omask || !X->okp || !X->made) {
    rmt_motion_free(X);
    return NULL;
  }
  double *p = X->mem;
  X->Mc = p; p += nc;
  X->Mrel = p; p += nc * nb;
  X->Mb = p; p += nball;
  X->Lb = p; p += nball;
  X->Mbrel = p; p += nball * nb;
  X->Lbrel = p; p += nball * nb;
  X->plb = p; p += m->nprim4;
  X->gchord = p; p += 4 * LANES * ngroup;
  X->cchord = p; p += 4 * LANES * nc;
  double *base = X->mem + nd;
  for (size_t k = 0; k < nblk; ++k) {
    block *B = k < 3 ? X->blk + k : (k + 1 < nblk ? X->deep + (k - 3) : &X->one);
    block_layout(m, n, ngroup, base + per * k, B);
  }
  for (long long c = 0; c < nc; ++c) {
    const double *K = m->cap + RMT_CAP_STRIDE * c;
    double d[3] = { K[3] - K[0], K[4] - K[1], K[5] - K[2] };
    fill_cap(X->local + c, K, d, K[6]);
  }
  return X;
}

#include "shortcut.h"

#ifdef RMT_PYEXT
#include "pyext.h"
#endif
