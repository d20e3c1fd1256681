/* A small kernel for the tests of kin.native (tests/kin/native/test_builder.py): a constant from the
   generated header, and a sum spread over rmt_parallel_for. */
#include "rmt_generated.h"
#include "rmt_common.h"
#include "rmt_parallel.h"

int rmt_probe_value(void) { return PROBE_VALUE; }

static void rmt_probe_add(void* ctx, long long begin, long long end) {
  long long s = 0;
  for (long long i = begin; i < end; ++i) s += i;
  __atomic_fetch_add((long long*)ctx, s, __ATOMIC_RELAXED);
}

/* 0 + 1 + ... + (n - 1) over nthreads threads; *ran: the threads that ran */
long long rmt_probe_sum(long long n, int nthreads, int* ran) {
  long long s = 0;
  *ran = rmt_parallel_for(n, 7, nthreads, rmt_probe_add, &s);
  return s;
}
