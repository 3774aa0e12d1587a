#include "parallel.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>
#if defined(__SSE__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif

typedef struct pool {
    uint32_t count, block;
    vb_parallel_fn fn;
    void *ctx;
    _Atomic uint32_t next, done;
    _Atomic unsigned worker_id;
    int running; /* under lock */
    pthread_mutex_t lock;
    pthread_cond_t cond;
} pool;

unsigned vb_parallel_threads(unsigned threads)
{
    if (threads == 0) {
        long nc = sysconf(_SC_NPROCESSORS_ONLN);
        threads = nc > 0 ? (unsigned)nc : 1;
    }
    return threads > 256 ? 256 : threads;
}

static void *worker(void *arg)
{
    pool *P = arg;
#if defined(__SSE__)
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
    unsigned me = atomic_fetch_add(&P->worker_id, 1);
    for (;;) {
        uint32_t a = atomic_fetch_add(&P->next, P->block);
        if (a >= P->count)
            break;
        uint32_t b = P->count - a > P->block ? a + P->block : P->count;
        P->fn(P->ctx, a, b, me);
        atomic_fetch_add(&P->done, b - a);
    }
    pthread_mutex_lock(&P->lock);
    P->running--;
    pthread_cond_signal(&P->cond);
    pthread_mutex_unlock(&P->lock);
    return NULL;
}

unsigned vb_parallel_for(unsigned threads, uint32_t count, uint32_t block, vb_parallel_fn fn,
                         void *ctx, vb_parallel_progress progress, void *user)
{
    threads = vb_parallel_threads(threads);
    pool P = {.count = count, .block = block ? block : 1, .fn = fn, .ctx = ctx};
    pthread_t *th = calloc(threads, sizeof *th);
    if (!th)
        return 0;
    pthread_mutex_init(&P.lock, NULL);
    pthread_cond_init(&P.cond, NULL);
    unsigned started = 0;
    pthread_mutex_lock(&P.lock);
    for (; started < threads; started++) {
        if (pthread_create(&th[started], NULL, worker, &P) != 0)
            break;
        P.running++;
    }
    while (P.running > 0) {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_nsec += 200000000L;
        if (ts.tv_nsec >= 1000000000L) {
            ts.tv_sec++;
            ts.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&P.cond, &P.lock, &ts);
        if (progress && P.running > 0) {
            pthread_mutex_unlock(&P.lock);
            progress(user, atomic_load(&P.done), count);
            pthread_mutex_lock(&P.lock);
        }
    }
    pthread_mutex_unlock(&P.lock);
    for (unsigned i = 0; i < started; i++)
        pthread_join(th[i], NULL);
    if (progress && started > 0)
        progress(user, count, count);
    pthread_cond_destroy(&P.cond);
    pthread_mutex_destroy(&P.lock);
    free(th);
    return started;
}
