"""The data directory outlives the daemon: after SIGTERM (exit 0 within
10 s) and after SIGKILL every case is listed again, a running case comes
back paused at its last checkpoint and runs on to the end, finished cases
keep their results, and a corrupt case directory does not stop start-up."""
import json
import os
import signal
import shutil
import time
import unittest

import numpy as np

from fdemd_harness import Daemon, fetched_result, tiny_case


def read_result(daemon, case_id):
    with fetched_result(daemon, case_id) as f:
        return {name: f["/snapshots/" + name][...] for name in ("time", "step", "position")}


class PersistenceTest(unittest.TestCase):
    def setUp(self):
        self.d = Daemon()
        self.d.start()

    def tearDown(self):
        self.d.close()

    def check_series(self, result, nodes):
        s = len(result["time"])
        self.assertEqual(result["step"].shape, (s,))
        self.assertEqual(result["position"].shape, (s, nodes, 2))
        self.assertEqual(result["time"][0], 0.0)
        self.assertTrue(np.all(np.diff(result["step"]) > 0), result["step"])

    def test_restart_after_sigterm(self):
        d = self.d
        finished = d.create(tiny_case("finished", end=0.0004), start=True)["id"]
        d.wait_state(finished, "finished")
        created = d.create(tiny_case("created"))["id"]
        running = d.create(d.case_lasting(2.0, name="running"), start=True)["id"]
        paused = d.create(tiny_case("paused", end=10.0), start=True)["id"]
        d.wait(paused, lambda s: s["step"] > 20, what="steps")
        paused_step = d.json("POST", "/cases/%s/pause" % paused)[1]["step"]
        seen = d.wait(running, lambda s: s["step"] > 20, what="steps")["step"]
        before = {c["id"]: c for c in d.json("GET", "/cases")[1]["cases"]}
        finished_result = read_result(d, finished)

        code, took = d.stop(signal.SIGTERM)
        self.assertEqual(code, 0, d.log_tail())
        self.assertLess(took, 10.0)

        d.start()
        after = d.json("GET", "/cases")[1]["cases"]
        self.assertEqual([c["id"] for c in after], [finished, created, running, paused])
        by_id = {c["id"]: c for c in after}
        # Elastic energy is excepted: the engine reports the energy of the
        # positions a step's forces used, and after a restore that of the
        # restored positions (core/checkpoint/checkpoint.c), one step apart.
        for st in (by_id[finished], before[finished]):
            st["energy"].pop("elastic")
        self.assertEqual(by_id[finished], before[finished])
        self.assertEqual(by_id[created]["state"], "created")
        self.assertEqual((by_id[paused]["state"], by_id[paused]["step"]), ("paused", paused_step))
        st = by_id[running]
        self.assertEqual(st["state"], "paused")
        self.assertGreaterEqual(st["step"], seen)
        self.assertIsNone(st["error"])
        for key in ("kinetic", "elastic"):
            self.assertTrue(np.isfinite(st["energy"][key]))
        again = read_result(d, finished)
        for key in finished_result:
            np.testing.assert_array_equal(again[key], finished_result[key])
        # The checkpoint was written at the pause: resuming continues from that step.
        status, state = d.json("GET", "/cases/%s/state" % running)
        self.assertEqual(state["step"], st["step"])
        status, st = d.json("POST", "/cases/%s/start" % running)
        self.assertEqual((status, st["state"]), (200, "running"))
        st = d.wait_state(running, "finished", timeout=30)
        result = read_result(d, running)
        self.check_series(result, st["nodes"])
        self.assertEqual(result["step"][-1], st["step"])
        self.assertEqual(len(result["time"]), st["snapshots"])
        self.assertEqual(d.stop()[0], 0, d.log_tail())

    def test_restart_after_sigkill(self):
        d = self.d
        # Far longer than the test watches it, so that it is still running
        # when killed however the machine's load changes: the test waits for
        # states, never for time (a 4 s case calibrated under load finished
        # before the kill once the load fell).
        case = d.case_lasting(60.0, name="killed")
        case["output"]["interval"] = case["time"]["end"] / 400
        case_id = d.create(case, start=True)["id"]
        finished = d.create(tiny_case("done", end=0.0003), start=True)["id"]
        d.wait_state(finished, "finished")
        seen = d.wait(case_id, lambda s: s["snapshots"] >= 6, timeout=60, what="progress")
        # Every snapshot comes with a checkpoint: two more, and the one that
        # holds `seen` is on disk.
        d.wait(case_id, lambda s: s["snapshots"] >= seen["snapshots"] + 2, timeout=60,
               what="two more snapshots")
        killed_at = d.status(case_id)["step"]
        d.stop(signal.SIGKILL)

        d.start()
        cases = d.json("GET", "/cases")[1]["cases"]
        self.assertEqual([c["id"] for c in cases], [case_id, finished])
        st = d.status(case_id)
        self.assertEqual(st["state"], "paused")
        self.assertGreater(st["step"], 0)
        self.assertLessEqual(st["step"], killed_at)
        self.assertGreaterEqual(st["step"], seen["step"])
        self.assertEqual(d.status(finished)["state"], "finished")
        # The result file is readable and holds nothing past the checkpoint.
        result = read_result(d, case_id)
        self.check_series(result, st["nodes"])
        self.assertLessEqual(result["step"][-1], st["step"])
        self.assertEqual(len(result["time"]), st["snapshots"])
        # It runs on with one continuous series.
        d.json("POST", "/cases/%s/start" % case_id)
        d.wait(case_id, lambda s: s["snapshots"] >= st["snapshots"] + 3, timeout=60,
               what="snapshots after the restart")
        d.json("POST", "/cases/%s/stop" % case_id)
        st = d.wait_state(case_id, "stopped", timeout=60)
        result = read_result(d, case_id)
        self.check_series(result, st["nodes"])
        self.assertEqual(len(result["time"]), st["snapshots"])
        interval = case["output"]["interval"]
        gaps = np.diff(result["time"])
        self.assertLess(gaps.max(), 1.5 * interval)
        self.assertEqual(d.stop()[0], 0, d.log_tail())

    def test_corrupt_case_dirs_do_not_stop_startup(self):
        d = self.d
        good = d.create(tiny_case("good", end=0.0002), start=True)["id"]
        d.wait_state(good, "finished")
        self.assertEqual(d.stop()[0], 0)
        data = d.data_dir
        os.makedirs(os.path.join(data, "0123456789abcdef"))
        with open(os.path.join(data, "0123456789abcdef", "case.json"), "w") as f:
            f.write("{ this is not json")
        with open(os.path.join(data, "0123456789abcdef", "status.json"), "w") as f:
            f.write("\x00\x01garbage")
        os.makedirs(os.path.join(data, "fedcba9876543210"))      # empty: never acknowledged
        os.makedirs(os.path.join(data, "not-a-case"))
        with open(os.path.join(data, "stray-file"), "w") as f:
            f.write("x")
        # A case whose checkpoint was damaged.
        broken = os.path.join(data, "00000000000000aa")
        shutil.copytree(os.path.join(data, good), broken)
        with open(os.path.join(broken, "checkpoint.bin"), "wb") as f:
            f.write(b"\x00" * 17)
        status = json.load(open(os.path.join(broken, "status.json")))
        status.update(id="00000000000000aa", state="paused", created="2000-01-01T00:00:00.000Z")
        json.dump(status, open(os.path.join(broken, "status.json"), "w"))

        d.start()
        # GET /cases/ID waits for the case's start-up check (the list may
        # show a case's stored status.json while it is being checked).
        cases = {c["id"]: d.status(c["id"]) for c in d.json("GET", "/cases")[1]["cases"]}
        self.assertEqual(cases[good]["state"], "finished")
        self.assertEqual(cases["0123456789abcdef"]["state"], "failed")
        self.assertTrue(cases["0123456789abcdef"]["error"])
        self.assertEqual(cases["00000000000000aa"]["state"], "failed")
        self.assertIn("checkpoint", cases["00000000000000aa"]["error"])
        self.assertNotIn("fedcba9876543210", cases)
        # The oldest (by created time) comes first.
        self.assertEqual(d.json("GET", "/cases")[1]["cases"][0]["id"], "00000000000000aa")
        # Failed cases answer clearly and can be deleted.
        status, problem = d.json("POST", "/cases/0123456789abcdef/start")
        self.assertEqual(status, 409)
        self.assertEqual(d.request("DELETE", "/cases/0123456789abcdef")[0], 204)
        self.assertEqual(d.stop()[0], 0, d.log_tail())


if __name__ == "__main__":
    unittest.main()
