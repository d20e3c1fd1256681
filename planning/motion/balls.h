/* Balls against primitives and against each other, eight lanes at once (included by motion.c): the
   vector tests that settle most pairs before any exact (scalar) distance is computed.  Each answers, per
   lane, "may this ball come within thr of that": exact but for rounding, which the callers' SLACK covers,
   so a "no" is a proof.  Results are lane masks (bit l for lane l). */
#ifndef RMT_MOTION_BALLS_H
#define RMT_MOTION_BALLS_H

/* the lanes (bits) where f[l] != 0: one instruction with AVX-512 or AVX2, a loop elsewhere (GCC's own
   code for the loop moves the lanes out one by one) */
RMT_INLINE unsigned pack(const long long *f)
{
#if defined(__AVX512F__)
  __m512i v = _mm512_loadu_si512((const void *)f);
  return (unsigned)_mm512_test_epi64_mask(v, v);
#elif defined(__AVX2__)
  __m256i z = _mm256_setzero_si256(), ones = _mm256_set1_epi64x(-1);
  __m256i a = _mm256_xor_si256(_mm256_cmpeq_epi64(_mm256_loadu_si256((const __m256i *)f), z), ones);
  __m256i b = _mm256_xor_si256(_mm256_cmpeq_epi64(_mm256_loadu_si256((const __m256i *)(f + 4)), z), ones);
  return (unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(a)) | (unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(b)) << 4;
#else
  unsigned bits = 0;
  for (int l = 0; l < LANES; ++l) bits |= (unsigned)(f[l] != 0) << l;
  return bits;
#endif
}

/* the lanes where the ball (c, rad)[l] may come within thr of primitive P of kind `kind` (box,
   cylinder, sphere, capsule): the distance of a point from the solid, in closed form */
RMT_INLINE unsigned ball_prim(const double *P, long long kind, const double *cx, const double *cy, const double *cz,
                              const double *rad, double thr)
{
  long long f[LANES];
  if (kind == RMT_PRIM_BOX || kind == RMT_PRIM_CYLINDER) {
    const double *X = P + 12, *Y = P + 15, *Z = P + 18, *O = P + 21;
    double x0 = X[0], x1 = X[1], x2 = X[2], y0 = Y[0], y1 = Y[1], y2 = Y[2], z0 = Z[0], z1 = Z[1], z2 = Z[2];
    double o0 = O[0], o1 = O[1], o2 = O[2], h0 = P[4], h1 = P[5], h2 = P[6];
    if (kind == RMT_PRIM_BOX) {
      RMT_SIMD
      for (int l = 0; l < LANES; ++l) {
        double vx = cx[l] - o0, vy = cy[l] - o1, vz = cz[l] - o2;
        double qx = fabs(x0 * vx + x1 * vy + x2 * vz) - h0;
        double qy = fabs(y0 * vx + y1 * vy + y2 * vz) - h1;
        double qz = fabs(z0 * vx + z1 * vy + z2 * vz) - h2;
        qx = qx > 0.0 ? qx : 0.0; qy = qy > 0.0 ? qy : 0.0; qz = qz > 0.0 ? qz : 0.0;
        double rr = rad[l] + thr;
        f[l] = !(qx * qx + qy * qy + qz * qz > rr * rr);
      }
    } else {
      RMT_SIMD
      for (int l = 0; l < LANES; ++l) {
        double vx = cx[l] - o0, vy = cy[l] - o1, vz = cz[l] - o2;
        double lx = x0 * vx + x1 * vy + x2 * vz, ly = y0 * vx + y1 * vy + y2 * vz;
        double qr = sqrt(lx * lx + ly * ly) - h0, qz = fabs(z0 * vx + z1 * vy + z2 * vz) - h1;
        qr = qr > 0.0 ? qr : 0.0; qz = qz > 0.0 ? qz : 0.0;
        double rr = rad[l] + thr;
        f[l] = !(qr * qr + qz * qz > rr * rr);
      }
    }
    return pack(f);
  }
  if (kind == RMT_PRIM_SPHERE) {
    double s0 = P[4], s1 = P[5], s2 = P[6], R = P[10] + thr;
    RMT_SIMD
    for (int l = 0; l < LANES; ++l) {
      double vx = cx[l] - s0, vy = cy[l] - s1, vz = cz[l] - s2, rr = rad[l] + R;
      f[l] = !(vx * vx + vy * vy + vz * vz > rr * rr);
    }
    return pack(f);
  }
  /* capsule obstacle: segment P[4..6] .. P[7..9], radius P[10] */
  double s0 = P[4], s1 = P[5], s2 = P[6], ex = P[7] - s0, ey = P[8] - s1, ez = P[9] - s2;
  double ee = ex * ex + ey * ey + ez * ez, ie = ee > 0.0 ? 1.0 / ee : 0.0, R = P[10] + thr;
  RMT_SIMD
  for (int l = 0; l < LANES; ++l) {
    double vx = cx[l] - s0, vy = cy[l] - s1, vz = cz[l] - s2;
    double u = (vx * ex + vy * ey + vz * ez) * ie;
    u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
    double wx = vx - u * ex, wy = vy - u * ey, wz = vz - u * ez, rr = rad[l] + R;
    f[l] = !(wx * wx + wy * wy + wz * wz > rr * rr);
  }
  return pack(f);
}

/* the lanes where the ball (c, rad)[l] may come within thr of primitive P's bounding ball and of its
   world box (both must be near) */
RMT_INLINE unsigned ball_bound(const double *P, const double *cx, const double *cy, const double *cz,
                               const double *rad, double thr)
{
  long long f[LANES];
  const double *B = P + RMT_PRIM_AABB;
  double p0 = P[0], p1 = P[1], p2 = P[2], pr = P[3] + thr, b0 = B[0], b1 = B[1], b2 = B[2];
  double e0 = B[3], e1 = B[4], e2 = B[5];
  RMT_SIMD
  for (int l = 0; l < LANES; ++l) {
    double vx = cx[l] - p0, vy = cy[l] - p1, vz = cz[l] - p2, rr = rad[l] + pr;
    double gx = fabs(cx[l] - b0) - e0, gy = fabs(cy[l] - b1) - e1, gz = fabs(cz[l] - b2) - e2;
    gx = gx > 0.0 ? gx : 0.0; gy = gy > 0.0 ? gy : 0.0; gz = gz > 0.0 ? gz : 0.0;
    double r2 = rad[l] + thr;
    f[l] = (vx * vx + vy * vy + vz * vz <= rr * rr) & (gx * gx + gy * gy + gz * gz <= r2 * r2);
  }
  return pack(f);
}

/* the lanes where the ball (c, rad)[l] comes within `more` of the point (p)[l] (lane-fastest triple p;
   pstride 0: one point for every lane) */
RMT_INLINE unsigned ball_point(const double *cx, const double *cy, const double *cz, const double *rad,
                               const double *p, int pstride, double more)
{
  long long f[LANES];
  const double *px = p, *py = p + (pstride ? LANES : 1), *pz = p + (pstride ? 2 * LANES : 2);
  RMT_SIMD
  for (int l = 0; l < LANES; ++l) {
    int k = pstride ? l : 0;
    double x = cx[l] - px[k], y = cy[l] - py[k], z = cz[l] - pz[k], rr = rad[l] + more;
    f[l] = x * x + y * y + z * z <= rr * rr;
  }
  return pack(f);
}

#endif
