#!/usr/bin/env python3
"""HTTP load figure for `make bench`: latency (p50, p99) and requests/s of
GET /cases/ID against bin/fdemd on loopback while four cases step, then
the same with 64 event streams (GET /stream) open and read meanwhile; and
first what a small case's snapshot writes cost as their number grows.

Uses wrk when installed (2 threads, 8 connections, 5 s; once with keep-alive and
once with a connection per request, Connection: close), else a bounded
Python client (4 threads x 500 requests). Never part of the tests.

    FDEMD_BIN=bin/fdemd /usr/bin/python3 bench/bench_http.py
"""
import http.client
import os
import re
import select
import shutil
import socket
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "integration"))
from fdemd_harness import Daemon, tiny_case  # noqa: E402

WRK_SECONDS = 5
PY_THREADS, PY_REQUESTS = 4, 500


def wrk_figures(url, close=False):
    extra = ["-H", "Connection: close"] if close else []
    out = subprocess.run(["wrk", "-t2", "-c8", "-d%ds" % WRK_SECONDS, "--latency"] + extra + [url],
                         capture_output=True, text=True, timeout=WRK_SECONDS + 30).stdout
    unit = {"us": 1e-3, "ms": 1.0, "s": 1e3}

    def pct(p):
        m = re.search(r"^\s*%d%%\s+([\d.]+)(us|ms|s)\s*$" % p, out, re.M)
        return float(m.group(1)) * unit[m.group(2)] if m else float("nan")

    rate = re.search(r"Requests/sec:\s+([\d.]+)", out)
    errors = re.search(r"Non-2xx or 3xx responses: (\d+)", out)
    return pct(50), pct(99), float(rate.group(1)) if rate else float("nan"), \
        int(errors.group(1)) if errors else 0, \
        "wrk -t2 -c8 -d%ds%s" % (WRK_SECONDS, ", Connection: close" if close else ", keep-alive")


def python_figures(port, ids):
    latencies, bad = [], [0]
    lock = threading.Lock()

    def client(k):
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        mine = []
        for i in range(PY_REQUESTS):
            t0 = time.perf_counter()
            conn.request("GET", "/cases/" + ids[(k + i) % len(ids)])
            resp = conn.getresponse()
            resp.read()
            mine.append(time.perf_counter() - t0)
            if resp.status != 200:
                bad[0] += 1
        conn.close()
        with lock:
            latencies.extend(mine)

    threads = [threading.Thread(target=client, args=(k,)) for k in range(PY_THREADS)]
    t0 = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    elapsed = time.perf_counter() - t0
    latencies.sort()
    return (1e3 * latencies[len(latencies) // 2], 1e3 * latencies[int(0.99 * len(latencies)) - 1],
            len(latencies) / elapsed, bad[0], "python %dx%d" % (PY_THREADS, PY_REQUESTS))


STREAMS = 64


class OpenStreams:
    """STREAMS connections on GET /stream, drained by one thread (a stream
    whose client reads nothing would only measure the socket buffers)."""

    def __init__(self, port):
        self.socks, self.received, self.stopping = [], 0, False
        for _ in range(STREAMS):
            s = socket.create_connection(("127.0.0.1", port), timeout=10)
            s.sendall(b"GET /stream HTTP/1.1\r\nHost: bench\r\n\r\n")
            head = s.recv(4096)
            if not head.startswith(b"HTTP/1.1 200"):
                raise RuntimeError("GET /stream answered %r" % head[:80])
            s.setblocking(False)
            self.socks.append(s)
        self.thread = threading.Thread(target=self._drain)
        self.thread.start()

    def _drain(self):
        while not self.stopping:
            ready, _, _ = select.select(self.socks, [], [], 0.2)
            for s in ready:
                try:
                    self.received += len(s.recv(65536))
                except OSError:
                    pass

    def close(self):
        self.stopping = True
        self.thread.join()
        for s in self.socks:
            s.close()


def report(d, ids, runs, streams):
    for p50, p99, rate, bad, how in runs:
        steps = sum(d.status(i)["steps_per_second"] for i in ids)
        print("http GET /cases/ID (4 cases running, %d streams open, %s): p50 %.3f ms, p99 "
              "%.3f ms, %.0f requests/s, %d non-200; cases stepped %.3g steps/s in total "
              "meanwhile" % (streams, how, p50, p99, rate, bad, steps))


def snapshot_write_figures():
    """Wall seconds a snapshot of a small case takes to become durable
    (result.h5 row, checkpoint, status, the XDMF sidecar), by how many the
    run writes: a cost that grows with the count (the sidecar rewritten
    whole after each, before 2026-12-07: 1.6 ms a snapshot at 41 and 4.2
    at 161) shows here, and the run-time estimate prices one figure."""
    d = Daemon(args=["--max-running", "1"]).start()
    try:
        for snapshots in (40, 160, 640):
            end = 1e-3
            case_id = d.create(tiny_case("writes%d" % snapshots, end=end,
                                         interval=end / snapshots), start=True)["id"]
            d.wait_state(case_id, ("finished",), timeout=600)
            st = d.status(case_id)
            print("snapshot writes, a 200-triangle case: %d snapshots in %.3f s of its run, "
                  "%.2f ms each" % (st["snapshots"], st["elapsed"],
                                    1e3 * st["elapsed"] / st["snapshots"]))
        d.stop()
    finally:
        d.close()


def main():
    snapshot_write_figures()
    d = Daemon(args=["--max-running", "4"]).start()
    try:
        ids = [d.create(tiny_case("bench%d" % i, end=100.0, interval=1e-3), start=True)["id"]
               for i in range(4)]
        url = "http://127.0.0.1:%d/cases/%s" % (d.port, ids[0])

        def measure():
            # keep-alive (what clients that reuse a connection get), then a
            # connection per request (what each passes through the gate)
            return [wrk_figures(url), wrk_figures(url, close=True)] if shutil.which("wrk") \
                else [python_figures(d.port, ids)]
        report(d, ids, measure(), 0)
        streams = OpenStreams(d.port)
        try:
            report(d, ids, measure(), STREAMS)
        finally:
            streams.close()
        print("http: the %d streams read %.0f kB of events meanwhile" %
              (STREAMS, streams.received / 1e3))
        d.stop()
    finally:
        d.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
