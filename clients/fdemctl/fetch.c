/*
 * fetch.c - `fdemctl fetch ID`: downloads result.h5 and its result.xdmf.
 *
 * The server's XDMF refers to its data as "result.h5:/snapshots/...". Saved
 * under another name, that reference would point at a file that is not
 * there, so the XDMF text is rewritten to name the .h5 file as saved (both
 * land in the same folder, so the reference stays relative).
 * Files are written to "<path>.part" and renamed, so an interrupted fetch
 * never leaves a truncated result under the real name.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <jansson.h>
#include "fdemctl.h"

static const char USAGE_FETCH[] =
    "usage: fdemctl fetch ID [-o FILE.h5] [--force]\n"
    "  Downloads the case's result.h5 to FILE.h5 (default <name>.h5 with <name> the\n"
    "  case's name, or <id>.h5) and its XDMF sidecar to FILE.xdmf beside it,\n"
    "  rewritten to refer to FILE.h5, so ParaView opens FILE.xdmf directly. Works\n"
    "  while the case runs (the file then holds every snapshot written so far).\n"
    "  --force   replace FILE.h5 / FILE.xdmf if they exist (else fetch refuses,\n"
    "            exit 1, and downloads nothing)\n";

#define FETCH_SERVER_H5 "result.h5"

/* "<name>.h5" with only portable file-name characters, else "<id>.h5". */
static void fetch_default_path(char *out, size_t size, const char *id, const char *name)
{
    const char *base = name && name[0] && name[0] != '.' ? name : id;
    size_t n = 0;
    for (const char *c = base; *c && n + 4 < size && n < 200; c++) {
        int ok = (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') ||
                 (*c >= '0' && *c <= '9') || *c == '-' || *c == '_' || *c == '.';
        out[n++] = ok ? *c : '_';
    }
    snprintf(out + n, size - n, ".h5");
}

/* path without a .h5/.hdf5 extension, then ".xdmf". */
static void fetch_xdmf_path(char *out, size_t size, const char *h5_path)
{
    size_t n = strlen(h5_path);
    static const char *extensions[] = {".h5", ".hdf5", ".hdf", NULL};
    for (int i = 0; extensions[i]; i++) {
        size_t e = strlen(extensions[i]);
        if (n > e && strcmp(h5_path + n - e, extensions[i]) == 0) { n -= e; break; }
    }
    snprintf(out, size, "%.*s.xdmf", (int)n, h5_path);
}

static const char *fetch_basename(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

/* Appends s to the growing buffer *out (NULL stays NULL on failure). */
static void fetch_append(char **out, size_t *length, size_t *capacity, const char *s, size_t n)
{
    if (!*out) return;
    if (*length + n + 1 > *capacity) {
        while (*length + n + 1 > *capacity) *capacity *= 2;
        char *grown = realloc(*out, *capacity);
        if (!grown) { free(*out); *out = NULL; return; }
        *out = grown;
    }
    memcpy(*out + *length, s, n);
    *length += n;
    (*out)[*length] = '\0';
}

static int fetch_is_path_char(char c)
{
    return c != ' ' && c != '\t' && c != '\r' && c != '\n' && c != '>' && c != '"' && c != '\'';
}

/* Replaces every "[dir/]result.h5:" reference with "<h5_name>:" (XML-escaped). */
static char *fetch_rewrite_xdmf(const char *text, size_t length, const char *h5_name)
{
    size_t capacity = length + 256, n = 0;
    char *out = malloc(capacity);
    if (!out) return NULL;
    out[0] = '\0';
    const char *done = text, *hit;
    const char *end = text + length;
    while ((hit = strstr(done, FETCH_SERVER_H5 ":")) != NULL && hit < end) {
        const char *start = hit;
        while (start > done && fetch_is_path_char(start[-1])) start--;
        fetch_append(&out, &n, &capacity, done, (size_t)(start - done));
        for (const char *c = h5_name; *c; c++) {
            const char *escaped = *c == '&' ? "&amp;" : *c == '<' ? "&lt;" : *c == '>' ? "&gt;" : NULL;
            fetch_append(&out, &n, &capacity, escaped ? escaped : c, escaped ? strlen(escaped) : 1);
        }
        done = hit + strlen(FETCH_SERVER_H5);
    }
    fetch_append(&out, &n, &capacity, done, (size_t)(end - done));
    return out;
}

/* Writes data to path via path.part + rename. */
static int fetch_save(const char *path, const char *data, size_t length)
{
    char part[4096];
    snprintf(part, sizeof part, "%s.part", path);
    FILE *f = fopen(part, "wb");
    if (!f) {
        fprintf(stderr, "fdemctl: cannot write %s: %s\n", part, strerror(errno));
        return CTL_FAIL;
    }
    int failed = fwrite(data, 1, length, f) != length;
    failed |= fclose(f) != 0;
    if (failed || rename(part, path) != 0) {
        fprintf(stderr, "fdemctl: cannot write %s: %s\n", path, strerror(errno));
        remove(part);
        return CTL_FAIL;
    }
    return CTL_OK;
}

/* Streams GET path into file via file.part; reports refusals as problems. */
static int fetch_download(const ctl_options *o, const char *path, const char *file)
{
    char part[4096];
    snprintf(part, sizeof part, "%s.part", file);
    FILE *f = fopen(part, "w+b");
    if (!f) {
        fprintf(stderr, "fdemctl: cannot write %s: %s\n", part, strerror(errno));
        return CTL_FAIL;
    }
    http_response r;
    int rc = http_download(o, path, f, &r);
    if (rc == 0 && r.status != 200) {
        /* The body is problem details: read it back to report it. */
        char body[8192];
        rewind(f);
        r.length = fread(body, 1, sizeof body - 1, f);
        body[r.length] = '\0';
        r.body = body;
        fclose(f);
        remove(part);
        int code = ctl_report_failure(o, path, &r);
        r.body = NULL;
        return code;
    }
    int write_failed = fclose(f) != 0;
    if (rc != 0) { remove(part); return ctl_report_failure(o, path, &r); }
    if (write_failed || rename(part, file) != 0) {
        fprintf(stderr, "fdemctl: cannot write %s: %s\n", file, strerror(errno));
        remove(part);
        return CTL_FAIL;
    }
    return CTL_OK;
}

static int fetch_xdmf(const ctl_options *o, const char *id, const char *xdmf_file,
                      const char *h5_file)
{
    char path[512];
    http_response r;
    http_case_path(path, sizeof path, id, "/result.xdmf");
    int code = ctl_call(o, "GET", path, NULL, 0, 200, &r);
    if (code) return code;
    char *text = fetch_rewrite_xdmf(r.body, r.length, fetch_basename(h5_file));
    http_response_free(&r);
    if (!text) { fprintf(stderr, "fdemctl: out of memory\n"); return CTL_FAIL; }
    code = fetch_save(xdmf_file, text, strlen(text));
    free(text);
    return code;
}

/* 0 when neither file exists (or --force), else CTL_FAIL after saying which. */
static int fetch_check_overwrite(const char *h5_file, const char *xdmf_file, int force)
{
    const char *files[] = {h5_file, xdmf_file};
    for (int i = 0; i < 2 && !force; i++) {
        if (access(files[i], F_OK) == 0) {
            fprintf(stderr, "fdemctl: %s exists; not overwriting it (use --force to replace it, "
                    "or -o to save elsewhere)\n", files[i]);
            return CTL_FAIL;
        }
    }
    return CTL_OK;
}

int cmd_fetch(const ctl_options *o, int argc, char **argv)
{
    const char *id[1], *output = NULL;
    int force = 0;
    ctl_option_spec specs[] = {{"--output", "-o", &output, NULL},
                               {"--force", "-f", NULL, &force}, {0}};
    int n = ctl_parse_args(argc, argv, specs, USAGE_FETCH, id, 1, 1);
    if (n < 0) return ctl_args_exit(n);
    char id_buf[CTL_ID_SIZE];
    int resolved = ctl_resolve_id(o, &id[0], id_buf, sizeof id_buf);
    if (resolved) return resolved;

    char h5_file[2048], xdmf_file[2048], path[512];
    if (http_case_path(path, sizeof path, id[0], "/result.h5") != 0 ||
        (output && strlen(output) > 2000)) {
        fprintf(stderr, "fdemctl: case id or output path too long\n");
        return CTL_USAGE;
    }
    if (output) {
        snprintf(h5_file, sizeof h5_file, "%s", output);
    } else {
        int code;
        json_t *s = ctl_get_status(o, id[0], &code);
        if (!s) return code;
        fetch_default_path(h5_file, sizeof h5_file, id[0],
                           json_string_value(json_object_get(s, "name")));
        json_decref(s);
    }
    fetch_xdmf_path(xdmf_file, sizeof xdmf_file, h5_file);
    if (fetch_check_overwrite(h5_file, xdmf_file, force) != CTL_OK) return CTL_FAIL;

    int code = fetch_download(o, path, h5_file);
    if (code) return code;
    code = fetch_xdmf(o, id[0], xdmf_file, h5_file);
    if (code) return code;
    printf("%s\n%s\n", h5_file, xdmf_file);
    return CTL_OK;
}
