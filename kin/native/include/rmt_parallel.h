/* The one threading model of rmtkit's kernels: POSIX threads started for a call and joined before
   it returns.

   rmt_parallel_for(n, chunk, nthreads, fn, ctx) calls fn(ctx, begin, end) over [0, n) in ranges
   of `chunk` items, on the calling thread and nthreads - 1 started ones, which take the next range
   from an atomic counter (so a thread the scheduler delays does not hold up the call).  Waiting is
   a blocking join: no thread pool is left spinning to compete with other processes, no OpenMP
   runtime is loaded, and no environment variable plays a part.  The caller decides nthreads (the
   Python side passes RMTKIT_THREADS or the CPUs the process may use, and the kernel caps it by the
   work there is); ranges must be independent.  Returns the number of threads that ran (>= 1). */
#ifndef RMT_PARALLEL_H
#define RMT_PARALLEL_H
#include <pthread.h>
#include "rmt_common.h"

typedef void (*rmt_range_fn)(void* ctx, long long begin, long long end);

typedef struct {
  rmt_range_fn fn;
  void* ctx;
  long long n, chunk, next;
} rmt_parallel_job;

static void* rmt_parallel_worker(void* arg) {
  rmt_parallel_job* job = (rmt_parallel_job*)arg;
  for (;;) {
    long long b0 = __atomic_fetch_add(&job->next, job->chunk, __ATOMIC_RELAXED);
    if (b0 >= job->n) break;
    job->fn(job->ctx, b0, b0 + job->chunk < job->n ? b0 + job->chunk : job->n);
  }
  return NULL;
}

static int rmt_parallel_for(long long n, long long chunk, int nthreads, rmt_range_fn fn, void* ctx) {
  rmt_parallel_job job = { fn, ctx, n, chunk > 0 ? chunk : 1, 0 };
  if (nthreads < 1) nthreads = 1;
  if (nthreads > RMT_MAX_THREADS) nthreads = RMT_MAX_THREADS;
  pthread_t tid[RMT_MAX_THREADS];
  int started = 0;
  for (int t = 1; t < nthreads; ++t) {
    if (pthread_create(&tid[started], NULL, rmt_parallel_worker, &job) != 0) break;
    ++started;
  }
  rmt_parallel_worker(&job);
  for (int t = 0; t < started; ++t) pthread_join(tid[t], NULL);
  return started + 1;
}

#endif
