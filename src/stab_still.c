/* A still camera stays still: a small motion registered between frames that otherwise register
 * as the identity (a tripod shot, where fog, noise or a passing object can tip one registration
 * of many) is taken as none, so that such motions cannot accumulate into drift. A large motion
 * is kept: a tripod that is knocked moves. With a lookahead the frames after the motion are
 * looked at too, so the first frames of a real start are kept. */
#include "stab_internal.h"
#include <math.h>

#define STILL_NEIGHBOURS 4     /* frames looked at around a motion, */
#define STILL_AFTER 2          /* at most this many after it (and only within the lookahead) */
#define STILL_MIN 2            /* neighbours registered as the identity that make a motion lone,
                                  with no other motion among them (held frames are neither) */
/* A motion moving the frame's corners by more than this share of the half diagonal is kept
 * however lone (a knocked tripod, 7 px at 640x360). Not a multiple of sigma_px: the lone wrong
 * motions of a textured object over a faint background are 10-30 of their own sigma off. */
#define STILL_KNOCK 0.02

long home__stab_still_delay(const home_stab *st)
{
    return st->cfg.lookahead < STILL_AFTER ? st->cfg.lookahead : STILL_AFTER;
}

/* RMS displacement of the frame's corners under the similarity m, px. */
static double corner_motion(const home_stab *st, const home_stab_sim *m)
{
    const double cx = 0.5 * (st->cfg.width - 1), cy = 0.5 * (st->cfg.height - 1);
    const double k = exp(m->log_scale), a = k * cos(m->angle) - 1.0, b = k * sin(m->angle);
    double sum = 0.0;
    int i;
    for (i = 0; i < 4; i++) {
        const double x = (i & 1) ? cx : -cx, y = (i & 2) ? cy : -cy;
        const double u = a * x - b * y + m->tx, v = b * x + a * y + m->ty;
        sum += u * u + v * v;
    }
    return sqrt(sum / 4.0);
}

static int is_lone(const home_stab *st, long t, long newest)
{
    const stab_slot *s = slot_of(st, t);
    const long after = newest - t < STILL_AFTER ? newest - t : STILL_AFTER;
    long i;
    int still = 0, moved = 0;
    if (s->status != HOME_STAB_MOTION_OK || s->registered_still ||
        corner_motion(st, &s->motion) > STILL_KNOCK * st->norm)
        return 0;
    for (i = t - (STILL_NEIGHBOURS - after); i <= t + after; i++)
        if (i != t && i > st->first && slot_of(st, i)->frame == i) {
            const stab_slot *n = slot_of(st, i);
            still += n->registered_still;
            moved += n->status == HOME_STAB_MOTION_OK && !n->registered_still;
        }
    return still >= STILL_MIN && !moved;
}

/* Decide frame t's motion once the frames up to newest are in: a lone one becomes none, and the
 * path from t on is recomputed and filtered again. */
void home__stab_settle_still(home_stab *st, long t, long newest)
{
    const long first = st->first, lookahead = st->cfg.lookahead;
    stab_slot *s;
    long i;
    double z[4];
    if (t <= first || t < st->emitted || !is_lone(st, t, newest)) return;
    s = slot_of(st, t);
    s->motion.tx = s->motion.ty = s->motion.angle = s->motion.log_scale = 0.0;
    s->status = HOME_STAB_MOTION_STILL;
    for (i = t; i <= newest; i++)
        slot_of(st, i)->raw = home__stab_sim_compose(&slot_of(st, i)->motion,
                                                     &slot_of(st, i - 1)->raw);
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
