/*
 * download.h - GET /cases/ID/result.h5.
 *
 * Contract: download_reply() answers 200 with the file, or a problem:
 * 404 (no result file yet), 500 (damaged or unreadable, naming why), 503
 * with Retry-After (the copy a running case needs would leave less free
 * space in --data than the running cases will soon write), 507 (no room
 * for the copy at all). It never blocks the calling
 * HTTP thread, nor the I/O thread, for the length of a copy: a running
 * case's file is copied by a thread of its own while the response streams
 * the bytes already copied, and the case's writes wait only for that copy
 * (its other requests and other cases do not wait at all). With `head`
 * (a HEAD request) it answers the same headers, the size included, and
 * copies nothing; a copy whose client goes away is stopped and released.
 */
#ifndef FDEMD_DOWNLOAD_H
#define FDEMD_DOWNLOAD_H

#include <microhttpd.h>

#include "cases/registry.h"

enum MHD_Result download_reply(struct MHD_Connection *conn, server_case *c, int head);

#endif
