/*
 * stream.h - GET /stream: the case feed (cases/case_feed.h) as
 * Server-Sent Events (contract 6.3).
 *
 * Contract:
 *  - stream_start() starts the thread that wakes streams (a new event, a
 *    keep-alive every STREAM_KEEPALIVE_SECONDS); stream_stop() ends every
 *    open stream cleanly (its last chunk sent), waits at most
 *    STREAM_STOP_WAIT seconds for their clients to take it, and refuses
 *    new ones; it must run before libmicrohttpd stops, which may find no
 *    connection suspended.
 *  - stream_open() answers one GET /stream: 200 text/event-stream, or 400
 *    (a malformed ?case= or Last-Event-ID), 404 (?case= names no case and
 *    no Last-Event-ID asks for what it may have left in the feed), 503
 *    (--max-streams streams are open, or the daemon is stopping). An open
 *    stream holds no thread: its connection is suspended while it has
 *    nothing to send. It leaves the per-address count and the request
 *    deadline (gate.h); a client that reads nothing for
 *    STREAM_IDLE_TIMEOUT seconds is cut.
 */
#ifndef FDEMD_STREAM_H
#define FDEMD_STREAM_H

#include <microhttpd.h>

#define STREAM_KEEPALIVE_SECONDS 15.0
#define STREAM_IDLE_TIMEOUT 60   /* s a client may read nothing */
#define STREAM_STOP_WAIT 2.0

int stream_start(int max_streams);
void stream_stop(void);
enum MHD_Result stream_open(struct MHD_Connection *conn);

#endif
