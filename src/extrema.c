/* Hough-space extrema as keypoints: strict 3x3 extrema, one Newton step to subpixel, saliency
 * |det H / tr H|, and fixed-capacity min-heaps that keep the top-K per sign. */
#include "home_internal.h"
#include <math.h>

/* Strict total order: higher saliency first, then earlier detection. */
static int ranks_below(const home__heap_entry *a, const home__heap_entry *b)
{
    if (a->saliency != b->saliency) return a->saliency < b->saliency;
    return a->order > b->order;
}

void home__heap_init(home__heap *heap, home__heap_entry *entries, home__candidate *pool,
                     int capacity)
{
    heap->entries = entries;
    heap->pool = pool;
    heap->count = 0;
    heap->capacity = capacity;
}

int home__heap_would_accept(const home__heap *heap, float saliency, uint32_t order)
{
    home__heap_entry probe;
    if (heap->count < heap->capacity) return 1;
    probe.saliency = saliency;
    probe.order = order;
    probe.slot = 0;
    return ranks_below(&heap->entries[0], &probe);
}

/* items[i] down to its place, bottom-up: the hole follows the weaker child down to a leaf and
 * the item rises back up that path. The same heap as swapping it down (the order is strict),
 * with one comparison a level instead of two on the way down: an item taken from the bottom
 * (heap sort) or a newcomer just above the weakest (top-K) ends deep. */
static void sift_down(home__heap_entry *items, int count, int i)
{
    const home__heap_entry item = items[i];
    int hole = i, child;
    while ((child = 2 * hole + 1) < count) {
        if (child + 1 < count && ranks_below(&items[child + 1], &items[child])) child++;
        items[hole] = items[child];
        hole = child;
    }
    while (hole > i) {
        const int parent = (hole - 1) / 2;
        if (!ranks_below(&item, &items[parent])) break;
        items[hole] = items[parent];
        hole = parent;
    }
    items[hole] = item;
}

/* Insert, or replace the weakest when full (callers check home__heap_would_accept first); the
 * weakest's pool slot takes the newcomer. */
void home__heap_push(home__heap *heap, const home__candidate *cand)
{
    home__heap_entry e;
    e.saliency = cand->saliency;
    e.order = cand->order;
    if (heap->count < heap->capacity) {
        int i = heap->count++;
        e.slot = i;
        heap->pool[i] = *cand;
        heap->entries[i] = e;
        while (i > 0) {
            int parent = (i - 1) / 2;
            home__heap_entry tmp;
            if (!ranks_below(&heap->entries[i], &heap->entries[parent])) break;
            tmp = heap->entries[i];
            heap->entries[i] = heap->entries[parent];
            heap->entries[parent] = tmp;
            i = parent;
        }
    } else if (ranks_below(&heap->entries[0], &e)) {
        e.slot = heap->entries[0].slot;
        heap->pool[e.slot] = *cand;
        heap->entries[0] = e;
        sift_down(heap->entries, heap->count, 0);
    }
}

int home__heap_sort_desc(home__heap *heap)
{
    int n;
    for (n = heap->count - 1; n > 0; n--) {
        home__heap_entry tmp = heap->entries[0];
        heap->entries[0] = heap->entries[n];
        heap->entries[n] = tmp;
        sift_down(heap->entries, n, 0);
    }
    return heap->count;
}

int home__extremum_candidates(const home__kernels *kernels, const float *up, const float *mid,
                              const float *down, int n, int *idx)
{
    int end, count = kernels->extremum_candidates(up, mid, down, n, idx, &end);
    for (; end < n - 1; end++) /* what the kernel left: the reference */
        if (home__is_extremum(up, mid, down, end)) idx[count++] = end;
    return count;
}

int home__detect_row(const home__kernels *kernels, const float *const *rows, int centre, int r_bins,
                     int theta_bins, int *candidates, home__extremum *out)
{
    const float *up = rows[0], *mid = rows[1], *down = rows[2];
    const int n_candidates = home__extremum_candidates(kernels, up, mid, down, r_bins, candidates);
    int c, n = 0;
    for (c = 0; c < n_candidates; c++) {
        const int i = candidates[c];
        const float v = mid[i];
        const int sign = v > 0.0f ? 1 : -1;
        double g_t, g_r, h_tt, h_rr, h_tr, det, step_t, step_r, theta;
        /* central-difference gradient and Hessian; one Newton step */
        g_t = 0.5 * ((double)down[i] - up[i]);
        g_r = 0.5 * ((double)mid[i + 1] - mid[i - 1]);
        h_tt = (double)down[i] - 2.0 * v + up[i];
        h_rr = (double)mid[i + 1] - 2.0 * v + mid[i - 1];
        h_tr = 0.25 * ((double)down[i + 1] - down[i - 1] - up[i + 1] + up[i - 1]);
        det = h_tt * h_rr - h_tr * h_tr;
        if (!(det > 0.0)) continue;                 /* a saddle, not an extremum */
        step_t = -(h_rr * g_t - h_tr * g_r) / det;
        step_r = -(h_tt * g_r - h_tr * g_t) / det;
        if (fabs(step_t) > 1.0 || fabs(step_r) > 1.0) continue;
        theta = centre + step_t;
        /* the padding only serves as neighbours */
        if (theta < 0.0 || theta >= theta_bins) continue;
        out[n].theta_bin = (float)theta;
        out[n].r_bin = (float)(i + step_r);
        out[n].saliency = (float)fabs(det / (h_tt + h_rr));
        out[n].sign = sign;
        n++;
    }
    return n;
}
