/*
 * http.c - the one place fdemctl touches libcurl: a request returning
 * status + body, a download streaming into a FILE, and a body followed as
 * it arrives (an event stream, GET /stream).
 *
 * Each call builds and frees its own easy handle: fdemctl makes a handful of
 * requests per run, so connection reuse is not worth shared mutable state.
 */
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <curl/curl.h>
#include "fdemctl.h"

typedef struct body_buffer {
    char *data;
    size_t length, capacity;
    int out_of_memory;
} body_buffer;

static size_t http_collect(char *chunk, size_t size, size_t count, void *user)
{
    body_buffer *b = user;
    size_t n = size * count;
    if (b->length + n + 1 > b->capacity) {
        size_t capacity = b->capacity ? b->capacity : 4096;
        while (capacity < b->length + n + 1) capacity *= 2;
        char *grown = realloc(b->data, capacity);
        if (!grown) { b->out_of_memory = 1; return 0; }
        b->data = grown;
        b->capacity = capacity;
    }
    memcpy(b->data + b->length, chunk, n);
    b->length += n;
    b->data[b->length] = '\0';
    return n;
}

static size_t http_to_file(char *chunk, size_t size, size_t count, void *user)
{
    return fwrite(chunk, size, count, (FILE *)user) * size;
}

static struct curl_slist *http_headers(const ctl_options *o, const char *content_type)
{
    struct curl_slist *h = NULL;
    h = curl_slist_append(h, "Accept: application/json, application/problem+json, */*");
    if (content_type) {
        char line[128];
        snprintf(line, sizeof line, "Content-Type: %s", content_type);
        h = curl_slist_append(h, line);
    }
    if (o->token && o->token[0]) {
        char line[1024];
        snprintf(line, sizeof line, "Authorization: Bearer %s", o->token);
        h = curl_slist_append(h, line);
    }
    return h;
}

/* Common set-up of a handle; the caller adds the method and body. */
static CURL *http_open(const ctl_options *o, const char *path, char *errbuf)
{
    CURL *c = curl_easy_init();
    if (!c) return NULL;
    size_t n = strlen(o->server) + strlen(path) + 1;
    char *url = malloc(n);
    if (!url) { curl_easy_cleanup(c); return NULL; }
    snprintf(url, n, "%s%s", o->server, path);
    curl_easy_setopt(c, CURLOPT_URL, url);
    free(url);  /* libcurl copies the URL string */
    curl_easy_setopt(c, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(c, CURLOPT_CONNECTTIMEOUT, 10L);
    curl_easy_setopt(c, CURLOPT_ERRORBUFFER, errbuf);
    curl_easy_setopt(c, CURLOPT_USERAGENT, "fdemctl/1");
    errbuf[0] = '\0';
    return c;
}

/* Runs the transfer and fills status or the transport error. */
static int http_perform(CURL *c, const char *errbuf, http_response *out)
{
    CURLcode rc = curl_easy_perform(c);
    if (rc != CURLE_OK) {
        snprintf(out->error, sizeof out->error, "%s",
                 errbuf[0] ? errbuf : curl_easy_strerror(rc));
        out->status = 0;
        return -1;
    }
    curl_easy_getinfo(c, CURLINFO_RESPONSE_CODE, &out->status);
    return 0;
}

int http_request(const ctl_options *o, const char *method, const char *path,
                 const char *body, size_t body_length, http_response *out)
{
    return http_request_as(o, method, path, body, body_length, "application/json", out);
}

int http_request_as(const ctl_options *o, const char *method, const char *path,
                    const char *body, size_t body_length, const char *content_type,
                    http_response *out)
{
    char errbuf[CURL_ERROR_SIZE];
    body_buffer b = {0};
    memset(out, 0, sizeof *out);
    CURL *c = http_open(o, path, errbuf);
    if (!c) { snprintf(out->error, sizeof out->error, "out of memory"); return -1; }

    int is_post = strcmp(method, "POST") == 0;
    struct curl_slist *h = http_headers(o, is_post && body ? content_type : NULL);
    curl_easy_setopt(c, CURLOPT_HTTPHEADER, h);
    if (is_post) {
        /* An empty POST still sends Content-Length: 0 (the server answers
         * 411 to a body without a length). */
        curl_easy_setopt(c, CURLOPT_POSTFIELDSIZE_LARGE, (curl_off_t)(body ? body_length : 0));
        curl_easy_setopt(c, CURLOPT_POSTFIELDS, body ? body : "");
    } else if (strcmp(method, "GET") != 0) {
        curl_easy_setopt(c, CURLOPT_CUSTOMREQUEST, method);
    }
    curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, http_collect);
    curl_easy_setopt(c, CURLOPT_WRITEDATA, &b);

    int rc = http_perform(c, errbuf, out);
    if (b.out_of_memory) {
        snprintf(out->error, sizeof out->error, "out of memory reading the answer");
        out->status = 0;
        rc = -1;
    }
    curl_slist_free_all(h);
    curl_easy_cleanup(c);
    if (rc != 0) { free(b.data); return -1; }
    out->body = b.data ? b.data : calloc(1, 1);
    out->length = b.length;
    if (!out->body) { snprintf(out->error, sizeof out->error, "out of memory"); return -1; }
    return 0;
}

int http_download(const ctl_options *o, const char *path, FILE *sink, http_response *out)
{
    char errbuf[CURL_ERROR_SIZE];
    memset(out, 0, sizeof *out);
    CURL *c = http_open(o, path, errbuf);
    if (!c) { snprintf(out->error, sizeof out->error, "out of memory"); return -1; }
    struct curl_slist *h = http_headers(o, 0);
    curl_easy_setopt(c, CURLOPT_HTTPHEADER, h);
    curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, http_to_file);
    curl_easy_setopt(c, CURLOPT_WRITEDATA, sink);
    int rc = http_perform(c, errbuf, out);
    curl_slist_free_all(h);
    curl_easy_cleanup(c);
    return rc;
}

/* ------------------------------------------------------------ following */

/* What a followed body's write callback keeps until the loop hands it on:
 * `take` may make requests of its own, which must not run inside a
 * libcurl callback. */
typedef struct follow_state {
    CURL *c;
    body_buffer pending;
    long status;       /* known once the first piece arrives */
} follow_state;

static size_t http_follow_collect(char *chunk, size_t size, size_t count, void *user)
{
    follow_state *f = user;
    if (!f->status)
        curl_easy_getinfo(f->c, CURLINFO_RESPONSE_CODE, &f->status);
    return http_collect(chunk, size, count, &f->pending);
}

static double http_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Runs the transfer in `m` until `take` asks to stop (returns 1), the
 * answer is not 200, the transfer ends or fails, or nothing arrives for
 * `quiet_limit` seconds (returns -1, out says which). */
static int http_follow_loop(CURLM *m, follow_state *f, double quiet_limit,
                            http_piece_fn take, void *arg, http_response *out)
{
    double heard = http_now();
    for (;;) {
        int running = 0;
        curl_multi_perform(m, &running);
        int refused = f->status && f->status != 200; /* its body is a problem: kept whole */
        if (refused && !running) {
            out->status = f->status;
            out->body = f->pending.data ? f->pending.data : calloc(1, 1);
            out->length = f->pending.length;
            f->pending = (body_buffer){0};
            return -1;
        }
        if (!refused && f->pending.length > 0) {
            heard = http_now();
            body_buffer piece = f->pending;
            f->pending = (body_buffer){0};
            int stop = take(arg, piece.data, piece.length);
            free(piece.data);
            if (stop)
                return 1;
        }
        if (!running) {
            CURLMsg *msg;
            int left;
            CURLcode rc = CURLE_OK;
            while ((msg = curl_multi_info_read(m, &left)) != NULL)
                if (msg->msg == CURLMSG_DONE) rc = msg->data.result;
            out->status = f->status;
            snprintf(out->error, sizeof out->error, "%s",
                     rc != CURLE_OK ? curl_easy_strerror(rc) : "the server ended the stream");
            return -1;
        }
        if (http_now() - heard > quiet_limit) {
            out->status = f->status;
            snprintf(out->error, sizeof out->error, "nothing arrived for %.0f s", quiet_limit);
            return -1;
        }
        curl_multi_poll(m, NULL, 0, 1000, NULL);
    }
}

int http_follow(const ctl_options *o, const char *path, double quiet_limit, http_piece_fn take,
                void *arg, http_response *out)
{
    char errbuf[CURL_ERROR_SIZE];
    memset(out, 0, sizeof *out);
    follow_state f = {0};
    f.c = http_open(o, path, errbuf);
    CURLM *m = f.c ? curl_multi_init() : NULL;
    if (!m) {
        if (f.c) curl_easy_cleanup(f.c);
        snprintf(out->error, sizeof out->error, "out of memory");
        return -1;
    }
    struct curl_slist *h = http_headers(o, NULL);
    curl_easy_setopt(f.c, CURLOPT_HTTPHEADER, h);
    curl_easy_setopt(f.c, CURLOPT_WRITEFUNCTION, http_follow_collect);
    curl_easy_setopt(f.c, CURLOPT_WRITEDATA, &f);
    curl_multi_add_handle(m, f.c);
    int rc = http_follow_loop(m, &f, quiet_limit, take, arg, out);
    curl_multi_remove_handle(m, f.c);
    curl_multi_cleanup(m);
    curl_easy_cleanup(f.c);
    curl_slist_free_all(h);
    free(f.pending.data);
    return rc > 0 ? 0 : -1;
}

void http_response_free(http_response *r)
{
    free(r->body);
    r->body = NULL;
    r->length = 0;
}

int http_case_path(char *out, size_t size, const char *id, const char *suffix)
{
    /* Escaped so an id typed by a user can never change the path. */
    char *escaped = curl_easy_escape(NULL, id, 0);
    if (!escaped) return -1;
    int n = snprintf(out, size, "/cases/%s%s", escaped, suffix ? suffix : "");
    curl_free(escaped);
    return (n < 0 || (size_t)n >= size) ? -1 : 0;
}
