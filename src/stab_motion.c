/* Similarities about the frame centre: composition, inverse, scaling, and the least-squares
 * similarity through what HOME's homography does to a grid of the frame. */
#include "stab_internal.h"
#include <math.h>

#define STAB_FIT_GRID 5                   /* similarity fitted to H on a 5x5 grid of the frame */

home_stab_sim home__stab_sim_compose(const home_stab_sim *b, const home_stab_sim *a)
{
    home_stab_sim r;
    double s = exp(b->log_scale), c = cos(b->angle), n = sin(b->angle);
    r.angle = a->angle + b->angle;
    r.log_scale = a->log_scale + b->log_scale;
    r.tx = s * (c * a->tx - n * a->ty) + b->tx;
    r.ty = s * (n * a->tx + c * a->ty) + b->ty;
    return r;
}

home_stab_sim home__stab_sim_inverse(const home_stab_sim *a)
{
    home_stab_sim r;
    double s = exp(-a->log_scale), c = cos(a->angle), n = sin(a->angle);
    r.angle = -a->angle;
    r.log_scale = -a->log_scale;
    r.tx = -s * (c * a->tx + n * a->ty);
    r.ty = -s * (-n * a->tx + c * a->ty);
    return r;
}

home_stab_sim home__stab_sim_scaled(const home_stab_sim *a, double k)
{
    home_stab_sim r;
    r.tx = k * a->tx; r.ty = k * a->ty; r.angle = k * a->angle; r.log_scale = k * a->log_scale;
    return r;
}

void home_stab_sim_to_matrix(const home_stab_sim *s, int width, int height, double *m)
{
    double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
    double k = exp(s->log_scale), a = k * cos(s->angle), b = k * sin(s->angle);
    m[0] = a; m[1] = -b; m[2] = cx + s->tx - a * cx + b * cy;
    m[3] = b; m[4] = a;  m[5] = cy + s->ty - b * cx - a * cy;
    m[6] = 0; m[7] = 0;  m[8] = 1;
}

void home__stab_apply(const double *h, double x, double y, double *u, double *v)
{
    double w = h[6] * x + h[7] * y + h[8];
    *u = (h[0] * x + h[1] * y + h[2]) / w;
    *v = (h[3] * x + h[4] * y + h[5]) / w;
}

/* Least-squares similarity through the points a grid of the full frame reaches under HOME's H
 * (found on the downscaled frame). Returns the RMS residual in px, or -1 if H is unusable. */
double home__stab_fit_similarity(const home_stab *st, const double *h, home_stab_sim *out)
{
    const double f = st->cfg.downscale, off = 0.5 * (f - 1);
    const double cx = 0.5 * (st->cfg.width - 1), cy = 0.5 * (st->cfg.height - 1);
    double px[STAB_FIT_GRID * STAB_FIT_GRID][2], qx[STAB_FIT_GRID * STAB_FIT_GRID][2];
    double mp[2] = {0, 0}, mq[2] = {0, 0}, spp = 0, sa = 0, sb = 0, a, b, res = 0;
    const int n = STAB_FIT_GRID * STAB_FIT_GRID;
    int i, j, k = 0;
    for (j = 0; j < STAB_FIT_GRID; j++)
        for (i = 0; i < STAB_FIT_GRID; i++, k++) {
            double x = (st->cfg.width - 1) * (double)i / (STAB_FIT_GRID - 1);
            double y = (st->cfg.height - 1) * (double)j / (STAB_FIT_GRID - 1);
            double w = h[6] * (x - off) / f + h[7] * (y - off) / f + h[8], u, v;
            if (!(w > 1e-6)) return -1.0;   /* grid point crosses the horizon of H */
            home__stab_apply(h, (x - off) / f, (y - off) / f, &u, &v);
            px[k][0] = x - cx; px[k][1] = y - cy;
            qx[k][0] = f * u + off - cx; qx[k][1] = f * v + off - cy;
            mp[0] += px[k][0]; mp[1] += px[k][1]; mq[0] += qx[k][0]; mq[1] += qx[k][1];
        }
    mp[0] /= n; mp[1] /= n; mq[0] /= n; mq[1] /= n;
    for (k = 0; k < n; k++) {
        double p0 = px[k][0] - mp[0], p1 = px[k][1] - mp[1], q0 = qx[k][0] - mq[0],
               q1 = qx[k][1] - mq[1];
        spp += p0 * p0 + p1 * p1;
        sa += p0 * q0 + p1 * q1;
        sb += p0 * q1 - p1 * q0;
    }
    a = sa / spp;
    b = sb / spp;
    if (!(a * a + b * b > 1e-12) || !isfinite(a) || !isfinite(b)) return -1.0;
    out->angle = atan2(b, a);
    out->log_scale = 0.5 * log(a * a + b * b);
    out->tx = mq[0] - (a * mp[0] - b * mp[1]);
    out->ty = mq[1] - (b * mp[0] + a * mp[1]);
    for (k = 0; k < n; k++) {
        double u = a * px[k][0] - b * px[k][1] + out->tx - qx[k][0];
        double v = b * px[k][0] + a * px[k][1] + out->ty - qx[k][1];
        res += u * u + v * v;
    }
    return sqrt(res / n);
}

/* RMS displacement of the frame's corners under the similarity m, px. */
double home__stab_corner_motion(const home_stab *st, const home_stab_sim *m)
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
