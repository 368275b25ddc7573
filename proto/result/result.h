/*
 * result.h - result.h5 (contract section 4) and its result.xdmf sidecar.
 *
 * Contract:
 *  - Not thread-safe by design: the daemon calls every function here from
 *    its single I/O thread (the HDF5 high-level API is not thread-safe and a
 *    write must never stall an HTTP request).
 *  - result_create() writes the root attributes and /mesh, creates the
 *    chunked, extendible /snapshots datasets, and starts SWMR writing
 *    (libver bounds LATEST). result_append() extends every dataset by one
 *    and writes /snapshots/time last, then flushes: time is the commit
 *    marker, so a SWMR reader never sees a snapshot half written.
 *  - result_reopen() reopens a file left by a previous run (clearing the
 *    status flags a crash leaves, as `h5clear -s` does), drops snapshots
 *    whose step is after `keep_until_step` and fracture events of joints
 *    that are not broken in `model` (the model the run resumes from), and
 *    resumes SWMR writing.
 *  - /events (contract 5.4) follows the same commit discipline as
 *    /snapshots, with /events/time as its marker (result_events.c).
 *  - Downloads while running: result_flush() on the I/O thread, then, with
 *    no append in between, any thread may copy the bytes with
 *    result_image_copy_step() (no HDF5 call; it clears the superblock's
 *    "open for writing" flags in the copy, so it opens as a plain file).
 *  - result_check_file() opens a closed result file read-only and says
 *    whether it is whole (a truncated or replaced file is refused).
 *  - xdmf_write() rewrites the XDMF2 sidecar atomically (temp + rename):
 *    a temporal collection with one grid per snapshot, Triangle topology
 *    and XY geometry (3D: Tetrahedron, XYZ); each snapshot's fields are
 *    its /xdmf views once result_finish() made them (every ParaView XDMF
 *    reader opens that), HyperSlabs into /snapshots before (the legacy
 *    XDMF Reader only).
 *  - Both dimensions share one layout (contract 5.2); the root attribute
 *    `dimension` says which, and /mesh/triangles becomes /mesh/tetrahedra.
 *
 * Folder proto/result/, result.h5 and result.xdmf: owns this header, the
 * HDF5 files (result_h5.c writes; result_describe.c, result_events.c and
 * result_views.c add to them; result_reopen.c reads them back; all share
 * result_internal.h), the sidecar (result_xdmf.c) and the HDF5-free copy
 * for downloads (result_image.c). May call core/, proto/case/ (case_info)
 * and proto/state/ (the snapshots it writes). Called by server/ (the I/O
 * thread, downloads) and the unit tests.
 */
#ifndef FDEM_RESULT_H
#define FDEM_RESULT_H

#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>
#include "case/case.h"
#include "fdem.h"
#include "state/history.h"
#include "state/snapshot.h"

typedef struct result_file result_file;

result_file *result_create(const char *path, const fdem_model *model,
                           const case_info *info, char *err, size_t errlen);
/* result_create() that also stores the case document (the root attribute
 * `case`) and the part and material names it gives (/mesh/part_names,
 * /mesh/material_names), contract 5.4. */
result_file *result_create_described(const char *path, const fdem_model *model,
                                     const case_info *info, const char *document,
                                     size_t document_length, char *err, size_t errlen);
/* Replaces the root attribute `case` of a closed result file (POST
 * /cases/ID/extend rewrites the stored document); 0, or -1 with err. */
int result_replace_document(const char *path, const char *text, size_t length, char *err,
                            size_t errlen);
result_file *result_reopen(const char *path, const fdem_model *model,
                           const case_info *info, int64_t keep_until_step,
                           char *err, size_t errlen);
int result_append(result_file *f, const snapshot *s, char *err, size_t errlen);
/* Appends fracture events to /events (result_events.c); the daemon appends
 * a step's events before the snapshot after them. */
int result_append_events(result_file *f, const fdem_event *events, int count, char *err,
                         size_t errlen);
/* The events with time > since of an open result file (f), or of the closed
 * file at path (f NULL; a file written before events has none): *out
 * (free() it) gets *count of them, *dimension the position width (0 for a
 * file without /events). */
int result_read_events(result_file *f, const char *path, double since, fdem_event **out,
                       int *count, int *dimension, char *err, size_t errlen);
/* Appends history rows to /history (result_history.c, contract 6.2); rows
 * at or before the last row's time (a replay) are skipped. */
int result_append_history(result_file *f, history_row *const *rows, int count, char *err,
                          size_t errlen);
/* The history rows with time > since of an open result file (f) or of the
 * closed file at path (f NULL; a file written before history has none):
 * *out gets *count rows; free them with result_free_history(); `names`
 * the point names of /history/points (count 0 without). */
int result_read_history(result_file *f, const char *path, double since, history_row ***out,
                        int *count, history_names *names, char *err, size_t errlen);
void result_free_history(history_row **rows, int count);
/* One snapshot as the web page's binary frame (result_frame.c; the layout
 * is in docs/api.md, "Binary mesh frames"): the mesh, or only its visible
 * facets, the deformed positions and the fields asked for, float32. */
#define RESULT_FRAME_FIELDS 10
/* velocity, displacement, stress, strain, principal_stress, damage,
 * fragment, active, fluid_pressure, aperture: bit k of
 * result_frame_request.fields */
extern const char *const result_frame_field_names[RESULT_FRAME_FIELDS];
/* One case's mesh tables kept between its frames (the mesh of a case never
 * changes): its cells, joints and which facets face which; owned by the
 * caller, used by one thread (the I/O thread), holding one mesh at a time. */
typedef struct result_frame_cache result_frame_cache;
result_frame_cache *result_frame_cache_new(void);
void result_frame_cache_free(result_frame_cache *cache);
void result_frame_cache_clear(result_frame_cache *cache);
size_t result_frame_cache_bytes(const result_frame_cache *cache);
typedef struct result_frame_request {
    int snapshot;      /* index, or -1 for the last complete one */
    unsigned fields;   /* bit k: result_frame_field_names[k]; those the file lacks are left out */
    /* called with the bytes building the frame may hold, before any is allocated;
     * non-zero refuses (503) */
    int (*reserve)(void *ctx, size_t bytes);
    void *reserve_ctx;
    int surface;       /* 1: only the facets that can be seen (the surface form) */
    int has_shape_key; /* 1: the client holds the shape of key shape_key */
    uint64_t shape_key; /* the shape sections are left out when the frame's key equals it */
    result_frame_cache *cache; /* NULL, or the tables to use and keep when owner's */
    const char *cache_owner;   /* who the mesh is (the case id) */
} result_frame_request;
/* Reads the frame from the open file f, or the closed file at path (f
 * NULL): *out (free() it) gets *size bytes. Returns 0; 404 (no such
 * snapshot) or 503 (refused by reserve, out of memory) with err; -1 with
 * err when the file cannot be read. */
int result_read_frame(result_file *f, const char *path, const result_frame_request *q,
                      unsigned char **out, size_t *size, char *err, size_t errlen);
int result_flush(result_file *f, char *err, size_t errlen);
int result_check_file(const char *path, char *err, size_t errlen);
/* Copies the next piece of bytes [done, size) of src to the same place in
 * dst; returns the bytes copied (0 when done == size) or -1 with errno. */
ssize_t result_image_copy_step(int src, int dst, size_t done, size_t size);
/* Clears the open-for-writing flags of the superblock in `head` (the first
 * bytes of a copy) and fixes its checksum; -1 if it is not a v2/v3 one. */
int result_image_mark_closed(unsigned char *head, size_t len);
int result_snapshot_count(const result_file *f);
/* Simulated time of complete snapshot `index` (NAN when out of range). */
double result_snapshot_time(const result_file *f, int index);
int result_close(result_file *f);
/* Ends SWMR writing and adds the /xdmf views (result_views.c) of every
 * snapshot; `f` stays valid for xdmf_write() and must still be closed with
 * result_close(). -1 with err on failure (the file keeps what it had). */
int result_finish(result_file *f, const char *path, int dimension, char *err, size_t errlen);
/* Snapshots that have /xdmf views; the sidecar names them directly. */
int result_view_count(const result_file *f);

/* h5_name is the .h5 file name as the .xdmf refers to it (same folder). */
int xdmf_write(const char *xdmf_path, const char *h5_name, const fdem_model *model,
               const case_info *info, const result_file *f, char *err, size_t errlen);

#endif
