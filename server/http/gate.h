/*
 * gate.h - the thread that accepts connections and holds each one until
 * its request headers have arrived whole, before libmicrohttpd gets it.
 *
 * Contract:
 *  - gate_start() takes a bound, listening socket and serves it on its own
 *    thread. Each accepted connection is refused (503) when the daemon has
 *    `total` connections, or when its address has `per_ip` and none of
 *    them closes within a quarter of a second (GATE_SLOT_GRACE); it is
 *    cut (408) when its header block is not whole `timeout` seconds after it
 *    was accepted; it is answered (400, 401, 411, 413, 414, 431, 505) when
 *    the block frames its body ambiguously or is malformed (http_frame.h),
 *    and 400 when the client shuts its side before the block is whole. Every other connection is passed
 *    to `hand_over`, which owns the socket from then on.
 *  - The owner of a handed-over connection calls gate_closed(fd) before it
 *    closes the socket, so the per-address count stays true; it may call it
 *    earlier (once its one answer is sent), and a second call is a no-op.
 *  - A handed-over connection may carry several requests (keep-alive).
 *    gate_request_began(fd, &later) is when the request now at the daemon
 *    began (monotonic seconds: the accept for the first, the end of the
 *    last answer for a later one; *later says which), so the
 *    whole-request deadline can be applied to the body; the owner calls it
 *    when a request's headers are in, and gate_request_done(fd) when its
 *    answer is sent. Between the two calls the connection is the daemon's;
 *    from gate_request_done() on, the next request's headers must reach the
 *    daemon within `timeout`, or the gate shuts the socket down (the
 *    owner then closes it and calls gate_closed() as for any close).
 *  - gate_stream_began(fd): the connection now carries an event stream
 *    (GET /stream, stream.h), which lives as long as its client wants:
 *    it stops counting against its address's limit (it still counts in
 *    `total` until gate_closed). Its request is the daemon's, so the
 *    watchdog leaves it alone as it does every request being answered.
 *  - gate_stop() stops accepting, closes held connections and joins.
 */
#ifndef FDEMD_GATE_H
#define FDEMD_GATE_H

#include <netinet/in.h>

typedef int (*gate_hand_over)(int fd, const struct sockaddr_in *addr);

typedef struct gate_limits {
    int per_ip;        /* connections per client address */
    int total;         /* connections in all, held or handed over */
    double timeout;    /* seconds for a whole request */
    int token;         /* the daemon wants a bearer token (a NUL in one is a 401) */
} gate_limits;

int gate_start(int listen_fd, const gate_limits *limits, gate_hand_over hand_over);
void gate_stop(void);

void gate_closed(int fd);
double gate_request_began(int fd, int *later);
void gate_request_done(int fd);
void gate_stream_began(int fd);

/* Monotonic clock in seconds. */
double gate_now(void);

#endif
