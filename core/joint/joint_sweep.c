/*
 * joint_sweep.c - runs the joint loop of either dimension on any number of
 * threads, every node's force formed by adding its joints in joint order.
 *
 * Why not the colour plan the elements use (scatter_plan.c): that plan fixes
 * each node's order as colour by colour, so even one thread has to walk the
 * blocks of a colour spread over the whole mesh, then the next colour's.
 * 3D joints are numbered by their tetrahedra (joint_tet_model.c), so in
 * joint order face A's tetrahedron was met a layer earlier and is still in
 * the last-level cache; in colour order it was met half a mesh earlier and
 * comes from memory. At 1e5 tetrahedra that was about 4 ns an element-step
 * (median of ten interleaved rounds, 70.4 -> 66.4).
 *
 * How T threads keep joint order. Joints are cut into T contiguous ranges.
 * An element belongs to the range of the first joint that touches it (the
 * elements of a fracturing part keep their own nodes, and a joint touches
 * only its two elements' nodes). Range r walks its joints in order and adds
 * each face's forces into the face's element when r owns it. A face whose
 * element an earlier range owns (a slot) gets its forces set aside; after a
 * barrier, each range adds the slots of its elements, in joint order. All
 * joints of range r come before any joint of a later range, and every joint
 * of a later range that touches an element of r is a slot, so each node
 * sees its joints in joint order: the serial order, on any thread count.
 *
 * The energy sums are kept per fixed block of joints, in joint order within
 * it (a loop continues the running sums it is handed, so a block walked in
 * pieces around its slot joints sums as one walk), and totalled in block
 * order: the same bits on any thread count.
 *
 * A cut with more slots than an eighth of the joints (many threads on a
 * small mesh) is cut again into fewer ranges; a model whose joints touch
 * other elements' nodes (a fracture region's), or a cut that finds no
 * memory, runs on one thread.
 */
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "parallel/team.h"
#include "joint.h"

/* Frees a cut's joint and slot lists. */
static void sweep_drop_lists(joint_sweep *s)
{
    free(s->cross_joint);
    free(s->cross_slot);
    free(s->slot_face);
    free(s->slot_force);
    free(s->slot_live);
    s->cross_joint = s->cross_slot = s->slot_face = NULL;
    s->slot_force = NULL;
    s->slot_live = NULL;
}

void joint_sweep_free(joint_sweep *s)
{
    sweep_drop_lists(s);
    free(s->block_sum);
    free(s->range_block);
    free(s->cross_begin);
    free(s->slot_begin);
    memset(s, 0, sizeof *s);
}

/* The serial walk: one range of every block, no slot (keeps the blocks). */
static void sweep_serial(joint_sweep *s)
{
    sweep_drop_lists(s);
    s->ranges = 1;
    s->range_block[0] = 0;
    s->range_block[1] = s->block_count;
    s->cross_begin[0] = s->cross_begin[1] = 0;
    s->slot_begin[0] = s->slot_begin[1] = 0;
}

/* Joint index where block b begins (b = block_count: the end). */
static int block_first_joint(const joint_sweep *s, int joint_count, int b)
{
    return (long)b * s->block_size < joint_count ? b * s->block_size : joint_count;
}

/* The fixed blocks and the serial walk; 0, or -1 without memory. */
int joint_sweep_init(joint_sweep *s, int joint_count)
{
    joint_sweep_free(s);
    if (joint_count <= 0) return 0;
    s->block_size = scatter_block_size(joint_count, SCATTER_BLOCK_JOINTS);
    s->block_count = (joint_count + s->block_size - 1) / s->block_size;
    s->block_sum = calloc(SCATTER_SUMS * (size_t)s->block_count, sizeof *s->block_sum);
    s->range_block = malloc(2 * sizeof *s->range_block);
    s->cross_begin = malloc(2 * sizeof *s->cross_begin);
    s->slot_begin = malloc(2 * sizeof *s->slot_begin);
    if (!s->block_sum || !s->range_block || !s->cross_begin || !s->slot_begin) {
        joint_sweep_free(s);
        return -1;
    }
    sweep_serial(s);
    return 0;
}

size_t joint_sweep_bytes(const joint_sweep *s)
{
    if (!s->block_sum) return 0;
    size_t cross = (size_t)s->cross_begin[s->ranges], slots = (size_t)s->slot_begin[s->ranges];
    return SCATTER_SUMS * (size_t)s->block_count * sizeof(double) +
           3 * ((size_t)s->ranges + 1) * sizeof(int32_t) + cross * 3 * sizeof(int32_t) +
           slots * (sizeof(int32_t) + JOINT_FACE_VALUES * sizeof(double) + 1);
}

/* Whether every joint touches only nodes of its two elements, and those
 * nodes no other element's, the premise of owning by element. A fracture
 * region's elements share the nodes where no joint splits a vertex, so
 * two ranges could add to one node: such a model walks its joints on one
 * thread. */
static int joints_keep_to_their_elements(const fdem_model *m)
{
    const int D = m->dim, K = m->elem_nodes;
    for (int k = 0; k < m->part_count; k++)
        if (m->parts[k].region) return 0;
    for (int j = 0; j < m->joint_count; j++)
        for (int face = 0; face < 2; face++) {
            const int32_t *own = m->elem_node + (size_t)K * (size_t)m->joint_elem[2 * j + face];
            const int32_t *n = m->joint_node + (size_t)2 * D * j + (size_t)face * D;
            for (int i = 0; i < D; i++) {
                int found = 0;
                for (int c = 0; c < K; c++) found |= own[c] == n[i];
                if (!found) return 0;
            }
        }
    return 1;
}

/* Cuts the blocks into `ranges` ranges and lists their slots: 0, 1 when the
 * cut has too many slots, -1 without memory. owner is scratch, an element
 * each. */
static int sweep_cut(const fdem_model *m, joint_sweep *s, int ranges, uint8_t *owner)
{
    const int J = m->joint_count;
    int32_t *range_block = s->range_block;
    for (int r = 0; r <= ranges; r++) range_block[r] = (int)((long)s->block_count * r / ranges);
    memset(owner, 0xff, (size_t)m->elem_count);
    /* owners, and the slots and slot joints of each range */
    int32_t *cross_count = s->cross_begin, *slot_count = s->slot_begin;
    memset(cross_count, 0, sizeof *cross_count * ((size_t)ranges + 1));
    memset(slot_count, 0, sizeof *slot_count * ((size_t)ranges + 1));
    long slots = 0;
    for (int r = 0; r < ranges; r++) {
        int end = block_first_joint(s, J, range_block[r + 1]);
        for (int j = block_first_joint(s, J, range_block[r]); j < end; j++) {
            int crossing = 0;
            for (int face = 0; face < 2; face++) {
                int e = m->joint_elem[2 * j + face];
                if (owner[e] == 0xff) owner[e] = (uint8_t)r;
                if (owner[e] < r) {
                    slot_count[owner[e] + 1]++;
                    slots++;
                    crossing = 1;
                }
            }
            cross_count[r + 1] += crossing;
        }
    }
    if (slots > J / 8) return 1;
    for (int r = 0; r < ranges; r++) {
        cross_count[r + 1] += cross_count[r];
        slot_count[r + 1] += slot_count[r];
    }
    size_t nc = (size_t)cross_count[ranges], ns = (size_t)slots;
    s->cross_joint = malloc(sizeof *s->cross_joint * (nc + 1));
    s->cross_slot = malloc(sizeof *s->cross_slot * (2 * nc + 1));
    s->slot_face = malloc(sizeof *s->slot_face * (ns + 1));
    s->slot_force = malloc(sizeof *s->slot_force * JOINT_FACE_VALUES * (ns + 1));
    s->slot_live = malloc(ns + 1);
    int32_t *fill = malloc(sizeof *fill * ((size_t)ranges + 1));
    if (!s->cross_joint || !s->cross_slot || !s->slot_face || !s->slot_force || !s->slot_live ||
        !fill) {
        free(fill);
        return -1;
    }
    /* slots by owner in joint order: joints are met in order below */
    memcpy(fill, slot_count, sizeof *fill * (size_t)ranges);
    size_t c = 0;
    for (int r = 0; r < ranges; r++) {
        int end = block_first_joint(s, J, range_block[r + 1]);
        for (int j = block_first_joint(s, J, range_block[r]); j < end; j++) {
            int slot[2] = {-1, -1};
            for (int face = 0; face < 2; face++) {
                int e = m->joint_elem[2 * j + face];
                if (owner[e] >= r) continue;
                slot[face] = fill[owner[e]]++;
                s->slot_face[slot[face]] = 2 * j + face;
            }
            if (slot[0] < 0 && slot[1] < 0) continue;
            s->cross_joint[c] = j;
            s->cross_slot[2 * c] = slot[0];
            s->cross_slot[2 * c + 1] = slot[1];
            c++;
        }
    }
    free(fill);
    s->ranges = ranges;
    return 0;
}

/* Ranges for m->threads threads, or the serial walk. */
static void sweep_prepare(fdem_model *m, joint_sweep *s)
{
    sweep_serial(s);
    s->threads = m->threads;
    int ranges = m->threads < s->block_count ? m->threads : s->block_count;
    if (ranges > 255) ranges = 255; /* owners are bytes */
    if (ranges < 2 || !joints_keep_to_their_elements(m)) return;
    int32_t *range_block = realloc(s->range_block, sizeof *range_block * ((size_t)ranges + 1));
    int32_t *cross_begin = realloc(s->cross_begin, sizeof *cross_begin * ((size_t)ranges + 1));
    int32_t *slot_begin = realloc(s->slot_begin, sizeof *slot_begin * ((size_t)ranges + 1));
    if (range_block) s->range_block = range_block;
    if (cross_begin) s->cross_begin = cross_begin;
    if (slot_begin) s->slot_begin = slot_begin;
    uint8_t *owner = malloc((size_t)m->elem_count);
    int rc = -1;
    if (range_block && cross_begin && slot_begin && owner)
        while (ranges >= 2 && (rc = sweep_cut(m, s, ranges, owner)) == 1) ranges /= 2;
    free(owner);
    if (rc != 0) sweep_serial(s);
}

/* Adds a face's share: +fa to face A's nodes, -fa to face B's (the
 * operations the loops' own scatters do, so the same bits). */
static void face_add(fdem_model *m, int j, int face, const double *fa)
{
    const int D = m->dim;
    const int32_t *n = m->joint_node + (size_t)2 * D * j + (size_t)face * D;
    for (int i = 0; i < D; i++) {
        double *f = m->force + (size_t)D * n[i];
        for (int c = 0; c < D; c++) f[c] = face ? f[c] - fa[D * i + c] : f[c] + fa[D * i + c];
    }
}

/* A slot joint of range r: its own faces' forces added, the others set
 * aside. */
static void sweep_cross_joint(fdem_model *m, joint_sweep *s, size_t c, joint_one_fn one_fn,
                              double sums[SCATTER_SUMS])
{
    double fa[JOINT_FACE_VALUES];
    joint_totals t = joint_totals_load(sums);
    int j = s->cross_joint[c], live = one_fn(m, j, &t, fa);
    joint_totals_store(&t, sums);
    for (int face = 0; face < 2; face++) {
        int slot = s->cross_slot[2 * c + face];
        if (slot >= 0) {
            s->slot_live[slot] = (uint8_t)live;
            if (live) /* dim x dim values: a 2D joint sets only the first four */
                memcpy(s->slot_force + JOINT_FACE_VALUES * (size_t)slot, fa,
                       sizeof(double) * (size_t)(m->dim * m->dim));
        } else if (live) {
            face_add(m, j, face, fa);
        }
    }
}

/* Range r's joints in order, block by block, each slot joint on its own. */
static void sweep_range(fdem_model *m, joint_sweep *s, int r, scatter_block_fn range_fn,
                        joint_one_fn one_fn)
{
    const int J = m->joint_count;
    int c = s->cross_begin[r], c_end = s->cross_begin[r + 1];
    for (int b = s->range_block[r]; b < s->range_block[r + 1]; b++) {
        double *sum = s->block_sum + SCATTER_SUMS * (size_t)b;
        for (int i = 0; i < SCATTER_SUMS; i++) sum[i] = 0;
        int j = block_first_joint(s, J, b), end = block_first_joint(s, J, b + 1);
        while (j < end) {
            int stop = c < c_end && s->cross_joint[c] < end ? s->cross_joint[c] : end;
            if (stop > j) range_fn(m, j, stop, sum);
            if (stop == end) break;
            sweep_cross_joint(m, s, (size_t)c++, one_fn, sum);
            j = stop + 1;
        }
    }
}

/* The slots range r owns, in joint order. */
static void sweep_settle(fdem_model *m, const joint_sweep *s, int r)
{
    for (int slot = s->slot_begin[r]; slot < s->slot_begin[r + 1]; slot++)
        if (s->slot_live[slot])
            face_add(m, s->slot_face[slot] / 2, s->slot_face[slot] % 2,
                     s->slot_force + JOINT_FACE_VALUES * (size_t)slot);
}

void joint_sweep_run(fdem_model *m, scatter_block_fn range_fn, joint_one_fn one_fn,
                     double totals[SCATTER_SUMS])
{
    joint_sweep *s = &m->joint_sweep;
    if (!s->block_sum) return;
    if (s->threads != m->threads) sweep_prepare(m, s);
    if (s->ranges > 1) {
#pragma omp parallel num_threads(s->ranges)
        {
            int t, nt;
            parallel_team(&t, &nt);
            for (int r = t; r < s->ranges; r += nt) sweep_range(m, s, r, range_fn, one_fn);
#pragma omp barrier
            for (int r = t; r < s->ranges; r += nt) sweep_settle(m, s, r);
        }
    } else {
        sweep_range(m, s, 0, range_fn, one_fn);
    }
    for (int b = 0; b < s->block_count; b++)
        scatter_sums_add(totals, s->block_sum + SCATTER_SUMS * (size_t)b);
}
