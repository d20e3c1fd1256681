/* Evaluating an instruction table of rmt_generated.h (written by kin/native/graph.py).

   RMT_GRAPH_EVAL(G) expands the tables G_WORK, G_ZEROS and G_CODE into one statement per
   instruction, for lane l of arrays of lane stride ld (element k of lane l at [k*ld + l]): the
   caller declares l and ld and names the input and output arrays as the table does.  Inside
   `#pragma omp simd` over the lanes every statement is a vector operation across configurations. */
#ifndef RMT_GRAPH_H
#define RMT_GRAPH_H
#include <math.h>

#define RMT_G_DECLARE(i) double w##i;
#define RMT_G_ZERO(arr, k) arr[(k)*ld + l] = 0.0;
#define RMT_G_IN(o, arr, k) w##o = arr[(k)*ld + l];
#define RMT_G_OUT(arr, k, i) arr[(k)*ld + l] = w##i;
#define RMT_G_CONST(o, v) w##o = v;
#define RMT_G_OP1(f, o, a) w##o = RMT_OP_##f(w##a);
#define RMT_G_OP2(f, o, a, b) w##o = RMT_OP_##f(w##a, w##b);

#define RMT_GRAPH_EVAL(G) \
  G##_WORK(RMT_G_DECLARE) \
  G##_ZEROS(RMT_G_ZERO) \
  G##_CODE(RMT_G_IN, RMT_G_OUT, RMT_G_CONST, RMT_G_OP1, RMT_G_OP2)

/* the operations (CasADi's OP_* codes of a kinematic chain and its dynamics) */
#define RMT_OP_ADD(x, y) x + y
#define RMT_OP_SUB(x, y) x - y
#define RMT_OP_MUL(x, y) x * y
#define RMT_OP_DIV(x, y) x / y
#define RMT_OP_FMIN(x, y) fmin(x, y)
#define RMT_OP_FMAX(x, y) fmax(x, y)
#define RMT_OP_ATAN2(x, y) atan2(x, y)
#define RMT_OP_POW(x, y) pow(x, y)
#define RMT_OP_COPYSIGN(x, y) copysign(x, y)
#define RMT_OP_ASSIGN(x) x
#define RMT_OP_NEG(x) -x
#define RMT_OP_SQ(x) x * x
#define RMT_OP_TWICE(x) 2.0 * x
#define RMT_OP_INV(x) 1.0 / x
#define RMT_OP_SQRT(x) sqrt(x)
#define RMT_OP_SIN(x) sin(x)
#define RMT_OP_COS(x) cos(x)
#define RMT_OP_TAN(x) tan(x)
#define RMT_OP_FABS(x) fabs(x)
#define RMT_OP_EXP(x) exp(x)
#define RMT_OP_LOG(x) log(x)
#define RMT_OP_ASIN(x) asin(x)
#define RMT_OP_ACOS(x) acos(x)
#define RMT_OP_ATAN(x) atan(x)
/* CasADi's sign: -1, 1, or x itself (0, -0 and NaN pass through) */
#define RMT_OP_SIGN(x) (x < 0 ? -1.0 : x > 0 ? 1.0 : x)

#endif
