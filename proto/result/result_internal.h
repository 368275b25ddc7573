/*
 * result_internal.h - what result_h5.c (writing) and result_reopen.c
 * (reading back a file an earlier run left) share: the layout of the
 * /snapshots datasets and the handle. Not part of any public contract;
 * result.h is the interface. Every function here runs on the I/O thread.
 */
#ifndef FDEM_RESULT_INTERNAL_H
#define FDEM_RESULT_INTERNAL_H

#include <hdf5.h>
#include <sys/types.h>

#include "result.h"

#define RESULT_FORMAT "fdem-result/1"

/* The /snapshots datasets in append order: time must stay last. */
enum series_kind {
    SERIES_STEP,
    SERIES_POSITION,
    SERIES_VELOCITY,
    SERIES_STRESS,
    SERIES_DAMAGE,
    SERIES_FRAGMENT,
    SERIES_STRAIN,
    SERIES_PRINCIPAL_STRESS,
    SERIES_DISPLACEMENT,
    SERIES_STAGE,
    SERIES_ACTIVE,
    SERIES_EXCAVATED,
    SERIES_CONSTRAINT_FORCE,
    SERIES_KINETIC,
    SERIES_ELASTIC,
    SERIES_CONTACT,
    SERIES_FRICTION,
    SERIES_JOINT,
    SERIES_FRACTURE,
    SERIES_DAMPING,
    SERIES_GRAVITY_WORK,
    SERIES_EXTERNAL_WORK,
    SERIES_FLUID_PRESSURE, /* contract 6.4: (S, J), only with fluid */
    SERIES_APERTURE,
    SERIES_TIME,
    SERIES_COUNT
};

extern const char *const series_names[SERIES_COUNT]; /* dataset names under /snapshots */

typedef struct series {
    hid_t id;       /* H5I_INVALID_HID when the model does not have it */
    int rank;       /* including the snapshot axis */
    hsize_t row[2]; /* per-snapshot extent after the snapshot axis */
} series;

/* The /events datasets in append order: time, the commit marker, last
 * (result_events.c). */
enum event_series_kind { EVENT_JOINT, EVENT_POSITION, EVENT_MODE, EVENT_ENERGY, EVENT_TIME,
                         EVENT_SERIES };
extern const char *const event_series_names[EVENT_SERIES];

/* The /history datasets in append order: time, the commit marker, last
 * (result_history.c); the energy terms in history_energy_names order; the
 * fluid's series (from HIST_FLUID_PRESSURE to time) only with fluid. */
enum history_series_kind { HIST_STEP, HIST_POINT_DISPLACEMENT, HIST_POINT_VELOCITY,
                           HIST_CONSTRAINT_FORCE, HIST_CONSTRAINT_DISPLACEMENT, HIST_ENERGY,
                           HIST_FLUID_PRESSURE = HIST_ENERGY + HISTORY_ENERGY_TERMS,
                           HIST_FLUID_INJECTED, HIST_FLUID_ENERGY,
                           HIST_TIME = HIST_FLUID_ENERGY + HISTORY_FLUID_ENERGY_TERMS,
                           HISTORY_SERIES };
extern const char *const history_series_names[HISTORY_SERIES];

struct result_file {
    hid_t file;
    series ds[SERIES_COUNT];
    hid_t events[EVENT_SERIES];
    hsize_t event_count;  /* complete events (= len(/events/time)) */
    int event_dimension;
    int count;     /* complete snapshots (= len(/snapshots/time)) */
    double *times; /* the time of each of them, for the XDMF sidecar */
    int times_capacity;
    int views;     /* snapshots with /xdmf views (result_views.c) */
    hid_t history[HISTORY_SERIES];
    hsize_t history_count; /* complete rows (= len(/history/time)) */
    int history_dimension, history_points, history_constraints;
    int history_fluid;    /* the fluid's series are in the file */
    double history_last_time; /* of the last committed row, -inf before any */
};

/* "what: innermost HDF5 message" into err; clears the HDF5 error stack. */
void result_fail(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Keeps HDF5 from printing its error stack (per thread). */
void h5_quiet(void);
/* The variable-length UTF-8 string type (h5py reads a str), and a scalar
 * attribute of it. */
hid_t utf8_string_type(void);
int write_string_attribute(hid_t obj, const char *name, const char *value);
/* 1 when the file's root says format = RESULT_FORMAT. */
int has_result_format(hid_t file);
/* Opens a result file read-only from another process than its writer:
 * with SWMR reading (a file a rank process is still writing opens), else
 * plainly (a file of an HDF5 without SWMR's format). H5I_INVALID_HID when
 * neither opens. */
hid_t result_open_read(const char *path);
hid_t series_mem_type(int kind);
hid_t series_file_type(int kind);
/* Which /snapshots datasets this model has, and their per-snapshot shape. */
void series_layout(series ds[SERIES_COUNT], const fdem_model *model, unsigned fields);
/* File access with the latest format (SWMR); optionally clearing the
 * status flags a crashed writer left. */
hid_t file_access_latest(int clear_status_flags);
int result_reserve_room(const char *path, off_t bytes, const char *what, char *err,
                        size_t errlen);
result_file *result_alloc(void);
/* Closes every HDF5 handle of f and marks it closed; -1 if HDF5 reported
 * a failure. result_release also frees f. */
int result_close_handles(result_file *f);
int result_release(result_file *f);
/* The root attribute `case` (the document) and /mesh/part_names,
 * /mesh/material_names, the names from info when the builder kept them
 * there (else read from the document); nothing when text is NULL
 * (result_describe.c). */
int result_describe(hid_t file, const char *text, size_t length, const case_info *info,
                    char *err, size_t errlen);
/* The attributes `order` and `rock_mechanics_names` of the principal
 * stress dataset (result_describe.c); 0 or -1. */
int result_describe_principal_stress(hid_t dataset, int dimension);
int start_swmr(result_file *f, const char *path, char *err, size_t errlen);

/* The /events group, empty, in a new file; in a reopened one, its events
 * trimmed to those whose joints `model` has broken (result_events.c). Both
 * before SWMR writing starts. */
int events_create(result_file *f, int dimension, char *err, size_t errlen);
int events_reopen(result_file *f, const fdem_model *model, char *err, size_t errlen);

/* The /history group, empty, in a new file; in a reopened one, its rows
 * trimmed to those at steps <= keep_until_step (a file written before
 * history gets it empty). Both before SWMR writing starts; and closing its
 * datasets (result_history.c). */
int history_create(result_file *f, const fdem_model *model, const case_info *info, char *err,
                   size_t errlen);
int history_reopen(result_file *f, const fdem_model *model, const case_info *info,
                   int64_t keep_until_step, char *err, size_t errlen);
int history_close_handles(result_file *f);

/* Creates /snapshots/<series_names[kind]> empty and extendible (result_h5.c). */
int series_create(hid_t group, int kind, series *s);

#endif
