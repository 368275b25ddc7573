/*
 * nbs.c - Munjiza-NBS contact detection in 2D (Munjiza 2004, ch. 3.7-3.11).
 *
 * Owns: integerising bounding circles onto a grid of cell size d (the largest
 * diameter), the book's singly connected lists held in integer arrays (rows:
 * B = row_head / Y = row_next; cells: A = cell_head / X = cell_next), the
 * half contact mask, the pair list, and the all-pairs reference.
 *
 * Why it is shaped this way:
 *  - Only non-empty rows are visited, found by looping over elements and
 *    marking each row "old" once done; all lists are cleared by looping over
 *    elements again. Nothing ever loops over nx or ny, so the CPU cost is O(n)
 *    however sparse the packing is.
 *  - Integer coordinates are folded modulo a table size of O(n) (a power of
 *    two >= n, and at least 4) when the real extent is larger, so RAM is
 *    O(n) whatever the extent. Folding maps distant cells onto the same table
 *    slot; that only adds candidates, which the exact circle test removes.
 *    Because every folded size is >= 3, the mask offsets -1, 0, +1 stay
 *    distinct, so each candidate pair is still met exactly once.
 *  - A row is processed together with the row below it (two cell tables, the
 *    book's 2*nx): for a cell (ix, iy) the mask is the cell itself, (ix-1, iy)
 *    and (ix-1 .. ix+1, iy-1): half of the 3x3 neighbourhood, so no pair is
 *    tested twice and no pair needs de-duplication.
 *  - Each cell table has a guard slot on either side, so the mask never
 *    branches on the edges: unfolded guards stay empty, folded guards mirror
 *    the opposite edge for the duration of one row.
 *  - "Old" rows keep their list (it is still needed as the row below another
 *    row): a row head h >= 0 is new; an old one is stored as -2 - h.
 *  - The cell size is padded by a few ulps of the extent so that rounding
 *    in (x - xmin) / d can never put two touching circles two cells apart;
 *    the circle test is the same expression as the brute-force reference,
 *    so both return exactly the same set.
 *  - Circles with a non-finite or absurd (> 1e150) centre or radius, or a
 *    negative radius, are never in contact (in both detectors): the engine
 *    validates its mesh, and here they must not crash or poison the grid.
 */
#include "nbs.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NBS_EMPTY (-1)
#define NBS_VALUE_LIMIT 1e150
#define NBS_MIN_TABLE 4
/* at most 2^30 circles, so table sizes and indices fit int32 */
#define NBS_MAX_CIRCLES ((size_t)1 << 30)
/* the integer extent is kept below 2^40 cells so int64 never overflows */
#define NBS_MAX_CELLS_PER_AXIS 1099511627776.0

/* ------------------------------------------------------------------ helpers */

static inline int nbs_circle_valid(double x, double y, double r)
{
    return fabs(x) <= NBS_VALUE_LIMIT && fabs(y) <= NBS_VALUE_LIMIT &&
           r >= 0.0 && r <= NBS_VALUE_LIMIT;
}

/* The one circle test both detectors use. Split into statements so that no
 * compiler contracts it into an FMA in one detector and not in the other. */
static inline int nbs_circles_touch(double xi, double yi, double ri,
                                    double xj, double yj, double rj)
{
    double dx = xi - xj;
    double dy = yi - yj;
    double reach = ri + rj;
    double dx2 = dx * dx;
    double dy2 = dy * dy;
    double dist2 = dx2 + dy2;
    double reach2 = reach * reach;
    return dist2 <= reach2;
}

static inline int nbs_same_body(const int32_t *body, int32_t i, int32_t j)
{
    return body && body[i] >= 0 && body[i] == body[j];
}

static int nbs_pairs_grow(nbs_pairs *pairs, size_t want)
{
    if (want <= pairs->capacity) return 0;
    size_t cap = pairs->capacity ? pairs->capacity : 1024;
    while (cap < want) cap *= 2;
    int32_t *a = realloc(pairs->a, cap * sizeof *a);
    if (!a) return -1;
    pairs->a = a;
    int32_t *b = realloc(pairs->b, cap * sizeof *b);
    if (!b) return -1;
    pairs->b = b;
    pairs->capacity = cap;
    return 0;
}

static inline int nbs_pairs_push(nbs_pairs *pairs, int32_t i, int32_t j)
{
    if (pairs->count == pairs->capacity &&
        nbs_pairs_grow(pairs, pairs->count + 1) != 0)
        return -1;
    pairs->a[pairs->count] = i;
    pairs->b[pairs->count] = j;
    pairs->count++;
    return 0;
}

static void nbs_fill_empty(int32_t *a, size_t count)
{
    for (size_t k = 0; k < count; k++) a[k] = NBS_EMPTY;
}

static int nbs_grow_array(int32_t **array, size_t count)
{
    int32_t *p = realloc(*array, count * sizeof *p);
    if (!p) return -1;
    *array = p;
    return 0;
}

static size_t nbs_next_pow2(size_t n)
{
    size_t p = NBS_MIN_TABLE;
    while (p < n) p *= 2;
    return p;
}

/* --------------------------------------------------------- public lifecycle */

void nbs_grid_init(nbs_grid *grid)
{
    memset(grid, 0, sizeof *grid);
}

void nbs_grid_free(nbs_grid *grid)
{
    free(grid->row_head);
    free(grid->row_next);
    free(grid->cell_head);
    free(grid->cell_next);
    free(grid->ix);
    free(grid->iy);
    nbs_grid_init(grid);
}

void nbs_pairs_init(nbs_pairs *pairs)
{
    memset(pairs, 0, sizeof *pairs);
}

void nbs_pairs_free(nbs_pairs *pairs)
{
    free(pairs->a);
    free(pairs->b);
    nbs_pairs_init(pairs);
}

/* cell_head holds two tables (this row, the row below) of nx + 2 slots each */
static size_t nbs_cell_slots(size_t table) { return 2 * (table + 2); }

size_t nbs_memory_bytes(const nbs_grid *grid, const nbs_pairs *pairs)
{
    size_t ints = 4 * grid->n_capacity + grid->ny_capacity;
    if (grid->nx_capacity) ints += nbs_cell_slots(grid->nx_capacity);
    size_t bytes = ints * sizeof(int32_t);
    if (pairs) bytes += 2 * pairs->capacity * sizeof(int32_t);
    return bytes;
}

/* Grows the arrays to their high-water mark; all heads are left empty. The
 * tables are sized by n alone (not by the extent), so the memory taken for
 * a given n is the same wherever the circles are. */
static int nbs_grid_reserve(nbs_grid *grid, size_t n, size_t table)
{
    if (n > grid->n_capacity) {
        size_t cap = n > 2 * grid->n_capacity ? n : 2 * grid->n_capacity;
        if (nbs_grow_array(&grid->row_next, cap) || nbs_grow_array(&grid->cell_next, cap) ||
            nbs_grow_array(&grid->ix, cap) || nbs_grow_array(&grid->iy, cap))
            return -1;
        grid->n_capacity = cap;
    }
    if (table > grid->ny_capacity) {
        if (nbs_grow_array(&grid->row_head, table)) return -1;
        nbs_fill_empty(grid->row_head, table);
        grid->ny_capacity = table;
    }
    if (table > grid->nx_capacity) {
        if (nbs_grow_array(&grid->cell_head, nbs_cell_slots(table))) return -1;
        nbs_fill_empty(grid->cell_head, nbs_cell_slots(table));
        grid->nx_capacity = table;
    }
    return 0;
}

/* After a failure part-way through, the heads may hold stale lists. */
static void nbs_grid_reset_heads(nbs_grid *grid)
{
    if (grid->row_head) nbs_fill_empty(grid->row_head, grid->ny_capacity);
    if (grid->cell_head) nbs_fill_empty(grid->cell_head, nbs_cell_slots(grid->nx_capacity));
}

/* ------------------------------------------------------------ grid planning */

typedef struct nbs_bounds {
    double xmin, xmax, ymin, ymax, rmax;
    size_t valid;
} nbs_bounds;

typedef struct nbs_layout {
    double xmin, ymin, inv_cell, cell;
    int32_t nx, ny;      /* table sizes actually used */
    int fold_x, fold_y;  /* 1 when the real extent is folded onto the table */
} nbs_layout;

static nbs_bounds nbs_bounds_of(size_t n, const double *cx, const double *cy, const double *r)
{
    nbs_bounds b = {DBL_MAX, -DBL_MAX, DBL_MAX, -DBL_MAX, 0.0, 0};
    for (size_t i = 0; i < n; i++) {
        if (!nbs_circle_valid(cx[i], cy[i], r[i])) continue;
        b.xmin = fmin(b.xmin, cx[i]);
        b.xmax = fmax(b.xmax, cx[i]);
        b.ymin = fmin(b.ymin, cy[i]);
        b.ymax = fmax(b.ymax, cy[i]);
        b.rmax = fmax(b.rmax, r[i]);
        b.valid++;
    }
    return b;
}

/* Cell size d = largest diameter, padded so that (1) rounding of
 * (x - xmin) * (1/d) stays well below one cell even at 1e6 m from the origin
 * (a relative 1e-9 plus 32 ulps of the extent), (2) the integer extent
 * stays below 2^40 cells, (3) all-zero radii still get a positive size. */
static double nbs_cell_size(const nbs_bounds *b)
{
    double span = fmax(b->xmax - b->xmin, b->ymax - b->ymin);
    double cell = 2.0 * b->rmax * (1.0 + 1e-9) + 32.0 * DBL_EPSILON * span;
    cell = fmax(cell, span / NBS_MAX_CELLS_PER_AXIS);
    if (!(cell > 0.0)) cell = 1.0;
    return cell;
}

static void nbs_axis_plan(double span, double inv_cell, int32_t table,
                          int32_t *size, int *fold)
{
    double real = floor(span * inv_cell) + 1.0;
    *fold = real > (double)table;
    *size = *fold ? table : (int32_t)real;
}

static nbs_layout nbs_layout_plan(const nbs_bounds *b, size_t table)
{
    nbs_layout L;
    L.cell = nbs_cell_size(b);
    L.inv_cell = 1.0 / L.cell;
    L.xmin = b->xmin;
    L.ymin = b->ymin;
    nbs_axis_plan(b->xmax - b->xmin, L.inv_cell, (int32_t)table, &L.nx, &L.fold_x);
    nbs_axis_plan(b->ymax - b->ymin, L.inv_cell, (int32_t)table, &L.ny, &L.fold_y);
    return L;
}

/* First pass: integerised, folded coordinates, stored so that later passes
 * read two int arrays instead of recomputing from doubles. iy = -1 marks a
 * circle that takes no part. Tables are powers of two, so folding is a mask;
 * unfolded axes use an all-ones mask (their coordinates are already < size). */
static void nbs_integerise(nbs_grid *grid, const nbs_layout *L, size_t n,
                           const double *cx, const double *cy, const double *r)
{
    int64_t mask_x = L->fold_x ? (int64_t)L->nx - 1 : INT64_MAX;
    int64_t mask_y = L->fold_y ? (int64_t)L->ny - 1 : INT64_MAX;
    int32_t *ix = grid->ix, *iy = grid->iy;
    for (size_t i = 0; i < n; i++) {
        if (!nbs_circle_valid(cx[i], cy[i], r[i])) {
            ix[i] = 0;
            iy[i] = -1;
            continue;
        }
        /* x >= xmin, so truncation is floor */
        int64_t tx = (int64_t)((cx[i] - L->xmin) * L->inv_cell);
        int64_t ty = (int64_t)((cy[i] - L->ymin) * L->inv_cell);
        ix[i] = (int32_t)(tx & mask_x);
        iy[i] = (int32_t)(ty & mask_y);
    }
}

/* Stage 1 of the book: every circle onto the singly connected list of its row. */
static void nbs_rows_build(nbs_grid *grid, size_t n)
{
    const int32_t *iy = grid->iy;
    int32_t *head = grid->row_head, *next = grid->row_next;
    for (size_t i = 0; i < n; i++) {
        int32_t y = iy[i];
        if (y < 0) continue;
        next[i] = head[y];
        head[y] = (int32_t)i;
    }
}

static void nbs_rows_clear(nbs_grid *grid, size_t n)
{
    const int32_t *iy = grid->iy;
    int32_t *head = grid->row_head;
    for (size_t i = 0; i < n; i++)
        if (iy[i] >= 0) head[iy[i]] = NBS_EMPTY;
}

/* A row's list whether it is still new (h >= 0), old (-2 - h) or empty. */
static inline int32_t nbs_row_list(int32_t mark)
{
    return mark >= NBS_EMPTY ? mark : -2 - mark;
}

/* ------------------------------------------------------------- row detection */

/* What one row's detection reads: the inputs, the lists and both cell
 * tables (each offset by one so that slot -1 and slot nx are the guards). */
typedef struct nbs_scan {
    const double *cx, *cy, *r;
    const int32_t *body;
    const int32_t *ix, *row_next;
    int32_t *cell_next;
    int32_t *cur, *below;
    int32_t nx;
    int fold_x;
} nbs_scan;

static inline void nbs_cells_map(const nbs_scan *s, int32_t *table, int32_t list)
{
    for (int32_t j = list; j >= 0; j = s->row_next[j]) {
        int32_t x = s->ix[j];
        s->cell_next[j] = table[x];
        table[x] = j;
    }
}

static inline void nbs_cells_unmap(const nbs_scan *s, int32_t *table, int32_t list)
{
    for (int32_t j = list; j >= 0; j = s->row_next[j]) table[s->ix[j]] = NBS_EMPTY;
    table[-1] = NBS_EMPTY;
    table[s->nx] = NBS_EMPTY;
}

/* Tests circle e against one cell's list. */
static inline int nbs_chain_test(const nbs_scan *s, int32_t e, int32_t list, nbs_pairs *pairs)
{
    double xe = s->cx[e], ye = s->cy[e], re = s->r[e];
    for (int32_t j = list; j >= 0; j = s->cell_next[j]) {
        if (!nbs_circles_touch(xe, ye, re, s->cx[j], s->cy[j], s->r[j])) continue;
        if (nbs_same_body(s->body, e, j)) continue;
        if (nbs_pairs_push(pairs, e, j) != 0) return -1;
    }
    return 0;
}

/* Maps one new row and the row below it to cells, applies the half mask to
 * every circle of the row, then empties both cell tables. */
static int nbs_row_detect(const nbs_scan *s, int32_t row, int32_t below, nbs_pairs *pairs)
{
    int32_t *cur = s->cur, *low = s->below;
    nbs_cells_map(s, cur, row);
    nbs_cells_map(s, low, below);
    if (s->fold_x) {
        cur[-1] = cur[s->nx - 1];
        low[-1] = low[s->nx - 1];
        low[s->nx] = low[0];
    }
    int status = 0;
    for (int32_t e = row; e >= 0 && status == 0; e = s->row_next[e]) {
        int32_t x = s->ix[e];
        status |= nbs_chain_test(s, e, s->cell_next[e], pairs); /* later in own cell */
        status |= nbs_chain_test(s, e, cur[x - 1], pairs);
        status |= nbs_chain_test(s, e, low[x - 1], pairs);
        status |= nbs_chain_test(s, e, low[x], pairs);
        status |= nbs_chain_test(s, e, low[x + 1], pairs);
    }
    nbs_cells_unmap(s, cur, row);
    nbs_cells_unmap(s, low, below);
    return status;
}

/* Stage 2 of the book: loop over circles, not rows; a row seen for the first
 * time is marked old and detected against the row below it. */
static int nbs_rows_detect(nbs_grid *grid, const nbs_layout *L, size_t n,
                           const double *cx, const double *cy, const double *r,
                           const int32_t *body, nbs_pairs *pairs)
{
    nbs_scan s = {
        .cx = cx, .cy = cy, .r = r, .body = body,
        .ix = grid->ix, .row_next = grid->row_next, .cell_next = grid->cell_next,
        .cur = grid->cell_head + 1,
        .below = grid->cell_head + 1 + (L->nx + 2),
        .nx = L->nx, .fold_x = L->fold_x,
    };
    int32_t *row_head = grid->row_head;
    const int32_t *iy = grid->iy;
    for (size_t i = 0; i < n; i++) {
        int32_t y = iy[i];
        if (y < 0) continue;
        int32_t head = row_head[y];
        if (head < 0) continue; /* old */
        row_head[y] = -2 - head;
        int32_t y_below = y > 0 ? y - 1 : (L->fold_y ? L->ny - 1 : -1);
        int32_t below = y_below >= 0 ? nbs_row_list(row_head[y_below]) : NBS_EMPTY;
        if (nbs_row_detect(&s, head, below, pairs) != 0) return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------- detection */

int nbs_detect(nbs_grid *grid, size_t n, const double *cx, const double *cy,
               const double *r, const int32_t *body, nbs_pairs *pairs)
{
    pairs->count = 0;
    if (n > NBS_MAX_CIRCLES) return -1;
    size_t table = nbs_next_pow2(n);
    if (nbs_grid_reserve(grid, n, table) != 0) return -1;
    if (nbs_pairs_grow(pairs, n) != 0) return -1;
    if (n < 2) return 0;

    nbs_bounds b = nbs_bounds_of(n, cx, cy, r);
    if (b.valid < 2) return 0;
    nbs_layout L = nbs_layout_plan(&b, table);
    grid->nx = L.nx;
    grid->ny = L.ny;
    grid->cell = L.cell;

    nbs_integerise(grid, &L, n, cx, cy, r);
    nbs_rows_build(grid, n);
    int status = nbs_rows_detect(grid, &L, n, cx, cy, r, body, pairs);
    if (status != 0) {
        nbs_grid_reset_heads(grid);
        return -1;
    }
    nbs_rows_clear(grid, n);
    return 0;
}

int nbs_detect_brute(size_t n, const double *cx, const double *cy,
                     const double *r, const int32_t *body, nbs_pairs *pairs)
{
    pairs->count = 0;
    if (n > NBS_MAX_CIRCLES) return -1;
    for (size_t i = 0; i < n; i++) {
        if (!nbs_circle_valid(cx[i], cy[i], r[i])) continue;
        for (size_t j = i + 1; j < n; j++) {
            if (!nbs_circle_valid(cx[j], cy[j], r[j])) continue;
            if (!nbs_circles_touch(cx[i], cy[i], r[i], cx[j], cy[j], r[j])) continue;
            if (nbs_same_body(body, (int32_t)i, (int32_t)j)) continue;
            if (nbs_pairs_push(pairs, (int32_t)i, (int32_t)j) != 0) return -1;
        }
    }
    return 0;
}
