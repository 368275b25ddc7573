/*
 * server/common/ - what every part of the daemon shares and reads: its
 * settings and its one memory account.
 *  - Owns: the command-line settings (this header), filled once by main.c;
 *    the --max-memory account every large allocation is reserved against
 *    (memory_budget.c).
 *  - May call: the C library and jansson's allocator hooks; no other
 *    server folder.
 *  - Called by: main.c, http/ and cases/.
 */
/*
 * config.h - the daemon's command-line settings, filled once by main() and
 * read-only afterwards (so every thread may read them without locking).
 */
#ifndef FDEMD_CONFIG_H
#define FDEMD_CONFIG_H

#include <stddef.h>

typedef struct fdemd_config {
    char listen_host[64];     /* dotted IPv4 */
    int listen_port;          /* 0 = pick a free port */
    char data_dir[1024];
    const char *token;        /* NULL = no authentication */
    size_t max_upload;        /* bytes of a request body */
    int max_running;          /* cases stepping at once; more are queued */
    int threads;              /* OpenMP threads per running case */
    size_t max_case_memory;   /* memory_limit handed to case_build */
    size_t max_memory;        /* --max-memory: all models and uploads together */
    double checkpoint_every;  /* s of wall time between checkpoints of a running case */
    int max_connections_per_ip; /* open connections per client address */
    double request_timeout;   /* s for a whole request, headers and body */
    int max_streams;          /* GET /stream streams open at once */
    char web_dir[1024];       /* --web: the page's files; "" = web/ beside bin/ */
    char launcher[1024];      /* --launcher: starts a ranked case's ranks ({ranks}) */
    int max_ranks;            /* --max-ranks: most "parallel" ranks a case may ask for */
} fdemd_config;

#endif
