/* rmtkit compiled IK: the Levenberg-Marquardt solver of kin/ik/compiled.py, around the chain's FK
   and Jacobian.  Specialised by rmt_generated.h: RMT_N joints and the graph of (q, p) -> (T, J)
   as the instruction table RMT_GRAPH (kin/native/graph.py).

   One start is a Levenberg-Marquardt (damped least squares) iteration on the weighted pose error
   e = [p* - p(q); w log(R* R(q)^T)] (the error of kin/ik/numeric.py; position rows only in position
   mode): (J^T J + lambda diag(J^T J) + lambda 1e-6 I) dq = J^T e solved by Cholesky.  Joints at a
   limit whose step points outwards are held there and the step is solved again for the others (an
   active set); the step is then projected onto the limits and kept only when it lowers |e|^2
   (lambda / 3), otherwise lambda * 6.  A start ends when |e|^2 <= tol_cost (far inside the success
   tolerances), when lambda exceeds 1e8, after max_iter iterations, or when it stagnates: it has not
   succeeded and its cost is still above STAG_RATIO times the cost of STAG_EVERY iterations before.

   A target tries its starts in order - the warm start q0 when given, then random configurations
   uniform within the limits, drawn from a splitmix64 stream keyed by the seed, the target's values
   and the start index (so the answer depends neither on threads, nor on the other targets of a
   batch, nor on the target's place in it) - and stops at the first start that succeeds.  There is
   no "home" start: the zero configuration of many arms is singular, and a start there stays on the
   singular branch.  A target beyond the chain's reach bound (kin.ik.compiled.ReachBound) gets
   BEYOND_STARTS starts only, which look for the configuration nearest the target; other unreachable
   targets cost their max_starts starts, each cut short by the stagnation test.  When no start
   succeeds, the best one is iterated on without the stagnation test (up to max_iter more
   iterations), so that the reported residual is that of the local minimum.

   Success means: position error <= tol_position and orientation error <= tol_orientation, measured
   at the returned configuration by the same FK that drove the iteration; the configuration is
   inside the limits by construction.

   Threads: the targets of a batch are spread over rmt_parallel_for (POSIX threads for the call, 4
   targets at a time; one thread below 8 targets). */
#include "rmt_generated.h"
#include "rmt_common.h"
#include "rmt_graph.h"
#include "rmt_parallel.h"

#define STAG_EVERY 5
#define STAG_RATIO 0.8
#define BEYOND_STARTS 8
#define RMTIK_CHUNK 4

/* T (4x4) and J (6xn), column-major, at q with parameters p */
static void rmtik_fk(const double* q, const double* p, double* T, double* J) {
  const int ld = 1, l = 0;
  (void)q; (void)p;
  RMT_GRAPH_EVAL(RMT_GRAPH)
}

/* rotation vector of Re (row-major 3×3 rotation), as kin.transforms.log_so3 */
static void rmtik_log(const double* Re, double* out) {
  double vx = Re[7] - Re[5], vy = Re[2] - Re[6], vz = Re[3] - Re[1];
  double c = 0.5 * (Re[0] + Re[4] + Re[8] - 1.0);
  if (c > 1.0) c = 1.0;
  if (c < -1.0) c = -1.0;
  double s = 0.5 * sqrt(vx*vx + vy*vy + vz*vz);
  double ang = atan2(s, c);
  if (s >= 1e-7) {
    double k = ang / (2.0 * s);
    out[0] = vx * k; out[1] = vy * k; out[2] = vz * k;
  } else if (c >= 0) {
    out[0] = 0.5 * vx; out[1] = 0.5 * vy; out[2] = 0.5 * vz;
  } else {  /* angle near pi: axis from the symmetric part B = (Re + I)/2 = a·aᵀ */
    double B[9];
    for (int i = 0; i < 9; ++i) B[i] = 0.5 * Re[i];
    B[0] += 0.5; B[4] += 0.5; B[8] += 0.5;
    int k = 0;
    if (B[4] > B[k*4]) k = 1;
    if (B[8] > B[k*4]) k = 2;
    double d = sqrt(B[k*4] > 1e-300 ? B[k*4] : 1e-300);
    double a0 = B[0*3+k] / d, a1 = B[1*3+k] / d, a2 = B[2*3+k] / d;
    double nn = sqrt(a0*a0 + a1*a1 + a2*a2);
    a0 /= nn; a1 /= nn; a2 /= nn;
    double sg = (a0*vx + a1*vy + a2*vz) < 0 ? -1.0 : 1.0;
    out[0] = a0 * ang * sg; out[1] = a1 * ang * sg; out[2] = a2 * ang * sg;
  }
}

typedef struct {
  const double* lo; const double* hi;
  int pose;            /* 1: six rows, 0: position rows only */
  double w;            /* length weighing radians against metres */
  double tol_p, tol_o, tol_cost;
  int max_iter;
  int stag;            /* 1: end a start when it stagnates */
} rmtik_opts;

/* error e (m rows) and weighted Jacobian Jw (m×n row-major) at q; returns cost, sets pe, oe */
static double rmtik_residual(const rmtik_opts* o, const double* q, const double* p, const double* pt,
                             const double* Rt, double* e, double* Jw, double* pe, double* oe) {
  double T[16], J[6 * RMT_N];                       /* column-major */
  rmtik_fk(q, p, T, J);
  e[0] = pt[0] - T[12]; e[1] = pt[1] - T[13]; e[2] = pt[2] - T[14];
  double s2 = e[0]*e[0] + e[1]*e[1] + e[2]*e[2];
  /* beyond ~1e154 m the squares overflow (the cost is then +inf and no step is taken): the
     position error itself is still reported, without overflow */
  *pe = s2 < INFINITY ? sqrt(s2) : hypot(hypot(e[0], e[1]), e[2]);
  for (int r = 0; r < 3; ++r) for (int c = 0; c < RMT_N; ++c) Jw[r*RMT_N + c] = J[c*6 + r];
  if (!o->pose) { *oe = 0.0; return e[0]*e[0] + e[1]*e[1] + e[2]*e[2]; }
  double Re[9];                                      /* Rt · Rᵀ, row-major; R(i,j) = T[j*4 + i] */
  for (int i = 0; i < 3; ++i) for (int j = 0; j < 3; ++j)
    Re[i*3 + j] = Rt[i*3 + 0] * T[0*4 + j] + Rt[i*3 + 1] * T[1*4 + j] + Rt[i*3 + 2] * T[2*4 + j];
  double v[3];
  rmtik_log(Re, v);
  *oe = sqrt(v[0]*v[0] + v[1]*v[1] + v[2]*v[2]);
  for (int r = 0; r < 3; ++r) {
    e[3 + r] = o->w * v[r];
    for (int c = 0; c < RMT_N; ++c) Jw[(3 + r)*RMT_N + c] = o->w * J[c*6 + 3 + r];
  }
  double cost = 0;
  for (int r = 0; r < 6; ++r) cost += e[r] * e[r];
  return cost;
}

/* solve A x = b, A n×n symmetric positive definite (destroyed); 0 when not positive definite */
static int rmtik_chol(double* A, double* b) {
  for (int j = 0; j < RMT_N; ++j) {
    double d = A[j*RMT_N + j];
    for (int k = 0; k < j; ++k) d -= A[j*RMT_N + k] * A[j*RMT_N + k];
    if (!(d > 0)) return 0;
    d = sqrt(d);
    A[j*RMT_N + j] = d;
    for (int i = j + 1; i < RMT_N; ++i) {
      double s = A[i*RMT_N + j];
      for (int k = 0; k < j; ++k) s -= A[i*RMT_N + k] * A[j*RMT_N + k];
      A[i*RMT_N + j] = s / d;
    }
  }
  for (int i = 0; i < RMT_N; ++i) {
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= A[i*RMT_N + k] * b[k];
    b[i] = s / A[i*RMT_N + i];
  }
  for (int i = RMT_N - 1; i >= 0; --i) {
    double s = b[i];
    for (int k = i + 1; k < RMT_N; ++k) s -= A[k*RMT_N + i] * b[k];
    b[i] = s / A[i*RMT_N + i];
  }
  return 1;
}

/* one start: iterate q (in/out, inside the limits) towards the target; returns iterations */
static int rmtik_run(const rmtik_opts* o, const double* p, const double* pt, const double* Rt, double* q,
                     double* pe, double* oe) {
  const int m = o->pose ? 6 : 3;
  double e[6], Jw[6 * RMT_N], en[6], Jn[6 * RMT_N], qn[RMT_N], A[RMT_N * RMT_N], g[RMT_N], step[RMT_N];
  double pen, oen;
  double cost = rmtik_residual(o, q, p, pt, Rt, e, Jw, pe, oe);
  double lam = 1e-3, ref = cost;
  int it = 0;
  while (it < o->max_iter && cost > o->tol_cost) {
    ++it;
    for (int i = 0; i < RMT_N; ++i) {
      double s = 0;
      for (int r = 0; r < m; ++r) s += Jw[r*RMT_N + i] * e[r];
      g[i] = s;
      for (int j = 0; j <= i; ++j) {
        double a = 0;
        for (int r = 0; r < m; ++r) a += Jw[r*RMT_N + i] * Jw[r*RMT_N + j];
        A[i*RMT_N + j] = a; A[j*RMT_N + i] = a;
      }
    }
    for (int i = 0; i < RMT_N; ++i) A[i*RMT_N + i] += lam * (A[i*RMT_N + i] + 1e-6);
    /* joints at a limit whose step points outwards are held there and the step is solved again
       for the others (an active set): a projected full step would stall against the limit */
    int fixed[RMT_N] = {0}, ok = 0;
    for (int pass = 0; pass <= RMT_N; ++pass) {
      double Af[RMT_N * RMT_N];
      memcpy(Af, A, sizeof Af);
      memcpy(step, g, sizeof step);
      for (int i = 0; i < RMT_N; ++i) if (fixed[i]) {
        for (int j = 0; j < RMT_N; ++j) { Af[i*RMT_N + j] = 0; Af[j*RMT_N + i] = 0; }
        Af[i*RMT_N + i] = 1; step[i] = 0;
      }
      ok = rmtik_chol(Af, step);
      if (!ok) break;
      int more = 0;
      for (int i = 0; i < RMT_N; ++i)
        if (!fixed[i] && ((q[i] <= o->lo[i] && step[i] < 0) || (q[i] >= o->hi[i] && step[i] > 0))) { fixed[i] = 1; more = 1; }
      if (!more) break;
    }
    double cn = INFINITY;
    if (ok) {
      for (int i = 0; i < RMT_N; ++i) {
        double v = q[i] + step[i];
        qn[i] = v < o->lo[i] ? o->lo[i] : (v > o->hi[i] ? o->hi[i] : v);
      }
      cn = rmtik_residual(o, qn, p, pt, Rt, en, Jn, &pen, &oen);
    }
    if (cn < cost) {
      memcpy(q, qn, sizeof qn); memcpy(e, en, sizeof en); memcpy(Jw, Jn, sizeof Jn);
      cost = cn; *pe = pen; *oe = oen;
      lam = lam / 3.0 > 1e-9 ? lam / 3.0 : 1e-9;
    } else {
      lam *= 6.0;
      if (lam > 1e8) break;
    }
    if (o->stag && it % STAG_EVERY == 0) {
      if (cost > STAG_RATIO * ref && !(*pe <= o->tol_p && *oe <= o->tol_o)) break;   /* stagnated */
      ref = cost;
    }
  }
  return it;
}

static uint64_t rmtik_mix(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/* 1 when the target is certainly out of reach (see kin.ik.compiled.ReachBound for the constants rb) */
static int rmtik_beyond(const double* rb, const double* pt, const double* Rt) {
  const double *Bi = rb, *Ti = rb + 46;
  double P[3], bound, rest;
  if (!Rt || !(rb[38] > 0)) {
    for (int i = 0; i < 3; ++i) P[i] = Bi[i*4] * pt[0] + Bi[i*4 + 1] * pt[1] + Bi[i*4 + 2] * pt[2] + Bi[i*4 + 3];
    bound = rb[32]; rest = rb[44];
  } else {
    double X[16] = { Rt[0], Rt[1], Rt[2], pt[0], Rt[3], Rt[4], Rt[5], pt[1], Rt[6], Rt[7], Rt[8], pt[2], 0, 0, 0, 1 };
    double Y[16], M[16];
    for (int i = 0; i < 4; ++i) for (int j = 0; j < 4; ++j) {
      double s = 0; for (int k = 0; k < 4; ++k) s += Bi[i*4 + k] * X[k*4 + j]; Y[i*4 + j] = s; }
    for (int i = 0; i < 4; ++i) for (int j = 0; j < 4; ++j) {
      double s = 0; for (int k = 0; k < 4; ++k) s += Y[i*4 + k] * Ti[k*4 + j]; M[i*4 + j] = s; }
    const double a = rb[39], d = rb[43], *zl = rb + 40;
    for (int i = 0; i < 3; ++i)
      P[i] = M[i*4 + 3] - a * M[i*4] - d * (M[i*4] * zl[0] + M[i*4 + 1] * zl[1] + M[i*4 + 2] * zl[2]);
    bound = rb[33]; rest = rb[45];
  }
  if (sqrt(P[0]*P[0] + P[1]*P[1] + P[2]*P[2]) > bound * (1 + 1e-9) + 1e-12) return 1;
  if (rb[37] > 0) {
    double rho = sqrt(P[0]*P[0] + P[1]*P[1]);
    double dr = rho - rb[35], dz = P[2] - rb[36];
    if (sqrt(dr*dr + dz*dz) > rest * (1 + 1e-9) + 1e-12) return 1;
  }
  return 0;
}

/* the reach test alone, for N targets (out: N flags) */
void rmtik_beyond_batch(const double* rb, const double* pt, const double* Rt, long long N, unsigned char* out) {
  for (long long t = 0; t < N; ++t) out[t] = (unsigned char)rmtik_beyond(rb, pt + 3*t, Rt ? Rt + 9*t : NULL);
}

/* A batch call's arguments (see rmtik_solve) and its count of successes. */
typedef struct {
  const double *pt, *Rt, *p; long long pstride;
  const double* q0; long long q0stride;
  const double *lo, *hi, *rb;
  int max_starts; uint64_t seed; double w, tol_p, tol_o;
  rmtik_opts o;
  double *q, *pe, *oe; int *status, *starts, *iters;
  long long solved;
} rmtik_batch;

/* Solve target t of the batch B; returns 1 on success. */
static int rmtik_target(const rmtik_batch* B, long long t) {
  const double *lo = B->lo, *hi = B->hi;
  const double w = B->w;
  const double* pp = B->p + t * B->pstride;
  const double* tp = B->pt + 3*t;
  const double* tR = B->Rt ? B->Rt + 9*t : NULL;
  double best[RMT_N], bpe = INFINITY, boe = INFINITY, bres = INFINITY, cur[RMT_N], cpe, coe;
  int ok = 0, k = 0, total = 0;
  uint64_t key = rmtik_mix(B->seed);             /* the random starts depend on the seed and the target's values */
  for (int i = 0; i < (tR ? 12 : 3); ++i) {
    uint64_t bits;
    memcpy(&bits, i < 3 ? tp + i : tR + (i - 3), sizeof bits);
    key = rmtik_mix(key ^ bits);
  }
  int limit = (B->rb && rmtik_beyond(B->rb, tp, tR) && B->max_starts > BEYOND_STARTS) ? BEYOND_STARTS : B->max_starts;
  for (k = 0; k < limit && !ok; ++k) {
    if (k == 0 && B->q0) {
      for (int i = 0; i < RMT_N; ++i) {
        double v = B->q0[t*B->q0stride + i];
        cur[i] = v < lo[i] ? lo[i] : (v > hi[i] ? hi[i] : v);
      }
    } else {
      uint64_t s = rmtik_mix(key + (uint64_t)k);
      for (int i = 0; i < RMT_N; ++i) {
        s = rmtik_mix(s);
        double u = (double)(s >> 11) * 0x1.0p-53;
        cur[i] = lo[i] + u * (hi[i] - lo[i]);
      }
    }
    total += rmtik_run(&B->o, pp, tp, tR, cur, &cpe, &coe);
    ok = cpe <= B->tol_p && coe <= B->tol_o;
    double res = cpe + coe * w;
    /* the first start is always kept: best is defined even when no residual is finite (a target
       so far away that its error overflows) */
    if (k == 0 || ok || res < bres) {
      memcpy(best, cur, sizeof cur); bpe = cpe; boe = coe; bres = res == res ? res : INFINITY;
    }
  }
  if (!ok && bres < INFINITY) {   /* out of reach (or not found): settle the best start into its minimum */
    rmtik_opts os = B->o;
    os.stag = 0;
    memcpy(cur, best, sizeof best);
    total += rmtik_run(&os, pp, tp, tR, cur, &cpe, &coe);
    ok = cpe <= B->tol_p && coe <= B->tol_o;
    if (ok || cpe + coe * w < bres) { memcpy(best, cur, sizeof cur); bpe = cpe; boe = coe; }
  }
  memcpy(B->q + t*RMT_N, best, sizeof best);
  B->pe[t] = bpe; B->oe[t] = boe; B->status[t] = ok; B->starts[t] = k; B->iters[t] = total;
  return ok;
}

/* Targets [t0, t1) of the batch ctx (an rmtik_batch), on one thread. */
static void rmtik_targets(void* ctx, long long t0, long long t1) {
  rmtik_batch* B = (rmtik_batch*)ctx;
  long long ok = 0;
  for (long long t = t0; t < t1; ++t) ok += rmtik_target(B, t);
  __atomic_fetch_add(&B->solved, ok, __ATOMIC_RELAXED);
}

/* Solve a batch of targets.
   pt: N x 3 positions; Rt: N x 3 x 3 rotations (row-major; NULL in position mode); p: parameters,
   advanced by pstride per target; q0: warm starts advanced by q0stride per target (NULL: none);
   lo, hi: limits; rb: reach-bound constants (NULL: no reach test); nthreads: threads (>= 1);
   out: q N x n, pe, oe (N), status N (1 success, 0 not), starts N (starts used), iters N.
   Returns the number of successes. */
int rmtik_solve(const double* pt, const double* Rt, const double* p, long long pstride,
                const double* q0, long long q0stride, const double* lo, const double* hi,
                const double* rb, long long N, int pose, double w, double tol_p, double tol_o,
                double tol_cost, int max_iter, int max_starts, unsigned long long seed, int nthreads,
                double* q, double* pe, double* oe, int* status, int* starts, int* iters) {
  rmtik_batch B = { pt, Rt, p, pstride, q0, q0stride, lo, hi, rb, max_starts, seed, w, tol_p, tol_o,
                    { lo, hi, pose, w, tol_p, tol_o, tol_cost, max_iter, 1 },
                    q, pe, oe, status, starts, iters, 0 };
  long long chunks = (N + RMTIK_CHUNK - 1) / RMTIK_CHUNK;
  if (N < 8) nthreads = 1;
  if (nthreads > chunks) nthreads = (int)chunks;
  rmt_parallel_for(N, RMTIK_CHUNK, nthreads, rmtik_targets, &B);
  return (int)B.solved;
}
