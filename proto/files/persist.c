/*
 * persist.c - atomic, fsynced file writes for the data directory.
 *
 * Every file the daemon keeps (case.json, status.json, checkpoint.bin) goes
 * through persist_write_atomic so that a crash at any instant leaves a file
 * that is either the previous version or the new one. The directory is
 * fsynced after the rename because on Linux the rename itself is only
 * durable once its directory is.
 */
#include "persist.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int persist_write_all(int fd, const void *data, size_t size)
{
    const char *p = data;
    while (size > 0) {
        ssize_t n = write(fd, p, size);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return -1;
        }
        p += n;
        size -= (size_t)n;
    }
    return 0;
}

static int persist_fsync_opened(const char *path, int flags)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC | flags);
    if (fd < 0)
        return -1;
    int rc = fsync(fd);
    int saved = errno;
    close(fd);
    errno = saved;
    return rc;
}

int persist_fsync_dir(const char *dir)
{
    return persist_fsync_opened(dir, O_DIRECTORY);
}

int persist_write_atomic(const char *dir, const char *name, const void *data, size_t size)
{
    char tmp[4096], dst[4096];
    if (snprintf(tmp, sizeof tmp, "%s/.%s.tmp", dir, name) >= (int)sizeof tmp ||
        snprintf(dst, sizeof dst, "%s/%s", dir, name) >= (int)sizeof dst) {
        errno = ENAMETOOLONG;
        return -1;
    }
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
        return -1;
    if (persist_write_all(fd, data, size) != 0 || fsync(fd) != 0) {
        int saved = errno;
        close(fd);
        unlink(tmp);
        errno = saved;
        return -1;
    }
    if (close(fd) != 0 || rename(tmp, dst) != 0) {
        int saved = errno;
        unlink(tmp);
        errno = saved;
        return -1;
    }
    return persist_fsync_dir(dir);
}

int persist_read_file(const char *path, char **data, size_t *size, size_t max_size)
{
    *data = NULL;
    *size = 0;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return -1;
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || (size_t)st.st_size > max_size) {
        close(fd);
        errno = EFBIG;
        return -1;
    }
    size_t want = (size_t)st.st_size;
    char *buf = malloc(want + 1);
    if (!buf) {
        close(fd);
        return -1;
    }
    size_t got = 0;
    while (got < want) {
        ssize_t n = read(fd, buf + got, want - got);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        got += (size_t)n;
    }
    close(fd);
    if (got != want) {
        free(buf);
        errno = EIO;
        return -1;
    }
    buf[got] = '\0';
    *data = buf;
    *size = got;
    return 0;
}

int persist_mkdir(const char *path)
{
    if (mkdir(path, 0755) != 0 && errno != EEXIST)
        return -1;
    return 0;
}

int persist_remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return errno == ENOENT ? 0 : -1;
    struct dirent *e;
    char path[4096];
    int first_errno = 0;
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) < (int)sizeof path &&
            unlink(path) != 0 && errno != ENOENT && !first_errno)
            first_errno = errno;
    }
    closedir(d);
    if (rmdir(dir) == 0 || errno == ENOENT)
        return 0;
    if (first_errno)
        errno = first_errno;
    return -1;
}

int persist_fsync_path(const char *path)
{
    return persist_fsync_opened(path, 0);
}

#define PERSIST_RESERVE_BYTES (64 * 1024)

static int persist_reserve_path(const char *dir, char *path, size_t size)
{
    if (snprintf(path, size, "%s/.reserve", dir) >= (int)size) {
        errno = ENAMETOOLONG;
        return -1;
    }
    return 0;
}

int persist_reserve(const char *dir)
{
    char path[4096];
    struct stat st;
    if (persist_reserve_path(dir, path, sizeof path) != 0)
        return -1;
    if (stat(path, &st) == 0 && st.st_size >= PERSIST_RESERVE_BYTES)
        return 0;
    /* Real bytes, not a hole: a sparse file would free nothing. */
    static const char zeros[PERSIST_RESERVE_BYTES];
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
        return -1;
    int rc = persist_write_all(fd, zeros, sizeof zeros);
    int saved = errno;
    close(fd);
    if (rc != 0)
        unlink(path);
    errno = saved;
    return rc;
}

int persist_release_reserve(const char *dir)
{
    char path[4096];
    if (persist_reserve_path(dir, path, sizeof path) != 0)
        return -1;
    return unlink(path);
}

int persist_check_writable(const char *dir)
{
    char path[4096];
    if (snprintf(path, sizeof path, "%s/.probe-%ld", dir, (long)getpid()) >= (int)sizeof path) {
        errno = ENAMETOOLONG;
        return -1;
    }
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0)
        return -1;
    int rc = persist_write_all(fd, "probe\n", 6) != 0 || fsync(fd) != 0 ? -1 : 0;
    int saved = errno;
    close(fd);
    if (unlink(path) != 0 && rc == 0) {
        saved = errno;
        rc = -1;
    }
    errno = saved;
    return rc;
}
