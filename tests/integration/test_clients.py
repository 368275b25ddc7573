"""test_clients.py - fdemctl, the Python client and plot_result.py against
the real daemon.

Every test drives a real bin/fdemd started on a free loopback port with a
temporary data directory, so what is checked is what a user gets: exit
codes, what reaches stdout/stderr, and files that open with h5py.
The cases are tiny (a few elements, ~100-1000 steps) to keep the whole file
well under a minute.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))

import h5py  # noqa: E402
import numpy as np  # noqa: E402
from fdemd_client import Client, FdemdConnectionError, FdemdError  # noqa: E402

import fdemd_harness  # noqa: E402  (starts bin/fdemd on port 0, temp data dir)

FDEMCTL = os.environ.get("FDEMCTL_BIN", "bin/fdemctl")
if not os.path.isabs(FDEMCTL):
    FDEMCTL = os.path.join(ROOT, FDEMCTL)
PLOT = os.path.join(ROOT, "clients", "python", "plot_result.py")
PYTHON = "/usr/bin/python3"
SLOW = fdemd_harness.SLOW     # sanitizer builds: every time limit scales

MATERIAL = {"density": 2000, "young": 1e8, "poisson": 0.25}


def quick_case(name="quick", end=0.01):
    """A 2x2 block falling under gravity: ~150 steps, 11 snapshots."""
    return {
        "name": name,
        "materials": {"rock": dict(MATERIAL)},
        "parts": [{"name": "block", "material": "rock",
                   "rectangle": {"origin": [0, 0], "size": [0.1, 0.1], "divisions": [2, 2]}}],
        "gravity": [0, -9.81],
        "time": {"end": end},
        "output": {"interval": end / 10, "fields": ["position", "velocity", "stress"]},
    }


def long_case(name="long"):
    """Runs far longer than any test waits: for pause/stop."""
    return quick_case(name, end=1000.0)


def wait_for(predicate, timeout=10.0, interval=0.05):
    deadline = time.monotonic() + timeout * SLOW
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(interval)
    return predicate()


class ClientTestCase(unittest.TestCase):
    """One daemon per test class; helpers to run fdemctl against it."""

    token = None     # the daemon's --token, and what the clients send

    @classmethod
    def setUpClass(cls):
        cls.daemon = fdemd_harness.Daemon(token=cls.token).start()
        cls.url = "http://127.0.0.1:%d" % cls.daemon.port
        cls.client = Client(cls.url, token=cls.token)
        cls.work = tempfile.TemporaryDirectory(prefix="fdemctl-work-")

    @classmethod
    def tearDownClass(cls):
        cls.daemon.stop()
        cls.daemon.close()
        cls.work.cleanup()

    def ctl(self, *args, stdin=None, token=None, server=None, timeout=30):
        env = dict(os.environ)
        env.pop("FDEMD_TOKEN", None)
        env["FDEMD_URL"] = server or self.url
        token = token if token is not None else self.token
        if token:
            env["FDEMD_TOKEN"] = token
        return subprocess.run([FDEMCTL] + list(args), input=stdin, capture_output=True,
                              text=True, env=env, cwd=self.work.name, timeout=timeout * SLOW)

    def write_case(self, doc, name="case.json"):
        path = os.path.join(self.work.name, name)
        with open(path, "w") as f:
            json.dump(doc, f)
        return path

    def submit(self, doc, *flags):
        r = self.ctl("submit", self.write_case(doc), *flags)
        self.assertEqual(r.returncode, 0, r.stderr)
        return r.stdout.strip()

    def finished_case(self, name="quick"):
        case_id = self.submit(quick_case(name), "--start")
        r = self.ctl("wait", case_id, "--interval", "0.1")
        self.assertEqual(r.returncode, 0, r.stderr)
        return case_id


class FdemctlTests(ClientTestCase):

    def test_help_for_every_command(self):
        r = self.ctl("--help")
        self.assertEqual(r.returncode, 0)
        for command in ("submit", "list", "status", "start", "pause", "stop", "delete",
                        "wait", "state", "fetch", "fragments"):
            self.assertIn(command, r.stdout)
            h = self.ctl(command, "--help")
            self.assertEqual(h.returncode, 0, command)
            self.assertIn("usage: fdemctl", h.stdout, command)

    def test_usage_errors_exit_2(self):
        self.assertEqual(self.ctl("frobnicate").returncode, 2)
        self.assertEqual(self.ctl("status").returncode, 2)
        self.assertEqual(self.ctl("status", "a", "b").returncode, 2)
        self.assertEqual(self.ctl("wait", "x", "--interval", "-1").returncode, 2)

    def test_server_option_before_or_after_the_command(self):
        dead = "http://127.0.0.1:9"  # FDEMD_URL points nowhere: only --server can reach it
        for args in (("--server", self.url, "list"), ("list", "--server", self.url),
                     ("list", "--server=" + self.url)):
            r = self.ctl(*args, server=dead)
            self.assertEqual(r.returncode, 0, (args, r.stderr))
        self.assertEqual(self.ctl("list", "--server", server=dead).returncode, 2)

    def test_submit_prints_only_the_id(self):
        case_id = self.submit(quick_case("submitted"))
        self.assertRegex(case_id, r"^\S+$")
        s = json.loads(self.ctl("status", case_id, "--json").stdout)
        self.assertEqual(s["id"], case_id)
        self.assertEqual(s["name"], "submitted")
        self.assertEqual(s["state"], "created")

    def test_submit_from_stdin(self):
        r = self.ctl("submit", "-", stdin=json.dumps(quick_case("from-stdin")))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.client.status(r.stdout.strip())["name"], "from-stdin")

    def test_submit_invalid_case_shows_pointer_and_message(self):
        doc = quick_case("bad")
        doc["parts"][0]["material"] = "granit"
        r = self.ctl("submit", self.write_case(doc, "bad.json"))
        self.assertEqual(r.returncode, 1)
        self.assertEqual(r.stdout, "")
        self.assertIn("422", r.stderr)
        self.assertIn("/parts/0/material:", r.stderr)
        self.assertIn("granit", r.stderr)

    def test_submit_malformed_json_is_refused(self):
        r = self.ctl("submit", "-", stdin='{"name": "broken",')
        self.assertEqual(r.returncode, 1)
        self.assertIn("400", r.stderr)

    def test_submit_missing_file(self):
        # A file the user mistyped is a usage error (2), not a refusal by
        # the server (1): a script must be able to tell the two apart.
        r = self.ctl("submit", "/nonexistent/case.json")
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("/nonexistent/case.json", r.stderr)

    def test_submit_a_directory_says_why(self):
        # fopen() takes a directory on Linux; the read then fails, and the
        # user is told the reason, not only that it failed.
        r = self.ctl("submit", os.path.join(ROOT, "examples"))
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("examples: Is a directory", r.stderr)

    def test_list_shows_every_case(self):
        a = self.submit(quick_case("listed-a"))
        b = self.submit(quick_case("listed-b"))
        r = self.ctl("list")
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = r.stdout.splitlines()
        self.assertTrue(lines[0].startswith("ID"))
        rows = {line.split()[0]: line for line in lines[1:]}
        self.assertIn("listed-a", rows[a])
        self.assertIn("created", rows[b])

    def test_status_table_and_json(self):
        case_id = self.finished_case("status-me")
        table = self.ctl("status", case_id)
        self.assertEqual(table.returncode, 0)
        self.assertIn("finished", table.stdout)
        self.assertIn("100.0 %", table.stdout)
        # one body, no contact: its contact account is 0, not "-0"
        self.assertRegex(table.stdout, r"contact 0[,\n]")
        s = json.loads(self.ctl("status", case_id, "--json").stdout)
        for key in ("id", "name", "state", "step", "time", "end_time", "progress", "dt",
                    "nodes", "elements", "snapshots"):
            self.assertIn(key, s)
        self.assertEqual(s["state"], "finished")
        self.assertAlmostEqual(s["progress"], 1.0, places=9)
        self.assertEqual(s["elements"], 8)   # 2 x 2 cells, two triangles each
        self.assertEqual(s["nodes"], 9)

    def test_start_pause_stop_delete(self):
        case_id = self.submit(long_case("lifecycle"))
        r = self.ctl("start", case_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.split(), [case_id, "running"])
        self.assertEqual(self.ctl("pause", case_id).returncode, 0)
        self.assertTrue(wait_for(lambda: self.client.status(case_id)["state"] == "paused"))
        step = self.client.status(case_id)["step"]
        time.sleep(0.3)
        self.assertEqual(self.client.status(case_id)["step"], step, "a paused case must not step")
        again = self.ctl("pause", case_id)          # paused -> paused is not allowed
        self.assertEqual(again.returncode, 1)
        self.assertIn("409", again.stderr)
        self.assertEqual(self.ctl("start", case_id).returncode, 0)
        r = self.ctl("stop", case_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.split(), [case_id, "stopped"])
        self.assertEqual(self.ctl("start", case_id).returncode, 1)   # terminal
        r = self.ctl("delete", case_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        gone = self.ctl("status", case_id)
        self.assertEqual(gone.returncode, 1)
        self.assertIn("404", gone.stderr)

    def test_unknown_case_is_404(self):
        for command in ("status", "start", "pause", "stop", "delete", "wait", "state", "fetch"):
            r = self.ctl(command, "no-such-case")
            self.assertEqual(r.returncode, 1, command)
            self.assertIn("404", r.stderr, command)

    def test_wait_finished_exits_0_with_one_line_per_update(self):
        case_id = self.submit(quick_case("waited"), "--start")
        r = self.ctl("wait", case_id, "--interval", "0.1")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotIn("\r", r.stdout)     # not a terminal: plain lines
        self.assertIn("finished", r.stdout.splitlines()[-1])

    def test_wait_on_a_case_nobody_started_says_so_and_keeps_waiting(self):
        # A user who submitted without --start would otherwise watch
        # "created 0.0%" forever. wait still waits (someone may start the
        # case), but says once, on stderr, what the case is waiting for.
        case_id = self.submit(quick_case("never-started"))
        with self.assertRaises(subprocess.TimeoutExpired) as cm:
            self.ctl("wait", case_id, "--interval", "0.1", timeout=2)
        stderr = cm.exception.stderr or b""
        stderr = stderr.decode() if isinstance(stderr, bytes) else stderr
        self.assertIn("case %s is created" % case_id, stderr)
        self.assertIn("fdemctl start %s" % case_id, stderr)
        self.assertEqual(stderr.count("fdemctl start"), 1)

    def test_wait_stopped_exits_1(self):
        case_id = self.submit(long_case("to-stop"), "--start")
        self.client.stop(case_id)
        r = self.ctl("wait", case_id)
        self.assertEqual(r.returncode, 1)
        self.assertIn("stopped", r.stderr)

    def test_wait_failed_exits_1_and_prints_the_error(self):
        # 1e30 N on one corner: the element inverts within a few steps and
        # the daemon must fail the case with a sentence saying why.
        doc = quick_case("unstable", end=1.0)
        doc["constraints"] = [{"box": [0.09, 0.09, 0.11, 0.11], "force": [1e30, 0]}]
        case_id = self.submit(doc, "--start")
        w = self.ctl("wait", case_id, "--interval", "0.1")
        self.assertEqual(w.returncode, 1)
        self.assertIn("case %s failed: " % case_id, w.stderr)
        self.assertIn("non-finite", w.stderr)

    def test_connection_error_names_the_url_and_exits_2(self):
        r = self.ctl("list", server="http://127.0.0.1:9")
        self.assertEqual(r.returncode, 2)
        self.assertIn("http://127.0.0.1:9", r.stderr)
        r = self.ctl("wait", "x", server="http://127.0.0.1:9")
        self.assertEqual(r.returncode, 2)

    def test_server_option_overrides_environment(self):
        r = self.ctl("--server", self.url, "list", server="http://127.0.0.1:9")
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_state_prints_the_fields(self):
        case_id = self.finished_case("stateful")
        r = self.ctl("state", case_id, "--fields", "position,velocity")
        self.assertEqual(r.returncode, 0, r.stderr)
        state = json.loads(r.stdout)
        self.assertEqual(len(state["position"]), 9)
        self.assertEqual(len(state["velocity"][0]), 2)
        self.assertIn("step", state)
        # Free fall for 0.01 s: every node moves at g t (central difference
        # is exact for constant acceleration up to one half step).
        for vx, vy in state["velocity"]:
            self.assertAlmostEqual(vx, 0.0, places=9)
            self.assertAlmostEqual(vy, -9.81 * state["time"], delta=9.81 * 1e-3)

    def test_fetch_writes_h5_and_an_xdmf_that_points_at_it(self):
        case_id = self.finished_case("fetched")
        r = self.ctl("fetch", case_id, "-o", "run1.h5")
        self.assertEqual(r.returncode, 0, r.stderr)
        h5 = os.path.join(self.work.name, "run1.h5")
        xdmf = os.path.join(self.work.name, "run1.xdmf")
        status = self.client.status(case_id)
        with h5py.File(h5, "r") as f:
            self.assertEqual(f["/snapshots/time"].shape[0], status["snapshots"])
            self.assertEqual(f["/mesh/triangles"].shape, (8, 3))
        with open(xdmf) as f:
            text = f.read()
        self.assertIn("run1.h5:/", text)
        self.assertNotIn("result.h5", text)
        self.assertFalse(os.path.exists(h5 + ".part"))

    def test_fetch_default_name_is_the_case_name(self):
        case_id = self.finished_case("named-result")
        r = self.ctl("fetch", case_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(os.path.exists(os.path.join(self.work.name, "named-result.h5")))
        self.assertTrue(os.path.exists(os.path.join(self.work.name, "named-result.xdmf")))


class TokenTests(ClientTestCase):
    token = "s3cret"

    def test_fdemctl_sends_the_token(self):
        self.assertEqual(self.ctl("list").returncode, 0)
        case_id = self.submit(quick_case("guarded"))
        self.assertEqual(self.ctl("status", case_id).returncode, 0)

    def test_missing_or_wrong_token_is_401(self):
        # The detail tells the two user mistakes apart: no token sent (set
        # FDEMD_TOKEN) and a token that is not the daemon's.
        for token, says in (("", "set FDEMD_TOKEN"), ("wrong", "does not match")):
            r = self.ctl("list", token=token)      # "" = FDEMD_TOKEN unset
            self.assertEqual(r.returncode, 1, token)
            self.assertIn("401", r.stderr)
            self.assertIn(says, r.stderr)

    def test_health_needs_no_token(self):
        self.assertEqual(Client(self.url, token="").health()["status"], "ok")

    def test_python_client_token(self):
        self.assertIsInstance(self.client.list(), list)
        with self.assertRaises(FdemdError) as e:
            Client(self.url, token="wrong").list()
        self.assertEqual(e.exception.status, 401)


class PythonClientTests(ClientTestCase):

    def test_submit_start_wait_with_callback_then_fetch(self):
        case_id = self.client.submit(quick_case("py"))
        self.assertEqual(self.client.status(case_id)["state"], "created")
        self.assertEqual(self.client.start(case_id)["state"], "running")
        seen = []
        final = self.client.wait(case_id, callback=seen.append, interval=0.05, timeout=30 * SLOW)
        self.assertEqual(final["state"], "finished")
        self.assertGreaterEqual(len(seen), 1)
        self.assertIs(seen[-1], final)
        h5, xdmf = self.client.fetch(case_id, os.path.join(self.work.name, "py-run.h5"))
        self.assertTrue(xdmf.endswith("py-run.xdmf"))
        with h5py.File(h5, "r") as f:
            self.assertEqual(f["/snapshots/time"].shape[0], final["snapshots"])
            self.assertAlmostEqual(float(f["/snapshots/time"][-1]), final["time"], delta=1e-12)
        with open(xdmf) as f:
            self.assertIn("py-run.h5:/", f.read())

    def test_submit_from_path_with_start(self):
        case_id = self.client.submit(self.write_case(quick_case("py-path"), "p.json"), start=True)
        self.assertEqual(self.client.wait(case_id, interval=0.05, timeout=30 * SLOW)["state"], "finished")
        ids = [c["id"] for c in self.client.list()]
        self.assertIn(case_id, ids)
        self.assertEqual(self.client.case(case_id)["name"], "py-path")

    def test_invalid_case_raises_with_the_problem_list(self):
        doc = quick_case("py-bad")
        doc["parts"][0]["material"] = "granit"
        with self.assertRaises(FdemdError) as e:
            self.client.submit(doc)
        self.assertEqual(e.exception.status, 422)
        pointers = [p["pointer"] for p in e.exception.errors]
        self.assertIn("/parts/0/material", pointers)
        self.assertIn("/parts/0/material", str(e.exception))

    def test_wait_on_a_case_nobody_started_warns_once(self):
        # As fdemctl wait: a created case does not move by itself; the
        # client keeps waiting (up to its timeout) but says why, once.
        case_id = self.client.submit(quick_case("py-never-started"))
        with self.assertWarnsRegex(UserWarning, "case %s is created: .*start" % case_id) as cm:
            with self.assertRaises(TimeoutError):
                self.client.wait(case_id, interval=0.05, timeout=0.5)
        self.assertEqual(len(cm.warnings), 1)

    def test_wait_raises_on_a_stopped_case_when_asked(self):
        case_id = self.client.submit(long_case("py-stop"), start=True)
        self.assertEqual(self.client.stop(case_id)["state"], "stopped")
        self.assertEqual(self.client.wait(case_id, timeout=30 * SLOW)["state"], "stopped")
        with self.assertRaises(FdemdError) as e:
            self.client.wait(case_id, raise_on_failure=True, timeout=30 * SLOW)
        self.assertEqual(e.exception.case_status["state"], "stopped")
        self.client.delete(case_id)
        with self.assertRaises(FdemdError) as e:
            self.client.status(case_id)
        self.assertEqual(e.exception.status, 404)

    def test_state_fields(self):
        case_id = self.client.submit(quick_case("py-state"), start=True)
        self.client.wait(case_id, interval=0.05, timeout=30 * SLOW)
        state = self.client.state(case_id, ["position", "stress"])
        self.assertEqual(len(state["position"]), 9)
        self.assertEqual(len(state["stress"]), 8)
        self.assertEqual(len(state["stress"][0]), 3)

    def test_unreachable_server(self):
        with self.assertRaises(FdemdConnectionError) as e:
            Client("http://127.0.0.1:9").health()
        self.assertEqual(e.exception.status, 0)
        self.assertIn("127.0.0.1:9", str(e.exception))


class PlotTests(ClientTestCase):

    def setUp(self):
        if not hasattr(PlotTests, "h5"):
            case_id = self.client.submit(quick_case("plotted"), start=True)
            self.client.wait(case_id, interval=0.05, timeout=30 * SLOW)
            PlotTests.h5, _ = self.client.fetch(case_id, os.path.join(self.work.name, "plot.h5"))

    def plot(self, *args):
        png = os.path.join(self.work.name, "out-%d.png" % len(os.listdir(self.work.name)))
        r = subprocess.run([PYTHON, PLOT, self.h5, "-o", png] + list(args),
                           capture_output=True, text=True, timeout=60 * SLOW)
        return r, png

    def assert_png(self, r, png):
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(png, "rb") as f:
            data = f.read()
        self.assertEqual(data[:8], b"\x89PNG\r\n\x1a\n")
        self.assertGreater(len(data), 10_000)

    def test_stress_plot(self):
        self.assert_png(*self.plot("--field", "stress"))

    def test_velocity_plot_of_the_first_snapshot(self):
        self.assert_png(*self.plot("--field", "velocity", "--snapshot", "0"))

    def test_stress_component_plot(self):
        self.assert_png(*self.plot("--component", "xy"))

    def test_plot_reads_a_file_the_daemon_is_still_writing(self):
        doc = long_case("live")
        doc["output"]["interval"] = 0.005
        case_id = self.client.submit(doc, start=True)
        try:
            self.assertTrue(wait_for(lambda: self.client.status(case_id)["snapshots"] >= 3))
            live = os.path.join(self.daemon.data_dir, case_id, "result.h5")
            self.assertTrue(os.path.exists(live), live)
            png = os.path.join(self.work.name, "live.png")
            r = subprocess.run([PYTHON, PLOT, live, "-o", png, "--field", "velocity"],
                               capture_output=True, text=True, timeout=60 * SLOW)
            self.assert_png(r, png)
        finally:
            self.client.delete(case_id)

    def test_poisson_ratio_comes_from_the_file(self):
        """von Mises takes each part's nu from the case document result.h5
        carries (no longer 0.25 unless told); --case and --poisson override
        it, and a file without the document asks for one of them."""
        sys.path.insert(0, os.path.dirname(PLOT))
        from plot_result import MissingMaterial, element_poisson
        doc = quick_case("two-nu")
        doc["materials"]["soft"] = dict(MATERIAL, poisson=0.4)
        doc["materials"]["rock"]["poisson"] = 0.1
        doc["parts"].append({"name": "top", "material": "soft",
                             "rectangle": {"origin": [0, 0.2], "size": [0.1, 0.1],
                                           "divisions": [1, 1]}})
        case_id = self.client.submit(doc, start=True)
        self.client.wait(case_id, interval=0.05, timeout=30 * SLOW)
        h5, _ = self.client.fetch(case_id, os.path.join(self.work.name, "two-nu.h5"))
        other = os.path.join(self.work.name, "other.json")
        with open(other, "w") as f:
            json.dump(dict(doc, materials={"rock": dict(MATERIAL, poisson=0.3),
                                           "soft": dict(MATERIAL, poisson=0.35)}), f)
        with h5py.File(h5, "r") as f:
            part = f["/mesh/element_part"][:]
            self.assertEqual(sorted(set(part)), [0, 1])
            np.testing.assert_array_equal(element_poisson(f), np.where(part == 0, 0.1, 0.4))
            np.testing.assert_array_equal(element_poisson(f, case_path=other),
                                          np.where(part == 0, 0.3, 0.35))
            np.testing.assert_array_equal(element_poisson(f, other, poisson=0.2), 0.2)
        r = subprocess.run([PYTHON, PLOT, h5, "-o", os.path.join(self.work.name, "nu.png")],
                           capture_output=True, text=True, timeout=60 * SLOW)
        self.assert_png(r, os.path.join(self.work.name, "nu.png"))
        # a file written before the `case` attribute existed
        old = os.path.join(self.work.name, "old.h5")
        shutil.copy(h5, old)
        with h5py.File(old, "a") as f:
            del f.attrs["case"]
        with h5py.File(old, "r") as f, self.assertRaises(MissingMaterial):
            element_poisson(f)
        png = os.path.join(self.work.name, "old.png")
        r = subprocess.run([PYTHON, PLOT, old, "-o", png], capture_output=True, text=True,
                           timeout=60 * SLOW)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--poisson", r.stderr)
        self.assertFalse(os.path.exists(png))
        r = subprocess.run([PYTHON, PLOT, old, "-o", png, "--poisson", "0.25"],
                           capture_output=True, text=True, timeout=60 * SLOW)
        self.assert_png(r, png)

    def test_damage_without_joints_is_a_clear_error(self):
        r, png = self.plot("--field", "damage")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("fractures", r.stderr)
        self.assertFalse(os.path.exists(png))

    def test_snapshot_out_of_range(self):
        r, _ = self.plot("--snapshot", "999")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("out of range", r.stderr)


class ExampleTests(ClientTestCase):
    """The bundled examples stay valid case documents as the daemon evolves."""

    EXAMPLES = os.path.join(ROOT, "examples")

    def test_every_example_is_accepted(self):
        names = sorted(n for n in os.listdir(self.EXAMPLES) if n.endswith(".json"))
        self.assertGreaterEqual(len(names), 7)
        for name in names:
            with self.subTest(example=name):
                case_id = self.client.submit(os.path.join(self.EXAMPLES, name))
                s = self.client.status(case_id)
                self.assertEqual(s["name"], name[:-len(".json")])
                self.assertGreater(s["elements"], 0)
                self.client.delete(case_id)

    def assert_example_drops_half_g_t_squared(self, name, vertical):
        case_id = self.client.submit(os.path.join(self.EXAMPLES, name + ".json"), start=True)
        final = self.client.wait(case_id, interval=0.05, timeout=60 * SLOW)
        self.assertEqual(final["state"], "finished")
        h5, _ = self.client.fetch(case_id, os.path.join(self.work.name, name + ".h5"))
        with h5py.File(h5, "r") as f:
            t = f["/snapshots/time"][-1]
            drop = (f["/mesh/position0"][:, vertical]
                    - f["/snapshots/position"][-1][:, vertical])
        self.assertEqual(t, 0.5)
        # Central difference integrates constant acceleration exactly.
        for d in drop:
            self.assertAlmostEqual(d, 0.5 * 9.81 * t * t, delta=1e-9)

    def test_freefall_drops_half_g_t_squared(self):
        self.assert_example_drops_half_g_t_squared("freefall", vertical=1)

    def test_freefall_3d_drops_half_g_t_squared_along_z(self):
        self.assert_example_drops_half_g_t_squared("freefall-3d", vertical=2)

    def test_collision_3d_keeps_momentum(self):
        case_id = self.client.submit(os.path.join(self.EXAMPLES, "collision-3d.json"), start=True)
        final = self.client.wait(case_id, interval=0.05, timeout=120 * SLOW)
        self.assertEqual(final["state"], "finished")
        h5, _ = self.client.fetch(case_id, os.path.join(self.work.name, "collision-3d.h5"))
        with h5py.File(h5, "r") as f:
            mass = f["/mesh/node_mass"][:]
            part = f["/mesh/node_part"][:]
            v = f["/snapshots/velocity"][:]
        momentum = np.einsum("n,snk->sk", mass, v)
        # 2 kg at 2 m/s along x; contact forces are equal and opposite.
        self.assertTrue(np.allclose(momentum, [4.0, 0, 0], rtol=0, atol=1e-12), momentum)
        left = (mass[part == 0] * v[-1, part == 0, 0]).sum() / mass[part == 0].sum()
        right = (mass[part == 1] * v[-1, part == 1, 0]).sum() / mass[part == 1].sum()
        # The cubes did meet: most of the momentum changed hands.
        self.assertLess(left, 0.5)
        self.assertGreater(right, 1.5)


def box_case_3d(name, divisions=(2, 2, 2), end=0.01):
    """A 3D box (contract 5.2) falling under gravity along -z."""
    return {
        "name": name,
        "dimension": 3,
        "materials": {"rock": dict(MATERIAL)},
        "parts": [{"name": "block", "material": "rock",
                   "box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1],
                           "divisions": list(divisions)}}],
        "gravity": [0, 0, -9.81],
        "time": {"end": end},
        "output": {"interval": end / 10, "fields": ["position", "velocity", "stress"]},
    }


class Clients3DTests(ClientTestCase):
    """The clients are used the same way on a 3D case: nothing in them may
    assume two components per node or three stresses per element."""

    NODES, ELEMENTS = 27, 48      # a 2 x 2 x 2 box: 3^3 nodes, 6 tetrahedra a cell

    def finished_3d_case(self, name):
        case_id = self.submit(box_case_3d(name), "--start")
        r = self.ctl("wait", case_id, "--interval", "0.1")
        self.assertEqual(r.returncode, 0, r.stderr)
        return case_id

    def assert_falling_3d_state(self, state):
        self.assertEqual(len(state["position"]), self.NODES)
        self.assertEqual({len(p) for p in state["position"]}, {3})
        self.assertEqual(len(state["stress"]), self.ELEMENTS)
        self.assertEqual({len(s) for s in state["stress"]}, {6})
        # Free fall along -z (exact for central difference up to half a step).
        for vx, vy, vz in state["velocity"]:
            self.assertAlmostEqual(vx, 0.0, places=9)
            self.assertAlmostEqual(vy, 0.0, places=9)
            self.assertAlmostEqual(vz, -9.81 * state["time"], delta=9.81 * 1e-3)

    def test_fdemctl_state_of_a_3d_case(self):
        case_id = self.finished_3d_case("state-3d")
        r = self.ctl("state", case_id, "--fields", "position,velocity,stress")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assert_falling_3d_state(json.loads(r.stdout))

    def test_python_client_state_of_a_3d_case(self):
        case_id = self.finished_3d_case("py-state-3d")
        self.assert_falling_3d_state(
            self.client.state(case_id, ["position", "velocity", "stress"]))

    def test_fdemctl_status_of_a_3d_case(self):
        case_id = self.finished_3d_case("status-3d")
        r = self.ctl("status", case_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("%d nodes, %d elements" % (self.NODES, self.ELEMENTS), r.stdout)
        self.assertNotIn("energy [J/m]", r.stdout)   # 3D energies are not per metre

    def test_fdemctl_and_python_fetch_of_a_3d_case(self):
        case_id = self.finished_3d_case("fetch-3d")
        r = self.ctl("fetch", case_id, "-o", "run3d.h5")
        self.assertEqual(r.returncode, 0, r.stderr)
        h5 = os.path.join(self.work.name, "run3d.h5")
        py_h5, py_xdmf = self.client.fetch(case_id, os.path.join(self.work.name, "py3d.h5"))
        snapshots = self.client.status(case_id)["snapshots"]
        for path in (h5, py_h5):
            with h5py.File(path, "r") as f:
                self.assertEqual(int(f.attrs["dimension"]), 3)
                self.assertEqual(f["/mesh/tetrahedra"].shape, (self.ELEMENTS, 4))
                self.assertEqual(f["/snapshots/position"].shape, (snapshots, self.NODES, 3))
                self.assertEqual(f["/snapshots/stress"].shape, (snapshots, self.ELEMENTS, 6))
        with open(os.path.join(self.work.name, "run3d.xdmf")) as f:
            self.assertIn("run3d.h5:/", f.read())
        with open(py_xdmf) as f:
            self.assertIn("py3d.h5:/", f.read())


class DocReferenceTests(unittest.TestCase):
    """Every doc the Python clients' docstrings and comments send a reader
    to exists in the repository, with the section they name."""

    def test_referenced_docs_exist(self):
        import re
        found = 0
        for name in ("fdemd_client.py", "plot_result.py"):
            with open(os.path.join(ROOT, "clients", "python", name)) as f:
                text = " ".join(f.read().split())  # references may wrap lines
            self.assertNotRegex(text, r"[Cc]ontract \d", "%s cites the spec, not a doc" % name)
            for doc, section in re.findall(r"(docs/[\w-]+\.md)(?:, \"([^\"]+)\")?", text):
                found += 1
                path = os.path.join(ROOT, doc)
                self.assertTrue(os.path.exists(path), "%s names %s" % (name, doc))
                if section:
                    with open(path) as f:
                        headings = [line.lstrip("#").strip() for line in f
                                    if line.startswith("#")]
                    self.assertIn(section, headings, "%s names %s, %r" % (name, doc, section))
        self.assertGreaterEqual(found, 3)


class VonMisesTests(unittest.TestCase):
    """The plane-strain von Mises formula of plot_result.py on known states."""

    def test_known_states(self):
        sys.path.insert(0, os.path.dirname(PLOT))
        import numpy as np
        from plot_result import von_mises_plane_strain
        # Pure shear: svm = sqrt(3) |sxy| whatever nu.
        self.assertAlmostEqual(von_mises_plane_strain(np.array([[0, 0, 2.0]]), 0.3)[0],
                               2 * 3 ** 0.5, places=12)
        # Uniaxial in-plane stress with nu = 0 (szz = 0): svm = |sxx|.
        self.assertAlmostEqual(von_mises_plane_strain(np.array([[5.0, 0, 0]]), 0.0)[0], 5.0,
                               places=12)
        # Equal biaxial with nu = 0.5: szz = sxx = syy, hydrostatic, svm = 0.
        self.assertAlmostEqual(von_mises_plane_strain(np.array([[3.0, 3.0, 0]]), 0.5)[0], 0.0,
                               places=12)


if __name__ == "__main__":
    unittest.main()
