"""--max-memory (contract 5.5): the daemon holds a model only for running
cases, admits uploads against its budget before reading them, answers 503
with Retry-After beyond the budget without changing anything, gives freed
memory back to the OS, and never fails a stored case because memory was
short at the moment. RSS is read from /proc/PID/status (VmRSS, VmHWM)."""
import json
import os
import signal
import socket
import threading
import time
import unittest

import numpy as np

from fdemd_harness import SLOW, Daemon, fetched_result, tiny_case

MiB = 1 << 20
# ASan keeps freed memory in quarantine and maps shadow memory: RSS then says
# nothing about the daemon, so sanitizer builds check everything else.
RSS_MEANINGFUL = SLOW == 1.0


def memory(pid):
    """{"VmRSS": bytes, "VmHWM": bytes} of a process."""
    out = {}
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            key, _, value = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                out[key] = int(value.split()[0]) * 1024
    return out


def mesh_case(n, name="mesh"):
    """An explicit n x n-node mesh (2 (n-1)^2 triangles) written with long
    floats, as a mesher would: about 75 bytes of JSON per node."""
    nodes = [[i * 0.01 + 1e-7 * j, j * 0.01 + 3e-9 * i] for j in range(n) for i in range(n)]
    triangles = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            triangles += [[a, a + 1, a + n + 1], [a, a + n + 1, a + n]]
    case = tiny_case(name)
    case["parts"] = [{"name": "m", "material": "rock", "mesh": {"nodes": nodes, "triangles": triangles}}]
    case["constraints"] = [{"box": [-1, -0.001, 100, 0.001], "fix": ["x", "y"]}]
    return case


class Upload:
    """A POST /cases sent in two halves: headers (with Expect: 100-continue,
    so the daemon answers before the body when it refuses it), then the body."""

    def __init__(self, port, body):
        self.body = body
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=30 * SLOW)
        self.sock.sendall(b"POST /cases HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n"
                          b"Content-Type: application/json\r\nExpect: 100-continue\r\n"
                          b"Content-Length: %d\r\n\r\n" % len(body))
        self.buffer = b""
        self.status, self.headers, self.data = self._read_response()
        self.admitted = self.status == 100

    def _read_response(self):
        while b"\r\n\r\n" not in self.buffer:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise AssertionError("connection closed without a response: %r" % self.buffer)
            self.buffer += chunk
        head, _, self.buffer = self.buffer.partition(b"\r\n\r\n")
        lines = head.decode().split("\r\n")
        status = int(lines[0].split()[1])
        headers = {k.strip().lower(): v.strip() for k, _, v in (l.partition(":") for l in lines[1:])}
        length = int(headers.get("content-length", 0))
        while len(self.buffer) < length:
            chunk = self.sock.recv(65536)
            if not chunk:
                break
            self.buffer += chunk
        data, self.buffer = self.buffer[:length], self.buffer[length:]
        return status, headers, data

    def finish(self):
        self.sock.sendall(self.body)
        self.status, self.headers, self.data = self._read_response()
        self.sock.close()

    def close(self):
        self.sock.close()


class MemoryTest(unittest.TestCase):
    def setUp(self):
        self.d = None

    def tearDown(self):
        if self.d:
            self.d.close()

    def start(self, *args):
        self.d = Daemon(args=list(args))
        self.d.start()
        return self.d

    def assertUnavailable(self, status, headers, body, words=()):
        self.assertEqual(status, 503, body)
        self.assertEqual(headers.get("content-type"), "application/problem+json")
        self.assertGreater(int(headers["retry-after"]), 0)
        problem = json.loads(body)
        self.assertEqual(problem["status"], 503)
        for word in words:
            self.assertIn(word, problem["detail"])

    def test_concurrent_uploads_stay_within_the_budget(self):
        budget = 96 * MiB
        d = self.start("--max-memory", "96M")
        body = json.dumps(mesh_case(200)).encode()  # 3 MiB, a tree of ~27 MiB
        idle = memory(d.proc.pid)
        uploads = [Upload(d.port, body) for _ in range(6)]
        admitted = [u for u in uploads if u.admitted]
        refused = [u for u in uploads if not u.admitted]
        # Admitted at 12 bytes per byte of body: two fit in 96 MiB, the rest
        # are told to come back before they send their body.
        self.assertEqual(len(admitted), 2, [u.status for u in uploads])
        for u in refused:
            self.assertUnavailable(u.status, u.headers, u.data, ["--max-memory"])
            u.close()
        threads = [threading.Thread(target=u.finish) for u in admitted]
        for t in threads:
            t.start()
        for t in threads:
            t.join(60 * SLOW)
        self.assertEqual([u.status for u in admitted], [201, 201], [u.data[:300] for u in admitted])
        # The budget is free again: a refused upload now goes through.
        status, headers, data = d.request("POST", "/cases", body)
        self.assertEqual(status, 201, data[:300])
        if not RSS_MEANINGFUL:
            return
        peak = memory(d.proc.pid)["VmHWM"]
        margin = idle["VmRSS"] + 16 * MiB  # the daemon's own code and libraries, allocator slack
        self.assertLess(peak, budget + margin, "peak RSS %.0f MiB" % (peak / MiB))
        time.sleep(0.2)
        after = memory(d.proc.pid)["VmRSS"]
        self.assertLess(after, idle["VmRSS"] + 16 * MiB,
                        "RSS %.0f MiB after the uploads, %.0f MiB idle" % (after / MiB, idle["VmRSS"] / MiB))

    def test_stored_cases_hold_no_model(self):
        d = self.start()
        # 80 000 elements: a model of ~17 MiB.
        first = d.create(tiny_case("big0", divisions=(200, 200)))
        time.sleep(0.1)
        one = memory(d.proc.pid)["VmRSS"]
        ids = [first["id"]] + [d.create(tiny_case("big%d" % k, divisions=(200, 200)))["id"]
                               for k in range(1, 6)]
        time.sleep(0.1)
        six = memory(d.proc.pid)["VmRSS"]
        if RSS_MEANINGFUL:
            self.assertLess(six - one, 8 * MiB,
                            "RSS grew %.0f MiB for 5 more stored cases" % ((six - one) / MiB))
        # What users read of them is still there: figures and the state.
        st = d.status(ids[-1])
        self.assertEqual((st["state"], st["nodes"], st["elements"]), ("created", 201 * 201, 80000))
        self.assertTrue(np.isfinite(st["energy"]["kinetic"]))
        status, state = d.json("GET", "/cases/%s/state" % ids[-1])
        self.assertEqual((status, state["step"], len(state["position"])), (200, 0, 201 * 201))

    def test_start_over_the_budget_is_503_and_changes_nothing(self):
        # Each 200 x 200 model is charged ~31 MiB (an estimate of ~24 MiB with
        # finalize's scratch, a quarter more for a checkpoint copy, ~0.4 MiB
        # a thread): one fits in 45 MiB, two do not.
        d = self.start("--max-memory", "45M")
        running = d.create(tiny_case("running", end=1e3, divisions=(200, 200)))["id"]
        waiting = d.create(tiny_case("waiting", end=1e3, divisions=(200, 200)))["id"]
        self.assertEqual(d.json("POST", "/cases/%s/start" % running)[0], 200)
        before = d.status(waiting)
        with open(os.path.join(d.data_dir, waiting, "status.json"), "rb") as f:
            stored = f.read()
        status, headers, body = d.request("POST", "/cases/%s/start" % waiting)
        self.assertUnavailable(status, headers, body, ["--max-memory"])
        status, headers, body = d.request("GET", "/cases/%s/state" % waiting)
        self.assertUnavailable(status, headers, body, ["--max-memory"])
        self.assertEqual(d.status(waiting), before)
        with open(os.path.join(d.data_dir, waiting, "status.json"), "rb") as f:
            self.assertEqual(f.read(), stored)
        # Once the first case pauses, its model is freed and the second starts.
        self.assertEqual(d.json("POST", "/cases/%s/pause" % running)[0], 200)
        status, st = d.json("POST", "/cases/%s/start" % waiting)
        self.assertEqual((status, st["state"]), (200, "running"))
        d.wait(waiting, lambda s: s["step"] > 2, what="steps")
        self.assertEqual(d.json("POST", "/cases/%s/stop" % waiting)[0], 200)

    def test_restart_short_of_memory_keeps_every_case(self):
        d = self.start()
        created = d.create(tiny_case("created"))["id"]
        finished = d.create(tiny_case("finished", end=0.0004), start=True)["id"]
        d.wait_state(finished, "finished")
        paused = d.create(tiny_case("paused", end=10.0), start=True)["id"]
        d.wait(paused, lambda s: s["step"] > 20, what="steps")
        paused_step = d.json("POST", "/cases/%s/pause" % paused)[1]["step"]
        _, paused_state = d.json("GET", "/cases/%s/state" % paused)
        running = d.create(tiny_case("running", end=10.0), start=True)["id"]
        d.wait(running, lambda s: s["step"] > 20, what="steps")
        stopped = d.create(tiny_case("stopped"))["id"]
        d.json("POST", "/cases/%s/stop" % stopped)
        before = {c["id"]: c for c in self._cases_on_restart(d, [])}
        expected = {created: "created", finished: "finished", paused: "paused",
                    running: "paused", stopped: "stopped"}
        self.assertEqual({i: c["state"] for i, c in before.items()}, expected)

        # A lower per-case limit, then a tiny total budget: nothing fails.
        for args in (["--max-case-memory", "1K"], ["--max-memory", "1K"],
                     ["--max-memory", "1K", "--max-case-memory", "1K"]):
            after = {c["id"]: c for c in self._cases_on_restart(d, args)}
            for case_id, st in after.items():
                self.assertEqual((st["state"], st["error"], st["step"]),
                                 (before[case_id]["state"], None, before[case_id]["step"]),
                                 "%s after a restart with %s" % (st["name"], args))
            if "--max-memory" in args:
                status, headers, body = d.request("POST", "/cases/%s/start" % paused)
                self.assertUnavailable(status, headers, body, ["whole memory budget"])
                status, headers, body = d.request("GET", "/cases/%s/state" % paused)
                self.assertUnavailable(status, headers, body)
                self.assertEqual(d.status(paused)["state"], "paused")

        # With memory again, the paused case gives its state and runs on.
        self._cases_on_restart(d, [])
        status, state = d.json("GET", "/cases/%s/state" % paused)
        self.assertEqual((status, state["step"]), (200, paused_step))
        self.assertEqual(state["position"], paused_state["position"])
        self.assertEqual(d.json("POST", "/cases/%s/start" % running)[0], 200)
        d.wait(running, lambda s: s["step"] > before[running]["step"], what="steps")
        self.assertEqual(d.stop()[0], 0, d.log_tail())

    def _cases_on_restart(self, d, args):
        if d.proc and d.proc.poll() is None:
            self.assertEqual(d.stop()[0], 0, d.log_tail())
        d.args = list(args)
        d.start()
        return d.json("GET", "/cases")[1]["cases"]

    def test_state_of_a_stopped_case_is_its_last_step(self):
        d = self.start()
        case_id = d.create(tiny_case("stopped", end=10.0), start=True)["id"]
        d.wait(case_id, lambda s: s["step"] > 30, what="steps")
        st = d.json("POST", "/cases/%s/stop" % case_id)[1]
        status, state = d.json("GET", "/cases/%s/state?fields=position,velocity" % case_id)
        self.assertEqual((status, state["step"]), (200, st["step"]))
        # The stop wrote its last snapshot at that step: the state is the same.
        with fetched_result(d, case_id) as f:
            self.assertEqual(f["/snapshots/step"][-1], st["step"])
            np.testing.assert_array_equal(np.array(state["position"]), f["/snapshots/position"][-1])
            np.testing.assert_array_equal(np.array(state["velocity"]), f["/snapshots/velocity"][-1])


if __name__ == "__main__":
    unittest.main()
