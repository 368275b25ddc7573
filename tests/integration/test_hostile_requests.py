"""Hostile requests (issue 11, contract 5.5): a case document built to make
validation expensive, slow clients that hold connections, and malformed
framing headers. Each must end with a prompt, clean answer while other
clients keep being served. Raw sockets are used where http.client would
refuse to send what a hostile client sends."""
import http.client
import json
import random
import re
import socket
import threading
import time
import unittest

from fdemd_harness import SLOW, DaemonTestCase, tiny_case


def raw_exchange(port, data, timeout=10.0, source="127.0.0.1"):
    """Sends `data` on a fresh connection and reads until the daemon closes.
    Returns (bytes received, seconds until the close)."""
    s = socket.socket()
    s.settimeout(timeout * SLOW)
    try:
        s.bind((source, 0))
        s.connect(("127.0.0.1", port))
        t0 = time.monotonic()
        s.sendall(data)
        reply = read_until_closed(s)
        return reply, time.monotonic() - t0
    finally:
        s.close()


def read_until_closed(s):
    reply = b""
    try:
        while True:
            chunk = s.recv(65536)
            if not chunk:
                break
            reply += chunk
    except ConnectionResetError:
        pass
    except socket.timeout:
        reply += b"<no close before the timeout>"
    return reply


def read_head(s):
    """Reads until the end of a reply's header block (or a close): the head,
    with whatever of the body came in the same reads."""
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = s.recv(65536)
        if not chunk:
            break
        head += chunk
    return head


def status_of(reply):
    return int(reply.split(b" ", 2)[1]) if reply.startswith(b"HTTP/1.1 ") else None


def unknown_material_case(parts=1024, materials=1500, seed=11):
    """Every part names an unknown 64-character material among 1500 other
    64-character ones: the worst case for a 'did you mean' search that
    compares every pair (~6e9 edit-distance cells, tens of seconds)."""
    rnd = random.Random(seed)
    letters = "abcdefghijklmnopqrstuvwxyz0123456789"

    def word():
        return "".join(rnd.choice(letters) for _ in range(64))

    return {
        "materials": {word(): {"density": 2700, "young": 3e10, "poisson": 0.25}
                      for _ in range(materials)},
        "parts": [{"name": "p%d" % i, "material": word(),
                   "rectangle": {"size": [1, 1], "divisions": [1, 1]}} for i in range(parts)],
        "time": {"end": 0.001},
    }


class ExpensiveValidationTest(DaemonTestCase):
    def post_timed(self, body):
        t0 = time.monotonic()
        status, headers, data = self.d.request("POST", "/cases", body,
                                               headers={"Content-Type": "application/json"})
        return status, json.loads(data), time.monotonic() - t0

    def test_unknown_names_are_checked_in_bounded_time(self):
        body = json.dumps(unknown_material_case()).encode()
        self.assertGreater(len(body), 300 << 10)
        status, problem, seconds = self.post_timed(body)
        self.assertEqual(status, 422)
        self.assertLess(seconds, 1.5 * SLOW, "validation took %.1f s" % seconds)
        self.assertIn("1024 problems", problem["detail"])
        self.assertIn("first 100 are listed", problem["detail"])
        self.assertEqual(len(problem["errors"]), 100)
        self.assertEqual(problem["errors"][0]["pointer"], "/parts/0/material")
        self.assertIn("unknown material", problem["errors"][0]["message"])

    def test_a_typo_still_gets_its_suggestion(self):
        case = unknown_material_case(parts=2, materials=3)
        case["materials"]["granite"] = {"density": 2700, "young": 3e10, "poisson": 0.25}
        case["parts"][1]["material"] = "granit"
        status, problem, _ = self.post_timed(json.dumps(case).encode())
        self.assertEqual(status, 422)
        messages = {e["pointer"]: e["message"] for e in problem["errors"]}
        self.assertIn('did you mean "granite"', messages["/parts/1/material"])

    def test_health_answers_while_several_are_checked(self):
        body = json.dumps(unknown_material_case()).encode()
        answers = []

        def post():
            try:
                answers.append(self.post_timed(body)[0])
            except OSError as e:  # a timeout is a failure, reported below
                answers.append(repr(e))

        threads = [threading.Thread(target=post) for _ in range(8)]
        for t in threads:
            t.start()
        t0 = time.monotonic()
        status, _, _ = self.d.request("GET", "/health")
        health_seconds = time.monotonic() - t0
        for t in threads:
            t.join(60 * SLOW)
        self.assertEqual(status, 200)
        self.assertLess(health_seconds, 1.0 * SLOW, "/health took %.1f s" % health_seconds)
        self.assertEqual(answers, [422] * 8)


class FramingTest(DaemonTestCase):
    """Content-Length and Transfer-Encoding forms libmicrohttpd mishandled:
    each must get exactly one prompt, clean answer and create nothing."""

    def case_count(self):
        status, body = self.d.json("GET", "/cases")
        self.assertEqual(status, 200)
        return len(body["cases"]) if isinstance(body, dict) else len(body)

    def assertOneProblem(self, reply, status, seconds, words=()):
        self.assertLess(seconds, 2.0 * SLOW, "answered after %.1f s" % seconds)
        self.assertEqual(reply.count(b"HTTP/1.1 "), 1, reply[:400])
        self.assertEqual(status_of(reply), status, reply[:400])
        head, _, body = reply.partition(b"\r\n\r\n")
        self.assertIn(b"application/problem+json", head)
        problem = json.loads(body)
        self.assertEqual(problem["status"], status)
        for w in words:
            self.assertIn(w, problem["detail"])

    def post_raw(self, headers, body=b""):
        request = (b"POST /cases HTTP/1.1\r\nHost: x\r\n" + b"".join(h + b"\r\n" for h in headers)
                   + b"Connection: close\r\n\r\n" + body)
        return raw_exchange(self.d.port, request)

    def test_malformed_content_length_gets_one_400(self):
        before = self.case_count()
        for value in (b"-1", b"0x10", b"+2", b"8 ", b"", b"8, 8", b"1e3"):
            reply, seconds = self.post_raw([b"Content-Length: " + value], b"{}")
            self.assertOneProblem(reply, 400, seconds, ["Content-Length"])
        self.assertEqual(self.case_count(), before)

    def test_disagreeing_content_lengths_are_refused(self):
        body = json.dumps(tiny_case("smuggled")).encode()
        before = self.case_count()
        reply, seconds = self.post_raw([b"Content-Length: %d" % len(body), b"Content-Length: 2"], body)
        self.assertOneProblem(reply, 400, seconds, ["disagree"])
        self.assertEqual(self.case_count(), before)
        # the same length twice frames the body unambiguously: accepted
        reply, _ = self.post_raw([b"Content-Length: %d" % len(body)] * 2, body)
        self.assertEqual(status_of(reply), 201, reply[:300])

    def test_transfer_encoding_with_length_answers_at_once(self):
        body = json.dumps(tiny_case("identity")).encode()
        reply, seconds = self.post_raw([b"Transfer-Encoding: identity",
                                        b"Content-Length: %d" % len(body)], body)
        self.assertOneProblem(reply, 400, seconds, ["Content-Length alone"])
        reply, seconds = self.post_raw([b"Transfer-Encoding: identity"], body)
        self.assertOneProblem(reply, 411, seconds, ["Content-Length"])

    def test_folded_or_spaced_length_is_refused(self):
        for headers in ([b"Content-Length:", b" 2"], [b"Content-Length : 2"]):
            reply, seconds = self.post_raw(headers, b"{}")
            self.assertOneProblem(reply, 400, seconds)


class BusyClientTest(DaemonTestCase):
    """A client within --max-connections-per-ip is always served: every
    answer closes its connection, and a client keeping all its allowed
    connections busy opens the next one the moment it has read an answer,
    before the daemon has finished counting the old one. Refusing that
    connection at once gave ~9 % 503s to 4 connections under a limit of 4."""
    PER_IP = 2
    DAEMON_ARGS = ("--max-connections-per-ip", str(PER_IP))
    REQUESTS = 400  # per connection thread

    def test_a_client_using_all_its_connections_gets_no_503(self):
        statuses, lock = [], threading.Lock()

        def client():
            mine = []
            for _ in range(self.REQUESTS):
                conn = http.client.HTTPConnection("127.0.0.1", self.d.port, timeout=10 * SLOW)
                conn.request("GET", "/health")
                resp = conn.getresponse()
                resp.read()  # the whole answer (Content-Length), then at once the next
                conn.close()
                mine.append(resp.status)
            with lock:
                statuses.extend(mine)

        threads = [threading.Thread(target=client) for _ in range(self.PER_IP)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        refused = sum(1 for s in statuses if s != 200)
        self.assertEqual(len(statuses), self.PER_IP * self.REQUESTS)
        self.assertEqual(refused, 0, "%d of %d requests were not answered 200 (%s)" %
                         (refused, len(statuses), sorted(set(statuses))))


class SlowClientTest(DaemonTestCase):
    """Slowloris: clients that trickle a request must not hold connections
    past --request-timeout, nor more than --max-connections-per-ip each."""
    TIMEOUT = 2
    PER_IP = 4
    DAEMON_ARGS = ("--request-timeout", str(TIMEOUT), "--max-connections-per-ip", str(PER_IP))

    def connect(self, source="127.0.0.1"):
        s = socket.socket()
        s.settimeout(10 * SLOW)
        s.bind((source, 0))
        s.connect(("127.0.0.1", self.d.port))
        return s

    def trickle(self, s, first, piece, every, limit):
        """Sends `first`, then `piece` every `every` s until the daemon
        closes or `limit` s pass. Returns (reply, seconds alive)."""
        t0 = time.monotonic()
        s.sendall(first)
        s.settimeout(every)
        reply = b""
        while time.monotonic() - t0 < limit:
            try:
                chunk = s.recv(65536)
                if not chunk:
                    break
                reply += chunk
            except socket.timeout:
                try:
                    s.sendall(piece)
                except (BrokenPipeError, ConnectionResetError):
                    break
            except ConnectionResetError:
                break
        return reply, time.monotonic() - t0

    def test_trickled_header_is_cut_at_the_deadline(self):
        with self.connect() as s:
            reply, alive = self.trickle(s, b"GET /health HTTP/1.1\r\nHost: x\r\n", b"X-Slow: 1\r\n",
                                        0.3, 10 * SLOW)
        self.assertLess(alive, self.TIMEOUT + 1.5 * SLOW, "the connection lived %.1f s" % alive)
        self.assertGreater(alive, self.TIMEOUT - 0.5)
        self.assertEqual(status_of(reply), 408, reply[:200])
        self.assertIn(b"--request-timeout", reply)

    def test_trickled_body_is_not_accepted(self):
        body = json.dumps(tiny_case("trickled")).encode()
        head = b"POST /cases HTTP/1.1\r\nHost: x\r\nContent-Length: %d\r\n\r\n" % len(body)
        with self.connect() as s:
            reply, alive = self.trickle(s, head + body[:10], body[10:11], 0.3, 10 * SLOW)
        self.assertLess(alive, self.TIMEOUT + 1.5 * SLOW, "the connection lived %.1f s" % alive)
        self.assertNotEqual(status_of(reply), 201, reply[:200])
        status, cases = self.d.json("GET", "/cases")
        self.assertNotIn("trickled", json.dumps(cases))

    def test_stalled_body_is_cut_at_the_deadline(self):
        head = b"POST /cases HTTP/1.1\r\nHost: x\r\nContent-Length: 100\r\n\r\n{"
        with self.connect() as s:
            t0 = time.monotonic()
            s.sendall(head)
            reply = read_until_closed(s)
            alive = time.monotonic() - t0
        self.assertLess(alive, self.TIMEOUT + 1.5 * SLOW, "the connection lived %.1f s" % alive)
        self.assertNotEqual(status_of(reply), 201)

    def test_connections_per_address_are_capped(self):
        slow = [self.connect() for _ in range(self.PER_IP)]
        try:
            for s in slow:
                s.sendall(b"GET /health HTTP/1.1\r\n")
            time.sleep(0.2)
            reply, seconds = raw_exchange(self.d.port, b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n")
            self.assertEqual(status_of(reply), 503, reply[:200])
            self.assertIn(b"max-connections-per-ip", reply)
            self.assertLess(seconds, 1.0 * SLOW)
            try:  # another address is still served while these are held
                reply, _ = raw_exchange(self.d.port, b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n",
                                        source="127.0.0.2")
                self.assertEqual(status_of(reply), 200, reply[:200])
            except OSError as e:
                print("(127.0.0.2 not usable here: %s)" % e)
        finally:
            for s in slow:
                s.close()
        # once they are gone (or cut), this address is served again
        deadline = time.monotonic() + (self.TIMEOUT + 2) * SLOW
        while True:
            reply, _ = raw_exchange(self.d.port, b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n")
            if status_of(reply) == 200 or time.monotonic() > deadline:
                break
            time.sleep(0.1)
        self.assertEqual(status_of(reply), 200, reply[:200])


if __name__ == "__main__":
    unittest.main()


class KeepAliveTest(DaemonTestCase):
    """Keep-alive (issue 30, item 5): a connection carries several requests,
    and each later request is held to what the gate holds a first one to:
    its headers within --request-timeout of the answer before it, and the
    same framing checks, answered once and cleanly. Error answers close."""
    TIMEOUT = 2
    DAEMON_ARGS = ("--request-timeout", str(TIMEOUT))

    def connect(self):
        s = socket.create_connection(("127.0.0.1", self.d.port))
        s.settimeout(10 * SLOW)
        return s

    def exchange(self, s, request):
        """Sends one request on s and reads its whole answer (head and the
        Content-Length body); returns (head, body)."""
        s.sendall(request)
        reply = read_head(s)
        head, _, body = reply.partition(b"\r\n\r\n")
        length = int(re.search(rb"(?i)content-length: *(\d+)", head).group(1))
        while len(body) < length:
            chunk = s.recv(65536)
            if not chunk:
                break
            body += chunk
        return head, body

    def test_one_connection_carries_many_requests(self):
        with self.connect() as s:
            for _ in range(20):
                head, body = self.exchange(s, b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n")
                self.assertEqual(status_of(head), 200, head)
                self.assertNotIn(b"connection: close", head.lower())
                self.assertEqual(json.loads(body)["status"], "ok")
            # a case made and read on the same connection
            doc = json.dumps(tiny_case("kept")).encode()
            head, body = self.exchange(s, b"POST /cases HTTP/1.1\r\nHost: x\r\nContent-Length: %d"
                                       b"\r\n\r\n" % len(doc) + doc)
            self.assertEqual(status_of(head), 201, head)
            case_id = json.loads(body)["id"]
            head, body = self.exchange(s, b"GET /cases/%s HTTP/1.1\r\nHost: x\r\n\r\n"
                                       % case_id.encode())
            self.assertEqual(json.loads(body)["id"], case_id)

    def test_a_trickled_later_request_is_cut_at_the_deadline(self):
        with self.connect() as s:
            head, _ = self.exchange(s, b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n")
            self.assertEqual(status_of(head), 200)
            t0 = time.monotonic()
            s.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\n")
            s.settimeout(0.3)
            closed = False
            while time.monotonic() - t0 < 10 * SLOW and not closed:
                try:
                    closed = s.recv(65536) == b""
                except socket.timeout:
                    try:
                        s.sendall(b"X-Slow: 1\r\n")
                    except (BrokenPipeError, ConnectionResetError):
                        closed = True
                except ConnectionResetError:
                    closed = True
            alive = time.monotonic() - t0
        self.assertTrue(closed, "the trickling connection was still open after %.1f s" % alive)
        self.assertLess(alive, self.TIMEOUT + 1.5 * SLOW, "it lived %.1f s" % alive)
        self.assertGreater(alive, self.TIMEOUT - 0.5)

    def test_an_idle_kept_connection_is_closed(self):
        with self.connect() as s:
            self.exchange(s, b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n")
            t0 = time.monotonic()
            reply = read_until_closed(s)
            alive = time.monotonic() - t0
        self.assertEqual(reply, b"")
        self.assertLess(alive, self.TIMEOUT + 1.5 * SLOW, "it lived %.1f s" % alive)

    def test_a_later_request_gets_the_framing_checks(self):
        doc = json.dumps(tiny_case("smuggled-later")).encode()
        cases = [([b"Content-Length: %d" % len(doc), b"Content-Length: 2"], 400, b"disagree"),
                 ([b"Transfer-Encoding: identity"], 411, b"Content-Length"),
                 ([b"Transfer-Encoding: chunked", b"Content-Length: %d" % len(doc)], 400,
                  b"Content-Length alone"),
                 ([b"X-Field-%d: 1" % k for k in range(120)], 431, b"header fields")]
        for headers, status, words in cases:
            with self.connect() as s:
                head, _ = self.exchange(s, b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n")
                self.assertEqual(status_of(head), 200)
                t0 = time.monotonic()
                s.sendall(b"POST /cases HTTP/1.1\r\nHost: x\r\n" +
                          b"".join(h + b"\r\n" for h in headers) + b"\r\n" + doc)
                reply = read_until_closed(s)
                seconds = time.monotonic() - t0
            self.assertLess(seconds, 2.0 * SLOW, "answered after %.1f s" % seconds)
            self.assertEqual(reply.count(b"HTTP/1.1 "), 1, reply[:400])
            self.assertEqual(status_of(reply), status, reply[:400])
            self.assertIn(words, reply)
        status, listing = self.d.json("GET", "/cases")
        self.assertNotIn("smuggled-later", json.dumps(listing))

    def test_an_error_answer_closes_its_connection(self):
        with self.connect() as s:
            s.sendall(b"GET /nowhere HTTP/1.1\r\nHost: x\r\n\r\n")
            reply = read_until_closed(s)
        self.assertEqual(status_of(reply), 404, reply[:200])
        self.assertIn(b"connection: close", reply.lower())
