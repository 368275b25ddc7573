"""Watching a 3D case never changes it (contract 5.1 "Output never changes
the physics", docs/daemon.md "--threads", "Data directory, persistence
and restart"), end to end through the daemon, on the two kinds of 3D case the
2D tests (test_trust.py, test_daemon.py, test_persistence.py) do not reach:

- a fracturing Brazilian disc (examples/brazilian-disc-3d.json, 16 rim
  divisions, platens at 0.2 m/s, 2e-4 s: 240 tetrahedra, 144 joints, some
  16 of which break into several fragments), and
- two boxes meeting obliquely with friction 0.4 (examples/collision-3d.json
  moved off-centre: contact, stick springs, sliding).

Against the same case run straight through on one thread, each of these
must leave every snapshot row they share bit for bit (h5py .tobytes()),
and the events, fragments, final state and status energies equal:

- another output interval (half) and other fields;
- pausing twice and resuming;
- running on two threads with a checkpoint every 0.05 s of wall time, the
  daemon stopped by SIGTERM and restarted on one thread, then killed
  (SIGKILL) and restarted on two, resuming from its last checkpoint: the
  whole result.h5, every dataset and attribute, is the straight run's.

And what a user reads agrees with itself: the final `state` is the last
row of result.h5, the status energies its last energy rows, the status'
fragments and broken joints the file's and the events'; the energy
residual stays within a stated fraction of the energy through the model
(measured: disc 0.2 % of the platens' work, boxes 5e-6 of the kinetic
energy they start with)."""
import json
import os
import signal
import unittest

import h5py
import numpy as np

from fdemd_harness import ROOT, SLOW, Daemon, DaemonTestCase

STATE = "/cases/%s/state?fields=position,velocity,stress,damage"
ROWS = {"kinetic": "kinetic_energy", "elastic": "elastic_energy", "joint": "joint_energy",
        "contact": "contact_energy", "friction": "friction_energy",
        "fracture": "fracture_energy", "damping": "damping_energy",
        "gravity_work": "gravity_work", "external_work": "external_work"}


def example(name):
    with open(os.path.join(ROOT, "examples", name)) as f:
        return json.load(f)


def fracturing_disc():
    """16349 steps, 16 joints broken by the end; under the sanitizers (each
    step about ten times dearer) the platens go twice as fast for half the
    time: 8175 steps, 8 joints broken, 5 fragments, so the CI stays within
    its time."""
    case = example("brazilian-disc-3d.json")
    speed, end = (0.4, 1e-4) if SLOW > 1 else (0.2, 2e-4)
    case["parts"][0]["cylinder"]["divisions"] = [16, 1]
    case["constraints"][0]["velocity"] = [0, -speed, 0]
    case["constraints"][1]["velocity"] = [0, speed, 0]
    case["time"]["end"] = end
    return case


def sliding_boxes():
    case = example("collision-3d.json")
    case["materials"]["rock"]["friction"] = 0.4
    case["parts"][0]["velocity"] = [2.0, 0.5, -0.3]
    case["parts"][1]["box"]["origin"] = [0.005, 0.02, 0.01]
    return case


def file_items(f):
    """Every dataset's bytes and shape and every attribute of an open HDF5
    file, by name, so that two files compare item by item."""
    items = {}

    def attrs(name, obj):
        for key, value in obj.attrs.items():
            value = np.asarray(value) if not isinstance(value, (str, bytes)) else value
            # an array of strings (/history/points@names) holds objects: its
            # bytes are pointers, so it compares by its text
            items[name + "@" + key] = repr(value) if isinstance(value, (str, bytes)) \
                else repr(value.tolist()) if value.dtype == object else value.tobytes()

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            items[name] = (obj.shape, obj[...].tobytes())
        attrs(name, obj)
    f.visititems(visit)
    attrs("", f)
    return items


class ObservationIndependence:
    """The checks, for a case CASE() that breaks joints or not; RESIDUAL is
    the bound on |residual| over the energy through the model."""
    CASE = None
    RESIDUAL = None

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.straight = cls.finish(cls.d, cls.d.create(cls.CASE(), start=True)["id"], "straight")

    @classmethod
    def finish(cls, d, case_id, tag):
        """Waits for the case to finish and keeps what a user can read of
        it: status, result.h5 (path), events, fragments and state."""
        st = d.wait_state(case_id, ("finished", "failed"), timeout=300)
        assert st["state"] == "finished", st
        status, _, data = d.request("GET", "/cases/%s/result.h5" % case_id)
        assert status == 200, status
        path = os.path.join(cls.tmp, tag + ".h5")
        with open(path, "wb") as f:
            f.write(data)
        return {"status": st, "path": path,
                "events": d.json("GET", "/cases/%s/events" % case_id)[1],
                "fragments": d.json("GET", "/cases/%s/fragments" % case_id)[1],
                "state": d.json("GET", STATE % case_id)[1]}

    def assert_same_run(self, a, b, whole_file):
        """b reached a's bits: every row at a common (step, time), or the
        whole file when both wrote the same rows; events, fragments, final
        state and status figures equal."""
        for key in ("step", "time", "energy", "broken_joints", "fragments", "contacts"):
            self.assertEqual(a["status"][key], b["status"][key], key)
        self.assertEqual(a["events"], b["events"])
        self.assertEqual(a["fragments"], b["fragments"])
        self.assertEqual(a["state"], b["state"])
        with h5py.File(a["path"], "r") as fa, h5py.File(b["path"], "r") as fb:
            if whole_file:
                ia, ib = file_items(fa), file_items(fb)
                self.assertEqual(sorted(ia), sorted(ib))
                for name in ia:
                    self.assertTrue(ia[name] == ib[name], "%s differs" % name)
                return
            rows = lambda f: list(zip(f["/snapshots/step"][...], f["/snapshots/time"][...]))
            ra, rb = rows(fa), rows(fb)
            common = [r for r in ra if r in rb]
            self.assertGreaterEqual(len(common), len(ra) // 2, "too few common rows")
            names = set(fa["/snapshots"]) & set(fb["/snapshots"])
            self.assertIn("stress", names)
            for name in sorted(names):
                for row in common:
                    x = fa["/snapshots/" + name][ra.index(row)]
                    y = fb["/snapshots/" + name][rb.index(row)]
                    self.assertEqual(np.asarray(x).tobytes(), np.asarray(y).tobytes(),
                                     "%s at step %d" % (name, row[0]))

    def test_interval_and_fields_leave_every_common_row_bit_identical(self):
        case = self.CASE()
        case["output"]["interval"] /= 2
        case["output"]["fields"] = ["position", "stress", "strain", "principal_stress"]
        other = self.finish(self.d, self.d.create(case, start=True)["id"], "interval")
        self.assertEqual(len(other["state"]["position"]), len(self.straight["state"]["position"]))
        self.assert_same_run(self.straight, other, whole_file=False)

    def wait_progress(self, d, case_id, progress):
        st = d.wait(case_id, lambda s: s["progress"] >= progress or s["state"] != "running",
                    timeout=300, what="progress %g" % progress)
        self.assertEqual(st["state"], "running", "the case ended before it could be interrupted")

    def test_pausing_twice_reaches_the_bits_of_the_straight_run(self):
        case_id = self.d.create(self.CASE(), start=True)["id"]
        for progress in (0.3, 0.7):
            self.wait_progress(self.d, case_id, progress)
            self.assertEqual(self.d.json("POST", "/cases/%s/pause" % case_id)[0], 200)
            self.d.wait_state(case_id, "paused")
            self.assertEqual(self.d.json("POST", "/cases/%s/start" % case_id)[0], 200)
        paused = self.finish(self.d, case_id, "paused")
        self.assert_same_run(self.straight, paused, whole_file=True)

    def assert_paused_state_is_in_the_file(self, d, case_id):
        """A case back from a restart, paused at its checkpoint: at a
        snapshot step its state and status are that row of result.h5."""
        st = d.status(case_id)
        self.assertEqual(st["state"], "paused")
        status, _, data = d.request("GET", "/cases/%s/result.h5" % case_id)
        self.assertEqual(status, 200)
        path = os.path.join(self.tmp, "restarted.h5")
        with open(path, "wb") as f:
            f.write(data)
        state = d.json("GET", STATE % case_id)[1]
        with h5py.File(path, "r") as f:
            s = f["/snapshots"]
            self.assertLessEqual(s["step"][-1], st["step"])
            if s["step"][-1] != st["step"]:
                return  # a wall-time checkpoint between two snapshots
            for name in ("position", "velocity", "stress", "damage"):
                if name in s:
                    self.assertEqual(np.array(state[name]).tobytes(), s[name][-1].tobytes(), name)
            for key, row in ROWS.items():
                self.assertEqual(st["energy"][key], s[row][-1], key)

    def test_sigterm_and_sigkill_restarts_on_other_thread_counts_reach_the_same_file(self):
        d = Daemon(args=["--threads", "2", "--checkpoint-every", "0.05"]).start()
        try:
            case_id = d.create(self.CASE(), start=True)["id"]
            for progress, sig, threads in ((0.3, signal.SIGTERM, "1"), (0.7, signal.SIGKILL, "2")):
                self.wait_progress(d, case_id, progress)
                code, _ = d.stop(sig)
                self.assertEqual(code, 0 if sig == signal.SIGTERM else -signal.SIGKILL, d.log_tail())
                d.args = ["--threads", threads, "--checkpoint-every", "0.05"]
                d.start()
                self.assert_paused_state_is_in_the_file(d, case_id)
                self.assertEqual(d.json("POST", "/cases/%s/start" % case_id)[0], 200)
            restarted = self.finish(d, case_id, "restarted")
            self.assertEqual(d.stop()[0], 0, d.log_tail())
        finally:
            d.close()
        self.assert_same_run(self.straight, restarted, whole_file=True)

    def test_state_status_and_file_agree_and_the_energy_closes(self):
        st, state = self.straight["status"], self.straight["state"]
        events = self.straight["events"]["events"]
        with h5py.File(self.straight["path"], "r") as f:
            s = f["/snapshots"]
            self.assertEqual(s["step"][-1], st["step"])
            self.assertEqual(state["step"], st["step"])
            for name in ("position", "velocity", "stress", "damage"):
                if name in s:
                    self.assertEqual(np.array(state[name]).tobytes(), s[name][-1].tobytes(), name)
            for key, row in ROWS.items():
                self.assertEqual(st["energy"][key], s[row][-1], key)
            self.assertEqual(st["fragments"], len(np.unique(s["fragment"][-1])))
            self.assertEqual(st["fragments"], len(self.straight["fragments"]["fragments"]))
            if "damage" in s:
                self.assertEqual(st["broken_joints"], int((s["damage"][-1] >= 1).sum()))
                self.assertEqual(len(f["/events/time"]), len(events))
            self.assertEqual(st["broken_joints"], len(events))
            e0 = s["kinetic_energy"][0] + s["elastic_energy"][0]
            residual = sum(s[row][...] for row in ROWS.values()
                           if row not in ("gravity_work", "external_work")) \
                - s["gravity_work"][...] - s["external_work"][...] - e0
        through = max(e0, st["energy"]["external_work"] + abs(st["energy"]["gravity_work"]))
        self.assertAlmostEqual(residual[-1], st["energy"]["residual"], delta=1e-12 * through)
        self.assertLess(np.abs(residual).max(), self.RESIDUAL * through, st["energy"])


class FracturingDisc3D(ObservationIndependence, DaemonTestCase):
    PREFIX = "fdemd-obs-disc-3d-"
    CASE = staticmethod(fracturing_disc)
    RESIDUAL = 0.01

    def test_the_disc_breaks(self):
        st = self.straight["status"]
        self.assertGreater(st["broken_joints"], 0)
        self.assertGreater(st["fragments"], 1)


class SlidingBoxes3D(ObservationIndependence, DaemonTestCase):
    PREFIX = "fdemd-obs-boxes-3d-"
    CASE = staticmethod(sliding_boxes)
    RESIDUAL = 1e-4

    def test_the_boxes_slide(self):
        self.assertGreater(self.straight["status"]["energy"]["friction"], 0)


if __name__ == "__main__":
    unittest.main()
