/*
 * result_describe.c - what makes result.h5 self-describing (contract 5.4):
 * the case document as the root's string attribute `case`, the names
 * behind the indices of /mesh/node_part, /mesh/element_part (part_names)
 * and of the materials (material_names), and the order of the columns of
 * /snapshots/principal_stress, named for a rock mechanic (attributes
 * `order` and `rock_mechanics_names`: sigma1 is the most compressive).
 *
 * The names come from the builder (case_info's names: parts by their
 * place in "parts", unnamed ones "part<i>", materials in the order of the
 * "materials" object, which is the order jansson iterates and the engine
 * numbers them in). Only when they did not fit there is the document
 * parsed again here, the same way, for the same indices: a second parse
 * of a 4 MB explicit mesh cost as much CPU as building its model (issue
 * 38). The
 * name lists are fixed-length strings (see write_string_list); the
 * `case` attribute is variable length, as the other root attributes.
 * Runs before SWMR writing starts: a SWMR writer cannot add objects.
 */
#include "result_internal.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A 1-D dataset of fixed-length strings as wide as the longest name
 * (NUL-padded; the bytes of a name are its UTF-8). Fixed length and the
 * default (ASCII) character set because Octave's load('-hdf5') reads only
 * those (HDF5 converts neither variable-length nor UTF-8 strings to what
 * it asks for), and one dataset it cannot read drops the whole /mesh group. */
static int write_string_list(hid_t group, const char *name, const char *const *values, size_t count)
{
    size_t width = 1;
    for (size_t i = 0; i < count; i++)
        if (strlen(values[i]) > width) width = strlen(values[i]);
    char *packed = calloc(count ? count : 1, width);
    hsize_t dims[1] = {count};
    hid_t type = H5Tcopy(H5T_C_S1);
    hid_t space = H5Screate_simple(1, dims, NULL);
    hid_t ds = H5I_INVALID_HID;
    int rc = -1;
    if (!packed || type < 0 || space < 0) goto done;
    for (size_t i = 0; i < count; i++) memcpy(packed + i * width, values[i], strlen(values[i]));
    if (H5Tset_size(type, width) < 0 || H5Tset_strpad(type, H5T_STR_NULLPAD) < 0) goto done;
    ds = H5Dcreate2(group, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (ds < 0) goto done;
    if (count > 0 && H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, packed) < 0) goto done;
    rc = 0;
done:
    if (ds >= 0) H5Dclose(ds);
    if (space >= 0) H5Sclose(space);
    if (type >= 0) H5Tclose(type);
    free(packed);
    return rc;
}

/* Part names in "parts" order; an unnamed part is "part<i>" as the builder
 * calls it. `scratch` holds the made-up names (count * 32 bytes). */
static const char **part_names(const json_t *parts, size_t count, char *scratch)
{
    const char **names = calloc(count ? count : 1, sizeof *names);
    if (!names) return NULL;
    for (size_t i = 0; i < count; i++) {
        const json_t *name = json_object_get(json_array_get(parts, i), "name");
        if (json_is_string(name) && json_string_length(name) > 0) {
            names[i] = json_string_value(name);
        } else {
            snprintf(scratch + 32 * i, 32, "part%zu", i);
            names[i] = scratch + 32 * i;
        }
    }
    return names;
}

static const char **material_names(const json_t *materials, size_t *count)
{
    *count = json_object_size(materials);
    const char **names = calloc(*count ? *count : 1, sizeof *names);
    if (!names) return NULL;
    const char *key;
    json_t *value;
    size_t i = 0;
    json_object_foreach((json_t *)materials, key, value) names[i++] = key;
    return names;
}

static int write_names(hid_t file, const json_t *root, char *err, size_t errlen)
{
    const json_t *parts = json_object_get(root, "parts");
    size_t part_count = json_is_array(parts) ? json_array_size(parts) : 0, material_count = 0;
    char *scratch = malloc(32 * (part_count ? part_count : 1));
    const char **parts_list = scratch ? part_names(parts, part_count, scratch) : NULL;
    const char **materials_list = material_names(json_object_get(root, "materials"), &material_count);
    hid_t mesh = H5Gopen2(file, "mesh", H5P_DEFAULT);
    int rc = -1;
    if (!parts_list || !materials_list)
        snprintf(err, errlen, "out of memory listing the part and material names");
    else if (mesh < 0)
        result_fail(err, errlen, "cannot open /mesh to write the part names");
    else if (write_string_list(mesh, "part_names", parts_list, part_count) < 0 ||
             write_string_list(mesh, "material_names", materials_list, material_count) < 0)
        result_fail(err, errlen, "cannot write /mesh/part_names and /mesh/material_names");
    else
        rc = 0;
    if (mesh >= 0) H5Gclose(mesh);
    free(parts_list);
    free(materials_list);
    free(scratch);
    return rc;
}

static int write_case_attribute(hid_t file, const char *text, size_t length)
{
    char *copy = malloc(length + 1); /* HDF5 strings end at a NUL */
    if (!copy) return -1;
    memcpy(copy, text, length);
    copy[length] = '\0';
    int rc = write_string_attribute(file, "case", copy);
    free(copy);
    return rc;
}

/* The names the builder kept (case_info's names: part_count parts, then
 * material_count materials, each ending in a NUL). */
static int write_kept_names(hid_t file, const case_info *info, char *err, size_t errlen)
{
    size_t parts = (size_t)info->part_count, count = parts + (size_t)info->material_count;
    const char **names = calloc(count ? count : 1, sizeof *names);
    const char *at = info->names, *end = info->names + info->names_bytes;
    for (size_t i = 0; names && i < count; i++) {
        names[i] = at < end ? at : "";
        at += at < end ? strlen(at) + 1 : 0;
    }
    hid_t mesh = H5Gopen2(file, "mesh", H5P_DEFAULT);
    int rc = -1;
    if (!names)
        snprintf(err, errlen, "out of memory listing the part and material names");
    else if (mesh < 0)
        result_fail(err, errlen, "cannot open /mesh to write the part names");
    else if (write_string_list(mesh, "part_names", names, parts) < 0 ||
             write_string_list(mesh, "material_names", names + parts,
                               (size_t)info->material_count) < 0)
        result_fail(err, errlen, "cannot write /mesh/part_names and /mesh/material_names");
    else
        rc = 0;
    if (mesh >= 0) H5Gclose(mesh);
    free(names);
    return rc;
}

int result_describe(hid_t file, const char *text, size_t length, const case_info *info,
                    char *err, size_t errlen)
{
    if (!text) return 0;
    if (write_case_attribute(file, text, length) < 0) {
        result_fail(err, errlen, "cannot write the case document as the root attribute \"case\"");
        return -1;
    }
    if (info && info->names_bytes > 0) return write_kept_names(file, info, err, errlen);
    json_t *root = json_loadb(text, length, 0, NULL);
    if (!root) {
        snprintf(err, errlen, "the case document stored with the result is not JSON");
        return -1;
    }
    int rc = write_names(file, root, err, errlen);
    json_decref(root);
    return rc;
}

/* The columns of /snapshots/principal_stress are descending with tension
 * positive, the engine's sign, so the first is the most tensile; a rock
 * mechanic counts compression positive and calls the most compressive
 * sigma1. Both readings are written on the dataset, so neither has to be
 * guessed: a sentence (`order`) and the rock-mechanics name of each column
 * (`rock_mechanics_names`, fixed-length strings for Octave's sake; 2D: the
 * in-plane major and minor stresses are sigma1 and sigma3, as in RS2). */
int result_describe_principal_stress(hid_t dataset, int dimension)
{
    static const char order[] =
        "descending, tension positive: the first column is the most tensile (least "
        "compressive) principal stress, the last column the most compressive, which is sigma1 "
        "in rock mechanics' convention (compression positive); see rock_mechanics_names";
    static const char names2[] = "sigma3\0sigma1", names3[] = "sigma3\0sigma2\0sigma1";
    if (write_string_attribute(dataset, "order", order) < 0) return -1;
    hsize_t dims[1] = {(hsize_t)dimension};
    hid_t type = H5Tcopy(H5T_C_S1);
    hid_t space = H5Screate_simple(1, dims, NULL);
    hid_t attr = H5I_INVALID_HID;
    int rc = -1;
    if (type >= 0 && space >= 0 && H5Tset_size(type, 7) >= 0 &&
        H5Tset_strpad(type, H5T_STR_NULLPAD) >= 0)
        attr = H5Acreate2(dataset, "rock_mechanics_names", type, space, H5P_DEFAULT, H5P_DEFAULT);
    if (attr >= 0 && H5Awrite(attr, type, dimension == 3 ? names3 : names2) >= 0) rc = 0;
    if (attr >= 0) H5Aclose(attr);
    if (space >= 0) H5Sclose(space);
    if (type >= 0) H5Tclose(type);
    return rc;
}

int result_replace_document(const char *path, const char *text, size_t length, char *err,
                            size_t errlen)
{
    h5_quiet();
    /* The attribute and the heap blocks around it: twice the text. */
    if (result_reserve_room(path, (off_t)(2 * length + 65536), "store the new case document", err,
                            errlen) != 0)
        return -1;
    hid_t fapl = file_access_latest(1);
    hid_t file = fapl >= 0 ? H5Fopen(path, H5F_ACC_RDWR, fapl) : H5I_INVALID_HID;
    if (fapl >= 0) H5Pclose(fapl);
    if (file < 0) {
        result_fail(err, errlen, "cannot open %s to store the new case document", path);
        return -1;
    }
    int rc = -1;
    if (!has_result_format(file))
        snprintf(err, errlen, "%s is not an fdem result file", path);
    else if (H5Aexists(file, "case") > 0 && H5Adelete(file, "case") < 0)
        result_fail(err, errlen, "cannot remove the old root attribute \"case\" of %s", path);
    else if (write_case_attribute(file, text, length) < 0)
        result_fail(err, errlen, "cannot write the root attribute \"case\" of %s", path);
    else
        rc = 0;
    if (H5Fclose(file) < 0 && rc == 0) {
        result_fail(err, errlen, "closing %s after storing the case document failed", path);
        rc = -1;
    }
    return rc;
}
