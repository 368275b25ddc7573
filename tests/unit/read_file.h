/*
 * read_file.h - a whole test data file in memory, for the tests that feed
 * files of tests/data to a reader (gmsh text, case documents).
 */
#ifndef FDEM_READ_FILE_H
#define FDEM_READ_FILE_H

#include <stdio.h>
#include <stdlib.h>

#include "check.h"

/* The file's bytes in a buffer of exactly their length (no NUL: ASan then
 * catches a reader that goes past `length`); free it. NULL and a failed
 * check when the file is missing (the tests run from the repository root). */
static inline char *read_file(const char *path, size_t *length)
{
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL, "cannot open %s (run from the repository root)", path);
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc(n > 0 ? (size_t)n : 1);
    *length = text ? fread(text, 1, (size_t)n, f) : 0;
    fclose(f);
    return text;
}

/* The same as a NUL-terminated string (case documents for the JSON
 * parser); NULL without a check when the file is missing. */
static inline char *read_text(const char *path, size_t *length)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (text && fread(text, 1, (size_t)n, f) != (size_t)n) {
        free(text);
        text = NULL;
    }
    fclose(f);
    if (text) text[n] = 0;
    *length = (size_t)n;
    return text;
}

#endif
