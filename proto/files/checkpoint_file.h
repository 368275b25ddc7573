/*
 * checkpoint_file.h - checkpoint.bin on disk: the engine's checkpoint bytes
 * (core/checkpoint/checkpoint.c) followed by an 8-byte trailer, the magic "FDCK" and
 * the CRC-32 (zlib's, little-endian) of the bytes before it.
 *
 * Contract:
 *  - checkpoint_file_take() returns a malloc'd, sealed buffer of *size bytes
 *    holding model m's state, or NULL without memory.
 *  - checkpoint_file_open() checks a file's bytes: CHECKPOINT_FILE_SEALED
 *    (the checksum holds; *payload is the engine's part), CHECKPOINT_FILE_BARE
 *    (no trailer: a file of a daemon from before the checksum, all of it
 *    the engine's) or CHECKPOINT_FILE_DAMAGED, with a message in err naming
 *    the sums. A bare file is still checked by the engine's own reader
 *    (sizes, counts, finite values). Bare means of an engine version
 *    before CHECKPOINT_FILE_SEALED_SINCE: a later one without a trailer
 *    (its end damaged or cut off) is DAMAGED.
 */
#ifndef FDEMD_CHECKPOINT_FILE_H
#define FDEMD_CHECKPOINT_FILE_H

#include <stddef.h>

#include "fdem.h"

/* The checkpoints of a case directory: the latest state; the state before
 * the step cut to land on time.end; and, after a daemon's extend of a
 * finished case, that state renamed, which the next run resumes from (the
 * daemon's server/cases/case_model.h, the runner's runner/run_case.c). */
#define CHECKPOINT_FILE_LATEST "checkpoint.bin"
#define CHECKPOINT_FILE_END "checkpoint-end.bin"
#define CHECKPOINT_FILE_RESUME "checkpoint-resume.bin"

#define CHECKPOINT_FILE_TRAILER 8
/* The engine's checkpoint version (fdem_checkpoint_version) the first sealing
 * daemon wrote: no daemon ever wrote it bare. */
#define CHECKPOINT_FILE_SEALED_SINCE 6

typedef enum {
    CHECKPOINT_FILE_SEALED,
    CHECKPOINT_FILE_BARE,
    CHECKPOINT_FILE_DAMAGED
} checkpoint_file_kind;

void *checkpoint_file_take(const fdem_model *m, size_t *size);
checkpoint_file_kind checkpoint_file_open(const void *bytes, size_t size, size_t *payload,
                                          char *err, size_t errlen);

#endif /* FDEMD_CHECKPOINT_FILE_H */
