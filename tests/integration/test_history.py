"""History output through the real daemon (contract 6.2, issue 33 item 2).

A steel bar (E = 200 GPa, Poisson 0, so a uniaxial bar in 2D and 3D),
1 m long and 0.1 m thick (0.1 x 0.1 m in 3D), held at x = 0 and pulled at
x = 1 at 0.05 m/s after a smooth 2 ms ramp (ten wave transits: the load is
quasi-static), with a history interval of 0.5 ms over 20 ms.

Against numbers: the pulled constraint's force against its mean
displacement (/history/constraint_force, /history/constraint_displacement)
is a line of slope E A / L within 2 % (A = 0.1 m per metre of thickness
in 2D, 0.01 m^2 in 3D); the held end carries the opposite force within
2 %; the monitoring point at the pulled end moved with it; rows lie at the
first step boundary at or after each multiple of the interval; every
energy account is there and the balance closes (|residual| under 1 % of
the external work); GET /cases/ID/history holds the rows of result.h5 and
?since=T returns those after T; a point outside the bar is one 422 at its
pointer; a case without "history" records a row with every snapshot."""
import os
import sys
import unittest

import h5py
import numpy as np

from fdemd_harness import ROOT, Daemon, DimensionRunsTestCase

sys.path.insert(0, os.path.join(ROOT, "clients", "python"))

E, RHO, LENGTH, SIDE = 2e11, 7800.0, 1.0, 0.1
SPEED, RAMP, END, INTERVAL = 0.05, 2e-3, 0.02, 5e-4
TERMS = ("kinetic", "elastic", "joint", "contact", "friction", "fracture", "damping",
         "gravity_work", "external_work", "excavated", "residual")


def bar(dimension, history=True):
    if dimension == 2:
        shape = {"rectangle": {"origin": [0, 0], "size": [LENGTH, SIDE], "divisions": [20, 2]}}
        box = lambda x: [x - 1e-9, -1, x + 1e-9, 1]
        free, tip, middle = [None], [LENGTH, 0.05], [0.5, 0.05]
    else:
        shape = {"box": {"origin": [0, 0, 0], "size": [LENGTH, SIDE, SIDE],
                         "divisions": [10, 1, 1]}}
        box = lambda x: [x - 1e-9, -1, -1, x + 1e-9, 1, 1]
        free, tip, middle = [None, None], [LENGTH, 0.05, 0.05], [0.5, 0.05, 0.05]
    part = {"name": "bar", "material": "steel"}
    part.update(shape)
    case = {
        "name": "history-bar-%dd" % dimension,
        "dimension": dimension,
        "materials": {"steel": {"density": RHO, "young": E, "poisson": 0.0, "damping": 0.05}},
        "parts": [part],
        "constraints": [{"box": box(0), "velocity": [0] + free},
                        {"box": box(LENGTH), "velocity": [SPEED] + free,
                         "amplitude": [[0, 0], [RAMP, 1]]}],
        "time": {"end": END},
        "output": {"interval": END / 4},
    }
    if history:
        case["history"] = {"interval": INTERVAL,
                           "points": [{"name": "tip", "at": tip}, {"name": "middle", "at": middle}]}
    return case


class HistoryThroughDaemon(DimensionRunsTestCase):
    PREFIX = "fdemd-history-"
    ROUTE = "history"

    @classmethod
    def case_of(cls, dimension):
        return bar(dimension)

    def test_force_against_displacement_has_slope_EA_over_L(self):
        for dimension, _, final, _, path in self.each():
            self.assertEqual(final["state"], "finished", final.get("error"))
            with h5py.File(path, "r") as f:
                force = f["/history/constraint_force"][...]
                disp = f["/history/constraint_displacement"][...]
            area = SIDE if dimension == 2 else SIDE * SIDE
            u, pull, hold = disp[:, 1, 0], force[:, 1, 0], force[:, 0, 0]
            late = u > 0.25 * u[-1]  # past the ramp
            slope = np.polyfit(u[late], pull[late], 1)[0]
            want = E * area / LENGTH
            print("  %dD: slope %.6g N/m, E A / L %.6g N/m, error %.3f %%"
                  % (dimension, slope, want, 100 * (slope / want - 1)))
            self.assertLess(abs(slope / want - 1), 0.02)
            self.assertLess(abs(hold[-1] + pull[-1]), 0.02 * abs(pull[-1]))
            self.assertLess(np.max(np.abs(disp[:, 0, 0])), 1e-12, "the held end moved along the bar")

    def test_points_follow_their_nodes(self):
        for dimension, _, _, body, path in self.each():
            self.assertEqual(body["names"], ["tip", "middle"])
            with h5py.File(path, "r") as f:
                names = [n.decode() if isinstance(n, bytes) else n
                         for n in f["/history/points"].attrs["names"]]
                pd = f["/history/points/displacement"][...]
                pv = f["/history/points/velocity"][...]
                disp = f["/history/constraint_displacement"][...]
            self.assertEqual(names, ["tip", "middle"])
            self.assertEqual(pd.shape[1:], (2, dimension))
            self.assertEqual(pv.shape, pd.shape)
            self.assertLess(abs(pd[-1, 0, 0] - disp[-1, 1, 0]), 1e-3 * disp[-1, 1, 0])
            self.assertLess(abs(pv[-1, 0, 0] - SPEED), 1e-9)
            # the middle of a uniformly stretched bar moves half as far
            self.assertLess(abs(pd[-1, 1, 0] / pd[-1, 0, 0] - 0.5), 0.02)

    def test_rows_at_the_interval(self):
        for dimension, _, final, _, path in self.each():
            with h5py.File(path, "r") as f:
                t = f["/history/time"][...]
                step = f["/history/step"][...]
            dt = final["dt"]
            self.assertEqual(t[0], 0.0)
            self.assertEqual(step[0], 0)
            k = np.arange(len(t))
            self.assertEqual(len(t), int(round(END / INTERVAL)) + 1)
            # first step boundary at or after k * interval (the last: time.end)
            self.assertTrue(np.all(t[:-1] >= k[:-1] * INTERVAL - 1e-12), t)
            self.assertTrue(np.all(t[:-1] < k[:-1] * INTERVAL + dt * (1 + 1e-9)), t)
            self.assertAlmostEqual(t[-1], END, delta=1e-12)
            self.assertTrue(np.all(np.diff(step) > 0))

    def test_energy_terms_and_balance(self):
        for dimension, _, final, body, path in self.each():
            with h5py.File(path, "r") as f:
                energy = {k: f["/history/energy/" + k][...] for k in TERMS}
            work = energy["external_work"][-1]
            self.assertGreater(work, 0)
            print("  %dD: external work %.6g J, residual %.3g J"
                  % (dimension, work, energy["residual"][-1]))
            self.assertLess(np.max(np.abs(energy["residual"])), 0.01 * work)
            self.assertAlmostEqual(energy["external_work"][-1],
                                   final["energy"]["external_work"], delta=1e-9 * work)
            self.assertEqual(sorted(body["rows"][-1]["energy"]), sorted(TERMS))

    def test_json_rows_match_the_file_and_since_filters(self):
        for dimension, case_id, _, body, path in self.each():
            with h5py.File(path, "r") as f:
                t = f["/history/time"][...]
                force = f["/history/constraint_force"][...]
            rows = body["rows"]
            self.assertEqual([r["time"] for r in rows], list(t))
            self.assertEqual(rows[-1]["constraint_force"], force[-1].tolist())
            status, later = self.d.json("GET", "/cases/%s/history?since=%r" % (case_id, t[10]))
            self.assertEqual(status, 200)
            self.assertEqual([r["time"] for r in later["rows"]], list(t[11:]))
            status, _ = self.d.json("GET", "/cases/%s/history?since=abc" % case_id)
            self.assertEqual(status, 400)

    def test_point_outside_every_body_is_422(self):
        for dimension in (2, 3):
            with self.subTest(dimension=dimension):
                case = bar(dimension)
                case["history"]["points"][1]["at"][0] = 1.5
                status, body = self.d.json("POST", "/cases", case)
                self.assertEqual(status, 422, body)
                pointers = [e["pointer"] for e in body["errors"]]
                self.assertEqual(pointers, ["/history/points/1/at"], body)

    def test_clients(self):
        """fdemctl history --csv, Client.history(since), plot_history.py: the same rows."""
        from fdemd_client import Client
        case_id, _, body, path = self.runs[2]
        csv = os.path.join(self.tmp, "history.csv")
        run = self.d.fdemctl("history", case_id, "--csv", csv)
        self.assertEqual(run.returncode, 0, run.stderr)
        table = np.genfromtxt(csv, delimiter=",", names=True)
        self.assertEqual(len(table), len(body["rows"]))
        self.assertIn("tip_ux", table.dtype.names)
        self.assertTrue(np.allclose(table["c1_fx"], [r["constraint_force"][1][0]
                                                     for r in body["rows"]], rtol=1e-15))
        self.assertTrue(np.allclose(table["residual"], [r["energy"]["residual"]
                                                        for r in body["rows"]], rtol=1e-15))
        url = "http://127.0.0.1:%d" % self.d.port
        client = Client(url, token=self.d.default_token)
        rows = client.history(case_id)["rows"]
        self.assertEqual([r["time"] for r in rows], [r["time"] for r in body["rows"][1:]])
        columns = Client.history_columns(client.history(case_id, since=None))
        self.assertEqual(columns["constraint_force"].shape, (len(body["rows"]), 2, 2))
        png = os.path.join(self.tmp, "history.png")
        import subprocess
        for source in ([path], ["--server", url, "--case", case_id]
                       + (["--token", self.d.default_token] if self.d.default_token else [])):
            run = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "clients", "python",
                                                                    "plot_history.py")]
                                 + source + ["-o", png, "--print"],
                                 capture_output=True, text=True, timeout=120)
            self.assertEqual(run.returncode, 0, run.stderr)
            import json
            drawn = json.loads(run.stdout)
            self.assertEqual(drawn["axis"], "x")
            self.assertEqual(len(drawn["force"]), len(body["rows"]))
            with open(png, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

    def test_without_history_a_row_per_snapshot(self):
        st = self.d.create(bar(2, history=False), start=True)
        st = self.d.wait_state(st["id"], ("finished", "failed", "stopped"), timeout=120)
        self.assertEqual(st["state"], "finished", st.get("error"))
        status, body = self.d.json("GET", "/cases/%s/history" % st["id"])
        self.assertEqual(status, 200)
        self.assertEqual(len(body["rows"]), st["snapshots"])
        self.assertEqual(body["names"], [])


class HistorySurvivesARestart(unittest.TestCase):
    """Paused mid-run, the daemon restarted, resumed: the history rows are
    those of the same case run without a pause, to the bit; an extended
    case goes on appending rows after its old end, time only growing."""

    def test_pause_restart_resume_and_extend(self):
        d = Daemon().start()
        try:
            case = bar(2)
            case["output"]["interval"] = END / 400  # ~400 fsynced snapshots: time to pause
            reference = d.create(case, start=True)["id"]
            d.wait_state(reference, "finished", timeout=120)
            expected = d.json("GET", "/cases/%s/history?since=-1" % reference)[1]["rows"]

            case_id = d.create(case, start=True)["id"]
            d.wait(case_id, lambda s: s["time"] > 0.2 * END or s["state"] != "running",
                   timeout=60, what="a fifth of the run")
            status, _ = d.json("POST", "/cases/%s/pause" % case_id)
            paused = status == 200
            if paused:
                d.wait_state(case_id, "paused")
                before = d.json("GET", "/cases/%s/history?since=-1" % case_id)[1]["rows"]
                self.assertEqual(before, expected[:len(before)])
                print("  paused with %d of %d rows written" % (len(before), len(expected)))
            self.assertEqual(d.stop()[0], 0, d.log_tail())
            d.start()
            if paused:
                self.assertEqual(d.status(case_id)["state"], "paused")
                d.json("POST", "/cases/%s/start" % case_id)
            d.wait_state(case_id, "finished", timeout=120)
            after = d.json("GET", "/cases/%s/history?since=-1" % case_id)[1]
            self.assertEqual(after["rows"], expected)
            self.assertEqual(after["names"], ["tip", "middle"])  # from the file, after a restart

            status, body = d.json("POST", "/cases/%s/extend" % case_id, {"end": 1.5 * END})
            self.assertIn(status, (200, 201, 202), body)
            d.json("POST", "/cases/%s/start" % case_id)
            d.wait_state(case_id, "finished", timeout=120)
            longer = d.json("GET", "/cases/%s/history?since=-1" % case_id)[1]["rows"]
            times = [r["time"] for r in longer]
            self.assertEqual(longer[:len(expected)], expected)
            self.assertTrue(all(b > a for a, b in zip(times, times[1:])), times)
            self.assertAlmostEqual(times[-1], 1.5 * END, delta=1e-12)
            self.assertGreaterEqual(len(longer), int(round(1.5 * END / INTERVAL)))
            self.assertEqual(d.stop()[0], 0, d.log_tail())
        finally:
            d.close()


if __name__ == "__main__":
    unittest.main()
