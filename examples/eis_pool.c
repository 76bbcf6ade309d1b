/* The live examples' worker pool: see eis_pool.h. One mutex guards the job; the workers read
 * the job's fields outside it, which stay unchanged until its last band is counted. */
#define _DEFAULT_SOURCE
#include "eis_pool.h"
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

typedef struct pool_job {
    double warp[9];
    home_stab_image src, dst;
    int bands, next_band, bands_done, status;
    eis_pool_done_fn done;
    void *user;
    long tag;
    double t_start;                /* the first band's start */
} pool_job;

struct eis_pool {
    int threads, workers_started;
    pthread_t workers[EIS_POOL_MAX_THREADS];
    pthread_mutex_t lock;
    pthread_cond_t work;           /* to the workers: bands to take, or stop */
    pthread_cond_t idle;           /* to the callers: the job is done */
    int busy, stop, status;        /* status: the last finished job's, until reported */
    pool_job job;
};

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

int eis_pool_auto_threads(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > EIS_POOL_AUTO_MAX ? EIS_POOL_AUTO_MAX : (int)n;
}

/* Rows of band k of n: even edges (4:2:0 chroma rows), the last band to the end. */
static void band_rows(int height, int k, int n, int *first, int *rows)
{
    const int a = (int)((long)height * k / n) & ~1;
    const int b = k + 1 == n ? height : (int)((long)height * (k + 1) / n) & ~1;
    *first = a;
    *rows = b - a;
}

/* Take and warp the job's bands until none is left; the one who counts the last band runs done()
 * and ends the job. Called and returns with the lock held. */
static void run_bands(eis_pool *p)
{
    pool_job *j = &p->job;
    while (p->busy && j->next_band < j->bands) {
        const int k = j->next_band++;
        int first, rows, st = HOME_OK;
        if (k == 0) j->t_start = now_ms();
        pthread_mutex_unlock(&p->lock);
        band_rows(j->dst.height, k, j->bands, &first, &rows);
        if (rows > 0) st = home_stab_warp_rows(j->warp, &j->src, &j->dst, first, rows);
        pthread_mutex_lock(&p->lock);
        if (st != HOME_OK && j->status == HOME_OK) j->status = st;
        if (++j->bands_done == j->bands) {
            if (j->done && j->status == HOME_OK) {
                const double ms = now_ms() - j->t_start;
                int bad;
                pthread_mutex_unlock(&p->lock);   /* busy stays set: nothing else starts */
                bad = j->done(j->user, j->tag, ms);
                pthread_mutex_lock(&p->lock);
                if (bad) j->status = EIS_POOL_E_DONE;
            }
            p->status = j->status;
            p->busy = 0;
            pthread_cond_broadcast(&p->idle);
        }
    }
}

static void *worker_main(void *arg)
{
    eis_pool *p = arg;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (!p->stop && !(p->busy && p->job.next_band < p->job.bands)) pthread_cond_wait(&p->work, &p->lock);
        if (p->stop) break;   /* stop is set only while no job is in flight */
        run_bands(p);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

int eis_pool_start(eis_pool **pool, int threads)
{
    eis_pool *p;
    int i;
    *pool = NULL;
    if (threads == 0) threads = eis_pool_auto_threads();
    if (threads < 1 || threads > EIS_POOL_MAX_THREADS || !(p = calloc(1, sizeof *p))) return -1;
    p->threads = threads;
    p->status = HOME_OK;
    if (pthread_mutex_init(&p->lock, NULL)) { free(p); return -1; }
    if (pthread_cond_init(&p->work, NULL)) { pthread_mutex_destroy(&p->lock); free(p); return -1; }
    if (pthread_cond_init(&p->idle, NULL)) {
        pthread_cond_destroy(&p->work);
        pthread_mutex_destroy(&p->lock);
        free(p);
        return -1;
    }
    for (i = 0; i + 1 < threads; i++) {
        if (pthread_create(&p->workers[i], NULL, worker_main, p)) { eis_pool_stop(p); return -1; }
        p->workers_started++;
    }
    *pool = p;
    return 0;
}

int eis_pool_threads(const eis_pool *pool) { return pool->threads; }

/* Wait (lock held) until no job is in flight; its status, reported once. */
static int wait_idle(eis_pool *p)
{
    int st;
    while (p->busy) pthread_cond_wait(&p->idle, &p->lock);
    st = p->status;
    p->status = HOME_OK;
    return st;
}

void eis_pool_stop(eis_pool *pool)
{
    int i;
    if (!pool) return;
    pthread_mutex_lock(&pool->lock);
    wait_idle(pool);
    pool->stop = 1;
    pthread_cond_broadcast(&pool->work);
    pthread_mutex_unlock(&pool->lock);
    for (i = 0; i < pool->workers_started; i++) pthread_join(pool->workers[i], NULL);
    pthread_cond_destroy(&pool->idle);
    pthread_cond_destroy(&pool->work);
    pthread_mutex_destroy(&pool->lock);
    free(pool);
}

/* Set up a job in `bands` bands (lock held, no job in flight). */
static void set_job(eis_pool *p, const double *warp, const home_stab_image *src, home_stab_image *dst,
                    int bands, eis_pool_done_fn done, void *user, long tag)
{
    pool_job *j = &p->job;
    memcpy(j->warp, warp, sizeof j->warp);
    j->src = *src;
    j->dst = *dst;
    j->bands = bands;
    j->next_band = j->bands_done = 0;
    j->status = HOME_OK;
    j->done = done;
    j->user = user;
    j->tag = tag;
    p->busy = 1;
}

int eis_pool_warp(eis_pool *pool, const double *warp, const home_stab_image *src, home_stab_image *dst)
{
    int st;
    if (!pool || !warp || !src || !dst) return HOME_E_NULL;
    if (pool->threads == 1) return home_stab_warp(warp, src, dst);
    pthread_mutex_lock(&pool->lock);
    wait_idle(pool);   /* (a background job's status stays for its own caller: none mixes both) */
    set_job(pool, warp, src, dst, pool->threads, NULL, NULL, 0);
    pthread_cond_broadcast(&pool->work);
    run_bands(pool);   /* the caller takes bands too */
    st = wait_idle(pool);
    pthread_mutex_unlock(&pool->lock);
    return st;
}

int eis_pool_submit(eis_pool *pool, const double *warp, const home_stab_image *src, home_stab_image *dst,
                    eis_pool_done_fn done, void *user, long tag)
{
    int st;
    if (!pool || !warp || !src || !dst) return HOME_E_NULL;
    pthread_mutex_lock(&pool->lock);
    st = wait_idle(pool);
    if (st == HOME_OK) {
        /* one thread: one band, run here; else a band per worker */
        set_job(pool, warp, src, dst, pool->threads == 1 ? 1 : pool->threads - 1, done, user, tag);
        if (pool->threads == 1) run_bands(pool);
        else pthread_cond_broadcast(&pool->work);
    }
    pthread_mutex_unlock(&pool->lock);
    return st;
}

int eis_pool_wait(eis_pool *pool)
{
    int st;
    if (!pool) return HOME_E_NULL;
    pthread_mutex_lock(&pool->lock);
    st = wait_idle(pool);
    pthread_mutex_unlock(&pool->lock);
    return st;
}
