"""test_stages.py - a case in stages (contract 5.3 "Continue and clone").

Extend: a finished case extended to a later end goes on in the same
result.h5 (time strictly increasing across the join, more snapshots, the
rows up to the old end bit-identical to what they were), and the continued
run is bit-identical to a run asked for the new end from the start (the
product's promise: pausing, extending and restarting never change results);
across a daemon restart too. Clone: a JSON Merge Patch applied to the
stored document makes a new case, stored patched, that runs. Every error
of both routes, and fdemctl's and the Python client's commands."""
import json
import os
import signal
import sys
import unittest

import numpy as np

from fdemd_harness import Daemon, DaemonTestCase, fetched_result, tiny_case

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
from fdemd_client import Client, FdemdError  # noqa: E402


OLD_END, NEW_END, INTERVAL = 0.0004, 0.001, 0.00005


def staged_case(name, end):
    """tiny_case() with the output interval fixed, so runs to different ends
    snapshot on the same grid (the old end is on it: 8 intervals)."""
    return tiny_case(name, end=end, interval=INTERVAL)


def staged_case_3d(name, end):
    """A tetrahedral box pressed onto its fixed base, on the same grid."""
    return {
        "name": name, "dimension": 3,
        "materials": {"rock": {"density": 2700, "young": 3e10, "poisson": 0.25}},
        "parts": [{"name": "box", "material": "rock", "velocity": [0, 0, -1],
                   "box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1], "divisions": [2, 2, 2]}}],
        "constraints": [{"box": [-1, -1, -0.001, 1, 1, 0.001], "fix": ["x", "y", "z"]}],
        "time": {"end": end},
        "output": {"interval": INTERVAL, "fields": ["position", "velocity", "stress"]},
    }


def read_result(daemon, case_id):
    """Every /snapshots dataset and the root attribute `case`, from a download."""
    with fetched_result(daemon, case_id) as f:
        out = {name: f["/snapshots/" + name][...] for name in f["/snapshots"]}
        out["case"] = json.loads(f.attrs["case"])
    return out


def rows(result, keep):
    return {k: v[keep] for k, v in result.items() if k != "case"}


class StagesCheck:
    """The checks both extend tests make of a continued run."""

    def check_continued(self, before, after, straight):
        n = len(before["time"])
        self.assertGreater(len(after["time"]), n)
        self.assertTrue(np.all(np.diff(after["time"]) > 0), after["time"])
        self.assertEqual(before["time"][-1], OLD_END)
        # The rows up to the old end are as they were, bit for bit.
        for key, value in rows(before, slice(None)).items():
            np.testing.assert_array_equal(after[key][:n], value, err_msg=key)
        # What follows is the uninterrupted run's, bit for bit.
        later = straight["time"] > OLD_END
        self.assertEqual(len(after["time"]) - n, int(np.sum(later)))
        for key, value in rows(straight, later).items():
            np.testing.assert_array_equal(after[key][n:], value, err_msg=key)
        self.assertEqual(after["time"][-1], NEW_END)


class ExtendTests(DaemonTestCase, StagesCheck):

    def finished(self, name, end=OLD_END, make=staged_case):
        case_id = self.d.create(make(name, end), start=True)["id"]
        self.d.wait_state(case_id, "finished")
        return case_id

    def test_extend_continues_the_same_files_bit_identically(self):
        self.check_extend(staged_case)

    def test_extend_of_a_3d_case_is_bit_identical_too(self):
        self.check_extend(staged_case_3d)

    def check_extend(self, make):
        d = self.d
        case_id = self.finished("extended", make=make)
        before = read_result(d, case_id)
        state_path = "/cases/%s/state?fields=position,velocity,stress" % case_id
        end_state = d.json("GET", state_path)[1]
        status, st = d.json("POST", "/cases/%s/extend" % case_id, {"end": NEW_END})
        self.assertEqual(status, 200, st)
        self.assertEqual(d.json("GET", state_path)[1], end_state)
        self.assertEqual((st["state"], st["end_time"], st["finished_at"]),
                         ("paused", NEW_END, None))
        self.assertEqual((st["time"], st["snapshots"]), (OLD_END, len(before["time"])))
        # The stored document and the one inside result.h5 say the new end.
        status, doc = d.json("GET", "/cases/%s/case" % case_id)
        self.assertEqual(doc["time"]["end"], NEW_END)
        self.assertEqual(doc["output"]["interval"], INTERVAL)
        self.assertEqual(read_result(d, case_id)["case"], doc)
        d.json("POST", "/cases/%s/start" % case_id)
        st = d.wait_state(case_id, "finished")
        self.assertEqual((st["time"], st["end_time"]), (NEW_END, NEW_END))
        after = read_result(d, case_id)
        self.assertEqual(st["snapshots"], len(after["time"]))
        straight = read_result(d, self.finished("straight", NEW_END, make))
        self.check_continued(before, after, straight)
        with open(os.path.join(d.data_dir, case_id, "result.xdmf")) as f:
            self.assertEqual(f.read().count("<Time "), len(after["time"]))

    def test_extend_of_a_default_interval_keeps_its_pace(self):
        case = tiny_case("default-interval", end=0.0002)
        del case["output"]["interval"]
        case_id = self.d.create(case, start=True)["id"]
        self.d.json("POST", "/cases/%s/pause" % case_id)  # or finished already: both extend
        self.d.wait_state(case_id, ("paused", "finished"))
        status, st = self.d.json("POST", "/cases/%s/extend" % case_id, {"end": 0.0004})
        self.assertEqual(status, 200, st)
        doc = self.d.json("GET", "/cases/%s/case" % case_id)[1]
        self.assertEqual(doc["output"]["interval"], 0.0002 / 100)

    def test_extend_a_paused_case(self):
        d = self.d
        case_id = d.create(tiny_case("paused", end=10.0), start=True)["id"]
        d.wait(case_id, lambda s: s["step"] > 20, what="steps")
        paused = d.json("POST", "/cases/%s/pause" % case_id)[1]
        status, st = d.json("POST", "/cases/%s/extend" % case_id, {"end": 20.0})
        self.assertEqual(status, 200, st)
        self.assertEqual((st["state"], st["step"], st["end_time"]), ("paused", paused["step"], 20.0))
        self.assertEqual(d.json("GET", "/cases/%s/case" % case_id)[1]["time"]["end"], 20.0)
        d.json("POST", "/cases/%s/stop" % case_id)

    def test_409_names_the_state_or_the_end(self):
        d = self.d
        case_id = self.finished("conflicts")
        status, problem = d.json("POST", "/cases/%s/extend" % case_id, {"end": OLD_END})
        self.assertEqual(status, 409)
        self.assertIn("not beyond the current end", problem["detail"])
        # The ends read as the user wrote them (api.md's example), not as
        # 17 digits (0.00040000000000000002).
        self.assertIn("the new end %r s is not beyond the current end %r s" % (OLD_END, OLD_END),
                      problem["detail"])
        status, problem = d.json("POST", "/cases/%s/extend" % case_id, {"end": OLD_END / 2})
        self.assertEqual(status, 409)
        running = d.create(tiny_case("running", end=1e3), start=True)["id"]
        created = d.create(tiny_case("created"))["id"]
        stopped = d.create(tiny_case("stopped"))["id"]
        d.json("POST", "/cases/%s/stop" % stopped)
        for other, state in ((running, "running"), (created, "created"), (stopped, "stopped")):
            status, problem = d.json("POST", "/cases/%s/extend" % other, {"end": 2e3})
            self.assertEqual(status, 409, (state, problem))
            self.assertIn("the case is %s" % state, problem["detail"])
            self.assertIn("finished or paused", problem["detail"])
        d.json("POST", "/cases/%s/stop" % running)
        self.assertEqual(d.status(case_id)["state"], "finished")

    def test_409_for_a_failed_case(self):
        d = self.d
        case = tiny_case("fails", end=0.01)
        case["time"]["dt"] = 1e-7
        case["materials"]["rock"]["young"] = 3e10
        case["parts"][0]["velocity"] = [0, -1e200]
        case_id = d.create(case, start=True)["id"]
        st = d.wait_state(case_id, ("failed", "finished"))
        if st["state"] != "failed":
            self.skipTest("this case did not fail here")
        status, problem = d.json("POST", "/cases/%s/extend" % case_id, {"end": 1.0})
        self.assertEqual(status, 409)
        self.assertIn("the case is failed", problem["detail"])

    def test_bad_bodies_are_422_with_pointers_and_400(self):
        d = self.d
        case_id = self.finished("bad-bodies")
        for body, pointer in (({}, "/end"), ({"end": "1"}, "/end"), ({"end": None}, "/end"),
                              ({"end": [1]}, "/end"), ({"end": 1, "start": True}, "/start"),
                              ([1], "")):
            status, problem = d.json("POST", "/cases/%s/extend" % case_id, body)
            self.assertEqual(status, 422, (body, problem))
            self.assertIn(pointer, [e["pointer"] for e in problem["errors"]], (body, problem))
        # JSON has no non-finite numbers: 1e999 does not parse as a double.
        for text in (b'{"end": ', b'{"end": 1e999}', b'{"end": 1, "end": 2}', b'{"end": NaN}'):
            status, problem = d.json("POST", "/cases/%s/extend" % case_id, text)
            self.assertEqual(status, 400, (text, problem))
        # Too many snapshots at the case's interval: 422 on /end.
        status, problem = d.json("POST", "/cases/%s/extend" % case_id, {"end": 1e3})
        self.assertEqual(status, 422, problem)
        self.assertEqual(problem["errors"][0]["pointer"], "/end")
        self.assertEqual(d.status(case_id)["state"], "finished")
        self.assertEqual(d.status(case_id)["end_time"], OLD_END)

    def test_404_405_and_query(self):
        d = self.d
        status, _ = d.json("POST", "/cases/0123456789abcdef/extend", {"end": 1.0})
        self.assertEqual(status, 404)
        case_id = self.finished("methods")
        status, headers, _ = d.request("GET", "/cases/%s/extend" % case_id)
        self.assertEqual((status, headers.get("allow")), (405, "POST"))
        status, _ = d.json("POST", "/cases/%s/extend?start=true" % case_id, {"end": 1.0})
        self.assertEqual(status, 400)


class ExtendRestartTests(unittest.TestCase, StagesCheck):
    """An extended case and the restart of the daemon in between."""

    def setUp(self):
        self.d = Daemon().start()

    def tearDown(self):
        self.d.close()

    def test_extend_survives_a_restart(self):
        d = self.d
        case_id = d.create(staged_case("restarted", OLD_END), start=True)["id"]
        d.wait_state(case_id, "finished")
        before = read_result(d, case_id)
        self.assertEqual(d.json("POST", "/cases/%s/extend" % case_id, {"end": NEW_END})[0], 200)
        self.assertEqual(d.stop()[0], 0, d.log_tail())
        d.start()
        st = d.status(case_id)
        self.assertEqual((st["state"], st["end_time"], st["time"]), ("paused", NEW_END, OLD_END))
        self.assertEqual(d.json("GET", "/cases/%s/case" % case_id)[1]["time"]["end"], NEW_END)
        d.json("POST", "/cases/%s/start" % case_id)
        self.assertEqual(d.wait_state(case_id, "finished")["time"], NEW_END)
        after = read_result(d, case_id)
        straight_id = d.create(staged_case("straight", NEW_END), start=True)["id"]
        d.wait_state(straight_id, "finished")
        self.check_continued(before, after, read_result(d, straight_id))

    def test_killed_while_running_on_comes_back_with_the_new_end(self):
        d = self.d
        case_id = d.create(tiny_case("killed", end=0.0002), start=True)["id"]
        d.wait_state(case_id, "finished")
        self.assertEqual(d.json("POST", "/cases/%s/extend" % case_id, {"end": 1e3})[0], 422)
        self.assertEqual(d.json("POST", "/cases/%s/extend" % case_id, {"end": 2.0})[0], 200)
        d.json("POST", "/cases/%s/start" % case_id)
        d.wait(case_id, lambda s: s["time"] > 0.0004, what="the run to go on")
        d.stop(signal.SIGKILL)
        d.start()
        st = d.status(case_id)
        self.assertEqual((st["state"], st["end_time"]), ("paused", 2.0))
        self.assertGreaterEqual(st["time"], 0.0002)
        d.json("POST", "/cases/%s/stop" % case_id)
        result = read_result(d, case_id)
        self.assertTrue(np.all(np.diff(result["time"]) > 0), result["time"])
        self.assertEqual(result["case"]["time"]["end"], 2.0)


class CloneTests(DaemonTestCase):

    def test_clone_stores_the_patched_document_and_runs(self):
        d = self.d
        original = tiny_case("original", end=0.0003, gravity=[0, -9.81])
        source = d.create(original)["id"]
        patch = {"name": "clone", "gravity": None, "time": {"end": 0.0002},
                 "materials": {"rock": {"young": 1e10}}}
        status, headers, data = d.request("POST", "/cases/%s/clone?start=true" % source, patch)
        st = json.loads(data)
        self.assertEqual(status, 201, st)
        self.assertEqual(headers["location"], "/cases/" + st["id"])
        self.assertNotEqual(st["id"], source)
        self.assertEqual((st["name"], st["end_time"]), ("clone", 0.0002))
        want = json.loads(json.dumps(original))
        want.update(name="clone")
        del want["gravity"]
        want["time"]["end"] = 0.0002
        want["materials"]["rock"]["young"] = 1e10
        self.assertEqual(d.json("GET", "/cases/%s/case" % st["id"])[1], want)
        self.assertEqual(d.wait_state(st["id"], "finished")["time"], 0.0002)
        self.assertEqual(read_result(d, st["id"])["case"], want)
        # The source is untouched.
        self.assertEqual(d.json("GET", "/cases/%s/case" % source)[1], original)
        self.assertEqual(d.status(source)["state"], "created")

    def test_invalid_patched_case_is_422_with_pointers_into_it(self):
        d = self.d
        source = d.create(tiny_case("source"))["id"]
        count = len(d.json("GET", "/cases")[1]["cases"])
        status, problem = d.json("POST", "/cases/%s/clone" % source,
                                 {"parts": [{"name": "p", "material": "granit",
                                             "rectangle": {"origin": [0, 0], "size": [1, 1],
                                                           "divisions": [2, 2]}}],
                                  "time": {"end": -1}})
        self.assertEqual(status, 422, problem)
        pointers = [e["pointer"] for e in problem["errors"]]
        self.assertIn("/parts/0/material", pointers)
        self.assertIn("/time/end", pointers)
        status, problem = d.json("POST", "/cases/%s/clone" % source, {"time": None})
        self.assertEqual(status, 422, problem)
        status, problem = d.json("POST", "/cases/%s/clone" % source, [1, 2])
        self.assertEqual(status, 422, problem)
        self.assertEqual(len(d.json("GET", "/cases")[1]["cases"]), count)

    def test_errors(self):
        d = self.d
        source = d.create(tiny_case("errors"))["id"]
        self.assertEqual(d.json("POST", "/cases/0123456789abcdef/clone", {})[0], 404)
        status, headers, _ = d.request("GET", "/cases/%s/clone" % source)
        self.assertEqual((status, headers.get("allow")), (405, "POST"))
        self.assertEqual(d.json("POST", "/cases/%s/clone" % source, b'{"name": ')[0], 400)
        self.assertEqual(d.json("POST", "/cases/%s/clone" % source, b'{"a":1,"a":2}')[0], 400)
        self.assertEqual(d.json("POST", "/cases/%s/clone?strat=true" % source, {})[0], 400)
        # An empty patch is a copy; a dry run stores nothing.
        status, st = d.json("POST", "/cases/%s/clone" % source, {})
        self.assertEqual((status, st["name"]), (201, "errors"))
        status, sizing = d.json("POST", "/cases/%s/clone?dry_run=true" % source,
                                {"time": {"end": 0.002}})
        self.assertEqual(status, 200, sizing)
        self.assertIn("steps", sizing)

    def test_409_after_delete_is_404(self):
        d = self.d
        source = d.create(tiny_case("deleted"))["id"]
        d.request("DELETE", "/cases/" + source)
        self.assertEqual(d.json("POST", "/cases/%s/clone" % source, {})[0], 404)
        self.assertEqual(d.json("POST", "/cases/%s/extend" % source, {"end": 1})[0], 404)


class UploadLimitTests(unittest.TestCase):

    def test_413_over_max_upload(self):
        d = Daemon(args=["--max-upload", "1000"]).start()
        try:
            source = d.create(tiny_case("limit"))["id"]
            big = {"name": "x" * 2000}
            for route in ("clone", "extend"):
                try:
                    status, _ = d.json("POST", "/cases/%s/%s" % (source, route), big)
                except (BrokenPipeError, ConnectionResetError):
                    continue
                self.assertEqual(status, 413, route)
        finally:
            d.close()


class ClientCommandTests(DaemonTestCase):

    def ctl(self, *args, stdin=None):
        return self.d.fdemctl(*args, stdin=stdin, cwd=self.tmp)

    def test_fdemctl_extend(self):
        case_id = self.d.create(staged_case("ctl-extend", OLD_END), start=True)["id"]
        self.d.wait_state(case_id, "finished")
        r = self.ctl("extend", case_id, str(NEW_END), "--start")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(case_id, r.stdout)
        self.assertIn("end 0.001 s", r.stdout)
        self.assertEqual(self.d.wait_state(case_id, "finished")["time"], NEW_END)
        r = self.ctl("extend", case_id, "0.0005")
        self.assertEqual(r.returncode, 1)
        self.assertIn("not beyond", r.stderr)
        self.assertEqual(self.ctl("extend", case_id, "soon").returncode, 2)
        self.assertEqual(self.ctl("extend", case_id).returncode, 2)
        r = self.ctl("extend", "0123456789abcdef", "1")
        self.assertEqual(r.returncode, 1)
        self.assertIn("404", r.stderr)
        self.assertEqual(self.ctl("extend", "--help").returncode, 0)

    def test_fdemctl_clone(self):
        source = self.d.create(tiny_case("ctl-source", end=0.0002))["id"]
        path = os.path.join(self.tmp, "patch.json")
        with open(path, "w") as f:
            json.dump({"name": "ctl-clone"}, f)
        r = self.ctl("clone", source, path, "--start")
        self.assertEqual(r.returncode, 0, r.stderr)
        new_id = r.stdout.strip()
        self.assertEqual(self.d.wait_state(new_id, "finished")["name"], "ctl-clone")
        r = self.ctl("clone", source, "-", stdin='{"materials": {"rock": {"density": -1}}}')
        self.assertEqual(r.returncode, 1)
        self.assertIn("/materials/rock/density", r.stderr)
        r = self.ctl("clone", source, "-", stdin='{"name": "piped"}')
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.d.status(r.stdout.strip())["name"], "piped")
        self.assertEqual(self.ctl("clone", source, "missing.json").returncode, 2)
        self.assertEqual(self.ctl("clone", "0123456789abcdef", path).returncode, 1)
        self.assertEqual(self.ctl("clone", "--help").returncode, 0)

    def test_python_extend_and_clone(self):
        client = Client("http://127.0.0.1:%d" % self.d.port)
        source = self.d.create(staged_case("py-source", OLD_END), start=True)["id"]
        self.d.wait_state(source, "finished")
        st = client.extend(source, NEW_END)
        self.assertEqual((st["state"], st["end_time"]), ("paused", NEW_END))
        with self.assertRaises(FdemdError) as raised:
            client.extend(source, OLD_END)
        self.assertEqual(raised.exception.status, 409)
        st = client.extend(source, 2 * NEW_END, start=True)
        self.assertIn(st["state"], ("running", "queued", "finished"))
        new_id = client.clone(source, {"name": "py-clone", "time": {"end": 0.0001}}, start=True)
        self.assertEqual(client.wait(new_id)["state"], "finished")
        self.assertEqual(client.case(new_id)["name"], "py-clone")
        with self.assertRaises(FdemdError) as raised:
            client.clone(source, {"time": {"end": "late"}})
        self.assertEqual(raised.exception.status, 422)
        self.assertEqual(raised.exception.errors[0]["pointer"], "/time/end")
        client.wait(source)


if __name__ == "__main__":
    unittest.main()


class ExtendFractureTests(DaemonTestCase):
    """An extend that cuts through a crack's growth: the fracture events of
    the continued run are those of the uninterrupted one, none twice, none
    lost (the end checkpoint an extend resumes from holds no undrained
    event, and the reopened file keeps only the events of joints broken
    in it)."""

    def events(self, case_id):
        return self.d.json("GET", "/cases/%s/events" % case_id)[1]["events"]

    def test_events_of_an_extended_fracturing_case_are_the_uninterrupted_ones(self):
        # The bar's four joints break in one step near t = 52.7 us. Cut
        # before it, and 0.3 us after it: between two snapshots, so the
        # events are still in the engine when the end checkpoint is taken.
        from test_events import pulled_bar
        d = self.d
        new_end = 2.5e-4
        straight = d.create(pulled_bar(2, end=new_end), start=True)["id"]
        d.wait_state(straight, "finished")
        expected = self.events(straight)
        self.assertEqual(len(expected), 4)
        for old_end, before in ((5.2e-5, 0), (5.3e-5, 4)):
            staged = d.create(pulled_bar(2, end=old_end), start=True)["id"]
            d.wait_state(staged, "finished")
            self.assertEqual(len(self.events(staged)), before, old_end)
            status, _ = d.json("POST", "/cases/%s/extend" % staged, {"end": new_end})
            self.assertEqual(status, 200)
            d.json("POST", "/cases/%s/start" % staged)
            d.wait_state(staged, "finished")
            self.assertEqual(self.events(staged), expected, old_end)
