"""Hostile use of resources, third review (issue 30, contract 5.5): request
bodies no route reads. Each test failed
on the code before its fix (the commit that adds it says by how much).

RSS is read from /proc/PID/status; sanitizer builds keep freed memory in
quarantine, so there only the answers are checked."""
import json
import os
import socket
import threading
import time
import unittest

from fdemd_harness import SLOW, Daemon, DaemonTestCase, tiny_case
from test_hostile_input import problem_of
from test_hostile_requests import read_until_closed, status_of
from test_memory import RSS_MEANINGFUL, memory

MiB = 1 << 20


def send_head_then_body(port, head, body_size, piece=MiB):
    """Sends `head`, then `body_size` bytes of body (stopping if the daemon
    closes first), and reads the answer until the daemon closes."""
    s = socket.create_connection(("127.0.0.1", port), timeout=60 * SLOW)
    try:
        s.sendall(head)
        chunk = b"x" * piece
        sent = 0
        try:
            while sent < body_size:
                n = min(piece, body_size - sent)
                s.sendall(chunk[:n])
                sent += n
        except (BrokenPipeError, ConnectionResetError):
            pass
        return read_until_closed(s)
    finally:
        s.close()


class BodylessRouteTest(DaemonTestCase):
    """A body on a route that takes none (GET /health with 64 MiB) was
    buffered up to --max-upload, outside the memory budget: 48 such
    connections took the RSS to 3 GB. Now none of it is held."""
    BODY = 64 * MiB
    CLIENTS = 8

    def test_bodies_sent_to_get_health_are_refused_and_never_held(self):
        pid = self.d.proc.pid
        idle = memory(pid)
        head = (b"GET /health HTTP/1.1\r\nHost: x\r\nContent-Length: %d\r\n\r\n" % self.BODY)
        replies = [None] * self.CLIENTS

        def client(k):
            try:
                replies[k] = send_head_then_body(self.d.port, head, self.BODY)
            except OSError as e:
                replies[k] = repr(e).encode()
        threads = [threading.Thread(target=client, args=(k,)) for k in range(self.CLIENTS)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(120 * SLOW)
        peak = memory(pid)["VmHWM"]
        print("  %d x %d MiB bodies to GET /health: peak RSS %.1f MiB, idle %.1f MiB"
              % (self.CLIENTS, self.BODY // MiB, peak / MiB, idle["VmRSS"] / MiB))
        for reply in replies:
            self.assertEqual(status_of(reply), 413, reply[:300])
            _, _, problem = problem_of(reply)
            self.assertIn("takes no request body", problem["detail"])
        # A client that waits for 100-continue is answered before its body.
        s = socket.create_connection(("127.0.0.1", self.d.port), timeout=30 * SLOW)
        try:
            s.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\nExpect: 100-continue\r\n"
                      b"Content-Length: %d\r\n\r\n" % self.BODY)
            reply = read_until_closed(s)
        finally:
            s.close()
        self.assertEqual(status_of(reply), 413, reply[:300])
        # GET /health without a body still works.
        self.assertEqual(self.d.json("GET", "/health")[0], 200)
        if RSS_MEANINGFUL:
            # Each connection may hold libmicrohttpd's 64 KiB read buffer, no
            # more; 32 MiB covers that, thread arenas and allocator slack. The
            # old code held every body whole: 8 x 64 MiB.
            self.assertLess(peak, idle["VmHWM"] + 32 * MiB, "peak RSS %.0f MiB" % (peak / MiB))


if __name__ == "__main__":
    unittest.main()
