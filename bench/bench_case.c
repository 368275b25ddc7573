/*
 * bench_case.c - where a real case's time goes, window by window (issue
 * 34): it steps a case document through case_build and the engine (the
 * daemon's own path, without HTTP or output) and prints, every window of
 * steps, the CPU ns per element-step, the split over the stages, and the
 * counts that drive the contact stage: candidate pairs, near pairs walked
 * and pairs touching per element, candidate pairs by how many mesh
 * vertices their two elements share (3: the two sides of a broken joint,
 * 2: an edge, 1: a corner, 0: none), elements with a vertex on a crack,
 * broken joints and detections per 1000 steps. A fracturing case's phase
 * after the split shows against its phase before it.
 *
 *   bench_case [--window STEPS] [--threads T] [--steps N] [CASE.json ...]
 *
 * --steps stops each case after N steps (for instruction counts under
 * valgrind).
 *
 * Without a case it runs examples/brazilian-disc-3d.json and
 * examples/brazilian-disc.json (2D) to their end (a minute or two). Figures,
 * not pass/fail.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "case/case.h"
#include "model/model.h"
#include "pair_kinds.h"
#include "math/clock.h"

static char *read_file(const char *path, size_t *length)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (text && fread(text, 1, (size_t)n, f) != (size_t)n) {
        free(text);
        text = NULL;
    }
    fclose(f);
    if (text) text[n] = 0;
    *length = (size_t)n;
    return text;
}

/* Elements with a vertex on a broken joint. */
static int elements_on_crack(const fdem_model *m)
{
    int on_crack = 0;
    if (!m->vertex_broken) return 0;
    for (int e = 0; e < m->elem_count; e++) {
        const int32_t *n = m->elem_node + (size_t)m->elem_nodes * (size_t)e;
        int on = 0;
        for (int i = 0; i < m->elem_nodes; i++) on |= m->vertex_broken[m->node_origin[n[i]]];
        on_crack += on;
    }
    return on_crack;
}

/* FNV-1a over the node positions and velocities: two runs with this hash
 * ended in the same state, bit for bit. */
static unsigned long long state_hash(const fdem_model *m)
{
    unsigned long long h = 1469598103934665603ull;
    size_t n = (size_t)m->dim * (size_t)m->node_count * sizeof(double);
    const unsigned char *arrays[2] = {(const unsigned char *)m->pos, (const unsigned char *)m->vel};
    for (int a = 0; a < 2; a++)
        for (size_t i = 0; i < n; i++) h = (h ^ arrays[a][i]) * 1099511628211ull;
    return h;
}

static int run_case(const char *path, int window, int threads, long max_steps)
{
    size_t length = 0;
    char *text = read_file(path, &length);
    if (!text) {
        fprintf(stderr, "bench_case: cannot read %s\n", path);
        return -1;
    }
    problems p;
    problems_init(&p);
    case_info info;
    fdem_model *m = case_build(text, length, (size_t)1 << 32, &info, &p);
    free(text);
    if (!m) {
        fprintf(stderr, "bench_case: %s was rejected (%d problems)\n", path, p.count);
        problems_free(&p);
        return -1;
    }
    problems_free(&p);
    fdem_set_threads(m, threads);
    int E = m->elem_count;
    printf("\n## %s: %d elements, %d joints, dt %.4g s, %d thread(s), windows of %d steps\n",
           path, E, m->joint_count, fdem_get_dt(m), threads, window);
    printf("%9s %7s %6s %5s %9s %7s %7s %6s %6s %7s %8s %7s %7s %7s %8s %7s %7s %7s %7s %6s  %s\n",
           "t ms", "step", "broken", "frag", "ns/el-st", "det/1k", "mend/1k", "elem%", "joint%", "detect%",
           "contact%", "integr%", "pair/el", "near/el", "touch/el", "face/el", "edge/el",
           "corn/el", "none/el", "crack%", "kernel ns/el over each kind once: face edge corner none");
    double total_cpu = 0, total_wall = 0;
    long total_steps = 0;
    while (fdem_get_time(m) < info.end_time && total_steps < max_steps) {
        fdem_stage_times before = fdem_get_stage_times(m);
        long det0 = m->contact.detections, mend0 = m->contact.break_mends;
        double c0 = clock_cpu_seconds(), w0 = clock_wall_seconds();
        int steps = 0;
        fdem_error err;
        for (; steps < window && fdem_get_time(m) < info.end_time &&
               total_steps + steps < max_steps;
             steps++)
            if (fdem_step(m, &err)) {
                fprintf(stderr, "bench_case: step failed: %s\n", err.message);
                fdem_model_destroy(m);
                return -1;
            }
        double cpu = clock_cpu_seconds() - c0;
        total_cpu += cpu;
        total_wall += clock_wall_seconds() - w0;
        total_steps += steps;
        fdem_stage_times t = fdem_get_stage_times(m);
        double fe = t.elements - before.elements, jo = t.joints - before.joints;
        double de = t.detection - before.detection;
        double co = t.contact - before.contact, in = t.integration - before.integration;
        double sum = fe + jo + de + co + in;
        double kinds[PAIR_KINDS], seconds[PAIR_KINDS], touching[PAIR_KINDS];
        pair_kind_counts(m, kinds);
        pair_kind_kernel(m, seconds, touching);
        fdem_counts c = fdem_get_counts(m);
        printf("%9.4f %7lld %6d %5d %9.1f %7.1f %7.1f %6.1f %6.1f %7.1f %8.1f %7.1f %7.2f %7.2f %8.3f "
               "%7.3f %7.3f %7.3f %7.3f %6.1f  %.0f %.0f %.0f %.0f\n",
               1e3 * fdem_get_time(m), (long long)fdem_get_step(m), c.broken_joints, c.fragments,
               cpu * 1e9 / ((double)steps * E), 1000.0 * (double)(c.detections - det0) / steps,
               1000.0 * (double)(m->contact.break_mends - mend0) / steps,
               100 * fe / sum, 100 * jo / sum, 100 * de / sum, 100 * co / sum, 100 * in / sum,
               (double)c.contact_pairs / E, (double)(m->contact.near_count + m->contact.near_vertex_count) / E,
               (double)c.contacts / E, kinds[PAIR_FACE] / E, kinds[PAIR_EDGE] / E,
               kinds[PAIR_CORNER] / E, kinds[PAIR_APART_MESH] / E,
               100.0 * elements_on_crack(m) / E, seconds[PAIR_FACE] * 1e9 / E,
               seconds[PAIR_EDGE] * 1e9 / E, seconds[PAIR_CORNER] * 1e9 / E,
               seconds[PAIR_APART_MESH] * 1e9 / E);
    }
    printf("whole run: %ld steps, CPU %.2f s (%.1f ns/element-step, %.0f steps/s), wall %.2f s, "
           "state %016llx\n", total_steps, total_cpu, total_cpu * 1e9 / ((double)total_steps * E),
           total_steps / total_cpu, total_wall, state_hash(m));
    fdem_model_destroy(m);
    return 0;
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    int window = 1000, threads = 1, cases = 0, failed = 0;
    long max_steps = 1L << 62;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--window") == 0 && i + 1 < argc) window = atoi(argv[++i]);
        else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc) max_steps = atol(argv[++i]);
        else {
            failed |= run_case(argv[i], window > 0 ? window : 1000, threads, max_steps) != 0;
            cases++;
        }
    }
    if (!cases) {
        failed |= run_case("examples/brazilian-disc-3d.json", window, threads, max_steps) != 0;
        failed |= run_case("examples/brazilian-disc.json", window, threads, max_steps) != 0;
    }
    return failed;
}
