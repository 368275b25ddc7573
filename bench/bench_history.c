/*
 * bench_history.c - what history output (contract 6.2) costs against a
 * step: the worker's history_take() (on the stepping thread: the cost the
 * run pays) and the I/O thread's append of rows to /history in the
 * daemon's batches, per row, next to the time of one step of the same
 * model, in 2D and 3D. Figures only.
 *
 * The model is a case document through case_build (the daemon's path): a
 * block with a fixed face, a pulled face and 8 monitoring points; the
 * constraints hold a face of nodes each, so the mean displacements sum a
 * face per row (the part of a row that grows with the model).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "case/case.h"
#include "result/result.h"
#include "state/history.h"
#include "math/clock.h"

#define BATCH 64 /* WORKER_HISTORY_BATCH */

static const char *doc_2d =
    "{\"materials\": {\"rock\": {\"density\": 2700, \"young\": 3e10, \"poisson\": 0.25}},"
    " \"parts\": [{\"name\": \"block\", \"material\": \"rock\","
    "   \"rectangle\": {\"origin\": [0, 0], \"size\": [1, 1], \"divisions\": [100, 100]}}],"
    " \"constraints\": [{\"box\": [-1, -1, 1e-9, 2], \"fix\": [\"x\", \"y\"]},"
    "                   {\"box\": [0.999999, -1, 2, 2], \"velocity\": [0.01, null]}],"
    " \"time\": {\"end\": 1},"
    " \"history\": {\"interval\": 1e-3, \"points\": [%s]}}";

static const char *doc_3d =
    "{\"dimension\": 3, \"materials\": {\"rock\": {\"density\": 2700, \"young\": 3e10,"
    " \"poisson\": 0.25}},"
    " \"parts\": [{\"name\": \"block\", \"material\": \"rock\","
    "   \"box\": {\"origin\": [0, 0, 0], \"size\": [1, 1, 1], \"divisions\": [16, 16, 16]}}],"
    " \"constraints\": [{\"box\": [-1, -1, -1, 1e-9, 2, 2], \"fix\": [\"x\", \"y\", \"z\"]},"
    "                   {\"box\": [0.999999, -1, -1, 2, 2, 2], \"velocity\": [0.01, null, null]}],"
    " \"time\": {\"end\": 1},"
    " \"history\": {\"interval\": 1e-3, \"points\": [%s]}}";

static void bench(const char *title, const char *layout, int dim)
{
    char points[1024] = "", doc[4096];
    for (int k = 0; k < 8; k++) {
        size_t at = strlen(points);
        if (dim == 2)
            snprintf(points + at, sizeof points - at, "%s{\"name\": \"p%d\", \"at\": [%g, 0.5]}",
                     k ? ", " : "", k, 0.1 + 0.1 * k);
        else
            snprintf(points + at, sizeof points - at,
                     "%s{\"name\": \"p%d\", \"at\": [%g, 0.5, 0.5]}", k ? ", " : "", k,
                     0.1 + 0.1 * k);
    }
    snprintf(doc, sizeof doc, layout, points);
    problems p;
    problems_init(&p);
    case_info info;
    fdem_model *m = case_build(doc, strlen(doc), (size_t)1 << 32, &info, &p);
    if (!m) {
        fprintf(stderr, "bench_history: %s: %s %s\n", title, p.count ? p.items[0].pointer : "",
                p.count ? p.items[0].message : "");
        problems_free(&p);
        return;
    }
    problems_free(&p);
    fdem_error err;
    int steps = 200, rows = 4096;
    double t0 = clock_wall_seconds();
    for (int s = 0; s < steps; s++) fdem_step(m, &err);
    double step_ns = (clock_wall_seconds() - t0) / steps * 1e9;

    history_row **batch = calloc(rows, sizeof *batch);
    t0 = clock_wall_seconds();
    for (int r = 0; r < rows; r++) batch[r] = history_take(m, info.history_nodes, 8);
    double take_ns = (clock_wall_seconds() - t0) / rows * 1e9;
    /* the part of a row that is the engine's energy accounts (O(nodes)) */
    double sink = 0;
    t0 = clock_wall_seconds();
    for (int r = 0; r < rows; r++) sink += fdem_get_energy(m).kinetic;
    double energy_ns = (clock_wall_seconds() - t0) / rows * 1e9 + 0 * sink;

    char path[] = "/tmp/bench_history_XXXXXX";
    int fd = mkstemp(path);
    if (fd >= 0) close(fd);
    char e[256] = "";
    result_file *f = result_create(path, m, &info, e, sizeof e);
    double write_ns = NAN;
    if (f) {
        for (int r = 0; r < rows; r++) batch[r]->time = r + 1.0; /* strictly growing */
        t0 = clock_wall_seconds();
        for (int r = 0; r < rows; r += BATCH)
            if (result_append_history(f, batch + r, BATCH, e, sizeof e) != 0) break;
        write_ns = (clock_wall_seconds() - t0) / rows * 1e9;
        result_close(f);
    } else {
        fprintf(stderr, "bench_history: %s\n", e);
    }
    unlink(path);
    for (int r = 0; r < rows; r++) history_free(batch[r]);
    free(batch);
    printf("%-26s %9d %10.0f %12.0f %10.0f %9.3f %13.0f %10.3f\n", title,
           fdem_get_counts(m).elements, step_ns, take_ns, energy_ns, take_ns / step_ns, write_ns,
           write_ns / step_ns);
    fdem_model_destroy(m);
}

int main(void)
{
    printf("## History rows (8 points, 2 constraints on a face each; batches of %d rows)\n",
           BATCH);
    printf("%-26s %9s %10s %12s %10s %9s %13s %10s\n", "model", "elements", "ns/step",
           "ns/row take", "of which E", "take/step", "ns/row write", "write/step");
    bench("2D block 100 x 100 cells", doc_2d, 2);
    bench("3D box 16^3 cells", doc_3d, 3);
    printf("take: on the stepping thread, once per history interval (at most every step);\n"
           "  'of which E' is fdem_get_energy(), the O(nodes) kinetic-energy pass every\n"
           "  energy account needs; the rest is O(points + constraint nodes).\n"
           "write: on the I/O thread, HDF5 append with the two flushes of a batch shared\n");
    return 0;
}
