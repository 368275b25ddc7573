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
/* Removes a case directory: its plain files, then the directory itself. */
int persist_remove_dir(const char *dir);

#endif
