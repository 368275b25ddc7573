/*
 * nbs_3d.c - Munjiza-NBS contact detection in 3D (Munjiza 2004, ch. 3.11,
 * seed page 145: M = 3N + nz + 2nx + 2ny).
 *
 * Owns: integerising bounding spheres onto a grid of cell size d (the
 * largest diameter), the three levels of singly connected lists of the book
 * (z-layers: layer_head / layer_next; y-lists of a layer and the layer below
 * it: two sets of row heads / next.row; x-lists of a row and the row below
 * it: two sets of cell heads / next.cell), the half contact mask in 3D, and
 * the all-pairs reference. What it shares with the 2D detector (pair list,
 * padding, folding, the old-list encoding) is in nbs_internal.h.
 *
 * Why it is shaped this way:
 *  - Integer RAM is exactly the book's 3N + nz + 2nx + 2ny: integer
 *    coordinates are not stored (that would be 3N more) but recomputed from
 *    the centre when needed - a subtract, a multiply and a convert, cheaper
 *    than the memory traffic of storing them at 1e6 elements. The one
 *    exception costs no memory: an element's x-link is unused from the
 *    mapping of its layer to the mapping of its row, and again once the
 *    row is out, and holds its x then (nbs3_layer_map): the walks read it
 *    beside the row link instead of converting on their chain of loads.
 *  - The bounds pass also writes a packed copy of the spheres, (x, y, z, r)
 *    in 32 bytes, and the walks read centres and radii from it: a candidate
 *    is one cache line, not one in each of four arrays, and its test two
 *    SSE2 subtractions and multiplications (the same arithmetic, in the
 *    same order, as nbs_spheres_touch). At density 1 this took 13-18 % off
 *    a detection of 1e4 .. 1e6 spheres (old and new run turn about). It
 *    costs 32 B a sphere, and 8-13 % (1.2-3.3 ns) at 1e6 spheres and 1/100
 *    .. 1/1e4 per cell: a sparse walk reads only x and y, and a line of
 *    the copy holds two spheres where a line of x holds eight. z is read
 *    from its own array: the layer passes read nothing else.
 *  - The y- and x-links of an element are side by side (nbs_next_3d):
 *    as two page-aligned arrays a store to one and the next load from the
 *    other stalled as 4 KiB aliases.
 *  - Half mask: an element meets the elements of its row mapped before it
 *    in cells x-1 .. x+1 (the row is mapped and tested in one pass), the
 *    cells (x-1 .. x+1, y-1, z) and the nine cells (x-1 .. x+1, y-1 .. y+1,
 *    z-1): every pair of neighbouring cells is met exactly once and no pair
 *    needs de-duplication.
 *  - Layers are done in runs of consecutive layers, bottom-up, and rows of a
 *    layer likewise, exactly as the 2D rows are: the layer (row) just done
 *    stays mapped in its set as the layer (row) below the next one, so each
 *    element is mapped and unmapped once per level. The rows of the layer
 *    below are not mapped to x-lists at all: their elements are walked
 *    against the x-lists of the rows (the mask is symmetric), which needs
 *    no third set of heads. With rows y and y-1 of the layer mapped, row
 *    y-1 below meets both and row y below meets y-1, so each row below is
 *    walked twice, not once for each of the three rows it meets.
 *  - An element whose three (six) neighbouring cells are all empty is
 *    skipped on one AND of their heads before its sphere is loaded, and a
 *    hit is a branch (a few candidates in a hundred touch even in a
 *    touching packing): sparse packings pay for the walk, not the tests.
 *  - Every table is a power of two >= 4 slots: at least one more than the
 *    cells it spans (an unfolded axis), or the fold. The neighbours v - 1
 *    and v + 1 are then one AND each and never branch on an edge: on an
 *    unfolded axis the wrap lands on an always-empty slot, and a cell
 *    coordinate is the same truncation and AND on either kind of axis.
 *    Three consecutive slots are always distinct, so a folded pair of cells
 *    is still met once; folding only adds candidates, which the exact
 *    sphere test removes.
 *  - Only non-empty layers and rows are visited, found by looping over
 *    elements (a loop that stops once the runs have taken every element:
 *    in a packed grid the first run takes them all); lists are cleared by
 *    looping over the elements just mapped. Nothing loops over nx, ny or
 *    nz, so CPU is O(N) however sparse.
 *  - The walk is instantiated twice, with and without body ids, so that
 *    a row costs no call (a sparse packing's rows hold one or two
 *    elements).
 *  - Spheres with a non-finite or absurd centre or radius take no part (in
 *    both detectors), as in 2D.
 */
#include "nbs_internal.h"

#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* --------------------------------------------------------------- spheres */

/* Bytes of a packed sphere (x, y, z, r), and its alignment: its two halves
 * are aligned SSE2 loads. */
#define NBS3_PACKED (4 * sizeof(double))

/* Element j's packed sphere, (x, y, z, r). */
static inline const double *nbs3_packed(const double *sphere, int32_t j)
{
    return sphere + 4 * (size_t)j;
}

/* The sphere test in SSE2 only where scalar doubles are SSE2 too: with x87
 * arithmetic (-m32) nbs_spheres_touch in the all-pairs check may round
 * twice where the SSE2 test rounds once, and the two would disagree. */
#if defined(__SSE2__) && defined(__SSE2_MATH__)
#define NBS3_SSE2_TEST 1
#else
#define NBS3_SSE2_TEST 0
#endif

/* ------------------------------------------------------------- lifecycle */

void nbs_grid_3d_init(nbs_grid_3d *grid)
{
    memset(grid, 0, sizeof *grid);
}

void nbs_grid_3d_free(nbs_grid_3d *grid)
{
    int32_t *arrays[] = {grid->layer_head, grid->layer_next, grid->row_head, grid->cell_head};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++) free(arrays[k]);
    free(grid->next);
    free(grid->sphere);
    nbs_grid_3d_init(grid);
}

size_t nbs_integers_3d(const nbs_grid_3d *grid)
{
    return 3 * grid->n_capacity + grid->nz_capacity + 2 * grid->nx_capacity +
           2 * grid->ny_capacity;
}

size_t nbs_memory_bytes_3d(const nbs_grid_3d *grid, const nbs_pairs *pairs)
{
    size_t bytes = nbs_integers_3d(grid) * sizeof(int32_t) + grid->n_capacity * NBS3_PACKED;
    if (pairs) bytes += 2 * pairs->capacity * sizeof(int32_t);
    return bytes;
}

/* Grows a table of heads (sets of `size` slots each) to hold `want` slots a
 * set, all empty. Between detections every head is empty, so nothing is
 * kept across the move. */
static int nbs3_grow_heads(int32_t **heads, size_t *capacity, size_t want, size_t sets)
{
    if (want <= *capacity) return 0;
    if (nbs_grow_array(heads, sets * want)) return -1;
    nbs_fill_empty(*heads, sets * want);
    *capacity = want;
    return 0;
}

/* The per-element arrays, before the bounds pass writes the packed copy. */
static int nbs3_reserve_elements(nbs_grid_3d *g, size_t n)
{
    if (n > g->n_capacity) {
        size_t cap = n > 2 * g->n_capacity ? n : 2 * g->n_capacity;
        if (nbs_grow_array(&g->layer_next, cap)) return -1;
        nbs_next_3d *next = realloc(g->next, cap * sizeof *next);
        if (!next) return -1;
        g->next = next;
        double *sphere = aligned_alloc(NBS3_PACKED, cap * NBS3_PACKED);
        if (!sphere) return -1;
        free(g->sphere); /* nothing in it outlives a detection */
        g->sphere = sphere;
        g->n_capacity = cap;
    }
    return 0;
}

static int nbs3_reserve_heads(nbs_grid_3d *g, int32_t nx, int32_t ny, int32_t nz)
{
    if (nbs3_grow_heads(&g->layer_head, &g->nz_capacity, (size_t)nz, 1) ||
        nbs3_grow_heads(&g->row_head, &g->ny_capacity, (size_t)ny, 2) ||
        nbs3_grow_heads(&g->cell_head, &g->nx_capacity, (size_t)nx, 2))
        return -1;
    return 0;
}

static void nbs3_reset_heads(nbs_grid_3d *g)
{
    if (g->layer_head) nbs_fill_empty(g->layer_head, g->nz_capacity);
    if (g->row_head) nbs_fill_empty(g->row_head, 2 * g->ny_capacity);
    if (g->cell_head) nbs_fill_empty(g->cell_head, 2 * g->nx_capacity);
}

/* ---------------------------------------------------------------- layout */

typedef struct nbs3_axis {
    double lo;      /* smallest centre coordinate */
    int64_t mask;   /* size - 1 */
    int32_t size;   /* table slots, a power of two >= 4: > cells spanned, or the fold */
} nbs3_axis;

typedef struct nbs3_bounds {
    double lo[3], hi[3], rmax;
    size_t valid;
    int all_valid;
} nbs3_bounds;

#if defined(__SSE2__)
static inline double nbs3_lanes_min(__m128d v)
{
    double t[2];
    _mm_storeu_pd(t, v);
    return t[0] < t[1] ? t[0] : t[1];
}

static inline double nbs3_lanes_max(__m128d v)
{
    double t[2];
    _mm_storeu_pd(t, v);
    return t[0] > t[1] ? t[0] : t[1];
}
#endif

/* Extremes of the valid spheres. Whether every sphere is valid is decided
 * from one sum (finite only without NaN or infinity) and the extremes, so
 * the usual case runs the loop without a per-sphere test. The axes are
 * written out, each extreme keeps its own register (min/max in the order
 * that compiles to one instruction) and the sum is one addition a sphere on
 * its dependent chain: this loop was 38 instructions a sphere, a sixth of
 * a sparse detection. With SSE2 it takes two spheres a step (0.3-1 ns of
 * the 1e6 detection at density 1): minpd and maxpd pick as the scalar
 * a < b ? a : b does in each lane, so the extremes are the same numbers
 * (a -0 and a +0 may trade places as the lower bound, which changes no
 * difference v - lo nor the cell), and the order of the sum does not
 * matter, as it only decides finiteness (all-valid values are below
 * 1e150, so no order overflows). It writes every sphere, valid or not, to
 * `packed` on the way (an invalid one is never read from it). */
static nbs3_bounds nbs3_bounds_of(size_t n, const double *const c[3], const double *r,
                                  double *restrict packed)
{
    nbs3_bounds b;
    const double *cx = c[0], *cy = c[1], *cz = c[2];
    double lx = DBL_MAX, ly = DBL_MAX, lz = DBL_MAX, hx = -DBL_MAX, hy = -DBL_MAX, hz = -DBL_MAX;
    double rmin = DBL_MAX, rmax = 0.0, sum = 0.0;
    size_t i = 0;
#if defined(__SSE2__)
    __m128d vlx = _mm_set1_pd(DBL_MAX), vly = vlx, vlz = vlx, vrmin = vlx;
    __m128d vhx = _mm_set1_pd(-DBL_MAX), vhy = vhx, vhz = vhx, vrmax = _mm_setzero_pd();
    __m128d vsum = _mm_setzero_pd();
    for (; i + 2 <= n; i += 2) {
        __m128d x = _mm_loadu_pd(cx + i), y = _mm_loadu_pd(cy + i);
        __m128d z = _mm_loadu_pd(cz + i), ri = _mm_loadu_pd(r + i);
        vlx = _mm_min_pd(vlx, x), vhx = _mm_max_pd(vhx, x);
        vly = _mm_min_pd(vly, y), vhy = _mm_max_pd(vhy, y);
        vlz = _mm_min_pd(vlz, z), vhz = _mm_max_pd(vhz, z);
        vrmin = _mm_min_pd(vrmin, ri), vrmax = _mm_max_pd(vrmax, ri);
        vsum = _mm_add_pd(vsum, _mm_add_pd(_mm_add_pd(x, y), _mm_add_pd(z, ri)));
        double *out = packed + 4 * i;
        _mm_store_pd(out, _mm_unpacklo_pd(x, y));
        _mm_store_pd(out + 2, _mm_unpacklo_pd(z, ri));
        _mm_store_pd(out + 4, _mm_unpackhi_pd(x, y));
        _mm_store_pd(out + 6, _mm_unpackhi_pd(z, ri));
    }
    lx = nbs3_lanes_min(vlx), ly = nbs3_lanes_min(vly), lz = nbs3_lanes_min(vlz);
    hx = nbs3_lanes_max(vhx), hy = nbs3_lanes_max(vhy), hz = nbs3_lanes_max(vhz);
    rmin = nbs3_lanes_min(vrmin), rmax = nbs3_lanes_max(vrmax);
    double lanes[2];
    _mm_storeu_pd(lanes, vsum);
    sum = lanes[0] + lanes[1];
#endif
    for (; i < n; i++) {
        double x = cx[i], y = cy[i], z = cz[i], ri = r[i];
        lx = lx < x ? lx : x, hx = hx > x ? hx : x;
        ly = ly < y ? ly : y, hy = hy > y ? hy : y;
        lz = lz < z ? lz : z, hz = hz > z ? hz : z;
        rmin = rmin < ri ? rmin : ri, rmax = rmax > ri ? rmax : ri;
        sum += (x + y) + (z + ri);
        double *out = packed + 4 * i;
        out[0] = x, out[1] = y, out[2] = z, out[3] = ri;
    }
    b.lo[0] = lx, b.lo[1] = ly, b.lo[2] = lz;
    b.hi[0] = hx, b.hi[1] = hy, b.hi[2] = hz;
    b.rmax = rmax;
    b.valid = n;
    b.all_valid = n > 0 && isfinite(sum) && nbs3_sphere_valid(lx, ly, lz, rmin) &&
                  nbs3_sphere_valid(hx, hy, hz, rmax);
    if (b.all_valid) return b;

    b.rmax = 0.0;
    b.valid = 0;
    for (int a = 0; a < 3; a++) b.lo[a] = DBL_MAX, b.hi[a] = -DBL_MAX;
    for (i = 0; i < n; i++) {
        if (!nbs3_sphere_valid(c[0][i], c[1][i], c[2][i], r[i])) continue;
        for (int a = 0; a < 3; a++) {
            b.lo[a] = fmin(b.lo[a], c[a][i]);
            b.hi[a] = fmax(b.hi[a], c[a][i]);
        }
        b.rmax = fmax(b.rmax, r[i]);
        b.valid++;
    }
    return b;
}

/* At least one spare slot beyond the cells spanned, so that the wrap-around
 * neighbour of an edge cell is an empty slot, rounded up to a power of two
 * (at most doubling a table that is already O(N)); folded when the cells
 * spanned exceed the table of O(N). */
static nbs3_axis nbs3_axis_plan(double lo, double hi, double inv_cell, int32_t table)
{
    nbs3_axis ax;
    int32_t spanned;
    int fold;
    nbs_axis_plan(hi - lo, inv_cell, table - 1, &spanned, &fold);
    ax.lo = lo;
    ax.size = fold ? table : (int32_t)nbs_next_pow2((size_t)spanned + 1);
    ax.mask = (int64_t)ax.size - 1;
    return ax;
}

/* --------------------------------------------------------------- the scan */

/* What the detection reads and writes while it walks the lists. rows[k] and
 * cells[k] are the two sets of heads. */
typedef struct nbs3_scan {
    const double *cx, *cy, *cz, *r, *sphere;
    const int32_t *body;
    double inv;
    nbs3_axis ax, ay, az;
    int32_t *layer_head, *layer_next, *rows[2], *cells[2];
    nbs_next_3d *next;
} nbs3_scan;

/* x >= lo, so truncation is floor */
static inline int32_t nbs3_coord(const nbs3_axis *a, double v, double inv)
{
    return (int32_t)((int64_t)((v - a->lo) * inv) & a->mask);
}

/* x and y from the packed copy, which the candidates read too; z from its
 * own array, where the layer passes find it beside nothing else */
static inline int32_t nbs3_x(const nbs3_scan *s, int32_t j)
{
    return nbs3_coord(&s->ax, nbs3_packed(s->sphere, j)[0], s->inv);
}

static inline int32_t nbs3_y(const nbs3_scan *s, int32_t j)
{
    return nbs3_coord(&s->ay, nbs3_packed(s->sphere, j)[1], s->inv);
}

static inline int32_t nbs3_z(const nbs3_scan *s, int32_t j)
{
    return nbs3_coord(&s->az, s->cz[j], s->inv);
}

/* neighbours on a table of a power of two slots */
static inline int32_t nbs3_down(int32_t v, int32_t size) { return (v - 1) & (size - 1); }
static inline int32_t nbs3_up(int32_t v, int32_t size) { return (v + 1) & (size - 1); }

/* Layer `list` into y-set k, and out again (by looping over its elements).
 * Mapping also puts each element's x in its x-link, dead until its row is
 * mapped: every walk of a row then reads x beside the row link it has just
 * loaded instead of converting the centre on its chain of dependent loads
 * (row link, centre, x, heads), and nbs3_row_unmap puts it back. Returns
 * the layer's element count. */
static int32_t nbs3_layer_map(const nbs3_scan *s, int k, int32_t list)
{
    int32_t *heads = s->rows[k], count = 0;
    for (int32_t j = list; j >= 0; j = s->layer_next[j], count++) {
        int32_t y = nbs3_y(s, j);
        s->next[j] = (nbs_next_3d){heads[y], nbs3_x(s, j)};
        heads[y] = j;
    }
    return count;
}

static void nbs3_layer_unmap(const nbs3_scan *s, int k, int32_t list)
{
    int32_t *heads = s->rows[k];
    for (int32_t j = list; j >= 0; j = s->layer_next[j]) heads[nbs3_y(s, j)] = NBS_EMPTY;
}

/* Row `list` into x-set k (head insertion: an element's link leads to the
 * elements of its cell mapped before it); returns the row's element count. */
static int32_t nbs3_row_map(const nbs3_scan *s, int k, int32_t list)
{
    int32_t *heads = s->cells[k], count = 0;
    for (int32_t j = list, after; j >= 0; j = after, count++) {
        after = s->next[j].row; /* read before the store beside it */
        int32_t x = s->next[j].cell;
        s->next[j].cell = heads[x];
        heads[x] = j;
    }
    return count;
}

/* Out of x-set k again, its x-links holding x again (nbs3_layer_map) for
 * the next layer's walks of this row. Inlined: it runs once a row, and a
 * sparse packing's rows hold one or two elements (1/1e4: 1.3-1.6 ns of
 * 22-26 an element as a call). */
static NBS_ALWAYS_INLINE void nbs3_row_unmap(const nbs3_scan *s, int k, int32_t list)
{
    int32_t *heads = s->cells[k];
    for (int32_t j = list, after; j >= 0; j = after) {
        after = s->next[j].row; /* read before the store beside it */
        int32_t x = nbs3_x(s, j);
        heads[x] = NBS_EMPTY;
        s->next[j].cell = x;
    }
}

/* The pair list in locals the compiler can keep in registers. */
typedef struct nbs3_out {
    int32_t *a, *b;
    size_t count, capacity;
    nbs_pairs *pairs;
} nbs3_out;

/* Makes room for `need` more pairs (one element's worst case), so the
 * candidate loops need no capacity test. */
static inline int nbs3_room(nbs3_out *o, size_t need)
{
    if (NBS_UNLIKELY(o->capacity - o->count < need)) {
        o->pairs->count = o->count;
        if (nbs_pairs_grow(o->pairs, o->count + need) != 0) return -1;
        o->a = o->pairs->a;
        o->b = o->pairs->b;
        o->capacity = o->pairs->capacity;
    }
    return 0;
}

/* What the candidate loops read, copied out of the scan: reached through
 * a pointer, the scan's fields would be reloaded after every store to a
 * list (an int32 store may alias them). */
typedef struct nbs3_probe {
    const double *sphere;
    const int32_t *body;
    const nbs_next_3d *next;
    int64_t xmask;
} nbs3_probe;

static inline nbs3_probe nbs3_probe_of(const nbs3_scan *s)
{
    nbs3_probe p = {s->sphere, s->body, s->next, s->ax.mask};
    return p;
}

/* The heads of the cells x-1, x, x+1 of an x-set. Cell heads are never in
 * the old encoding, so the three are all empty exactly when their AND is
 * negative: one branch skips an element with nothing to meet, and its
 * sphere is loaded only when there is. */
typedef struct nbs3_trio {
    int32_t down, mid, up;
} nbs3_trio;

static inline nbs3_trio nbs3_trio_of(const int32_t *cells, int32_t x, int32_t mask)
{
    nbs3_trio t = {cells[(x - 1) & mask], cells[x], cells[(x + 1) & mask]};
    return t;
}

static inline int32_t nbs3_trio_and(nbs3_trio t) { return t.down & t.mid & t.up; }

/* An element's sphere, loaded once for all the cells it meets. With SSE2
 * it is (x, y) and (z, -r): subtracting a candidate's (x, y) and (z, r)
 * gives dx, dy, dz and -(r + r_j) exactly, and squaring these the terms of
 * nbs_spheres_touch, which are added in its order: the same decisions as
 * the all-pairs check, bit for bit. */
typedef struct nbs3_ball {
#if NBS3_SSE2_TEST
    __m128d xy, zr;
#else
    double x, y, z, r;
#endif
    int32_t e;
} nbs3_ball;

static inline nbs3_ball nbs3_ball_of(const nbs3_probe *p, int32_t e)
{
    const double *q = nbs3_packed(p->sphere, e);
#if NBS3_SSE2_TEST
    nbs3_ball b = {_mm_load_pd(q), _mm_xor_pd(_mm_load_pd(q + 2), _mm_set_pd(-0.0, 0.0)), e};
#else
    nbs3_ball b = {q[0], q[1], q[2], q[3], e};
#endif
    return b;
}

static inline int nbs3_ball_touches(nbs3_ball b, const double *q)
{
#if NBS3_SSE2_TEST
    __m128d dxy = _mm_sub_pd(b.xy, _mm_load_pd(q));
    __m128d dzr = _mm_sub_pd(b.zr, _mm_load_pd(q + 2));
    dxy = _mm_mul_pd(dxy, dxy);
    dzr = _mm_mul_pd(dzr, dzr);
    __m128d dist2 = _mm_add_sd(_mm_add_sd(dxy, _mm_unpackhi_pd(dxy, dxy)), dzr);
    return _mm_comile_sd(dist2, _mm_unpackhi_pd(dzr, dzr));
#else
    return nbs_spheres_touch(b.x, b.y, b.z, b.r, q[0], q[1], q[2], q[3]);
#endif
}

/* Tests a ball against one cell's list. A hit is rare (a few in a hundred
 * candidates even in a touching packing), so it is a branch: cheaper than
 * writing every candidate and advancing by the outcome. The caller has made
 * room for the cell's pairs. */
static NBS_ALWAYS_INLINE void nbs3_chain_test(const nbs3_probe *p, int use_body, nbs3_ball b,
                                              int32_t list, nbs3_out *o)
{
    const double *sphere = p->sphere;
    const nbs_next_3d *next = p->next;
    for (int32_t j = list; j >= 0; j = next[j].cell) {
        if (!nbs3_ball_touches(b, nbs3_packed(sphere, j))) continue;
        if (use_body && nbs_same_body(p->body, b.e, j)) continue;
        o->a[o->count] = b.e;
        o->b[o->count] = j;
        o->count++;
    }
}

static NBS_ALWAYS_INLINE void nbs3_trio_test(const nbs3_probe *p, int use_body, nbs3_ball b,
                                             nbs3_trio t, nbs3_out *o)
{
    nbs3_chain_test(p, use_body, b, t.down, o);
    nbs3_chain_test(p, use_body, b, t.mid, o);
    nbs3_chain_test(p, use_body, b, t.up, o);
}

/* A row in x-set `cur` (count elements, known once mapped) and the row
 * below it in the same layer in x-set `held` (held_count elements). */
typedef struct nbs3_row {
    int32_t list, count, held_count;
    int cur, held;
} nbs3_row;

/* The row's own pass: mapping and testing in one, e meets the elements of
 * its row mapped before it in cells x-1, x, x+1 (so each pair of the row
 * once) and the held row's. The held set is empty when the row below is. */
static NBS_ALWAYS_INLINE int nbs3_row_own(const nbs3_scan *s, int use_body, nbs3_row *row,
                                          nbs_pairs *pairs)
{
    nbs3_out o = {pairs->a, pairs->b, pairs->count, pairs->capacity, pairs};
    const nbs3_probe p = nbs3_probe_of(s);
    nbs_next_3d *next = s->next;
    int32_t *cur = s->cells[row->cur];
    const int32_t *held = s->cells[row->held];
    const int32_t mask = (int32_t)p.xmask;
    const size_t held_count = (size_t)row->held_count;
    int32_t count = 0;
    for (int32_t e = row->list, after; e >= 0; e = after, count++) {
        after = next[e].row; /* read before the store beside it */
        int32_t x = next[e].cell; /* nbs3_layer_map */
        nbs3_trio here = nbs3_trio_of(cur, x, mask), below = nbs3_trio_of(held, x, mask);
        if ((nbs3_trio_and(here) & nbs3_trio_and(below)) >= 0) {
            if (nbs3_room(&o, (size_t)count + held_count) != 0) return -1;
            nbs3_ball b = nbs3_ball_of(&p, e);
            nbs3_trio_test(&p, use_body, b, here, &o);
            nbs3_trio_test(&p, use_body, b, below, &o);
        }
        next[e].cell = here.mid;
        cur[x] = e;
    }
    row->count = count;
    pairs->count = o.count;
    return 0;
}

/* A row of the layer below against one or two mapped rows of this layer
 * (x-sets `one`, `two`; two < 0: only one): each of its elements against
 * their x-lists. */
static NBS_ALWAYS_INLINE int nbs3_row_cross(const nbs3_scan *s, int use_body, int32_t list,
                                            int one, int two, size_t room, nbs_pairs *pairs)
{
    nbs3_out o = {pairs->a, pairs->b, pairs->count, pairs->capacity, pairs};
    const nbs3_probe p = nbs3_probe_of(s);
    const nbs_next_3d *next = s->next;
    const int32_t *set1 = s->cells[one], *set2 = s->cells[two < 0 ? one : two];
    const int32_t mask = (int32_t)p.xmask;
    for (int32_t j = list; j >= 0; j = next[j].row) {
        int32_t x = next[j].cell; /* nbs3_row_unmap */
        nbs3_trio t1 = nbs3_trio_of(set1, x, mask);
        int32_t any = nbs3_trio_and(t1);
        nbs3_trio t2 = t1;
        if (two >= 0) t2 = nbs3_trio_of(set2, x, mask), any &= nbs3_trio_and(t2);
        if (any < 0) continue;
        if (nbs3_room(&o, room) != 0) return -1;
        nbs3_ball b = nbs3_ball_of(&p, j);
        nbs3_trio_test(&p, use_body, b, t1, &o);
        if (two >= 0) nbs3_trio_test(&p, use_body, b, t2, &o);
    }
    pairs->count = o.count;
    return 0;
}

/* The walk against one x-set is made at three places of a run: out of
 * line, once with and once without body ids. */
static int nbs3_row_cross_one_all(const nbs3_scan *s, int32_t list, int one, size_t room,
                                  nbs_pairs *pairs)
{
    return nbs3_row_cross(s, 0, list, one, -1, room, pairs);
}

static int nbs3_row_cross_one_body(const nbs3_scan *s, int32_t list, int one, size_t room,
                                   nbs_pairs *pairs)
{
    return nbs3_row_cross(s, 1, list, one, -1, room, pairs);
}

/* A row of the layer below against x-sets one and two (two < 0: one
 * alone). An empty row costs no call. */
static NBS_ALWAYS_INLINE int nbs3_cross(const nbs3_scan *s, int use_body, int32_t list, int one,
                                        int two, size_t room, nbs_pairs *pairs)
{
    if (list < 0) return 0;
    if (two >= 0) return nbs3_row_cross(s, use_body, list, one, two, room, pairs);
    return use_body ? nbs3_row_cross_one_body(s, list, one, room, pairs)
                    : nbs3_row_cross_one_all(s, list, one, room, pairs);
}

/* The rows of a layer (its y-lists in set `cur`; the layer below in set
 * `below`): loop over the layer's elements to find rows not yet done; each
 * starts a run down to the lowest consecutive new row, then up while the
 * row above is new, the row just done held in its x-set as the row below
 * of the next. Done rows are marked old (-2 - head): they are still read
 * as neighbours, and are emptied when the layer is unmapped.
 * The layer below: row y of this layer meets its rows y-1, y, y+1. With
 * rows y (cur) and y-1 (held) mapped, its row y-1 is walked against both
 * and its row y against held, so each row of the layer below is walked
 * twice rather than three times; after the run's last row y, its rows y
 * and y+1 against that row. A held row that was not done in this run (the
 * run started above an old row) is another run's: its pairs with the layer
 * below are that run's.
 * The search stops once the runs have taken all `left` elements of the
 * layer: in a packed layer the first run takes every row, and the rest of
 * the search (a centre converted and a head read per element) was 2 ns of
 * the 30 a 1e6 packing took. */
static NBS_ALWAYS_INLINE int nbs3_layer_rows(const nbs3_scan *s, int use_body, int32_t layer,
                                             int32_t left, int cur, int below,
                                             nbs_pairs *pairs)
{
    int32_t *rows = s->rows[cur];
    const int32_t *low = s->rows[below];
    const int32_t ny = s->ay.size;
    for (int32_t i = layer; i >= 0 && left > 0; i = s->layer_next[i]) {
        int32_t y = nbs3_y(s, i);
        if (rows[y] < 0) continue; /* done */
        for (int32_t steps = 1; steps < ny; steps++) {
            int32_t yb = nbs3_down(y, ny);
            if (rows[yb] < 0) break;
            y = yb;
        }
        nbs3_row row = {.held = 1};
        int32_t held_list = nbs_row_list(rows[nbs3_down(y, ny)]);
        row.held_count = nbs3_row_map(s, row.held, held_list);
        int held_ours = 0;
        for (;;) {
            int32_t head = rows[y];
            rows[y] = -2 - head;
            row.list = head;
            row.cur = 1 - row.held;
            if (nbs3_row_own(s, use_body, &row, pairs) != 0) return -1;
            left -= row.count;
            int32_t low_down = nbs_row_list(low[nbs3_down(y, ny)]);
            size_t room = (size_t)row.count + (held_ours ? (size_t)row.held_count : 0);
            int two = held_ours ? row.held : -1;
            if (nbs3_cross(s, use_body, low_down, row.cur, two, room, pairs) ||
                (held_ours && nbs3_cross(s, use_body, nbs_row_list(low[y]), row.held, -1,
                                         (size_t)row.held_count, pairs)))
                return -1;
            nbs3_row_unmap(s, row.held, held_list);
            row.held = row.cur;
            row.held_count = row.count;
            held_list = head;
            held_ours = 1;
            y = nbs3_up(y, ny);
            if (rows[y] < 0) break; /* the run ends */
        }
        size_t room = (size_t)row.held_count;
        if (nbs3_cross(s, use_body, nbs_row_list(low[nbs3_down(y, ny)]), row.held, -1, room,
                       pairs) ||
            nbs3_cross(s, use_body, nbs_row_list(low[y]), row.held, -1, room, pairs))
            return -1;
        nbs3_row_unmap(s, row.held, held_list);
    }
    return 0;
}

/* The layers, in runs exactly like the rows: a layer is mapped to its
 * y-set, its rows tested with the layer below held in the other set, and
 * stays mapped as the layer below of the next. A layer head is emptied as
 * soon as no layer can need it any more. The search stops once the runs
 * have taken all `valid` elements, as the rows' does: every head is empty
 * by then, as each run empties its own.
 * use_body is a constant in each of the two copies nbs_detect_3d makes of
 * this walk, so the rows, own passes and two-set walks are one function
 * without a call per row: a row of a sparse packing holds one or two
 * elements, and the calls were 1-1.6 ns of the 22-27 an element took at
 * 1 sphere per 1e4 cells. */
static NBS_ALWAYS_INLINE int nbs3_layers_detect(const nbs3_scan *s, int use_body, size_t n,
                                                size_t valid, int all_valid, nbs_pairs *pairs)
{
    int32_t *layers = s->layer_head;
    const int32_t nz = s->az.size;
    size_t left = valid;
    for (size_t i = 0; i < n && left > 0; i++) {
        if (!all_valid && !nbs3_sphere_valid(s->cx[i], s->cy[i], s->cz[i], s->r[i])) continue;
        int32_t z = nbs3_z(s, (int32_t)i);
        if (layers[z] < 0) continue;
        for (int32_t steps = 1; steps < nz; steps++) {
            int32_t zb = nbs3_down(z, nz);
            if (layers[zb] < 0) break;
            z = zb;
        }
        int held = 1;
        int32_t held_list = nbs_row_list(layers[nbs3_down(z, nz)]);
        nbs3_layer_map(s, held, held_list);
        for (;;) {
            int32_t head = layers[z];
            layers[z] = -2 - head;
            int cur = 1 - held;
            int32_t count = nbs3_layer_map(s, cur, head);
            left -= (size_t)count;
            if (nbs3_layer_rows(s, use_body, head, count, cur, held, pairs) != 0) return -1;
            nbs3_layer_unmap(s, held, held_list);
            held = cur;
            held_list = head;
            int32_t zb = nbs3_down(z, nz), za = nbs3_up(z, nz);
            if (layers[zb] < NBS_EMPTY) layers[zb] = NBS_EMPTY;
            if (layers[za] < 0) {
                layers[z] = NBS_EMPTY;
                break;
            }
            z = za;
        }
        nbs3_layer_unmap(s, held, held_list);
    }
    return 0;
}

/* Stage 1 of the book: every valid sphere onto the list of its z-layer. */
static void nbs3_layers_build(const nbs3_scan *s, size_t n, int all_valid)
{
    for (size_t i = n; i-- > 0;) {
        if (!all_valid && !nbs3_sphere_valid(s->cx[i], s->cy[i], s->cz[i], s->r[i])) continue;
        int32_t z = nbs3_z(s, (int32_t)i);
        s->layer_next[i] = s->layer_head[z];
        s->layer_head[z] = (int32_t)i;
    }
}

/* ------------------------------------------------------------- detection */

int nbs_detect_3d(nbs_grid_3d *grid, size_t n, const double *cx, const double *cy,
                  const double *cz, const double *r, const int32_t *body, nbs_pairs *pairs)
{
    pairs->count = 0;
    if (n > NBS_MAX_CIRCLES) return -1;
    if (nbs_pairs_grow(pairs, n) != 0) return -1;
    if (n < 2) return 0;
    const double *c[3] = {cx, cy, cz};
    if (nbs3_reserve_elements(grid, n) != 0) return -1;
    nbs3_bounds b = nbs3_bounds_of(n, c, r, grid->sphere);
    if (b.valid < 2) return 0;

    double span = fmax(b.hi[0] - b.lo[0], fmax(b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]));
    double cell = nbs_padded_cell(b.rmax, span);
    int32_t table = (int32_t)nbs_next_pow2(n);
    nbs3_scan s = {.cx = cx, .cy = cy, .cz = cz, .r = r, .sphere = grid->sphere, .body = body,
                   .inv = 1.0 / cell};
    s.ax = nbs3_axis_plan(b.lo[0], b.hi[0], s.inv, table);
    s.ay = nbs3_axis_plan(b.lo[1], b.hi[1], s.inv, table);
    s.az = nbs3_axis_plan(b.lo[2], b.hi[2], s.inv, table);
    if (nbs3_reserve_heads(grid, s.ax.size, s.ay.size, s.az.size) != 0) return -1;
    grid->nx = s.ax.size;
    grid->ny = s.ay.size;
    grid->nz = s.az.size;
    grid->cell = cell;

    s.layer_head = grid->layer_head;
    s.rows[0] = grid->row_head;
    s.rows[1] = grid->row_head + grid->ny_capacity;
    s.cells[0] = grid->cell_head;
    s.cells[1] = grid->cell_head + grid->nx_capacity;
    s.layer_next = grid->layer_next;
    s.next = grid->next;

    nbs3_layers_build(&s, n, b.all_valid);
    int failed = body ? nbs3_layers_detect(&s, 1, n, b.valid, b.all_valid, pairs)
                      : nbs3_layers_detect(&s, 0, n, b.valid, b.all_valid, pairs);
    if (failed) {
        nbs3_reset_heads(grid);
        return -1;
    }
    return 0;
}
