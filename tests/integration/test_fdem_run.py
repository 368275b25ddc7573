"""bin/fdem-run and ranked cases (contract 6.5, issue 37 items 3 and 4).

fdem-run writes a daemon's case directory: the same case run by the daemon
and by fdem-run gives result.h5 files whose every dataset is equal bit for
bit, the same checkpoint.bin bytes and status.json figures (2D and 3D
fracturing bars with history points, so /events and /history are
compared too). A run paused at a step and run again ends with the files of
an uninterrupted run. A bad case is exit status 2 with its JSON Pointers.
A directory fdem-run wrote inside the data directory is listed by a
daemon that starts on it.

"parallel": {"ranks": N}: not a positive integer or above --max-ranks is a
422 at /parallel/ranks; the dry run and the status show `ranks`. A ranked
case runs through the --launcher line and bin/fdem-rank and ends with the
files of a one-process run, also once extended; it pauses and resumes; a launcher that does
not exist fails the case with a sentence naming it; when the daemon is
killed its ranks checkpoint and exit, and the restarted daemon lists the
case paused, which pauses and is deleted like any other; the results
routes read the file while the ranks write it.
"""
import contextlib
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

import h5py
import numpy as np

from fdemd_harness import FDEMD_BIN, SLOW, Daemon, DaemonTestCase, boom_case, tiny_case
from test_events import pulled_bar

BIN = os.path.dirname(FDEMD_BIN)
FDEM_RUN = os.path.join(BIN, "fdem-run")
FDEM_RANK = os.path.join(BIN, "fdem-rank")
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}
HAVE_RANKS = os.path.exists(FDEM_RANK) and shutil.which("mpirun") is not None
# status.json members that belong to the run, not to who ran it or when
RUN_FIGURES = ("name", "state", "step", "time", "end_time", "progress", "dt", "dimension",
               "nodes", "elements", "joints", "broken_joints", "fragments", "contacts",
               "stage", "fluid", "snapshots", "energy", "error", "warnings")


def bar_with_history(dimension):
    case = pulled_bar(dimension, end=1.2e-4, interval=2e-5)
    # a penalty below young: a document warning both status.json files list
    case["materials"]["rock"]["penalty"] = 2e10
    at = [0.05, 0.005] if dimension == 2 else [0.05, 0.005, 0.005]
    case["history"] = {"interval": 1e-5, "points": [{"name": "middle", "at": at}]}
    return case


def datasets(path):
    """{name: array} of every dataset in an HDF5 file."""
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()])
                     if isinstance(obj, h5py.Dataset) else None)
    return out


def fdem_run(args, **kw):
    return subprocess.run([FDEM_RUN] + args, capture_output=True, text=True,
                          timeout=120 * SLOW, **kw)


class FdemRunFiles(DaemonTestCase):
    """The same case through the daemon and through fdem-run."""
    PREFIX = "fdem-run-test-"

    def write_case(self, case, name):
        path = os.path.join(self.tmp, name)
        with open(path, "w") as f:
            json.dump(case, f)
        return path

    def daemon_dir(self, case):
        st = self.d.create(case, start=True)
        st = self.d.wait_state(st["id"], ("finished", "failed", "stopped"), timeout=60)
        self.assertEqual(st["state"], "finished", st.get("error"))
        return os.path.join(self.d.data_dir, st["id"])

    def assert_same_files(self, a, b, what):
        da, db = datasets(os.path.join(a, "result.h5")), datasets(os.path.join(b, "result.h5"))
        self.assertEqual(sorted(da), sorted(db), what)
        for name in da:
            self.assertEqual(da[name].dtype, db[name].dtype, name)
            self.assertEqual(np.asarray(da[name]).tobytes(), np.asarray(db[name]).tobytes(),
                             "%s: %s differs" % (what, name))
        with open(os.path.join(a, "checkpoint.bin"), "rb") as fa, \
                open(os.path.join(b, "checkpoint.bin"), "rb") as fb:
            self.assertEqual(fa.read(), fb.read(), "%s: checkpoint.bin differs" % what)
        with open(os.path.join(a, "status.json")) as fa, \
                open(os.path.join(b, "status.json")) as fb:
            sa, sb = json.load(fa), json.load(fb)
        for key in RUN_FIGURES:
            self.assertEqual(sa.get(key), sb.get(key), "%s: status.json %s" % (what, key))
        for name in ("result.xdmf", "case.json"):
            self.assertTrue(os.path.exists(os.path.join(b, name)), name)
        return da

    def test_fdem_run_writes_the_daemons_files(self):
        # the sanitizer pass checks 2D only: 3D runs the same loop and writers
        for dimension in (2, 3) if SLOW == 1 else (2,):
            with self.subTest(dimension=dimension):
                case = bar_with_history(dimension)
                expected = self.daemon_dir(case)
                out = os.path.join(self.tmp, "run-%dd" % dimension)
                r = fdem_run([self.write_case(case, "bar%d.json" % dimension), "--out", out,
                              "--quiet"])
                self.assertEqual(r.returncode, 0, r.stderr)
                d = self.assert_same_files(expected, out, "%dD" % dimension)
                # the comparison saw fracture, history, several snapshots and a warning
                self.assertGreater(len(d["events/time"]), 0)
                self.assertGreater(len(d["history/time"]), 5)
                self.assertGreater(len(d["snapshots/time"]), 5)
                with open(os.path.join(out, "status.json")) as f:
                    warnings = json.load(f)["warnings"]
                self.assertIn("/materials/rock/penalty", [w["pointer"] for w in warnings])

    def test_a_paused_run_goes_on_to_the_same_files(self):
        case = bar_with_history(2)
        path = self.write_case(case, "paused.json")
        whole, parts = os.path.join(self.tmp, "whole"), os.path.join(self.tmp, "parts")
        self.assertEqual(fdem_run([path, "--out", whole, "--quiet"]).returncode, 0)
        r = fdem_run([path, "--out", parts, "--quiet", "--pause-at-step", "37"])
        self.assertEqual(r.returncode, 3, r.stderr)
        with open(os.path.join(parts, "status.json")) as f:
            st = json.load(f)
        self.assertEqual((st["state"], st["step"]), ("paused", 37))
        r = fdem_run([path, "--out", parts, "--quiet"])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assert_same_files(whole, parts, "paused at step 37 and resumed")

    def test_a_finished_directory_run_again_takes_no_step(self):
        case = bar_with_history(2)
        path = self.write_case(case, "twice.json")
        out = os.path.join(self.tmp, "twice")
        self.assertEqual(fdem_run([path, "--out", out, "--quiet"]).returncode, 0)

        def files():
            with open(os.path.join(out, "status.json")) as f:
                st = json.load(f)
            with open(os.path.join(out, "checkpoint.bin"), "rb") as f:
                return st, f.read(), datasets(os.path.join(out, "result.h5"))
        st, ckpt, d = files()
        r = fdem_run([path, "--out", out])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("already finished", r.stderr)
        st2, ckpt2, d2 = files()
        # it took one step past its end before (step 54 of 53)
        self.assertEqual((st2["state"], st2["step"], st2["finished_at"]),
                         (st["state"], st["step"], st["finished_at"]))
        self.assertEqual(ckpt2, ckpt, "checkpoint.bin changed")
        self.assertEqual(len(d2["snapshots/time"]), len(d["snapshots/time"]))
        self.assertEqual(len(d2["history/time"]), len(d["history/time"]))

    def test_pause_and_stop_lines_on_stdin(self):
        path = self.write_case(tiny_case("lines", end=5.0, divisions=(4, 4), interval=1e-3),
                               "lines.json")
        out = os.path.join(self.tmp, "lines")
        for line, code, state in (("pause", 3, "paused"), ("stop", 4, "stopped")):
            p = subprocess.Popen([FDEM_RUN, path, "--out", out, "--control", "stdin",
                                  "--quiet"], stdin=subprocess.PIPE, stderr=subprocess.PIPE)
            status_path = os.path.join(out, "status.json")
            deadline = time.monotonic() + 30 * SLOW
            step = 0
            while step == 0 and time.monotonic() < deadline:
                with contextlib.suppress(OSError, ValueError):
                    with open(status_path) as f:
                        st = json.load(f)
                    step = st["step"] if st["state"] == "running" else 0
                time.sleep(0.02)
            p.stdin.write((line + "\n").encode())
            p.stdin.flush()
            self.assertEqual(p.wait(30 * SLOW), code, p.stderr.read())
            p.stdin.close()
            p.stderr.close()
            with open(status_path) as f:
                st = json.load(f)
            self.assertEqual(st["state"], state)
            self.assertGreaterEqual(st["step"], step)

    def test_a_bad_case_names_its_pointers(self):
        case = tiny_case("bad")
        case["time"]["end"] = -1
        case["parallel"] = {"ranks": 0}
        r = fdem_run([self.write_case(case, "bad.json"), "--out",
                      os.path.join(self.tmp, "bad")])
        self.assertEqual(r.returncode, 2)
        self.assertIn("/time/end", r.stderr)
        self.assertIn("/parallel/ranks", r.stderr)
        # a case that goes non-finite fails with the engine's sentence, its
        # results so far kept and closed
        out = os.path.join(self.tmp, "boom")
        r = fdem_run([self.write_case(boom_case(), "boom.json"), "--out", out, "--quiet"])
        self.assertEqual(r.returncode, 1, r.stderr)
        with open(os.path.join(out, "status.json")) as f:
            st = json.load(f)
        self.assertEqual(st["state"], "failed")
        self.assertIn("non-finite", st["error"])
        self.assertIn(st["error"], r.stderr)
        self.assertGreaterEqual(len(datasets(os.path.join(out, "result.h5"))["snapshots/time"]), 1)

    def test_the_daemon_lists_a_directory_fdem_run_wrote(self):
        data = os.path.join(self.tmp, "data")
        os.makedirs(data)
        case_id = "0123456789abcdef"
        r = fdem_run([self.write_case(tiny_case("batch"), "batch.json"), "--out",
                      os.path.join(data, case_id), "--quiet"])
        self.assertEqual(r.returncode, 0, r.stderr)
        d = Daemon(data_dir=data).start()
        try:
            st = d.status(case_id)
            self.assertEqual((st["state"], st["name"], st["ranks"]), ("finished", "batch", 1))
            self.assertEqual(st["snapshots"], 11)
            status, _, body = d.request("GET", "/cases/%s/result.h5" % case_id)
            self.assertEqual(status, 200)
            self.assertGreater(len(body), 1000)
        finally:
            code, _ = d.stop()
            d.close()
        self.assertEqual(code, 0)


class RanksInput(DaemonTestCase):
    """"parallel": {"ranks": N} as input."""
    DAEMON_ARGS = ("--max-ranks", "4")

    def test_ranks_must_be_a_positive_integer_within_max_ranks(self):
        for ranks in (0, -1, 2.5, "2", None, True, 5):
            with self.subTest(ranks=ranks):
                case = tiny_case("ranks")
                case["parallel"] = {"ranks": ranks}
                status, body = self.d.json("POST", "/cases", case)
                self.assertEqual(status, 422, body)
                pointers = [e["pointer"] for e in body["errors"]]
                self.assertEqual(pointers, ["/parallel/ranks"], body)
        case = tiny_case("ranks")
        case["parallel"] = {"ranks": 1, "rank": 2}
        status, body = self.d.json("POST", "/cases", case)
        self.assertEqual(status, 422)
        self.assertIn("/parallel/rank", [e["pointer"] for e in body["errors"]])

    def test_dry_run_and_status_show_ranks(self):
        case = tiny_case("ranks")
        case["parallel"] = {"ranks": 4}
        status, body = self.d.json("POST", "/cases?dry_run=true", case)
        self.assertEqual((status, body["ranks"]), (200, 4), body)
        self.assertEqual(self.d.create(case)["ranks"], 4)
        self.assertEqual(self.d.create(tiny_case("one"))["ranks"], 1)


@unittest.skipUnless(HAVE_RANKS, "no bin/fdem-rank or mpirun (openmpi-bin libopenmpi-dev)")
class RankedCases(DaemonTestCase):
    """Ranked cases through the daemon's launcher."""
    DAEMON_ARGS = ("--max-ranks", "2")

    def ranked(self, case, ranks=2):
        case = dict(case)
        case["parallel"] = {"ranks": ranks}
        return case

    @unittest.skipIf(SLOW > 1, "12 s under ASan; fdem-rank runs fdem-run's loop, whose files "
                     "the sanitizer pass compares, and its daemon side is the next test's")
    def test_a_ranked_case_writes_the_files_of_one_process(self):
        case = bar_with_history(2)
        one = self.d.create(case, start=True)
        two = self.d.create(self.ranked(case), start=True)
        one = self.d.wait_state(one["id"], ("finished", "failed", "stopped"), timeout=60)
        two = self.d.wait_state(two["id"], ("finished", "failed", "stopped"), timeout=60)
        self.assertEqual(two["state"], "finished", two.get("error"))
        self.assertEqual(two["ranks"], 2)
        for key in ("step", "time", "snapshots", "broken_joints", "energy"):
            self.assertEqual(one[key], two[key], key)
        a = datasets(os.path.join(self.d.data_dir, one["id"], "result.h5"))
        b = datasets(os.path.join(self.d.data_dir, two["id"], "result.h5"))
        self.assertEqual(sorted(a), sorted(b))
        for name in a:
            self.assertEqual(a[name].tobytes(), b[name].tobytes(), name)
        status, body = self.d.json("GET", "/cases/%s/events" % two["id"])
        self.assertEqual(status, 200)
        self.assertEqual(len(body["events"]), two["broken_joints"])
        # extended, both go on from the step before their old end (the grid
        # of an uninterrupted run) to the same files again
        for st in (one, two):
            status, body = self.d.json("POST", "/cases/%s/extend" % st["id"],
                                       {"end": 1.5 * case["time"]["end"]})
            self.assertEqual(status, 200, body)
            status, body = self.d.json("POST", "/cases/%s/start" % st["id"])
            self.assertEqual(status, 200, body)
        one = self.d.wait_state(one["id"], ("finished", "failed", "stopped"), timeout=60)
        two = self.d.wait_state(two["id"], ("finished", "failed", "stopped"), timeout=60)
        self.assertEqual(two["state"], "finished", two.get("error"))
        self.assertEqual((one["step"], one["snapshots"]), (two["step"], two["snapshots"]))
        a = datasets(os.path.join(self.d.data_dir, one["id"], "result.h5"))
        b = datasets(os.path.join(self.d.data_dir, two["id"], "result.h5"))
        for name in a:
            self.assertEqual(a[name].tobytes(), b[name].tobytes(), "extended: " + name)

    def test_fdem_run_on_ranks_pauses_at_a_step_and_goes_on(self):
        case = bar_with_history(2)
        path = os.path.join(self.tmp, "paused-ranks.json")
        with open(path, "w") as f:
            json.dump(case, f)
        whole, parts = os.path.join(self.tmp, "whole-one"), os.path.join(self.tmp, "parts-two")
        env = dict(os.environ, **MPI_ENV)
        self.assertEqual(fdem_run([path, "--out", whole, "--quiet"]).returncode, 0)
        # --pause-at-step was not handed on to the ranks: they ran to the end
        r = fdem_run([path, "--out", parts, "--ranks", "2", "--quiet", "--pause-at-step", "13"],
                     env=env)
        self.assertEqual(r.returncode, 3, r.stderr)
        with open(os.path.join(parts, "status.json")) as f:
            st = json.load(f)
        self.assertEqual((st["state"], st["step"]), ("paused", 13))
        r = fdem_run([path, "--out", parts, "--ranks", "2", "--quiet"], env=env)
        self.assertEqual(r.returncode, 0, r.stderr)
        a = datasets(os.path.join(whole, "result.h5"))
        b = datasets(os.path.join(parts, "result.h5"))
        self.assertEqual(sorted(a), sorted(b))
        for name in a:
            self.assertEqual(a[name].tobytes(), b[name].tobytes(), name)

    def test_a_missing_launcher_fails_the_case_with_a_sentence(self):
        d = Daemon(args=("--launcher", "/nonexistent/mpirun -np {ranks}")).start()
        try:
            st = d.create(self.ranked(tiny_case("nolauncher")), start=True)
            st = d.wait_state(st["id"], ("failed", "finished"), timeout=30)
            self.assertEqual(st["state"], "failed")
            self.assertIn("/nonexistent/mpirun", st["error"])
            self.assertIn("--launcher", st["error"])
        finally:
            d.stop()
            d.close()
        # a launcher that fails: its exit status and the last line of its
        # output that says something (mpirun frames its messages in dashes)
        failing = "sh -c 'echo ----; echo launcher: no slots >&2; echo ----; exit 7'"
        d = Daemon(args=("--launcher", failing)).start()
        try:
            st = d.create(self.ranked(tiny_case("failing")), start=True)
            st = d.wait_state(st["id"], ("failed", "finished"), timeout=30)
            self.assertEqual(st["state"], "failed")
            self.assertIn("exit status 7", st["error"])
            self.assertIn("says: launcher: no slots", st["error"])
        finally:
            d.stop()
            d.close()

    def test_ranks_pause_when_the_daemon_dies_and_go_on_after_a_restart(self):
        d = Daemon(args=("--max-ranks", "2")).start()
        try:
            st = d.create(self.ranked(tiny_case("orphan", end=5.0, divisions=(4, 4),
                                                interval=1e-3)), start=True)
            d.wait(st["id"], lambda s: s["snapshots"] > 1, timeout=30, what="the ranks step")
            # the eta follows the ranks' status.json as the worker's own
            # (it was always null for a ranked case)
            st = d.wait(st["id"], lambda s: s.get("eta") is not None, timeout=30,
                        what="a ranked case's eta")
            self.assertGreater(st["eta"], 0)
            # while the ranks write, the routes read their file (SWMR); a byte
            # copy of it could catch a write half done: 409 with a sentence
            for route in ("events", "history", "mesh.bin?snapshot=1", "state"):
                status, _, body = d.request("GET", "/cases/%s/%s" % (st["id"], route))
                self.assertEqual(status, 200, (route, body[:200]))
            status, _, body = d.request("GET", "/cases/%s/result.h5" % st["id"])
            self.assertEqual(status, 409, body[:200])
            self.assertIn(b"once the case is paused", body)
            d.kill()
            # the pipe's end of file: rank 0 checkpoints and the ranks exit
            status_path = os.path.join(d.data_dir, st["id"], "status.json")
            deadline = time.monotonic() + 30 * SLOW
            state = None
            while time.monotonic() < deadline:
                with open(status_path) as f:
                    state = json.load(f).get("state")
                if state == "paused":
                    break
                time.sleep(0.05)
            self.assertEqual(state, "paused")
            d.start()
            paused = d.status(st["id"])
            self.assertEqual((paused["state"], paused["ranks"]), ("paused", 2))
            self.assertGreater(paused["step"], 0)
            # start relaunches the ranks from the checkpoint; pause goes down the pipe
            status, body = d.json("POST", "/cases/%s/start" % st["id"])
            self.assertEqual(status, 200, body)
            d.wait(st["id"], lambda s: s["step"] > paused["step"], timeout=30,
                   what="the relaunched ranks step on")
            status, body = d.json("POST", "/cases/%s/pause" % st["id"])
            self.assertEqual(status, 200, (body, d.status(st["id"]).get("error")))
            again = d.wait_state(st["id"], "paused")
            self.assertGreater(again["step"], paused["step"])
            self.assertEqual(again["error"], None)
            # a delete ends the launcher's process group: the daemon blocks
            # SIGTERM for itself, and an mpirun that inherited the mask never
            # ended its ranks (the DELETE hung)
            status, body = d.json("POST", "/cases/%s/start" % st["id"])
            self.assertEqual(status, 200, body)
            d.wait(st["id"], lambda s: s["step"] > again["step"], timeout=30,
                   what="the ranks step on once more")
            status, _, _ = d.request("DELETE", "/cases/" + st["id"])
            self.assertEqual(status, 204)
            self.assertFalse(os.path.exists(os.path.join(d.data_dir, st["id"])))
        finally:
            d.stop()
            d.close()


if __name__ == "__main__":
    unittest.main()
