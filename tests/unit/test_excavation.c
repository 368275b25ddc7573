/*
 * test_excavation.c - stages and excavation (contract 6.1, PHYSICS.md
 * "Excavation under in-situ stress"), in 2D and 3D:
 *  - a circular opening excavated from a plate under in-situ stress
 *    (sigma_v vertical, sigma_h = K0 sigma_v, compression) reproduces
 *    Kirsch's hoop stress at the wall and the displacement the excavation
 *    induces there, at the crown and the sidewall, once settled, for
 *    K0 = 1.5 and 1, with a slow release (relax long against the wave
 *    transit) and a sudden one (relax 0);
 *  - 3D: the same opening through a block held in plane strain (rollers on
 *    both end faces), against the same closed forms;
 *  - the energy account closes through an excavation (excavated energy);
 *  - the run is bit for bit the same on one and two threads and across a
 *    checkpoint taken before or during the release;
 *  - the unloading forces hold what the joints of a fracturing block and
 *    the weight of the mass that leaves the shared nodes held (the
 *    remaining body does not notice the excavation at its first step);
 *  - a support pressure on the opening acts on its wall once excavated
 *    (Kirsch plus Lame's internal-pressure term);
 *  - an excavated joint keeps the damage it had; the penalty energy of the
 *    contact pairs of a removed element leaves with it;
 *  - stage-only constraints act during their stage only;
 *  - bad stages are refused with a message naming the stage.
 *
 * The closed forms (plane strain, tension positive in the engine, the far
 * field written here as compressions p_h along x and p_v along y; the
 * polar angle theta from x; G the shear modulus, nu Poisson's ratio):
 *  - hoop stress at the wall (Kirsch): sigma_theta(a, theta) = -[(p_h +
 *    p_v) - 2 (p_h - p_v) cos 2 theta], so -(3 p_h - p_v) at the crown
 *    (theta = 90) and -(3 p_v - p_h) at the sidewall (theta = 0);
 *  - displacement the excavation induces at the wall: the isotropic part
 *    P = (p_h + p_v) / 2 unloading the hole gives u_r = -P a^2 / (2 G r);
 *    the deviatoric part S = (p_v - p_h) / 2 (far field xx = +S, yy = -S
 *    once P is taken out) gives, from Kirsch's displacement field
 *    2 G u_r = S cos 2 theta [r + (kappa + 1) a^2 / r - a^4 / r^3]
 *    (kappa = 3 - 4 nu) less the uniform field's 2 G u_r = S r cos 2
 *    theta, 2 G u_r = S cos 2 theta [(kappa + 1) a^2 / r - a^4 / r^3].
 *    At r = a: u_r = a / (2 G) [-P + (3 - 4 nu) S cos 2 theta]. The model
 *    starts at rest in its in-situ stress with zero displacement, so its
 *    displacement is what the excavation induces.
 *
 * The tunnel model and how the wall figures are read off it:
 * tunnel_model.h.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "build_model.h"
#include "check.h"
#include "joint/joint.h"
#include "model/model.h"
#include "tunnel_model.h"

/* ------------------------------------------------------------------ tests */

#define T_RELAX 0.04   /* about 6 shear-wave transits of R */
#define T_END 0.12

/* One tunnel against Kirsch; returns what it measured. tol: relative. */
static kirsch tunnel_against_kirsch(const tunnel_spec *s, double tol)
{
    tunnel t = tunnel_build(s, T_END);
    run_to(t.m, T_EXCAVATE * 0.5);
    CHECK(fdem_stage_index(t.m) == 0, "stage %d in stage 0's time", fdem_stage_index(t.m));
    CHECK(fdem_element_active(t.m) == NULL, "elements inactive before any excavation");
    double u_before = fabs(radial_displacement(&t, t.crown));
    run_to(t.m, T_END);
    CHECK(fdem_stage_index(t.m) == 1, "stage %d at the end", fdem_stage_index(t.m));
    const uint8_t *active = fdem_element_active(t.m);
    int inactive = 0;
    for (int e = 0; active && e < t.m->elem_count; e++) inactive += !active[e];
    CHECK(inactive == t.hole_count, "%d elements excavated, want %d", inactive, t.hole_count);
    kirsch want = kirsch_of(s->k0, s->support), got = measured(&t, s);
    double ke = kinetic_energy(t.m), elastic = fdem_get_energy(t.m).elastic;
    printf("  %dD K0 %.2g relax %.3g support %.3g MPa: hoop crown %.4g (Kirsch %.4g, %+.2f %%), sidewall %.4g "
           "(%.4g, %+.2f %%); u crown %.4g mm (%.4g, %+.2f %%), sidewall %.4g mm (%.4g, %+.2f %%); "
           "kinetic/elastic %.2g; u before %.2g mm\n",
           s->dim, s->k0, s->relax, s->support / 1e6, got.hoop_crown / 1e6, want.hoop_crown / 1e6,
           100 * (got.hoop_crown / want.hoop_crown - 1), got.hoop_sidewall / 1e6,
           want.hoop_sidewall / 1e6, 100 * (got.hoop_sidewall / want.hoop_sidewall - 1),
           got.u_crown * 1e3, want.u_crown * 1e3, 100 * (got.u_crown / want.u_crown - 1),
           got.u_sidewall * 1e3, want.u_sidewall * 1e3, 100 * (got.u_sidewall / want.u_sidewall - 1),
           ke / elastic, u_before * 1e3);
    CHECK(u_before < 1e-6 * fabs(want.u_crown), "the model moved before the excavation: %g m",
          u_before);
    CHECK(ke < 1e-6 * elastic, "not settled: kinetic %g J/m of elastic %g J/m", ke, elastic);
    CHECK_REL(got.hoop_crown, want.hoop_crown, tol);
    CHECK_REL(got.hoop_sidewall, want.hoop_sidewall, tol);
    CHECK_REL(got.u_crown, want.u_crown, tol);
    CHECK_REL(got.u_sidewall, want.u_sidewall, tol);
    tunnel_free(&t);
    return got;
}

static void kirsch_2d_k0_1_5_slow(void)
{
    tunnel_spec s = {2, CELLS, R_OUT, 1.5, T_RELAX, 0.05, 1, 0};
    tunnel_against_kirsch(&s, 0.05);
}

static void kirsch_2d_k0_1_slow(void)
{
    tunnel_spec s = {2, CELLS, R_OUT, 1.0, T_RELAX, 0.05, 1, 0};
    tunnel_against_kirsch(&s, 0.05);
}

/* relax 0: the dynamic release settles to the state of the slow one. */
static void kirsch_2d_sudden_settles_alike(void)
{
    for (int k = 0; k < 2; k++) {
        const double k0 = k ? 1.0 : 1.5;
        tunnel_spec slow = {2, CELLS, R_OUT, k0, T_RELAX, 0.05, 1, 0};
        tunnel_spec fast = slow;
        fast.relax = 0;
        kirsch a = tunnel_against_kirsch(&slow, 0.05), b = tunnel_against_kirsch(&fast, 0.05);
        CHECK_REL(b.hoop_crown, a.hoop_crown, 0.01);
        CHECK_REL(b.hoop_sidewall, a.hoop_sidewall, 0.01);
        CHECK_REL(b.u_crown, a.u_crown, 0.01);
        CHECK_REL(b.u_sidewall, a.u_sidewall, 0.01);
    }
}

static void kirsch_3d_plane_strain(void)
{
    tunnel_spec s = {3, CELLS, R_OUT, 1.5, T_RELAX, 0.05, 1, 0};
    tunnel_against_kirsch(&s, 0.10);
}

/* A support pressure on the wall, acting from the excavation on (the wall's
 * facets are interior until then): Kirsch plus Lame's internal-pressure
 * term, 2D and 3D, at the tolerances of the unsupported tunnel. Before
 * boundary loads followed the opening, such a pressure selected no
 * boundary edge and the model was refused at finalize. */
static void kirsch_with_support_pressure(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        tunnel_spec s = {dim, CELLS, R_OUT, 1.5, T_RELAX, 0.05, 1, 0.3 * P_V};
        tunnel_against_kirsch(&s, dim == 2 ? 0.05 : 0.10);
    }
}

/* --------------------------------------------------------- bits and energy */

#define SMALL_CELLS 8
#define SMALL_OUTER 5.0
#define SMALL_END 0.012
#define SMALL_RELAX 0.004

static int same_bits(const fdem_model *a, const fdem_model *b)
{
    size_t nb = sizeof(double) * (size_t)a->dim * (size_t)a->node_count;
    fdem_energy ea = fdem_get_energy(a), eb = fdem_get_energy(b);
    return memcmp(a->pos, b->pos, nb) == 0 && memcmp(a->vel, b->vel, nb) == 0 &&
           memcmp(&ea, &eb, sizeof ea) == 0;
}

/* One and two threads, and a run checkpointed during the release and
 * restored into a model built afresh, all end in the bits of the one that
 * never stopped; 2D and 3D, with damping (its history crosses the
 * checkpoint). */
static void same_bits_on_threads_and_across_a_checkpoint(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        /* threads: a mesh of several element blocks (scatter_plan.h), so
         * that two threads do share the element loop */
        tunnel_spec big = {dim, dim == 2 ? 32 : 16, R_OUT, 1.5, SMALL_RELAX, 0.05, 1, 0};
        tunnel one_big = tunnel_build(&big, SMALL_END);
        big.threads = 2;
        tunnel two_big = tunnel_build(&big, SMALL_END);
        CHECK(one_big.m->elem_plan.block_count > 2, "%dD: %d element blocks", dim,
              one_big.m->elem_plan.block_count);
        run_to(one_big.m, T_EXCAVATE + SMALL_RELAX);
        run_to(two_big.m, T_EXCAVATE + SMALL_RELAX);
        CHECK(fdem_element_active(one_big.m) != NULL, "%dD: nothing excavated", dim);
        CHECK(same_bits(one_big.m, two_big.m), "%dD: two threads differ from one", dim);
        tunnel_free(&one_big);
        tunnel_free(&two_big);
        /* checkpoints: the small tunnel */
        tunnel_spec s = {dim, SMALL_CELLS, SMALL_OUTER, 1.5, SMALL_RELAX, 0.05, 1, 0};
        tunnel one = tunnel_build(&s, SMALL_END);
        tunnel first = tunnel_build(&s, SMALL_END), second = tunnel_build(&s, SMALL_END);
        run_to(one.m, SMALL_END);
        /* a checkpoint from before the excavation, restored into a fresh
         * model and into one that has excavated already */
        run_to(first.m, 0.5 * T_EXCAVATE);
        size_t early_size = fdem_checkpoint_size(first.m);
        unsigned char *early = malloc(early_size);
        CHECK(fdem_checkpoint_write(first.m, early, early_size) == 0, "write before");
        tunnel fresh = tunnel_build(&s, SMALL_END);
        fdem_error early_err;
        if (fdem_checkpoint_read(fresh.m, early, early_size, &early_err))
            build_die("restore before", &early_err);
        run_to(fresh.m, SMALL_END);
        CHECK(same_bits(fresh.m, one.m), "%dD: restored from before the excavation, differs", dim);
        if (fdem_checkpoint_read(fresh.m, early, early_size, &early_err))
            build_die("restore back", &early_err);
        CHECK(fdem_element_active(fresh.m) == NULL, "%dD: restored back, still excavated", dim);
        run_to(fresh.m, SMALL_END);
        CHECK(same_bits(fresh.m, one.m), "%dD: restored back to before the excavation, differs",
              dim);
        free(early);
        tunnel_free(&fresh);
        run_to(first.m, T_EXCAVATE + 0.5 * SMALL_RELAX); /* during the release */
        CHECK(fdem_element_active(first.m) != NULL, "%dD: not excavated yet", dim);
        size_t size = fdem_checkpoint_size(first.m);
        unsigned char *buf = malloc(size);
        fdem_error err;
        CHECK(fdem_checkpoint_write(first.m, buf, size) == 0, "write");
        CHECK(fdem_checkpoint_version(buf, size) == FDEM_CHECKPOINT_VERSION, "version");
        if (fdem_checkpoint_read(second.m, buf, size, &err)) build_die("restore", &err);
        CHECK(fdem_stage_index(second.m) == 1, "%dD: restored stage %d", dim,
              fdem_stage_index(second.m));
        CHECK(fdem_element_active(second.m) &&
                  memcmp(fdem_element_active(second.m), fdem_element_active(first.m),
                         (size_t)first.m->elem_count) == 0,
              "%dD: restored excavation differs", dim);
        CHECK(fdem_checkpoint_read(second.m, buf, size - 1, &err) < 0, "truncated accepted");
        if (fdem_checkpoint_read(second.m, buf, size, &err)) build_die("restore", &err);
        run_to(first.m, SMALL_END);
        run_to(second.m, SMALL_END);
        CHECK(same_bits(first.m, one.m), "%dD: the checkpointed run differs before restoring", dim);
        CHECK(same_bits(second.m, one.m), "%dD: the restored run differs", dim);
        free(buf);
        tunnel_free(&one);
        tunnel_free(&first);
        tunnel_free(&second);
    }
}

/* The balance closes through the excavation: the strain energy the hole
 * held goes to `excavated`, the unloading forces' work to external work;
 * what is left is the time discretisation, against the energies in play. */
static void energy_closes_through_the_excavation(void)
{
    for (int dim = 2; dim <= 3; dim++)
        for (int sudden = 0; sudden < 2; sudden++) {
            tunnel_spec s = {dim, SMALL_CELLS, SMALL_OUTER, 1.5, sudden ? 0 : SMALL_RELAX, 0.05, 1, 0};
            tunnel t = tunnel_build(&s, SMALL_END);
            run_to(t.m, T_EXCAVATE * 0.5);
            fdem_energy e0 = fdem_get_energy(t.m);
            run_to(t.m, SMALL_END);
            fdem_energy e = fdem_get_energy(t.m);
            double scale = fabs(e.excavated) + fabs(e.external_work) + fabs(e.damping) +
                           fabs(e.elastic - e0.elastic);
            printf("  %dD relax %g: excavated %.6g, external %.6g, damping %.6g, elastic %.6g -> "
                   "%.6g, kinetic %.3g, residual %.3g J/m (%.2g of the energies in play)\n",
                   dim, s.relax, e.excavated, e.external_work, e.damping, e0.elastic, e.elastic,
                   e.kinetic, e.residual, e.residual / scale);
            CHECK(e.excavated > 0, "%dD: nothing booked as excavated", dim);
            CHECK(fabs(e.residual) < 1e-3 * scale, "%dD relax %g: residual %g of %g", dim,
                  s.relax, e.residual, scale);
            tunnel_free(&t);
        }
}

/* --------------------------------------------------- joints and contact */

/* A fracturing block on a fixed base, loaded by gravity for a while, with
 * the elements of its upper middle excavated; the twin excavates nothing.
 * In a fracturing part every element has nodes of its own, so the
 * remaining nodes keep their masses, and at the excavation step (s = 0)
 * the unloading forces stand in for what the removed elements pulled
 * through their joints: the remaining nodes' velocity change over that
 * step is the twin's to round-off (an excavated joint opens no crack, so
 * no contact appears between the remaining elements around it). Without
 * the joints' share in the unloading forces the change is off by 3-4
 * times the largest change (measured by leaving it out). */
static void fracturing_block_keeps_its_forces(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *twin[2];
        const double t_dig = 1e-3; /* about three wave transits: the joints carry the weight */
        for (int k = 0; k < 2; k++) {
            fdem_model *m = fdem_model_create();
            fdem_error err;
            if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
            int mat = build_fracturing_rock(m, 0);
            const double size[3] = {1, 1, 1};
            const int div[3] = {4, 4, 2};
            build_box_part(m, mat, dim, size, div, 1);
            fdem_constraint_def base = {0};
            base.select = FDEM_SELECT_BOX;
            for (int d = 0; d < dim; d++) {
                base.box[d] = -1;
                base.box[dim + d] = 2;
            }
            base.box[dim + dim - 1] = 1e-9;
            base.kind = FDEM_CONSTRAINT_FIX;
            base.fix_x = base.fix_y = base.fix_z = 1;
            add_constraint(m, &base);
            const double g[3] = {0, dim == 2 ? -2000 : 0, dim == 3 ? -2000 : 0};
            fdem_set_gravity_v(m, g);
            int32_t *dig = malloc(sizeof(int32_t) * (size_t)m->elem_count);
            int count = 0;
            for (int e = 0; e < m->elem_count && k == 0; e++) {
                double c[3] = {0, 0, 0};
                const int32_t *n = m->elem_node + (size_t)(dim + 1) * (size_t)e;
                for (int q = 0; q <= dim; q++)
                    for (int d = 0; d < dim; d++) c[d] += m->pos0[dim * n[q] + d] / (dim + 1);
                if (c[0] > 0.25 && c[0] < 0.75 && c[dim - 1] > 0.5) dig[count++] = e;
            }
            fdem_stage_def s0 = {.end = t_dig}, s1 = {.end = 1, .relax = 1, .excavate = dig,
                                                      .excavate_count = count};
            fdem_add_stage(m, &s0, &err);
            if (fdem_add_stage(m, &s1, &err) < 0) build_die("stage", &err);
            free(dig);
            build_finalize(m, 0.5);
            twin[k] = m;
        }
        fdem_model *a = twin[0], *b = twin[1];
        fdem_error err;
        while (fdem_get_time(a) < t_dig) {
            fdem_step(a, &err);
            fdem_step(b, &err);
        }
        CHECK(same_bits(a, b), "%dD: the twins differ before the excavation", dim);
        const size_t n = (size_t)dim * (size_t)a->node_count;
        double *va = malloc(sizeof(double) * n), *vb = malloc(sizeof(double) * n);
        memcpy(va, a->vel, sizeof(double) * n);
        memcpy(vb, b->vel, sizeof(double) * n);
        double *shown = malloc(sizeof(double) * (size_t)a->joint_count);
        fdem_copy_joint_damage(a, shown);
        fdem_step(a, &err);
        fdem_step(b, &err);
        CHECK(fdem_element_active(a) && !fdem_element_active(b), "%dD: excavated the wrong one",
              dim);
        /* an excavated joint holds nothing, yet shows the damage it had
         * (it read 1, broken, before) */
        double *now = malloc(sizeof(double) * (size_t)a->joint_count);
        fdem_copy_joint_damage(a, now);
        int gone = 0, kept = 0;
        for (int j = 0; j < a->joint_count; j++) {
            if (!joint_is_excavated(a, j)) continue;
            gone++; /* kept to the 2 ulp of the stored 2 + d (model.h) */
            kept += fabs(now[j] - shown[j]) <= 4.5e-16 && a->joint_damage[j] >= 1.0;
        }
        CHECK(gone > 0 && kept == gone, "%dD: %d of %d excavated joints show their damage", dim,
              kept, gone);
        free(shown);
        free(now);
        double worst = 0, scale = 0;
        for (int i = 0; i < a->node_count; i++) {
            if (a->node_frozen[i]) continue;
            for (int d = 0; d < dim; d++) {
                size_t q = (size_t)dim * (size_t)i + (size_t)d;
                worst = fmax(worst, fabs((a->vel[q] - va[q]) - (b->vel[q] - vb[q])));
                scale = fmax(scale, fabs(b->vel[q] - vb[q]));
            }
        }
        printf("  %dD: velocity change at the excavation step off the twin's by %.3g of %.3g m/s "
               "(%.2g), %d joints, %d touching pairs (twin %d)\n", dim, worst, scale, worst / scale,
               a->joint_count, fdem_get_counts(a).contacts, fdem_get_counts(b).contacts);
        CHECK(scale > 0 && worst < 1e-6 * scale, "%dD: off by %g of %g", dim, worst, scale);
        CHECK(fdem_get_counts(a).broken_joints == 0 && fdem_event_count(a) == 0,
              "%dD: excavated joints counted as broken (%d) or events (%d)", dim,
              fdem_get_counts(a).broken_joints, fdem_event_count(a));
        CHECK(fdem_get_counts(a).fragments == 1, "%dD: %d fragments", dim,
              fdem_get_counts(a).fragments);
        int32_t *label = malloc(sizeof(int32_t) * (size_t)a->elem_count);
        CHECK(fdem_fragment_labels(a, label) == 1, "%dD: labels", dim);
        int minus = 0, inactive = 0;
        for (int e = 0; e < a->elem_count; e++) {
            minus += label[e] == -1;
            inactive += !fdem_element_active(a)[e];
        }
        CHECK(inactive > 0 && minus == inactive, "%dD: %d labels -1 for %d excavated", dim, minus,
              inactive);
        free(label);
        free(va);
        free(vb);
        fdem_model_destroy(a);
        fdem_model_destroy(b);
    }
}

/* A block resting under gravity on a fixed one, on a soft contact penalty
 * (E / 10, so the contact holds a fifth of the energy in play), excavated
 * whole: the penalty energy of its contact pairs leaves with it, so the
 * contact account (the work the contact forces did) reads nothing once no
 * pair is left, instead of what the pairs held, and the balance still
 * closes (that energy is booked as excavated). */
static void contact_energy_leaves_with_the_element(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *m = fdem_model_create();
        fdem_error err;
        if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
        fdem_material_def soft = {.density = 2700, .young = 1e9, .poisson = 0.25,
                                  .damping = 0.1, .penalty = 1e8};
        int mat = fdem_add_material(m, &soft, &err);
        const int up = dim - 1;
        double oa[3] = {0, 0, 0}, sa[3] = {1, 1, 1}, ob[3] = {0.25, 0.25, 0.25};
        double sb[3] = {0.5, 0.5, 0.5};
        sa[up] = 0.5;
        ob[up] = 0.5;
        sb[up] = 0.25;
        const int da[3] = {4, 4, 2}, db[3] = {2, 2, 1};
        build_box_at(m, mat, dim, oa, sa, da, 0);
        int b = build_box_at(m, mat, dim, ob, sb, db, 0);
        fdem_constraint_def base = {0};
        base.select = FDEM_SELECT_BOX;
        for (int d = 0; d < dim; d++) {
            base.box[d] = -1;
            base.box[dim + d] = 2;
        }
        base.box[dim + up] = 1e-9;
        base.kind = FDEM_CONSTRAINT_FIX;
        base.fix_x = base.fix_y = base.fix_z = 1;
        add_constraint(m, &base);
        double g[3] = {0, 0, 0};
        g[up] = -200;
        fdem_set_gravity_v(m, g);
        const double t_dig = 2e-3; /* about two wave transits: resting, still ringing */
        int32_t *dig = malloc(sizeof(int32_t) * (size_t)m->elem_count);
        int count = 0;
        for (int e = 0; e < m->elem_count; e++)
            if (m->elem_part[e] == b) dig[count++] = e;
        fdem_stage_def s0 = {.end = t_dig}, s1 = {.end = 1, .excavate = dig, .excavate_count = count};
        fdem_add_stage(m, &s0, &err);
        if (fdem_add_stage(m, &s1, &err) < 0) build_die("stage", &err);
        free(dig);
        build_finalize(m, 0.5);
        run_to(m, t_dig - 1e-12);
        fdem_energy before = fdem_get_energy(m);
        int touching = fdem_get_counts(m).contacts;
        run_to(m, t_dig + 5e-4);
        fdem_energy after = fdem_get_energy(m);
        double scale = fabs(before.elastic) + fabs(before.contact) + fabs(after.excavated) +
                       fabs(after.gravity_work) + fabs(after.damping);
        printf("  %dD: contact %.6g J before the excavation (%d pairs touching, elastic %.6g), "
               "%.3g after; excavated %.6g, residual %.3g -> %.3g (%.2g of the energies in "
               "play)\n", dim, before.contact, touching, before.elastic, after.contact,
               after.excavated, before.residual, after.residual, after.residual / scale);
        CHECK(touching > 0 && before.contact > 0.1 * before.elastic,
              "%dD: the contact holds %g J against %g J elastic", dim, before.contact,
              before.elastic);
        CHECK(fdem_get_counts(m).contacts == 0, "%dD: %d pairs still touch", dim,
              fdem_get_counts(m).contacts);
        /* the pairs' energy now against what their forces' work booked
         * step by step, while the block rings: 2 % (2D) and 4 % (3D) at
         * this step, 0.5 % and 1 % at a quarter of it (a time error); the
         * residual moves by 1.4 % of the contact energy at the excavation
         * step, 0.4 % at a quarter of it (the half step of the pairs' work
         * that the sudden release cuts off), with or without the booking */
        CHECK(fabs(after.contact) < 0.05 * before.contact,
              "%dD: the contact account keeps %g J of the %g J the pairs held", dim, after.contact,
              before.contact);
        CHECK(fabs(after.residual - before.residual) < 0.03 * before.contact,
              "%dD: residual %g J (%g before) of %g", dim, after.residual, before.residual, scale);
        fdem_model_destroy(m);
    }
}

/* A column under gravity in the in-situ stress that holds it (rollers at
 * its sides and base: at rest up to the discretisation), its upper middle
 * excavated with a relax of 10^6 s (the release alone moves the nodes at
 * about u / relax, 4e-13 m/s): the remaining nodes, which lose the removed
 * elements' share of their mass, must stay still, so the unloading forces
 * carry that share's weight too (leaving it out, the shared nodes start
 * falling). */
static void column_under_gravity_stays_still(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *twin[2];
        const double t_dig = 1e-4, t_end = 3e-4, g = 9.81, k0 = 0.5;
        const double size[3] = {1, dim == 2 ? 2 : 1, 2};
        const int div[3] = {4, dim == 2 ? 8 : 4, 8};
        for (int k = 0; k < 2; k++) {
            fdem_model *m = fdem_model_create();
            fdem_error err;
            if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
            int mat = build_material(m, RHO, YOUNG, NU, 0, 0);
            int pi = build_box_part(m, mat, dim, size, div, 0);
            const double top = size[dim - 1];
            double value[6] = {0}, gradient[6] = {0}, gv[3] = {0, 0, 0};
            for (int d = 0; d < dim; d++) gradient[d] = RHO * g * (d == dim - 1 ? 1 : k0);
            gv[dim - 1] = -g;
            if (fdem_set_part_initial_stress(m, pi, value, gradient, top, &err))
                build_die("stress", &err);
            fdem_set_gravity_v(m, gv);
            for (int a = 0; a < dim; a++) {
                roller(m, a, 0);
                if (a < dim - 1) roller(m, a, size[a]);
            }
            int32_t *dig = malloc(sizeof(int32_t) * (size_t)m->elem_count);
            int count = 0;
            for (int e = 0; e < m->elem_count && k == 0; e++) {
                double c[3] = {0, 0, 0};
                const int32_t *n = m->elem_node + (size_t)(dim + 1) * (size_t)e;
                for (int q = 0; q <= dim; q++)
                    for (int d = 0; d < dim; d++) c[d] += m->pos0[dim * n[q] + d] / (dim + 1);
                if (c[0] > 0.25 && c[0] < 0.75 && c[dim - 1] > 0.5 * top && c[dim - 1] < 0.75 * top)
                    dig[count++] = e;
            }
            fdem_stage_def s0 = {.end = t_dig}, s1 = {.end = 1, .relax = 1e6, .excavate = dig,
                                                      .excavate_count = count};
            fdem_add_stage(m, &s0, &err);
            if (fdem_add_stage(m, &s1, &err) < 0) build_die("stage", &err);
            free(dig);
            build_finalize(m, 0.5);
            twin[k] = m;
        }
        run_to(twin[0], t_end);
        run_to(twin[1], t_end);
        double fastest[2] = {0, 0};
        for (int k = 0; k < 2; k++)
            for (int q = 0; q < dim * twin[k]->node_count; q++)
                fastest[k] = fmax(fastest[k], fabs(twin[k]->vel[q]));
        fdem_energy e = fdem_get_energy(twin[0]);
        printf("  %dD column: fastest node %.3g m/s, twin %.3g m/s; excavated %.6g, gravity work "
               "%.3g, external %.3g, residual %.3g J\n",
               dim, fastest[0], fastest[1], e.excavated, e.gravity_work, e.external_work,
               e.residual);
        CHECK(fabs(e.residual) < 1e-6 * e.excavated, "%dD: residual %g J", dim, e.residual);
        CHECK(fdem_element_active(twin[0]) != NULL, "%dD: nothing excavated", dim);
        CHECK(fastest[0] < 1e-11, "%dD: the excavated column moves at %g m/s, its twin at %g m/s",
              dim, fastest[0], fastest[1]);
        fdem_model_destroy(twin[0]);
        fdem_model_destroy(twin[1]);
    }
}

/* ------------------------------------------------------- stage-only loads */

/* A block fixed at its base: a velocity on its top acts during stage 1
 * only, a force on it during stage 0 only. */
static void stage_only_constraints_act_in_their_stage(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        fdem_model *m = fdem_model_create();
        fdem_error err;
        if (dim == 3 && fdem_set_dimension(m, 3, &err)) build_die("dimension", &err);
        int mat = build_material(m, RHO, YOUNG, NU, 0.1, 0);
        const double size[3] = {1, 1, 1};
        const int div[3] = {2, 2, 2};
        build_box_part(m, mat, dim, size, div, 0);
        const int D = dim, up = dim - 1;
        fdem_constraint_def base = {0}, top = {0};
        base.select = top.select = FDEM_SELECT_BOX;
        for (int d = 0; d < D; d++) {
            base.box[d] = top.box[d] = -1;
            base.box[D + d] = top.box[D + d] = 2;
        }
        base.box[D + up] = 1e-9;
        top.box[up] = 1 - 1e-9;
        base.kind = FDEM_CONSTRAINT_FIX;
        base.fix_x = base.fix_y = base.fix_z = 1;
        add_constraint(m, &base);
        fdem_constraint_def pull = top;
        top.kind = FDEM_CONSTRAINT_VELOCITY;
        top.value[up] = 0.01;
        top.only_stage = 2;
        int c_vel = fdem_add_constraint(m, &top, &err);
        pull.kind = FDEM_CONSTRAINT_FORCE;
        pull.value[0] = 1e3;
        pull.only_stage = 1;
        int c_force = fdem_add_constraint(m, &pull, &err);
        /* boundary loads scale by the amplitude, not by value_now alone */
        fdem_constraint_def field = pull, traction = pull;
        field.kind = FDEM_CONSTRAINT_BOUNDARY_STRESS;
        field.value[0] = 0;
        field.stress_value[up] = -1e5;
        int c_field = fdem_add_constraint(m, &field, &err);
        traction.kind = FDEM_CONSTRAINT_TRACTION;
        traction.value[0] = 0;
        traction.value[up] = 2e3;
        int c_traction = fdem_add_constraint(m, &traction, &err);
        fdem_stage_def s0 = {.end = 1e-3}, s1 = {.end = 2e-3};
        fdem_add_stage(m, &s0, &err);
        fdem_add_stage(m, &s1, &err);
        build_finalize(m, 0.5);
        run_to(m, 0.5e-3);
        const double *f = fdem_constraint_forces(m);
        CHECK(fdem_stage_index(m) == 0, "stage %d", fdem_stage_index(m));
        CHECK(f[D * c_force] == 1e3, "%dD: the stage-0 force reads %g", dim, f[D * c_force]);
        CHECK(f[D * c_vel + up] == 0, "%dD: the stage-1 velocity reacts in stage 0", dim);
        CHECK(f[D * c_field + up] < 0 && f[D * c_traction + up] > 0,
              "%dD: the stage-0 boundary stress and traction read %g and %g", dim,
              f[D * c_field + up], f[D * c_traction + up]);
        double top_y0 = 0;
        int top_node = -1;
        for (int i = 0; i < m->node_count; i++)
            if (m->pos0[D * i + up] > 1 - 1e-9) top_node = i;
        top_y0 = m->pos[D * top_node + up];
        run_to(m, 2e-3);
        f = fdem_constraint_forces(m);
        CHECK(fdem_stage_index(m) == 1, "stage %d", fdem_stage_index(m));
        CHECK(f[D * c_force] == 0, "%dD: the stage-0 force acts in stage 1: %g", dim,
              f[D * c_force]);
        CHECK(f[D * c_field + up] == 0 && f[D * c_traction + up] == 0,
              "%dD: the stage-0 boundary stress and traction act in stage 1: %g, %g", dim,
              f[D * c_field + up], f[D * c_traction + up]);
        CHECK(m->vel[D * top_node + up] == 0.01, "%dD: top moves at %g in stage 1", dim,
              m->vel[D * top_node + up]);
        double moved = m->pos[D * top_node + up] - top_y0;
        CHECK(moved > 0.9 * 0.01 * 1e-3, "%dD: top moved %g in stage 1", dim, moved);
        fdem_model_destroy(m);
    }
}

/* ------------------------------------------------------------- bad input */

static void bad_stages_are_refused(void)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    int mat = build_material(m, RHO, YOUNG, NU, 0, 0);
    build_rectangle(m, mat, 0, 0, 1, 1, 2, 2); /* 8 elements */
    int32_t bad_index[2] = {3, 8};
    fdem_stage_def first = {.end = 1};
    CHECK(fdem_add_stage(m, &first, &err) == 0, "%s", err.message);
    fdem_stage_def same_end = {.end = 1}, nan_relax = {.end = 2, .relax = NAN},
                   negative_relax = {.end = 2, .relax = -1},
                   out_of_range = {.end = 2, .excavate = bad_index, .excavate_count = 2},
                   infinite = {.end = INFINITY};
    const fdem_stage_def *bad[] = {&same_end, &nan_relax, &negative_relax, &out_of_range,
                                   &infinite};
    const char *why[] = {"not after", "relax", "relax", "element 8", "not finite"};
    for (int k = 0; k < 5; k++) {
        memset(&err, 0, sizeof err);
        CHECK(fdem_add_stage(m, bad[k], &err) == -1, "bad stage %d accepted", k);
        CHECK(strstr(err.message, "stage 1") && strstr(err.message, why[k]),
              "case %d: message \"%s\"", k, err.message);
    }
    fdem_constraint_def c = {0};
    c.select = FDEM_SELECT_PART;
    c.kind = FDEM_CONSTRAINT_ABSORB;
    c.only_stage = 1;
    CHECK(fdem_add_constraint(m, &c, &err) < 0 && strstr(err.message, "absorbing"),
          "a stage-only absorbing boundary: \"%s\"", err.message);
    c.kind = FDEM_CONSTRAINT_FIX;
    c.fix_x = 1;
    c.only_stage = -1;
    CHECK(fdem_add_constraint(m, &c, &err) < 0 && strstr(err.message, "only_stage"),
          "only_stage -1: \"%s\"", err.message);
    c.only_stage = 3; /* stage 2: there is one stage */
    CHECK(fdem_add_constraint(m, &c, &err) == 0, "%s", err.message);
    CHECK(fdem_model_finalize(m, &err) < 0 && strstr(err.message, "stage 2"),
          "a constraint of a missing stage: \"%s\"", err.message);
    fdem_model_destroy(m);
}

CHECK_MAIN(T(kirsch_2d_k0_1_5_slow), T(kirsch_2d_k0_1_slow), T(kirsch_2d_sudden_settles_alike),
           T(kirsch_3d_plane_strain), T(kirsch_with_support_pressure), T(same_bits_on_threads_and_across_a_checkpoint),
           T(energy_closes_through_the_excavation), T(fracturing_block_keeps_its_forces),
           T(column_under_gravity_stays_still), T(contact_energy_leaves_with_the_element),
           T(stage_only_constraints_act_in_their_stage),
           T(bad_stages_are_refused))
