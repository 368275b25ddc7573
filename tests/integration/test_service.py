"""Service details a user meets on the first day (issue 15 item 6, contract
5.4): the status' started/finished_at/elapsed and their persistence across
a restart, a finished case's mean speed, progress never 100 % before the
end, POST /cases?dry_run=true (its step count against the run's), the
warning of a case that will run for hours, GET /cases?state=, unknown
query parameters, the daemon's log line per case event, and fetch never
overwriting a file unless forced."""
import json
import os
import re
import sys
import tempfile
import time
import unittest
from datetime import datetime

from fdemd_harness import ROOT, Daemon, DaemonTestCase, boom_case, tiny_case

sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
import fdemd_client  # noqa: E402

# "warnings" (contract 6.2) is always there, empty for a plausible case
SIZING_KEYS = {"nodes", "elements", "joints", "dt", "steps", "snapshots", "memory_bytes",
               "result_bytes", "estimated_seconds", "estimate", "warnings", "ranks"}
STATES = ("created", "queued", "running", "paused", "finished", "stopped", "failed")
LONG = 1e3  # simulated seconds: never finishes within a test


def iso(text):
    """An ISO 8601 UTC time as the daemon writes it ("...T...Z")."""
    return datetime.strptime(text, "%Y-%m-%dT%H:%M:%S.%fZ")


class ServiceTest(DaemonTestCase):
    """One daemon for the class (fdemd_harness); each test leaves no case behind."""

    def tearDown(self):
        for st in self.d.json("GET", "/cases")[1]["cases"]:
            self.d.request("DELETE", "/cases/" + st["id"])

    def run_to_end(self, case):
        st = self.d.create(case, start=True)
        return self.d.wait_state(st["id"], ("finished", "failed", "stopped"), timeout=60)

    # ------------------------------------------------ started, finished_at, elapsed

    def test_created_case_has_not_started(self):
        st = self.d.create(tiny_case("fresh"))
        self.assertIsNone(st["started"])
        self.assertIsNone(st["finished_at"])
        self.assertEqual(st["elapsed"], 0)
        self.assertEqual(st["steps_per_second"], 0)

    def test_finished_case_shows_times_and_its_mean_speed(self):
        st = self.run_to_end(tiny_case("timed", end=0.002))
        self.assertEqual(st["state"], "finished")
        created, started, finished = iso(st["created"]), iso(st["started"]), iso(st["finished_at"])
        self.assertLessEqual(created, started)
        self.assertLessEqual(started, finished)
        self.assertGreater(st["elapsed"], 0)
        # Stepping happened between the start and the end.
        self.assertLessEqual(st["elapsed"], (finished - started).total_seconds() + 0.01)
        # Mean speed: every step over the wall time spent stepping, not 0.
        self.assertGreater(st["steps_per_second"], 0)
        self.assertAlmostEqual(st["steps_per_second"], st["step"] / st["elapsed"],
                               delta=1e-9 * st["steps_per_second"])
        self.assertEqual(st["progress"], 1.0)
        # The list shows the same.
        listed = self.d.json("GET", "/cases?state=finished")[1]["cases"]
        self.assertEqual([c["finished_at"] for c in listed], [st["finished_at"]])

    def test_stopped_and_failed_cases_have_finished_at(self):
        stopped = self.d.create(tiny_case("to-stop", end=LONG), start=True)["id"]
        self.d.wait(stopped, lambda s: s["step"] > 0, what="some steps")
        status, st = self.d.json("POST", "/cases/%s/stop" % stopped)
        self.assertEqual((status, st["state"]), (200, "stopped"))
        self.assertIsNotNone(st["finished_at"])
        self.assertGreater(st["elapsed"], 0)
        self.assertGreater(st["steps_per_second"], 0)
        self.assertLess(st["progress"], 1.0)
        failed = self.run_to_end(boom_case())
        self.assertEqual(failed["state"], "failed")
        self.assertIsNotNone(failed["started"])
        self.assertIsNotNone(failed["finished_at"])
        # Stopped before it ever ran: ended, never started.
        never = self.d.create(tiny_case("never"))["id"]
        st = self.d.json("POST", "/cases/%s/stop" % never)[1]
        self.assertIsNone(st["started"])
        self.assertIsNotNone(st["finished_at"])

    def test_elapsed_adds_up_over_pause_and_resume(self):
        case_id = self.d.create(tiny_case("resumed", end=LONG), start=True)["id"]
        self.d.wait(case_id, lambda s: s["step"] > 0, what="some steps")
        status, paused = self.d.json("POST", "/cases/%s/pause" % case_id)
        self.assertEqual((status, paused["state"]), (200, "paused"))
        first = paused["elapsed"]
        self.assertGreater(first, 0)
        time.sleep(0.2)  # paused time is not stepping time
        again = self.d.status(case_id)
        self.assertEqual(again["elapsed"], first)
        self.assertIsNone(again["finished_at"])
        self.d.json("POST", "/cases/%s/start" % case_id)
        st = self.d.wait(case_id, lambda s: s["elapsed"] > first, what="more elapsed")
        self.assertEqual(st["started"], paused["started"])  # the first start stays

    def test_progress_is_below_1_until_finished(self):
        case_id = self.d.create(tiny_case("progress", end=0.003, interval=0.0003), start=True)["id"]
        seen = []
        while True:
            st = self.d.status(case_id)
            seen.append((st["state"], st["progress"]))
            if st["state"] in ("finished", "failed", "stopped"):
                break
        self.assertEqual(seen[-1], ("finished", 1.0))
        for state, progress in seen[:-1]:
            self.assertLess(progress, 1.0, seen)

    def test_fdemctl_wait_never_prints_running_100(self):
        case_id = self.d.create(tiny_case("waited", end=0.003, interval=0.0003), start=True)["id"]
        r = self.d.fdemctl("wait", case_id, "--interval", "0.05", timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = r.stdout.splitlines()
        self.assertTrue(lines)
        for line in lines:
            self.assertNotRegex(line, r"^running\s+100", lines)

    # --------------------------------------------------------------- dry run

    def test_dry_run_sizes_without_storing(self):
        case = tiny_case("sized", end=0.002, interval=0.0002)
        status, headers, data = self.d.request("POST", "/cases?dry_run=true", case)
        self.assertEqual(status, 200, data)
        self.assertNotIn("location", headers)
        z = json.loads(data)
        self.assertEqual(set(z), SIZING_KEYS)
        self.assertEqual(z["warnings"], [])
        self.assertEqual((z["nodes"], z["elements"], z["joints"]), (121, 200, 0))
        self.assertGreater(z["memory_bytes"], 0)
        self.assertGreater(z["result_bytes"], 0)
        self.assertGreater(z["estimated_seconds"], 0)
        # Nothing stored: no case listed, no directory made.
        self.assertEqual(self.d.json("GET", "/cases")[1]["cases"], [])
        self.assertEqual(self.d.json("GET", "/health")[1]["cases"], 0)
        self.assertEqual([n for n in os.listdir(self.d.data_dir) if not n.startswith(".")], [])

    def assert_dry_run_matches_the_run(self, case):
        status, z = self.d.json("POST", "/cases?dry_run=true", case)
        self.assertEqual(status, 200, z)
        st = self.run_to_end(case)
        self.assertEqual(st["state"], "finished", st)
        # Contract: the step estimate within 1 % of the steps the run takes.
        self.assertLessEqual(abs(z["steps"] - st["step"]), 0.01 * st["step"], (z, st["step"]))
        self.assertEqual(z["dt"], st["dt"])
        self.assertEqual((z["nodes"], z["elements"], z["joints"]),
                         (st["nodes"], st["elements"], st["joints"]))
        self.assertEqual(z["snapshots"], st["snapshots"])
        return z, st

    def test_dry_run_steps_match_the_run_auto_dt(self):
        z, st = self.assert_dry_run_matches_the_run(tiny_case("auto", end=0.002, interval=0.0002))
        self.assertGreater(st["step"], 1000)

    def test_dry_run_steps_match_the_run_given_dt_and_a_short_last_step(self):
        # end / dt = 1234.5: the last step is cut, and counted once.
        case = tiny_case("given", end=0.0012345, interval=0.0003)
        case["time"]["dt"] = 1e-6
        z, st = self.assert_dry_run_matches_the_run(case)
        self.assertEqual(st["step"], 1235)
        self.assertEqual(z["steps"], 1235)

    def test_dry_run_snapshots_when_an_output_time_falls_in_the_cut_last_step(self):
        # Full steps of 1 us end at 1.234 ms, the cut one at 1.2345 ms; the
        # third output time, 1.23426 ms, lies inside that cut step, so the
        # end snapshot stands for it: 0, two outputs, the end = 4 (the dry
        # run counted 5, one per output time before the end).
        case = tiny_case("cut-output", end=0.0012345, interval=0.00041142)
        case["time"]["dt"] = 1e-6
        z, st = self.assert_dry_run_matches_the_run(case)
        self.assertEqual(st["snapshots"], 4)

    def test_dry_run_memory_and_result_scale_with_the_mesh(self):
        small = self.d.json("POST", "/cases?dry_run=true", tiny_case("s", divisions=(10, 10)))[1]
        large = self.d.json("POST", "/cases?dry_run=true", tiny_case("l", divisions=(40, 40)))[1]
        # 16 x the elements, (41/11)^2 = 13.9 x the nodes: memory and the
        # per-snapshot data grow between those ratios.
        for key in ("memory_bytes", "result_bytes"):
            ratio = large[key] / small[key]
            self.assertGreater(ratio, 10, key)
            self.assertLess(ratio, 17, key)

    def test_dry_run_result_bytes_against_the_file(self):
        # 61 snapshots of 3721 nodes and 7200 elements: the data (~13 MB)
        # dwarf HDF5's own metadata, which the estimate leaves out.
        case = tiny_case("big", end=0.0006, divisions=(60, 60), interval=0.00001)
        z = self.d.json("POST", "/cases?dry_run=true", case)[1]
        st = self.run_to_end(case)
        self.assertEqual(st["state"], "finished", st)
        size = os.path.getsize(os.path.join(self.d.data_dir, st["id"], "result.h5"))
        self.assertLessEqual(z["result_bytes"], size)
        self.assertGreater(z["result_bytes"], 0.95 * size, (z["result_bytes"], size))

    def test_dry_run_refusals(self):
        status, problem = self.d.json("POST", "/cases?dry_run=true", {"name": "x"})
        self.assertEqual(status, 422)
        self.assertTrue(problem["errors"])
        status, _ = self.d.json("POST", "/cases?dry_run=true", "{not json")
        self.assertEqual(status, 400)
        status, problem = self.d.json("POST", "/cases?dry_run=maybe", tiny_case())
        self.assertEqual(status, 400)
        self.assertIn("dry_run", problem["detail"])
        status, problem = self.d.json("POST", "/cases?dry_run=true&start=true", tiny_case())
        self.assertEqual(status, 400)
        self.assertIn("start", problem["detail"])
        status, headers, _ = self.d.request("PUT", "/cases?dry_run=true", tiny_case())
        self.assertEqual(status, 405)
        self.assertIn("POST", headers["allow"])
        self.assertEqual(self.d.json("GET", "/cases")[1]["cases"], [])

    def test_a_case_that_runs_for_hours_is_warned_about(self):
        # ~1e10 steps: hours on any machine.
        long = tiny_case("hours", end=1e4, interval=1e3)
        status, z = self.d.json("POST", "/cases?dry_run=true", long)
        self.assertEqual(status, 200)
        self.assertGreater(z["steps"], 1e9)
        self.assertGreaterEqual(z["estimated_seconds"], 3600)
        self.assertRegex(z["warning"], r"will run for about [\d.]+ (hours|days|years)")
        st = self.d.create(long)
        self.assertIn("warning", st)
        self.assertRegex(st["warning"], r"will run for about [\d.]+ (hours|days|years)")
        self.assertNotIn("warning", self.d.status(st["id"]))  # said once, in the 201
        short = self.d.create(tiny_case("short"))
        self.assertNotIn("warning", short)
        self.assertNotIn("warning", self.d.json("POST", "/cases?dry_run=true", tiny_case())[1])

    # -------------------------------------------------- ?state= and query rules

    def test_list_by_state(self):
        created = self.d.create(tiny_case("c"))["id"]
        finished = self.run_to_end(tiny_case("f", end=0.0005))["id"]
        stopped = self.d.create(tiny_case("s"))["id"]
        self.d.json("POST", "/cases/%s/stop" % stopped)
        expect = {"created": [created], "finished": [finished], "stopped": [stopped],
                  "running": [], "queued": [], "paused": [], "failed": []}
        for state in STATES:
            status, body = self.d.json("GET", "/cases?state=" + state)
            self.assertEqual(status, 200)
            self.assertEqual([c["id"] for c in body["cases"]], expect[state], state)
            self.assertTrue(all(c["state"] == state for c in body["cases"]))
        self.assertEqual(len(self.d.json("GET", "/cases")[1]["cases"]), 3)

    def test_list_by_invalid_state_is_400(self):
        for query in ("state=done", "state=", "state=Running", "state=created&state=finished"):
            status, problem = self.d.json("GET", "/cases?" + query)
            self.assertEqual(status, 400, query)
            self.assertIn("state", problem["detail"], query)

    def test_unknown_query_parameters_are_400_naming_them(self):
        case_id = self.d.create(tiny_case("q"))["id"]
        for method, path, name in [
                ("GET", "/health?verbose=1", "verbose"),
                ("GET", "/cases?stat=running", "stat"),
                ("POST", "/cases?strat=true", "strat"),
                ("GET", "/cases/%s?full=1" % case_id, "full"),
                ("POST", "/cases/%s/start?force=1" % case_id, "force"),
                ("POST", "/cases/%s/pause?now" % case_id, "now"),
                ("DELETE", "/cases/%s?really=yes" % case_id, "really"),
                ("GET", "/cases/%s/state?field=position" % case_id, "field"),
                ("GET", "/cases/%s/result.h5?x=1" % case_id, "x"),
                ("GET", "/cases/%s/case?pretty=1" % case_id, "pretty")]:
            body = tiny_case("q2") if path.startswith("/cases?") and method == "POST" else None
            status, problem = self.d.json(method, path, body)
            self.assertEqual(status, 400, (method, path))
            self.assertIn('"%s"' % name, problem["detail"], (method, path))
        # None of them did anything: still one case, still created.
        cases = self.d.json("GET", "/cases")[1]["cases"]
        self.assertEqual([(c["id"], c["state"]) for c in cases], [(case_id, "created")])
        # The known ones still work, and the path and method come first.
        self.assertEqual(self.d.request("GET", "/cases/%s/state?fields=position" % case_id)[0], 200)
        self.assertEqual(self.d.request("GET", "/nowhere?x=1")[0], 404)
        self.assertEqual(self.d.request("PUT", "/cases?x=1")[0], 405)
        self.assertEqual(self.d.request("GET", "/cases/%s?x=1" % ("0" * 16))[0], 400)
        self.assertEqual(self.d.request("GET", "/cases/%s" % ("0" * 16))[0], 404)

    def test_query_commands_keep_their_conflicts(self):
        case_id = self.run_to_end(tiny_case("done", end=0.0005))["id"]
        status, problem = self.d.json("POST", "/cases/%s/start" % case_id)
        self.assertEqual(status, 409)
        self.assertEqual(self.d.json("GET", "/cases?state=finished")[1]["cases"][0]["id"], case_id)


class DryRunLimitsTest(unittest.TestCase):
    """A dry run is refused exactly as the upload would be."""

    def test_over_max_case_memory_is_422_naming_the_size(self):
        d = Daemon(args=["--max-case-memory", "1M"]).start()
        try:
            big = tiny_case("big", divisions=(200, 200))
            status, problem = d.json("POST", "/cases?dry_run=true", big)
            self.assertEqual(status, 422, problem)
            self.assertEqual(problem["errors"][0]["pointer"], "/parts")
            self.assertIn("limit", problem["errors"][0]["message"])
            status, z = d.json("POST", "/cases?dry_run=true", tiny_case("small"))
            self.assertEqual(status, 200)
            self.assertLess(z["memory_bytes"], 1 << 20)
        finally:
            d.close()


class ServiceLogTest(unittest.TestCase):
    """The daemon's log: one line per case event, with the case id and figures."""

    def setUp(self):
        self.d = Daemon().start()

    def tearDown(self):
        self.d.close()

    def lines_of(self, case_id):
        pattern = re.compile(r'^fdemd: case %s "[^"]*": (.*)$' % case_id)
        return [m.group(1) for m in map(pattern.match, self.d.log_tail(200000).splitlines()) if m]

    @staticmethod
    def events(lines):
        return [re.match(r"[a-z ]+", line).group(0).strip() for line in lines]

    def test_one_line_per_event(self):
        done = self.d.create(tiny_case("logged", end=0.001), start=True)["id"]
        st = self.d.wait_state(done, "finished")
        boom = self.d.create(boom_case())["id"]
        self.d.json("POST", "/cases/%s/start" % boom)
        failed = self.d.wait_state(boom, "failed")
        paused_id = self.d.create(tiny_case("paused", end=LONG), start=True)["id"]
        self.d.wait(paused_id, lambda s: s["step"] > 0, what="some steps")
        paused = self.d.json("POST", "/cases/%s/pause" % paused_id)[1]

        lines = self.lines_of(done)
        self.assertEqual(self.events(lines), ["submitted", "started at step", "finished at step"],
                         lines)
        self.assertRegex(lines[0], r"submitted: 121 nodes, 200 elements, 0 joints, dt = [\d.e+-]+ s, "
                                   r"end = 0.001 s, %d steps" % st["step"])
        self.assertIn("finished at step %d " % st["step"], lines[2])
        self.assertIn("%d snapshots" % st["snapshots"], lines[2])
        self.assertRegex(lines[2], r"[\d.e+]+ steps/s")
        lines = self.lines_of(boom)
        self.assertEqual(self.events(lines), ["submitted", "started at step", "failed at step"],
                         lines)
        self.assertIn("failed at step %d" % failed["step"], lines[2])
        self.assertIn("non-finite", lines[2])
        lines = self.lines_of(paused_id)
        self.assertEqual(self.events(lines), ["submitted", "started at step", "paused at step"],
                         lines)
        self.assertIn("paused at step %d " % paused["step"], lines[2])

    def test_resumed_after_a_restart(self):
        case_id = self.d.create(tiny_case("survivor", end=LONG), start=True)["id"]
        self.d.wait(case_id, lambda s: s["step"] > 0, what="some steps")
        code, _ = self.d.stop()
        self.assertEqual(code, 0)
        self.d.start()
        st = self.d.status(case_id)
        self.assertEqual(st["state"], "paused")
        lines = self.lines_of(case_id)
        resumed = [line for line in lines if line.startswith("resumed after a restart")]
        self.assertEqual(len(resumed), 1, lines)
        self.assertIn("was running when fdemd stopped, now paused at its checkpoint, step %d "
                      % st["step"], resumed[0])
        # Restarted once more, it was paused (not running) when fdemd stopped.
        code, _ = self.d.stop()
        self.assertEqual(code, 0)
        self.d.start()
        self.d.status(case_id)  # a request for the case waits for its start-up check and line
        lines = self.lines_of(case_id)
        self.assertEqual(len([line for line in lines if line.startswith("resumed")]), 1, lines)
        self.assertTrue(lines[-1].startswith("restored after a restart: paused at step %d"
                                             % st["step"]), lines)


class ServiceRestartTest(unittest.TestCase):
    """started, finished_at and elapsed are in status.json: a restart keeps them."""

    def test_times_survive_a_restart(self):
        d = Daemon()
        try:
            d.start()
            finished = d.create(tiny_case("kept", end=0.001), start=True)["id"]
            before_finished = d.wait_state(finished, "finished")
            paused_id = d.create(tiny_case("half", end=LONG), start=True)["id"]
            d.wait(paused_id, lambda s: s["step"] > 0, what="some steps")
            before_paused = d.json("POST", "/cases/%s/pause" % paused_id)[1]
            running = d.create(tiny_case("running", end=LONG), start=True)["id"]
            before_running = d.wait(running, lambda s: s["step"] > 0, what="some steps")
            code, _ = d.stop()
            self.assertEqual(code, 0)

            d.start()
            after = d.status(finished)
            for key in ("started", "finished_at", "elapsed", "steps_per_second", "step"):
                self.assertEqual(after[key], before_finished[key], key)
            after = d.status(paused_id)
            for key in ("started", "finished_at", "elapsed", "step"):
                self.assertEqual(after[key], before_paused[key], key)
            after = d.status(running)
            self.assertEqual(after["state"], "paused")
            self.assertEqual(after["started"], before_running["started"])
            self.assertIsNone(after["finished_at"])
            self.assertGreaterEqual(after["elapsed"], before_running["elapsed"])
            self.assertGreater(after["elapsed"], 0)
            # Run on: elapsed keeps adding, the first start stays.
            d.json("POST", "/cases/%s/start" % running)
            st = d.wait(running, lambda s: s["elapsed"] > after["elapsed"], what="more elapsed")
            self.assertEqual(st["started"], before_running["started"])
            code, _ = d.stop()
            self.assertEqual(code, 0)
        finally:
            d.close()


class FetchTest(unittest.TestCase):
    """fdemctl fetch and Client.fetch: <name>.h5 by default, never overwriting
    an existing file unless forced."""

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon().start()
        cls.case_id = cls.d.create(tiny_case("fetch me", end=0.0005), start=True)["id"]
        cls.d.wait_state(cls.case_id, "finished")
        cls.url = "http://127.0.0.1:%d" % cls.d.port

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()
        cls.d.close()

    def setUp(self):
        self.work = tempfile.TemporaryDirectory(prefix="fdemd-fetch-")

    def tearDown(self):
        self.work.cleanup()

    def ctl(self, *args):
        return self.d.fdemctl(*args, cwd=self.work.name)

    def test_fdemctl_fetch_names_the_file_after_the_case_and_never_overwrites(self):
        r = self.ctl("fetch", self.case_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        h5 = os.path.join(self.work.name, "fetch_me.h5")  # the name, made file-safe
        self.assertEqual(r.stdout.split(), ["fetch_me.h5", "fetch_me.xdmf"])
        with open(h5, "rb") as f:
            self.assertEqual(f.read(4), b"\x89HDF")
        with open(h5, "wb") as f:
            f.write(b"mine")
        r = self.ctl("fetch", self.case_id)
        self.assertEqual(r.returncode, 1)
        self.assertIn("fetch_me.h5 exists", r.stderr)
        self.assertIn("--force", r.stderr)
        with open(h5, "rb") as f:
            self.assertEqual(f.read(), b"mine")
        # The .xdmf alone is protected too.
        os.remove(h5)
        r = self.ctl("fetch", self.case_id, "-o", "fetch_me.h5")
        self.assertEqual(r.returncode, 1)
        self.assertIn("fetch_me.xdmf exists", r.stderr)
        self.assertFalse(os.path.exists(h5))
        r = self.ctl("fetch", self.case_id, "--force")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(h5, "rb") as f:
            self.assertEqual(f.read(4), b"\x89HDF")
        self.assertEqual(os.listdir(self.work.name).count("fetch_me.h5.part"), 0)

    def test_python_fetch_never_overwrites_unless_forced(self):
        client = fdemd_client.Client(self.url)
        path = os.path.join(self.work.name, "run.h5")
        self.assertEqual(client.fetch(self.case_id, path),
                         (path, os.path.join(self.work.name, "run.xdmf")))
        with open(path, "wb") as f:
            f.write(b"mine")
        with self.assertRaises(FileExistsError) as caught:
            client.fetch(self.case_id, path)
        self.assertIn("force=True", str(caught.exception))
        with open(path, "rb") as f:
            self.assertEqual(f.read(), b"mine")
        client.fetch(self.case_id, path, force=True)
        with open(path, "rb") as f:
            self.assertEqual(f.read(4), b"\x89HDF")
        # Default name: <name>.h5 in the current directory.
        cwd = os.getcwd()
        os.chdir(self.work.name)
        try:
            self.assertEqual(client.fetch(self.case_id)[0], "fetch_me.h5")
        finally:
            os.chdir(cwd)

    def test_python_client_dry_run_and_list_by_state(self):
        client = fdemd_client.Client(self.url)
        z = client.dry_run(tiny_case("py"))
        self.assertTrue(SIZING_KEYS <= set(z))
        with self.assertWarnsRegex(UserWarning, r"will run for about"):
            hours = client.submit(tiny_case("py-hours", end=1e4, interval=1e3))
        client.delete(hours)
        self.assertEqual([c["id"] for c in client.list(state="finished")], [self.case_id])
        self.assertEqual(client.list(state="running"), [])
        with self.assertRaises(fdemd_client.FdemdError) as caught:
            client.list(state="done")
        self.assertEqual(caught.exception.status, 400)

    def test_python_client_docstring_points_at_docs_that_exist(self):
        doc = fdemd_client.__doc__
        named = re.findall(r"[\w./-]+\.md", doc)
        self.assertTrue(named, doc)
        for path in named:
            self.assertTrue(os.path.exists(os.path.join(ROOT, path)), path)


if __name__ == "__main__":
    unittest.main()
