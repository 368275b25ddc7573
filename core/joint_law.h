/*
 * joint_law.h - the cohesive law of a joint at one integration point, shared
 * by the 2D joint (joint.c, two Gauss points on an edge) and the 3D joint
 * (joint_tet.c, three points on a triangle). It lives here, once, so the two
 * dimensions cannot drift apart: the law is dimension-free once the sliding
 * is a magnitude along its own direction (2D passes the signed slide along
 * the edge, 3D the length of the sliding vector).
 *
 * Contract:
 *  - joint_point_measure: opening, sliding, the shear strength with its
 *    compression part (Mohr-Coulomb) and the damage D they ask for
 *    (mixed-mode: D = sqrt(Dn^2 + Ds^2), spans set by energy_I, energy_II).
 *  - joint_points_damage: the joint's damage, the largest its points ask
 *    for, never less than before, at most 1.
 *  - joint_point_respond: the point's tractions (sigma along the normal,
 *    positive opening only; tau along the sliding) for softening z, and its
 *    share (weight w) of the stored energy, of what the damage growth
 *    dissipated and of the frictional work over the last step.
 *  - joint_point_elastic: the undamaged elastic test on unnormalised
 *    projections (both scaled by the same positive `scale`).
 *  - joint_points_mode: how a joint that broke broke (tensile, shear or
 *    mixed), from the point that broke it (docs/physics.md has the rule).
 * The law itself is described in joint.c's header.
 */
#ifndef FDEM_JOINT_LAW_H
#define FDEM_JOINT_LAW_H

#include <math.h>

/* One material's cohesive constants for one joint. */
typedef struct joint_law {
    double k;                /* penalty / h: traction per unit opening or sliding */
    double tensile_strength; /* f_t */
    double cohesion;         /* c */
    double tan_phi;          /* tan of the friction angle */
    double energy_I, energy_II;
} joint_law;

/* What a joint's points book over one evaluation. */
typedef struct joint_energy {
    double stored;     /* held in the joint now */
    double dissipated; /* by damage growth (fracture account) */
    double friction;   /* by the sigma_c tan(phi) part of the shear traction */
    double handed;     /* compression energy of a joint that broke shut */
    int broke;         /* how the joint broke in this evaluation (JOINT_MODE_*), 0 if it holds */
} joint_energy;

/* Fracture modes of a joint that broke (contract 5.4, /events/mode). */
enum { JOINT_MODE_TENSILE = 1, JOINT_MODE_SHEAR = 2, JOINT_MODE_MIXED = 3 };

/* A break is tensile when the opening carries at least this share of
 * D^2 = Dn^2 + Ds^2 at the point that broke it, shear when the sliding
 * does, mixed otherwise. */
#define JOINT_MODE_SHARE 0.9

/* Munjiza's softening curve z(D), 1 at D <= 0, 0 at D >= 1. */
double joint_softening(double D);

/* The area under Munjiza's curve, integral of z(D) over [0, 1] (held to a
 * Simpson sum of joint_softening in test_joint.c). */
#define JOINT_Z_INTEGRAL 0.38630729474388764

/* The softening spans delta_c - delta_p (or s_c - s_p) for strength f,
 * elastic limit p = f / k and fracture energy G. A joint pulled apart in
 * one mode absorbs 1/2 f p while elastic and f span Z_INTEGRAL while it
 * softens; the span is chosen so that the two add up to G exactly. A joint
 * too soft for its G (1/2 f p >= G / 2) keeps a span of p, and absorbs more
 * than G: the fracture account then reports what it really dissipated. */
static inline double softening_span(double f, double p, double G)
{
    double span = (G - 0.5 * f * p) / (f * JOINT_Z_INTEGRAL);
    return span > p ? span : p;
}

/* One integration point of a joint leaving its elastic range or already
 * damaged. */
typedef struct joint_point {
    double delta, slide;   /* opening and sliding */
    double fs;             /* shear strength there: cohesion + compression tan(phi) */
    double D;              /* the damage its opening and sliding ask for */
} joint_point;

/* The opening and the sliding of point g beyond their elastic limits, each
 * over its softening span: Dn and Ds, 1 at the critical opening (sliding)
 * of a joint loaded in that mode alone. */
static inline void joint_point_parts(const joint_law *law, const joint_point *g, double *dn,
                                     double *ds)
{
    double k = law->k, ft = law->tensile_strength;
    double dp = ft / k, sp = g->fs / k;
    *dn = g->delta > dp ? (g->delta - dp) / softening_span(ft, dp, law->energy_I) : 0;
    *ds = fabs(g->slide) > sp ? (fabs(g->slide) - sp) / softening_span(g->fs, sp, law->energy_II)
                              : 0;
}

static inline void joint_point_measure(const joint_law *law, double delta, double slide,
                                       joint_point *g)
{
    g->delta = delta;
    g->slide = slide;
    g->fs = law->cohesion + (delta < 0 ? -law->k * delta * law->tan_phi : 0);
    double dn, ds;
    joint_point_parts(law, g, &dn, &ds);
    g->D = sqrt(dn * dn + ds * ds);
}

/* The mode of a joint whose points g[0 .. count) broke it: that of the
 * point asking for the most damage, by the share of its D^2 the opening
 * (Dn^2) and the sliding (Ds^2) make up (JOINT_MODE_SHARE). */
static inline int joint_points_mode(const joint_law *law, const joint_point *g, int count)
{
    int worst = 0;
    for (int i = 1; i < count; i++)
        if (g[i].D > g[worst].D) worst = i;
    double dn, ds;
    joint_point_parts(law, &g[worst], &dn, &ds);
    double n2 = dn * dn, s2 = ds * ds;
    if (n2 >= JOINT_MODE_SHARE * (n2 + s2)) return JOINT_MODE_TENSILE;
    if (s2 >= JOINT_MODE_SHARE * (n2 + s2)) return JOINT_MODE_SHEAR;
    return JOINT_MODE_MIXED;
}

/* The joint's damage after its points g[0 .. count) were measured: the
 * largest any asks for, never less than `before`, at most 1. */
static inline double joint_points_damage(const joint_point *g, int count, double before)
{
    double D = before;
    for (int i = 0; i < count; i++)
        if (g[i].D > D) D = g[i].D;
    return D > 1 ? 1 : D;
}

/* The stored energy psi = z(D) phi(delta, s) (plus 1/2 k delta^2 in
 * compression, which damage leaves alone): phi is the undamaged joint's
 * energy, 1/2 k x^2 up to the elastic limit and linear beyond it, for the
 * opening and the sliding alike. The tractions are f_t min(delta/delta_p, 1) z
 * and f_s clamp(s/s_p) z. Damage growing by dD dissipates -z'(D) phi dD,
 * which joint_point_respond books as (z_old - z_new) phi.
 *
 * Beyond the elastic slip s_p, phi grows with the cohesion c only: the rest
 * of the shear strength, sigma_c tan(phi), is friction, and its work is
 * dissipated as the joint slides (joint_friction_slip), not stored. Storing
 * it (f_s (|s| - s_p / 2), as before) made psi follow the strength when the
 * compression changed, without the normal force doing that work: the law is
 * not the gradient of such a psi (d tau / d delta != d sigma / d s), and
 * after the peak of a Brazilian disc 10.9 % of the work went to no account. */
static inline double joint_phi(const joint_law *law, const joint_point *g)
{
    double k = law->k, ft = law->tensile_strength;
    double dp = ft / k, sp = g->fs / k, phi = 0;
    if (g->delta > 0)
        phi += g->delta <= dp ? 0.5 * k * g->delta * g->delta : ft * (g->delta - 0.5 * dp);
    double s = fabs(g->slide);
    phi += s <= sp ? 0.5 * k * s * s : 0.5 * k * sp * sp + law->cohesion * (s - sp);
    return phi;
}

/* The slide beyond the elastic limit s_p that the last step added at a
 * point (negative when it slid back toward s_p), on the side the joint is
 * on now; the frictional traction sigma_c tan(phi) z works through it.
 * slide_before is the sliding a step ago (the step's relative displacement
 * taken off the current one) along the current sliding direction. Zero
 * within the elastic limit. */
static inline double joint_friction_slip(const joint_point *g, double k, double slide_before)
{
    double sp = g->fs / k, s = fabs(g->slide);
    if (!(s > sp)) return 0;
    double side = g->slide > 0 ? 1 : -1;
    return s - fmax(side * slide_before, sp);
}

/* Tractions at a point for damage with softening factor z. */
static inline void joint_point_traction(const joint_law *law, const joint_point *g, double z,
                                        double *sigma, double *tau)
{
    double k = law->k, ft = law->tensile_strength;
    double dp = ft / k, sp = g->fs / k;
    /* compression is resisted over the shut part of the face by each
     * dimension's kernel, integrated exactly */
    *sigma = g->delta > 0 ? ft * fmin(g->delta / dp, 1.0) * z : 0;
    double r = g->slide / sp;
    *tau = g->fs * (r > 1 ? 1 : r < -1 ? -1 : r) * z;
}

/* The tractions at point g (weight w: its share of the face) once the
 * joint's softening went from z_old to z, and its share of the energies. */
static inline void joint_point_respond(const joint_law *law, const joint_point *g, double w,
                                       double z_old, double z, double slide_before,
                                       joint_energy *e, double *sigma, double *tau)
{
    double phi = w * joint_phi(law, g);
    e->dissipated += (z_old - z) * phi;
    e->stored += z * phi;
    double frictional = g->fs - law->cohesion; /* sigma_c tan(phi) */
    e->friction += w * z * frictional * joint_friction_slip(g, law->k, slide_before);
    joint_point_traction(law, g, z, sigma, tau);
}

/* The elastic test of joint_point_measure for an undamaged joint, on
 * unnormalised projections: on = scale delta and sl = scale slide (the
 * gap against an unnormalised normal and tangent of length `scale`), so the
 * hot path needs neither unit vectors nor a division. */
static inline int joint_point_elastic(const joint_law *law, double scale, double on, double sl)
{
    double ksig = law->k * on;
    double shear_limit = law->cohesion * scale + (on < 0 ? -ksig * law->tan_phi : 0);
    return ksig <= law->tensile_strength * scale && fabs(law->k * sl) <= shear_limit;
}

#endif /* FDEM_JOINT_LAW_H */
