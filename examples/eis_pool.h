/* A fixed pool of worker threads for the live examples (eis-v4l2, eis-libcamera) and the
 * homestab element: a frame's warp split in row bands (home_stab_warp_rows) over the pool.
 *
 * A pool of N threads counts the caller: it starts N - 1 workers once and keeps them.
 * - eis_pool_warp(): the warp now, in N bands over the workers and the caller, which returns
 *   when the frame is done (the GStreamer element: its streaming thread waits anyway).
 * - eis_pool_submit(): the warp in the background, in N - 1 bands over the workers, then the
 *   caller's done() (e.g. write the frame out) on the worker that finished the last band,
 *   while the caller registers the next frame. One job at a time: a submit waits for the
 *   previous job, so done() runs once per frame, in submit order.
 * With N = 1 both run everything in the caller at once. Every band gives the whole warp's bytes
 * (home_stab.h), so the output does not depend on N. Bands start on even rows (4:2:0 chroma). */
#ifndef HOME_EIS_POOL_H
#define HOME_EIS_POOL_H
#include "home_stab.h"
#ifdef __cplusplus
extern "C" {
#endif

/* Largest pool; and what `--threads 0` (automatic) takes at most: the online CPUs, capped at 4
 * (a Raspberry Pi 4 or 5: one registers, three warp). */
#define EIS_POOL_MAX_THREADS 16
#define EIS_POOL_AUTO_MAX 4

/* A done() that failed (eis_pool_wait()'s status); the warp's own failures are HOME_E_*. */
#define EIS_POOL_E_DONE (-100)

typedef struct eis_pool eis_pool;

/* After a background warp: the frame `tag` (the caller's, e.g. its index) is in dst; warp_ms is
 * the wall time from its first band's start to its last band's end. 0, or nonzero on failure. */
typedef int (*eis_pool_done_fn)(void *user, long tag, double warp_ms);

/* The automatic thread count: online CPUs, 1 .. EIS_POOL_AUTO_MAX. */
int eis_pool_auto_threads(void);

/* Start a pool of `threads` (1 .. EIS_POOL_MAX_THREADS; 0 = eis_pool_auto_threads()), the caller
 * counted. 0, or -1 (bad count, no memory or no thread: nothing left running). */
int eis_pool_start(eis_pool **pool, int threads);

/* The thread count, the caller counted. */
int eis_pool_threads(const eis_pool *pool);

/* Wait for the job in flight, then end the workers and free the pool (NULL: nothing). */
void eis_pool_stop(eis_pool *pool);

/* Warp src into dst by warp (as home_stab_warp) in bands over the pool and the caller; returns
 * when all is written: HOME_OK or the warp's status. Waits for a background job first. */
int eis_pool_warp(eis_pool *pool, const double *warp, const home_stab_image *src, home_stab_image *dst);

/* Warp src into dst in the background, then done(user, tag, ms) on a worker (done may be NULL).
 * warp, src and dst are copied; the pixels must stay put until the job is done (the next
 * submit, eis_pool_wait() or eis_pool_stop() returns). First waits for the previous job: its
 * status, when not HOME_OK, is returned and nothing is submitted. With one thread all runs
 * here, before the return; its status too is the next call's to report. */
int eis_pool_submit(eis_pool *pool, const double *warp, const home_stab_image *src, home_stab_image *dst,
                    eis_pool_done_fn done, void *user, long tag);

/* Wait for the job in flight: HOME_OK (also when none was), the warp's status, or
 * EIS_POOL_E_DONE; each job's status is reported once. */
int eis_pool_wait(eis_pool *pool);

#ifdef __cplusplus
}
#endif
#endif
