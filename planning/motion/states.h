/* States (included by motion.c): which of eight placed states are not clear by the margin — an exact
   verdict per lane.  Bodies against primitives, then body pairs, each down the hierarchy body ball →
   group balls → capsule balls (balls.h, eight lanes at once) → the exact distance of clearance.c for a
   capsule of non-zero length whose ball is not clear. */
#ifndef RMT_MOTION_STATES_H
#define RMT_MOTION_STATES_H

RMT_INLINE void fill_rad(double *rad, double r)
{
  for (int l = 0; l < LANES; ++l) rad[l] = r;
}

/* the lanes of `cand` where capsule c is not clear of primitive p (thr: the margin, tnext: the next double) */
static unsigned cap_prim_lanes(const rmt_motion *X, const block *B, long long c, long long p, unsigned cand,
                               double thr)
{
  const rmt_clear_model *m = X->m;
  const double *P = m->prim + RMT_PRIM_STRIDE * p;
  long long kind = m->prim_int[4 * p];
  wcap w;
  unsigned hit = 0;
  if (kind == RMT_PRIM_SET) {
    double tnext = nextafter(thr, HUGE_VAL);
    for (int l = 0; l < LANES; ++l) {
      if (!((cand >> l) & 1)) continue;
      long long h;
      cap_of(m, B, l, c, &w);
      cap_set(m, m->prim_int[4 * p + 2], &w, tnext, &h);
      if (h >= 0) hit |= 1u << l;
    }
    return hit;
  }
  double cx[LANES], cy[LANES], cz[LANES], rad[LANES];
  fill_rad(rad, cap_balls(m, B, c, cx, cy, cz) + SLACK);
  hit = ball_prim(P, kind, cx, cy, cz, rad, thr) & cand;
  if (m->cap[RMT_CAP_STRIDE * c + 7] == 0.0 || !hit) return hit;   /* a ball: its ball test is exact */
  double tnext = nextafter(thr, HUGE_VAL);
  for (int l = 0; l < LANES && hit; ++l) {
    if (!((hit >> l) & 1)) continue;
    cap_of(m, B, l, c, &w);
    if (cap_prim(&w, P, kind, tnext, 0, NULL) > thr) hit &= ~(1u << l);
  }
  return hit;
}

/* the lanes of `cand` where capsules ci and cj are not clear of each other */
static unsigned cap_cap_lanes(const rmt_motion *X, const block *B, long long ci, long long cj, unsigned cand,
                              double thr)
{
  const rmt_clear_model *m = X->m;
  double ax[LANES], ay[LANES], az[LANES], bx[LANES * 3], rad[LANES];
  double ri = cap_balls(m, B, ci, ax, ay, az);
  double rj = cap_balls(m, B, cj, bx, bx + LANES, bx + 2 * LANES);
  fill_rad(rad, ri + SLACK);
  unsigned hit = ball_point(ax, ay, az, rad, bx, 1, rj + thr) & cand;
  if (m->cap[RMT_CAP_STRIDE * ci + 7] == 0.0 && m->cap[RMT_CAP_STRIDE * cj + 7] == 0.0) return hit;
  wcap u, w;
  for (int l = 0; l < LANES && hit; ++l) {
    if (!((hit >> l) & 1)) continue;
    double s, t;
    cap_of(m, B, l, ci, &u);
    cap_of(m, B, l, cj, &w);
    if (seg_seg(&u, w.a, w.d, w.dd, w.idd, &s, &t) - u.r - w.r > thr) hit &= ~(1u << l);
  }
  return hit;
}

/* the lanes of `lanes` where body b comes within thr of primitive p (exact per lane: body ball →
   group balls → capsules) */
static unsigned body_prim_lanes(const rmt_motion *X, const block *B, long long b, long long p, unsigned lanes,
                                double thr)
{
  const rmt_clear_model *m = X->m;
  if ((m->prim_int[4 * p + 3] >> b) & 1) return 0;
  const double *P = m->prim + RMT_PRIM_STRIDE * p, *Wb = B->W + 3 * LANES * b;
  long long kind = m->prim_int[4 * p];
  double rad[LANES], grad[LANES];
  fill_rad(rad, m->body_sphere[4 * b + 3] + SLACK);
  unsigned near = ball_bound(P, Wb, Wb + LANES, Wb + 2 * LANES, rad, thr) & lanes, hit = 0;
  for (long long g = X->gbeg[b]; g < X->gbeg[b + 1] && near; ++g) {
    const double *Gg = B->G + 3 * LANES * g;
    fill_rad(grad, X->gball[4 * g + 3] + SLACK);
    unsigned gn = (kind == RMT_PRIM_SET ? ball_bound(P, Gg, Gg + LANES, Gg + 2 * LANES, grad, thr)
                                        : ball_prim(P, kind, Gg, Gg + LANES, Gg + 2 * LANES, grad, thr)) & near;
    for (long long k = X->cbeg[g]; k < X->cbeg[g + 1] && gn; ++k) {
      unsigned h = cap_prim_lanes(X, B, X->gcap[k], p, gn, thr);
      hit |= h;
      gn &= ~h;
      near &= ~h;
    }
  }
  return hit;
}

/* the lanes of `lanes` where body pair pr comes within thr (exact per lane: body balls → group balls →
   capsules) */
static unsigned pair_lanes(const rmt_motion *X, const block *B, long long pr, unsigned lanes, double thr)
{
  const rmt_clear_model *m = X->m;
  long long bi = m->pair[2 * pr], bj = m->pair[2 * pr + 1];
  const double *Wi = B->W + 3 * LANES * bi, *Wj = B->W + 3 * LANES * bj;
  double rad[LANES], grad[LANES];
  fill_rad(rad, m->body_sphere[4 * bj + 3] + SLACK);
  unsigned near = ball_point(Wj, Wj + LANES, Wj + 2 * LANES, rad, Wi, 1, m->body_sphere[4 * bi + 3] + thr) & lanes;
  unsigned hit = 0;
  for (long long gj = X->gbeg[bj]; gj < X->gbeg[bj + 1] && near; ++gj) {
    const double *Gj = B->G + 3 * LANES * gj;
    fill_rad(grad, X->gball[4 * gj + 3] + SLACK);
    unsigned n1 = ball_point(Gj, Gj + LANES, Gj + 2 * LANES, grad, Wi, 1, m->body_sphere[4 * bi + 3] + thr) & near;
    for (long long gi = X->gbeg[bi]; gi < X->gbeg[bi + 1] && n1; ++gi) {
      const double *Gi = B->G + 3 * LANES * gi;
      unsigned n2 = ball_point(Gj, Gj + LANES, Gj + 2 * LANES, grad, Gi, 1, X->gball[4 * gi + 3] + thr) & n1;
      for (long long kj = X->cbeg[gj]; kj < X->cbeg[gj + 1] && n2; ++kj)
        for (long long ki = X->cbeg[gi]; ki < X->cbeg[gi + 1] && n2; ++ki) {
          unsigned h = cap_cap_lanes(X, B, X->gcap[ki], X->gcap[kj], n2, thr);
          hit |= h;
          n2 &= ~h;
          n1 &= ~h;
          near &= ~h;
        }
    }
  }
  return hit;
}

/* the lanes of `lanes` where the pair `code` (b · nprim + p for body b against primitive p, −1 − pr for
   body pair pr) comes within thr */
static unsigned code_lanes(const rmt_motion *X, const block *B, long long code, unsigned lanes, double thr)
{
  const rmt_clear_model *m = X->m;
  if (code >= 0) return body_prim_lanes(X, B, code / m->nprim, code % m->nprim, lanes, thr);
  return pair_lanes(X, B, -1 - code, lanes, thr);
}

/* the lanes (bits) of `lanes` in block B whose state is not clear by the margin (exact per lane); with
   `stop`, returns as soon as one is found — trying first the pair that collided last (X->hint: random
   samples and the motions of a planner keep running into the same obstacle) */
static unsigned block_collisions(rmt_motion *X, const block *B, unsigned lanes, int stop)
{
  const rmt_clear_model *m = X->m;
  unsigned bad = 0;
  if (stop && X->hint != NO_HINT && X->placed == ~0ULL) {
    bad = code_lanes(X, B, X->hint, lanes, X->margin);
    if (bad) return bad;
  }
  for (long long b = 0; b <= m->last; ++b) {
    /* a body not placed is proven clear on the whole motion (see X->placed) */
    if (m->body_cap[b] == m->body_cap[b + 1] || !((X->placed >> b) & 1)) continue;
    for (long long p = 0; p < m->nprim; ++p) {
      unsigned h = body_prim_lanes(X, B, b, p, lanes & ~bad, X->margin);
      if (h) { bad |= h; X->hint = b * m->nprim + p; }
      if ((stop && bad) || !(lanes & ~bad)) return bad;
    }
  }
  for (long long pr = 0; pr < m->npair; ++pr) {
    if (!((X->placed >> m->pair[2 * pr]) & 1) || !((X->placed >> m->pair[2 * pr + 1]) & 1)) continue;
    unsigned h = pair_lanes(X, B, pr, lanes & ~bad, X->margin);
    if (h) { bad |= h; X->hint = -1 - pr; }
    if ((stop && bad) || !(lanes & ~bad)) return bad;
  }
  return bad;
}

/* One configuration, scalar (the state validity checker's question: one state, not eight): clearance.c's
   frames and capsules of one configuration into its scratch s, then every body against the primitives
   (the bounds of its ball against all of them at once, body_bounds), the capsules of those that come
   near, and the body pairs — the pair that collided last first.  1 when clear by the margin. */
static int state_one(rmt_motion *X, scratch *s, const double *q)
{
  const rmt_clear_model *m = X->m;
  double thr = X->tnext;                         /* a distance below it is not clear */
  frames(m, q, 1, s, 1);
  place(m, s, 1);
  s->Cl = s->C;
  s->Wl = s->W;
  long long nprim = m->nprim;
  for (int pass = X->hint == NO_HINT ? 1 : 0; pass < 2; ++pass) {   /* pass 0: the hint alone */
    for (long long b = 0; b <= m->last; ++b) {
      long long c0 = m->body_cap[b], c1 = m->body_cap[b + 1];
      if (c0 == c1 || nprim == 0) continue;
      if (pass == 0 && !(X->hint >= 0 && X->hint / nprim == b)) continue;   /* the hint's body first */
      body_bounds(m, s->Wl + 4 * b, b, X->plb);
      for (long long p = 0; p < nprim; ++p) {
        if (!(X->plb[p] < thr)) continue;
        if (pass == 0 && p != X->hint % nprim) continue;
        const double *P = m->prim + RMT_PRIM_STRIDE * p;
        long long kind = m->prim_int[4 * p];
        for (long long c = c0; c < c1; ++c) {
          const wcap *w = s->Cl + c;
          if (kind == RMT_PRIM_SET) {
            long long hit;
            cap_set(m, m->prim_int[4 * p + 2], w, thr, &hit);
            if (hit >= 0) { X->hint = b * nprim + p; return 0; }
            continue;
          }
          if (far_apart(dist2(w->m, P), w->rb + P[3], thr)) continue;
          if (cap_prim(w, P, kind, thr, 0, NULL) < thr) { X->hint = b * nprim + p; return 0; }
        }
      }
    }
    for (long long pr = 0; pr < m->npair; ++pr) {
      if (pass == 0 && X->hint != -1 - pr) continue;
      long long bi = m->pair[2 * pr], bj = m->pair[2 * pr + 1];
      const double *Wi = s->Wl + 4 * bi, *Wj = s->Wl + 4 * bj;
      if (far_apart(dist2(Wi, Wj), Wi[3] + Wj[3], thr)) continue;
      for (long long ci = m->body_cap[bi]; ci < m->body_cap[bi + 1]; ++ci) {
        const wcap *u = s->Cl + ci;
        for (long long cj = m->body_cap[bj]; cj < m->body_cap[bj + 1]; ++cj) {
          const wcap *w = s->Cl + cj;
          if (far_apart(dist2(u->m, w->m), u->rb + w->rb, thr)) continue;
          double sa, tb;
          if (seg_seg(u, w->a, w->d, w->dd, w->idd, &sa, &tb) - u->r - w->r < thr) { X->hint = -1 - pr; return 0; }
        }
      }
    }
  }
  return 1;
}

#endif
