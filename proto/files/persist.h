/*
 * proto/files/ - a case directory's plain files, written the same way by
 *    the daemon (server/) and by the batch runner (runner/, bin/fdem-run),
 *    so that both leave the same bytes.
 *  - Owns: atomic, fsynced writes, reads and removals (this header,
 *    persist.c); checkpoint.bin sealed with a CRC-32 (checkpoint_file.c).
 *  - May call: core/ (the checkpoint's types), zlib and the C library; no
 *    other proto folder.
 *  - Called by: server/ and runner/.
 */
/*
 * persist.h - durable files in the data directory.
 *
 * Contract: persist_write_atomic() leaves either the old or the new content
 * under `name`, never a mix, and returns only after the new content and the
 * directory entry are on disk (temp + fsync + rename + fsync dir). This is
 * what "nothing acknowledged is lost" rests on. persist_read_file() reads a
 * whole file into a NUL-terminated malloc'd buffer. All return 0 / -1 with
 * errno set.
 */
#ifndef FDEMD_PERSIST_H
#define FDEMD_PERSIST_H

#include <stddef.h>

int persist_write_atomic(const char *dir, const char *name, const void *data, size_t size);
int persist_read_file(const char *path, char **data, size_t *size, size_t max_size);
int persist_mkdir(const char *path);
int persist_fsync_dir(const char *dir);
/* Removes a case directory: its plain files, then the directory itself;
 * -1 with errno of the first file or the directory that would not go. */
int persist_remove_dir(const char *dir);
int persist_fsync_path(const char *path);

/* A few pages kept in DIR/.reserve so that on a full disk the file that
 * records a failure (status.json) can still be written: release it, then
 * retry. persist_reserve is best effort. */
int persist_reserve(const char *dir);
int persist_release_reserve(const char *dir);

/* Creates, syncs and removes a probe file: 0 when `dir` takes writes. */
int persist_check_writable(const char *dir);

#endif
