/*
 * joint_law.h - the cohesive law of a joint at one integration point, shared
 * by the 2D joint (joint.c, two Gauss points on an edge) and the 3D joint
 * (joint_tet.c, three points on a triangle). It lives here, once, so the two
 * dimensions cannot drift apart: the law is dimension-free once the sliding
 * is a vector in the face's own frame (2D passes the signed slide along the
 * edge as [s, 0], 3D the two components along the face's tangents).
 *
 * Contract:
 *  - joint_point_measure: opening, sliding, the shear strength with its
 *    compression part (Mohr-Coulomb), the return of the slip (Coulomb
 *    plasticity: the point's joint_slip, kept by the caller per point from
 *    step to step and zero while the joint is undamaged) and the damage D
 *    they ask for (mixed-mode: D = sqrt(Dn^2 + Ds^2), spans set by
 *    energy_I, energy_II).
 *  - joint_points_damage: the joint's damage, the largest its points ask
 *    for, never less than before, at most 1.
 *  - joint_point_respond: the point's tractions (sigma along the normal,
 *    positive opening only; tau along the face frame of the sliding) for
 *    softening z, and its share (weight w) of the stored energy and of what
 *    the damage growth and the slip dissipated (fracture, friction: each
 *    >= 0 at every evaluation).
 *  - joint_point_elastic: the undamaged elastic test on unnormalised
 *    projections (both scaled by the same positive `scale`).
 *  - joint_points_mode: how a joint that broke broke (tensile, shear or
 *    mixed), from the point that broke it (docs/physics.md has the rule).
 * The law itself is described in joint.c's header.
 */
#ifndef FDEM_JOINT_LAW_H
#define FDEM_JOINT_LAW_H

#include <float.h>
#include <math.h>

#include "math/norm2.h"

/* One material's cohesive constants for one joint, and two figures of
 * them that a damaged joint's points asked for again and again (a damaged
 * 3D joint worked out f_t / k four times a point): make it with
 * joint_law_make, which works them out once, by the same operations. */
typedef struct joint_law {
    double k;                /* penalty / h: traction per unit opening or sliding */
    double tensile_strength; /* f_t */
    double cohesion;         /* c */
    double tan_phi;          /* tan of the friction angle */
    double energy_I, energy_II;
    double dp;               /* f_t / k: the opening at the elastic limit */
    double span_I;           /* softening_span(f_t, dp, energy_I) */
} joint_law;

/* What a joint's points book over one evaluation. */
typedef struct joint_energy {
    double stored;     /* held in the joint now */
    double dissipated; /* by damage growth and cohesive slip (fracture account) */
    double friction;   /* by slip against the sigma_c tan(phi) part of the strength */
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

/* The softening before (z_old) and after (z) a joint's damage went from
 * `before` to D. z(D) is not monotone to the last bit, so damage that grew
 * must not book a release below zero: z is at most z_old. Damage that did
 * not grow (most steps of a damaged joint) needs one evaluation, not two:
 * a damaged 3D joint's exp and pow were 3 % of a split disc's run. */
static inline void joint_softening_step(double before, double D, double *z_old, double *z)
{
    *z_old = joint_softening(before);
    *z = D == before ? *z_old : fmin(*z_old, joint_softening(D));
}

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

static inline joint_law joint_law_make(double k, double tensile_strength, double cohesion,
                                       double tan_phi, double energy_I, double energy_II)
{
    joint_law law = {k, tensile_strength, cohesion, tan_phi, energy_I, energy_II, 0, 0};
    law.dp = tensile_strength / k;
    law.span_I = softening_span(tensile_strength, law.dp, energy_I);
    return law;
}

/* What one integration point keeps from step to step: its plastic slide
 * (the part of the sliding that friction let through, in the face's own
 * frame) and its accumulated slip (the length of the path that plastic
 * slide has run). An undamaged point keeps zeros. */
typedef struct joint_slip {
    double plastic[2];
    double path;
} joint_slip;

/* One integration point of a joint leaving its elastic range or already
 * damaged. The sliding is a vector in the face (2D: along the edge, its
 * second component 0; 3D: along the face's two tangents, joint_tet.c), so
 * one law serves both dimensions. */
typedef struct joint_point {
    double delta;    /* opening */
    double slide[2]; /* sliding, in the face's own frame */
    joint_slip slip; /* after this evaluation's return */
    double flow;     /* the plastic slip of this evaluation (>= 0) */
    double fs;       /* shear strength there: cohesion + compression tan(phi) */
    double D;        /* the damage its opening and its slip ask for */
} joint_point;

/* The opening beyond its elastic limit and the accumulated slip of point
 * g, each over its softening span: Dn and Ds, 1 at the critical opening
 * (sliding) of a joint loaded in that mode alone. Under a monotonic slide
 * at a constant compression the path is |s| - s_p, so the softening is
 * Munjiza's curve in the sliding, as before slip had a history; sliding
 * to and fro wears the cohesion down as one long slide would, so the
 * cohesion dissipates G_II at most, however the joint is cycled. */
static inline void joint_point_parts(const joint_law *law, const joint_point *g, double *dn,
                                     double *ds)
{
    double k = law->k, dp = law->dp, sp = g->fs / k;
    *dn = g->delta > dp ? (g->delta - dp) / law->span_I : 0;
    *ds = g->slip.path > 0 ? g->slip.path / softening_span(g->fs, sp, law->energy_II) : 0;
}

/* Coulomb slip as plasticity: the elastic trial slide s - plastic (the
 * plastic slide kept from the last evaluation) against the yield slide
 * s_p = f_s / k, returned onto it along its own direction. The slip then
 * always runs the way the shear traction points, so friction dissipates
 * at every step and every point, however the compression changes. Before,
 * the traction was f_s clamp(s / s_p): a joint that slid out under low
 * compression and was driven back under high compression gave back more
 * work than it took (18.7x the platen work as kinetic energy in an
 * undamped Brazilian disc). norm2(x, 0) is |x| exactly (math/norm2.h): a
 * 2D point gets the bits of a one-component return. */
static inline void joint_point_return(const joint_law *law, joint_point *g,
                                      const joint_slip *before)
{
    double e0 = g->slide[0] - before->plastic[0], e1 = g->slide[1] - before->plastic[1];
    double trial = norm2(e0, e1), sp = g->fs / law->k;
    g->slip = *before;
    g->flow = 0;
    if (!(trial > sp)) return;
    double flow = trial - sp, share = flow / trial;
    g->slip.plastic[0] += share * e0;
    g->slip.plastic[1] += share * e1;
    g->slip.path += flow;
    g->flow = flow;
}

/* Measures point g at opening delta and sliding slide[2] from the slip it
 * kept (before): its strength, its return and the damage it asks for. A
 * point that has slipped is damaged (D > 0, if only DBL_MIN), so an
 * undamaged joint has no slip to keep and the elastic fast paths, which
 * keep none, stay exact. */
static inline void joint_point_measure(const joint_law *law, double delta, const double slide[2],
                                       const joint_slip *before, joint_point *g)
{
    g->delta = delta;
    g->slide[0] = slide[0];
    g->slide[1] = slide[1];
    g->fs = law->cohesion + (delta < 0 ? -law->k * delta * law->tan_phi : 0);
    joint_point_return(law, g, before);
    double dn, ds;
    joint_point_parts(law, g, &dn, &ds);
    g->D = sqrt(dn * dn + ds * ds);
    if (g->D == 0 && g->slip.path > 0) g->D = DBL_MIN;
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

/* The stored energy psi = z(D) phi (plus 1/2 k delta^2 in compression,
 * which damage leaves alone), phi the undamaged joint's energy: for the
 * opening 1/2 k delta^2 up to the elastic limit and linear beyond it, for
 * the sliding 1/2 k |s - plastic|^2, the elastic slide's. The tractions are
 * f_t min(delta/delta_p, 1) z and z k (s - plastic), each the derivative of
 * psi at fixed damage and slip, so the joint stores exactly what they do
 * not dissipate. Damage growing from z_old to z dissipates
 * (z_old - z) phi; the slip dissipates z f_s per unit of flow, its
 * cohesive part (z c) as fracture, its frictional part (z sigma_c tan phi)
 * as friction. Each of the three is >= 0 at every step. */
static inline double joint_phi(const joint_law *law, const joint_point *g)
{
    double k = law->k, ft = law->tensile_strength, dp = law->dp, phi = 0;
    if (g->delta > 0)
        phi += g->delta <= dp ? 0.5 * k * g->delta * g->delta : ft * (g->delta - 0.5 * dp);
    double e0 = g->slide[0] - g->slip.plastic[0], e1 = g->slide[1] - g->slip.plastic[1];
    return phi + 0.5 * k * (e0 * e0 + e1 * e1);
}

/* Tractions at a point for damage with softening factor z: sigma along
 * the normal, tau[2] along the face frame of slide. */
static inline void joint_point_traction(const joint_law *law, const joint_point *g, double z,
                                        double *sigma, double tau[2])
{
    double k = law->k, ft = law->tensile_strength, dp = law->dp;
    /* compression is resisted over the shut part of the face by each
     * dimension's kernel, integrated exactly */
    *sigma = g->delta > 0 ? ft * fmin(g->delta / dp, 1.0) * z : 0;
    tau[0] = z * k * (g->slide[0] - g->slip.plastic[0]);
    tau[1] = z * k * (g->slide[1] - g->slip.plastic[1]);
}

/* The tractions at point g (weight w: its share of the face) once the
 * joint's softening went from z_old to z, and its share of the energies. */
static inline void joint_point_respond(const joint_law *law, const joint_point *g, double w,
                                       double z_old, double z, joint_energy *e, double *sigma,
                                       double tau[2])
{
    double phi = w * joint_phi(law, g);
    e->dissipated += (z_old - z) * phi;
    e->stored += z * phi;
    double worked = w * z * g->flow; /* against z f_s, the traction on the yield slide */
    e->dissipated += worked * law->cohesion;
    e->friction += worked * (g->fs - law->cohesion);
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
