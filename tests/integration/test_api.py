"""Every route of the API against the real daemon: status codes, the
status object, the state machine (including the queued state), pause
holding the step count, and GET /state taken at one step boundary."""
import json
import os
import time
import unittest

from fdemd_harness import Daemon, tiny_case

STATUS_KEYS = {"id", "name", "state", "step", "time", "end_time", "progress", "dt", "nodes",
               "elements", "joints", "broken_joints", "contacts", "snapshots", "energy",
               "steps_per_second", "error", "created", "started", "finished_at", "elapsed"}
LONG = 1e3  # simulated seconds: never finishes within a test


class ApiTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon(args=["--max-running", "2"]).start()

    @classmethod
    def tearDownClass(cls):
        code, _ = cls.d.stop()
        cls.d.close()
        assert code == 0, "fdemd exited with %s" % code

    def tearDown(self):
        # Leave no case running for the next test (2 cores are shared).
        for st in self.d.json("GET", "/cases")[1]["cases"]:
            self.d.request("DELETE", "/cases/" + st["id"])

    def test_health(self):
        status, body = self.d.json("GET", "/health")
        self.assertEqual(status, 200)
        self.assertEqual(body["status"], "ok")
        self.assertIsInstance(body["version"], str)
        self.assertEqual(body["cases"], 0)
        self.assertEqual(body["running"], 0)

    def test_create_returns_201_location_and_status(self):
        doc = json.dumps(tiny_case("created-one"), indent=3).encode() + b"\n"
        status, headers, data = self.d.request("POST", "/cases", doc,
                                               {"Content-Type": "application/json"})
        self.assertEqual(status, 201, data)
        self.assertTrue(headers["content-type"].startswith("application/json"))
        st = json.loads(data)
        self.assertEqual(headers["location"], "/cases/" + st["id"])
        self.assertRegex(st["id"], r"^[0-9a-f]{16}$")
        self.assertTrue(STATUS_KEYS <= set(st), STATUS_KEYS - set(st))
        self.assertEqual(st["state"], "created")
        self.assertEqual((st["step"], st["time"], st["progress"]), (0, 0.0, 0.0))
        self.assertEqual((st["nodes"], st["elements"]), (121, 200))
        self.assertEqual(st["snapshots"], 1)  # the one at t = 0
        self.assertIsNone(st["error"])
        self.assertEqual(st["end_time"], 0.001)
        self.assertGreater(st["dt"], 0)
        # The document comes back byte for byte.
        status, headers, data = self.d.request("GET", "/cases/%s/case" % st["id"])
        self.assertEqual(status, 200)
        self.assertEqual(data, doc)
        self.assertTrue(headers["content-type"].startswith("application/json"))
        # And it is on disk with its status.
        case_dir = os.path.join(self.d.data_dir, st["id"])
        for name in ("case.json", "status.json", "result.h5", "result.xdmf", "checkpoint.bin"):
            self.assertTrue(os.path.exists(os.path.join(case_dir, name)), name)

    def test_list_is_oldest_first_and_get_matches(self):
        ids = [self.d.create(tiny_case("n%d" % i))["id"] for i in range(3)]
        status, body = self.d.json("GET", "/cases")
        self.assertEqual(status, 200)
        self.assertEqual([c["id"] for c in body["cases"]], ids)
        self.assertEqual([c["name"] for c in body["cases"]], ["n0", "n1", "n2"])
        self.assertEqual(self.d.status(ids[1])["name"], "n1")

    def test_run_to_finish(self):
        st = self.d.create(tiny_case("short", end=0.0005, interval=0.0001), start=True)
        self.assertIn(st["state"], ("running", "finished"))
        st = self.d.wait_state(st["id"], "finished")
        self.assertGreaterEqual(st["time"], 0.0005 * (1 - 1e-9))
        self.assertLess(st["time"], 0.0005 + st["dt"])
        self.assertEqual(st["progress"], 1.0)
        self.assertEqual(st["snapshots"], 6)  # t = 0, 1e-4 ... 5e-4
        # A finished case shows its mean speed (issue 15): steps over the
        # wall seconds spent stepping, not 0.
        self.assertAlmostEqual(st["steps_per_second"], st["step"] / st["elapsed"],
                               delta=1e-9 * st["steps_per_second"])
        self.assertIsNone(st["error"])
        for key in ("kinetic", "elastic", "contact", "gravity_work"):
            self.assertIsInstance(st["energy"][key], float)

    def test_start_pause_resume_stop(self):
        case_id = self.d.create(tiny_case("long", end=LONG))["id"]
        status, st = self.d.json("POST", "/cases/%s/start" % case_id)
        self.assertEqual((status, st["state"]), (200, "running"))
        self.d.wait(case_id, lambda s: s["step"] > 50, what="steps")
        status, st = self.d.json("POST", "/cases/%s/pause" % case_id)
        self.assertEqual((status, st["state"]), (200, "paused"))
        held = st["step"]
        self.assertGreater(held, 50)
        time.sleep(0.5)
        again = self.d.status(case_id)
        self.assertEqual((again["state"], again["step"]), ("paused", held))
        status, state = self.d.json("GET", "/cases/%s/state?fields=position" % case_id)
        self.assertEqual((status, state["step"]), (200, held))
        # Pausing twice is a conflict that names the state.
        status, problem = self.d.json("POST", "/cases/%s/pause" % case_id)
        self.assertEqual(status, 409)
        self.assertIn("paused", problem["detail"])
        status, st = self.d.json("POST", "/cases/%s/start" % case_id)
        self.assertEqual((status, st["state"]), (200, "running"))
        self.d.wait(case_id, lambda s: s["step"] > held, what="resumed stepping")
        status, st = self.d.json("POST", "/cases/%s/stop" % case_id)
        self.assertEqual((status, st["state"]), (200, "stopped"))
        stopped_at = st["step"]
        time.sleep(0.2)
        self.assertEqual(self.d.status(case_id)["step"], stopped_at)

    def test_409_names_state_and_allowed(self):
        case_id = self.d.create(tiny_case("done", end=0.0002), start=True)["id"]
        self.d.wait_state(case_id, "finished")
        for command in ("start", "pause", "stop"):
            status, headers, data = self.d.request("POST", "/cases/%s/%s" % (case_id, command))
            self.assertEqual(status, 409, command)
            self.assertEqual(headers["content-type"], "application/problem+json")
            problem = json.loads(data)
            self.assertEqual(problem["status"], 409)
            self.assertIn("finished", problem["detail"])
            self.assertIn("allowed only when", problem["detail"])
        # created -> pause is also not allowed
        other = self.d.create(tiny_case("fresh"))["id"]
        status, problem = self.d.json("POST", "/cases/%s/pause" % other)
        self.assertEqual(status, 409)
        self.assertIn("created", problem["detail"])
        # created -> stop is (any non-terminal state may stop)
        status, st = self.d.json("POST", "/cases/%s/stop" % other)
        self.assertEqual((status, st["state"]), (200, "stopped"))

    def test_failed_case_says_where_and_why(self):
        case = tiny_case("boom", end=0.01, divisions=(4, 4))
        case["constraints"].append({"box": [0.09, 0.09, 0.2, 0.2], "force": [1e300, 1e300]})
        case_id = self.d.create(case, start=True)["id"]
        st = self.d.wait_state(case_id, "failed")
        self.assertRegex(st["error"], r"non-finite at step \d+")
        self.assertRegex(st["error"], r"element \d+")
        self.assertIn("dt = ", st["error"])
        self.assertIn("reduce time.safety", st["error"])
        status, problem = self.d.json("POST", "/cases/%s/start" % case_id)
        self.assertEqual(status, 409)
        self.assertIn("failed", problem["detail"])
        self.assertEqual(self.d.request("GET", "/cases/%s/result.h5" % case_id)[0], 200)
        self.assertEqual(self.d.json("GET", "/health")[1]["running"], 0)

    def test_state_is_consistent(self):
        case_id = self.d.create(tiny_case("state", end=LONG), start=True)["id"]
        self.d.wait(case_id, lambda s: s["step"] > 10, what="steps")
        last = 0
        for _ in range(10):
            status, state = self.d.json("GET", "/cases/%s/state?fields=position,velocity,stress" % case_id)
            self.assertEqual(status, 200)
            st = self.d.status(case_id)
            self.assertEqual(len(state["position"]), st["nodes"])
            self.assertEqual(len(state["velocity"]), st["nodes"])
            self.assertEqual(len(state["stress"]), st["elements"])
            self.assertTrue(all(len(p) == 2 for p in state["position"]))
            self.assertTrue(all(len(s) == 3 for s in state["stress"]))
            # One step boundary: time is the sum of `step` constant steps.
            self.assertGreaterEqual(state["step"], last)
            self.assertAlmostEqual(state["time"], state["step"] * st["dt"],
                                   delta=1e-9 * max(state["time"], 1e-12) + 1e-15)
            last = state["step"]
        # The base row (fixed) has not moved; the block is falling (vy < 0 on top).
        self.assertEqual(state["position"][0], [0.0, 0.0])
        status, state = self.d.json("GET", "/cases/%s/state" % case_id)
        self.assertEqual(status, 200)
        self.assertEqual(set(state), {"step", "time", "position", "velocity"})
        status, problem = self.d.json("GET", "/cases/%s/state?fields=position,temperature" % case_id)
        self.assertEqual(status, 400)
        self.assertIn("temperature", json.dumps(problem))

    def test_queued_when_max_running_reached(self):
        ids = [self.d.create(tiny_case("q%d" % i, end=LONG))["id"] for i in range(4)]
        states = [self.d.json("POST", "/cases/%s/start" % i)[1]["state"] for i in ids]
        self.assertEqual(states, ["running", "running", "queued", "queued"])
        self.assertEqual(self.d.json("GET", "/health")[1]["running"], 2)
        # Pausing a queued case takes it out of the queue.
        status, st = self.d.json("POST", "/cases/%s/pause" % ids[2])
        self.assertEqual((status, st["state"]), (200, "paused"))
        # Stopping a running one frees a slot: the first still queued starts.
        status, st = self.d.json("POST", "/cases/%s/stop" % ids[0])
        self.assertEqual((status, st["state"]), (200, "stopped"))
        self.d.wait_state(ids[3], "running", timeout=5)
        self.assertEqual(self.d.status(ids[2])["state"], "paused")
        self.assertEqual(self.d.json("GET", "/health")[1]["running"], 2)
        # A queued case can be stopped.
        status, st = self.d.json("POST", "/cases/%s/start" % ids[2])
        self.assertEqual(st["state"], "queued")
        status, st = self.d.json("POST", "/cases/%s/stop" % ids[2])
        self.assertEqual((status, st["state"]), (200, "stopped"))

    def test_delete(self):
        case_id = self.d.create(tiny_case("gone", end=LONG), start=True)["id"]
        self.d.wait(case_id, lambda s: s["step"] > 0, what="steps")
        status, headers, data = self.d.request("DELETE", "/cases/" + case_id)
        self.assertEqual((status, data), (204, b""))
        self.assertFalse(os.path.exists(os.path.join(self.d.data_dir, case_id)))
        for method, path in (("GET", ""), ("GET", "/state"), ("GET", "/result.h5"),
                             ("POST", "/start"), ("DELETE", "")):
            status, problem = self.d.json(method, "/cases/%s%s" % (case_id, path))
            self.assertEqual(status, 404, path)
            self.assertIn(case_id, problem["detail"])
        self.assertEqual(self.d.json("GET", "/health")[1]["running"], 0)

    def test_404_and_405(self):
        # ("/" is the web page since contract 6.3: test_web.py)
        for path in ("/ui/nope.js", "/nope", "/cases/0123456789abcdef", "/cases/0123456789abcdef/state",
                     "/cases/xyz", "/cases/0123456789ABCDEF", "/cases/0123456789abcdef/what",
                     "/health/x"):
            status, headers, data = self.d.request("GET", path)
            self.assertEqual(status, 404, path)
            self.assertEqual(headers["content-type"], "application/problem+json")
            problem = json.loads(data)
            self.assertEqual((problem["type"], problem["status"]), ("about:blank", 404))
            self.assertEqual(problem["errors"], [])
        # A mistyped id (a user's copy-paste cut short, upper case) is told
        # what an id looks like, not only "no such path".
        for path in ("/cases/xyz", "/cases/0123456789ABCDEF", "/cases/0123456789abcde/state"):
            detail = json.loads(self.d.request("GET", path)[2])["detail"]
            self.assertIn("a case id is 16 lowercase hexadecimal digits", detail, path)
        for path in ("/nope", "/health/x", "/cases/0123456789abcdef/what"):
            detail = json.loads(self.d.request("GET", path)[2])["detail"]
            self.assertNotIn("case id", detail, path)
        case_id = self.d.create(tiny_case("methods"))["id"]
        for method, path, allow in (("DELETE", "/cases", "GET, HEAD, POST"),
                                    ("PUT", "/cases/" + case_id, "GET, HEAD, DELETE"),
                                    ("GET", "/cases/%s/start" % case_id, "POST"),
                                    ("POST", "/cases/%s/state" % case_id, "GET, HEAD"),
                                    ("POST", "/health", "GET, HEAD"),
                                    ("DELETE", "/cases/%s/result.h5" % case_id, "GET, HEAD")):
            status, headers, data = self.d.request(method, path)
            self.assertEqual(status, 405, (method, path))
            self.assertEqual(headers["allow"], allow)
            self.assertEqual(json.loads(data)["status"], 405)


class AuthTest(unittest.TestCase):
    TOKEN = "s3cret-token-for-tests"

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon(token=cls.TOKEN).start()

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()
        cls.d.close()

    def test_token_required(self):
        for token in (None, "wrong", self.TOKEN + "x", self.TOKEN[:-1], ""):
            for method, path in (("GET", "/cases"), ("POST", "/cases"), ("GET", "/cases/0123456789abcdef")):
                status, headers, data = self.d.request(method, path, b"{}" if method == "POST" else None,
                                                       token=token)
                self.assertEqual(status, 401, (token, path))
                self.assertTrue(headers["www-authenticate"].startswith("Bearer"))
                self.assertEqual(json.loads(data)["status"], 401)
        status, headers, data = self.d.request("GET", "/cases", headers={"Authorization": "Basic abc"},
                                               token=None)
        self.assertEqual(status, 401)

    def test_health_needs_no_token(self):
        status, body = self.d.json("GET", "/health", token=None)
        self.assertEqual((status, body["status"]), (200, "ok"))

    def test_right_token_works(self):
        status, body = self.d.json("GET", "/cases")
        self.assertEqual((status, body), (200, {"cases": []}))
        st = self.d.create(tiny_case("authed"))
        self.assertEqual(self.d.status(st["id"])["state"], "created")

    def test_env_token(self):
        d = Daemon(env={"FDEMD_TOKEN": "from-env"}).start()
        try:
            self.assertEqual(d.request("GET", "/cases", token=None)[0], 401)
            self.assertEqual(d.request("GET", "/cases", token="from-env")[0], 200)
        finally:
            d.stop()
            d.close()


if __name__ == "__main__":
    unittest.main()
