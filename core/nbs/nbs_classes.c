/*
 * nbs_classes.c - detection that skips what it can never list: the bulk
 * body of a fracturing model, size classes on graded meshes, each set on
 * its own Munjiza-NBS grid, the pairs between sets from a cell lookup
 * (nbs_classes.h). One algorithm for both dimensions; the grid of a set is
 * the dimension's detector (nbs.c, nbs_3d.c).
 *
 * Why it is shaped this way:
 *  - A fracturing model's bodies are its pieces (joint_contact_bodies):
 *    every element off the cracks shares its piece's id, and one grid
 *    tested all their pairs only to skip them (the penny: ~1e4 tests an
 *    element at each of its 5-12 detections per 1000 steps, which a break
 *    forces). The bulk, found by a majority vote, is never tested against
 *    itself: the rest (cracks, other pieces) is one grid's input, and each
 *    of its elements meets the bulk through the bulk's cells.
 *  - One grid's cell is the largest diameter. On a graded mesh (a fine
 *    zone around a crack or a tunnel in a coarse block) the small elements
 *    then crowd into few cells, and each meets all its cell's crowd. With
 *    the radii of a class within a factor of 2, a cell holds a bounded
 *    number of its elements again (for shapes that are not flat), and each
 *    class's detection is O(its count).
 *  - A pair of a small element s and a large one l has |cs - cl| <=
 *    rs + rl <= 2 rmax(L), less than the larger class's (padded) cell: s
 *    and l are in neighbouring cells of L's grid. L's elements go onto
 *    singly connected lists by cell (heads in a table of a power of two
 *    >= 2 n_L, hashed on the integer cell, next per element: O(n_L), never
 *    an array over the extent), and each smaller element walks the lists of
 *    its 9 (27) neighbouring cells. Hashing may put two cells on one list;
 *    a list is walked once per element (stamped), so each pair is met once
 *    and the hash only adds walking, never pairs. An element outside L's
 *    box widened by a cell meets nothing of L and looks nothing up.
 *  - The pair test is the all-pairs reference's (nbs_internal.h), and it
 *    is symmetric bit for bit (dx and -dx square alike, the sums are in the
 *    same order), so the set is exactly the reference's.
 *  - Classes must pay: a uniform mesh (every radius within a factor of 2
 *    of the largest, found in one pass of compares) goes to the one grid
 *    untouched. Otherwise the candidates of one grid and of the classes
 *    (gathering, each class's grid, the lookups) are estimated from each
 *    set's count over its box (box_crowd), and the classes are used only
 *    when they cost under 3/4 of one grid: on the penny (radii 0.08-0.30 m
 *    with the buffer, in a model 2-3 cells across) they do not.
 *  - Everything is a pure function of the circles, in a fixed order, and
 *    serial: the same list on any thread count and after a restore.
 */
#include "nbs_classes.h"

#include <string.h>

#include "nbs_internal.h"

void nbs_classes_init(nbs_classes *c)
{
    memset(c, 0, sizeof *c);
    nbs_pairs_init(&c->sub_pairs);
}

void nbs_classes_free(nbs_classes *c)
{
    free(c->member);
    free(c->cell_head);
    free(c->cell_next);
    free(c->sub);
    free(c->sub_body);
    nbs_pairs_free(&c->sub_pairs);
    nbs_classes_init(c);
}

size_t nbs_classes_memory_bytes(const nbs_classes *c)
{
    return c->n_capacity * (3 * sizeof(int32_t) + 4 * sizeof(double)) +
           2 * c->head_capacity * sizeof(int32_t) + 2 * c->sub_pairs.capacity * sizeof(int32_t);
}

/* ------------------------------------------------------------- the input */

/* The circles (dim 2, c[2] unused) or spheres. */
typedef struct classes_in {
    int dim;
    size_t n;
    const double *c[3], *r;
    const int32_t *body;
} classes_in;

static inline int in_valid(const classes_in *in, int32_t i)
{
    if (in->dim == 3)
        return nbs3_sphere_valid(in->c[0][i], in->c[1][i], in->c[2][i], in->r[i]);
    return nbs_circle_valid(in->c[0][i], in->c[1][i], in->r[i]);
}


/* ------------------------------------------------------------- scratch */

/* Room for `count` gathered elements; 0, or -1 out of memory. */
static int classes_reserve(nbs_classes *c, size_t count)
{
    if (count <= c->n_capacity) return 0;
    size_t cap = count > 2 * c->n_capacity ? count : 2 * c->n_capacity;
    int32_t *member = realloc(c->member, cap * sizeof *member);
    if (member) c->member = member;
    int32_t *next = realloc(c->cell_next, cap * sizeof *next);
    if (next) c->cell_next = next;
    int32_t *body = realloc(c->sub_body, cap * sizeof *body);
    if (body) c->sub_body = body;
    double *sub = realloc(c->sub, 4 * cap * sizeof *sub);
    if (sub) c->sub = sub;
    if (!member || !next || !body || !sub) return -1;
    c->n_capacity = cap;
    return 0;
}

/* The extent of a set of centres, and its largest radius. */
typedef struct classes_box {
    double lo[3], hi[3], rmax;
    size_t count;
} classes_box;

static void box_clear(classes_box *b)
{
    for (int a = 0; a < 3; a++) b->lo[a] = DBL_MAX, b->hi[a] = -DBL_MAX;
    b->rmax = 0.0;
    b->count = 0;
}

static void box_add(classes_box *b, const classes_in *in, int32_t e)
{
    for (int a = 0; a < in->dim; a++) {
        double v = in->c[a][e];
        b->lo[a] = v < b->lo[a] ? v : b->lo[a];
        b->hi[a] = v > b->hi[a] ? v : b->hi[a];
    }
    b->rmax = in->r[e] > b->rmax ? in->r[e] : b->rmax;
    b->count++;
}

static double box_span(const classes_box *b, int dim)
{
    double span = 0.0;
    for (int a = 0; a < dim; a++) span = fmax(span, b->hi[a] - b->lo[a]);
    return span;
}

/* ------------------------------------------------------ one set's grid */

/* `count` elements (member numbers) on one grid of the dimension; their
 * pairs appended in element numbers. */
static int classes_within(nbs_classes *c, const classes_in *in, const int32_t *member,
                          size_t count, void *grid, nbs_pairs *pairs)
{
    if (count < 2) return 0;
    size_t cap = c->n_capacity;
    double *s[4] = {c->sub, c->sub + cap, c->sub + 2 * cap, c->sub + 3 * cap};
    for (size_t q = 0; q < count; q++) {
        int32_t e = member[q];
        for (int a = 0; a < in->dim; a++) s[a][q] = in->c[a][e];
        s[3][q] = in->r[e];
        if (in->body) c->sub_body[q] = in->body[e];
    }
    const int32_t *body = in->body ? c->sub_body : NULL;
    int failed = in->dim == 3
                     ? nbs_detect_3d(grid, count, s[0], s[1], s[2], s[3], body, &c->sub_pairs)
                     : nbs_detect(grid, count, s[0], s[1], s[3], body, &c->sub_pairs);
    if (failed || nbs_pairs_grow(pairs, pairs->count + c->sub_pairs.count)) return -1;
    for (size_t q = 0; q < c->sub_pairs.count; q++) {
        pairs->a[pairs->count] = member[c->sub_pairs.a[q]];
        pairs->b[pairs->count] = member[c->sub_pairs.b[q]];
        pairs->count++;
    }
    return 0;
}

/* ----------------------------------------------- between two sets */

/* A set's cells: integer cells of size `cell` from the common origin,
 * hashed onto `mask + 1` heads. */
typedef struct classes_cells {
    const int32_t *member;       /* the set, in member order */
    const double *sphere;        /* its (x, y, z, r) in member order */
    int32_t *stamp;              /* per slot: the last element that walked it */
    double lo[3], inv, cell;
    double box_lo[3], box_hi[3]; /* its centres, widened by a cell */
    uint64_t mask;
} classes_cells;

static inline void cell_of(const classes_cells *g, const classes_in *in, int32_t e, int64_t *v)
{
    v[2] = 0;
    for (int a = 0; a < in->dim; a++) v[a] = (int64_t)((in->c[a][e] - g->lo[a]) * g->inv);
}

static inline uint64_t cell_slot(const classes_cells *g, const int64_t *v)
{
    uint64_t h = (uint64_t)v[0] * 0x9E3779B97F4A7C15u ^ (uint64_t)v[1] * 0xC2B2AE3D27D4EB4Fu ^
                 (uint64_t)v[2] * 0x165667B19E3779F9u;
    return (h ^ (h >> 29)) & g->mask;
}

/* The set's elements onto the lists of their cells of size `cell` from
 * the origin `lo` (head insertion, in member order), their spheres packed
 * in that order (c->sub: the lookups read one line a candidate). */
static int classes_cells_build(nbs_classes *c, const classes_in *in, const int32_t *member,
                               size_t count, double cell, const double *lo, classes_cells *g)
{
    size_t table = nbs_next_pow2(2 * count);
    if (table > c->head_capacity) {
        int32_t *head = realloc(c->cell_head, 2 * table * sizeof *head);
        if (!head) return -1;
        c->cell_head = head;
        c->head_capacity = table;
    }
    nbs_fill_empty(c->cell_head, 2 * table); /* heads, then the slots' stamps */
    g->member = member;
    g->stamp = c->cell_head + table;
    g->sphere = c->sub;
    g->mask = table - 1;
    g->cell = cell;
    g->inv = 1.0 / cell;
    for (int a = 0; a < 3; a++) {
        g->lo[a] = lo[a];
        g->box_lo[a] = DBL_MAX;
        g->box_hi[a] = -DBL_MAX;
    }
    for (size_t q = 0; q < count; q++) {
        int32_t e = member[q];
        int64_t v[3] = {0, 0, 0};
        cell_of(g, in, e, v);
        uint64_t s = cell_slot(g, v);
        c->cell_next[q] = c->cell_head[s];
        c->cell_head[s] = (int32_t)q;
        double *packed = c->sub + 4 * q;
        for (int a = 0; a < 3; a++) packed[a] = a < in->dim ? in->c[a][e] : 0.0;
        packed[3] = in->r[e];
        for (int a = 0; a < in->dim; a++) {
            g->box_lo[a] = fmin(g->box_lo[a], in->c[a][e]);
            g->box_hi[a] = fmax(g->box_hi[a], in->c[a][e]);
        }
    }
    for (int a = 0; a < in->dim; a++) g->box_lo[a] -= g->cell, g->box_hi[a] += g->cell;
    return 0;
}

/* Element s against the lists of its neighbouring cells. Two cells may
 * hash to one slot: a slot s has walked already is stamped and skipped,
 * so each element of the set is met at most once, and the ones of the
 * neighbouring cells always. */
static int classes_lookup(nbs_classes *c, const classes_in *in, const classes_cells *g,
                          int32_t s, nbs_pairs *pairs)
{
    int in_box = 1;
    for (int a = 0; a < in->dim; a++) {
        double v = in->c[a][s];
        in_box &= v >= g->box_lo[a] && v <= g->box_hi[a];
    }
    if (!in_box) return 0; /* nothing of the set within a cell */
    int64_t v[3] = {0, 0, 0}, w[3];
    cell_of(g, in, s, v);
    const double *x = in->c[0], *y = in->c[1], *z = in->c[2], *r = in->r;
    const int three = in->dim == 3;
    int zr = in->dim == 3 ? 1 : 0;
    for (int64_t dz = -zr; dz <= zr; dz++)
        for (int64_t dy = -1; dy <= 1; dy++)
            for (int64_t dx = -1; dx <= 1; dx++) {
                w[0] = v[0] + dx, w[1] = v[1] + dy, w[2] = v[2] + dz;
                uint64_t slot = cell_slot(g, w);
                if (g->stamp[slot] == s) continue;
                g->stamp[slot] = s;
                for (int32_t q = c->cell_head[slot]; q >= 0; q = c->cell_next[q]) {
                    const double *p = g->sphere + 4 * (size_t)q;
                    int hit = three ? nbs_spheres_touch(x[s], y[s], z[s], r[s], p[0], p[1], p[2], p[3])
                                    : nbs_circles_touch(x[s], y[s], r[s], p[0], p[1], p[3]);
                    if (!hit) continue;
                    int32_t l = g->member[q];
                    if (nbs_same_body(in->body, s, l)) continue;
                    if (nbs_pairs_push(pairs, s, l)) return -1;
                }
            }
    return 0;
}

/* Every pair between the set `big` (on cells of size `cell`, at least the
 * largest diameter of either set) and the elements of `few`. */
static int classes_between(nbs_classes *c, const classes_in *in, const int32_t *big,
                           size_t big_count, const int32_t *few, size_t few_count, double cell,
                           const double *lo, nbs_pairs *pairs)
{
    if (!big_count || !few_count) return 0;
    classes_cells g;
    if (classes_cells_build(c, in, big, big_count, cell, lo, &g)) return -1;
    for (size_t q = 0; q < few_count; q++)
        if (classes_lookup(c, in, &g, few[q], pairs)) return -1;
    return 0;
}

/* -------------------------------------------------------------- the bulk */

/* With pieces as bodies (a fracturing body: joint_contact_bodies) nearly
 * every element is one piece's, and its pairs are never listed; one grid
 * would still test them all (the penny: ~1e4 an element). The body of more
 * than half the valid elements (a majority vote, two passes), or -1. */
static int32_t bulk_body(const classes_in *in)
{
    if (!in->body) return -1;
    int32_t pick = -1;
    size_t votes = 0, valid = 0, held = 0;
    for (size_t i = 0; i < in->n; i++) {
        if (!in_valid(in, (int32_t)i)) continue;
        int32_t b = in->body[i];
        if (votes == 0) pick = b, votes = 1;
        else votes += b == pick ? 1 : (size_t)-1;
    }
    if (pick < 0) return -1; /* a negative id never skips a pair */
    for (size_t i = 0; i < in->n; i++) {
        if (!in_valid(in, (int32_t)i)) continue;
        valid++;
        held += in->body[i] == pick;
    }
    return 2 * held > valid ? pick : -1;
}

/* The rest on one grid, then the rest against the bulk's cells. */
static int bulk_detect(nbs_classes *c, const classes_in *in, int32_t bulk, void *grid,
                       nbs_pairs *pairs)
{
    if (classes_reserve(c, in->n)) return -1;
    classes_box rest, held, all;
    box_clear(&rest), box_clear(&held), box_clear(&all);
    size_t front = 0, back = in->n;
    for (size_t i = 0; i < in->n; i++) { /* the rest up from 0, the bulk down from n */
        if (!in_valid(in, (int32_t)i)) continue;
        int in_bulk = in->body[i] == bulk;
        box_add(in_bulk ? &held : &rest, in, (int32_t)i);
        box_add(&all, in, (int32_t)i);
        if (in_bulk) c->member[--back] = (int32_t)i;
        else c->member[front++] = (int32_t)i;
    }
    /* the bulk back in index order */
    for (size_t a = back, b = in->n - 1; a < b; a++, b--) {
        int32_t t = c->member[a];
        c->member[a] = c->member[b];
        c->member[b] = t;
    }
    pairs->count = 0;
    c->used = 2;
    if (classes_within(c, in, c->member, front, grid, pairs)) return -1;
    double cell = nbs_padded_cell(fmax(rest.rmax, held.rmax), box_span(&all, in->dim));
    return classes_between(c, in, c->member + back, in->n - back, c->member, front, cell, all.lo,
                           pairs);
}

/* ------------------------------------------------------- size classes */

typedef struct classes_plan {
    int count;                           /* non-empty classes, largest first */
    size_t start[NBS_CLASSES_MAX + 1];   /* their members in c->member */
    classes_box box[NBS_CLASSES_MAX];    /* their extents and largest radii */
    classes_box all;
} classes_plan;

/* Every radius within a factor of 2 of the largest: one class. One pass of
 * compares, all a uniform mesh pays (NaN compares false and is left to the
 * grid; a negative or absurd radius sends it on to the careful plan). */
static int classes_one(const double *r, size_t n)
{
    double lo = DBL_MAX, hi = 0.0;
    for (size_t i = 0; i < n; i++) {
        lo = r[i] < lo ? r[i] : lo;
        hi = r[i] > hi ? r[i] : hi;
    }
    return lo >= 0.0 && hi <= NBS_VALUE_LIMIT && 2.0 * lo > hi;
}

/* The class of radius ri: k with ri in (rmax / 2^(k+1), rmax / 2^k]. */
static int class_of(double ri, double rmax)
{
    if (!(ri > 0.0)) return NBS_CLASSES_MAX - 1;
    int e;
    frexp(rmax / ri, &e); /* rmax / ri = m 2^e, m in [0.5, 1) */
    int k = e - 1;
    return k < 0 ? 0 : (k >= NBS_CLASSES_MAX ? NBS_CLASSES_MAX - 1 : k);
}

/* The elements of a set found in a cell's neighbourhood, `cells` cells of
 * its grid (cell: its largest diameter), were they spread evenly over its
 * box: the candidates each of them tests, at most all. */
static double box_crowd(const classes_box *b, int dim, double cells)
{
    double d = 2.0 * b->rmax, cell_volume = 1.0, volume = 1.0;
    for (int a = 0; a < dim; a++) cell_volume *= d, volume *= b->hi[a] - b->lo[a] + d;
    double n = (double)b->count;
    return volume > 0.0 ? fmin(n, cells * n * cell_volume / volume) : n;
}

/* Classes are used when they cost under this much of one grid. */
#define CLASSES_PAY 0.75

/* Classes and their price against one grid's, in candidate tests: a grid
 * tests each element against its half mask (4.5 or 13.5 cells), a lookup
 * walks the full mask (9 or 27) of each larger class. Boxes see a graded
 * mesh's small elements crowded in their own zone. 1 if the classes pay
 * (c->member then holds them), 0 for one grid, -1 out of memory. */
static int classes_plan_make(nbs_classes *c, const classes_in *in, classes_plan *p)
{
    classes_box k_box[NBS_CLASSES_MAX];
    box_clear(&p->all);
    for (size_t i = 0; i < in->n; i++)
        if (in_valid(in, (int32_t)i)) box_add(&p->all, in, (int32_t)i);
    if (p->all.count < 2 || !(p->all.rmax > 0.0)) return 0;
    for (int k = 0; k < NBS_CLASSES_MAX; k++) box_clear(&k_box[k]);
    for (size_t i = 0; i < in->n; i++)
        if (in_valid(in, (int32_t)i)) box_add(&k_box[class_of(in->r[i], p->all.rmax)], in, (int32_t)i);
    double half = in->dim == 3 ? 13.5 : 4.5, full = in->dim == 3 ? 27.0 : 9.0;
    double single = (double)p->all.count * box_crowd(&p->all, in->dim, half), split = 0.0;
    p->count = 0;
    for (int k = 0; k < NBS_CLASSES_MAX; k++) {
        if (!k_box[k].count) continue;
        double n = (double)k_box[k].count;
        split += n * box_crowd(&k_box[k], in->dim, half);
        for (int L = 0; L < p->count; L++)
            split += n * full * (1.0 + box_crowd(&p->box[L], in->dim, 1.0));
        p->box[p->count++] = k_box[k];
    }
    if (p->count < 2 || !(split < CLASSES_PAY * single)) return 0;

    if (classes_reserve(c, p->all.count)) return -1;
    size_t at[NBS_CLASSES_MAX], sum = 0;
    int slot = 0;
    p->start[0] = 0;
    for (int k = 0; k < NBS_CLASSES_MAX; k++) { /* a counting sort, index order within */
        at[k] = sum;
        sum += k_box[k].count;
        if (k_box[k].count) p->start[++slot] = sum;
    }
    for (size_t i = 0; i < in->n; i++)
        if (in_valid(in, (int32_t)i))
            c->member[at[class_of(in->r[i], p->all.rmax)]++] = (int32_t)i;
    return 1;
}

/* Each class on its grid, then each larger class's cells against the
 * elements of every smaller one. */
static int classes_split(nbs_classes *c, const classes_in *in, const classes_plan *p, void *grid,
                         nbs_pairs *pairs)
{
    pairs->count = 0;
    c->used = p->count;
    for (int k = 0; k < p->count; k++)
        if (classes_within(c, in, c->member + p->start[k], p->start[k + 1] - p->start[k], grid,
                           pairs))
            return -1;
    double span = box_span(&p->all, in->dim);
    for (int L = 0; L + 1 < p->count; L++) {
        double cell = nbs_padded_cell(p->box[L].rmax, span);
        size_t after = p->start[L + 1];
        if (classes_between(c, in, c->member + p->start[L], after - p->start[L],
                            c->member + after, p->start[p->count] - after, cell, p->all.lo,
                            pairs))
            return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ detection */

static int classes_detect(nbs_classes *c, const classes_in *in, void *grid, nbs_pairs *pairs)
{
    c->used = 1;
    int32_t bulk = bulk_body(in);
    if (bulk >= 0) return bulk_detect(c, in, bulk, grid, pairs);
    classes_plan p;
    int plan = classes_one(in->r, in->n) ? 0 : classes_plan_make(c, in, &p);
    if (plan < 0) return -1;
    if (plan > 0) return classes_split(c, in, &p, grid, pairs);
    return in->dim == 3 ? nbs_detect_3d(grid, in->n, in->c[0], in->c[1], in->c[2], in->r,
                                        in->body, pairs)
                        : nbs_detect(grid, in->n, in->c[0], in->c[1], in->r, in->body, pairs);
}

int nbs_detect_classes(nbs_classes *c, nbs_grid *grid, size_t n, const double *cx,
                       const double *cy, const double *r, const int32_t *body,
                       nbs_pairs *pairs)
{
    if (n > NBS_MAX_CIRCLES) return -1;
    classes_in in = {2, n, {cx, cy, NULL}, r, body};
    return classes_detect(c, &in, grid, pairs);
}

int nbs_detect_classes_3d(nbs_classes *c, nbs_grid_3d *grid, size_t n, const double *cx,
                          const double *cy, const double *cz, const double *r,
                          const int32_t *body, nbs_pairs *pairs)
{
    if (n > NBS_MAX_CIRCLES) return -1;
    classes_in in = {3, n, {cx, cy, cz}, r, body};
    return classes_detect(c, &in, grid, pairs);
}
