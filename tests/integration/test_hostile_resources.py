"""Hostile use of resources, third review (issue 30, contract 5.5): request
bodies no route reads, JSON nested deep enough to blow up once rewritten,
downloads that copy a running case's file for nobody or into the room the
running cases need, and cases failed for good by a full disk. Each test
failed on the code before its fix (the commit that adds it says by how
much).

RSS is read from /proc/PID/status; sanitizer builds keep freed memory in
quarantine, so there only the answers are checked."""
import json
import os
import socket
import threading
import time
import unittest

from fdemd_harness import SLOW, TERMINAL, DaemonTestCase, tiny_case
from test_hostile_input import problem_of
from test_hostile_requests import read_head, read_until_closed, status_of
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


def deep_object(depth, leaves):
    """{"x": {"x": ... {"k0": 0, ..., "k<leaves-1>": 0} ...}} as text,
    `depth` objects deep: each leaf costs 2 * depth bytes of indentation
    once the document is rewritten (json_dump_document)."""
    inner = "{" + ",".join('"k%d":0' % i for i in range(leaves)) + "}"
    return '{"x":' * (depth - 1) + inner + "}" * (depth - 1)


class DeepJsonTest(DaemonTestCase):
    """jansson 2.14 reads up to 2048 levels; a 1 MB clone patch 2,000
    levels deep became 1 GB of RSS while rewritten. Bodies are now held to
    64 levels before they are parsed."""

    def test_a_deep_clone_patch_is_refused_before_it_is_parsed(self):
        pid = self.d.proc.pid
        cid = self.d.create(tiny_case("source"))["id"]
        idle = memory(pid)
        patch = deep_object(2000, 120000)  # ~1.4 MB
        t0 = time.monotonic()
        status, headers, body = self.d.request("POST", "/cases/%s/clone" % cid, patch,
                                               {"Content-Type": "application/json"})
        seconds = time.monotonic() - t0
        peak = memory(pid)["VmHWM"]
        print("  %.1f MB patch 2000 deep: %s in %.2f s, peak RSS %.1f MiB (idle %.1f MiB)"
              % (len(patch) / 1e6, status, seconds, peak / MiB, idle["VmRSS"] / MiB))
        self.assertEqual(status, 400, body[:300])
        self.assertEqual(headers["content-type"], "application/problem+json")
        problem = json.loads(body)
        self.assertIn("64", problem["detail"])
        self.assertEqual(problem["errors"][0]["pointer"], "")
        self.assertIn("line 1, column", problem["errors"][0]["message"])
        self.assertLess(seconds, 5 * SLOW)
        if RSS_MEANINGFUL:
            # The body (1.4 MB) and the admission of its parse: 32 MiB is
            # ample. The old code reached several hundred MiB.
            self.assertLess(peak, idle["VmHWM"] + 32 * MiB, "peak RSS %.0f MiB" % (peak / MiB))
        self.assertEqual(self.d.json("GET", "/cases")[1]["cases"][-1]["id"], cid)

    def test_deep_bodies_are_refused_on_every_json_route(self):
        cid = self.d.create(tiny_case("source2"))["id"]
        deep = "[" * 65 + "]" * 65
        for path in ("/cases", "/cases?dry_run=true", "/cases/%s/extend" % cid,
                     "/cases/%s/clone" % cid):
            status, body = self.d.json("POST", path, '{"a": %s}' % deep,
                                       headers={"Content-Type": "application/json"})
            self.assertEqual(status, 400, (path, body))
            self.assertIn("nest deeper than 64", body["errors"][0]["message"])
        # 64 levels, and brackets inside strings, are fine as JSON.
        status, body = self.d.json("POST", "/cases/%s/clone" % cid, {"name": "[{" * 40})
        self.assertEqual(status, 201, body)
        status, body = self.d.json("POST", "/cases/%s/clone" % cid,
                                   '{"name": "n", "x": %s}' % ("[" * 62 + "]" * 62),
                                   headers={"Content-Type": "application/json"})
        self.assertEqual(status, 422, body)  # read, then refused as an unknown member


class WideCloneTest(DaemonTestCase):
    """Within 64 levels a patch's trees and rewritten text still cost some
    30 times its size, against 12 admitted: the clone is metered, and a
    budget that cannot cover it answers 503 instead of growing the RSS."""
    DAEMON_ARGS = ("--max-memory", "96M")

    def test_a_clone_beyond_the_budget_is_503(self):
        pid = self.d.proc.pid
        cid = self.d.create(tiny_case("source"))["id"]
        idle = memory(pid)
        patch = deep_object(40, 600000)  # ~6 MB, admitted at 72 MiB
        status, headers, body = self.d.request("POST", "/cases/%s/clone" % cid, patch,
                                               {"Content-Type": "application/json"})
        peak = memory(pid)["VmHWM"]
        print("  %.1f MB patch 40 deep, --max-memory 96M: %s, peak RSS %.1f MiB (idle %.1f MiB)"
              % (len(patch) / 1e6, status, peak / MiB, idle["VmRSS"] / MiB))
        self.assertEqual(status, 503, body[:300])
        self.assertGreater(int(headers["retry-after"]), 0)
        self.assertIn("--max-memory", json.loads(body)["detail"])
        if RSS_MEANINGFUL:
            self.assertLess(peak, idle["VmHWM"] + 96 * MiB + 16 * MiB, "peak RSS %.0f MiB" % (peak / MiB))
        # The budget comes back once the refused request is done with (its
        # lease goes when libmicrohttpd reports it complete, which may be
        # just after the client has its answer): an ordinary clone then
        # goes through.
        deadline = time.monotonic() + 10 * SLOW
        while True:
            status, body = self.d.json("POST", "/cases/%s/clone" % cid, {"name": "copy"})
            if status != 503 or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        self.assertEqual(status, 201, body)


def download_copies(pid):
    """The copies (unlinked .download-N.h5 files) the daemon holds open."""
    out = []
    fd_dir = "/proc/%d/fd" % pid
    for name in os.listdir(fd_dir):
        try:
            target = os.readlink(os.path.join(fd_dir, name))
        except OSError:
            continue
        if "/.download-" in target:
            out.append(target)
    return out


class DownloadCopyTest(DaemonTestCase):
    """A download of a running case's result.h5 copies it while the case's
    writes wait. A HEAD started a whole copy, and a GET that hung up kept
    its copy going to the end: a case fell from 166 to 2 steps/s."""
    # Large enough that a copy outlasts the moment its client hangs up (40
    # of 147 MB were copied by then here), small enough to be quick: the
    # file grows by ~3.2 MB every 8 steps while the tests run.
    MEGABYTES = 150

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        # 80k elements, ~3.2 MB per snapshot, one snapshot every 8 steps.
        case = tiny_case("big", end=1.0, divisions=(200, 200))
        st = cls.d.create(case)
        case["output"]["interval"] = 8 * st["dt"]
        case["time"]["end"] = 8 * st["dt"] * 100000
        cls.d.request("DELETE", "/cases/" + st["id"])
        cls.cid = cls.d.create(case, start=True)["id"]
        cls.d.wait(cls.cid, lambda s: s["snapshots"] * 3.2 >= cls.MEGABYTES, timeout=120,
                   what="a big result")

    @classmethod
    def tearDownClass(cls):
        try:
            cls.d.request("DELETE", "/cases/" + cls.cid)
        finally:
            super().tearDownClass()

    def steps_advance(self):
        step = self.d.status(self.cid)["step"]
        self.d.wait(self.cid, lambda s: s["step"] > step + 4 or s["state"] != "running",
                    timeout=20, what="steps after step %d" % step)
        self.assertEqual(self.d.status(self.cid)["state"], "running")

    def test_head_answers_the_size_and_copies_nothing(self):
        pid = self.d.proc.pid
        seen, stop = [], threading.Event()

        def watch():  # bounded by the stop event, set below whatever happens
            while not stop.is_set():
                seen.extend(download_copies(pid))
                time.sleep(0.001)
        watcher = threading.Thread(target=watch)
        watcher.start()
        try:
            for _ in range(5):
                conn = self.d.connection()
                try:
                    conn.request("HEAD", "/cases/%s/result.h5" % self.cid)
                    resp = conn.getresponse()
                    data = resp.read()
                finally:
                    conn.close()
                self.assertEqual(resp.status, 200)
                self.assertEqual(data, b"")
                self.assertEqual(resp.getheader("Content-Type"), "application/x-hdf5")
                self.assertGreater(int(resp.getheader("Content-Length")), self.MEGABYTES * 1e6 * 0.9)
            self.steps_advance()
        finally:
            stop.set()
            watcher.join()
        print("  5 HEAD of a %d MB result.h5: copies seen %d" % (self.MEGABYTES, len(set(seen))))
        self.assertEqual(sorted(set(seen)), [])

    def test_a_get_that_hangs_up_leaves_no_copy(self):
        pid = self.d.proc.pid
        s = socket.create_connection(("127.0.0.1", self.d.port), timeout=30 * SLOW)
        try:
            s.sendall(b"GET /cases/%s/result.h5 HTTP/1.1\r\nHost: x\r\n\r\n" % self.cid.encode())
            head = read_head(s)
            self.assertEqual(status_of(head), 200, head[:300])
        finally:
            # a reset, as a client killed mid-download leaves
            s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, b"\x01\x00\x00\x00\x00\x00\x00\x00")
            s.close()
        deadline = time.monotonic() + 20 * SLOW
        while "abandoned by its client" not in self.d.log_tail() or download_copies(pid):
            self.assertLess(time.monotonic(), deadline, "the copy was not released: %s\n%s"
                            % (download_copies(pid), self.d.log_tail()[-600:]))
            time.sleep(0.02)
        line = [l for l in self.d.log_tail().splitlines() if "abandoned by its client" in l][-1]
        print("  " + line)
        self.steps_advance()


class DiskHeadroomTest(unittest.TestCase):
    """Copies for downloads of running cases were allocated while any disk
    space was left: nine unread ones filled a 200 MB disk and another
    user's running case failed for good. A copy must now leave the running
    cases room for their next snapshots and checkpoints (503 otherwise)."""

    def test_a_copy_that_would_eat_the_headroom_is_503(self):
        from test_storage_faults import daemon_on_tmpfs
        d, _ = daemon_on_tmpfs(self, "64m")
        # A running case that writes nothing more during the test: its next
        # snapshot is half a minute away.
        case = d.case_lasting(60.0, name="running", divisions=(60, 60))
        case["output"]["interval"] = case["time"]["end"] / 2
        cid = d.create(case, start=True)["id"]
        d.wait(cid, lambda s: s["state"] == "running" and s["step"] > 0, what="running")
        status, headers, _ = d.request("HEAD", "/cases/%s/result.h5" % cid)
        self.assertEqual(status, 200)
        size = int(headers["content-length"])
        # Leave room for the copy and 1 MiB: the copy fits, the headroom
        # (at least 4 MiB) does not.
        filler = os.path.join(d.data_dir, "filler")
        fs = os.statvfs(d.data_dir)
        with open(filler, "wb") as f:
            f.truncate(0)
            os.posix_fallocate(f.fileno(), 0, fs.f_bavail * fs.f_frsize - size - MiB)
        status, headers, body = d.request("GET", "/cases/%s/result.h5" % cid)
        print("  GET of a %.1f MB running result.h5 with %.1f MB free: %d"
              % (size / 1e6, (size + MiB) / 1e6, status))
        self.assertEqual(status, 503, body[:200])
        self.assertGreater(int(headers["retry-after"]), 0)
        self.assertIn("kept free for the running cases", json.loads(body)["detail"])
        self.assertEqual(d.status(cid)["state"], "running")
        # With the room back, the download goes through whole.
        os.unlink(filler)
        status, headers, body = d.request("GET", "/cases/%s/result.h5" % cid)
        self.assertEqual(status, 200)
        self.assertGreaterEqual(len(body), size)
        d.json("POST", "/cases/%s/stop" % cid)
        self.assertEqual(d.stop()[0], 0, d.log_tail())


class DiskFullRetryTest(unittest.TestCase):
    """A case that failed only because the disk was full failed for good:
    start was a 409 however much room was made. It now starts again from
    its last checkpoint, as a restarted case does, and ends as the same run
    uninterrupted would have."""

    def test_a_case_failed_for_a_full_disk_starts_again_once_there_is_room(self):
        import subprocess
        import numpy as np
        from test_storage_faults import daemon_on_tmpfs
        from fdemd_harness import fetched_result
        d, where = daemon_on_tmpfs(self, "2m")
        # ~33 KB per snapshot: 1001 of them cannot fit in 2 MiB.
        case = tiny_case("full", end=0.01, divisions=(20, 20), interval=1e-5)
        cid = d.create(case, start=True)["id"]
        st = d.wait_state(cid, ("finished", "failed", "stopped"), timeout=60)
        self.assertEqual(st["state"], "failed", st)
        self.assertIn("No space left on device", st["error"])
        failed_at = st["snapshots"]
        done = subprocess.run(["mount", "-o", "remount,size=128m", where], capture_output=True, text=True)
        self.assertEqual(done.returncode, 0, done.stderr)
        status, body = d.json("POST", "/cases/%s/start" % cid)
        print("  start of a case failed for a full disk (%d of 1001 snapshots), room made: %d"
              % (failed_at, status))
        self.assertEqual(status, 200, body)
        self.assertIn(body["state"], ("running", "finished"))
        self.assertIsNone(body["error"])
        st = d.wait_state(cid, ("finished", "failed", "stopped"), timeout=60)
        self.assertEqual(st["state"], "finished", (st, d.log_tail()))
        self.assertEqual(st["snapshots"], 1001)
        self.assertIsNone(st["error"])
        self.assertIn("started again from its last checkpoint after failing for a full disk",
                      d.log_tail(20000))
        reference = d.create(dict(case, name="reference"), start=True)["id"]
        st = d.wait_state(reference, TERMINAL, timeout=60)
        self.assertEqual(st["state"], "finished", st)
        with fetched_result(d, cid) as f, fetched_result(d, reference) as g:
            self.assertEqual(f["/snapshots/time"].shape[0], 1001)
            self.assertTrue(np.array_equal(f["/snapshots/step"][...], g["/snapshots/step"][...]))
            self.assertTrue(np.array_equal(f["/snapshots/position"][...], g["/snapshots/position"][...]))
        # The process that hit the full disk is killed, not stopped (as in
        # DiskFullTest): HDF5 keeps what it allocated for the failed write
        # until exit, which a sanitizer build reports as a leak. The
        # finished case comes back finished, and that daemon stops cleanly.
        d.kill()
        d.start()
        st = d.status(cid)
        self.assertEqual((st["state"], st["snapshots"]), ("finished", 1001), st)
        self.assertEqual(d.stop()[0], 0, d.log_tail())


if __name__ == "__main__":
    unittest.main()


class IdleSlotsTest(DaemonTestCase):
    """16 idle connections (half a request head each) from each of 33
    loopback addresses filled all 512 slots, and every other client got 503
    for as long as they were held (item 2). Now a connection that finds
    every slot taken cuts the one that has waited longest for its headers
    (answered 408), so /health is served while they are held."""
    ADDRESSES = 33
    PER_ADDRESS = 16

    def test_idle_connections_are_cut_first_when_every_slot_is_taken(self):
        idle = []
        try:
            for a in range(self.ADDRESSES):
                for _ in range(self.PER_ADDRESS):
                    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
                    s.bind(("127.0.0.%d" % (2 + a), 0))
                    s.connect(("127.0.0.1", self.d.port))
                    s.sendall(b"GET /health HTTP/1.1\r\nHo")
                    idle.append(s)
            # accepted after every idle one (the listen queue is in order)
            status, body = self.d.json("GET", "/health")
            self.assertEqual(status, 200, body)
            self.assertEqual(self.d.json("GET", "/cases")[0], 200)
            cut = 0
            for s in idle:
                s.settimeout(0)
                try:
                    head = s.recv(64)
                except BlockingIOError:
                    continue
                cut += head.startswith(b"HTTP/1.1 408")
            # the 16 beyond 512, and one for each of the two requests
            self.assertGreaterEqual(cut, 2)
        finally:
            for s in idle:
                s.close()
