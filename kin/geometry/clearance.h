/* The model the clearance kernel (clearance.c) reads: a robot's DH rows and capsules and a cell's
   obstacles, flattened by kin/geometry/clearance.py (class _Model there mirrors this struct field by
   field; change both together).  Every length in metres, every pose a rigid transform stored as its
   columns x, y, z, origin (12 doubles).  Bodies: 0 base, 1 … n the DH frames, n + 1 the tool. */
#ifndef RMT_CLEARANCE_H
#define RMT_CLEARANCE_H

/* obstacle primitive kinds (prim_int[4 k]) */
#define RMT_PRIM_SPHERE 0     /* centre prim[4..6], radius prim[10] */
#define RMT_PRIM_CAPSULE 1    /* segment prim[4..6] .. prim[7..9], radius prim[10] */
#define RMT_PRIM_BOX 2        /* pose prim[12..23] (columns), half sizes prim[4..6] */
#define RMT_PRIM_CYLINDER 3   /* pose prim[12..23] (columns), radius prim[4], half length prim[5] */
#define RMT_PRIM_SET 4        /* spheres under BVH node prim_int[4 k + 2] */
#define RMT_PRIM_STRIDE 32    /* doubles per primitive; prim[0..3]: bounding sphere (centre, radius) */
#define RMT_PRIM_AABB 24      /* prim[24..29]: a box holding it, axis-aligned in the world (centre, half sizes) */
#define RMT_CAP_STRIDE 12     /* doubles per capsule */
#define RMT_NODE_STRIDE 10    /* doubles per BVH node: ball (centre, radius), box (centre, half sizes) */

/* output modes of rmt_clearance */
#define RMT_MODE_MIN 0        /* the minimum per configuration */
#define RMT_MODE_NEAREST 1    /* ... with the body, the other party and the witness points */
#define RMT_MODE_PER_BODY 2   /* per body: the minimum against obstacles and against other bodies */

typedef struct {
  long long n;                /* joints */
  long long modified;         /* 1: modified DH (Craig), 0: standard */
  long long nbody;            /* n + 2 */
  long long last;             /* the highest body holding a capsule: frames beyond it are not computed */
  long long ncap, nprim, npair, nnode, nsphere;
  long long nprim4;           /* nprim rounded up to a multiple of 4 (the SoA arrays' length) */
  long long nset;             /* primitives that are sphere sets */
  const double *dh;           /* n × 8: a, cos α, sin α, d, θ, prismatic (0/1), largest |q| (C checks
                                 one configuration against it), 0 */
  const double *base;         /* 12: frame 0 in the world */
  const double *tool;         /* 12: the tool frame in frame n */
  const double *cap;          /* ncap × RMT_CAP_STRIDE: a (3), b (3) in the body frame, radius, |b − a|²,
                                 1/|b − a|² (0 for a ball), |b − a|/2 + radius + 1e-12 (its ball), 0, 0;
                                 sorted by body */
  const long long *body_cap;  /* nbody + 1: body k holds capsules body_cap[k] … body_cap[k + 1] − 1 */
  const double *body_sphere;  /* nbody × 4: a ball holding the body's capsules (centre in its frame, radius) */
  const long long *prim_int;  /* nprim × 4: kind, obstacle index, BVH root (sets), ignored bodies (bit mask) */
  const double *prim;         /* nprim × RMT_PRIM_STRIDE, in the world */
  const double *prim_soa;     /* 10 × nprim4: bounding ball x, y, z, radius, box centre x, y, z, half
                                 sizes x, y, z (a copy of prim[0..3], prim[24..29] for SIMD) */
  const long long *prim_ignore;  /* nprim4: ignored bodies (bit mask; all bits set past nprim) */
  const long long *pair;      /* npair × 2: body pairs (i < j) checked against each other */
  const double *node;         /* nnode × RMT_NODE_STRIDE: BVH nodes' balls (centre, radius) and boxes
                                 (axis-aligned: centre, half sizes), each holding the node's spheres */
  const long long *link;      /* nnode × 2: (left, right) children, or (first sphere, −count) for a leaf */
  const double *sphere;       /* nsphere × 4: x, y, z, radius, in leaf order */
} rmt_clear_model;

#endif
