/*
 * result_frame.c - one snapshot of result.h5 as the web page's binary frame
 * (GET /cases/ID/mesh.bin, docs/api.md "Binary mesh frames").
 *
 * The page draws a 1e5-element mesh at every snapshot; as JSON that is tens
 * of MB of text and seconds of parsing, so it gets the mesh, the deformed
 * positions and the fields it colours by as little-endian float32 arrays
 * (u32 for indices) in named sections behind a fixed header, which a
 * browser maps with typed arrays and no parsing. HDF5 converts to float32
 * as it reads.
 *
 * Version 2 (issue 35) made the 3D view take under a second: the surface
 * form carries only the facets that can be seen (result_frame_shape.c),
 * and the mesh's shape is keyed by a hash, so a client that already holds
 * it gets only positions and fields at the next snapshot (the shape of a
 * fracturing case changes only when joints break).
 *
 * Reads the open file of a running case (its handle, between two appends:
 * only the I/O thread calls this) or the closed file on disk.
 */
#include "result_frame_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FRAME_MAGIC "FDEMMESH"
#define FRAME_VERSION 2u
#define FRAME_HEADER_BYTES 80u
#define FRAME_SECTION_HEADER_BYTES 32u
#define FRAME_NAME_BYTES 16u
#define FRAME_FLAG_SURFACE 1u
#define FRAME_FLAG_SHAPE 2u
/* fluid_pressure, aperture: asking for either shows the faces of the
 * joints holding fluid in the surface form, so the fluid inside a body can
 * be drawn */
#define FRAME_WET_FIELDS ((1u << 8) | (1u << 9))

const char *const result_frame_field_names[RESULT_FRAME_FIELDS] = {
    "velocity", "displacement", "stress", "strain", "principal_stress", "damage", "fragment",
    "active", "fluid_pressure", "aperture",
};

/* The /snapshots series of each frame field, in result_frame_field_names order. */
static const int frame_series[RESULT_FRAME_FIELDS] = {
    SERIES_VELOCITY, SERIES_DISPLACEMENT, SERIES_STRESS, SERIES_STRAIN,
    SERIES_PRINCIPAL_STRESS, SERIES_DAMAGE, SERIES_FRAGMENT, SERIES_ACTIVE,
    SERIES_FLUID_PRESSURE, SERIES_APERTURE,
};

typedef struct frame_array {
    hid_t ds;      /* open dataset, or H5I_INVALID_HID */
    hsize_t items; /* rows (mesh) or items per snapshot (snapshots) */
    hsize_t width; /* components per item */
} frame_array;

typedef struct frame_source {
    hid_t file;
    int dimension, snapshots;
    frame_array cells, joints, position0, position, field[RESULT_FRAME_FIELDS];
} frame_source;

/* ------------------------------------------------------------- datasets */

/* Opens `name` if the file has it and reads its shape: a /mesh array is
 * (items, width) or (items); a /snapshots series (S, items, width),
 * (S, items) or (S) (one item). Missing is not an error. */
static void frame_open(hid_t file, const char *name, int per_snapshot, frame_array *a)
{
    a->ds = H5I_INVALID_HID;
    a->items = a->width = 0;
    if (H5Lexists(file, name, H5P_DEFAULT) <= 0)
        return;
    a->ds = H5Dopen2(file, name, H5P_DEFAULT);
    if (a->ds < 0)
        return;
    hsize_t dims[3] = {0, 0, 0};
    hid_t space = H5Dget_space(a->ds);
    int rank = space >= 0 ? H5Sget_simple_extent_dims(space, dims, NULL) : -1;
    if (space >= 0)
        H5Sclose(space);
    int base = per_snapshot ? 1 : 0;
    if (rank < 1 || rank > base + 2) {
        H5Dclose(a->ds);
        a->ds = H5I_INVALID_HID;
        return;
    }
    a->items = rank > base ? dims[base] : 1;
    a->width = rank == base + 2 ? dims[base + 1] : 1;
}

static void frame_close(frame_array *a)
{
    if (a->ds >= 0)
        H5Dclose(a->ds);
    a->ds = H5I_INVALID_HID;
}

/* Reads row `index` of a /snapshots series (or the whole of a /mesh array
 * when index < 0) converted to `type` into dst. The memory space has the
 * shape of the row read, so HDF5 copies it in blocks: a flat one made it
 * walk the selection element by element, 90 % of a frame's time. */
static int frame_read(const frame_array *a, int index, hid_t type, void *dst)
{
    hsize_t count = a->items * a->width;
    if (count == 0)
        return 0;
    hid_t file_space = H5Dget_space(a->ds);
    hsize_t dims[3] = {0, 0, 0};
    int rank = file_space >= 0 ? H5Sget_simple_extent_ndims(file_space) : -1;
    int ok = rank >= 1 && rank <= 3;
    hid_t mem_space = H5I_INVALID_HID;
    if (ok) {
        hsize_t start[3] = {(hsize_t)(index >= 0 ? index : 0), 0, 0};
        H5Sget_simple_extent_dims(file_space, dims, NULL);
        if (index >= 0)
            dims[0] = 1; /* one snapshot's row */
        mem_space = H5Screate_simple(rank, dims, NULL);
        ok = mem_space >= 0;
        if (ok && index >= 0)
            ok = H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, NULL, dims, NULL) >= 0;
    }
    ok = ok && H5Dread(a->ds, type, mem_space, file_space, H5P_DEFAULT, dst) >= 0;
    if (mem_space >= 0) H5Sclose(mem_space);
    if (file_space >= 0) H5Sclose(file_space);
    return ok ? 0 : -1;
}

static int frame_read_scalar(hid_t file, const char *name, int index, hid_t type, void *dst)
{
    frame_array a;
    frame_open(file, name, 1, &a);
    if (a.ds < 0)
        return -1;
    a.items = a.width = 1;
    int rc = frame_read(&a, index, type, dst);
    frame_close(&a);
    return rc;
}

/* ----------------------------------------------------------- the source */

static void frame_source_close(frame_source *s)
{
    frame_close(&s->cells);
    frame_close(&s->joints);
    frame_close(&s->position0);
    frame_close(&s->position);
    for (int k = 0; k < RESULT_FRAME_FIELDS; k++)
        frame_close(&s->field[k]);
}

/* Opens what the frame reads; `wanted` bit k asks for field k (damage,
 * active and fluid_pressure are opened anyway: the surface form needs them). */
static int frame_source_open(frame_source *s, hid_t file, const result_file *f, unsigned wanted,
                             char *err, size_t errlen)
{
    memset(s, 0, sizeof *s);
    s->file = file;
    frame_open(file, "/mesh/position0", 0, &s->position0);
    s->dimension = (int)s->position0.width;
    frame_open(file, s->dimension == 3 ? "/mesh/tetrahedra" : "/mesh/triangles", 0, &s->cells);
    frame_open(file, "/mesh/joints", 0, &s->joints);
    frame_open(file, "/snapshots/position", 1, &s->position);
    for (int k = 0; k < RESULT_FRAME_FIELDS; k++) {
        char name[64];
        snprintf(name, sizeof name, "/snapshots/%s", series_names[frame_series[k]]);
        s->field[k].ds = H5I_INVALID_HID;
        if (wanted & (1u << k) || frame_series[k] == SERIES_DAMAGE ||
            frame_series[k] == SERIES_ACTIVE || frame_series[k] == SERIES_FLUID_PRESSURE)
            frame_open(file, name, 1, &s->field[k]);
    }
    frame_array time;
    frame_open(file, "/snapshots/time", 1, &time);
    hsize_t stored = 0;
    if (time.ds >= 0) {
        hsize_t dims[1] = {0};
        hid_t space = H5Dget_space(time.ds);
        H5Sget_simple_extent_dims(space, dims, NULL);
        H5Sclose(space);
        stored = dims[0];
    }
    frame_close(&time);
    s->snapshots = f ? f->count : (int)stored;
    int d = s->dimension;
    if (s->position0.ds < 0 || s->cells.ds < 0 || (d != 2 && d != 3) ||
        s->cells.width != (hsize_t)d + 1 || s->position0.items > UINT32_MAX / 8 ||
        s->cells.items > UINT32_MAX / 8 ||
        (s->joints.ds >= 0 && (s->joints.width != (hsize_t)(2 * d) ||
                               s->joints.items > UINT32_MAX / 8))) {
        snprintf(err, errlen, "the result file has no readable /mesh");
        return -1;
    }
    if (s->joints.ds < 0)
        s->joints.items = 0;
    return 0;
}

/* A field's row fits the frame when it has one value row per item of its
 * kind; any other shape (a file of an older layout) is left out. */
static int frame_field_fits(const frame_source *s, int k)
{
    const frame_array *a = &s->field[k];
    int kind = frame_series[k];
    hsize_t items = kind == SERIES_VELOCITY || kind == SERIES_DISPLACEMENT ? s->position0.items
                    : kind == SERIES_DAMAGE || kind == SERIES_FLUID_PRESSURE ||
                            kind == SERIES_APERTURE
                        ? s->joints.items
                        : s->cells.items;
    return a->ds >= 0 && a->items == items && a->width <= 16;
}

static uint32_t frame_location(int k)
{
    int kind = frame_series[k];
    if (kind == SERIES_VELOCITY || kind == SERIES_DISPLACEMENT)
        return FRAME_AT_NODE;
    return kind == SERIES_DAMAGE || kind == SERIES_FLUID_PRESSURE || kind == SERIES_APERTURE
               ? FRAME_AT_JOINT
               : FRAME_AT_ELEMENT;
}

/* ------------------------------------------------------------- sections */

void *frame_add(frame_build *b, const char *name, uint32_t at, uint32_t width, uint32_t type,
                uint32_t items, int shape)
{
    if (b->count >= FRAME_MAX_SECTIONS)
        return NULL;
    frame_section *s = &b->section[b->count];
    memset(s, 0, sizeof *s);
    size_t n = strlen(name); /* NUL-padded, not terminated: "principal_stress" fills it */
    memcpy(s->name, name, n < sizeof s->name ? n : sizeof s->name);
    s->at = at;
    s->width = width;
    s->type = type;
    s->items = items;
    s->shape = shape;
    s->data = calloc((size_t)items * width + 1, 4);
    if (!s->data)
        return NULL;
    b->count++;
    return s->data;
}

static void frame_build_free(frame_build *b)
{
    for (int i = 0; i < b->count; i++)
        free(b->section[i].data);
    for (int k = 0; k < CARRY_KINDS; k++)
        free(b->carry.id[k]);
    memset(b, 0, sizeof *b);
}

/* The carried items of a whole row of `width` doubles per item, rounded
 * to float. The rows are read as stored (double), which HDF5 copies
 * straight from its chunks: converting a 1e5-element mesh's row to float
 * in HDF5 cost more than reading it, and only the carried items need it. */
static void frame_gather(float *out, const double *all, uint32_t width, const frame_carry *c,
                         int kind)
{
    const uint32_t *id = c->id[kind];
    for (uint32_t i = 0; i < c->count[kind]; i++) {
        const double *row = all + (size_t)(id ? id[i] : i) * width;
        for (uint32_t k = 0; k < width; k++)
            out[(size_t)i * width + k] = (float)row[k];
    }
}

static void frame_gather_float(float *out, const float *all, uint32_t width,
                               const frame_carry *c, int kind)
{
    const uint32_t *id = c->id[kind];
    for (uint32_t i = 0; i < c->count[kind]; i++)
        memcpy(out + (size_t)i * width, all + (size_t)(id ? id[i] : i) * width,
               sizeof(float) * width);
}

/* ------------------------------------------------------------ the bytes */

static void put_u32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

static void put_u64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

/* The arrays are written in the host's order: the frame is little-endian,
 * which every machine fdemd builds on is (checked at compile time). */
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "result_frame.c writes float32 arrays as the host stores them: little-endian only"
#endif

/* The shape's key: a 64-bit hash of the shape sections (names, sizes and
 * values), so equal keys mean the same mesh drawn the same way. Word by
 * word, a multiply and a rotation each: 20 MB take ~10 ms. */
static uint64_t frame_shape_key(const frame_build *b)
{
    uint64_t h = 0x9e3779b97f4a7c15ull ^ (uint64_t)b->dimension ^ ((uint64_t)b->surface << 8);
    for (int i = 0; i < b->count; i++) {
        const frame_section *s = &b->section[i];
        if (!s->shape)
            continue;
        uint32_t meta[5];
        memcpy(meta, s->name, 4);
        meta[1] = s->at, meta[2] = s->width, meta[3] = s->type, meta[4] = s->items;
        const uint32_t *w = s->data;
        size_t n = (size_t)s->items * s->width;
        for (int k = 0; k < 5; k++)
            h = ((h ^ meta[k]) * 0xff51afd7ed558ccdull), h ^= h >> 29;
        for (size_t k = 0; k < n; k++)
            h = ((h ^ w[k]) * 0xc4ceb9fe1a85ec53ull), h = (h << 23) | (h >> 41);
    }
    return h ^ (h >> 31);
}

typedef struct frame_head {
    int index, snapshots, deformed;
    double time;
    int64_t step;
    uint64_t key;
    int with_shape;
} frame_head;

static size_t frame_bytes(const frame_build *b, int with_shape)
{
    size_t n = FRAME_HEADER_BYTES;
    for (int i = 0; i < b->count; i++)
        if (with_shape || !b->section[i].shape)
            n += FRAME_SECTION_HEADER_BYTES + 4 * (size_t)b->section[i].items * b->section[i].width;
    return n;
}

static void frame_write(const frame_build *b, const frame_head *h, unsigned char *buf)
{
    unsigned char *p = buf + FRAME_HEADER_BYTES;
    uint32_t sections = 0;
    for (int i = 0; i < b->count; i++) {
        const frame_section *s = &b->section[i];
        if (s->shape && !h->with_shape)
            continue;
        memset(p, 0, FRAME_SECTION_HEADER_BYTES);
        memcpy(p, s->name, sizeof s->name);
        put_u32(p + FRAME_NAME_BYTES, s->at);
        put_u32(p + FRAME_NAME_BYTES + 4, s->width);
        put_u32(p + FRAME_NAME_BYTES + 8, s->type);
        put_u32(p + FRAME_NAME_BYTES + 12, s->items);
        p += FRAME_SECTION_HEADER_BYTES;
        memcpy(p, s->data, 4 * (size_t)s->items * s->width);
        p += 4 * (size_t)s->items * s->width;
        sections++;
    }
    memcpy(buf, FRAME_MAGIC, 8);
    put_u32(buf + 8, FRAME_VERSION);
    put_u32(buf + 12, (uint32_t)b->dimension);
    put_u32(buf + 16, b->carry.count[CARRY_NODES]);
    put_u32(buf + 20, b->carry.count[CARRY_ELEMENTS]);
    put_u32(buf + 24, b->carry.count[CARRY_JOINTS]);
    put_u32(buf + 28, (uint32_t)h->index);
    put_u32(buf + 32, (uint32_t)h->snapshots);
    put_u32(buf + 36, sections);
    uint64_t time_bits;
    memcpy(&time_bits, &h->time, sizeof time_bits);
    put_u64(buf + 40, time_bits);
    put_u64(buf + 48, (uint64_t)h->step);
    put_u32(buf + 56, (uint32_t)h->deformed);
    put_u32(buf + 60, b->faces);
    put_u64(buf + 64, h->key);
    put_u32(buf + 72, (b->surface ? FRAME_FLAG_SURFACE : 0) | (h->with_shape ? FRAME_FLAG_SHAPE : 0));
    put_u32(buf + 76, 0);
}

/* ------------------------------------------------------------- reading */

/* The deformed positions (doubles) from position0 (x0, given):
 * /snapshots/position, else position0 plus /snapshots/displacement, else
 * position0 (header flag 0). */
static int frame_positions(const frame_source *s, int index, const float *x0, double *x,
                           int *deformed)
{
    size_t n = (size_t)(s->position0.items * s->position0.width);
    frame_array disp;
    if (s->position.ds >= 0 && s->position.items * s->position.width == n) {
        *deformed = 1;
        return frame_read(&s->position, index, H5T_NATIVE_DOUBLE, x);
    }
    frame_open(s->file, "/snapshots/displacement", 1, &disp);
    int rc = 0;
    *deformed = disp.ds >= 0 && disp.items * disp.width == n;
    if (*deformed) {
        rc = frame_read(&disp, index, H5T_NATIVE_DOUBLE, x);
        for (size_t i = 0; rc == 0 && i < n; i++)
            x[i] += x0[i];
    } else {
        for (size_t i = 0; i < n; i++)
            x[i] = x0[i];
    }
    frame_close(&disp);
    return rc;
}

/* Which joints open their faces (broken: damage 1, read as double: a
 * float would round 0.99999999 up; and with `wet`, holding fluid:
 * pressure not 0) and which elements are there, in this snapshot. */
static int frame_state(const frame_source *s, int index, int wet, unsigned char *broken,
                       unsigned char *active, void *scratch, int *has_broken, int *has_active)
{
    const frame_array *dmg = &s->field[5], *act = &s->field[7], *p = &s->field[8];
    int fits_damage = frame_field_fits(s, 5);
    wet = wet && frame_field_fits(s, 8) && p->width == 1;
    *has_broken = fits_damage || wet;
    *has_active = frame_field_fits(s, 7) && act->width == 1;
    if (*has_broken)
        memset(broken, 0, (size_t)s->joints.items);
    if (fits_damage) {
        if (frame_read(dmg, index, H5T_NATIVE_DOUBLE, scratch) != 0)
            return -1;
        const double *d = scratch;
        for (hsize_t j = 0; j < s->joints.items; j++)
            broken[j] = d[j] >= 1.0;
    }
    if (wet) {
        if (frame_read(p, index, H5T_NATIVE_DOUBLE, scratch) != 0)
            return -1;
        const double *pressure = scratch;
        for (hsize_t j = 0; j < s->joints.items; j++)
            broken[j] |= pressure[j] != 0.0;
    }
    if (*has_active) {
        if (frame_read(act, index, H5T_NATIVE_INT32, scratch) != 0)
            return -1;
        const int32_t *a = scratch;
        for (hsize_t e = 0; e < s->cells.items; e++)
            active[e] = a[e] != 0;
    }
    return 0;
}

/* The /mesh arrays of the file and their facet map, into m. */
static int frame_mesh_read(frame_mesh *m, const frame_source *s, const char *owner, char *err,
                           size_t errlen)
{
    frame_mesh_clear(m);
    m->dimension = s->dimension;
    m->nodes = (uint32_t)s->position0.items;
    m->elements = (uint32_t)s->cells.items;
    m->joints = (uint32_t)s->joints.items;
    m->cells = malloc(sizeof(int32_t) * ((size_t)m->elements * (m->dimension + 1) + 1));
    m->joint_nodes = malloc(sizeof(int32_t) * ((size_t)m->joints * 2 * m->dimension + 1));
    m->position0 = malloc(sizeof(float) * ((size_t)m->nodes * m->dimension + 1));
    if (!m->cells || !m->joint_nodes || !m->position0) {
        frame_mesh_clear(m);
        snprintf(err, errlen, "out of memory for the frame's mesh");
        return -1;
    }
    if (frame_read(&s->cells, -1, H5T_NATIVE_INT32, m->cells) != 0 ||
        frame_read(&s->position0, -1, H5T_NATIVE_FLOAT, m->position0) != 0 ||
        (m->joints && frame_read(&s->joints, -1, H5T_NATIVE_INT32, m->joint_nodes) != 0)) {
        frame_mesh_clear(m);
        result_fail(err, errlen, "cannot read the result file's /mesh");
        return -1;
    }
    if (frame_mesh_map(m, err, errlen) != 0) {
        frame_mesh_clear(m);
        return -1;
    }
    snprintf(m->owner, sizeof m->owner, "%s", owner ? owner : "");
    return 0;
}

/* The cached mesh when it is this one's (same owner, same sizes). */
static int frame_mesh_cached(const result_frame_request *q, const frame_source *s)
{
    const frame_mesh *m = q->cache ? &q->cache->mesh : NULL;
    return m && m->cells && q->cache_owner && q->cache_owner[0] &&
           strcmp(m->owner, q->cache_owner) == 0 && m->dimension == s->dimension &&
           m->nodes == s->position0.items && m->elements == s->cells.items &&
           m->joints == s->joints.items;
}

/* The shape: the mesh (kept in the cache, or read into *mesh), the surface
 * chosen. */
static int frame_read_shape(frame_build *b, const frame_source *s, int index, frame_mesh *mesh,
                            const result_frame_request *q, size_t row, char *err,
                            size_t errlen)
{
    int rc = frame_mesh_cached(q, s) ? 0 : frame_mesh_read(mesh, s, q->cache_owner, err, errlen);
    int has_broken = 0, has_active = 0;
    if (rc == 0 && frame_mesh_work(mesh, row) != 0) {
        snprintf(err, errlen, "out of memory for the frame's mesh");
        rc = 503;
    } else if (rc == 0 && frame_state(s, index, q->fields & FRAME_WET_FIELDS, mesh->broken,
                                      mesh->active, mesh->row,
                                      &has_broken, &has_active) != 0) {
        result_fail(err, errlen, "cannot read the damage of snapshot %d", index);
        rc = -1;
    }
    if (rc == 0)
        rc = frame_shape(b, mesh, has_broken ? mesh->broken : NULL,
                         has_active ? mesh->active : NULL, err, errlen);
    return rc;
}

/* Positions and the fields asked for, of the carried items. */
static int frame_read_values(frame_build *b, const frame_source *s, int index,
                             const frame_mesh *mesh, unsigned wanted, double *scratch,
                             int *deformed)
{
    const frame_carry *c = &b->carry;
    uint32_t d = (uint32_t)b->dimension, n = c->count[CARRY_NODES];
    float *x0 = frame_add(b, "position0", FRAME_AT_NODE, d, FRAME_F32, n, 1);
    float *x = frame_add(b, "position", FRAME_AT_NODE, d, FRAME_F32, n, 0);
    if (!x0 || !x || frame_positions(s, index, mesh->position0, scratch, deformed) != 0)
        return -1;
    frame_gather_float(x0, mesh->position0, d, c, CARRY_NODES);
    frame_gather(x, scratch, d, c, CARRY_NODES);
    for (int k = 0; k < RESULT_FRAME_FIELDS; k++) {
        if (!(wanted & (1u << k)) || !frame_field_fits(s, k))
            continue;
        uint32_t at = frame_location(k), width = (uint32_t)s->field[k].width;
        int kind = at == FRAME_AT_NODE ? CARRY_NODES
                   : at == FRAME_AT_JOINT ? CARRY_JOINTS : CARRY_ELEMENTS;
        float *out = frame_add(b, result_frame_field_names[k], at, width, FRAME_F32,
                               c->count[kind], 0);
        if (!out || frame_read(&s->field[k], index, H5T_NATIVE_DOUBLE, scratch) != 0)
            return -1;
        frame_gather(out, scratch, width, c, kind);
    }
    return 0;
}

/* ------------------------------------------------------------ the entry */

/* What building the frame may hold at its peak: the whole-mesh frame, the
 * two scratch rows, the shape's tables, then the bytes sent. */
static size_t frame_peak_bytes(const frame_source *s)
{
    size_t N = s->position0.items, E = s->cells.items, J = s->joints.items;
    size_t d = (size_t)s->dimension, row = N * d, whole = FRAME_HEADER_BYTES;
    whole += 4 * (E * (d + 1) + J * (2 * d + 2) + 2 * row);
    for (int k = 0; k < RESULT_FRAME_FIELDS; k++)
        if (s->field[k].ds >= 0) {
            size_t values = (size_t)(s->field[k].items * s->field[k].width);
            whole += FRAME_SECTION_HEADER_BYTES + 4 * values;
            row = values > row ? values : row;
        }
    row = row > J ? row : J; /* damage, as double */
    return 2 * whole + 8 * row + frame_shape_bytes((int)d, (uint32_t)N, (uint32_t)E, (uint32_t)J);
}

static int frame_head_read(const frame_source *s, int index, frame_head *h, char *err,
                           size_t errlen)
{
    h->index = index;
    h->snapshots = s->snapshots;
    h->time = NAN;
    h->step = 0;
    if (frame_read_scalar(s->file, "/snapshots/time", index, H5T_NATIVE_DOUBLE, &h->time) != 0 ||
        frame_read_scalar(s->file, "/snapshots/step", index, H5T_NATIVE_INT64, &h->step) != 0) {
        result_fail(err, errlen, "cannot read the time of snapshot %d", index);
        return -1;
    }
    return 0;
}

static int frame_make(const frame_source *s, int index, const result_frame_request *q,
                      unsigned char **out, size_t *size, char *err, size_t errlen)
{
    frame_build b;
    frame_head h;
    frame_mesh local; /* the mesh when there is no cache to keep it in */
    memset(&b, 0, sizeof b);
    memset(&h, 0, sizeof h);
    memset(&local, 0, sizeof local);
    frame_mesh *mesh = q->cache ? &q->cache->mesh : &local;
    b.dimension = s->dimension;
    b.surface = q->surface;
    size_t row = 2 * (size_t)s->joints.items + 1;
    for (int k = 0; k < RESULT_FRAME_FIELDS; k++)
        if (s->field[k].ds >= 0 && s->field[k].items * s->field[k].width > row)
            row = (size_t)(s->field[k].items * s->field[k].width);
    if (s->position0.items * s->position0.width > row)
        row = (size_t)(s->position0.items * s->position0.width);
    int rc = frame_head_read(s, index, &h, err, errlen);
    if (rc == 0)
        rc = frame_read_shape(&b, s, index, mesh, q, row, err, errlen);
    if (rc == 0 && frame_read_values(&b, s, index, mesh, q->fields, mesh->row, &h.deformed) != 0) {
        result_fail(err, errlen, "cannot read snapshot %d of the result file", index);
        rc = -1;
    }
    frame_mesh_clear(&local);
    unsigned char *buf = NULL;
    if (rc == 0) {
        h.key = frame_shape_key(&b);
        h.with_shape = !(q->has_shape_key && q->shape_key == h.key);
        *size = frame_bytes(&b, h.with_shape);
        buf = malloc(*size);
        if (!buf) {
            snprintf(err, errlen, "out of memory for a frame of %zu bytes", *size);
            rc = 503;
        } else {
            frame_write(&b, &h, buf);
        }
    }
    frame_build_free(&b);
    *out = buf;
    return rc;
}

static int frame_build_file(hid_t file, const result_file *f, const result_frame_request *q,
                            unsigned char **out, size_t *size, char *err, size_t errlen)
{
    frame_source s;
    int rc = frame_source_open(&s, file, f, q->fields, err, errlen);
    int index = q->snapshot < 0 ? s.snapshots - 1 : q->snapshot;
    if (rc == 0 && (index < 0 || index >= s.snapshots)) {
        snprintf(err, errlen, "the case has %d snapshots (0 to %d); there is no snapshot %d",
                 s.snapshots, s.snapshots - 1, q->snapshot);
        rc = 404;
    }
    size_t peak = rc == 0 ? frame_peak_bytes(&s) : 0;
    if (rc == 0 && q->reserve && q->reserve(q->reserve_ctx, peak) != 0) {
        snprintf(err, errlen, "a frame needing %zu bytes to build would take the daemon past "
                 "its memory budget", peak);
        rc = 503;
    }
    if (rc == 0)
        rc = frame_make(&s, index, q, out, size, err, errlen);
    frame_source_close(&s);
    return rc;
}

int result_read_frame(result_file *f, const char *path, const result_frame_request *q,
                      unsigned char **out, size_t *size, char *err, size_t errlen)
{
    h5_quiet();
    *out = NULL;
    *size = 0;
    if (err && errlen) err[0] = '\0';
    if (f)
        return frame_build_file(f->file, f, q, out, size, err, errlen);
    hid_t file = result_open_read(path);
    if (file < 0) {
        result_fail(err, errlen, "cannot open %s to read a snapshot", path);
        return -1;
    }
    int rc = frame_build_file(file, NULL, q, out, size, err, errlen);
    H5Fclose(file);
    return rc;
}
