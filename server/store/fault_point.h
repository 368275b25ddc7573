/*
 * server/store/ - what the daemon alone does to its data directory's
 *    files: the named crash points tests place between durable writes
 *    (fault_point.c). The writes themselves are proto/files/ (shared with
 *    the batch runner).
 *  - May call: the C library. Called by: cases/.
 */
/*
 * fault_point.h - named places where a test makes the daemon die as a
 * crash would, to check what a restart makes of the files left between
 * two writes that belong together (e.g. the steps of an extend).
 *
 * Contract: fault_point(name) does nothing unless the environment variable
 * FDEMD_FAULT_POINT equals `name`; then the process sends itself SIGKILL
 * there (no handler, no flush: exactly what a crash leaves). Only the
 * integration tests set it.
 */
#ifndef FDEMD_FAULT_POINT_H
#define FDEMD_FAULT_POINT_H

void fault_point(const char *name);

#endif
