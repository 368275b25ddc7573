"""Fracture events through the real daemon (contract 5.4, issue 15 item 2):
the rock bars of tests/unit/test_events.c (2D: 0.1 x 0.01 m, 20 x 2 cells;
3D: 0.1 x 0.01 x 0.01 m, 10 x 1 x 1 boxes) pulled apart at 0.5 m/s at both
ends, slowly enough that the crack localises before the other sections
soften (their joints keep under 1 % of the fracture account).

Against numbers: one event per broken joint (the status' broken_joints),
their energies sum to energy.fracture within 1 %, each joint across the
bar broke in tension and dissipated G_I times its face within 5 %;
GET /events and /events/* in result.h5 hold the same rows; a snapshot at
time T shows broken exactly the joints of the events with time <= T;
?since=T returns the events after T; bad ?since= is 400, other methods
405, unknown cases 404, a case without fracture has none. A case paused
mid-run and resumed by a restarted daemon reports the very events of an
uninterrupted run."""
import json
import os
import subprocess
import sys
import unittest

import h5py
import numpy as np

from fdemd_harness import ROOT, SLOW, Daemon, DaemonTestCase, DimensionRunsTestCase, tiny_case

sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
from fdemd_client import Client  # noqa: E402

PLOT = os.path.join(ROOT, "clients", "python", "plot_fragments.py")
PYTHON = "/usr/bin/python3"

LENGTH, SIDE, SPEED = 0.1, 0.01, 0.5
ENERGY_I = 10.0


def pulled_bar(dimension, speed=SPEED, end=2.5e-4, interval=1e-5):
    if dimension == 2:
        shape = {"rectangle": {"origin": [0, 0], "size": [LENGTH, SIDE], "divisions": [20, 2]}}
        box = lambda x: [x - 1e-9, -1, x + 1e-9, 1]
        free = [None]
    else:
        shape = {"box": {"origin": [0, 0, 0], "size": [LENGTH, SIDE, SIDE],
                         "divisions": [10, 1, 1]}}
        box = lambda x: [x - 1e-9, -1, -1, x + 1e-9, 1, 1]
        free = [None, None]
    part = {"name": "bar", "material": "rock", "fracture": True}
    part.update(shape)
    return {
        "name": "pulled-bar-%dd" % dimension,
        "dimension": dimension,
        "materials": {"rock": {
            "density": 2700, "young": 3e10, "poisson": 0.25, "damping": 0.1, "friction": 0.3,
            "fracture": {"tensile_strength": 1e6, "cohesion": 3e6, "friction_angle": 30,
                         "energy_I": ENERGY_I, "energy_II": 50}}},
        "parts": [part],
        "constraints": [{"box": box(0), "velocity": [-speed] + free},
                        {"box": box(LENGTH), "velocity": [speed] + free}],
        "time": {"end": end, "safety": 0.5},
        "output": {"interval": interval, "fields": ["position", "damage"]},
    }


def passing_at(curve, x):
    """The mass fraction of a sieve curve no larger than x."""
    return max([p["passing"] for p in curve if p["diameter"] <= x] + [0.0])


def face_size(x0, nodes, dimension):
    """Initial length (2D) or area (3D) of a joint's face A."""
    a = x0[nodes[:dimension]]
    if dimension == 2:
        return float(np.linalg.norm(a[1] - a[0]))
    return 0.5 * float(np.linalg.norm(np.cross(a[1] - a[0], a[2] - a[0])))


class EventsThroughDaemon(DimensionRunsTestCase):
    PREFIX = "fdemd-events-"
    ROUTE = "events"

    @classmethod
    def case_of(cls, dimension):
        return pulled_bar(dimension)

    def test_one_event_per_broken_joint(self):
        for dimension, _, final, body, _ in self.each():
            self.assertEqual(final["state"], "finished", final.get("error"))
            events = body["events"]
            self.assertGreater(final["broken_joints"], 0)
            self.assertEqual(len(events), final["broken_joints"])
            self.assertEqual(body["count"], len(events))
            self.assertEqual(body["dimension"], dimension)
            self.assertIsNone(body["since"])
            joints = [e["joint"] for e in events]
            self.assertEqual(len(set(joints)), len(joints), "a joint broke twice")
            keys = [(e["time"], e["joint"]) for e in events]
            self.assertEqual(keys, sorted(keys), "events not in the order they broke")
            for e in events:
                self.assertIn(e["mode"], (1, 2, 3))
                self.assertEqual(len(e["position"]), dimension)
                self.assertTrue(-0.01 < e["position"][0] < LENGTH + 0.01, e)
                self.assertGreater(e["energy"], 0)

    def test_energies_add_up_to_the_fracture_account(self):
        for dimension, _, final, body, _ in self.each():
            total = sum(e["energy"] for e in body["events"])
            fracture = final["energy"]["fracture"]
            self.assertLess(abs(total - fracture), 0.01 * fracture,
                            "events %.6g J, energy.fracture %.6g J" % (total, fracture))

    def test_joints_across_the_bar_break_in_tension_at_G_I(self):
        for dimension, _, _, body, path in self.each():
            with h5py.File(path, "r") as f:
                x0 = f["/mesh/position0"][...]
                joints = f["/mesh/joints"][...]
            across = 0
            for e in body["events"]:
                nodes = joints[e["joint"]]
                xs = x0[nodes[:dimension], 0]
                if np.ptp(xs) > 1e-12:
                    continue  # a face not normal to the bar
                across += 1
                self.assertEqual(e["mode"], 1, e)
                expected = ENERGY_I * face_size(x0, nodes, dimension)
                self.assertLess(abs(e["energy"] / expected - 1), 0.05,
                                "%.6g J against G_I A = %.6g J" % (e["energy"], expected))
            self.assertGreater(across, 0)

    def test_file_holds_the_same_events(self):
        for dimension, _, _, body, path in self.each():
            events = body["events"]
            with h5py.File(path, "r") as f:
                g = f["/events"]
                self.assertEqual(g["time"].dtype, np.float64)
                self.assertEqual(g["joint"].dtype, np.int32)
                self.assertEqual(g["mode"].dtype, np.int8)
                self.assertEqual(g["position"].shape, (len(events), dimension))
                np.testing.assert_array_equal(g["time"][...], [e["time"] for e in events])
                np.testing.assert_array_equal(g["joint"][...], [e["joint"] for e in events])
                np.testing.assert_array_equal(g["mode"][...], [e["mode"] for e in events])
                np.testing.assert_array_equal(g["energy"][...], [e["energy"] for e in events])
                np.testing.assert_array_equal(g["position"][...], [e["position"] for e in events])

    def test_snapshots_show_broken_the_joints_of_earlier_events(self):
        for dimension, _, _, body, path in self.each():
            with h5py.File(path, "r") as f:
                times = f["/snapshots/time"][...]
                damage = f["/snapshots/damage"][...]
            event_time = {e["joint"]: e["time"] for e in body["events"]}
            for t, row in zip(times, damage):
                broken = set(np.nonzero(row >= 1.0)[0].tolist())
                before = {j for j, te in event_time.items() if te <= t}
                self.assertEqual(broken, before, "snapshot at t = %g" % t)

    def test_since_filters(self):
        for dimension, case_id, _, body, _ in self.each():
            times = [e["time"] for e in body["events"]]
            for since in (0.0, times[0], times[-1], times[len(times) // 2], -1.0, 1.0):
                status, part = self.d.json("GET", "/cases/%s/events?since=%r" % (case_id, since))
                self.assertEqual(status, 200, part)
                self.assertEqual(part["since"], since)
                self.assertEqual(part["events"], [e for e in body["events"] if e["time"] > since])

    def test_bad_since_is_400(self):
        case_id = self.runs[2][0]
        for bad in ("abc", "nan", "inf", "-inf", "", "1e999", "1s"):
            status, body = self.d.json("GET", "/cases/%s/events?since=%s" % (case_id, bad))
            self.assertEqual(status, 400, (bad, body))
            self.assertIn("since", body["detail"])
        status, body = self.d.json("GET", "/cases/%s/events?after=1" % case_id)
        self.assertEqual(status, 400, body)

    def test_unknown_case_and_methods(self):
        status, _ = self.d.json("GET", "/cases/0123456789abcdef/events")
        self.assertEqual(status, 404)
        case_id = self.runs[2][0]
        for method in ("POST", "PUT", "DELETE"):
            status, _, _ = self.d.request(method, "/cases/%s/events" % case_id)
            self.assertEqual(status, 405, method)

    def test_cases_without_fracture_have_none(self):
        st = self.d.create(tiny_case("no-fracture", end=2e-5))
        status, body = self.d.json("GET", "/cases/%s/events" % st["id"])
        self.assertEqual((status, body["events"], body["count"]), (200, [], 0))
        self.d.json("POST", "/cases/%s/start" % st["id"])
        self.d.wait_state(st["id"], "finished")
        status, body = self.d.json("GET", "/cases/%s/events" % st["id"])
        self.assertEqual((status, body["events"]), (200, []))


    # ---- what a user runs on the same two bars

    def url(self):
        return "http://127.0.0.1:%d" % self.d.port

    def ctl(self, *args):
        return self.d.fdemctl(*args)

    def test_fdemctl_events(self):
        for dimension, case_id, _, body, _ in self.each():
            events = body["events"]
            r = self.ctl("events", case_id)
            self.assertEqual(r.returncode, 0, r.stderr)
            lines = r.stdout.splitlines()
            self.assertEqual(lines[0], "%d fracture events" % len(events))
            rows = lines[2:2 + len(events)]
            self.assertEqual([int(row.split()[1]) for row in rows], [e["joint"] for e in events])
            modes = {1: "tensile", 2: "shear", 3: "mixed"}
            for row, e in zip(rows, events):
                self.assertIn(" %s " % modes[e["mode"]], row)
            total = sum(e["energy"] for e in events)
            self.assertAlmostEqual(float(rows[-1].split()[-1]), total, delta=1e-5 * total)
            since = events[0]["time"]
            r = self.ctl("events", case_id, "--since", repr(since))
            self.assertEqual(r.returncode, 0, r.stderr)
            later = [e for e in events if e["time"] > since]
            self.assertEqual(r.stdout.splitlines()[0], "%d fracture events" % len(later))
            r = self.ctl("events", case_id, "--json")
            self.assertEqual(json.loads(r.stdout), body)
        self.assertEqual(self.ctl("events", case_id, "--since", "soon").returncode, 2)
        self.assertEqual(self.ctl("events").returncode, 2)
        self.assertNotEqual(self.ctl("events", "0123456789abcdef").returncode, 0)

    def test_python_client_events(self):
        client = Client(self.url())
        for dimension, case_id, _, body, _ in self.each():
            self.assertEqual(client.events(case_id), body)
            since = body["events"][-1]["time"]
            self.assertEqual(client.events(case_id, since=since)["events"], [])
            self.assertEqual(client.events(case_id, since=0)["events"], body["events"])

    def check_pngs(self, prefix):
        import matplotlib.image
        for kind in ("sieve", "events"):
            path = "%s-%s.png" % (prefix, kind)
            self.assertTrue(os.path.exists(path), path)
            self.assertGreater(os.path.getsize(path), 10000, path)
            image = matplotlib.image.imread(path)[..., :3]
            colours = np.unique(image.reshape(-1, 3), axis=0)
            self.assertGreater(len(colours), 20, "%s is nearly blank" % path)

    def test_plot_fragments_from_the_file_and_the_server(self):
        for dimension, case_id, _, body, path in self.each():
            pieces = self.d.json("GET", "/cases/%s/fragments" % case_id)[1]
            prefix = os.path.join(self.tmp, "file-%dd" % dimension)
            r = subprocess.run([PYTHON, PLOT, path, "-o", prefix, "--print"],
                               capture_output=True, text=True, timeout=120 * SLOW)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.check_pngs(prefix)
            drawn = json.loads(r.stdout)
            self.assertEqual(drawn["fragments"], len(pieces["fragments"]))
            # the file's sieve curve is the route's: the same mass fraction
            # passes between and above its diameters (equal pieces whose
            # sizes were summed in another order may differ by an ulp, so
            # not at a diameter itself)
            route = sorted(p["diameter"] for p in pieces["distribution"])
            probes = [np.sqrt(a * b) for a, b in zip(route, route[1:]) if b > a * (1 + 1e-6)]
            probes += [route[0] * 0.5, route[-1] * 2]
            for x in probes:
                self.assertAlmostEqual(passing_at(drawn["distribution"], x),
                                       passing_at(pieces["distribution"], x), delta=1e-9)
            self.assertEqual(drawn["events"]["time"], [e["time"] for e in body["events"]])
            self.assertAlmostEqual(drawn["events"]["energy"][-1],
                                   sum(e["energy"] for e in body["events"]), delta=1e-12)
            if dimension == 3:
                continue  # the server's side is the same code in either dimension
            prefix = os.path.join(self.tmp, "server-%dd" % dimension)
            r = subprocess.run([PYTHON, PLOT, "--server", self.url(), "--case", case_id, "-o",
                                prefix, "--print"], capture_output=True, text=True,
                               timeout=120 * SLOW)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.check_pngs(prefix)
            self.assertEqual(json.loads(r.stdout)["distribution"], pieces["distribution"])


class EventsSurviveARestart(unittest.TestCase):
    """Paused once it has broken joints, the daemon restarted, resumed: the
    events are those of the same case run without a pause, to the bit."""

    def test_pause_restart_resume(self):
        d = Daemon().start()
        try:
            # At 5 m/s joints break at two times 1.2e-5 s apart; a snapshot
            # every fifth step (each one fsynced) makes that a second or so
            # of wall time, so the pause usually lands between them
            case = pulled_bar(2, speed=5.0, end=2e-5, interval=2e-7)
            reference = d.create(case, start=True)["id"]
            d.wait_state(reference, "finished", timeout=120)
            expected = d.json("GET", "/cases/%s/events" % reference)[1]["events"]
            self.assertGreater(len(expected), 1)

            case_id = d.create(case, start=True)["id"]
            d.wait(case_id, lambda s: s["broken_joints"] > 0 or s["state"] != "running",
                   timeout=60, what="a broken joint")
            status, st = d.json("POST", "/cases/%s/pause" % case_id)
            paused = status == 200
            if paused:
                st = d.wait_state(case_id, "paused")
                before = d.json("GET", "/cases/%s/events" % case_id)[1]["events"]
                self.assertEqual(before, expected[:len(before)])
            self.assertEqual(d.stop()[0], 0, d.log_tail())
            d.start()
            if paused:
                self.assertEqual(d.status(case_id)["state"], "paused")
                d.json("POST", "/cases/%s/start" % case_id)
            st = d.wait_state(case_id, "finished", timeout=120)
            events = d.json("GET", "/cases/%s/events" % case_id)[1]["events"]
            self.assertEqual(len(events), st["broken_joints"])
            self.assertEqual(events, expected)
            self.assertEqual(d.stop()[0], 0, d.log_tail())
        finally:
            d.close()


if __name__ == "__main__":
    unittest.main()
