"""Model builds run off the threads that answer HTTP (issue 30, item 9).

GET /state of a stored case that holds no model rebuilds the model from
its document; so do POST /cases, dry runs and clones. Before, such requests
ran on libmicrohttpd's four answering threads: four rebuilds of a
750k-tetrahedron case held them all for 46 s, and /health, listed as always
served, got no answer until one was done. Now they run on threads of their
own (server/http/heavy_work.c) while their connections wait, so /health answers
while they are still being built. The test orders events, not times: every
/health answer must come before the first state is done."""
import threading
import time
import unittest

from fdemd_harness import DaemonTestCase

REBUILDS = 8  # more than the daemon's four answering threads


def block_case(n, name="block"):
    """A 3D block of n^3 cells, 6 n^3 tetrahedra (n = 34: 236k)."""
    return {"name": name, "dimension": 3,
            "materials": {"rock": {"density": 2700, "young": 3e10, "poisson": 0.25}},
            "parts": [{"name": "block", "material": "rock",
                       "box": {"origin": [0, 0, 0], "size": [1, 1, 1], "divisions": [n, n, n]}}],
            "time": {"end": 1e-3}}


class HeavyWorkTest(DaemonTestCase):
    def test_health_is_answered_while_states_are_rebuilt(self):
        d = self.d
        case_id = d.create(block_case(34))["id"]  # created: it holds no model
        done = []
        lock = threading.Lock()

        def state():
            status, _ = d.json("GET", "/cases/%s/state?fields=velocity" % case_id)
            with lock:
                done.append((time.monotonic(), status))

        threads = [threading.Thread(target=state) for _ in range(REBUILDS)]
        for t in threads:
            t.start()
        health = []
        for _ in range(5):
            status, body = d.json("GET", "/health")
            self.assertEqual(status, 200, body)
            health.append(time.monotonic())
        for t in threads:
            t.join()
        self.assertEqual(sorted(s for _, s in done), [200] * REBUILDS)
        first_state = min(t for t, _ in done)
        self.assertLess(max(health), first_state,
                        "/health waited for a rebuild: answered %.2f s after the first state"
                        % (max(health) - first_state))

    def test_a_full_queue_is_answered_503_not_dropped(self):
        """More rebuilds than the queue holds (32): each gets an answer,
        200 or 503 with Retry-After, none a reset."""
        d = self.d
        case_id = d.create(block_case(20, "queued"))["id"]
        answers = []
        lock = threading.Lock()

        def state():
            status, headers, _ = d.request("GET", "/cases/%s/state?fields=velocity" % case_id)
            with lock:
                answers.append((status, headers.get("retry-after")))

        threads = [threading.Thread(target=state) for _ in range(40)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        self.assertEqual(len(answers), 40)
        for status, retry in answers:
            self.assertIn(status, (200, 503))
            if status == 503:
                self.assertIsNotNone(retry)
        self.assertIn(200, [s for s, _ in answers])


if __name__ == "__main__":
    unittest.main()
