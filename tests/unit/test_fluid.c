/*
 * test_fluid.c - fluid in the fractures (contract 6.4, core/fluid/):
 *  - the network keeps its fluid: what is stored is what was injected, to
 *    round-off, in 2D and 3D, while the fluid breaks the rock;
 *  - the pressure's forces are equal and opposite: the momentum of a free
 *    body stays zero;
 *  - the fluid's work closes the energy balance (residual < 1 % of it);
 *  - 1 and 2 threads, and a restart from a checkpoint, give the same bits;
 *  - a bore (an "inject" with "bore": true, core/fluid/fluid_bore.c) holds
 *    the fluid injected into it, its volume is the hole's, its pressure
 *    pushes its wall apart until a wall joint breaks and takes fluid; the
 *    same accounts, momentum and bits as the joints' network, 2D and 3D;
 *  - a wet joint sheared under a normal stress sigma_n slides at
 *    c + (sigma_n - p) tan(phi) (Terzaghi's effective stress), within 3 %;
 *  - bad input: one 422 with a problem at each pointer.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "case_doc.h"
#include "check.h"
#include "fdem.h"

/* A fracturing square (cube) fed at its centre node. */
static const char *const network_2d =
    "{'dimension': 2,"
    " 'materials': {'rock': {'density': 2500, 'young': 1e10, 'poisson': 0.2, 'damping': 0.2,"
    "   'fracture': {'tensile_strength': 1e6, 'cohesion': 3e6, 'friction_angle': 30,"
    "                'energy_I': 20, 'energy_II': 100, 'aperture0': 1e-4}}},"
    " 'fluid': {'viscosity': 1e-3, 'bulk_modulus': 1e8, 'density': 1000},"
    " 'parts': [{'name': 'rock', 'material': 'rock', 'fracture': true,"
    "            'rectangle': {'origin': [-0.5, -0.5], 'size': [1, 1], 'divisions': [8, 8]}}],"
    " 'constraints': [{'box': [-0.01, -0.01, 0.01, 0.01], 'inject': 2e-3}],"
    " 'time': {'end': 1}}";

static const char *const network_3d =
    "{'dimension': 3,"
    " 'materials': {'rock': {'density': 2500, 'young': 1e10, 'poisson': 0.2, 'damping': 0.2,"
    "   'fracture': {'tensile_strength': 1e6, 'cohesion': 3e6, 'friction_angle': 30,"
    "                'energy_I': 20, 'energy_II': 100, 'aperture0': 1e-4}}},"
    " 'fluid': {'viscosity': 1e-3, 'bulk_modulus': 1e8, 'density': 1000},"
    " 'parts': [{'name': 'rock', 'material': 'rock', 'fracture': true,"
    "            'box': {'origin': [-0.5, -0.5, -0.5], 'size': [1, 1, 1], 'divisions': [4, 4, 4]}}],"
    " 'constraints': [{'box': [-0.01, -0.01, -0.01, 0.01, 0.01, 0.01], 'inject': 1e-2}],"
    " 'time': {'end': 1}}";

static fdem_model *network(const char *doc)
{
    return expect_built(load(doc), NULL);
}

/* ------------------------------------------------------- a bore */

#define BORE_CELLS_2D 6
#define BORE_CELLS_3D 4
#define BORE_Q_2D 3.0
#define BORE_Q_3D 8.0

/* Cell (i, j, k) of an n-cell square (cube) is in the hole: the middle
 * 2 x 2 (x 2) cells. */
static int in_hole(int dim, int n, const int *c, int slab)
{
    int in = 1;
    for (int d = 0; d < (slab ? 2 : dim); d++) in &= c[d] == n / 2 - 1 || c[d] == n / 2;
    return in;
}

static int grid_node(json_t *nodes, int *index, int dim, int n, const int *c, int slab)
{
    int key = c[0] + (n + 1) * (c[1] + (dim == 3 ? (n + 1) * c[2] : 0));
    if (index[key] < 0) {
        json_t *x = json_array();
        for (int d = 0; d < dim; d++)
            json_array_append_new(x, json_real(d == 2 && slab ? c[d] - 0.5 : -0.5 + (double)c[d] / n));
        index[key] = (int)json_array_size(nodes);
        json_array_append_new(nodes, x);
    }
    return index[key];
}

static json_t *cell_element(json_t *nodes, int *index, int dim, int n, int corners[][3], int count,
                            int slab)
{
    json_t *e = json_array();
    for (int i = 0; i < count; i++)
        json_array_append_new(e, json_integer(grid_node(nodes, index, dim, n, corners[i], slab)));
    return e;
}

/* A unit square (cube) of n cells a side, centred on the origin, without
 * its middle 2 x 2 (x 2) cells: the elements of a fracturing part
 * (triangles; 3D the six Kuhn tetrahedra of each cell, as
 * examples/penny_mesh.py), a bore fed at Q with "bore": true on the box
 * around the hole (it selects the hole's wall and nothing else). A slab
 * (3D) is one cell of 1 m in z, the hole through it, open at its faces. */
static char *bore_doc_of(int dim, double Q, int slab)
{
    const int n = dim == 3 ? BORE_CELLS_3D : BORE_CELLS_2D;
    int *index = malloc(sizeof(int) * (size_t)((n + 1) * (n + 1) * (n + 1)));
    for (int i = 0; i < (n + 1) * (n + 1) * (n + 1); i++) index[i] = -1;
    json_t *nodes = json_array(), *elements = json_array();
    for (int k = 0; k < (dim == 3 ? (slab ? 1 : n) : 1); k++)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                int c[3] = {i, j, k};
                if (in_hole(dim, n, c, slab)) continue;
                if (dim == 2) {
                    int t0[3][3] = {{i, j}, {i + 1, j}, {i + 1, j + 1}};
                    int t1[3][3] = {{i, j}, {i + 1, j + 1}, {i, j + 1}};
                    json_array_append_new(elements, cell_element(nodes, index, 2, n, t0, 3, 0));
                    json_array_append_new(elements, cell_element(nodes, index, 2, n, t1, 3, 0));
                    continue;
                }
                static const int orders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                                 {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
                for (int o = 0; o < 6; o++) {
                    int path[4][3] = {{i + 1, j, k}};
                    for (int s = 0; s < 3; s++) {
                        memcpy(path[s + 1], path[s], sizeof path[s]);
                        path[s + 1][orders[o][s]] += orders[o][s] == 0 ? -1 : 1;
                    }
                    json_array_append_new(elements, cell_element(nodes, index, 3, n, path, 4, slab));
                }
            }
    free(index);
    json_t *doc = load(dim == 3 ? network_3d : network_2d);
    json_t *part = json_array_get(json_object_get(doc, "parts"), 0);
    json_object_del(part, dim == 3 ? "box" : "rectangle");
    json_t *mesh = json_object();
    json_object_set_new(mesh, "nodes", nodes);
    json_object_set_new(mesh, dim == 3 ? "tetrahedra" : "triangles", elements);
    json_object_set_new(part, "mesh", mesh);
    const double e = 1.0 / n + 1e-6;
    char inject[160];
    if (dim == 3)
        snprintf(inject, sizeof inject,
                 "[{'box': [%g, %g, %g, %g, %g, %g], 'inject': %g, 'bore': true}]", -e, -e,
                 slab ? -1.0 : -e, e, e, slab ? 1.0 : e, Q);
    else
        snprintf(inject, sizeof inject, "[{'box': [%g, %g, %g, %g], 'inject': %g, 'bore': true}]",
                 -e, -e, e, e, Q);
    json_object_set_new(doc, "constraints", load(inject));
    /* a thin fluid, so the wall joints fill within the test's few steps
     * (a cavity of aperture0 fills in 12 mu l L / (aperture0^2 dp)) */
    json_object_set_new(json_object_get(doc, "fluid"), "viscosity", json_real(1e-5));
    if (slab) /* between rollers */
        json_array_append_new(json_object_get(doc, "constraints"),
                              load("{'part': 'rock', 'fix': ['z']}"));
    char *text = json_dumps(doc, JSON_COMPACT);
    json_decref(doc);
    return text;
}

static char *bore_doc(int dim, double Q) { return bore_doc_of(dim, Q, 0); }

static int run(fdem_model *m, int steps)
{
    fdem_error err;
    for (int s = 0; s < steps; s++)
        if (fdem_step(m, &err)) {
            fprintf(stderr, "  step failed: %s\n", err.message);
            return -1;
        }
    return 0;
}

static void momentum(const fdem_model *m, double p[3], double *scale)
{
    const int D = fdem_get_dimension(m), N = fdem_get_counts(m).nodes;
    const double *v = fdem_velocities(m), *mass = fdem_node_masses(m);
    p[0] = p[1] = p[2] = 0;
    *scale = 0;
    for (int i = 0; i < N; i++)
        for (int d = 0; d < D; d++) {
            p[d] += mass[i] * v[D * i + d];
            *scale += mass[i] * fabs(v[D * i + d]);
        }
}

static void check_network(const char *doc, int steps)
{
    fdem_model *m = network(doc);
    if (!m) return;
    fdem_fluid_status f0 = fdem_get_fluid(m);
    CHECK(f0.enabled && f0.injected_volume == 0 && f0.stored_volume > 0, "at t = 0");
    if (run(m, steps)) {
        fdem_model_destroy(m);
        return;
    }
    fdem_fluid_status f = fdem_get_fluid(m);
    fdem_energy e = fdem_get_energy(m);
    fdem_counts c = fdem_get_counts(m);
    double p[3], scale;
    momentum(m, p, &scale);
    fprintf(stderr, "  %dD: injected %.6g, stored %.6g (%.6g at t = 0), source %.4g Pa, flow "
                    "step %.3g s x %d, %d open, %d broken of %d; fluid work %.6g J, "
                    "dissipation %.4g J, residual %.3g J; momentum %.3g of %.3g\n",
            fdem_get_dimension(m), f.injected_volume, f.stored_volume, f0.stored_volume,
            f.source_pressure, f.flow_step, f.subcycles, f.open_joints, c.broken_joints,
            c.joints, e.fluid_work, e.fluid_dissipation, e.residual, fabs(p[0]) + fabs(p[1]) +
            fabs(p[2]), scale);
    CHECK_REL(f.stored_volume - f0.stored_volume, f.injected_volume, 1e-9);
    CHECK(f.source_pressure > 0, "the source is under pressure");
    CHECK(c.broken_joints > 0, "the fluid broke the rock");
    CHECK(f.open_joints > f0.open_joints, "the network grew");
    CHECK(e.fluid_work > 0 && e.fluid_dissipation >= 0, "the fluid worked on the rock");
    CHECK(fabs(e.residual) < 0.01 * e.fluid_work, "residual %.3g of fluid work %.3g", e.residual,
          e.fluid_work);
    CHECK(fabs(p[0]) + fabs(p[1]) + fabs(p[2]) <= 1e-9 * scale, "momentum");
    /* the history's per-injection figures: the one injection holds the totals */
    double pressure = 0, injected = 0;
    fdem_fluid_sources(m, &pressure, &injected);
    CHECK(injected == f.injected_volume && pressure == f.source_pressure,
          "per injection %.17g Pa, %.17g; status %.17g Pa, %.17g", pressure, injected,
          f.source_pressure, f.injected_volume);
    /* the case builder admits a case on the estimate: the fluid's is in it */
    size_t held = fdem_memory_bytes(m);
    size_t priced = fdem_memory_estimate_of(&c) + fdem_fluid_memory_estimate(c.dimension, c.joints);
    CHECK(held <= priced, "memory %zu bytes, estimated %zu", held, priced);
    fdem_model_destroy(m);
}

static void fluid_network_2d(void) { check_network(network_2d, 600); }
static void fluid_network_3d(void) { check_network(network_3d, 300); }

/* 1 vs 2 threads and a restart halfway give the same positions and fluid. */
static void check_same_bits(const char *doc, int steps)
{
    fdem_model *a = network(doc), *b = network(doc), *c = network(doc);
    if (!a || !b || !c) return;
    fdem_set_threads(b, 2);
    run(a, steps / 2);
    run(b, steps / 2);
    size_t size = fdem_checkpoint_size(a);
    void *buf = malloc(size);
    CHECK(fdem_checkpoint_write(a, buf, size) == 0, "checkpoint written");
    fdem_error err;
    CHECK(fdem_checkpoint_read(c, buf, size, &err) == 0, "checkpoint read: %s", err.message);
    free(buf);
    fdem_energy ea = fdem_get_energy(a), ec = fdem_get_energy(c);
    CHECK(ea.fluid_work == ec.fluid_work && ea.residual == ec.residual, "restored accounts");
    run(a, steps - steps / 2);
    run(b, steps - steps / 2);
    run(c, steps - steps / 2);
    size_t n = (size_t)fdem_get_dimension(a) * (size_t)fdem_get_counts(a).nodes;
    CHECK(memcmp(fdem_positions(a), fdem_positions(b), n * sizeof(double)) == 0, "2 threads");
    CHECK(memcmp(fdem_positions(a), fdem_positions(c), n * sizeof(double)) == 0, "restart");
    fdem_fluid_status fa = fdem_get_fluid(a), fb = fdem_get_fluid(b), fc = fdem_get_fluid(c);
    CHECK(fa.stored_volume == fb.stored_volume && fa.stored_volume == fc.stored_volume &&
              fa.source_pressure == fc.source_pressure && fa.injected_volume == fc.injected_volume,
          "fluid");
    ea = fdem_get_energy(a);
    ec = fdem_get_energy(c);
    CHECK(ea.fluid_work == ec.fluid_work && ea.fluid_dissipation == ec.fluid_dissipation,
          "fluid accounts %.17g %.17g", ea.fluid_work, ec.fluid_work);
    double pa = 0, va = 0, pc = 0, vc = 0; /* one constraint: the injection */
    fdem_fluid_sources(a, &pa, &va);
    fdem_fluid_sources(c, &pc, &vc);
    CHECK(pa == pc && va == vc && va > 0, "per injection after the restart: %.17g %.17g", va, vc);
    fdem_model_destroy(a);
    fdem_model_destroy(b);
    fdem_model_destroy(c);
}

/* A version 9 checkpoint (no per-constraint injected volume: the fluid
 * section ends with the cavities, and this model has no stages after it)
 * restores the total to its one injection. */
static void fluid_checkpoint_version_9(void)
{
    fdem_model *a = network(network_2d), *c = network(network_2d);
    if (!a || !c) return;
    run(a, 200);
    size_t size = fdem_checkpoint_size(a);
    unsigned char *buf = malloc(size);
    CHECK(fdem_checkpoint_write(a, buf, size) == 0, "checkpoint written");
    const uint32_t nine = 9;
    memcpy(buf + 4, &nine, sizeof nine); /* magic, then the version */
    size_t v9 = size - sizeof(double) * (size_t)fdem_get_counts(a).constraints;
    fdem_error err;
    CHECK(fdem_checkpoint_version(buf, v9) == 9, "version 9");
    CHECK(fdem_checkpoint_read(c, buf, v9, &err) == 0, "version 9 read: %s", err.message);
    free(buf);
    double pa = 0, va = 0, pc = 0, vc = 0;
    fdem_fluid_sources(a, &pa, &va);
    fdem_fluid_sources(c, &pc, &vc);
    CHECK(vc == fdem_get_fluid(c).injected_volume && vc == va && va > 0,
          "restored %.17g, total %.17g, written %.17g", vc, fdem_get_fluid(c).injected_volume, va);
    fdem_model_destroy(a);
    fdem_model_destroy(c);
}

static void fluid_same_bits_2d(void) { check_same_bits(network_2d, 400); }
static void fluid_same_bits_3d(void) { check_same_bits(network_3d, 200); }

/* The bore holds the hole's volume at t = 0 and nothing else does; fed,
 * its pressure rises as its fluid over its volume says, with every joint
 * on its wall sealed, until a wall joint breaks and takes fluid. */
static void check_bore(int dim, double Q, int steps)
{
    char *doc = bore_doc(dim, Q);
    fdem_model *m = network(doc);
    if (!m) {
        free(doc);
        return;
    }
    const double hole = pow(2.0 / (dim == 3 ? BORE_CELLS_3D : BORE_CELLS_2D), dim);
    fdem_fluid_status f0 = fdem_get_fluid(m);
    CHECK_REL(f0.stored_volume, hole, 1e-12);
    CHECK(f0.open_joints == 0 && f0.source_pressure == 0, "only the bore holds fluid at t = 0");
    int sealed_until = -1, joints = fdem_get_counts(m).joints;
    double peak = 0, wet = 0;
    for (int s = 0; s < steps && !run(m, 1); s++) {
        fdem_fluid_status f = fdem_get_fluid(m);
        peak = fmax(peak, f.source_pressure);
        if (f.open_joints == 0) sealed_until = s;
    }
    const double *p = fdem_fluid_pressure(m), *damage = fdem_joint_damage(m);
    for (int j = 0; j < joints; j++)
        if (damage[j] > 0) wet = fmax(wet, p[j]);
    fdem_fluid_status f = fdem_get_fluid(m);
    fprintf(stderr, "  %dD bore: hole %.6g, sealed for %d steps, peak %.4g Pa, now %.4g Pa; "
                    "a wall joint at %.4g Pa; %d open, %d broken\n",
            dim, hole, sealed_until + 1, peak, f.source_pressure, wet, f.open_joints,
            fdem_get_counts(m).broken_joints);
    CHECK(sealed_until > 0 && sealed_until < steps - 1, "the wall holds, then gives");
    CHECK(peak > 0 && wet > 0, "the bore's fluid enters the broken wall joints");
    fdem_model_destroy(m);
    check_network(doc, steps);
    check_same_bits(doc, steps);
    free(doc);
}

static void fluid_bore_2d(void) { check_bore(2, BORE_Q_2D, 300); }

/* A bore through a slab between rollers: its wall is open at the slab's
 * faces, and the volume it encloses is measured normal to their axis
 * (fluid_bore.c), exactly the hole's; then, fed, what the bore holds
 * stays the hole's current volume (z held) times 1 + p / K_f. */
static void fluid_bore_slab(void)
{
    char *doc = bore_doc_of(3, BORE_Q_3D, 1);
    fdem_model *m = network(doc);
    free(doc);
    if (!m) return;
    const double hole = 0.5 * 0.5 * 1.0;
    CHECK_REL(fdem_get_fluid(m).stored_volume, hole, 1e-12);
    run(m, 20);
    fdem_fluid_status f = fdem_get_fluid(m);
    CHECK_REL(f.stored_volume - hole, f.injected_volume, 1e-9);
    CHECK(f.source_pressure > 0, "the slab's bore is under pressure: %.3g Pa", f.source_pressure);
    fdem_model_destroy(m);
}
static void fluid_bore_3d(void) { check_bore(3, BORE_Q_3D, 200); }

/* ------------------------------------------------------- a wet joint */

/* A 1 x 0.2 m block in two rows of elements, joined along y = 0.1 by a
 * joint set of cohesion c and friction angle phi holding a pore pressure
 * p (or none); the rest of the block is far stronger. The bottom is fixed,
 * the top pressed by sigma_n and dragged along x; the drag's reaction
 * per unit thickness, once the joint slides, is c + (sigma_n - p) tan phi
 * over the width. Returns that reaction (mean over the last quarter). */
#define SHEAR_WIDTH 1.0
#define SHEAR_SIGMA 1e7
#define SHEAR_C 1e4
#define SHEAR_PHI 30.0

static double wet_joint_shear(double pore, double *expected)
{
    fdem_model *m = fdem_model_create();
    fdem_error err;
    fdem_material_def rock = {.density = 2500, .young = 1e10, .poisson = 0.2, .damping = 0.3,
                              .has_fracture = 1};
    rock.fracture = (fdem_fracture_params){.tensile_strength = 1e9, .cohesion = 1e9,
                                           .friction_angle = 30, .energy_I = 1e6,
                                           .energy_II = 1e6};
    int mat = fdem_add_material(m, &rock, &err);
    fdem_mesh mesh;
    const int nx = 10, ny = 2;
    fdem_mesh_rectangle(0, 0, SHEAR_WIDTH, 0.2, nx, ny, &mesh, &err);
    int part = fdem_add_part(m, &mesh, mat, 1, &err);
    int32_t faces[2 * 16];
    int count = 0;
    for (int i = 0; i < mesh.node_count; i++)
        for (int k = 0; k < mesh.node_count; k++) {
            const double *a = mesh.xy + 2 * i, *b = mesh.xy + 2 * k;
            if (fabs(a[1] - 0.1) < 1e-9 && fabs(b[1] - 0.1) < 1e-9 && b[0] > a[0] &&
                fabs(b[0] - a[0] - SHEAR_WIDTH / nx) < 1e-9) {
                faces[2 * count] = i;
                faces[2 * count + 1] = k;
                count++;
            }
        }
    CHECK(count == nx, "%d faces on the interface", count);
    fdem_fracture_params weak = {.tensile_strength = 1e6, .cohesion = SHEAR_C,
                                 .friction_angle = SHEAR_PHI, .energy_I = 1e3,
                                 .energy_II = 1e9, .aperture0 = 1e-4};
    if (pore > 0) {
        weak.has_pore_pressure = 1;
        weak.pore_pressure[0] = pore;
    }
    fdem_add_joint_set(m, part, &weak, NULL, faces, count, &err);
    fdem_fluid_def water = {.viscosity = 1e-3, .bulk_modulus = 1e8, .density = 1000};
    fdem_set_fluid(m, &water, &err);
    fdem_constraint_def bottom = {.select = FDEM_SELECT_BOX, .box = {-1, -1e-6, 2, 1e-6},
                                  .kind = FDEM_CONSTRAINT_FIX, .fix_x = 1, .fix_y = 1};
    fdem_add_constraint(m, &bottom, &err);
    fdem_constraint_def top = {.select = FDEM_SELECT_BOX, .box = {-1, 0.2 - 1e-6, 2, 0.2 + 1e-6}};
    top.kind = FDEM_CONSTRAINT_PRESSURE;
    top.value[0] = SHEAR_SIGMA;
    fdem_add_constraint(m, &top, &err);
    /* the drag ramps up, so the block is pressed before it is dragged */
    const double ramp[] = {0, 0, 0.004, 0, 0.008, 1};
    fdem_constraint_def drag = top;
    drag.kind = FDEM_CONSTRAINT_VELOCITY;
    drag.value[0] = 0.02;
    drag.value[1] = 0;
    drag.free_y = 1;
    drag.amplitude = ramp;
    drag.amplitude_count = 3;
    int drag_index = fdem_add_constraint(m, &drag, &err);
    fdem_mesh_free(&mesh);
    if (fdem_model_finalize(m, &err)) {
        CHECK(0, "finalize: %s", err.message);
        fdem_model_destroy(m);
        return NAN;
    }
    const double end = 0.06, dt = fdem_get_dt(m);
    int steps = (int)(end / dt), tail = steps / 4;
    double sum = 0;
    for (int s = 0; s < steps; s++) {
        if (fdem_step(m, &err)) {
            CHECK(0, "step: %s", err.message);
            break;
        }
        if (s >= steps - tail) sum += fdem_constraint_forces(m)[2 * drag_index];
    }
    *expected = (SHEAR_C + (SHEAR_SIGMA - pore) * tan(SHEAR_PHI * M_PI / 180)) * SHEAR_WIDTH;
    fdem_fluid_status f = fdem_get_fluid(m);
    fprintf(stderr, "  pore %.3g Pa: drag %.6g N/m (want %.6g), %d steps, pore now %.6g Pa\n",
            pore, sum / tail, *expected, steps, f.open_joints ? fdem_fluid_pressure(m)[0] : 0.0);
    fdem_model_destroy(m);
    return sum / tail;
}

static void wet_joint_slides_at_effective_stress(void)
{
    double want_dry, want_wet;
    double dry = wet_joint_shear(0, &want_dry), wet = wet_joint_shear(4e6, &want_wet);
    CHECK_REL(dry, want_dry, 0.03);
    CHECK_REL(wet, want_wet, 0.03);
}

/* ------------------------------------------------------- at rest */

/* A fracturing block under an in-situ stress held by the matching
 * boundary stress, its joints holding a pore pressure: the joints carry
 * the effective traction sigma.n + p n from t = 0 and the fluid the rest,
 * so the block is at rest (contract 6.1 with 6.4). */
static void pore_pressure_starts_at_rest(void)
{
    json_t *doc = load(network_2d);
    edit(doc, "/constraints/0",
         load("{'box': [-1, -1, 1, 1], 'boundary_stress': {'value': [-2e6, -3e6, 0]}}"));
    edit(doc, "/parts/0/initial_stress", load("{'value': [-2e6, -3e6, 0]}"));
    edit(doc, "/materials/rock/fracture/pore_pressure", load("{'value': 5e5}"));
    edit(doc, "/materials/rock/damping", json_real(0));
    fdem_model *m = expect_built(doc, NULL);
    if (!m) return;
    fdem_fluid_status f0 = fdem_get_fluid(m);
    run(m, 400);
    fdem_energy e = fdem_get_energy(m);
    fdem_fluid_status f = fdem_get_fluid(m);
    const double *p = fdem_fluid_pressure(m), *damage = fdem_joint_damage(m);
    double most = 0, worst = 0;
    for (int j = 0; j < fdem_get_counts(m).joints; j++) {
        most = fmax(most, fabs(p[j] - 5e5));
        worst = fmax(worst, damage[j]);
    }
    fprintf(stderr, "  kinetic %.3g J of elastic %.3g J, joint %.3g J; pressure off by %.3g Pa at "
                    "most; %d open joints; largest damage %.3g\n",
            e.kinetic, e.elastic, e.joint, most, f.open_joints, worst);
    CHECK(f0.open_joints == fdem_get_counts(m).joints, "every joint wet");
    CHECK(e.kinetic < 1e-12 * e.elastic, "at rest: kinetic %.3g", e.kinetic);
    CHECK(most < 1e-6 * 5e5, "pressure held");
    CHECK(worst == 0, "no joint damaged");
    fdem_model_destroy(m);
}

/* ------------------------------------------------------- bad input */

static void fluid_bad_input(void)
{
    problems p;
    json_t *doc = load(network_2d);
    edit(doc, "/fluid/viscosity", json_real(-1));
    edit(doc, "/fluid/bulk_modulus", json_real(-1));
    edit(doc, "/fluid/density", json_real(-1));
    edit(doc, "/materials/rock/fracture/aperture0", json_real(0));
    build_refused(doc, GiB, &p);
    CHECK(p.status == 422, "status %d", p.status);
    CHECK(has_problem(&p, "/fluid/viscosity", "must be > 0"), "viscosity");
    CHECK(has_problem(&p, "/fluid/bulk_modulus", "must be > 0"), "bulk_modulus");
    CHECK(has_problem(&p, "/fluid/density", "must be >= 0"), "density");
    CHECK(has_problem(&p, "/materials/rock/fracture/aperture0", "must be > 0"), "aperture0");
    if (p.count != 4) dump_problems(&p);
    problems_free(&p);

    /* inject and pore pressure without fluid; pore pressure on a part
     * that does not fracture */
    doc = load(network_2d);
    edit(doc, "/fluid", NULL);
    edit(doc, "/parts/0/fracture", json_false());
    edit(doc, "/materials/rock/fracture/pore_pressure", load("{'value': 1e6}"));
    build_refused(doc, GiB, &p);
    CHECK(p.status == 422, "status %d", p.status);
    CHECK(has_problem(&p, "/constraints/0/inject", "no top-level \"fluid\""), "inject");
    CHECK(has_problem(&p, "/materials/rock/fracture/pore_pressure", "needs the top-level"),
          "pore pressure without fluid");
    CHECK(has_problem(&p, "/materials/rock/fracture/pore_pressure", "does not fracture"),
          "pore pressure on a part that does not fracture");
    problems_free(&p);

    /* an injection that touches no joint */
    doc = load(network_2d);
    edit(doc, "/parts/0/fracture", json_false());
    expect_doc(doc, GiB, 422, "/constraints/0", "none of the nodes");

    /* "bore": not a boolean, not with an injection; a bore whose selection
     * spans no boundary edge; a bore whose wall no joint meets */
    expect_variant_of(network_2d, "/constraints/0/bore", "'yes'", "/constraints/0/bore",
                      "true or false");
    expect_variant_of(network_2d, "/constraints/0",
                      "{'box': [-1, -1, 1, 1], 'pressure': 1e6, 'bore': true}",
                      "/constraints/0/bore", "with \"inject\" only");
    expect_variant_of(network_2d, "/constraints/0/bore", "true", "/constraints/0",
                      "selects no boundary edge");
    char *bore = bore_doc(2, 1);
    doc = load(bore);
    free(bore);
    edit(doc, "/parts/0/fracture", json_false());
    expect_doc(doc, GiB, 422, "/constraints/0", "no joint meets");
}

CHECK_MAIN(T(fluid_network_2d), T(fluid_network_3d), T(fluid_same_bits_2d), T(fluid_same_bits_3d),
           T(fluid_checkpoint_version_9), T(fluid_bore_2d), T(fluid_bore_3d),
           T(fluid_bore_slab),
           T(wet_joint_slides_at_effective_stress), T(pore_pressure_starts_at_rest),
           T(fluid_bad_input))
