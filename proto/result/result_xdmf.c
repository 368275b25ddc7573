/*
 * result_xdmf.c - the result.xdmf sidecar that lets ParaView open result.h5
 * as a time series (XDMF2, read by ParaView's "XDMF Reader").
 *
 * Layout: a Temporal collection with one Uniform grid per complete snapshot.
 * Every grid shares /mesh/triangles as its Triangle topology (2D) or
 * /mesh/tetrahedra as its Tetrahedron topology (3D); its XY (XYZ) geometry
 * and node/cell attributes are HyperSlab DataItems that pick row s out of
 * the (S, ...) datasets, so the sidecar holds no numbers of its own and
 * stays small. One writer serves both dimensions through the xdmf_ctx.
 *
 * Choices ParaView dictates (every XDMF reader of ParaView 5.11: the
 * legacy XDMF Reader, Xdmf3ReaderS and Xdmf3ReaderT, without a message):
 *  - a snapshot's fields are named through its /xdmf views (plain HDF
 *    DataItems, result_views.c) once the file was finished; the Xdmf3
 *    readers crash on HyperSlab DataItems, which remain only for the
 *    snapshots of a case still running (legacy reader only).
 *  - velocity is a Node "Vector" of 3 components (2D: z = 0 in the view),
 *    and so is displacement (position - /mesh/position0), which ParaView's
 *    "Warp By Vector" applies to the geometry.
 *  - stress and strain are Cell "Tensor"s of 9 components, row-major
 *    xx xy xz / yx yy yz / zx zy zz; a 2D tensor is the in-plane one (zz,
 *    xz, yz read 0: /snapshots/stress does not hold the plane-strain zz).
 *    Both reader families give the same 9 components ("Tensor6" would be
 *    6 in one and 9 in the other).
 *  - principal_stress is a Cell "Matrix" of `dimension` columns (a Matrix
 *    keeps its width in both families; a 2D "Vector" would gain a z).
 *  - damage lives on joints, which are not cells of the element mesh: a
 *    second Temporal collection ("joints", present when the model has
 *    joints) draws each joint as its face A (/xdmf/joint_faces, columns
 *    a0, a1 (3D: a0, a1, a2) of /mesh/joints: a line in 2D, a triangle in
 *    3D) on the same moving nodes, with damage as its cell value (and
 *    displacement as its node vector, when written, so that a warp moves
 *    the joints with the elements).
 *  - the energy series, the constraint forces and time are Grid (field
 *    data) attributes of every grid: the whole series, one tuple per
 *    snapshot (Dimensions "S 1", and "S C*dimension" for the forces, which
 *    both families accept over the (S) and (S, C, dimension) datasets), so
 *    ParaView's "Plot Data" draws them against time.
 *  - fragment (the fragment id of each element, an Int cell scalar),
 *    node_part and element_part (static, from /mesh) colour bodies.
 *  - active (a case with stages, contract 6.1: 1 for an element still
 *    there, 0 once excavated) is a UChar cell scalar, so ParaView's
 *    Threshold (active >= 1) draws the body without its excavations.
 *  - where the geometry still is a HyperSlab (a running case), so is the
 *    topology (the whole of /mesh/triangles): the legacy reader caches a
 *    grid whose topology is a plain DataItem and then logs "Cannot find
 *    DataItem element in geometry xml, no caching possible" at every time
 *    step whose geometry is not.
 *
 * The file is rewritten whole into path.tmp, synced, then renamed, so a
 * reader never sees a half-written sidecar.
 */
#include "result.h"
#include "result_internal.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

typedef struct xdmf_ctx {
    FILE *out;
    char h5[1024]; /* XML-escaped file name the DataItems refer to */
    long nodes, elements, joints;
    int dimension;         /* 2 or 3: columns of the node datasets */
    int corners;           /* nodes per element */
    int stress_components; /* 3 or 6 */
    int snapshots;
    int views;             /* snapshots with /xdmf views */
    long constraints;
    unsigned fields;
    int staged;            /* the case has stages: /snapshots/active is written */
    int fluid;             /* the case has fluid: fluid_pressure and aperture per joint */
} xdmf_ctx;

static void xml_escape(char *out, size_t size, const char *in)
{
    size_t n = 0;
    for (; *in && n + 7 < size; in++) {
        const char *rep = NULL;
        switch (*in) {
        case '&': rep = "&amp;"; break;
        case '<': rep = "&lt;"; break;
        case '>': rep = "&gt;"; break;
        case '"': rep = "&quot;"; break;
        }
        if (rep) {
            size_t len = strlen(rep);
            memcpy(out + n, rep, len);
            n += len;
        } else {
            out[n++] = *in;
        }
    }
    out[n] = '\0';
}

/* A whole /mesh dataset. */
static void xdmf_mesh_item(const xdmf_ctx *x, const char *dims, const char *number_type,
                           int precision, const char *dataset)
{
    fprintf(x->out,
            "        <DataItem Dimensions=\"%s\" NumberType=\"%s\" Precision=\"%d\" "
            "Format=\"HDF\">%s:/mesh/%s</DataItem>\n",
            dims, number_type, precision, x->h5, dataset);
}

/* The view of `field` of snapshot s (/xdmf/s/field, result_views.c). */
static void xdmf_view_item(const xdmf_ctx *x, int s, const char *dims, const char *number_type,
                           int precision, const char *field)
{
    fprintf(x->out,
            "        <DataItem Dimensions=\"%s\" NumberType=\"%s\" Precision=\"%d\" "
            "Format=\"HDF\">%s:/xdmf/%d/%s</DataItem>\n",
            dims, number_type, precision, x->h5, s, field);
}

static int xdmf_has_view(const xdmf_ctx *x, int s)
{
    return s < x->views;
}

/* Row `s` of a (S, rows) /snapshots dataset of the given number type. */
static void xdmf_scalar_row_item(const xdmf_ctx *x, int s, long rows, const char *number_type,
                                 int precision, const char *dataset)
{
    fprintf(x->out, "        <DataItem ItemType=\"HyperSlab\" Dimensions=\"%ld\" "
            "Type=\"HyperSlab\">\n", rows);
    fprintf(x->out, "          <DataItem Dimensions=\"3 2\" NumberType=\"Int\" Format=\"XML\">"
            "%d 0  1 1  1 %ld</DataItem>\n", s, rows);
    fprintf(x->out, "          <DataItem Dimensions=\"%d %ld\" NumberType=\"%s\" Precision=\"%d\" "
            "Format=\"HDF\">%s:/snapshots/%s</DataItem>\n", x->snapshots, rows, number_type,
            precision, x->h5, dataset);
    fprintf(x->out, "        </DataItem>\n");
}

/* Row `s` (and, when width_pick >= 0, only that component) of a
 * (S, rows, width) /snapshots dataset. */
static void xdmf_row_item(const xdmf_ctx *x, int s, long rows, int width, int width_pick,
                          const char *dataset)
{
    int pick = width_pick >= 0;
    if (pick)
        fprintf(x->out, "        <DataItem ItemType=\"HyperSlab\" Dimensions=\"%ld\" "
                "Type=\"HyperSlab\">\n", rows);
    else
        fprintf(x->out, "        <DataItem ItemType=\"HyperSlab\" Dimensions=\"%ld %d\" "
                "Type=\"HyperSlab\">\n", rows, width);
    fprintf(x->out,
            "          <DataItem Dimensions=\"3 3\" NumberType=\"Int\" Format=\"XML\">"
            "%d 0 %d  1 1 1  1 %ld %d</DataItem>\n",
            s, pick ? width_pick : 0, rows, pick ? 1 : width);
    fprintf(x->out,
            "          <DataItem Dimensions=\"%d %ld %d\" NumberType=\"Float\" Precision=\"8\" "
            "Format=\"HDF\">%s:/snapshots/%s</DataItem>\n",
            x->snapshots, rows, width, x->h5, dataset);
    fprintf(x->out, "        </DataItem>\n");
}

/* The nodes of snapshot s (or the initial ones when positions are not
 * stored), shared by the triangle and joint grids. */
static void xdmf_geometry(const xdmf_ctx *x, int s)
{
    char dims[64];
    fprintf(x->out, "      <Geometry GeometryType=\"%s\">\n", x->dimension == 3 ? "XYZ" : "XY");
    if ((x->fields & CASE_FIELD_POSITION) && xdmf_has_view(x, s)) {
        snprintf(dims, sizeof dims, "%ld %d", x->nodes, x->dimension);
        xdmf_view_item(x, s, dims, "Float", 8, "position");
    } else if (x->fields & CASE_FIELD_POSITION) {
        xdmf_row_item(x, s, x->nodes, x->dimension, -1, "position");
    } else {
        snprintf(dims, sizeof dims, "%ld %d", x->nodes, x->dimension);
        xdmf_mesh_item(x, dims, "Float", 8, "position0");
    }
    fprintf(x->out, "      </Geometry>\n");
}

/* A node field of `dimension` columns as a Node "Vector": its view, 3
 * components (2D: z = 0), or before the views exist a HyperSlab of row s. */
static void xdmf_node_vector(const xdmf_ctx *x, int s, const char *dataset)
{
    char dims[64];
    fprintf(x->out, "      <Attribute Name=\"%s\" AttributeType=\"Vector\" "
            "Center=\"Node\">\n", dataset);
    snprintf(dims, sizeof dims, "%ld 3", x->nodes);
    if (xdmf_has_view(x, s)) xdmf_view_item(x, s, dims, "Float", 8, dataset);
    else xdmf_row_item(x, s, x->nodes, x->dimension, -1, dataset);
    fprintf(x->out, "      </Attribute>\n");
}

/* Face A of each joint: a line (a0, a1) in 2D, a triangle (a0, a1, a2) in
 * 3D: /xdmf/joint_faces once the views exist, else picked out of the
 * (J, 2 * dimension) /mesh/joints by a HyperSlab. */
static void xdmf_joint_grid(const xdmf_ctx *x, int s, double time)
{
    long J = x->joints;
    int face = x->dimension, width = 2 * x->dimension;
    char dims[64];
    fprintf(x->out, "    <Grid Name=\"joints %d\" GridType=\"Uniform\">\n", s);
    fprintf(x->out, "      <Time Value=\"%.17g\"/>\n", time);
    if (face == 2)
        fprintf(x->out, "      <Topology TopologyType=\"Polyline\" NodesPerElement=\"2\" "
                "NumberOfElements=\"%ld\">\n", J);
    else
        fprintf(x->out, "      <Topology TopologyType=\"Triangle\" NumberOfElements=\"%ld\">\n",
                J);
    snprintf(dims, sizeof dims, "%ld %d", J, face);
    if (xdmf_has_view(x, s)) {
        fprintf(x->out, "        <DataItem Dimensions=\"%s\" NumberType=\"Int\" Precision=\"4\" "
                "Format=\"HDF\">%s:/xdmf/joint_faces</DataItem>\n", dims, x->h5);
    } else {
        fprintf(x->out, "        <DataItem ItemType=\"HyperSlab\" Dimensions=\"%s\" "
                "Type=\"HyperSlab\">\n", dims);
        fprintf(x->out, "          <DataItem Dimensions=\"3 2\" NumberType=\"Int\" "
                "Format=\"XML\">0 0  1 1  %ld %d</DataItem>\n", J, face);
        fprintf(x->out, "          <DataItem Dimensions=\"%ld %d\" NumberType=\"Int\" "
                "Precision=\"4\" Format=\"HDF\">%s:/mesh/joints</DataItem>\n", J, width, x->h5);
        fprintf(x->out, "        </DataItem>\n");
    }
    fprintf(x->out, "      </Topology>\n");
    xdmf_geometry(x, s);
    fprintf(x->out, "      <Attribute Name=\"damage\" AttributeType=\"Scalar\" Center=\"Cell\">\n");
    snprintf(dims, sizeof dims, "%ld", J);
    if (xdmf_has_view(x, s)) xdmf_view_item(x, s, dims, "Float", 8, "damage");
    else xdmf_scalar_row_item(x, s, J, "Float", 8, "damage");
    fprintf(x->out, "      </Attribute>\n");
    static const char *const fluid_fields[] = {"fluid_pressure", "aperture"};
    for (int k = 0; x->fluid && k < 2; k++) { /* contract 6.4, per joint like damage */
        fprintf(x->out, "      <Attribute Name=\"%s\" AttributeType=\"Scalar\" "
                "Center=\"Cell\">\n", fluid_fields[k]);
        if (xdmf_has_view(x, s)) xdmf_view_item(x, s, dims, "Float", 8, fluid_fields[k]);
        else xdmf_scalar_row_item(x, s, J, "Float", 8, fluid_fields[k]);
        fprintf(x->out, "      </Attribute>\n");
    }
    /* on the same nodes as the elements: Warp By Vector moves both blocks */
    if (x->fields & CASE_FIELD_DISPLACEMENT)
        xdmf_node_vector(x, s, "displacement");
    fprintf(x->out, "    </Grid>\n");
}

/* One Cell scalar per column of a (S, E, width) element dataset, named
 * dataset_xx ... in the Voigt order of stress (width 3 or 6), or
 * dataset_1 ... for principal values (width = dimension). */
static void xdmf_cell_components(const xdmf_ctx *x, int s, const char *dataset, int width)
{
    static const char *const plane[3] = {"xx", "yy", "xy"};
    static const char *const solid[6] = {"xx", "yy", "zz", "yz", "xz", "xy"};
    static const char *const principal[3] = {"1", "2", "3"};
    int tensor = width == x->stress_components;
    const char *const *suffix = !tensor ? principal : x->dimension == 3 ? solid : plane;
    for (int k = 0; k < width; k++) {
        fprintf(x->out, "      <Attribute Name=\"%s_%s\" AttributeType=\"Scalar\" "
                "Center=\"Cell\">\n", dataset, suffix[k]);
        xdmf_row_item(x, s, x->elements, width, k, dataset);
        fprintf(x->out, "      </Attribute>\n");
    }
}

/* An element field: its view (a Tensor of 9 or a Matrix of `width`
 * columns) or, before the views exist, one HyperSlab scalar per column. */
static void xdmf_cell_field(const xdmf_ctx *x, int s, const char *dataset, int width)
{
    if (!xdmf_has_view(x, s)) {
        xdmf_cell_components(x, s, dataset, width);
        return;
    }
    int tensor = width == x->stress_components;
    char dims[64];
    snprintf(dims, sizeof dims, "%ld %d", x->elements, tensor ? 9 : width);
    fprintf(x->out, "      <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Cell\">\n",
            dataset, tensor ? "Tensor" : "Matrix");
    xdmf_view_item(x, s, dims, "Float", 8, dataset);
    fprintf(x->out, "      </Attribute>\n");
}

/* The whole series of the energies, time and constraint forces, one tuple
 * per snapshot, as field data of the grid. */
static void xdmf_series_attributes(const xdmf_ctx *x)
{
    for (int kind = SERIES_KINETIC; kind <= SERIES_TIME; kind++) {
        if (kind == SERIES_FLUID_PRESSURE || kind == SERIES_APERTURE) continue; /* per joint */
        fprintf(x->out, "      <Attribute Name=\"%s\" AttributeType=\"Scalar\" "
                "Center=\"Grid\">\n", series_names[kind]);
        fprintf(x->out, "        <DataItem Dimensions=\"%d 1\" NumberType=\"Float\" "
                "Precision=\"8\" Format=\"HDF\">%s:/snapshots/%s</DataItem>\n", x->snapshots,
                x->h5, series_names[kind]);
        fprintf(x->out, "      </Attribute>\n");
    }
    if (x->staged) { /* written for cases with stages only */
        fprintf(x->out, "      <Attribute Name=\"%s\" AttributeType=\"Scalar\" "
                "Center=\"Grid\">\n", series_names[SERIES_EXCAVATED]);
        fprintf(x->out, "        <DataItem Dimensions=\"%d 1\" NumberType=\"Float\" "
                "Precision=\"8\" Format=\"HDF\">%s:/snapshots/%s</DataItem>\n", x->snapshots,
                x->h5, series_names[SERIES_EXCAVATED]);
        fprintf(x->out, "      </Attribute>\n");
    }
    if (x->constraints <= 0) return;
    fprintf(x->out, "      <Attribute Name=\"constraint_force\" AttributeType=\"Matrix\" "
            "Center=\"Grid\">\n");
    fprintf(x->out, "        <DataItem Dimensions=\"%d %ld\" NumberType=\"Float\" "
            "Precision=\"8\" Format=\"HDF\">%s:/snapshots/constraint_force</DataItem>\n",
            x->snapshots, x->constraints * x->dimension, x->h5);
    fprintf(x->out, "      </Attribute>\n");
}

static void xdmf_grid(const xdmf_ctx *x, int s, double time)
{
    char dims[64];
    fprintf(x->out, "    <Grid Name=\"snapshot %d\" GridType=\"Uniform\">\n", s);
    fprintf(x->out, "      <Time Value=\"%.17g\"/>\n", time);

    int solid = x->dimension == 3;
    fprintf(x->out, "      <Topology TopologyType=\"%s\" NumberOfElements=\"%ld\">\n",
            solid ? "Tetrahedron" : "Triangle", x->elements);
    snprintf(dims, sizeof dims, "%ld %d", x->elements, x->corners);
    const char *cells = solid ? "tetrahedra" : "triangles";
    if ((x->fields & CASE_FIELD_POSITION) && !xdmf_has_view(x, s)) {
        /* the whole of it, as a HyperSlab like the geometry (see the top) */
        fprintf(x->out, "        <DataItem ItemType=\"HyperSlab\" Dimensions=\"%s\" "
                "Type=\"HyperSlab\">\n", dims);
        fprintf(x->out, "          <DataItem Dimensions=\"3 2\" NumberType=\"Int\" "
                "Format=\"XML\">0 0  1 1  %s</DataItem>\n", dims);
        fprintf(x->out, "  ");
    }
    xdmf_mesh_item(x, dims, "Int", 4, cells);
    if ((x->fields & CASE_FIELD_POSITION) && !xdmf_has_view(x, s))
        fprintf(x->out, "        </DataItem>\n");
    fprintf(x->out, "      </Topology>\n");

    xdmf_geometry(x, s);

    if (x->fields & CASE_FIELD_VELOCITY)
        xdmf_node_vector(x, s, "velocity");
    if (x->fields & CASE_FIELD_DISPLACEMENT)
        xdmf_node_vector(x, s, "displacement");
    if (x->fields & CASE_FIELD_STRESS)
        xdmf_cell_field(x, s, "stress", x->stress_components);
    if (x->fields & CASE_FIELD_STRAIN)
        xdmf_cell_field(x, s, "strain", x->stress_components);
    if (x->fields & CASE_FIELD_PRINCIPAL_STRESS)
        xdmf_cell_field(x, s, "principal_stress", x->dimension);
    fprintf(x->out, "      <Attribute Name=\"fragment\" AttributeType=\"Scalar\" "
            "Center=\"Cell\">\n");
    snprintf(dims, sizeof dims, "%ld", x->elements);
    if (xdmf_has_view(x, s)) xdmf_view_item(x, s, dims, "Int", 4, "fragment");
    else xdmf_scalar_row_item(x, s, x->elements, "Int", 4, "fragment");
    fprintf(x->out, "      </Attribute>\n");
    if (x->staged) {
        fprintf(x->out, "      <Attribute Name=\"active\" AttributeType=\"Scalar\" "
                "Center=\"Cell\">\n");
        if (xdmf_has_view(x, s)) xdmf_view_item(x, s, dims, "UChar", 1, "active");
        else xdmf_scalar_row_item(x, s, x->elements, "UChar", 1, "active");
        fprintf(x->out, "      </Attribute>\n");
    }
    xdmf_series_attributes(x);
    fprintf(x->out, "      <Attribute Name=\"node_part\" AttributeType=\"Scalar\" "
            "Center=\"Node\">\n");
    snprintf(dims, sizeof dims, "%ld", x->nodes);
    xdmf_mesh_item(x, dims, "Int", 4, "node_part");
    fprintf(x->out, "      </Attribute>\n");
    fprintf(x->out, "      <Attribute Name=\"element_part\" AttributeType=\"Scalar\" "
            "Center=\"Cell\">\n");
    snprintf(dims, sizeof dims, "%ld", x->elements);
    xdmf_mesh_item(x, dims, "Int", 4, "element_part");
    fprintf(x->out, "      </Attribute>\n");
    fprintf(x->out, "    </Grid>\n");
}

/* The two temporal collections are named "elements" and "joints": the
 * Xdmf3 readers name their blocks after them (the legacy reader numbers
 * them), so a user, or a script's ExtractBlock, picks a block by what it
 * holds; the case name is the root attribute `name` of result.h5. */
static void xdmf_document(const xdmf_ctx *x, const result_file *f)
{
    fprintf(x->out, "<?xml version=\"1.0\" ?>\n");
    fprintf(x->out, "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n");
    fprintf(x->out, "<Xdmf Version=\"2.0\">\n");
    fprintf(x->out, "  <Domain>\n");
    fprintf(x->out, "  <Grid Name=\"elements\" GridType=\"Collection\" "
            "CollectionType=\"Temporal\">\n");
    for (int s = 0; s < x->snapshots; s++) xdmf_grid(x, s, result_snapshot_time(f, s));
    fprintf(x->out, "  </Grid>\n");
    if (x->joints > 0) {
        fprintf(x->out, "  <Grid Name=\"joints\" GridType=\"Collection\" "
                "CollectionType=\"Temporal\">\n");
        for (int s = 0; s < x->snapshots; s++) xdmf_joint_grid(x, s, result_snapshot_time(f, s));
        fprintf(x->out, "  </Grid>\n");
    }
    fprintf(x->out, "  </Domain>\n");
    fprintf(x->out, "</Xdmf>\n");
}

int xdmf_write(const char *xdmf_path, const char *h5_name, const fdem_model *model,
               const case_info *info, const result_file *f, char *err, size_t errlen)
{
    if (!xdmf_path || !h5_name || !model || !info || !f) {
        snprintf(err, errlen, "xdmf_write: missing path, file name, model, case info or file");
        return -1;
    }
    fdem_counts counts = fdem_get_counts(model);
    xdmf_ctx x = {.nodes = counts.nodes, .elements = counts.elements, .joints = counts.joints,
                  .dimension = fdem_get_dimension(model),
                  .corners = fdem_nodes_per_element(model),
                  .stress_components = fdem_stress_components(model),
                  .snapshots = result_snapshot_count(f), .views = result_view_count(f),
                  .constraints = counts.constraints, .fields = info->fields,
                  .staged = fdem_stage_index(model) >= 0,
                  .fluid = fdem_get_fluid(model).enabled && counts.joints > 0};
    xml_escape(x.h5, sizeof x.h5, h5_name);

    char tmp[4096];
    if ((size_t)snprintf(tmp, sizeof tmp, "%s.tmp", xdmf_path) >= sizeof tmp) {
        snprintf(err, errlen, "XDMF path too long: %s", xdmf_path);
        return -1;
    }
    x.out = fopen(tmp, "w");
    if (!x.out) {
        snprintf(err, errlen, "cannot create %s: %s", tmp, strerror(errno));
        return -1;
    }
    xdmf_document(&x, f);
    int failed = ferror(x.out) || fflush(x.out) != 0 || fsync(fileno(x.out)) != 0;
    int saved = errno;
    if (fclose(x.out) != 0) failed = 1;
    if (failed) {
        snprintf(err, errlen, "cannot write %s: %s", tmp, strerror(saved));
        unlink(tmp);
        return -1;
    }
    if (rename(tmp, xdmf_path) != 0) {
        snprintf(err, errlen, "cannot rename %s to %s: %s", tmp, xdmf_path, strerror(errno));
        unlink(tmp);
        return -1;
    }
    return 0;
}
