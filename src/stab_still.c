/* The frames around a motion decide what a doubtful one was.
 * A still camera stays still: a small motion registered between frames that otherwise register
 * as the identity (a tripod shot, where fog, noise or a passing object can tip one registration
 * of many) is taken as none, so that such motions cannot accumulate into drift. A large motion
 * is kept: a tripod that is knocked moves. With a lookahead the frames after the motion are
 * looked at too, so the first frames of a real start are kept.
 * A moving camera keeps moving: a motion HOME refused only because the frame's plain background
 * stood still is either a moving object over a still background (a tripod shot: its neighbours
 * register the identity) or the camera's motion with a plain part moving along (a hand at the
 * lens, blocks an encoder left unchanged: its neighbours register motions). Among moving
 * neighbours and no still one it is taken, instead of holding the frame and keeping its shake.
 * A still background refutes what one frame cannot: where the background is plain (fog), one
 * pair's score test is too weak to refuse the objects' motion HOME registers, but the tests of
 * the frames around, summed, can be strong enough; a motion they refute, and its own test leans
 * against, becomes none. Where the background shows nothing to test, a motion that leaves a
 * part of the frame unexplained which the identity explains becomes none when the camera was
 * not moving before it (its last decided frames). */
#include "stab_internal.h"
#include "home_internal.h"
#include <math.h>

#define STILL_NEIGHBOURS 4     /* frames looked at around a motion, */
#define STILL_AFTER 2          /* at most this many after it (and only within the lookahead) */
#define STILL_MIN 2            /* neighbours registered as the identity that make a motion lone,
                                  with no other motion among them (held frames are neither) */
/* A motion moving the frame's corners by more than this share of the half diagonal is kept
 * however lone (a knocked tripod, 7 px at 640x360). Not a multiple of sigma_px: the lone wrong
 * motions of a textured object over a faint background are 10-30 of their own sigma off. */
#define STILL_KNOCK 0.02
#define BACKGROUND_BEFORE 30   /* the score tests summed: frames before the motion (as far as
                                  the ring holds them; and up to STILL_AFTER after it) */
#define UNEXPLAINED_SHARE 0.08 /* a motion leaving this share of the regions unexplained, */
#define UNEXPLAINED_DECIDED 4  /* ... judged by this many decided frames before it */
#define RESTORE_BEFORE 8       /* frames looked at before a refused motion (and up to STILL_AFTER
                                  after it), */
#define RESTORE_MIN 2          /* registered moving (ok, not the identity), with none still */

long home__stab_still_delay(const home_stab *st)
{
    return st->cfg.lookahead < STILL_AFTER ? st->cfg.lookahead : STILL_AFTER;
}

static int is_lone(const home_stab *st, long t, long newest)
{
    const stab_slot *s = slot_of(st, t);
    const long after = newest - t < STILL_AFTER ? newest - t : STILL_AFTER;
    long i;
    int still = 0, moved = 0;
    if (s->status != HOME_STAB_MOTION_OK || s->registered_still ||
        home__stab_corner_motion(st, &s->motion) > STILL_KNOCK * st->norm)
        return 0;
    for (i = t - (STILL_NEIGHBOURS - after); i <= t + after; i++)
        if (i != t && i > st->first && slot_of(st, i)->frame == i) {
            const stab_slot *n = slot_of(st, i);
            still += n->registered_still;
            moved += n->status == HOME_STAB_MOTION_OK && !n->registered_still;
        }
    return still >= STILL_MIN && !moved;
}

/* Frame t's motion becomes m (status, weight): the path from t on is composed and filtered
 * again up to newest. */
void home__stab_retake_motion(home_stab *st, long t, long newest, const home_stab_sim *m,
                              int status, double weight)
{
    stab_slot *s = slot_of(st, t);
    long i;
    s->motion = *m;
    s->status = status;
    s->weight = weight;
    for (i = t; i <= newest; i++)
        slot_of(st, i)->raw = home__stab_sim_compose(&slot_of(st, i)->motion,
                                                     &slot_of(st, i - 1)->raw);
    home__stab_refilter(st, t, newest);
}

/* A frame's score test on a plain background: the motion's expected score rests on many
 * pixels, its per-pixel terms spread no wider than the noise (expected / evidence at most 1; a
 * fog: about 0.6). Where a few pixels next to texture carry it (2.5-3.5 on a structured scene
 * whose camera moves), observed falls short of expected for right motions too. */
static int plain_score(const stab_slot *s)
{
    return s->has_score && s->score[1] > 0.0 && s->score[2] >= s->score[1];
}

/* Does the plain background, over the frames around t, refute t's motion? Each ok motion's
 * score test (refine_background.c) gives observed, about N(0, 1) when the background stands
 * still, against expected, what the background would show if it moved so; where it is plain
 * (fog) one frame's expected is too small to tell. The frames' tests are independent
 * measurements of the same question, so their sums are tested as one: the sum of observed is
 * N(0, n) under a still background. */
static int background_refutes(const home_stab *st, long t, long newest)
{
    const stab_slot *s = slot_of(st, t);
    const long after = newest - t < STILL_AFTER ? newest - t : STILL_AFTER;
    double observed = 0.0, expected = 0.0, spread = 0.0;
    long i;
    int n = 0;
    /* its own test leans the same way (a camera that starts moving after a still stretch
     * shows its motion in its own frames) */
    if (s->status != HOME_STAB_MOTION_OK || s->registered_still || !plain_score(s) ||
        !(s->score[0] < s->score[1] / 3.0))
        return 0;
    for (i = t - BACKGROUND_BEFORE; i <= t + after; i++)
        if (i > st->first && slot_of(st, i)->frame == i && plain_score(slot_of(st, i))) {
            const double *sc = slot_of(st, i)->score;
            observed += sc[0];
            expected += sc[1];
            spread += (sc[1] / sc[2]) * (sc[1] / sc[2]); /* expected's own spread */
            n++;
        }
    /* the sums as one test's z scores, judged by the single frame's rule */
    return n > 1 && home__refine_score_refutes(observed / sqrt((double)n),
                                               expected / sqrt((double)n),
                                               expected / sqrt(spread));
}

int home__stab_leaves_part(const stab_slot *s)
{
    return s->status == HOME_STAB_MOTION_OK && !s->registered_still &&
           s->unexplained >= UNEXPLAINED_SHARE;
}

/* The last UNEXPLAINED_DECIDED frames before t whose motion was decided (held ones tell
 * nothing; up to BACKGROUND_BEFORE back): how many there are, and how many of them moved
 * (registered moving, restored or bridged, against registered the identity or still). */
int home__stab_moved_before(const home_stab *st, long t, int *decided)
{
    long i;
    int moved = 0;
    *decided = 0;
    for (i = t - 1; i > st->first && i >= t - BACKGROUND_BEFORE && *decided < UNEXPLAINED_DECIDED;
         i--) {
        const stab_slot *n = slot_of(st, i);
        const int moving = (n->status == HOME_STAB_MOTION_OK && !n->registered_still) ||
                           n->status == HOME_STAB_MOTION_RESTORED ||
                           n->status == HOME_STAB_MOTION_BRIDGED;
        if (n->frame != i) break;
        moved += moving;
        *decided += moving || n->registered_still || n->status == HOME_STAB_MOTION_STILL;
    }
    return moved;
}

/* Does t's motion leave much of the frame unexplained where the identity explains it, on a
 * camera that was not moving? Per pair the share cannot tell a still background under moving
 * objects from a hand or parallax in front of a moving camera; the path can. */
static int leaves_still_part(const home_stab *st, long t)
{
    int decided, moved;
    if (!home__stab_leaves_part(slot_of(st, t))) return 0;
    moved = home__stab_moved_before(st, t, &decided);
    return 2 * moved <= decided; /* more than half moved: a moving camera keeps its motions */
}

/* Decide frame t's motion once the frames up to newest are in: a lone one, or one the
 * background around refutes, becomes none. */
void home__stab_settle_still(home_stab *st, long t, long newest)
{
    static const home_stab_sim none = {0, 0, 0, 0};
    if (t <= st->first || t < st->emitted ||
        !(is_lone(st, t, newest) || background_refutes(st, t, newest) ||
          leaves_still_part(st, t)))
        return;
    home__stab_retake_motion(st, t, newest, &none, HOME_STAB_MOTION_STILL, slot_of(st, t)->weight);
}

/* Do the frames from..to of this segment, but skip, register a moving camera: at least
 * RESTORE_MIN motions and none still? */
static int moving_camera(const home_stab *st, long from, long to, long skip)
{
    long i;
    int still = 0, moved = 0;
    for (i = from; i <= to; i++)
        if (i != skip && i > st->first && slot_of(st, i)->frame == i) {
            const stab_slot *n = slot_of(st, i);
            still += n->registered_still || n->status == HOME_STAB_MOTION_STILL;
            moved += n->status == HOME_STAB_MOTION_OK && !n->registered_still;
        }
    return moved >= RESTORE_MIN && !still;
}

/* Do the RESTORE_BEFORE frames up to t register a moving camera? */
int home__stab_camera_moves(const home_stab *st, long t)
{
    return moving_camera(st, t - RESTORE_BEFORE + 1, t, -1);
}

/* A held frame t with a refused motion among moving neighbours takes that motion. Restored
 * frames are no evidence for their neighbours, so that one cannot carry the next. */
void home__stab_settle_restored(home_stab *st, long t, long newest)
{
    const long after = newest - t < STILL_AFTER ? newest - t : STILL_AFTER;
    const stab_slot *s;
    if (t <= st->first || t < st->emitted) return;
    s = slot_of(st, t);
    if (s->frame != t || s->status != HOME_STAB_MOTION_FAILED || !s->has_candidate) return;
    if (moving_camera(st, t - RESTORE_BEFORE, t + after, t))
        home__stab_retake_motion(st, t, newest, &s->candidate, HOME_STAB_MOTION_RESTORED,
                                 s->candidate_weight);
}
