/*
 * heap_count.h - the bytes the allocator holds for the program (glibc's
 * mallinfo2: small blocks in use and mmapped ones), for the tests that hold
 * a library's own count of its memory against the heap.
 *
 * The sanitizers' allocator keeps its own books, where mallinfo2 does not
 * see the blocks: HEAP_COUNTED is 0 in the sanitizer build (FDEM_SAN), and
 * the callers leave those checks to its leak report.
 */
#ifndef FDEM_TEST_HEAP_COUNT_H
#define FDEM_TEST_HEAP_COUNT_H

#include <malloc.h>

#ifdef FDEM_SAN
#define HEAP_COUNTED 0
#else
#define HEAP_COUNTED 1
#endif

static inline double heap_in_use(void)
{
    struct mallinfo2 m = mallinfo2();
    return (double)m.uordblks + (double)m.hblkhd;
}

#endif
