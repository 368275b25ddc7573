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
 *    marking each row "old" once done; the cell lists are cleared by looping
 *    over the elements just mapped. Nothing ever loops over nx or ny, so the
 *    CPU cost is O(n) however sparse the packing is.
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
 *    row): a row head h >= 0 is new; an old one is stored as -2 - h. A row
 *    head is emptied as soon as no row can need it any more (the row and the
 *    row above it are both done), so no pass is needed to clear the rows.
 *  - Speed (in spatial order the cost is per-element instructions, not
 *    memory, even at 1e6): integerising and the row lists are one pass; the
 *    bounds use plain compares, and whether every circle is valid is decided
 *    once from the extremes, so the usual case has no per-circle test; a
 *    new row's list is walked once, to map it into its cell table and to
 *    gather its circles into the order buffer, so that testing and
 *    unmapping read contiguous indices instead of chasing the list again;
 *    rows are done in runs of consecutive rows, bottom-up, and the row just
 *    done stays mapped as the row below of the next, so each circle is
 *    mapped and unmapped once instead of twice. The two rows in the tables
 *    are gathered at the two ends of one buffer of n (they are disjoint, so
 *    they never meet).
 *  - What bounds it: at density 1 about four candidate circle tests per
 *    element (the half mask), at 1/1e4 the cache misses of cell tables
 *    100 sqrt(n) slots wide; in shuffled order the list walks are chains of
 *    dependent cache misses, which a counting sort avoids (the bench's grid
 *    baseline) at the price of O(nx * ny) memory.
 *  - The cell size is padded by a few ulps of the extent so that rounding
 *    in (x - xmin) / d can never put two touching circles two cells apart;
 *    the circle test is the same expression as the brute-force reference,
 *    so both return exactly the same set.
 *  - Circles with a non-finite or absurd (> 1e150) centre or radius, or a
 *    negative radius, are never in contact (in both detectors): the engine
 *    validates its mesh, and here they must not crash or poison the grid.
 */
#include "nbs_internal.h"

#include <string.h>

/* ------------------------------------------------------------------ helpers */

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
    free(grid->order);
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

int nbs_pairs_reserve(nbs_pairs *pairs, size_t want) { return nbs_pairs_grow(pairs, want); }

/* cell_head holds two tables (this row, the row below) of nx + 2 slots each */
static size_t nbs_cell_slots(size_t table) { return 2 * (table + 2); }

size_t nbs_memory_bytes(const nbs_grid *grid, const nbs_pairs *pairs)
{
    size_t ints = 5 * grid->n_capacity + grid->ny_capacity;
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
            nbs_grow_array(&grid->ix, cap) || nbs_grow_array(&grid->iy, cap) ||
            nbs_grow_array(&grid->order, cap))
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

/* The careful bounds: invalid circles (including NaN) are skipped. Plain
 * compares, not fmin/fmax: the values are finite here, so the NaN rules of
 * fmin/fmax buy nothing, and they are calls at -O2. */
static nbs_bounds nbs_bounds_checked(size_t n, const double *cx, const double *cy,
                                     const double *r)
{
    double xmin = DBL_MAX, xmax = -DBL_MAX, ymin = DBL_MAX, ymax = -DBL_MAX, rmax = 0.0;
    size_t valid = 0;
    for (size_t i = 0; i < n; i++) {
        double x = cx[i], y = cy[i], ri = r[i];
        if (!nbs_circle_valid(x, y, ri)) continue;
        xmin = x < xmin ? x : xmin;
        xmax = x > xmax ? x : xmax;
        ymin = y < ymin ? y : ymin;
        ymax = y > ymax ? y : ymax;
        rmax = ri > rmax ? ri : rmax;
        valid++;
    }
    nbs_bounds bo = {xmin, xmax, ymin, ymax, rmax, valid};
    return bo;
}

/* The usual case is that every circle is valid, and that can be decided
 * from the bounds alone: a sum of every value is finite only if no value
 * is NaN or infinite, and then the extremes say whether all are within the
 * limits and no radius is negative. This loop has no per-circle test, two
 * circles per iteration so that each min/max chain has half the latency;
 * *all_valid = 0 sends the caller to the careful loop. */
static nbs_bounds nbs_bounds_of(size_t n, const double *cx, const double *cy, const double *r,
                                int *all_valid)
{
    double xmin[2] = {DBL_MAX, DBL_MAX}, xmax[2] = {-DBL_MAX, -DBL_MAX};
    double ymin[2] = {DBL_MAX, DBL_MAX}, ymax[2] = {-DBL_MAX, -DBL_MAX};
    double rmin[2] = {DBL_MAX, DBL_MAX}, rmax[2] = {0.0, 0.0}, sum[2] = {0.0, 0.0};
    size_t i = 0;
    for (; i + 2 <= n; i += 2) {
        for (int k = 0; k < 2; k++) {
            double x = cx[i + k], y = cy[i + k], ri = r[i + k];
            xmin[k] = x < xmin[k] ? x : xmin[k];
            xmax[k] = x > xmax[k] ? x : xmax[k];
            ymin[k] = y < ymin[k] ? y : ymin[k];
            ymax[k] = y > ymax[k] ? y : ymax[k];
            rmin[k] = ri < rmin[k] ? ri : rmin[k];
            rmax[k] = ri > rmax[k] ? ri : rmax[k];
            sum[k] += (x + y) + ri;
        }
    }
    for (; i < n; i++) {
        double x = cx[i], y = cy[i], ri = r[i];
        xmin[0] = x < xmin[0] ? x : xmin[0];
        xmax[0] = x > xmax[0] ? x : xmax[0];
        ymin[0] = y < ymin[0] ? y : ymin[0];
        ymax[0] = y > ymax[0] ? y : ymax[0];
        rmin[0] = ri < rmin[0] ? ri : rmin[0];
        rmax[0] = ri > rmax[0] ? ri : rmax[0];
        sum[0] += (x + y) + ri;
    }
    nbs_bounds bo = {fmin(xmin[0], xmin[1]), fmax(xmax[0], xmax[1]), fmin(ymin[0], ymin[1]),
                     fmax(ymax[0], ymax[1]), fmax(rmax[0], rmax[1]), n};
    double rlo = fmin(rmin[0], rmin[1]);
    *all_valid = isfinite(sum[0] + sum[1]) && n > 0 && nbs_circle_valid(bo.xmin, bo.ymin, rlo) &&
                 nbs_circle_valid(bo.xmax, bo.ymax, bo.rmax);
    if (!*all_valid) return nbs_bounds_checked(n, cx, cy, r);
    return bo;
}

static nbs_layout nbs_layout_plan(const nbs_bounds *b, size_t table)
{
    nbs_layout L;
    L.cell = nbs_padded_cell(b->rmax, fmax(b->xmax - b->xmin, b->ymax - b->ymin));
    L.inv_cell = 1.0 / L.cell;
    L.xmin = b->xmin;
    L.ymin = b->ymin;
    nbs_axis_plan(b->xmax - b->xmin, L.inv_cell, (int32_t)table, &L.nx, &L.fold_x);
    nbs_axis_plan(b->ymax - b->ymin, L.inv_cell, (int32_t)table, &L.ny, &L.fold_y);
    return L;
}

/* Stage 1 of the book, in the same pass as integerising: integer (folded)
 * coordinates are stored so that later stages read two int arrays instead
 * of recomputing from doubles, and every circle goes onto the singly
 * connected list of its row. iy = -1 marks a circle that takes no part.
 * Tables are powers of two, so folding is a mask; unfolded axes use an
 * all-ones mask (their coordinates are already < size). */
static inline void nbs_rows_build(nbs_grid *grid, const nbs_layout *L, size_t n,
                                  const double *cx, const double *cy, const double *r,
                                  int all_valid)
{
    int64_t mask_x = L->fold_x ? (int64_t)L->nx - 1 : INT64_MAX;
    int64_t mask_y = L->fold_y ? (int64_t)L->ny - 1 : INT64_MAX;
    const double xmin = L->xmin, ymin = L->ymin, inv = L->inv_cell;
    int32_t *ix = grid->ix, *iy = grid->iy;
    int32_t *head = grid->row_head, *next = grid->row_next;
    for (size_t i = n; i-- > 0;) {
        double x = cx[i], y = cy[i];
        if (!all_valid && !nbs_circle_valid(x, y, r[i])) {
            ix[i] = 0;
            iy[i] = -1;
            continue;
        }
        /* x >= xmin, so truncation is floor */
        int32_t tx = (int32_t)((int64_t)((x - xmin) * inv) & mask_x);
        int32_t ty = (int32_t)((int64_t)((y - ymin) * inv) & mask_y);
        ix[i] = tx;
        iy[i] = ty;
        next[i] = head[ty];
        head[ty] = (int32_t)i;
    }
}

/* ------------------------------------------------------------- row detection */

/* What the row detection reads: the inputs, the lists, the order buffer and
 * both cell tables (each offset by one so that slot -1 and slot nx are the
 * guards). Side 0 of the order buffer grows up from order[0], side 1 down
 * from order[n]; cell table k holds the row gathered on side k. */
typedef struct nbs_scan {
    const double *cx, *cy, *r;
    const int32_t *body;
    const int32_t *ix, *row_next;
    int32_t *cell_next;
    int32_t *order;
    int32_t *table[2];
    size_t n;
    int32_t nx;
    int fold_x;
} nbs_scan;

/* A row gathered on one side: its circles are seg[0 .. count). */
typedef struct nbs_held {
    int32_t *seg;
    int32_t count;
} nbs_held;

/* Walks a row's list once: maps each circle into the cell table of `side`
 * (head insertion, so a circle's X link leads to the circles mapped before
 * it) and gathers it into that side of the order buffer. */
static inline nbs_held nbs_row_gather(const nbs_scan *s, int side, int32_t list)
{
    int32_t *table = s->table[side];
    const int32_t *ix = s->ix, *row_next = s->row_next;
    int32_t *cell_next = s->cell_next;
    nbs_held h;
    int32_t k = 0;
    if (side == 0) {
        int32_t *o = s->order;
        for (int32_t j = list; j >= 0; j = row_next[j]) {
            int32_t x = ix[j];
            o[k++] = j;
            cell_next[j] = table[x];
            table[x] = j;
        }
        h.seg = o;
    } else {
        int32_t *o = s->order + s->n;
        for (int32_t j = list; j >= 0; j = row_next[j]) {
            int32_t x = ix[j];
            *--o = j;
            k++;
            cell_next[j] = table[x];
            table[x] = j;
        }
        h.seg = o;
    }
    h.count = k;
    return h;
}

/* Empties the cells of a gathered row and the guards of its table. */
static inline void nbs_row_unmap(const nbs_scan *s, int side, nbs_held h)
{
    int32_t *table = s->table[side];
    for (int32_t k = 0; k < h.count; k++) table[s->ix[h.seg[k]]] = NBS_EMPTY;
    table[-1] = NBS_EMPTY;
    table[s->nx] = NBS_EMPTY;
}

/* The pair list while a row is tested, in locals the compiler can keep in
 * registers (stores through a and b cannot then force reloads). */
typedef struct nbs_out {
    int32_t *a, *b;
    size_t count, capacity;
} nbs_out;

#define NBS_FULL 1 /* a row test stopped on a full pair list */

/* Tests circle e (centre xe, ye, radius re) against one cell's list. The
 * pair is always written and the count advanced by the test's outcome: at
 * packing densities near 1 about one test in ten finds a pair, at random,
 * and a branch on it would be mispredicted that often. The caller has made
 * room for every pair this circle can have, so there is no capacity test
 * per candidate (it cost ~15% of the whole detection at density 1). */
static NBS_ALWAYS_INLINE void nbs_chain_test(const nbs_scan *s, int use_body, int32_t e,
                                             double xe, double ye, double re, int32_t list,
                                             nbs_out *o)
{
    const double *cx = s->cx, *cy = s->cy, *r = s->r;
    const int32_t *cell_next = s->cell_next;
    for (int32_t j = list; j >= 0; j = cell_next[j]) {
        int hit = nbs_circles_touch(xe, ye, re, cx[j], cy[j], r[j]);
        if (use_body) hit &= !nbs_same_body(s->body, e, j);
        o->a[o->count] = e;
        o->b[o->count] = j;
        o->count += (size_t)hit;
    }
}

/* Applies the half mask to every circle of the row gathered in cur: later
 * circles of its own cell, the cell to the left, and the three cells below.
 * The five cells are distinct table slots (folded tables have >= 4), so a
 * circle meets each other circle of the two rows at most once: it has at
 * most row.count - 1 + low_count pairs, plus the one slot written past the
 * last. Room for that is checked once per circle; without it the test
 * stops with NBS_FULL and *need (pairs->count is then meaningless: the
 * caller grows the list and tests the row again). use_body is a constant
 * at each call, so the body test costs nothing when there are no bodies. */
static NBS_ALWAYS_INLINE int nbs_row_test(const nbs_scan *s, int use_body, const int32_t *cur,
                                          const int32_t *low, int32_t low_count, nbs_held row,
                                          nbs_pairs *pairs, size_t *need)
{
    const int32_t *ix = s->ix, *cell_next = s->cell_next;
    const double *cx = s->cx, *cy = s->cy, *r = s->r;
    nbs_out o = {pairs->a, pairs->b, pairs->count, pairs->capacity};
    const size_t room = (size_t)row.count + (size_t)low_count + 1;
    for (int32_t k = 0; k < row.count; k++) {
        if (NBS_UNLIKELY(o.capacity - o.count < room)) {
            *need = o.count + room;
            return NBS_FULL;
        }
        int32_t e = row.seg[k], x = ix[e];
        double xe = cx[e], ye = cy[e], re = r[e];
        nbs_chain_test(s, use_body, e, xe, ye, re, cell_next[e], &o);
        nbs_chain_test(s, use_body, e, xe, ye, re, cur[x - 1], &o);
        if (low_count == 0) continue;
        nbs_chain_test(s, use_body, e, xe, ye, re, low[x - 1], &o);
        nbs_chain_test(s, use_body, e, xe, ye, re, low[x], &o);
        nbs_chain_test(s, use_body, e, xe, ye, re, low[x + 1], &o);
    }
    pairs->count = o.count;
    return 0;
}

static int nbs_row_test_all(const nbs_scan *s, const int32_t *cur, const int32_t *low,
                            int32_t low_count, nbs_held row, nbs_pairs *pairs, size_t *need)
{
    return nbs_row_test(s, 0, cur, low, low_count, row, pairs, need);
}

static int nbs_row_test_body(const nbs_scan *s, const int32_t *cur, const int32_t *low,
                             int32_t low_count, nbs_held row, nbs_pairs *pairs, size_t *need)
{
    return nbs_row_test(s, 1, cur, low, low_count, row, pairs, need);
}

/* Tests one row, growing the pair list and testing the row again from its
 * first pair whenever it lacks room. Returns 0, or -1 when out of memory. */
static int nbs_row_test_grow(const nbs_scan *s, const int32_t *cur, const int32_t *low,
                             int32_t low_count, nbs_held row, nbs_pairs *pairs)
{
    size_t first = pairs->count;
    for (;;) {
        size_t need = 0;
        int status = s->body ? nbs_row_test_body(s, cur, low, low_count, row, pairs, &need)
                             : nbs_row_test_all(s, cur, low, low_count, row, pairs, &need);
        if (status == 0) return 0;
        pairs->count = first;
        if (nbs_pairs_grow(pairs, need) != 0) return -1;
    }
}

/* Stage 2 of the book: loop over circles, not rows, to find the rows not yet
 * done. A row seen for the first time starts a run: down to the lowest of
 * the consecutive new rows under it, then up row by row while the row above
 * is new (each step is one row head, so the walk costs no more than the
 * rows it then processes). Each row of the run is marked old, mapped with
 * the row below it and tested. The row just done stays mapped ("held") and
 * is the row below of the next one in the run, so a run maps and unmaps
 * each circle once; held is unmapped when the run ends. Runs matter for
 * sparse packings, where the new rows met in circle order are scattered. */
static int nbs_rows_detect(nbs_grid *grid, const nbs_layout *L, size_t n,
                           const double *cx, const double *cy, const double *r,
                           const int32_t *body, nbs_pairs *pairs)
{
    nbs_scan s = {
        .cx = cx, .cy = cy, .r = r, .body = body,
        .ix = grid->ix, .row_next = grid->row_next, .cell_next = grid->cell_next,
        .order = grid->order,
        .table = {grid->cell_head + 1, grid->cell_head + 1 + (L->nx + 2)},
        .n = n, .nx = L->nx, .fold_x = L->fold_x,
    };
    int32_t *row_head = grid->row_head;
    const int32_t *iy = grid->iy;
    const int32_t ny = L->ny, nx = L->nx;
    const int fold_y = L->fold_y;
    for (size_t i = 0; i < n; i++) {
        int32_t y = iy[i];
        if (y < 0 || row_head[y] < 0) continue; /* old, or done and emptied */
        /* folded, every row may be new: at most ny - 1 steps down */
        for (int32_t steps = 1; steps < ny; steps++) {
            int32_t yb = y > 0 ? y - 1 : (fold_y ? ny - 1 : -1);
            if (yb < 0 || row_head[yb] < 0) break;
            y = yb;
        }
        int held_side = 1; /* the first row's below is gathered on side 1 */
        nbs_held held = {NULL, 0};
        int first = 1;
        for (;;) {
            int32_t head = row_head[y];
            row_head[y] = -2 - head;
            int32_t y_below = y > 0 ? y - 1 : (fold_y ? ny - 1 : -1);
            int32_t y_above = y < ny - 1 ? y + 1 : (fold_y ? 0 : -1);
            if (first) {
                int32_t below = y_below >= 0 ? nbs_row_list(row_head[y_below]) : NBS_EMPTY;
                held = nbs_row_gather(&s, 1, below);
                first = 0;
            }
            nbs_held low = held;
            int side = 1 - held_side;
            nbs_held row = nbs_row_gather(&s, side, head);
            int32_t *cur = s.table[side], *lo = s.table[held_side];
            if (s.fold_x) {
                cur[-1] = cur[nx - 1];
                lo[-1] = lo[nx - 1];
                lo[nx] = lo[0];
            }
            if (nbs_row_test_grow(&s, cur, lo, low.count, row, pairs) != 0) return -1;
            nbs_row_unmap(&s, held_side, low);
            held_side = side;
            held = row;

            /* The row below has now served both its uses if it is old; this
             * row has if the row above is done or has no circles. */
            if (y_below >= 0 && row_head[y_below] < NBS_EMPTY) row_head[y_below] = NBS_EMPTY;
            if (y_above < 0 || row_head[y_above] < 0) {
                row_head[y] = NBS_EMPTY;
                break; /* the run ends */
            }
            y = y_above;
        }
        nbs_row_unmap(&s, held_side, held);
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

    int all_valid;
    nbs_bounds b = nbs_bounds_of(n, cx, cy, r, &all_valid);
    if (b.valid < 2) return 0;
    nbs_layout L = nbs_layout_plan(&b, table);
    grid->nx = L.nx;
    grid->ny = L.ny;
    grid->cell = L.cell;

    if (all_valid) /* constant flag: the loop without the per-circle test */
        nbs_rows_build(grid, &L, n, cx, cy, r, 1);
    else
        nbs_rows_build(grid, &L, n, cx, cy, r, 0);
    if (nbs_rows_detect(grid, &L, n, cx, cy, r, body, pairs) != 0) {
        nbs_grid_reset_heads(grid);
        return -1;
    }
    return 0;
}
