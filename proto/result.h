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
 *    whose step is after `keep_until_step` and resumes SWMR writing.
 *  - result_copy() writes a consistent, closed copy of the file as it is
 *    after the last completed append (for downloads while running).
 *  - xdmf_write() rewrites the XDMF2 sidecar atomically (temp + rename):
 *    a temporal collection with one grid per snapshot, Triangle topology,
 *    XY geometry and attributes as HyperSlabs into the .h5 file.
 */
#ifndef FDEM_RESULT_H
#define FDEM_RESULT_H

#include <stddef.h>
#include "case.h"
#include "fdem.h"
#include "snapshot.h"

typedef struct result_file result_file;

result_file *result_create(const char *path, const fdem_model *model,
                           const case_info *info, char *err, size_t errlen);
result_file *result_reopen(const char *path, const fdem_model *model,
                           const case_info *info, int64_t keep_until_step,
                           char *err, size_t errlen);
int result_append(result_file *f, const snapshot *s, char *err, size_t errlen);
int result_copy(result_file *f, const char *dst_path, char *err, size_t errlen);
int result_snapshot_count(const result_file *f);
/* Simulated time of complete snapshot `index` (NAN when out of range). */
double result_snapshot_time(const result_file *f, int index);
int result_close(result_file *f);

/* h5_name is the .h5 file name as the .xdmf refers to it (same folder). */
int xdmf_write(const char *xdmf_path, const char *h5_name, const fdem_model *model,
               const case_info *info, const result_file *f, char *err, size_t errlen);

#endif
