/* Intervals (included by motion.c): which of eight intervals — from lane l of one block of placed states
   to lane l of the next — are not proven clear.  The region a capsule sweeps over an interval is enclosed
   (motion.c's first comment) by a ball around the middle of its centre's chord, grown by half the chord
   and the curvature allowance q8 M; the hierarchy body → groups → capsules is walked with those balls,
   eight intervals at once, and only where a capsule's ball is not clear is the exact swept capsule
   (swept, clearance.c's distances: lower bounds) measured.  Against another body everything is done in
   the frame of the lower body of the pair, where its own balls and capsules stand still. */
#ifndef RMT_MOTION_INTERVALS_H
#define RMT_MOTION_INTERVALS_H

/* capsule c's swept region between lane lp of P and lane lc of C (world, or body `frame`'s frame when
   frame >= 0), curvature allowance e (m): the capsule of motion.c's first comment, into w */
static void swept(const rmt_clear_model *m, const block *P, int lp, const block *C, int lc, long long c,
                  long long frame, double e, wcap *w)
{
  wcap ca, cb;
  cap_of(m, P, lp, c, &ca);
  cap_of(m, C, lc, c, &cb);
  double a0[3], b0[3], a1[3], b1[3];
  for (int i = 0; i < 3; ++i) {
    a0[i] = ca.a[i]; b0[i] = ca.a[i] + ca.d[i];
    a1[i] = cb.a[i]; b1[i] = cb.a[i] + cb.d[i];
  }
  if (frame >= 0) {
    double t[3];
    to_frame(P, lp, frame, a0, t); memcpy(a0, t, sizeof t);
    to_frame(P, lp, frame, b0, t); memcpy(b0, t, sizeof t);
    to_frame(C, lc, frame, a1, t); memcpy(a1, t, sizeof t);
    to_frame(C, lc, frame, b1, t); memcpy(b1, t, sizeof t);
  }
  double r = ca.r + e + SLACK;
  if (ca.dd == 0.0) {                     /* a ball: its centre's chord */
    double d[3] = { a1[0] - a0[0], a1[1] - a0[1], a1[2] - a0[2] };
    fill_cap(w, a0, d, r);
    return;
  }
  double da = sqrt(dist2(a0, a1)), db = sqrt(dist2(b0, b1));
  double ma[3], d[3];
  for (int i = 0; i < 3; ++i) { ma[i] = 0.5 * (a0[i] + a1[i]); d[i] = 0.5 * (b0[i] + b1[i]) - ma[i]; }
  fill_cap(w, ma, d, r + 0.5 * (da > db ? da : db));
}

/* The exact test of one interval (lane lp of P to lane lc of C, q8 = h^2 / 8) against every pair, each
   measured up to the cap: 1 when proven clear; *lb the least lower bound found (HUGE_VAL: nothing within
   the cap).  Bound mode's test (slower than block_intervals, which stops at the first doubt). */
static int interval_exact(const rmt_motion *X, const block *P, int lp, const block *C, int lc, double q8, double *lb)
{
  const rmt_clear_model *m = X->m;
  double thr = X->cap, least = HUGE_VAL;
  wcap w;
  for (long long b = 0; b <= m->last; ++b)
    for (long long c = m->body_cap[b]; c < m->body_cap[b + 1]; ++c) {
      swept(m, P, lp, C, lc, c, -1, q8 * X->Mc[c], &w);
      for (long long p = 0; p < m->nprim; ++p) {
        if ((m->prim_int[4 * p + 3] >> b) & 1) continue;
        const double *Pr = m->prim + RMT_PRIM_STRIDE * p;
        long long kind = m->prim_int[4 * p];
        if (far_apart(dist2(w.m, Pr), w.rb + Pr[3], fmin(thr, least))) continue;
        double v;
        if (kind == RMT_PRIM_SET) {
          long long hit;
          v = cap_set(m, m->prim_int[4 * p + 2], &w, fmin(thr, least), &hit);
        } else v = cap_prim(&w, Pr, kind, fmin(thr, least), 0, NULL);
        if (v < least) least = v;
      }
    }
  long long nb = m->nbody;
  for (long long pr = 0; pr < m->npair; ++pr) {
    long long bi = m->pair[2 * pr], bj = m->pair[2 * pr + 1];
    for (long long cj = m->body_cap[bj]; cj < m->body_cap[bj + 1]; ++cj) {
      swept(m, P, lp, C, lc, cj, bi, q8 * X->Mrel[nb * cj + bi], &w);
      for (long long ci = m->body_cap[bi]; ci < m->body_cap[bi + 1]; ++ci) {
        const wcap *u = X->local + ci;
        if (far_apart(dist2(u->m, w.m), u->rb + w.rb, fmin(thr, least))) continue;
        double s, t, v = seg_seg(u, w.a, w.d, w.dd, w.idd, &s, &t) - u->r - w.r;
        if (v < least) least = v;
      }
    }
  }
  *lb = least;
  return least > X->margin;
}

/* The lanes of `lanes` whose interval, from lane l of P to lane l of C (q8 = h^2 / 8), is not proven
   clear.  strip: -1 when lane l lies in strip l (the first pass), else the one strip every lane lies in
   (refinement) — pairs proven on a strip from its ends (strip_culls) are skipped there. */
static unsigned block_intervals(rmt_motion *X, const block *P, const block *C, double q8, unsigned lanes, int strip)
{
  const rmt_clear_model *m = X->m;
  double thr = X->margin, tnext = X->tnext;
  long long nb = m->nbody;
  unsigned open = 0;                              /* lanes not proven */
  double bx[LANES], by[LANES], bz[LANES], brad[LANES];
  double *gc = X->gchord, *cc = X->cchord;       /* chord balls per group, per capsule: x, y, z, radius */
  unsigned char *made = X->made;
  wcap w;
  /* ---- obstacles */
  for (long long c = 0; c < m->ncap; ++c) made[c] = 0;
  for (long long b = 0; b <= m->last && m->nprim; ++b) {
    if (m->body_cap[b] == m->body_cap[b + 1]) continue;
    chord_balls(P->W + 3 * LANES * b, C->W + 3 * LANES * b, m->body_sphere[4 * b + 3] + q8 * X->Mb[b] + SLACK,
                bx, by, bz, brad);
    for (long long g = X->gbeg[b]; g < X->gbeg[b + 1]; ++g) {
      double *o = gc + 4 * LANES * g;
      chord_balls(P->G + 3 * LANES * g, C->G + 3 * LANES * g, X->gball[4 * g + 3] + q8 * X->Mb[nb + g] + SLACK,
                  o, o + LANES, o + 2 * LANES, o + 3 * LANES);
    }
    for (long long p = 0; p < m->nprim; ++p) {
      if ((m->prim_int[4 * p + 3] >> b) & 1) continue;
      unsigned om = X->omask[m->nprim * b + p];          /* strips not proven from their ends (strip_culls) */
      om = strip < 0 ? om : ((om >> strip) & 1 ? ALL_LANES : 0u);
      unsigned near = lanes & ~open & om;
      if (!near) continue;
      const double *Pr = m->prim + RMT_PRIM_STRIDE * p;
      long long kind = m->prim_int[4 * p];
      near &= ball_bound(Pr, bx, by, bz, brad, thr);
      for (long long g = X->gbeg[b]; g < X->gbeg[b + 1] && near; ++g) {
        const double *o = gc + 4 * LANES * g;
        unsigned gn = (kind == RMT_PRIM_SET ? ball_bound(Pr, o, o + LANES, o + 2 * LANES, o + 3 * LANES, thr)
                                            : ball_prim(Pr, kind, o, o + LANES, o + 2 * LANES, o + 3 * LANES, thr))
                      & near;
        for (long long k = X->cbeg[g]; k < X->cbeg[g + 1] && gn; ++k) {
          long long c = X->gcap[k];
          double *q = cc + 4 * LANES * c;
          unsigned hit = gn;
          if (kind != RMT_PRIM_SET) {
            if (!made[c]) {
              double p0[3 * LANES], p1[3 * LANES];
              double r = cap_balls(m, P, c, p0, p0 + LANES, p0 + 2 * LANES);
              cap_balls(m, C, c, p1, p1 + LANES, p1 + 2 * LANES);
              chord_balls(p0, p1, r + q8 * X->Mc[c] + SLACK, q, q + LANES, q + 2 * LANES, q + 3 * LANES);
              made[c] = 1;
            }
            hit = ball_prim(Pr, kind, q, q + LANES, q + 2 * LANES, q + 3 * LANES, thr) & gn;
          }
          for (int l = 0; l < LANES && hit; ++l) {   /* the ball is not clear: the swept capsule decides */
            if (!((hit >> l) & 1)) continue;
            swept(m, P, l, C, l, c, -1, q8 * X->Mc[c], &w);
            long long h = -1;
            int clear = kind == RMT_PRIM_SET
                ? (cap_set(m, m->prim_int[4 * p + 2], &w, tnext, &h), h < 0)
                : (far_apart(dist2(w.m, Pr), w.rb + Pr[3], tnext) || cap_prim(&w, Pr, kind, tnext, 0, NULL) >= tnext);
            if (clear) hit &= ~(1u << l);
          }
          open |= hit;
          gn &= ~hit;
          near &= ~hit;
        }
      }
    }
  }
  /* ---- body pairs, in the lower body's frame */
  double p0[3 * LANES], p1[3 * LANES], cx[LANES], cy[LANES], cz[LANES], rad[LANES];
  wcap sw[LANES];
  for (long long pr = 0; pr < m->npair; ++pr) {
    long long bi = m->pair[2 * pr], bj = m->pair[2 * pr + 1];
    unsigned pm = X->pmask[pr];
    pm = strip < 0 ? pm : ((pm >> strip) & 1 ? ALL_LANES : 0u);
    unsigned near = lanes & ~open & pm;
    if (!near) continue;
    const double *Si = m->body_sphere + 4 * bi;
    frame_lanes(P, bi, P->W + 3 * LANES * bj, P->W + 3 * LANES * bj + LANES, P->W + 3 * LANES * bj + 2 * LANES,
                p0, p0 + LANES, p0 + 2 * LANES);
    frame_lanes(C, bi, C->W + 3 * LANES * bj, C->W + 3 * LANES * bj + LANES, C->W + 3 * LANES * bj + 2 * LANES,
                p1, p1 + LANES, p1 + 2 * LANES);
    chord_balls(p0, p1, m->body_sphere[4 * bj + 3] + q8 * X->Mbrel[nb * bj + bi] + SLACK, cx, cy, cz, rad);
    near &= ball_point(cx, cy, cz, rad, Si, 0, Si[3] + thr);
    for (long long c = m->body_cap[bj]; c < m->body_cap[bj + 1]; ++c) made[c] = 0;
    for (long long gj = X->gbeg[bj]; gj < X->gbeg[bj + 1] && near; ++gj) {
      const double *Gp = P->G + 3 * LANES * gj, *Gc = C->G + 3 * LANES * gj;
      double gx[LANES], gy[LANES], gz[LANES], gr[LANES];
      frame_lanes(P, bi, Gp, Gp + LANES, Gp + 2 * LANES, p0, p0 + LANES, p0 + 2 * LANES);
      frame_lanes(C, bi, Gc, Gc + LANES, Gc + 2 * LANES, p1, p1 + LANES, p1 + 2 * LANES);
      chord_balls(p0, p1, X->gball[4 * gj + 3] + q8 * X->Mbrel[nb * (nb + gj) + bi] + SLACK, gx, gy, gz, gr);
      unsigned n1 = ball_point(gx, gy, gz, gr, Si, 0, Si[3] + thr) & near;
      for (long long gi = X->gbeg[bi]; gi < X->gbeg[bi + 1] && n1; ++gi) {
        const double *Gi = X->gball + 4 * gi;
        unsigned n2 = ball_point(gx, gy, gz, gr, Gi, 0, Gi[3] + thr) & n1;
        for (long long kj = X->cbeg[gj]; kj < X->cbeg[gj + 1] && n2; ++kj) {
          long long cj = X->gcap[kj];
          double *q = cc + 4 * LANES * cj;
          if (!made[cj]) {
            double a0[3 * LANES], a1[3 * LANES];
            double r = cap_balls(m, P, cj, a0, a0 + LANES, a0 + 2 * LANES);
            cap_balls(m, C, cj, a1, a1 + LANES, a1 + 2 * LANES);
            frame_lanes(P, bi, a0, a0 + LANES, a0 + 2 * LANES, p0, p0 + LANES, p0 + 2 * LANES);
            frame_lanes(C, bi, a1, a1 + LANES, a1 + 2 * LANES, p1, p1 + LANES, p1 + 2 * LANES);
            chord_balls(p0, p1, r + q8 * X->Mrel[nb * cj + bi] + SLACK, q, q + LANES, q + 2 * LANES, q + 3 * LANES);
            made[cj] = 1;
          }
          unsigned n3 = ball_point(q, q + LANES, q + 2 * LANES, q + 3 * LANES, Gi, 0, Gi[3] + thr) & n2;
          unsigned have = 0;
          for (long long ki = X->cbeg[gi]; ki < X->cbeg[gi + 1] && n3; ++ki) {
            const wcap *u = X->local + X->gcap[ki];
            unsigned hit = ball_point(q, q + LANES, q + 2 * LANES, q + 3 * LANES, u->m, 0, u->rb + thr) & n3;
            for (int l = 0; l < LANES && hit; ++l) {  /* the ball is not clear: the swept capsule decides */
              if (!((hit >> l) & 1)) continue;
              if (!((have >> l) & 1)) { swept(m, P, l, C, l, cj, bi, q8 * X->Mrel[nb * cj + bi], sw + l); have |= 1u << l; }
              const wcap *v = sw + l;
              double s, t;
              if (far_apart(dist2(u->m, v->m), u->rb + v->rb, tnext)
                  || seg_seg(u, v->a, v->d, v->dd, v->idd, &s, &t) - u->r - v->r >= tnext)
                hit &= ~(1u << l);
            }
            open |= hit;
            n3 &= ~hit;
            n2 &= ~hit;
            n1 &= ~hit;
            near &= ~hit;
          }
        }
      }
    }
  }
  return open & lanes;
}

#endif
