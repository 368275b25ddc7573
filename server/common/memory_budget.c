/*
 * memory_budget.c - one counter of reserved bytes against --max-memory, the
 * jansson allocation meter, and handing freed memory back to the OS.
 *
 * Why a meter: a JSON tree costs from 9 (a mesh of long floats) to ~80
 * ("[{},{},...]") times its text, so no fixed factor both admits ordinary
 * uploads and bounds hostile ones. An upload is admitted at a typical
 * factor; the meter then charges what jansson really allocates and makes the
 * parse fail cleanly (jansson reports out of memory) the moment the budget
 * cannot cover it.
 *
 * Why malloc_trim: a parsed tree is millions of small chunks; after it is
 * freed glibc keeps the pages (RSS stayed at 8.6 GB after four refused
 * 64 MiB uploads). Trimming after each large release returns them; large
 * blocks are mapped on their own (membudget_init) so that freeing one
 * returns it whatever lies above it in the heap.
 */
#include "memory_budget.h"

#include <jansson.h>
#include <malloc.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#define MEMBUDGET_UPLOAD_FACTOR 12 /* body and meshes read (2) + tree of a typical mesh (10) */
#define MEMBUDGET_METER_STEP ((size_t)1 << 20) /* grow the lease by at least this */
#define MEMBUDGET_TRIM_AT ((size_t)4 << 20)    /* releases worth trimming the heap for */
#define MEMBUDGET_CHUNK_OVERHEAD 8      /* glibc's size field per chunk */
#define MEMBUDGET_MMAP_AT (1 << 20)     /* blocks mapped on their own from this size */

static pthread_mutex_t budget_lock = PTHREAD_MUTEX_INITIALIZER;
static size_t budget_limit = (size_t)-1, budget_used;

typedef struct membudget_meter {
    membudget_lease *lease;
    size_t allowance, charged;
    int refused;
} membudget_meter;

static _Thread_local membudget_meter *tl_meter;
static _Thread_local membudget_meter tl_meter_storage;
static _Thread_local membudget_lease *tl_request_lease;

size_t membudget_default_limit(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0)
        return (size_t)4 << 30;
    return (size_t)pages / 2 * (size_t)page;
}

size_t membudget_limit(void)
{
    return budget_limit;
}

size_t membudget_used(void)
{
    pthread_mutex_lock(&budget_lock);
    size_t used = budget_used;
    pthread_mutex_unlock(&budget_lock);
    return used;
}

int membudget_grow(membudget_lease *lease, size_t bytes)
{
    int ok;
    pthread_mutex_lock(&budget_lock);
    ok = bytes <= budget_limit && budget_used <= budget_limit - bytes;
    if (ok)
        budget_used += bytes;
    pthread_mutex_unlock(&budget_lock);
    if (!ok)
        return -1;
    lease->bytes += bytes;
    return 0;
}

void membudget_shrink(membudget_lease *lease, size_t bytes)
{
    if (bytes > lease->bytes)
        bytes = lease->bytes;
    if (bytes == 0)
        return;
    lease->bytes -= bytes;
    pthread_mutex_lock(&budget_lock);
    budget_used -= bytes < budget_used ? bytes : budget_used;
    pthread_mutex_unlock(&budget_lock);
    if (bytes >= MEMBUDGET_TRIM_AT)
        malloc_trim(0);
}

void membudget_release(membudget_lease *lease)
{
    membudget_shrink(lease, lease->bytes);
}

void membudget_give_back(void)
{
    malloc_trim(0);
}

void membudget_move(membudget_lease *from, membudget_lease *to, size_t bytes)
{
    if (bytes > from->bytes)
        bytes = from->bytes;
    from->bytes -= bytes;
    to->bytes += bytes;
}

size_t membudget_upload_cost(size_t body_bytes)
{
    return body_bytes > (size_t)-1 / MEMBUDGET_UPLOAD_FACTOR ? (size_t)-1
                                                             : body_bytes * MEMBUDGET_UPLOAD_FACTOR;
}

const char *membudget_describe(size_t bytes, char *buf, size_t size)
{
    static const char *const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
    double x = (double)bytes;
    int unit = 0;
    while (x >= 1024 && unit < 4) {
        x /= 1024;
        unit++;
    }
    snprintf(buf, size, unit ? "%.3g %s" : "%.0f %s", x, units[unit]);
    return buf;
}

/* ------------------------------------------------------------- the meter */

static void *meter_malloc(size_t size)
{
    void *p = malloc(size);
    membudget_meter *m = tl_meter;
    if (!p || !m)
        return p;
    m->charged += malloc_usable_size(p) + MEMBUDGET_CHUNK_OVERHEAD;
    if (m->charged > m->allowance) {
        size_t need = m->charged - m->allowance;
        if (need < MEMBUDGET_METER_STEP)
            need = MEMBUDGET_METER_STEP;
        if (membudget_grow(m->lease, need) != 0) {
            m->charged -= malloc_usable_size(p) + MEMBUDGET_CHUNK_OVERHEAD;
            m->refused = 1;
            free(p);
            return NULL;
        }
        m->allowance += need;
    }
    return p;
}

static void meter_free(void *p)
{
    membudget_meter *m = tl_meter;
    if (p && m) {
        size_t size = malloc_usable_size(p) + MEMBUDGET_CHUNK_OVERHEAD;
        m->charged -= size < m->charged ? size : m->charged;
    }
    free(p);
}

void membudget_init(size_t limit)
{
    budget_limit = limit;
    json_set_alloc_funcs(meter_malloc, meter_free);
    /* Blocks from 1 MiB up always get their own mapping, given back when
     * freed. glibc otherwise raises this threshold to the largest block
     * freed so far (up to 32 MiB): after an upload's first few-MiB buffer
     * the next ones came from the heap, and pieces of the heap above them
     * kept it from shrinking (16-17.5 MiB over idle after test_memory's
     * concurrent 3 MiB uploads, once the document was no longer parsed a
     * second time on the I/O thread; 6.7 MiB with the fixed threshold). */
    mallopt(M_MMAP_THRESHOLD, MEMBUDGET_MMAP_AT);
}

void membudget_meter_begin(membudget_lease *lease, size_t allowance)
{
    tl_meter_storage = (membudget_meter){lease, allowance, 0, 0};
    tl_meter = &tl_meter_storage;
}

void membudget_meter_end(void)
{
    tl_meter = NULL;
}

int membudget_meter_refused(void)
{
    return tl_meter_storage.refused;
}

void membudget_request_enter(membudget_lease *lease)
{
    tl_request_lease = lease;
}

void membudget_request_leave(void)
{
    tl_request_lease = NULL;
}

membudget_lease *membudget_request_lease(void)
{
    return tl_request_lease;
}
