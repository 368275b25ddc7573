/*
 * web.h - the daemon's web page (contract 6.3): GET / and its assets under
 * /ui/, served from the repository's web/ folder.
 *
 * Contract:
 *  - web_init() finds the folder once at start-up: --web DIR, else web/
 *    beside the bin/ folder the daemon runs from (bin/fdemd in a build tree
 *    serves ./web). A daemon without the folder still runs; its GET / is a
 *    404 that says where it looked.
 *  - web_path() says whether a request path is the page's ("/" or
 *    "/ui/..."); those routes need no token (the files hold no data: the
 *    page asks for the token and sends it on every API request).
 *  - web_reply() serves only regular files inside the folder whose path
 *    segments are plain names ([A-Za-z0-9_-] and dots, never a leading
 *    dot): "..", "%2e%2e", "%2F", a NUL or a symlink out of the folder is a
 *    404. Every file goes with Content-Security-Policy default-src 'self'
 *    (nothing from another host, no inline script), nosniff, no referrer,
 *    no framing.
 */
#ifndef FDEMD_WEB_H
#define FDEMD_WEB_H

#include <microhttpd.h>

/* `configured`: --web DIR, or "" for the default. 0, or -1 when the folder
 * is not there (the daemon goes on without its page). */
int web_init(const char *configured);
int web_path(const char *url);
enum MHD_Result web_reply(struct MHD_Connection *conn, const char *url);

#endif
