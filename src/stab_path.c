/* The camera path: a constant-velocity Kalman filter per component, fixed-lag RTS smoothing
 * over the lookahead, and the stream's ends mirrored so that they are smoothed like the rest. */
#include "stab_internal.h"
#include <math.h>
#include <string.h>

#define STAB_INIT_VEL_VAR 1.0             /* prior variance of the path velocity, (px/frame)^2 */
#define STAB_STILL_VAR 1e-6               /* a still frame's path measurement variance, px^2 */
#define STAB_EASE_BEFORE 13               /* still frames this close before the camera moves */
#define STAB_EASE_AFTER 13                /* ... or after it stopped are pinned the less the
                                             closer they are: the path eases over them
                                             (bench/stab/README.md, session 37) */
#define STAB_EASE_MOVE_PX 1.0             /* a move: the frame's corners moved this far, px RMS */

void home__stab_path_components(const home_stab *st, const home_stab_sim *s, double *z)
{
    z[0] = s->tx; z[1] = s->ty; z[2] = s->angle * st->norm; z[3] = s->log_scale * st->norm;
}

static int is_still(const stab_slot *s)
{
    return s->registered_still || s->status == HOME_STAB_MOTION_STILL;
}

/* The variance of a frame's path measurement: the intended path plus shake of variance r, more
 * the less certain the frame's motion. A frame whose camera stood still since the previous one
 * (registered as the identity, or a small motion taken as none) has no shake: its path is the
 * intended one, so a tripod shot's still stretches stay still in the output instead of taking
 * up part of a pan that starts or ends next to them. Only where the lookahead spans the time
 * constant: the smoother then sees a still frame coming early enough to meet it smoothly, where
 * a causal or short-sighted path would jump onto it at the end of a pan. The still frames
 * nearest the move are pinned less (their ease share): a camera that starts or stops within a
 * frame or two is then eased into and out of over a few still frames, not within the move. */
static double measurement_noise(const home_stab *st, const stab_slot *cur)
{
    if (st->sees_ahead && is_still(cur)) {
        if (!(cur->ease > 0.0)) return STAB_STILL_VAR;
        /* geometric between the two: the information grows by equal steps */
        return exp(cur->ease * log(st->r * cur->weight) + (1.0 - cur->ease) * log(STAB_STILL_VAR));
    }
    return st->r * cur->weight;
}

/* Re-run the filter over frames t..newest of the segment (their measurements changed). */
void home__stab_refilter(const home_stab *st, long t, long newest)
{
    const long first = st->first, lookahead = st->cfg.lookahead;
    double z[4];
    long i;
    /* the mirrored start reflects the segment's first lookahead frames */
    if (lookahead > 0 && newest - first >= lookahead && t - first <= lookahead) {
        home__stab_refilter_mirrored_start(st, first, newest);
        return;
    }
    for (i = t; i <= newest; i++) {
        home__stab_path_components(st, &slot_of(st, i)->raw, z);
        home__stab_kalman_step(st, slot_of(st, i - 1), slot_of(st, i), z);
    }
}

/* Did the camera move from frame s's predecessor to s by STAB_EASE_MOVE_PX or more? A smaller
 * motion is no start or end of a move to ease over. */
static int moves(const home_stab *st, const stab_slot *s)
{
    return ((s->status == HOME_STAB_MOTION_OK && !s->registered_still) ||
            s->status == HOME_STAB_MOTION_RESTORED || s->status == HOME_STAB_MOTION_BRIDGED) &&
           home__stab_corner_motion(st, &s->motion) >= STAB_EASE_MOVE_PX;
}

/* How far a still frame's path may leave the camera's, d frames from the camera's move within
 * `reach` of it: 1 (an ordinary frame) next to the move, down to 0 (pinned) beyond the reach. */
static double ease_share(long d, long reach)
{
    return d <= reach ? (double)(reach + 1 - d) / (double)(reach + 1) : 0.0;
}

/* Frame n, just pushed: its ease share when it is still, within STAB_EASE_AFTER of the camera's
 * move. Decided as it arrives: a still frame pinned at the lookahead's edge would pull the
 * frames due before it onto itself at once. */
double home__stab_ease_after_move(const home_stab *st, long n)
{
    long i;
    if (!st->sees_ahead || !is_still(slot_of(st, n))) return 0.0;
    for (i = n - 1; i >= n - STAB_EASE_AFTER && i > st->first && slot_of(st, i)->frame == i; i--)
        if (moves(st, slot_of(st, i))) return ease_share(n - i, STAB_EASE_AFTER);
    return 0.0;
}

/* Frame t's motion is settled (home__stab_settle_still()). When the camera moves at t, the still
 * frames just before it are pinned less the closer they are: a camera that starts within a
 * frame or two (a tripod's pan, a hand lifting the camera) would otherwise be eased into within
 * the first frames of the move, and that ease is shake. Only frames not yet emitted change. */
void home__stab_ease_still(home_stab *st, long t, long newest)
{
    long i, from = newest + 1;
    if (!st->sees_ahead || t <= st->first || !moves(st, slot_of(st, t))) return;
    for (i = t - 1; i >= t - STAB_EASE_BEFORE && i > st->first && i >= st->emitted; i--) {
        stab_slot *s = slot_of(st, i);
        const double share = ease_share(t - i, STAB_EASE_BEFORE);
        if (is_still(s) && share > s->ease) {
            s->ease = share;
            from = i;
        }
    }
    if (from <= newest) home__stab_refilter(st, from, newest);
}

/* A held frame's motion is unknown and taken as none. Where the path cannot see past the hold
 * (causal, or a lookahead short of the time constant), it stands still with the frame: the
 * frame keeps the correction of the one before and its output moves as its input did, where a
 * path gliding on would add its own motion to the camera's (a camera sweeping 10-20 px a frame
 * came out shakier than it went in). With the lookahead, the smoother sees the frames after
 * the hold, which may bridge it, and glides over it. */
static int path_holds(const home_stab *st, const stab_slot *s)
{
    return !st->sees_ahead &&
           (s->status == HOME_STAB_MOTION_FAILED || s->status == HOME_STAB_MOTION_IMPLAUSIBLE);
}

/* One filter step for cur, measuring z (path components). */
void home__stab_kalman_step(const home_stab *st, const stab_slot *prev, stab_slot *cur,
                            const double *z)
{
    double k0, k1, sv;
    int c;
    if (prev && path_holds(st, cur)) { /* F = I, no process noise, no measurement */
        memcpy(cur->xp, prev->xf, sizeof cur->xp);
        memcpy(cur->xf, prev->xf, sizeof cur->xf);
        memcpy(cur->pp, prev->pf, sizeof cur->pp);
        memcpy(cur->pf, prev->pf, sizeof cur->pf);
        return;
    }
    if (!prev) {
        for (c = 0; c < 4; c++) {
            cur->xp[c][0] = cur->xf[c][0] = z[c];
            cur->xp[c][1] = cur->xf[c][1] = 0.0;
        }
        cur->pp[0] = cur->pf[0] = st->r;
        cur->pp[1] = cur->pf[1] = 0.0;
        cur->pp[2] = cur->pf[2] = STAB_INIT_VEL_VAR;
        return;
    }
    /* predict with F = [1 1; 0 1], Q = q [1/3 1/2; 1/2 1] (white acceleration, one frame) */
    cur->pp[0] = prev->pf[0] + 2.0 * prev->pf[1] + prev->pf[2] + st->q / 3.0;
    cur->pp[1] = prev->pf[1] + prev->pf[2] + st->q / 2.0;
    cur->pp[2] = prev->pf[2] + st->q;
    sv = cur->pp[0] + measurement_noise(st, cur);
    k0 = cur->pp[0] / sv;
    k1 = cur->pp[1] / sv;
    for (c = 0; c < 4; c++) {
        double innov;
        cur->xp[c][0] = prev->xf[c][0] + prev->xf[c][1];
        cur->xp[c][1] = prev->xf[c][1];
        innov = z[c] - cur->xp[c][0];
        cur->xf[c][0] = cur->xp[c][0] + k0 * innov;
        cur->xf[c][1] = cur->xp[c][1] + k1 * innov;
    }
    cur->pf[0] = (1.0 - k0) * cur->pp[0];
    cur->pf[1] = (1.0 - k0) * cur->pp[1];
    cur->pf[2] = cur->pp[2] - k1 * cur->pp[1];
}

/* The stream's ends. With a lookahead, the path before frame 0 and after the last frame is taken
 * to be the path inside the stream mirrored about the end frame, plus the share 1 - ease of its
 * linear trend (ease 0: the pan goes on, 1: the camera comes to rest). The first and last
 * lookahead frames are then smoothed over a full window like the others instead of over a
 * one-sided one, and with ease > 0 the virtual camera eases in and out of the pan over about a
 * lookahead of frames: on the bench clips the ends' ITF loss was that speed, not jitter (see
 * bench/stab/README.md). Latency is unchanged: the start is re-filtered when frame `lookahead`
 * arrives, before frame 0 is due; the end is appended at flush. */

/* Least-squares slope (path components per frame) over frames a..b. */
static void path_trend(const home_stab *st, long a, long b, double *v)
{
    double z[4], sz[4] = {0, 0, 0, 0}, tm = 0.5 * (double)(a + b), stt = 0.0;
    long t;
    int c;
    for (t = a; t <= b; t++) {
        home__stab_path_components(st, &slot_of(st, t)->raw, z);
        stt += (t - tm) * (t - tm);
        for (c = 0; c < 4; c++) sz[c] += (t - tm) * z[c];
    }
    for (c = 0; c < 4; c++) v[c] = stt > 0.0 ? sz[c] / stt : 0.0;
}

/* The measurement taken for frame t outside the segment first..last: the frame t is reflected
 * to (again and again for segments shorter than the lookahead), plus the kept trend over the
 * distance. */
static void mirrored_measurement(const home_stab *st, long t, long first, long last,
                                 const double *trend, double *z)
{
    const double keep = 1.0 - st->cfg.ease;
    long r = t;
    int c;
    while (last > first && (r < first || r > last)) r = r < first ? 2 * first - r : 2 * last - r;
    if (last == first) r = first;
    home__stab_path_components(st, &slot_of(st, r)->raw, z);
    for (c = 0; c < 4; c++) z[c] += keep * trend[c] * (double)(t - r);
}

/* Re-run the filter over the segment's frames first..last (all in the ring) after the mirrored
 * frames first-k..first-1, k = min(lookahead, last - first). */
void home__stab_refilter_mirrored_start(const home_stab *st, long first, long last)
{
    const long k = last - first < st->cfg.lookahead ? last - first : st->cfg.lookahead;
    stab_slot v[2];
    const stab_slot *prev = NULL;
    double trend[4], z[4];
    long i;
    if (k <= 0) return;
    v[0].weight = v[1].weight = 1.0;
    v[0].status = v[1].status = HOME_STAB_MOTION_OK;
    v[0].registered_still = v[1].registered_still = 0;
    v[0].ease = v[1].ease = 0.0;
    path_trend(st, first, first + k, trend);
    for (i = first - k; i <= last; i++) {
        stab_slot *cur = i < first ? &v[(first - i) & 1] : slot_of(st, i);
        if (i < first) mirrored_measurement(st, i, first, last, trend, z);
        else home__stab_path_components(st, &cur->raw, z);
        home__stab_kalman_step(st, prev, cur, z);
        prev = cur;
    }
}

/* Append the mirrored frames last+1..last+lookahead to the segment first..last. The ring has
 * 2 lookahead + 1 slots: frame last+i takes the slot of frame last+i-ring_len, older than every
 * frame mirrored or still due. */
static void append_mirrored_end(home_stab *st, long first, long last)
{
    const long k = last - first < st->cfg.lookahead ? last - first : st->cfg.lookahead;
    double trend[4], z[4];
    long i;
    path_trend(st, last - k, last, trend);
    for (i = 1; i <= st->cfg.lookahead; i++) {
        stab_slot *cur = slot_of(st, last + i);
        mirrored_measurement(st, last + i, first, last, trend, z);
        cur->frame = last + i;
        cur->status = HOME_STAB_MOTION_OK;
        cur->weight = 1.0;
        cur->registered_still = 0;
        cur->ease = 0.0;
        cur->smoothed_ready = 0;
        home__stab_kalman_step(st, slot_of(st, last + i - 1), cur, z);
    }
}

/* The segment ends with frame last (a scene cut follows, or the stream ends): every frame still
 * due is smoothed now over the mirrored end, as a stream ending there would be, and keeps its
 * smoothed path, so the frames after a cut can take the ring without touching them. */
void home__stab_end_segment(home_stab *st, long last)
{
    long m;
    if (last - st->first < st->cfg.lookahead)
        home__stab_refilter_mirrored_start(st, st->first, last);
    append_mirrored_end(st, st->first, last);
    for (m = st->emitted; m <= last; m++) {
        stab_slot *slot = slot_of(st, m);
        slot->smoothed = home__stab_smoothed_path(st, m, m + st->cfg.lookahead);
        slot->smoothed_ready = 1;
    }
}

/* Fixed-lag RTS smoothing: the estimate of frame m's path given every frame up to last. */
home_stab_sim home__stab_smoothed_path(const home_stab *st, long m, long last)
{
    double xs[4][2];
    home_stab_sim s;
    long k;
    int c;
    memcpy(xs, slot_of(st, last)->xf, sizeof xs);
    for (k = last - 1; k >= m; k--) {
        const stab_slot *a = slot_of(st, k), *b = slot_of(st, k + 1);
        if (path_holds(st, b)) continue; /* C = I: frame k's path is frame k + 1's */
        /* C = Pf F^T Pp(k+1)^-1 */
        double f00 = a->pf[0] + a->pf[1], f01 = a->pf[1], f10 = a->pf[1] + a->pf[2], f11 = a->pf[2];
        double det = b->pp[0] * b->pp[2] - b->pp[1] * b->pp[1];
        double i00 = b->pp[2] / det, i01 = -b->pp[1] / det, i11 = b->pp[0] / det;
        double c00 = f00 * i00 + f01 * i01, c01 = f00 * i01 + f01 * i11;
        double c10 = f10 * i00 + f11 * i01, c11 = f10 * i01 + f11 * i11;
        for (c = 0; c < 4; c++) {
            double d0 = xs[c][0] - b->xp[c][0], d1 = xs[c][1] - b->xp[c][1];
            xs[c][0] = a->xf[c][0] + c00 * d0 + c01 * d1;
            xs[c][1] = a->xf[c][1] + c10 * d0 + c11 * d1;
        }
    }
    s.tx = xs[0][0];
    s.ty = xs[1][0];
    s.angle = xs[2][0] / st->norm;
    s.log_scale = xs[3][0] / st->norm;
    return s;
}
