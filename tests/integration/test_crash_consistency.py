"""test_crash_consistency.py - crashes that turn back what a client saw
(issue 30; contract 1 "Nothing that was acknowledged is lost", 5.3 extend,
5.5). Each test SIGKILLs the real daemon at a moment a client has just
seen something, restarts it on the same --data and checks that what was
seen is still there: the snapshot count a status showed, a stop answered
200, an extend interrupted between its writes (a test-only fault point,
FDEMD_FAULT_POINT, makes the daemon kill itself there), and damaged files
of a paused case, which are kept as found rather than replaced.

Every wait is for a state, with a generous deadline, never for wall time."""
import json
import os
import signal
import threading
import time
import unittest

import h5py

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
                self.assertLess(time.monotonic(), deadline, "no new snapshot in 30 s")
                seen = d.status(cid)["snapshots"]
            d.kill()
            d.start()
            st = d.status(cid)
            self.assertEqual(st["state"], "paused", st)
            self.assertEqual(snapshot_count(d, cid), st["snapshots"])
            if st["snapshots"] < seen:
                lost.append((round_, seen, st["snapshots"]))
        self.assertEqual(lost, [], "rounds (round, seen, after restart) that lost a snapshot "
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
            st = d.json("POST", "/cases/%s/start" % busy)[1]
            self.assertEqual(st["state"], "running", st)
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


if __name__ == "__main__":
    unittest.main()
