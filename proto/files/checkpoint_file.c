/*
 * checkpoint_file.c - seals checkpoint.bin with a CRC-32 and checks it when
 * a case is rebuilt.
 *
 * Why: the engine's reader refuses a checkpoint of the wrong size or with
 * counts or values that cannot be, but a byte changed inside a position or
 * a velocity (a bad sector, a copy gone wrong, a hand edit) is a valid
 * number, and the case would carry on from a state it never had, silently.
 * The checksum catches that before anything is restored; the case then
 * fails with the sums in its error and its files are left as they are, so
 * putting the good file back brings it back.
 *
 * Why here and not in core/: the sum is about the file, not the state (the
 * engine's buffer also travels in memory to the I/O thread), and zlib's
 * crc32 is a well-kept implementation the server may link; core links
 * nothing beyond libm and OpenMP.
 */
#include "checkpoint_file.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

static const unsigned char checkpoint_file_magic[4] = {'F', 'D', 'C', 'K'};

/* zlib's crc32 takes at most UINT_MAX bytes a call. */
static uint32_t checkpoint_file_crc(const unsigned char *p, size_t size)
{
    uLong crc = crc32(0L, Z_NULL, 0);
    while (size > 0) {
        uInt chunk = size > 0x40000000u ? 0x40000000u : (uInt)size;
        crc = crc32(crc, p, chunk);
        p += chunk;
        size -= chunk;
    }
    return (uint32_t)crc;
}

static void checkpoint_file_put32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}

static uint32_t checkpoint_file_get32(const unsigned char *p)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++) v |= (uint32_t)p[i] << (8 * i);
    return v;
}

void *checkpoint_file_take(const fdem_model *m, size_t *size)
{
    size_t payload = fdem_checkpoint_size(m);
    unsigned char *buf = malloc(payload + CHECKPOINT_FILE_TRAILER);
    if (!buf) return NULL;
    if (fdem_checkpoint_write(m, buf, payload) != 0) {
        free(buf);
        return NULL;
    }
    memcpy(buf + payload, checkpoint_file_magic, sizeof checkpoint_file_magic);
    checkpoint_file_put32(buf + payload + 4, checkpoint_file_crc(buf, payload));
    *size = payload + CHECKPOINT_FILE_TRAILER;
    return buf;
}

checkpoint_file_kind checkpoint_file_open(const void *bytes, size_t size, size_t *payload,
                                          char *err, size_t errlen)
{
    const unsigned char *p = bytes;
    *payload = size;
    if (size < CHECKPOINT_FILE_TRAILER ||
        memcmp(p + size - CHECKPOINT_FILE_TRAILER, checkpoint_file_magic,
               sizeof checkpoint_file_magic) != 0) {
        /* Every daemon that writes the engine's version 6 or later seals
         * it: such a file without its trailer had its end damaged or cut
         * off, and is not restored unchecked (or refused only for its
         * size, an error that invites cutting the trailer off). */
        int version = fdem_checkpoint_version(p, size);
        if (version < CHECKPOINT_FILE_SEALED_SINCE)
            return CHECKPOINT_FILE_BARE;
        snprintf(err, errlen,
                 "it is damaged: it is of checkpoint version %d, always written with a trailer "
                 "(FDCK and a CRC-32), but its last 8 bytes are not one (the end of the file "
                 "changed or was cut off after fdemd wrote it)",
                 version);
        return CHECKPOINT_FILE_DAMAGED;
    }
    size_t body = size - CHECKPOINT_FILE_TRAILER;
    uint32_t stored = checkpoint_file_get32(p + body + 4), actual = checkpoint_file_crc(p, body);
    if (stored != actual) {
        snprintf(err, errlen,
                 "it is damaged: its %zu bytes sum to CRC-32 %08x, but it was written with "
                 "%08x (the file changed on disk after fdemd wrote it)",
                 body, (unsigned)actual, (unsigned)stored);
        return CHECKPOINT_FILE_DAMAGED;
    }
    *payload = body;
    return CHECKPOINT_FILE_SEALED;
}
