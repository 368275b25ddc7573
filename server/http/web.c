/*
 * web.c - static files of the web page (web.h).
 *
 * The page is a handful of files that change only with the repository, so
 * the daemon serves them straight from disk (libmicrohttpd sends the
 * descriptor). The danger of a static file server is a path that walks
 * out of its folder; here a path is refused unless each segment is a plain
 * name, and the resolved file must still lie inside the folder (a symlink
 * pointing out is refused too).
 */
#include "web.h"

#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "http.h"
#include "launch.h"

#define WEB_PREFIX "/ui/"
#define WEB_MAX_PATH 256

static char web_root[PATH_MAX]; /* resolved, no trailing slash; "" when absent */
static char web_looked[PATH_MAX];

int web_init(const char *configured)
{
    web_root[0] = '\0';
    if (configured && *configured)
        snprintf(web_looked, sizeof web_looked, "%s", configured);
    else if (launch_beside_binary("../web", web_looked, sizeof web_looked) != 0) /* bin/fdemd -> ./web */
        snprintf(web_looked, sizeof web_looked, "web");
    struct stat st;
    if (!realpath(web_looked, web_root) || stat(web_root, &st) != 0 || !S_ISDIR(st.st_mode)) {
        web_root[0] = '\0';
        return -1;
    }
    return 0;
}

int web_path(const char *url)
{
    return url && (strcmp(url, "/") == 0 || strncmp(url, WEB_PREFIX, strlen(WEB_PREFIX)) == 0);
}

/* 1 when every segment of rel is a plain name: letters, digits, '_', '-'
 * and '.', not starting with '.', none empty. */
static int web_plain(const char *rel)
{
    if (!*rel || strlen(rel) >= WEB_MAX_PATH)
        return 0;
    int start = 1;
    for (const char *p = rel; *p; p++) {
        char ch = *p;
        if (ch == '/') {
            if (start)
                return 0; /* an empty segment */
            start = 1;
            continue;
        }
        int ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                 (ch >= '0' && ch <= '9') || ch == '_' || ch == '-' || (ch == '.' && !start);
        if (!ok)
            return 0;
        start = 0;
    }
    return !start;
}

static const char *web_content_type(const char *path)
{
    static const struct { const char *ext, *type; } types[] = {
        {".html", "text/html; charset=utf-8"}, {".js", "text/javascript; charset=utf-8"},
        {".css", "text/css; charset=utf-8"},   {".svg", "image/svg+xml"},
        {".png", "image/png"},                  {".json", "application/json"},
        {".txt", "text/plain; charset=utf-8"},
    };
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (dot && (!slash || dot > slash))
        for (size_t i = 0; i < sizeof types / sizeof *types; i++)
            if (strcmp(dot, types[i].ext) == 0)
                return types[i].type;
    return "text/plain; charset=utf-8"; /* LICENSE and the like; never sniffed (nosniff) */
}

static enum MHD_Result web_not_found(struct MHD_Connection *conn, const char *url)
{
    char detail[PATH_MAX + 200];
    if (!web_root[0])
        snprintf(detail, sizeof detail, "this daemon has no web page: no folder %s (start it "
                 "with --web DIR, DIR being the repository's web/)", web_looked);
    else
        snprintf(detail, sizeof detail, "the web page has no file %.200s", url);
    return http_reply_problem(conn, 404, "Not found", detail, NULL);
}

/* Opens ROOT/rel if it resolves to a regular file inside ROOT. */
static int web_open(const char *rel, size_t *size)
{
    char path[PATH_MAX], real[PATH_MAX];
    if (snprintf(path, sizeof path, "%s/%s", web_root, rel) >= (int)sizeof path ||
        !realpath(path, real))
        return -1;
    size_t n = strlen(web_root);
    if (strncmp(real, web_root, n) != 0 || real[n] != '/')
        return -1;
    int fd = open(real, O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        if (fd >= 0)
            close(fd);
        return -1;
    }
    *size = (size_t)st.st_size;
    return fd;
}

enum MHD_Result web_reply(struct MHD_Connection *conn, const char *url)
{
    const char *rel = strcmp(url, "/") == 0 ? "index.html" : url + strlen(WEB_PREFIX);
    size_t size = 0;
    int fd = web_root[0] && web_plain(rel) ? web_open(rel, &size) : -1;
    if (fd < 0)
        return web_not_found(conn, url);
    struct MHD_Response *resp = MHD_create_response_from_fd(size, fd);
    if (!resp) {
        close(fd);
        return http_reply_problem(conn, 500, "Internal error", "the file could not be served",
                                  NULL);
    }
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, web_content_type(rel));
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    MHD_add_response_header(resp, "Content-Security-Policy",
                            "default-src 'self'; img-src 'self' blob: data:; object-src 'none'; "
                            "base-uri 'none'; frame-ancestors 'none'; form-action 'none'");
    MHD_add_response_header(resp, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(resp, "Referrer-Policy", "no-referrer");
    MHD_add_response_header(resp, "X-Frame-Options", "DENY");
    return http_reply_response(conn, 200, resp);
}
