/*
 * fluid_bore.c - bores: cavities of the fluid network that are not joints
 * (issue 36: fluid injected into a borehole breaks its wall). An "inject"
 * constraint with def.bore makes one: its wall is the boundary facets the
 * constraint selects (found with the other boundary loads,
 * boundary_load.c), the fluid it holds fills the space they enclose, and
 * its pressure presses on every wall facet as a "pressure" would. It is
 * one more cavity of the network (index joints + b), so the flow, the
 * sources, the accounts and the checkpoint treat it as any other; what
 * differs is measured here:
 *  - its wall's corners: a fracturing part has a node copy per element
 *    at each wall vertex, which part when a wall joint opens; the wall is
 *    drawn through the mean of the copies at each vertex, so it stays
 *    closed (the crack's mouth shared by the facets beside it), its
 *    pressure's forces sum to zero (momentum is kept) and its volume is
 *    well defined;
 *  - its volume, by the divergence theorem on the corners' current
 *    positions, V = -(1/dim) sum (c - o) . S over the facets (S the area
 *    vector pointing out of the rock, c the centroid, o a fixed point: the
 *    wall's centroid at t = 0 for a closed wall); a 3D wall open at a rim
 *    in planes normal to one axis e (a bore through a slab between
 *    rollers, a bore cut by one symmetry plane) takes the part of c - o
 *    normal to e and 1/(dim - 1), so the missing caps add nothing; any
 *    other open wall is measured from the origin, which its cuts must
 *    then pass through (bore_measure_frame);
 *  - its forces, -p S / dim on each node of each facet (into the rock),
 *    and their power for fluid_work;
 *  - its links: a wall facet's keys (2D its vertices, 3D its edges) link
 *    the bore to every joint that meets the wall there, the joint's
 *    aperture alone setting the conductance (fluid_network.c), so fluid
 *    leaves the bore only into a wall joint that is damaged or broken.
 * A bore starts full at zero pressure: V_fluid = V(t = 0).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "joint/joint.h"
#include "math/facet_area.h"
#include "math/vec3.h"
#include "fluid.h"

static int is_bore(const constraint *c)
{
    return c->def.kind == FDEM_CONSTRAINT_INJECT && c->def.bore;
}

/* Wall facet j's area vector and centroid on its corners' positions of
 * the last corners_update. */
static void facet_geometry(const fdem_model *m, const fluid_net *f, int j, double area[3],
                           double centroid[3])
{
    const int D = m->dim;
    const double *x[3] = {NULL, NULL, NULL};
    for (int a = 0; a < D; a++)
        x[a] = f->corner_pos + (size_t)D * (size_t)f->wall_corner[(size_t)D * (size_t)j + a];
    facet_area_vector_of(D, x, area); /* out of the rock, into the bore */
    for (int d = 0; d < 3; d++) {
        double sum = d < D ? x[0][d] : 0;
        for (int a = 1; a < D && d < D; a++) sum += x[a][d];
        centroid[d] = d < D ? sum / D : 0;
    }
}

/* Each corner at the mean of its node copies' current positions. */
static void corners_update(const fdem_model *m, fluid_net *f)
{
    const int D = m->dim;
    for (int c = 0; c < f->corner_count; c++) {
        double *x = f->corner_pos + (size_t)D * (size_t)c;
        const int first = f->corner_begin[c], count = f->corner_begin[c + 1] - first;
        for (int d = 0; d < D; d++) x[d] = 0;
        for (int i = first; i < first + count; i++)
            for (int d = 0; d < D; d++) x[d] += m->pos[(size_t)D * (size_t)f->corner_node[i] + d];
        for (int d = 0; d < D; d++) x[d] /= count;
    }
}

/* One node of a wall facet, for sorting by its mesh vertex. */
typedef struct wall_entry {
    int32_t vertex, node, slot; /* slot: the facet's node's index in bfacet_node */
} wall_entry;

static int wall_entry_compare(const void *pa, const void *pb)
{
    const wall_entry *a = pa, *b = pb;
    if (a->vertex != b->vertex) return a->vertex < b->vertex ? -1 : 1;
    if (a->node != b->node) return a->node < b->node ? -1 : 1;
    return (a->slot > b->slot) - (a->slot < b->slot);
}

/* The corners of every bore's wall: the wall's nodes grouped by mesh
 * vertex, each node copy once. */
static int corners_build(const fdem_model *m, fluid_net *f)
{
    const int D = m->dim;
    size_t n = 0;
    for (int b = 0; b < f->bores; b++) n += (size_t)D * (size_t)m->constraints[f->bore_constraint[b]].facet_count;
    wall_entry *e = malloc(sizeof *e * (n + 1));
    f->wall_corner = malloc(sizeof(int32_t) * (size_t)D * (size_t)(m->bfacet_count + 1));
    f->corner_begin = malloc(sizeof(int32_t) * (n + 1));
    f->corner_node = malloc(sizeof(int32_t) * (n + 1));
    f->corner_pos = malloc(sizeof(double) * (size_t)D * (n + 1));
    if (!e || !f->wall_corner || !f->corner_begin || !f->corner_node || !f->corner_pos) {
        free(e);
        return -1;
    }
    size_t k = 0;
    for (int b = 0; b < f->bores; b++) {
        const constraint *c = &m->constraints[f->bore_constraint[b]];
        for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++)
            for (int a = 0; a < D; a++) {
                int32_t slot = (int32_t)((size_t)D * (size_t)j + (size_t)a), node = m->bfacet_node[slot];
                e[k++] = (wall_entry){m->node_origin[node], node, slot};
            }
    }
    qsort(e, n, sizeof *e, wall_entry_compare);
    int corners = 0, nodes = 0;
    for (size_t i = 0; i < n; i++) {
        if (i == 0 || e[i].vertex != e[i - 1].vertex) f->corner_begin[corners++] = nodes;
        if (i == 0 || e[i].node != e[i - 1].node) f->corner_node[nodes++] = e[i].node;
        f->wall_corner[e[i].slot] = corners - 1;
    }
    f->corner_begin[corners] = nodes;
    f->corner_count = corners;
    free(e);
    return 0;
}

int fluid_bores_count(fdem_model *m, fluid_net *f, fdem_error *err)
{
    int bores = 0;
    for (int k = 0; k < m->constraint_count; k++) bores += is_bore(&m->constraints[k]);
    f->bores = bores;
    f->cavities = f->joints + bores;
    if (!bores) return 0;
    const size_t D = (size_t)m->dim;
    f->bore_constraint = malloc(sizeof(int32_t) * (size_t)bores);
    f->bore_origin = calloc(D * (size_t)bores, sizeof(double));
    f->bore_axis = calloc(D * (size_t)bores, sizeof(double));
    f->wall_force = calloc(D * (size_t)(m->bfacet_count ? m->bfacet_count : 1), sizeof(double));
    if (!f->bore_constraint || !f->bore_origin || !f->bore_axis || !f->wall_force) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the bores");
        return -1;
    }
    for (int k = 0, b = 0; k < m->constraint_count; k++)
        if (is_bore(&m->constraints[k])) f->bore_constraint[b++] = k;
    if (corners_build(m, f)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for the bores");
        return -1;
    }
    return 0;
}

/* The space bore b's wall encloses, on the current positions: the
 * divergence theorem on x - o, or, for a wall open along an axis e, on its
 * part normal to e (divergence dim - 1), whose flux through the missing
 * caps is zero. */
static double bore_volume(const fdem_model *m, const fluid_net *f, int b)
{
    const int D = m->dim;
    const constraint *c = &m->constraints[f->bore_constraint[b]];
    const double *o = f->bore_origin + D * b, *e = f->bore_axis + D * b;
    const int slab = e[0] != 0 || e[1] != 0 || (D == 3 && e[2] != 0);
    double sum = 0;
    for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++) {
        double s[3], x[3], along = 0;
        facet_geometry(m, f, j, s, x);
        for (int d = 0; d < D; d++) x[d] -= o[d];
        for (int d = 0; slab && d < D; d++) along += x[d] * e[d];
        for (int d = 0; d < D; d++) sum += (x[d] - along * e[d]) * s[d];
    }
    return -sum / (slab ? D - 1 : D);
}

static int pair_compare(const void *pa, const void *pb)
{
    const int32_t *a = pa, *b = pb;
    if (a[0] != b[0]) return a[0] < b[0] ? -1 : 1;
    return (a[1] > b[1]) - (a[1] < b[1]);
}

/* A 3D wall's rim: the corner pairs of its facets' edges that only one
 * wall facet has (none for a closed wall). Returns their count, the edges
 * into rim (2 corners each; room for 3 per facet). */
static int wall_rim_3d(const fluid_net *f, const constraint *c, int32_t *rim)
{
    int n = 0;
    for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++)
        for (int a = 0; a < 3; a++) {
            int32_t p = f->wall_corner[3 * (size_t)j + a], q = f->wall_corner[3 * (size_t)j + (a + 1) % 3];
            rim[2 * n] = p < q ? p : q;
            rim[2 * n + 1] = p < q ? q : p;
            n++;
        }
    /* keep the pairs that occur once */
    qsort(rim, (size_t)n, 2 * sizeof *rim, pair_compare);
    int kept = 0;
    for (int i = 0; i < n;) {
        int k = i + 1;
        while (k < n && rim[2 * k] == rim[2 * i] && rim[2 * k + 1] == rim[2 * i + 1]) k++;
        if (k == i + 1) {
            rim[2 * kept] = rim[2 * i];
            rim[2 * kept + 1] = rim[2 * i + 1];
            kept++;
        }
        i = k;
    }
    return kept;
}

/* The unit axis every rim edge is normal to, 0 when there is none. */
static int rim_axis(const fluid_net *f, const int32_t *rim, int n, double axis[3])
{
    double best = 0;
    for (int i = 0; i < n; i++)
        for (int k = i + 1; k < n; k++) {
            double u[3], v[3], w[3];
            vec3_sub(f->corner_pos + 3 * (size_t)rim[2 * i + 1], f->corner_pos + 3 * (size_t)rim[2 * i], u);
            vec3_sub(f->corner_pos + 3 * (size_t)rim[2 * k + 1], f->corner_pos + 3 * (size_t)rim[2 * k], v);
            vec3_cross(u, v, w);
            double size = vec3_dot(w, w) / (vec3_dot(u, u) * vec3_dot(v, v));
            if (size > best) {
                best = size;
                memcpy(axis, w, sizeof(double) * 3);
            }
        }
    if (!(best > 1e-6)) return 0;
    double len = sqrt(vec3_dot(axis, axis));
    for (int d = 0; d < 3; d++) axis[d] /= len;
    for (int i = 0; i < n; i++) {
        double u[3];
        vec3_sub(f->corner_pos + 3 * (size_t)rim[2 * i + 1], f->corner_pos + 3 * (size_t)rim[2 * i], u);
        if (fabs(vec3_dot(u, axis)) > 1e-9 * sqrt(vec3_dot(u, u))) return 0;
    }
    return 1;
}

/* How bore b's volume is measured (bore_volume): a closed wall from its
 * centroid; a 3D wall whose open rim lies in planes normal to one axis e
 * (a slab's bore between rollers, a bore cut by one symmetry plane) from
 * its centroid, normal to e; any other open wall from the origin, which
 * its cuts must pass through (docs/case-format.md). */
static void bore_measure_frame(const fdem_model *m, fluid_net *f, int b, const double *centre)
{
    const int D = m->dim;
    const constraint *c = &m->constraints[f->bore_constraint[b]];
    double *o = f->bore_origin + D * b, *e = f->bore_axis + D * b;
    int open = 0;
    for (int d = 0; d < D; d++) {
        o[d] = centre[d];
        e[d] = 0;
    }
    if (D == 2) {
        for (int k = 0; k < f->corner_count; k++) {
            int uses = 0;
            for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++)
                uses += f->wall_corner[2 * (size_t)j] == k || f->wall_corner[2 * (size_t)j + 1] == k;
            open |= uses == 1;
        }
    } else {
        int32_t *rim = malloc(sizeof(int32_t) * 6 * (size_t)c->facet_count);
        int n = rim ? wall_rim_3d(f, c, rim) : 0;
        double axis[3] = {0, 0, 0};
        open = n > 0 || !rim;
        int slab = n > 1 && rim_axis(f, rim, n, axis);
        free(rim);
        if (slab) {
            memcpy(e, axis, sizeof axis);
            return;
        }
    }
    for (int d = 0; open && d < D; d++) o[d] = 0;
}

/* Each bore's origin (see the top of the file), centre (the mean of its
 * facets' centroids: the height its pressure is taken at, with gravity),
 * and fluid: full at zero pressure. */
void fluid_bores_init(fdem_model *m, fluid_net *f)
{
    const int D = m->dim;
    corners_update(m, f);
    for (int b = 0; b < f->bores; b++) {
        const constraint *c = &m->constraints[f->bore_constraint[b]];
        const int cav = f->joints + b;
        double *centre = f->centre + D * cav;
        for (int d = 0; d < D; d++) centre[d] = 0;
        for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++) {
            double s[3], x[3];
            facet_geometry(m, f, j, s, x);
            for (int d = 0; d < D; d++) centre[d] += x[d] / c->facet_count;
        }
        bore_measure_frame(m, f, b, centre);
        f->wet[cav] = 1;
        f->floor[cav] = 0;
        f->pressure[cav] = 0;
        f->aperture0[cav] = 0;
        f->fluid[cav] = bore_volume(m, f, b);
    }
}

/* Bore b's volume and pressure on the current positions; with_forces,
 * the pressure's forces on its wall's nodes. */
void fluid_bore_measure(fdem_model *m, fluid_net *f, int b, int with_forces)
{
    const int D = m->dim, cav = f->joints + b;
    if (b == 0) corners_update(m, f);
    f->open[cav] = 1;
    f->open_list[f->open_count++] = cav;
    f->aperture[cav] = 0;
    f->volume[cav] = bore_volume(m, f, b);
    if (!(f->volume[cav] > 0)) f->volume[cav] = 1e-300; /* a wall turned inside out */
    const double p = f->pressure[cav] = fluid_cavity_pressure(f, cav);
    if (!with_forces) return;
    const constraint *c = &m->constraints[f->bore_constraint[b]];
    for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++) {
        double s[3], x[3], *F = f->wall_force + (size_t)D * (size_t)j;
        facet_geometry(m, f, j, s, x);
        const int32_t *n = m->bfacet_node + (size_t)D * (size_t)j;
        for (int d = 0; d < D; d++) F[d] = -p * s[d] / D;
        for (int a = 0; a < D; a++)
            for (int d = 0; d < D; d++) m->force[(size_t)D * n[a] + d] += F[d];
    }
}

/* Sum over the bores' wall nodes of F . v. */
double fluid_bores_power(const fdem_model *m, const fluid_net *f)
{
    const int D = m->dim;
    double power = 0;
    for (int b = 0; b < f->bores; b++) {
        const constraint *c = &m->constraints[f->bore_constraint[b]];
        for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++) {
            const double *F = f->wall_force + (size_t)D * (size_t)j;
            const int32_t *n = m->bfacet_node + (size_t)D * (size_t)j;
            for (int a = 0; a < D; a++)
                for (int d = 0; d < D; d++) power += F[d] * m->vel[(size_t)D * n[a] + d];
        }
    }
    return power;
}

/* The stiffness the bore's fluid adds to a wall node: moving a facet's
 * node by u along S changes V by |S| u / dim, so p by K |S| u / (dim V),
 * which the node feels over |S| / dim of each of the (about dim) facets it
 * is on: K |S|^2 / (dim V) at most. Small against the rock's for any bore
 * wider than its wall's cells, but kept honest. */
double fluid_bores_stable_dt(const fdem_model *m, fluid_net *f)
{
    const int D = m->dim;
    double dt = INFINITY;
    corners_update(m, f);
    for (int b = 0; b < f->bores; b++) {
        const constraint *c = &m->constraints[f->bore_constraint[b]];
        double V = bore_volume(m, f, b);
        if (!(V > 0)) continue;
        for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++) {
            double s[3], x[3], mass = INFINITY;
            facet_geometry(m, f, j, s, x);
            const int32_t *n = m->bfacet_node + (size_t)D * (size_t)j;
            for (int a = 0; a < D; a++) mass = fmin(mass, m->mass[n[a]]);
            double k = f->bulk_modulus * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) / (D * V);
            if (k > 0) dt = fmin(dt, joint_spring_dt(mass, k));
        }
    }
    return dt;
}

int fluid_bore_key_count(const fdem_model *m, const fluid_net *f)
{
    int count = 0;
    for (int b = 0; b < f->bores; b++) count += m->dim * m->constraints[f->bore_constraint[b]].facet_count;
    return count;
}

int fluid_bore_keys(const fdem_model *m, const fluid_net *f, int32_t (*keys)[2], int32_t *cavity)
{
    const int D = m->dim;
    int n = 0;
    for (int b = 0; b < f->bores; b++) {
        const constraint *c = &m->constraints[f->bore_constraint[b]];
        for (int j = c->facet_begin; j < c->facet_begin + c->facet_count; j++) {
            int32_t k[3][2];
            const int32_t *nodes = m->bfacet_node + (size_t)D * (size_t)j;
            int count = D == 3 ? fluid_facet_keys_3d(m, nodes, k) : fluid_facet_keys_2d(m, nodes, k);
            for (int i = 0; i < count; i++, n++) {
                keys[n][0] = k[i][0];
                keys[n][1] = k[i][1];
                cavity[n] = f->joints + b;
            }
        }
    }
    return n;
}

void fluid_key_point(const fdem_model *m, const int32_t key[2], double *x)
{
    const int D = m->dim;
    for (int d = 0; d < D; d++) {
        double a = m->pos0[(size_t)D * (size_t)key[0] + d];
        x[d] = key[1] >= 0 ? 0.5 * (a + m->pos0[(size_t)D * (size_t)key[1] + d]) : a;
    }
}
