/* Motion-model selection and predicted accuracy from a fit's Fisher information.
 *
 * A fit (the line fit or the photometric refinement) ends at an estimate p of 8 parameters with
 * its Fisher information F (the Gauss-Newton J^T J over the residual variance, so
 * cost(p') - cost(p) ~ (p' - p)^T F (p' - p) in units of the noise). Every simpler model is a
 * linear subspace p = o + B q of the same parameters, so its best estimate under that quadratic
 * is a k x k least-squares projection, its misfit Delta = (o + B q - p)^T F (o + B q - p), and
 * its covariance (B^T F B)^-1. The model chosen minimises Delta + penalty * k (BIC: the penalty
 * is ln of the number of observations), among the models the data determine (B^T F B positive
 * definite, and no more parameters than the caller says the data can fix); F need not be
 * invertible, so a scene whose lines leave a homography undetermined still gets the similarity
 * or translation they do fix.
 *
 * A fit's information sees independent noise, not errors its observations share (the photometric
 * refinement on the few edges of a dim frame: homographies 1-2 px off at a predicted 0.2 px,
 * their halves agreeing). With floor_px > 0 a homography chosen over the plain information must
 * also win with floor_px of error added to each corner coordinate, (F^-1 + floor^2 (J^T
 * J)^-1)^-1 with J the corners' Jacobian; otherwise the best simpler model by that measure
 * stands, and its predicted error holds the perspective it leaves out, as below.
 *
 * Spaces: the refinement's p are the homography's entries h0..h7 (h8 = 1) in normalised
 * coordinates; the line fit's are G = H^-T's. A model keeps the same form in both, except that the
 * translation and the perspective entries trade places: H = [A t; 0 1] has G = [A^-T 0; -(A^-1 t)^T
 * 1]. Similarity: A = [a -b; b a] in both (A^-T = A / (a^2 + b^2)). */
#include "home_internal.h"
#include <math.h>
#include <string.h>

/* Solve a x = b (k x k SPD, row stride 8) by padding to the 8x8 solver; a is overwritten. */
/* The leading k x k block of a (row stride 8) padded to 8x8 with the identity. */
static void pad_identity(double *a, int k)
{
    int i;
    for (i = k; i < 8; i++) {
        memset(a + i * 8, 0, 8 * sizeof *a);
        a[i * 8 + i] = 1.0;
    }
    for (i = 0; i < k; i++) memset(a + i * 8 + k, 0, (size_t)(8 - k) * sizeof *a);
}

int home__solve_spd(double *a, double *b, int k)
{
    int i;
    pad_identity(a, k);
    for (i = k; i < 8; i++) b[i] = 0.0;
    return home__solve_spd8(a, b);
}

/* The model's subspace p = o + B q: basis columns (8 entries each) and offset; returns k. */
int home__model_basis(int space, int model, double *o, double basis[8][8])
{
    const int tx = space == HOME__SPACE_G ? 6 : 2, ty = space == HOME__SPACE_G ? 7 : 5;
    const int px = space == HOME__SPACE_G ? 2 : 6, py = space == HOME__SPACE_G ? 5 : 7;
    int k = 0, i;
    memset(basis, 0, 64 * sizeof basis[0][0]);
    memset(o, 0, 8 * sizeof *o);
    switch (model) {
    case HOME_MODEL_IDENTITY:
        o[0] = o[4] = 1.0;
        break;
    case HOME_MODEL_TRANSLATION:
        o[0] = o[4] = 1.0;
        basis[k++][tx] = 1.0;
        basis[k++][ty] = 1.0;
        break;
    case HOME_MODEL_SIMILARITY:
        basis[k][0] = basis[k][4] = 1.0;
        k++; /* a scale, and a rigid motion's parameters: */
        /* fall through */
    case HOME__MODEL_RIGID:
        if (model == HOME__MODEL_RIGID) o[0] = o[4] = 1.0;
        basis[k][1] = -1.0;
        basis[k][3] = 1.0;
        k++;
        basis[k++][tx] = 1.0;
        basis[k++][ty] = 1.0;
        break;
    case HOME_MODEL_AFFINE:
        for (i = 0; i < 8; i++)
            if (i != px && i != py) basis[k++][i] = 1.0;
        break;
    default:
        for (i = 0; i < 8; i++) basis[k++][i] = 1.0;
        break;
    }
    return k;
}

/* d(corner)/dp of the image corners (px) for a pixel-space homography h (h8 = 1) whose
 * parameters p are its normalised entries (pixel = scale * u + centre): row 2c + axis. */
static void corner_jacobian(const double *hn, double scale, double cx, double cy, double jac[8][8])
{
    const double hu = cx / scale, hv = cy / scale;
    int c;
    for (c = 0; c < 4; c++) {
        const double u = (c & 1) ? hu : -hu, v = (c & 2) ? hv : -hv;
        const double w = hn[6] * u + hn[7] * v + 1.0;
        const double x = (hn[0] * u + hn[1] * v + hn[2]) / w;
        const double y = (hn[3] * u + hn[4] * v + hn[5]) / w;
        double *jx = jac[2 * c], *jy = jac[2 * c + 1];
        memset(jx, 0, 8 * sizeof *jx);
        memset(jy, 0, 8 * sizeof *jy);
        jx[0] = u / w * scale; jx[1] = v / w * scale; jx[2] = 1.0 / w * scale;
        jx[6] = -x * u / w * scale; jx[7] = -x * v / w * scale;
        jy[3] = u / w * scale; jy[4] = v / w * scale; jy[5] = 1.0 / w * scale;
        jy[6] = -y * u / w * scale; jy[7] = -y * v / w * scale;
    }
}

/* RMS over the four image corners of the distance between two normalised homographies, px. */
static double corner_rms_distance(const double *ha, const double *hb, const home__model_problem *mp)
{
    const double hu = mp->cx / mp->scale, hv = mp->cy / mp->scale;
    double sum = 0.0;
    int c;
    for (c = 0; c < 4; c++) {
        const double u = (c & 1) ? hu : -hu, v = (c & 2) ? hv : -hv;
        const double wa = ha[6] * u + ha[7] * v + 1.0, wb = hb[6] * u + hb[7] * v + 1.0;
        const double dx =
            (ha[0] * u + ha[1] * v + ha[2]) / wa - (hb[0] * u + hb[1] * v + hb[2]) / wb;
        const double dy =
            (ha[3] * u + ha[4] * v + ha[5]) / wa - (hb[3] * u + hb[4] * v + hb[5]) / wb;
        sum += dx * dx + dy * dy;
    }
    return mp->scale * sqrt(sum / 4.0);
}

/* G = H^-T normalised to g8 = 1 (the same map takes G back to H); 0 when singular. */
int home__inverse_transpose8(const double *p, double *out)
{
    const double m[9] = {p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], 1.0};
    double c[9], d;
    int k;
    home__cofactors3(m, c);
    d = c[8];
    if (!(fabs(d) > 1e-12) || !isfinite(d)) return 0;
    for (k = 0; k < 8; k++) out[k] = c[k] / d;
    return 1;
}

/* The normalised homography of parameters p (h0..h7, h8 = 1). */
static int to_h(int space, const double *p, double *hn)
{
    if (space == HOME__SPACE_H) {
        memcpy(hn, p, 8 * sizeof *hn);
        return 1;
    }
    return home__inverse_transpose8(p, hn);
}

/* Predicted RMS corner error (px) of a model's estimate p with information n_mat = B^T F B:
 * sqrt(mean over the corners of J_c B (B^T F B)^-1 B^T J_c^T); infinite when it cannot say. */
static double model_sigma(const home__model_problem *mp, const double basis[8][8], int k,
                          const double *n_mat, const double *p)
{
    double dh_dp[8][8], cj[8][8], hn[8], var = 0.0;
    int i, j, c;
    if (!to_h(mp->space, p, hn)) return INFINITY;
    corner_jacobian(hn, mp->scale, mp->cx, mp->cy, cj);
    if (mp->space == HOME__SPACE_G) {
        /* d corner / d g = d corner / d h  d h / d g, the latter by central differences */
        double p1[8], p2[8], h1[8], h2[8];
        for (j = 0; j < 8; j++) {
            const double eps = 1e-6;
            memcpy(p1, p, sizeof p1);
            memcpy(p2, p, sizeof p2);
            p1[j] += eps;
            p2[j] -= eps;
            if (!home__inverse_transpose8(p1, h1) || !home__inverse_transpose8(p2, h2))
                return INFINITY;
            for (i = 0; i < 8; i++) dh_dp[i][j] = (h1[i] - h2[i]) / (2 * eps);
        }
        for (c = 0; c < 8; c++) {
            double row[8];
            for (j = 0; j < 8; j++) {
                double s = 0.0;
                for (i = 0; i < 8; i++) s += cj[c][i] * dh_dp[i][j];
                row[j] = s;
            }
            memcpy(cj[c], row, sizeof row);
        }
    }
    if (k > 0) {
        double l[64];
        memcpy(l, n_mat, sizeof l);
        pad_identity(l, k);
        if (!home__cholesky8(l)) return INFINITY;
        for (c = 0; c < 8; c++) {
            double jq[8] = {0}, z[8], v = 0.0;
            for (i = 0; i < k; i++) {
                double s = 0.0;
                for (j = 0; j < 8; j++) s += basis[i][j] * cj[c][j];
                jq[i] = s;
            }
            memcpy(z, jq, sizeof z);
            home__cholesky_solve8(l, z);
            for (i = 0; i < k; i++) v += jq[i] * z[i];
            var += v;
        }
    }
    return sqrt(var / 4.0); /* RMS over the four corners of the 2-D error */
}

/* The information `info` with floor_px of independent error added to each corner coordinate:
 * with J the corners' Jacobian and G = J^T J / floor^2 (the floor's information), (F^-1 +
 * G^-1)^-1 = G (F + G)^-1 F. 0 when F + G is not positive definite. */
static int floored_information(const home__model_problem *mp, double *out)
{
    double cj[8][8], g[64], l[64];
    const double w = 1.0 / (mp->floor_px * mp->floor_px);
    int i, j, k;
    corner_jacobian(mp->p, mp->scale, mp->cx, mp->cy, cj);
    for (i = 0; i < 8; i++)
        for (j = 0; j < 8; j++) {
            double v = 0.0;
            for (k = 0; k < 8; k++) v += cj[k][i] * cj[k][j];
            g[i * 8 + j] = v * w;
            l[i * 8 + j] = g[i * 8 + j] + mp->info[i * 8 + j];
        }
    if (!home__cholesky8(l)) return 0;
    for (j = 0; j < 8; j++) { /* (F + G)^-1 F column by column, then G times it */
        double col[8];
        for (i = 0; i < 8; i++) col[i] = mp->info[i * 8 + j];
        home__cholesky_solve8(l, col);
        for (i = 0; i < 8; i++) {
            double v = 0.0;
            for (k = 0; k < 8; k++) v += g[i * 8 + k] * col[k];
            out[i * 8 + j] = v;
        }
    }
    return 1;
}

/* n_mat = B^T F B and rhs = B^T F (p - o) of a model's subspace (k x k, row stride 8). */
static void projected_normal(const home__model_problem *mp, const double basis[8][8], int k,
                             const double *o, double *n_mat, double *rhs)
{
    double fd[8];
    int i, j, a, b;
    memset(n_mat, 0, 64 * sizeof *n_mat);
    memset(rhs, 0, 8 * sizeof *rhs);
    for (i = 0; i < 8; i++) {
        double s = 0.0;
        for (j = 0; j < 8; j++) s += mp->info[i * 8 + j] * (mp->p[j] - o[j]);
        fd[i] = s;
    }
    for (i = 0; i < k; i++) {
        double s = 0.0;
        for (j = 0; j < 8; j++) s += basis[i][j] * fd[j];
        rhs[i] = s;
        for (j = 0; j < k; j++) {
            double t = 0.0;
            for (a = 0; a < 8; a++) {
                if (basis[i][a] == 0.0) continue;
                for (b = 0; b < 8; b++) t += basis[i][a] * mp->info[a * 8 + b] * basis[j][b];
            }
            n_mat[i * 8 + j] = t;
        }
    }
}

/* d^T m d (8 x 8). */
static double quadratic8(const double *d, const double *m)
{
    double v = 0.0;
    int i, j;
    for (i = 0; i < 8; i++)
        for (j = 0; j < 8; j++) v += d[i] * m[i * 8 + j] * d[j];
    return v;
}

/* The basis a model stands for in this problem: a rigid motion in the similarity's place. */
static int basis_model(const home__model_problem *mp, int model)
{
    return mp->rigid && model == HOME_MODEL_SIMILARITY ? HOME__MODEL_RIGID : model;
}

int home__select_model(const home__model_problem *mp, home__model_choice *out)
{
    enum { MODELS = HOME_MODEL_HOMOGRAPHY + 1 };
    double basis[8][8], o[8], n_mat[64], rhs[8], weigh[64];
    double p_of[MODELS][8], delta_of[MODELS], floored_of[MODELS];
    int k_of[MODELS], model, i, j, best = -1, general = -1, floored;
    double best_score = INFINITY;

    out->model = -1;
    out->sigma_px = INFINITY;
    /* the floor weighs only a homography against the simpler models (an information it cannot
     * be added to leaves the plain choice) */
    floored = mp->floor_px > 0.0 && mp->space == HOME__SPACE_H &&
              mp->max_model == HOME_MODEL_HOMOGRAPHY && floored_information(mp, weigh);
    for (model = HOME_MODEL_IDENTITY; model <= mp->max_model; model++) {
        double q[8], diff[8], a_copy[64];
        const int k = home__model_basis(mp->space, basis_model(mp, model), o, basis);
        k_of[model] = -1; /* not determined by the data */
        if (k > mp->max_params) break;
        /* q = (B^T F B)^-1 B^T F (p - o) */
        projected_normal(mp, (const double (*)[8])basis, k, o, n_mat, rhs);
        memcpy(a_copy, n_mat, sizeof a_copy);
        memcpy(q, rhs, sizeof q);
        if (k > 0 && !home__solve_spd(a_copy, q, k)) continue;
        memcpy(p_of[model], o, sizeof o);
        for (i = 0; i < k; i++)
            for (j = 0; j < 8; j++) p_of[model][j] += q[i] * basis[i][j];
        for (i = 0; i < 8; i++) diff[i] = p_of[model][i] - mp->p[i];
        delta_of[model] = quadratic8(diff, mp->info);
        if (!isfinite(delta_of[model])) continue;
        floored_of[model] = floored ? quadratic8(diff, weigh) : delta_of[model];
        k_of[model] = k;
        general = model; /* the most general determined model so far */
        if (delta_of[model] + mp->penalty * k < best_score) {
            best_score = delta_of[model] + mp->penalty * k;
            best = model;
        }
    }
    if (best < 0) return 0;
    /* a homography must also stand out of the corners' error floor: a translation, similarity
     * or affine takes its place when it scores lower with the floor (not the identity: a small
     * motion does not become none because of a floor) */
    if (best == HOME_MODEL_HOMOGRAPHY && floored) {
        double floored_best = mp->penalty * k_of[best];
        const int chosen = best;
        for (model = HOME_MODEL_TRANSLATION; model < HOME_MODEL_HOMOGRAPHY; model++)
            if (k_of[model] >= 0 && floored_of[model] + mp->penalty * k_of[model] < floored_best) {
                floored_best = floored_of[model] + mp->penalty * k_of[model];
                best = model;
            }
        if (best != chosen) delta_of[best] = floored_of[best];
    }
    memcpy(out->p, p_of[best], sizeof out->p);
    out->model = best;
    out->delta = delta_of[best];
    /* the chosen model must explain the data no worse than an exact homography would, at its
     * cost in parameters (matters when the homography is undetermined); a cap below the
     * homography asks for the best such model whatever its misfit */
    if (best < HOME_MODEL_HOMOGRAPHY && mp->max_model == HOME_MODEL_HOMOGRAPHY &&
        !(out->delta <= mp->penalty * (8 - k_of[best])))
        return 0;
    (void)home__model_basis(mp->space, basis_model(mp, best), o, basis);
    projected_normal(mp, (const double (*)[8])basis, k_of[best], o, n_mat, rhs);
    out->sigma_px = model_sigma(mp, (const double (*)[8])basis, k_of[best], n_mat, out->p);
    if (!isfinite(out->sigma_px)) return 0;
    /* a simpler model's error also holds its misfit: the RMS corner distance to the most
     * general determined estimate (a static scene's identity is off by the motion it ignores) */
    if (general > best) {
        double ha[8], hb[8];
        if (to_h(mp->space, out->p, ha) && to_h(mp->space, p_of[general], hb)) {
            const double bias = corner_rms_distance(ha, hb, mp);
            out->sigma_px = sqrt(out->sigma_px * out->sigma_px + bias * bias);
        }
    }
    return 1;
}

const char *home_model_name(int model)
{
    switch (model) {
    case HOME_MODEL_IDENTITY: return "identity";
    case HOME_MODEL_TRANSLATION: return "translation";
    case HOME_MODEL_SIMILARITY: return "similarity";
    case HOME_MODEL_AFFINE: return "affine";
    case HOME_MODEL_HOMOGRAPHY: return "homography";
    default: return "unknown";
    }
}

void home__project_normal(const double basis[8][8], int k, const double *jtj, const double *jte,
                          double *jtj_q, double *jte_q)
{
    int i, j, a, b;
    for (i = 0; i < 8; i++) {
        double s = 0.0;
        for (a = 0; a < 8 && i < k; a++) s += basis[i][a] * jte[a];
        jte_q[i] = s;
        for (j = 0; j < 8; j++) {
            double t = 0.0;
            if (i < k && j < k) {
                for (a = 0; a < 8; a++) {
                    if (basis[i][a] == 0.0) continue;
                    for (b = 0; b < 8; b++) t += basis[i][a] * jtj[a * 8 + b] * basis[j][b];
                }
            } else {
                t = i == j ? 1.0 : 0.0; /* unused coordinates: identity, no step */
            }
            jtj_q[i * 8 + j] = t;
        }
    }
}
