/*
 * heavy_work.c - a small pool of threads with a bounded queue for the
 * requests that build models (heavy_work.h says which and why). It owns
 * the queue and its threads, nothing of HTTP: http.c suspends the
 * connection, hands the request over as a function and an argument, and
 * resumes the connection from that function when the answer is ready.
 *
 * Why bounded and reserved: a queue without a bound would let a client
 * stack up builds without limit; a place is reserved before the connection
 * is suspended, so a full queue is answered 503 on the spot, while the
 * request can still be answered on the thread it arrived on.
 */
#include "heavy_work.h"

#include <pthread.h>
#include <stdio.h>

typedef struct heavy_job {
    heavy_work_fn fn;
    void *arg;
} heavy_job;

static struct {
    pthread_mutex_t lock;
    pthread_cond_t ready;
    pthread_t threads[HEAVY_WORK_THREADS];
    int started;
    heavy_job queue[HEAVY_WORK_QUEUE]; /* a ring: head .. head + queued */
    int head, queued;
    int places;   /* reserved, queued or running */
    int stopping;
} hw = {.lock = PTHREAD_MUTEX_INITIALIZER, .ready = PTHREAD_COND_INITIALIZER};

static void *heavy_work_thread(void *unused)
{
    (void)unused;
    pthread_mutex_lock(&hw.lock);
    for (;;) {
        while (!hw.queued && !hw.stopping)
            pthread_cond_wait(&hw.ready, &hw.lock);
        if (!hw.queued)
            break; /* stopping, and nothing left to run */
        heavy_job job = hw.queue[hw.head];
        hw.head = (hw.head + 1) % HEAVY_WORK_QUEUE;
        hw.queued--;
        pthread_mutex_unlock(&hw.lock);
        job.fn(job.arg);
        pthread_mutex_lock(&hw.lock);
        hw.places--;
    }
    pthread_mutex_unlock(&hw.lock);
    return NULL;
}

int heavy_work_start(void)
{
    for (int i = 0; i < HEAVY_WORK_THREADS; i++) {
        if (pthread_create(&hw.threads[i], NULL, heavy_work_thread, NULL) != 0) {
            fprintf(stderr, "fdemd: cannot start the model-building threads\n");
            heavy_work_stop();
            return -1;
        }
        hw.started++;
    }
    return 0;
}

int heavy_work_reserve(void)
{
    pthread_mutex_lock(&hw.lock);
    int ok = !hw.stopping && hw.started > 0 && hw.places < HEAVY_WORK_QUEUE;
    if (ok)
        hw.places++;
    pthread_mutex_unlock(&hw.lock);
    return ok ? 0 : -1;
}

void heavy_work_submit(heavy_work_fn fn, void *arg)
{
    pthread_mutex_lock(&hw.lock);
    /* a reserved place is never taken back, so the ring has room */
    hw.queue[(hw.head + hw.queued) % HEAVY_WORK_QUEUE] = (heavy_job){fn, arg};
    hw.queued++;
    pthread_cond_signal(&hw.ready);
    pthread_mutex_unlock(&hw.lock);
}

void heavy_work_stop(void)
{
    pthread_mutex_lock(&hw.lock);
    hw.stopping = 1;
    pthread_cond_broadcast(&hw.ready);
    pthread_mutex_unlock(&hw.lock);
    for (int i = 0; i < hw.started; i++)
        pthread_join(hw.threads[i], NULL);
    hw.started = 0;
}
