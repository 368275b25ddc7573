/*
 * gate.c - accepts connections and admits a request to libmicrohttpd only
 * once its header block is whole and frames its body unambiguously.
 *
 * Why a gate in front of libmicrohttpd: its per-connection timeout bounds
 * inactivity only, so a client sending one header line every 20 s held a
 * slot for ever, and 130 such clients held them all; and it answers some
 * malformed framing wrongly (see http_frame.c). Here a connection costs no
 * libmicrohttpd slot until its headers have arrived, the deadline counts
 * from accept(), and the checks run on the bytes as received (MSG_PEEK, so
 * libmicrohttpd reads the request from the start as usual).
 *
 * One thread polls the listening socket and every held connection. The
 * per-address and total counts cover held and handed-over connections
 * alike; libmicrohttpd reports each close through gate_closed(), which
 * runs before it closes the socket, so a descriptor number is never reused
 * while its slot is still counted.
 *
 * Why the gate sets SO_RCVLOWAT on a connection whose headers are not
 * whole yet: it only peeks, so the bytes stay queued and poll() would
 * report the socket readable again at once, for ever: one client holding
 * half a header made this thread spin (31,800 poll+recv in 2 s, issue 30).
 * With the low-water mark one byte above what has been seen, poll() wakes
 * only for new bytes, a hang-up or the deadline; the mark goes back to 1
 * before libmicrohttpd gets the socket.
 *
 * Keep-alive. The gate reads only a connection's first request; later
 * ones on a kept-alive connection go straight to libmicrohttpd. So the
 * gate keeps a watchdog on every handed-over connection between requests
 * (from its answer, gate_request_done(), to the next request's headers,
 * gate_request_began()): past the request timeout it shuts the socket
 * down, which bounds a client trickling its next request's headers as the
 * held connections are bounded, and closes idle kept-alive connections;
 * http.c checks a later request's framing on its parsed fields. Before,
 * every answer closed its connection: 7,400 requests/s where keep-alive
 * had given 21,600.
 *
 * Why a connection over its address's limit waits a moment before its 503:
 * a client that closes after each answer and keeps N
 * connections busy opens the next one as soon as it has read an answer,
 * while the server side counts the old one until libmicrohttpd reports it
 * done, a moment later. Refusing at once turned that moment into 503s for
 * a client within its limit (9 % of the requests of 4 connections under
 * --max-connections-per-ip 4), so such a connection waits, uncounted and
 * unread, up to GATE_SLOT_GRACE for a slot of its address to free.
 */
#define _GNU_SOURCE /* accept4, pipe2: the flags come with the descriptor, no race */
#include "gate.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <jansson.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "http_frame.h"
#include "math/clock.h"

#define GATE_HEAD_MAX (32 * 1024) /* larger header blocks get 431 */
#define GATE_MAX_SLOTS 65536      /* descriptors the gate can track */
#define GATE_SLOT_GRACE 0.25      /* seconds an over-limit connection waits */

typedef struct gate_slot {
    uint32_t ip;       /* network order */
    double began;      /* accepted, or the end of its last request (kept alive) */
    int live;          /* counted in gate_ips */
    int idle;          /* handed over and between requests: the watchdog's */
    int requests;      /* answered on it so far */
    int stream;        /* an event stream now: no longer counted for its address */
} gate_slot;

typedef struct gate_ip {
    uint32_t ip;
    int count;
} gate_ip;

typedef struct gate_held {
    int fd;
    struct sockaddr_in addr;
    double accepted;
    double deadline;   /* whole headers by then; a waiting one: its 503 */
    int waiting;       /* not counted yet: its address was at its limit */
    int lowat;         /* SO_RCVLOWAT set on it (1: the socket's default) */
} gate_held;

static struct {
    pthread_t thread;
    int running;
    int listen_fd, wake[2];   /* a byte on wake: stopping, or a slot freed */
    atomic_int stopping;
    gate_limits limits;
    gate_hand_over hand_over;
    gate_held *held;          /* only the gate thread touches these two */
    int held_count;
    pthread_mutex_t lock;     /* guards what follows: shared with MHD threads */
    gate_slot *slots;
    int slot_count, slot_high; /* slots[0 .. slot_high) have been used */
    gate_ip *ips;             /* addresses with a connection, unordered */
    int ip_count, total;
    int waiting;              /* held connections waiting for a slot */
} gate = {.lock = PTHREAD_MUTEX_INITIALIZER, .listen_fd = -1, .wake = {-1, -1}};

double gate_now(void)
{
    return clock_wall_seconds();
}

/* ------------------------------------------------------------ counting */

static gate_ip *gate_find_ip(uint32_t ip)
{
    for (int i = 0; i < gate.ip_count; i++)
        if (gate.ips[i].ip == ip) return &gate.ips[i];
    return NULL;
}

static const char GATE_ALL_FULL[] =
    "the daemon has as many connections open as it serves; try again shortly";
static const char GATE_PER_IP_FULL[] =
    "your address has as many connections open as it may "
    "(--max-connections-per-ip); close one or try again shortly";

/* Counts a new connection; 0 when a limit refuses it (with the reason:
 * GATE_PER_IP_FULL when it is its address's limit). */
static int gate_admit(int fd, uint32_t ip, double now, const char **why)
{
    int ok = 0;
    pthread_mutex_lock(&gate.lock);
    gate_ip *entry = gate_find_ip(ip);
    if (fd >= gate.slot_count || gate.total >= gate.limits.total) {
        *why = GATE_ALL_FULL;
    } else if (entry && entry->count >= gate.limits.per_ip) {
        *why = GATE_PER_IP_FULL;
    } else {
        if (!entry) {
            entry = &gate.ips[gate.ip_count++];
            entry->ip = ip;
            entry->count = 0;
        }
        entry->count++;
        gate.total++;
        gate.slots[fd] = (gate_slot){ip, now, 1, 0, 0, 0};
        if (fd >= gate.slot_high) gate.slot_high = fd + 1;
        ok = 1;
    }
    pthread_mutex_unlock(&gate.lock);
    return ok;
}

/* One connection of address `ip` less; a connection waiting for a slot
 * of its address may take it. With the lock held. */
static void gate_uncount_ip_locked(uint32_t ip)
{
    gate_ip *entry = gate_find_ip(ip);
    if (entry && --entry->count == 0) *entry = gate.ips[--gate.ip_count];
    if (gate.waiting > 0) (void)!write(gate.wake[1], "", 1);
}

void gate_closed(int fd)
{
    pthread_mutex_lock(&gate.lock);
    if (fd >= 0 && fd < gate.slot_count && gate.slots[fd].live) {
        gate.slots[fd].live = 0;
        gate.total--;
        if (!gate.slots[fd].stream) gate_uncount_ip_locked(gate.slots[fd].ip);
        gate.slots[fd].stream = 0;
    }
    pthread_mutex_unlock(&gate.lock);
}

void gate_stream_began(int fd)
{
    pthread_mutex_lock(&gate.lock);
    if (fd >= 0 && fd < gate.slot_count && gate.slots[fd].live && !gate.slots[fd].stream) {
        gate.slots[fd].stream = 1;
        gate_uncount_ip_locked(gate.slots[fd].ip);
    }
    pthread_mutex_unlock(&gate.lock);
}

double gate_request_began(int fd, int *later)
{
    double t = 0;
    *later = 0;
    pthread_mutex_lock(&gate.lock);
    if (fd >= 0 && fd < gate.slot_count && gate.slots[fd].live) {
        gate_slot *slot = &gate.slots[fd];
        t = slot->began;
        *later = slot->requests > 0;
        slot->idle = 0;
    }
    pthread_mutex_unlock(&gate.lock);
    return t;
}

void gate_request_done(int fd)
{
    pthread_mutex_lock(&gate.lock);
    if (fd >= 0 && fd < gate.slot_count && gate.slots[fd].live) {
        gate_slot *slot = &gate.slots[fd];
        slot->requests++;
        slot->idle = 1;
        slot->began = gate_now();
    }
    pthread_mutex_unlock(&gate.lock);
}

/* The watchdog of kept-alive connections: one whose next request has not
 * reached the daemon `timeout` seconds after its last answer is shut
 * down (libmicrohttpd then sees the end of the stream, closes it and
 * reports the close through gate_closed()); an idle one is closed as
 * keep-alive servers do. Not closed here: the descriptor is
 * libmicrohttpd's, and it must not be reused while it still holds it.
 * Returns the seconds until the next such deadline (1 when none). */
static double gate_cut_idle_kept(double now)
{
    double wait = 1.0;
    pthread_mutex_lock(&gate.lock);
    for (int fd = 0; fd < gate.slot_high; fd++) {
        gate_slot *slot = &gate.slots[fd];
        if (!slot->live || !slot->idle) continue;
        double left = slot->began + gate.limits.timeout - now;
        if (left > 0) {
            if (left < wait) wait = left;
            continue;
        }
        slot->idle = 0;
        shutdown(fd, SHUT_RDWR);
    }
    pthread_mutex_unlock(&gate.lock);
    return wait;
}

/* -------------------------------------------------------------- answers */

static const char *gate_reason(int status)
{
    switch (status) {
    case 400: return "Bad Request";
    case 401: return "Unauthorized";
    case 408: return "Request Timeout";
    case 411: return "Length Required";
    case 413: return "Payload Too Large";
    case 414: return "URI Too Long";
    case 431: return "Request Header Fields Too Large";
    case 505: return "HTTP Version Not Supported";
    default: return "Service Unavailable";
    }
}

/* Reads what the client already sent, so that closing the socket sends a
 * FIN after the answer rather than a reset that could discard it. */
static void gate_drain(int fd)
{
    char sink[4096];
    for (int i = 0; i < 64 && recv(fd, sink, sizeof sink, MSG_DONTWAIT) > 0; i++)
        ;
}

/* Sends one whole problem+json answer (best effort: the socket is
 * non-blocking and the answer small) and closes the connection. */
static void gate_answer_and_close(int fd, int status, const char *title, const char *detail)
{
    gate_drain(fd);
    json_t *body = json_pack("{s:s, s:s, s:i, s:s, s:[]}", "type", "about:blank", "title",
                             title, "status", status, "detail", detail, "errors");
    char *text = body ? json_dumps(body, JSON_COMPACT) : NULL;
    json_decref(body);
    char head[256];
    int n = snprintf(head, sizeof head,
                     "HTTP/1.1 %d %s\r\nContent-Type: application/problem+json\r\n"
                     "Cache-Control: no-store\r\nConnection: close\r\n%s"
                     "Content-Length: %zu\r\n\r\n",
                     status, gate_reason(status),
                     status == 503   ? "Retry-After: 1\r\n"
                     : status == 401 ? "WWW-Authenticate: Bearer realm=\"fdemd\"\r\n"
                                     : "",
                     text ? strlen(text) : 0);
    if (send(fd, head, (size_t)n, MSG_NOSIGNAL | MSG_DONTWAIT) == n && text)
        (void)!send(fd, text, strlen(text), MSG_NOSIGNAL | MSG_DONTWAIT);
    free(text);
    shutdown(fd, SHUT_WR);
    gate_closed(fd);
    close(fd);
}

/* -------------------------------------------------------- held requests */

static void gate_release(int index)
{
    if (gate.held[index].waiting) {
        pthread_mutex_lock(&gate.lock);
        gate.waiting--;
        pthread_mutex_unlock(&gate.lock);
    }
    gate.held[index] = gate.held[--gate.held_count];
}

/* Connections from `ip` waiting for a slot (an address may not park more
 * than its limit, so the queue cannot be one client's to fill). */
static int gate_waiting_from(uint32_t ip)
{
    int n = 0;
    for (int i = 0; i < gate.held_count; i++)
        n += gate.held[i].waiting && gate.held[i].addr.sin_addr.s_addr == ip;
    return n;
}

/* Parks connection fd, refused for its address's limit, to wait for a
 * slot; 0 when it may not wait either. */
static int gate_park(int fd, const struct sockaddr_in *addr, double now)
{
    if (gate.held_count >= gate.limits.total ||
        gate_waiting_from(addr->sin_addr.s_addr) >= gate.limits.per_ip)
        return 0;
    pthread_mutex_lock(&gate.lock);
    gate.waiting++;
    pthread_mutex_unlock(&gate.lock);
    gate.held[gate.held_count++] = (gate_held){fd, *addr, now, now + GATE_SLOT_GRACE, 1, 1};
    return 1;
}

/* Counts the waiting connections whose address has a free slot again and
 * refuses those whose grace has run out. */
static void gate_admit_waiting(double now)
{
    for (int i = gate.held_count - 1; i >= 0; i--) {
        gate_held *h = &gate.held[i];
        if (!h->waiting) continue;
        const char *why = NULL;
        if (gate_admit(h->fd, h->addr.sin_addr.s_addr, h->accepted, &why)) {
            pthread_mutex_lock(&gate.lock);
            gate.waiting--;
            pthread_mutex_unlock(&gate.lock);
            h->waiting = 0;
            h->deadline = h->accepted + gate.limits.timeout;
        } else if (now >= h->deadline) {
            int fd = h->fd;
            gate_release(i);
            gate_answer_and_close(fd, 503, "Too many connections", why);
        }
    }
}

/* Makes poll() report fd readable only once `lowat` bytes are queued (one
 * more than were seen: see the top of the file). Returns the mark now in
 * force (1, the default, if it could not be set). */
static int gate_set_lowat(int fd, int lowat)
{
    return setsockopt(fd, SOL_SOCKET, SO_RCVLOWAT, &lowat, sizeof lowat) == 0 ? lowat : 1;
}

/* Looks at what has arrived on held connection `index` (poll() said
 * `revents`); returns 1 when the connection left the gate (answered,
 * closed or handed over). */
static int gate_examine(int index, short revents)
{
    static char buf[GATE_HEAD_MAX];
    gate_held h = gate.held[index];
    ssize_t n = recv(h.fd, buf, sizeof buf, MSG_PEEK | MSG_DONTWAIT);
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return 0;
    if (n <= 0) { /* closed by the client, or broken */
        gate_release(index);
        gate_closed(h.fd);
        close(h.fd);
        return 1;
    }
    size_t end = http_frame_head_end(buf, (size_t)n);
    if (!end) {
        if ((size_t)n < sizeof buf && !(revents & (POLLRDHUP | POLLHUP | POLLERR))) {
            gate.held[index].lowat = gate_set_lowat(h.fd, (int)n + 1);
            return 0;
        }
        gate_release(index);
        if ((size_t)n < sizeof buf) /* no more can come: the client shut its side */
            gate_answer_and_close(h.fd, 400, "Bad request",
                                  "the connection was closed before the request headers "
                                  "were complete");
        else
            gate_answer_and_close(h.fd, 431, "Request header fields too large",
                                  "the request line and headers exceed 32 KiB");
        return 1;
    }
    http_frame_verdict v;
    gate_release(index);
    if (http_frame_check(buf, end, &v)) {
        if (v.nul_in_credentials && gate.limits.token)
            gate_answer_and_close(h.fd, 401, "Unauthorized",
                                  "the Authorization header holds a NUL byte, so it is no "
                                  "bearer token of this daemon");
        else
            gate_answer_and_close(h.fd, v.status, v.title, v.detail);
        return 1;
    }
    if (h.lowat != 1) gate_set_lowat(h.fd, 1);
    /* on failure the new owner has closed the socket without telling us */
    if (!gate.hand_over(h.fd, &h.addr)) gate_closed(h.fd);
    return 1;
}

/* Closes the connection that has waited longest for its headers, to make
 * room for a new one when every slot is taken; 0 when none is waiting for
 * headers (every slot is a request being served). Idle connections are
 * cut first: one sending its headers takes milliseconds, so the oldest
 * held one is the likeliest to be a client holding a slot on purpose
 * (16 idle connections from each of 33 addresses filled all 512 slots,
 * and everyone else got 503 for as long as they kept them). */
static int gate_cut_oldest_idle(void)
{
    int oldest = -1;
    for (int i = 0; i < gate.held_count; i++)
        if (!gate.held[i].waiting &&
            (oldest < 0 || gate.held[i].accepted < gate.held[oldest].accepted))
            oldest = i;
    if (oldest < 0) return 0;
    int fd = gate.held[oldest].fd;
    gate_release(oldest);
    gate_answer_and_close(fd, 408, "Request timeout",
                          "every connection slot was taken and this connection had waited "
                          "longest without sending whole request headers");
    return 1;
}

static void gate_accept_all(void)
{
    for (;;) {
        struct sockaddr_in addr;
        socklen_t len = sizeof addr;
        int fd = accept4(gate.listen_fd, (struct sockaddr *)&addr, &len,
                         SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0) return; /* EAGAIN, or out of descriptors until some close */
        double now = gate_now();
        const char *why = NULL;
        int admitted = addr.sin_family == AF_INET && gate.held_count < gate.limits.total &&
                       gate_admit(fd, addr.sin_addr.s_addr, now, &why);
        if (!admitted && addr.sin_family == AF_INET && why != GATE_PER_IP_FULL &&
            gate_cut_oldest_idle()) {
            why = NULL;
            admitted = gate_admit(fd, addr.sin_addr.s_addr, now, &why);
        }
        if (!admitted) {
            if (why == GATE_PER_IP_FULL && gate_park(fd, &addr, now)) continue;
            gate_answer_and_close(fd, 503, "Too many connections",
                                  why ? why : "too many connections are waiting for headers");
            continue;
        }
        gate.held[gate.held_count++] =
            (gate_held){fd, addr, now, now + gate.limits.timeout, 0, 1};
    }
}

static void gate_cut_late(double now)
{
    char detail[160];
    snprintf(detail, sizeof detail,
             "the request headers did not arrive whole within %g s (--request-timeout)",
             gate.limits.timeout);
    for (int i = gate.held_count - 1; i >= 0; i--)
        if (!gate.held[i].waiting && now >= gate.held[i].deadline) {
            int fd = gate.held[i].fd;
            gate_release(i);
            gate_answer_and_close(fd, 408, "Request timeout", detail);
        }
}

static void *gate_main(void *arg)
{
    (void)arg;
    int cap = gate.limits.total + 2;
    struct pollfd *fds = calloc((size_t)cap, sizeof *fds);
    if (!fds) {
        fprintf(stderr, "fdemd: gate: out of memory\n");
        return NULL;
    }
    for (;;) {
        double now = gate_now(), wait = gate_cut_idle_kept(now);
        fds[0] = (struct pollfd){.fd = gate.wake[0], .events = POLLIN};
        fds[1] = (struct pollfd){.fd = gate.listen_fd, .events = POLLIN};
        for (int i = 0; i < gate.held_count; i++) {
            /* a waiting connection is not read before it is counted */
            int fd = gate.held[i].waiting ? -1 : gate.held[i].fd;
            fds[2 + i] = (struct pollfd){.fd = fd, .events = POLLIN | POLLRDHUP};
            if (gate.held[i].deadline - now < wait) wait = gate.held[i].deadline - now;
        }
        int polled = gate.held_count;
        int ms = wait > 0 ? (int)(wait * 1000) + 1 : 0;
        if (poll(fds, (nfds_t)(2 + polled), ms) < 0 && errno != EINTR) break;
        if (fds[0].revents) {
            char sink[256];
            while (read(gate.wake[0], sink, sizeof sink) > 0)
                ;
        }
        if (gate.stopping) break;
        /* backwards, since gate_release() moves the last entry into i */
        for (int i = polled - 1; i >= 0; i--)
            if (fds[2 + i].revents) gate_examine(i, fds[2 + i].revents);
        gate_cut_late(gate_now());
        gate_admit_waiting(gate_now());
        if (fds[1].revents) gate_accept_all();
    }
    free(fds);
    return NULL;
}

/* ------------------------------------------------------------ lifecycle */

int gate_start(int listen_fd, const gate_limits *limits, gate_hand_over hand_over)
{
    struct rlimit rl;
    int slots = GATE_MAX_SLOTS;
    if (getrlimit(RLIMIT_NOFILE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY &&
        rl.rlim_cur < (rlim_t)slots)
        slots = (int)rl.rlim_cur;
    gate.limits = *limits;
    gate.hand_over = hand_over;
    gate.stopping = 0;
    gate.listen_fd = listen_fd;
    gate.slots = calloc((size_t)slots, sizeof *gate.slots);
    gate.ips = calloc((size_t)limits->total, sizeof *gate.ips);
    gate.held = calloc((size_t)limits->total, sizeof *gate.held);
    gate.slot_count = slots;
    if (!gate.slots || !gate.ips || !gate.held || pipe2(gate.wake, O_CLOEXEC | O_NONBLOCK) != 0 ||
        pthread_create(&gate.thread, NULL, gate_main, NULL) != 0) {
        fprintf(stderr, "fdemd: cannot start the connection gate: %s\n", strerror(errno));
        gate_stop();
        return -1;
    }
    gate.running = 1;
    return 0;
}

void gate_stop(void)
{
    if (gate.running) {
        gate.stopping = 1;
        (void)!write(gate.wake[1], "", 1);
        pthread_join(gate.thread, NULL);
        gate.running = 0;
    }
    for (int i = 0; i < gate.held_count; i++) close(gate.held[i].fd);
    gate.held_count = 0;
    /* under the lock: gate_closed() may still run on libmicrohttpd's
     * threads, and must not write to a reused descriptor number */
    pthread_mutex_lock(&gate.lock);
    gate.waiting = 0;
    for (int k = 0; k < 2; k++)
        if (gate.wake[k] >= 0) close(gate.wake[k]);
    gate.wake[0] = gate.wake[1] = -1;
    pthread_mutex_unlock(&gate.lock);
    if (gate.listen_fd >= 0) close(gate.listen_fd);
    gate.listen_fd = -1;
    free(gate.held);
    gate.held = NULL;
}
