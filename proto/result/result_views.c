/*
 * result_views.c - /xdmf in result.h5: one HDF5 virtual dataset ("view")
 * per snapshot and field, each a plain (rows, width) array that maps a row
 * of a /snapshots dataset and stores no numbers of its own.
 *
 * Why views: result.xdmf must open in every XDMF reader of ParaView 5.11.
 * A HyperSlab DataItem (row s of an (S, rows, width) dataset) works in the
 * legacy XDMF Reader only: the Xdmf3 readers ask for the type of an array
 * before reading it, a HyperSlab has none yet, and they crash (SIGSEGV in
 * vtkXdmf3DataSet::CopyShape). A view is an ordinary dataset to every
 * reader (HDF5 1.10 resolves the mapping), so the sidecar can name it in a
 * plain HDF DataItem. The views also present fields as ParaView wants them:
 * velocity and displacement padded to three components (z = 0 in 2D), and
 * stress and strain as full 3x3 tensors (row-major; the 2D ones with zz, xz
 * and yz zero), unmapped entries reading as the fill value 0. The element
 * rows (fragment, and active for a case with stages) are plain copies.
 *
 * SWMR writing cannot create datasets, so the views are made when a case's
 * file is closed (finished, paused, stopped): result_finish() closes the
 * SWMR handles, reopens the file for ordinary writing, adds the views the
 * file lacks and closes it again. While a case runs the sidecar keeps
 * HyperSlabs for the snapshots without views (result_xdmf.c).
 */
#include "result_internal.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define VIEW_MAX_COLUMNS 9

/* One view: `columns` destination columns, column k taken from source
 * column source[k] (-1: left at the fill value). */
typedef struct view_shape {
    int kind;
    int columns;
    int source[VIEW_MAX_COLUMNS];
} view_shape;

/* Voigt order of /snapshots/stress into a row-major 3x3 tensor. */
static const view_shape tensor_2d = {0, 9, {0, 2, -1, 2, 1, -1, -1, -1, -1}};
static const view_shape tensor_3d = {0, 9, {0, 5, 4, 5, 1, 3, 4, 3, 2}};

/* The layout of the view of series `kind` with `width` columns (0: a 1-D
 * row) in a model of `dimension`; 0 when the series has no view. */
static int view_shape_of(int kind, int width, int dimension, view_shape *v)
{
    memset(v, 0, sizeof *v);
    switch (kind) {
    case SERIES_STRESS:
    case SERIES_STRAIN:
        *v = dimension == 3 ? tensor_3d : tensor_2d;
        break;
    case SERIES_VELOCITY:
    case SERIES_DISPLACEMENT:
        v->columns = 3;
        for (int k = 0; k < 3; k++) v->source[k] = k < width ? k : -1;
        break;
    case SERIES_POSITION:
    case SERIES_PRINCIPAL_STRESS:
    case SERIES_DAMAGE:
    case SERIES_FLUID_PRESSURE:
    case SERIES_APERTURE:
    case SERIES_FRAGMENT:
    case SERIES_ACTIVE:
        v->columns = width; /* a copy; 0 for the 1-D series */
        for (int k = 0; k < width && k < VIEW_MAX_COLUMNS; k++) v->source[k] = k;
        break;
    default:
        return 0;
    }
    v->kind = kind;
    return 1;
}

/* The view of this file's series `kind` (a per-snapshot array, rank 2 or
 * 3): 0 when it has none. */
static int series_view(const series *ds, int kind, int dimension, view_shape *v)
{
    int width = ds[kind].rank == 3 ? (int)ds[kind].row[1] : 0;
    return ds[kind].rank >= 2 && view_shape_of(kind, width, dimension, v);
}

/* Maps destination column k (or the whole 1-D row) of `vspace` to row s
 * of the source. */
static int view_map(hid_t dcpl, hid_t vspace, hid_t sspace, const char *source, int s,
                    hsize_t rows, int dst, int src)
{
    hsize_t vstart[2] = {0, (hsize_t)(dst < 0 ? 0 : dst)}, vcount[2] = {rows, 1};
    hsize_t sstart[3] = {(hsize_t)s, 0, (hsize_t)(src < 0 ? 0 : src)}, scount[3] = {1, rows, 1};
    return H5Sselect_hyperslab(vspace, H5S_SELECT_SET, vstart, NULL, vcount, NULL) < 0 ||
                   H5Sselect_hyperslab(sspace, H5S_SELECT_SET, sstart, NULL, scount, NULL) < 0 ||
                   H5Pset_virtual(dcpl, vspace, ".", source, sspace) < 0
               ? -1
               : 0;
}

static int view_create(hid_t group, const series *ds, const view_shape *v, int s)
{
    const series *src = &ds[v->kind];
    hsize_t rows = src->row[0];
    int rank = v->columns ? 2 : 1;
    hsize_t vdims[2] = {rows, (hsize_t)v->columns};
    hsize_t sdims[3] = {(hsize_t)s + 1, rows, src->row[1]};
    char source[64];
    snprintf(source, sizeof source, "/snapshots/%s", series_names[v->kind]);
    hid_t type = series_mem_type(v->kind);
    const double zero = 0;
    const int32_t unrecorded = -1;
    const uint8_t inactive = 0;
    const void *fill = type == H5T_NATIVE_INT32   ? (const void *)&unrecorded
                     : type == H5T_NATIVE_UINT8 ? (const void *)&inactive
                                                : (const void *)&zero;
    hid_t vspace = H5Screate_simple(rank, vdims, NULL);
    hid_t sspace = H5Screate_simple(src->rank, sdims, NULL);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    int rc = vspace < 0 || sspace < 0 || dcpl < 0 ||
                     H5Pset_fill_value(dcpl, type, fill) < 0
                 ? -1
                 : 0;
    for (int k = 0; rc == 0 && k < (v->columns ? v->columns : 1); k++)
        if (!v->columns || v->source[k] >= 0)
            rc = view_map(dcpl, vspace, sspace, source, s, rows, v->columns ? k : -1,
                          v->columns ? v->source[k] : -1);
    hid_t id = rc == 0 ? H5Dcreate2(group, series_names[v->kind], series_file_type(v->kind), vspace,
                                    H5P_DEFAULT, dcpl, H5P_DEFAULT)
                       : H5I_INVALID_HID;
    if (id < 0) rc = -1;
    else H5Dclose(id);
    if (dcpl >= 0) H5Pclose(dcpl);
    if (sspace >= 0) H5Sclose(sspace);
    if (vspace >= 0) H5Sclose(vspace);
    return rc;
}

/* Face A of each joint (columns 0 .. dimension-1 of /mesh/joints): the
 * topology of the joints grid, a HyperSlab the Xdmf3 readers cannot read. */
static int view_joint_faces(hid_t file, hid_t xdmf, int dimension)
{
    if (H5Lexists(file, "/mesh/joints", H5P_DEFAULT) <= 0) return 0;
    if (H5Lexists(xdmf, "joint_faces", H5P_DEFAULT) > 0) return 0;
    hid_t joints = H5Dopen2(file, "/mesh/joints", H5P_DEFAULT);
    hid_t sspace = joints >= 0 ? H5Dget_space(joints) : H5I_INVALID_HID;
    hsize_t sdims[2] = {0, 0};
    if (sspace >= 0) H5Sget_simple_extent_dims(sspace, sdims, NULL);
    hsize_t vdims[2] = {sdims[0], (hsize_t)dimension}, start[2] = {0, 0};
    hid_t vspace = H5Screate_simple(2, vdims, NULL);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    int rc = -1;
    if (sspace >= 0 && vspace >= 0 && dcpl >= 0 && sdims[1] >= (hsize_t)dimension &&
        H5Sselect_hyperslab(sspace, H5S_SELECT_SET, start, NULL, vdims, NULL) >= 0 &&
        H5Pset_virtual(dcpl, vspace, ".", "/mesh/joints", sspace) >= 0) {
        hid_t id = H5Dcreate2(xdmf, "joint_faces", H5T_STD_I32LE, vspace, H5P_DEFAULT, dcpl,
                              H5P_DEFAULT);
        if (id >= 0) rc = H5Dclose(id) < 0 ? -1 : 0;
    }
    if (dcpl >= 0) H5Pclose(dcpl);
    if (vspace >= 0) H5Sclose(vspace);
    if (sspace >= 0) H5Sclose(sspace);
    if (joints >= 0) H5Dclose(joints);
    return rc;
}

/* /xdmf/<s>/<field> for every snapshot that has none yet. */
static int views_add(hid_t file, const series *ds, int count, int dimension)
{
    hid_t xdmf = H5Lexists(file, "xdmf", H5P_DEFAULT) > 0
                     ? H5Gopen2(file, "xdmf", H5P_DEFAULT)
                     : H5Gcreate2(file, "xdmf", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (xdmf < 0) return -1;
    int rc = view_joint_faces(file, xdmf, dimension);
    for (int s = 0; rc == 0 && s < count; s++) {
        char name[32];
        snprintf(name, sizeof name, "%d", s);
        if (H5Lexists(xdmf, name, H5P_DEFAULT) > 0) continue;
        hid_t group = H5Gcreate2(xdmf, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        if (group < 0) rc = -1;
        for (int kind = 0; rc == 0 && kind < SERIES_COUNT; kind++) {
            view_shape v;
            if (series_view(ds, kind, dimension, &v)) rc = view_create(group, ds, &v, s);
        }
        if (group >= 0 && H5Gclose(group) < 0) rc = -1;
    }
    if (H5Gclose(xdmf) < 0) rc = -1;
    return rc;
}

/* Room the views of `snapshots` more snapshots may take: measured at
 * 550-880 bytes a view with its share of the snapshot's group, so 1 KiB
 * each and for the group, and 64 KiB for /xdmf itself and joint_faces. */
#define VIEW_ROOM_BYTES 1024
#define VIEWS_FIXED_ROOM_BYTES 65536
static off_t views_room(const series *ds, int snapshots, int dimension)
{
    off_t per_snapshot = VIEW_ROOM_BYTES;
    for (int kind = 0; kind < SERIES_COUNT; kind++) {
        view_shape v;
        if (series_view(ds, kind, dimension, &v)) per_snapshot += VIEW_ROOM_BYTES;
    }
    return VIEWS_FIXED_ROOM_BYTES + per_snapshot * (snapshots > 0 ? snapshots : 0);
}

int result_finish(result_file *f, const char *path, int dimension, char *err, size_t errlen)
{
    h5_quiet();
    int rc = f->file >= 0 && H5Fflush(f->file, H5F_SCOPE_LOCAL) < 0 ? -1 : 0;
    /* Every handle, the event datasets too: an open object keeps HDF5
     * from closing the file, and the views must go to a file closed and
     * whole on disk. */
    if (result_close_handles(f) != 0) rc = -1;
    if (rc != 0) {
        result_fail(err, errlen, "cannot close %s", path);
        return -1;
    }
    if (result_reserve_room(path, views_room(f->ds, f->count - f->views, dimension),
                            "add the /xdmf views", err, errlen) != 0)
        return -1;
    hid_t fapl = file_access_latest(0);
    hid_t file = fapl >= 0 ? H5Fopen(path, H5F_ACC_RDWR, fapl) : H5I_INVALID_HID;
    if (fapl >= 0) H5Pclose(fapl);
    if (file < 0 || views_add(file, f->ds, f->count, dimension) != 0) rc = -1;
    if (file >= 0 && H5Fclose(file) < 0) rc = -1;
    if (rc != 0) {
        result_fail(err, errlen, "cannot add the /xdmf views to %s", path);
        return -1;
    }
    f->views = f->count;
    return 0;
}

int result_view_count(const result_file *f)
{
    return f ? f->views : 0;
}
