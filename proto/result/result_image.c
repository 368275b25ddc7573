/*
 * result_image.c - a byte copy of result.h5 that opens as a plain, closed
 * HDF5 file, taken without the HDF5 library.
 *
 * Why without HDF5: a download of a running case must not occupy the one
 * I/O thread (the only thread allowed to call HDF5) for the length of a
 * copy. The I/O thread only flushes the file and holds that case's writes;
 * any thread then copies the bytes with this file's functions.
 *
 * A flushed SWMR file is complete on disk except for one thing: its
 * superblock (version 2 or 3, at offset 0 since we write no user block)
 * still carries the "open for writing / SWMR writing" flags, which make a
 * plain reader refuse it. We clear the flags byte in the copy and recompute
 * the superblock checksum (Bob Jenkins' lookup3, as H5_checksum_metadata),
 * which is what `h5clear -s` achieves through the library.
 */
#define _GNU_SOURCE /* copy_file_range */
#include "result.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

#define SUPERBLOCK_FLAGS_AT 11
#define SUPERBLOCK_HEAD 12 /* signature, version, offset/length sizes, flags */
#define IMAGE_CHUNK ((size_t)4 << 20)

static uint32_t rotl32(uint32_t x, int k)
{
    return (x << k) | (x >> (32 - k));
}

/* lookup3 hashlittle() with initval 0, byte by byte (endian-neutral). */
static uint32_t lookup3(const uint8_t *k, size_t length)
{
    uint32_t a, b, c;
    a = b = c = 0xdeadbeefu + (uint32_t)length;
    while (length > 12) {
        a += k[0] + ((uint32_t)k[1] << 8) + ((uint32_t)k[2] << 16) + ((uint32_t)k[3] << 24);
        b += k[4] + ((uint32_t)k[5] << 8) + ((uint32_t)k[6] << 16) + ((uint32_t)k[7] << 24);
        c += k[8] + ((uint32_t)k[9] << 8) + ((uint32_t)k[10] << 16) + ((uint32_t)k[11] << 24);
        a -= c; a ^= rotl32(c, 4);  c += b;
        b -= a; b ^= rotl32(a, 6);  a += c;
        c -= b; c ^= rotl32(b, 8);  b += a;
        a -= c; a ^= rotl32(c, 16); c += b;
        b -= a; b ^= rotl32(a, 19); a += c;
        c -= b; c ^= rotl32(b, 4);  b += a;
        length -= 12;
        k += 12;
    }
    if (length == 0) return c;
    uint32_t w[3] = {0, 0, 0};
    for (size_t i = 0; i < length; i++) w[i / 4] += (uint32_t)k[i] << (8 * (i % 4));
    a += w[0];
    b += w[1];
    c += w[2];
    c ^= b; c -= rotl32(b, 14);
    a ^= c; a -= rotl32(c, 11);
    b ^= a; b -= rotl32(a, 25);
    c ^= b; c -= rotl32(b, 16);
    a ^= c; a -= rotl32(c, 4);
    b ^= a; b -= rotl32(a, 14);
    c ^= b; c -= rotl32(b, 24);
    return c;
}

int result_image_mark_closed(unsigned char *head, size_t len)
{
    static const unsigned char signature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    if (len < SUPERBLOCK_HEAD || memcmp(head, signature, 8) != 0) return -1;
    if (head[8] != 2 && head[8] != 3) return -1;
    size_t offsets = head[9];
    if (offsets != 2 && offsets != 4 && offsets != 8) return -1;
    size_t body = SUPERBLOCK_HEAD + 4 * offsets; /* base, extension, EOF, root addresses */
    if (len < body + 4) return -1;
    head[SUPERBLOCK_FLAGS_AT] = 0;
    uint32_t sum = lookup3(head, body);
    for (int i = 0; i < 4; i++) head[body + (size_t)i] = (unsigned char)(sum >> (8 * i));
    return 0;
}

static int image_copy_plain(int src, int dst, off_t at, size_t len)
{
    char buffer[1 << 16];
    while (len > 0) {
        size_t want = len < sizeof buffer ? len : sizeof buffer;
        ssize_t n = pread(src, buffer, want, at);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (n == 0) errno = EIO; /* the source is shorter than it was */
            return -1;
        }
        for (ssize_t done = 0; done < n;) {
            ssize_t w = pwrite(dst, buffer + done, (size_t)(n - done), at + done);
            if (w < 0 && errno == EINTR) continue;
            if (w < 0) return -1;
            done += w;
        }
        at += n;
        len -= (size_t)n;
    }
    return 0;
}

/* The first bytes, with the superblock flags cleared. */
static int image_copy_head(int src, int dst, size_t len)
{
    unsigned char head[256];
    if (len > sizeof head) len = sizeof head;
    size_t got = 0;
    while (got < len) {
        ssize_t n = pread(src, head + got, len - got, (off_t)got);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (n == 0) errno = EIO;
            return -1;
        }
        got += (size_t)n;
    }
    if (result_image_mark_closed(head, len) != 0) {
        errno = EINVAL; /* not a superblock we know: refuse rather than serve a file that will not open */
        return -1;
    }
    for (size_t done = 0; done < len;) {
        ssize_t w = pwrite(dst, head + done, len - done, (off_t)done);
        if (w < 0 && errno == EINTR) continue;
        if (w < 0) return -1;
        done += (size_t)w;
    }
    return (int)len;
}

ssize_t result_image_copy_step(int src, int dst, size_t done, size_t size)
{
    if (done >= size) return 0;
    if (done == 0) {
        int n = image_copy_head(src, dst, size);
        return n < 0 ? -1 : n;
    }
    size_t len = size - done < IMAGE_CHUNK ? size - done : IMAGE_CHUNK;
    off_t in = (off_t)done, out = (off_t)done;
    ssize_t n = copy_file_range(src, &in, dst, &out, len, 0);
    if (n > 0) return n;
    if (n == 0) {
        errno = EIO;
        return -1;
    }
    if (errno != EXDEV && errno != ENOSYS && errno != EINVAL && errno != EOPNOTSUPP) return -1;
    return image_copy_plain(src, dst, (off_t)done, len) == 0 ? (ssize_t)len : -1;
}
