/*
 * main.c - fdemd: options, start-up, signals and orderly shutdown.
 *
 * SIGTERM/SIGINT are blocked in every thread and taken synchronously by
 * sigwait() here, so shutdown runs as ordinary code in a known order: stop
 * accepting requests, pause every running case at a step boundary (each
 * worker checkpoints on its way out), close the HDF5 files on the I/O
 * thread, and exit 0.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "common/config.h"
#include "fdem.h"
#include "http/http.h"
#include "cases/io_thread.h"
#include "common/memory_budget.h"
#include "cases/registry.h"
#include "launch.h"

static void usage(FILE *out)
{
    fprintf(out,
            "usage: fdemd [--listen 127.0.0.1:8080] [--data DIR] [--token TOKEN]\n"
            "             [--max-upload BYTES] [--max-running N] [--threads T]\n"
            "             [--max-case-memory BYTES] [--max-memory BYTES]\n"
            "             [--checkpoint-every SECONDS] [--max-connections-per-ip N]\n"
            "             [--request-timeout SECONDS] [--max-streams N] [--web DIR]\n"
            "             [--launcher LINE] [--max-ranks N]\n"
            "\n"
            "  --listen HOST:PORT      address to serve on (default 127.0.0.1:8080; port 0 picks one)\n"
            "  --data DIR              where cases are kept (default ./fdemd-data)\n"
            "  --token TOKEN           require Authorization: Bearer TOKEN (or set FDEMD_TOKEN)\n"
            "  --max-upload BYTES      largest request body (default 64M)\n"
            "  --max-running N         cases stepping at once; later starts are queued (default: cores)\n"
            "  --threads T             OpenMP threads per running case (default 1)\n"
            "  --max-case-memory BYTES largest model a case may build (default 4G)\n"
            "  --max-memory BYTES      models and uploads held at once (default: half the RAM)\n"
            "  --checkpoint-every S    checkpoint running cases at least every S s of wall time (default 60)\n"
            "  --max-connections-per-ip N  open connections per client address (default 16)\n"
            "  --request-timeout SECONDS   a request must arrive whole (headers and body)\n"
            "                          within this time, or is cut (default 30)\n"
            "  --max-streams N         GET /stream event streams open at once (default 64)\n"
            "  --web DIR               the web page's files (default: web/ beside bin/)\n"
            "  --launcher LINE         starts the N ranks of a case with \"parallel\": {\"ranks\": N},\n"
            "                          {ranks} replaced by N (default \"" LAUNCH_DEFAULT "\")\n"
            "  --max-ranks N           most ranks a case may ask for (default: cores)\n"
            "\n"
            "Sizes accept a K, M or G suffix (powers of 1024). fdemd %s\n", FDEM_VERSION);
}

static int parse_size(const char *s, size_t *out)
{
    char *end = NULL;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || end == s || s[0] == '-')
        return -1;
    unsigned long long mult = 1;
    if (*end == 'K' || *end == 'k') mult = 1ull << 10;
    else if (*end == 'M' || *end == 'm') mult = 1ull << 20;
    else if (*end == 'G' || *end == 'g') mult = 1ull << 30;
    else if (*end != '\0') return -1;
    if (mult != 1 && end[1] != '\0' && strcmp(end + 1, "i") != 0 && strcmp(end + 1, "iB") != 0 &&
        strcmp(end + 1, "B") != 0)
        return -1;
    if (v > (unsigned long long)SIZE_MAX / mult)
        return -1;
    *out = (size_t)(v * mult);
    return 0;
}

static int parse_int(const char *s, int min, int *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < min || v > 1 << 20)
        return -1;
    *out = (int)v;
    return 0;
}

static int parse_seconds(const char *s, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !(v > 0) || v > 1e9)
        return -1;
    *out = v;
    return 0;
}

static int parse_listen(const char *s, fdemd_config *cfg)
{
    const char *colon = strrchr(s, ':');
    if (!colon || colon == s || (size_t)(colon - s) >= sizeof cfg->listen_host)
        return -1;
    memcpy(cfg->listen_host, s, (size_t)(colon - s));
    cfg->listen_host[colon - s] = '\0';
    if (strcmp(cfg->listen_host, "localhost") == 0)
        strcpy(cfg->listen_host, "127.0.0.1");
    struct in_addr ipv4;
    if (inet_pton(AF_INET, cfg->listen_host, &ipv4) != 1)
        /* a bad option like the others (exit 2), not a failed start; an
         * address with a colon or bracket is IPv6, anything else a name */
        return strpbrk(cfg->listen_host, ":[]") ? -2 : -3;
    int port = 0;
    if (parse_int(colon + 1, 0, &port) != 0)
        return -1;
    if (port > 65535)
        return -4;
    cfg->listen_port = port;
    return 0;
}

static int parse_options(int argc, char **argv, fdemd_config *cfg)
{
    enum { OPT_MAX_CASE_MEMORY = 1000, OPT_MAX_MEMORY, OPT_CHECKPOINT_EVERY,
           OPT_MAX_CONNECTIONS_PER_IP, OPT_REQUEST_TIMEOUT, OPT_MAX_STREAMS,
           OPT_WEB, OPT_LAUNCHER, OPT_MAX_RANKS };
    static const struct option opts[] = {
        {"listen", required_argument, 0, 'l'},  {"data", required_argument, 0, 'd'},
        {"token", required_argument, 0, 't'},   {"max-upload", required_argument, 0, 'u'},
        {"max-running", required_argument, 0, 'r'}, {"threads", required_argument, 0, 'j'},
        {"max-case-memory", required_argument, 0, OPT_MAX_CASE_MEMORY},
        {"max-memory", required_argument, 0, OPT_MAX_MEMORY},
        {"checkpoint-every", required_argument, 0, OPT_CHECKPOINT_EVERY},
        {"max-connections-per-ip", required_argument, 0, OPT_MAX_CONNECTIONS_PER_IP},
        {"request-timeout", required_argument, 0, OPT_REQUEST_TIMEOUT},
        {"max-streams", required_argument, 0, OPT_MAX_STREAMS},
        {"web", required_argument, 0, OPT_WEB},
        {"launcher", required_argument, 0, OPT_LAUNCHER},
        {"max-ranks", required_argument, 0, OPT_MAX_RANKS},
        {"help", no_argument, 0, 'h'},          {0, 0, 0, 0},
    };
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    strcpy(cfg->listen_host, "127.0.0.1");
    cfg->listen_port = 8080;
    strcpy(cfg->data_dir, "./fdemd-data");
    cfg->max_upload = (size_t)64 << 20;
    cfg->max_running = cores > 0 ? (int)cores : 1;
    cfg->threads = 1;
    cfg->max_case_memory = (size_t)4 << 30;
    cfg->max_memory = membudget_default_limit();
    cfg->checkpoint_every = 60.0;
    cfg->max_connections_per_ip = 16;
    cfg->request_timeout = 30;
    cfg->max_streams = 64;
    snprintf(cfg->launcher, sizeof cfg->launcher, "%s", LAUNCH_DEFAULT);
    cfg->max_ranks = cores > 0 ? (int)cores : 1;
    int request_timeout = 30;
    const char *env_token = getenv("FDEMD_TOKEN");
    cfg->token = env_token && *env_token ? env_token : NULL;

    char listen_error[256];
    int opt;
    while ((opt = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        const char *bad = NULL;
        switch (opt) {
        case 'l':
            switch (parse_listen(optarg, cfg)) {
            case 0: break;
            case -2: bad = "--listen serves IPv4 only, not IPv6: HOST is a dotted address such as 127.0.0.1 or 0.0.0.0 (or localhost)"; break;
            case -3:
                snprintf(listen_error, sizeof listen_error,
                         "--listen takes a dotted IPv4 address (or localhost), not a host name "
                         "(\"%.64s\"): 127.0.0.1 for this machine only, 0.0.0.0 for every "
                         "interface", cfg->listen_host);
                bad = listen_error;
                break;
            case -4: bad = "--listen: PORT is 0 to 65535 (0 picks a free port)"; break;
            default: bad = "--listen takes HOST:PORT, e.g. 127.0.0.1:8080"; break;
            }
            break;
        case 'd':
            if (!*optarg || strlen(optarg) >= sizeof cfg->data_dir) bad = "--data takes a directory path";
            else strcpy(cfg->data_dir, optarg);
            break;
        case 't': cfg->token = *optarg ? optarg : NULL; break;
        case 'u': if (parse_size(optarg, &cfg->max_upload) || !cfg->max_upload) bad = "--max-upload takes a positive size in bytes"; break;
        case 'r': if (parse_int(optarg, 1, &cfg->max_running)) bad = "--max-running takes a positive integer"; break;
        case 'j': if (parse_int(optarg, 1, &cfg->threads)) bad = "--threads takes a positive integer"; break;
        case OPT_MAX_CASE_MEMORY:
            if (parse_size(optarg, &cfg->max_case_memory) || !cfg->max_case_memory) bad = "--max-case-memory takes a positive size in bytes";
            break;
        case OPT_MAX_MEMORY:
            if (parse_size(optarg, &cfg->max_memory) || !cfg->max_memory) bad = "--max-memory takes a positive size in bytes";
            break;
        case OPT_CHECKPOINT_EVERY:
            if (parse_seconds(optarg, &cfg->checkpoint_every)) bad = "--checkpoint-every takes a positive number of seconds";
            break;
        case OPT_MAX_CONNECTIONS_PER_IP:
            if (parse_int(optarg, 1, &cfg->max_connections_per_ip)) bad = "--max-connections-per-ip takes a positive integer";
            break;
        case OPT_REQUEST_TIMEOUT:
            if (parse_int(optarg, 1, &request_timeout)) bad = "--request-timeout takes a positive number of seconds";
            cfg->request_timeout = request_timeout;
            break;
        case OPT_MAX_STREAMS:
            if (parse_int(optarg, 0, &cfg->max_streams)) bad = "--max-streams takes a number of streams, 0 or more";
            break;
        case OPT_WEB:
            if (!*optarg || strlen(optarg) >= sizeof cfg->web_dir) bad = "--web takes a directory path";
            else strcpy(cfg->web_dir, optarg);
            break;
        case OPT_LAUNCHER: {
            static char launcher_error[400];
            char **words = strlen(optarg) < sizeof cfg->launcher
                ? launch_argv(optarg, 1, NULL, launcher_error, sizeof launcher_error) : NULL;
            if (!words && strlen(optarg) >= sizeof cfg->launcher) bad = "--launcher: the line is too long";
            else if (!words) bad = launcher_error; /* refused now, not at each ranked start */
            else strcpy(cfg->launcher, optarg);
            launch_argv_free(words);
            break;
        }
        case OPT_MAX_RANKS:
            if (parse_int(optarg, 1, &cfg->max_ranks)) bad = "--max-ranks takes a positive integer";
            break;
        case 'h': usage(stdout); exit(0);
        default: usage(stderr); return -1;
        }
        if (bad) {
            fprintf(stderr, "fdemd: %s\n", bad);
            return -1;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "fdemd: unexpected argument \"%s\"\n", argv[optind]);
        usage(stderr);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    static fdemd_config cfg;
    if (parse_options(argc, argv, &cfg) != 0)
        return 2;

    /* Blocked before any thread exists, so every thread inherits the mask
     * and only sigwait() below ever sees these signals. */
    sigset_t stop_signals;
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGTERM);
    sigaddset(&stop_signals, SIGINT);
    pthread_sigmask(SIG_BLOCK, &stop_signals, NULL);
    signal(SIGPIPE, SIG_IGN);

    membudget_init(cfg.max_memory);
    if (io_start() != 0) {
        fprintf(stderr, "fdemd: cannot start the I/O thread\n");
        return 1;
    }
    if (registry_init(&cfg) != 0) {
        io_stop();
        return 1;
    }
    int port = http_start(&cfg);
    if (port < 0) {
        registry_shutdown();
        io_stop();
        return 1;
    }
    printf("listening on %s:%d\n", cfg.listen_host, port);
    fflush(stdout);
    registry_check_in_background();

    int sig = 0;
    while (sigwait(&stop_signals, &sig) != 0)
        ;
    fprintf(stderr, "fdemd: %s received, pausing cases and closing files\n",
            sig == SIGINT ? "SIGINT" : "SIGTERM");
    http_stop();
    registry_shutdown();
    io_stop();
    fprintf(stderr, "fdemd: stopped\n");
    return 0;
}
