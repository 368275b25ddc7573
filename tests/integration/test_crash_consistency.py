"""test_crash_consistency.py - crashes that turn back what a client saw
(issue 30; contract 1 "Nothing that was acknowledged is lost", 5.3 extend,
5.5). Each test SIGKILLs the real daemon at a moment a client has just
seen something, restarts it on the same --data and checks that what was
seen is still there: the snapshot count a status showed, a stop seen as
`stopped`, an extend interrupted between its writes (a test-only fault
point, FDEMD_FAULT_POINT, makes the daemon kill itself there), and damaged
files of a paused case, which are kept as found rather than replaced. A
last test checks that a restart listens before it rebuilds stored cases.

CRASH_ROUNDS (default 5) sets how many kills the racing tests make;
EXTEND_POINTS (comma-separated) narrows the extend's fault points, e.g. to
the ones a daemon without extend.json has. Every wait is for a state, with
a generous deadline, never for wall time."""
import json
import os
import signal
import threading
import time
import unittest

from fdemd_harness import SLOW, Daemon, fetched_result, tiny_case


def snapshot_count(daemon, case_id):
    with fetched_result(daemon, case_id) as f:
        return len(f["/snapshots/time"])


class SnapshotCountTest(unittest.TestCase):
    """Item 10: `snapshots` in the status is published only once the
    checkpoint holding that snapshot (and result.h5's row) is durable."""

    ROUNDS = int(os.environ.get("CRASH_ROUNDS", "5"))

    def test_a_snapshot_count_seen_survives_sigkill(self):
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        # A model big enough that its checkpoint takes a while to write,
        # with a snapshot every few steps: the window between a row and its
        # checkpoint is what a client must never see into.
        case = tiny_case("counted", end=10.0, divisions=(60, 60))
        probe = d.create(case)
        case["output"]["interval"] = 4 * probe["dt"]
        case["time"]["end"] = 4 * probe["dt"] * 100000
        d.request("DELETE", "/cases/" + probe["id"])
        cid = d.create(case)["id"]
        lost = []
        for round_ in range(self.ROUNDS):
            status, st = d.json("POST", "/cases/%s/start" % cid)
            self.assertEqual((status, st["state"]), (200, "running"), (round_, st))
            first = d.wait(cid, lambda s: s["snapshots"] > 0, what="a snapshot")["snapshots"]
            deadline = time.monotonic() + 30 * SLOW
            seen = first
            while seen == first:  # the moment a new count shows, the daemon dies
                st = d.status(cid)
                seen = st["snapshots"]
                # a case that fails (a reopened result.h5 that would not
                # take a row, once in some hundred kills) never shows one
                self.assertEqual(st["state"], "running", (round_, st.get("error")))
                self.assertLess(time.monotonic(), deadline, "round %d: no new snapshot in %g s"
                                % (round_, 30 * SLOW))
            d.kill()
            d.start()
            # The listing (which may come before the case's start-up check)
            # and the case itself.
            listed = [c for c in d.json("GET", "/cases")[1]["cases"] if c["id"] == cid][0]
            st = d.status(cid)
            self.assertEqual(st["state"], "paused", st)
            self.assertEqual(snapshot_count(d, cid), st["snapshots"])
            if min(listed["snapshots"], st["snapshots"]) < seen:
                lost.append((round_, seen, listed["snapshots"], st["snapshots"]))
        self.assertEqual(lost, [], "rounds (round, seen, listed and shown after the restart) "
                         "that lost a snapshot "
                         "of %d" % self.ROUNDS)
        self.assertEqual(d.stop()[0], 0, d.log_tail())


def busy_case(d):
    """A case whose snapshots (~3 MB each, every 2 steps) keep the I/O
    thread busy, so that other cases' file work waits behind them."""
    case = tiny_case("busy", end=1.0, divisions=(200, 200))
    st = d.create(case)
    case["output"]["interval"] = 2 * st["dt"]
    case["time"]["end"] = 2 * st["dt"] * 100000
    d.request("DELETE", "/cases/" + st["id"])
    return d.create(case)["id"]


class StopTest(unittest.TestCase):
    """Item 11: a stop of a case no worker runs is shown (and answered)
    only once status.json says stopped."""

    ROUNDS = int(os.environ.get("CRASH_ROUNDS", "5"))

    def test_a_stop_seen_survives_sigkill(self):
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        busy = busy_case(d)
        turned_back = []
        for round_ in range(self.ROUNDS):
            code, st = d.json("POST", "/cases/%s/start" % busy)
            # the answer whole when it is not a start: a CI run once got
            # one without a state, and the KeyError hid what it said
            self.assertEqual((code, (st or {}).get("state")), (200, "running"), st)
            d.wait(busy, lambda s: s["snapshots"] >= 2, timeout=60, what="busy snapshots")
            cid = d.create(tiny_case("stopped-%d" % round_))["id"]
            answers = []

            def stop():
                try:
                    answers.append(d.json("POST", "/cases/%s/stop" % cid))
                except OSError:  # the daemon was killed before it answered
                    pass
            stopper = threading.Thread(target=stop)
            stopper.start()
            deadline = time.monotonic() + 60 * SLOW
            while d.status(cid)["state"] != "stopped":  # seen: the daemon dies at once
                self.assertLess(time.monotonic(), deadline, "the stop never showed")
            d.kill()
            stopper.join()
            d.start()
            after = d.status(cid)
            if after["state"] != "stopped":
                turned_back.append((round_, after["state"], answers[0][0] if answers else None))
            status, problem = d.json("POST", "/cases/%s/start" % cid)
            if after["state"] == "stopped":
                self.assertEqual(status, 409, problem)
        self.assertEqual(turned_back, [], "rounds (round, state after restart, stop's answer "
                         "if any) where a stop seen turned back, of %d" % self.ROUNDS)
        self.assertEqual(d.stop()[0], 0, d.log_tail())


EXTEND_POINTS = ("extend:intent", "extend:case.json", "extend:result.h5", "extend:resume-point",
                 "extend:status.json")
OLD_END, NEW_END, INTERVAL = 0.0004, 0.001, 0.00005


def stored_end(daemon, case_id):
    """time.end as GET /case and result.h5's `case` attribute have it."""
    status, doc = daemon.json("GET", "/cases/%s/case" % case_id)
    assert status == 200, doc
    with fetched_result(daemon, case_id) as f:
        return doc["time"]["end"], json.loads(f.attrs["case"])["time"]["end"]


class ExtendTest(unittest.TestCase):
    """Item 12: an extend cut short by a crash between its writes comes
    back whole (paused with the new end, every file agreeing) and runs on;
    it never leaves a case that answers 409 to both extend and start."""

    POINTS = tuple(p for p in os.environ.get("EXTEND_POINTS", ",".join(EXTEND_POINTS)).split(","))

    def crash_extend(self, d, cid, end, point):
        """Restarts `d` with the fault point set and asks for the extend:
        the daemon must die there. Then restarts it plainly."""
        self.assertEqual(d.stop()[0], 0, d.log_tail())
        d.env = {"FDEMD_FAULT_POINT": point}
        d.start()
        try:
            status, body = d.json("POST", "/cases/%s/extend" % cid, {"end": end})
        except OSError:
            status, body = None, None
        code = d.proc.wait(30 * SLOW)
        d._closed()
        d.env = None
        self.assertEqual((status, code), (None, -signal.SIGKILL),
                         "the daemon did not die at %s (it answered %s %s)" % (point, status, body))
        d.start()

    def test_an_extend_of_a_finished_case_cut_short_comes_back_whole(self):
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        # What an extend no crash interrupts gives: the series to match.
        ref = d.create(tiny_case("reference", end=OLD_END, interval=INTERVAL), start=True)["id"]
        d.wait_state(ref, "finished")
        self.assertEqual(d.json("POST", "/cases/%s/extend" % ref, {"end": NEW_END})[0], 200)
        d.json("POST", "/cases/%s/start" % ref)
        self.assertEqual(d.wait_state(ref, ("finished", "failed"), timeout=60)["state"], "finished")
        with fetched_result(d, ref) as f:
            expected = list(f["/snapshots/time"][...])
        broken = []
        for point in self.POINTS:
            cid = d.create(tiny_case("finished", end=OLD_END, interval=INTERVAL), start=True)["id"]
            d.wait_state(cid, "finished")
            self.crash_extend(d, cid, NEW_END, point)
            st = d.status(cid)
            ends = stored_end(d, cid)
            if (st["state"], st["end_time"]) + ends != ("paused", NEW_END, NEW_END, NEW_END):
                again = d.json("POST", "/cases/%s/extend" % cid, {"end": NEW_END})[0]
                start = d.json("POST", "/cases/%s/start" % cid)[0]
                broken.append((point, st["state"], st["end_time"]) + ends + (again, start))
                continue
            status, st = d.json("POST", "/cases/%s/start" % cid)
            self.assertEqual((status, st["state"]), (200, "running"), (point, st))
            st = d.wait_state(cid, ("finished", "failed"), timeout=60)
            self.assertEqual((st["state"], st["time"]), ("finished", NEW_END), (point, st))
            with fetched_result(d, cid) as f:
                times = f["/snapshots/time"][...]
            self.assertEqual(len(times), st["snapshots"], point)
            self.assertEqual(list(times), expected, point)
        self.assertEqual(broken, [], "points that left the case torn: (point, state, end_time, "
                         "case.json end, result.h5 end, extend again, start)")
        self.assertEqual(d.stop()[0], 0, d.log_tail())

    def test_an_extend_answered_500_half_way_is_completed_by_the_next(self):
        """result.h5 cannot take the new document (a directory in its
        place): 500 with case.json already rewritten. Before, the repeat
        was 409 (\"not beyond the current end\") and so was start."""
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        cid = d.create(tiny_case("finished", end=OLD_END, interval=INTERVAL), start=True)["id"]
        done = d.wait_state(cid, "finished")
        path = os.path.join(d.data_dir, cid, "result.h5")
        os.rename(path, path + ".kept")
        os.mkdir(path)
        status, problem = d.json("POST", "/cases/%s/extend" % cid, {"end": NEW_END})
        self.assertEqual(status, 500, problem)
        self.assertIn("result.h5", problem["detail"])
        self.assertEqual(d.status(cid)["state"], "finished")
        os.rmdir(path)
        os.rename(path + ".kept", path)
        status, st = d.json("POST", "/cases/%s/extend" % cid, {"end": NEW_END})
        self.assertEqual((status, st.get("state"), st.get("end_time")), (200, "paused", NEW_END), st)
        self.assertEqual(stored_end(d, cid), (NEW_END, NEW_END))
        self.assertEqual(d.json("POST", "/cases/%s/start" % cid)[0], 200)
        st = d.wait_state(cid, ("finished", "failed"), timeout=60)
        self.assertEqual((st["state"], st["time"]), ("finished", NEW_END), st)
        self.assertGreater(st["snapshots"], done["snapshots"])
        self.assertEqual(snapshot_count(d, cid), st["snapshots"])
        self.assertEqual(d.stop()[0], 0, d.log_tail())

    def test_an_extend_of_a_paused_case_cut_short_comes_back_whole(self):
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        broken = []
        for point in self.POINTS:
            cid = d.create(tiny_case("paused", end=1.0), start=True)["id"]
            d.wait(cid, lambda s: s["step"] > 20, what="steps")
            paused = d.json("POST", "/cases/%s/pause" % cid)[1]
            self.assertEqual(paused["state"], "paused", paused)
            self.crash_extend(d, cid, 2.0, point)
            st = d.status(cid)
            ends = stored_end(d, cid)
            if (st["state"], st["end_time"]) + ends != ("paused", 2.0, 2.0, 2.0):
                broken.append((point, st["state"], st["end_time"]) + ends)
                continue
            self.assertEqual(st["step"], paused["step"], point)
            status, st = d.json("POST", "/cases/%s/start" % cid)
            self.assertEqual((status, st["state"]), (200, "running"), (point, st))
            d.wait(cid, lambda s: s["step"] > paused["step"], what="a step past the pause")
            self.assertEqual(d.json("POST", "/cases/%s/stop" % cid)[1]["state"], "stopped")
        self.assertEqual(broken, [], "points that left the case torn: (point, state, end_time, "
                         "case.json end, result.h5 end)")
        self.assertEqual(d.stop()[0], 0, d.log_tail())


class DamagedFilesTest(unittest.TestCase):
    """Item 13: a damaged result.h5 or status.json of a paused case is kept
    as found, the case failed naming the file, and putting the good file
    back brings the case back as it was (as for a damaged checkpoint)."""

    def paused_case(self, d, snapshots=6):
        cid = d.create(tiny_case("paused", end=10.0, interval=2e-5), start=True)["id"]
        d.wait(cid, lambda s: s["snapshots"] >= snapshots, what="%d snapshots" % snapshots)
        paused = d.json("POST", "/cases/%s/pause" % cid)[1]
        self.assertEqual(paused["state"], "paused", paused)
        return cid, paused

    def check_kept(self, name, damage, words):
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        cid, paused = self.paused_case(d)
        d.kill()
        path = os.path.join(d.data_dir, cid, name)
        with open(path, "rb") as f:
            good = f.read()
        damaged = damage(good)
        with open(path, "wb") as f:
            f.write(damaged)
        d.start()
        st = d.status(cid)
        with open(path, "rb") as f:
            found = f.read()
        self.assertEqual((st["state"], found == damaged), ("failed", True),
                         "%s of a case paused at step %d with %d snapshots: now %s at step %d "
                         "with %d snapshots, the damaged file %s"
                         % (name, paused["step"], paused["snapshots"], st["state"], st["step"],
                            st["snapshots"], "kept" if found == damaged else "replaced"))
        for word in words:
            self.assertIn(word, st["error"])
        self.assertEqual(d.json("POST", "/cases/%s/start" % cid)[0], 409)
        d.kill()  # and once more: still kept
        d.start()
        self.assertEqual(d.status(cid)["state"], "failed")
        with open(path, "rb") as f:
            self.assertEqual(f.read(), damaged)
        d.kill()
        with open(path, "wb") as f:  # mended: the case is back as it was
            f.write(good)
        d.start()
        st = d.status(cid)
        self.assertEqual((st["state"], st["step"], st["snapshots"]),
                         ("paused", paused["step"], paused["snapshots"]), st)
        self.assertEqual(snapshot_count(d, cid), paused["snapshots"])
        self.assertEqual(d.stop()[0], 0, d.log_tail())

    def test_a_damaged_result_file_of_a_paused_case_is_kept(self):
        self.check_kept("result.h5", lambda good: good[:len(good) // 2], ["result.h5"])

    def test_a_damaged_status_of_a_paused_case_is_kept(self):
        self.check_kept("status.json", lambda good: b"\x00\x01" + good[2:], ["status.json"])


class ListenFirstTest(unittest.TestCase):
    """Item 14: a restart listens before it rebuilds the stored cases that
    may run again (three 384k-tetrahedron cases kept it unreachable for
    17 s). A case whose case.json is a FIFO makes its rebuild wait until
    the test writes to it: a daemon that rebuilt before listening never
    came up; now it answers, and a request for another case checks that
    case at once."""

    def test_the_daemon_answers_while_a_stored_case_is_being_checked(self):
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        slow = d.create(tiny_case("slow", end=10.0, interval=2e-5), start=True)["id"]
        other = d.create(tiny_case("other", end=10.0, interval=2e-5), start=True)["id"]
        for cid in (slow, other):
            d.wait(cid, lambda s: s["snapshots"] >= 2, what="snapshots")
        d.kill()
        fifo = os.path.join(d.data_dir, slow, "case.json")
        with open(fifo, "rb") as f:
            document = f.read()
        os.unlink(fifo)
        os.mkfifo(fifo)
        released = []

        def release():  # once the daemon has opened the FIFO to read it
            deadline = time.monotonic() + 60 * SLOW
            while time.monotonic() < deadline:
                try:
                    fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
                except OSError:  # ENXIO: no reader yet
                    time.sleep(0.01)
                    continue
                os.close(fd)
                released.append(True)
                return
        self.addCleanup(release)  # never leave the daemon blocked
        d.start()
        self.assertEqual(d.request("GET", "/health")[0], 200)
        listed = [c["id"] for c in d.json("GET", "/cases")[1]["cases"]]
        self.assertEqual(listed, [slow, other])
        st = d.status(other)  # checked on the spot, not behind the blocked one
        self.assertEqual(st["state"], "paused", st)
        self.assertEqual(snapshot_count(d, other), st["snapshots"])
        new = d.create(tiny_case("new", end=0.0002), start=True)["id"]
        self.assertEqual(d.wait_state(new, ("finished", "failed"))["state"], "finished")
        release()
        self.assertEqual(released, [True])
        # Its case.json was not a file: the case fails naming it, files kept.
        st = d.wait_state(slow, "failed", timeout=60)
        self.assertIn("case.json", st["error"])
        os.unlink(fifo)
        with open(fifo, "wb") as f:
            f.write(document)
        self.assertEqual(d.stop()[0], 0, d.log_tail())
        d.start()
        self.assertEqual(d.status(slow)["state"], "paused")
        self.assertEqual(d.stop()[0], 0, d.log_tail())


if __name__ == "__main__":
    unittest.main()
