/* The motion checker's data (motion.c includes this after the clearance kernel, clearance.c, whose model,
   rmt_clear_model of clearance.h, it reads): a block of eight placed states, the checker with its
   per-motion bounds and scratch blocks, a check's result.

   Groups: each body's capsules are split by planning/motion/checker.py into a few groups of nearby
   capsules, each inside a ball (centre in the body's frame, radius) — a hierarchy body ball → group
   balls → capsules, as VAMP's coarse spheres are, so that most pairs are settled by a few ball tests. */
#ifndef RMT_MOTION_TYPES_H
#define RMT_MOTION_TYPES_H

#define SLACK 1e-9        /* m added to every swept radius: the placed points' rounding is ~1e-15 m */
#define MAX_DEPTH_CAP 12  /* eightfold cuts of an interval at most (8^-12 of it) */
#define ALL_LANES ((1u << LANES) - 1u)
#define STRIPS (LANES - 1)          /* the first block's states cut a motion into seven strips */
#define STRIP_LANES ((1u << STRIPS) - 1u)
#define MAX_JOINTS 63

/* outcome of a check (status) */
#define RMT_MOTION_CLEAR 1        /* proven valid */
#define RMT_MOTION_COLLISION 0    /* a state not clear by the margin at parameter t */
#define RMT_MOTION_UNPROVEN -1    /* neither proven nor refuted within the depth and evaluation budget */
#define RMT_MOTION_BAD -2         /* a non-finite value, a prismatic value beyond its bound */
#define RMT_MOTION_LIMITS 2       /* an end outside the joint limits */
#define RMT_MOTION_WINDOW 3       /* a state inside an interval window (t: where the motion enters it) */

typedef struct {          /* LANES placed states, lane fastest */
  double *F;              /* nbody × 12 × LANES: frames (clearance.c's frames()) */
  double *cs;             /* n × 2 × LANES: their cosines and sines */
  double *A;              /* ncap × 6 × LANES: each capsule's segment start a and direction d (world) */
  double *W;              /* nbody × 3 × LANES: each body's ball centre (world) */
  double *G;              /* ngroup × 3 × LANES: each group's ball centre (world) */
  double t[LANES];        /* the motion parameter of each lane */
} block;

typedef struct {
  const rmt_clear_model *m;  /* the robot and its cell; NULL: limits and windows only */
  long long n;
  double margin;             /* m: the clearance a state needs */
  const double *lower, *upper;   /* n: joint limits */
  const double *R;           /* ncap × n: capsule_radii, in the kernel's capsule order */
  const double *Rb;          /* (nbody + ngroup) × n: the same for every point of each body's, then group's, ball */
  const long long *revolute; /* n: 1 revolute, 0 prismatic */
  long long nwin;
  const double *win;         /* nwin × 3: joint index, lo, hi */
  long long ngroup;
  const long long *gbeg;     /* nbody + 1: body b's groups are gbeg[b] … gbeg[b + 1] − 1 */
  const long long *cbeg;     /* ngroup + 1: group g's capsules are gcap[cbeg[g]] … gcap[cbeg[g + 1] − 1] */
  const long long *gcap;     /* ncap: capsule indices, group by group */
  const double *gball;       /* ngroup × 4: each group's ball (centre in its body's frame, radius) */
  double step;               /* m: the largest first-order displacement between consecutive states */
  double cap;                /* m: bound mode measures clearances up to this (the model's cap) */
  long long max_states;      /* most states placed in a motion's first pass */
  int max_depth;             /* eightfold cuts of an interval */
  long long max_evals;       /* most states placed for one motion, refinement included */
  int ordered;               /* the current check's mode */
  double tnext;              /* the double after the margin (a distance below it is not clear) */
  long long hint;            /* the pair that collided last (code_lanes' code), or NO_HINT */
  unsigned long long placed; /* the bodies place_soa places (bit b: body b) */
  long long calls;           /* motions the extension's motion() has checked (a planner's budget) */
  /* per motion (motion_bounds) */
  double *Mc;                /* ncap: curvature bound of the capsules' points (world) */
  double *Mrel;              /* ncap × nbody: curvature bound in each body's frame */
  double *Mb, *Lb;           /* nball = nbody + ngroup: the same for the balls (world) */
  double *Mbrel, *Lbrel;     /* nball × nbody: ... in each body's frame */
  unsigned *pmask;           /* npair: the strips (lanes) where a body pair is not proven from its ends */
  unsigned *omask;           /* nbody × nprim: the same for a body against a primitive */
  double *plb;               /* nprim4: a body's bounds against every primitive */
  unsigned char *okp;        /* nprim: scratch */
  wcap *local;               /* ncap: every capsule in its own body's frame */
  double *gchord, *cchord;   /* ngroup, ncap × 4 × LANES: chord balls of one interval test */
  unsigned char *made;       /* ncap: which capsules' chord balls are made */
  block blk[3];              /* the first block, and two alternating */
  block *deep;               /* 2 × (max_depth + 1): refinement, two per depth */
  block one;                 /* a single state (refinement's spare) */
  scratch ss;                /* clearance.c's scratch for one configuration (the state check) */
  double *ssbuf;
  double *mem;
} rmt_motion;

typedef struct {
  int status;
  double t;                  /* where a violation was found (collision, window; unproven: the open piece's start) */
  long long evals;           /* states placed */
  long long states;          /* states of the first pass */
  double bound;              /* bound mode: a lower bound of the clearance along the motion when proven */
} rmt_motion_result;

#endif
