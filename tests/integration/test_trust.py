"""Numbers a user can trust, through the real daemon (contract 5.1):

- output never changes the physics: the same case with two output intervals
  (one that divides no step) and different fields ends in the same step with
  bit-identical positions and velocities, and every snapshot sits at the
  first step boundary at or after its output time;
- an undamped cantilever at time.safety 1 whose output interval is not a
  whole number of steps stays bounded for several periods (it used to go
  non-finite within 81 steps);
- the status and result.h5 carry every energy account, and the residual of
  a collision is under 1 % of the energy in play;
- a time.end below one step, and a density so high that the stable step
  exceeds time.end, end exactly at time.end with a snapshot there.
"""
import time

import h5py
import numpy as np

from fdemd_harness import DaemonTestCase, tiny_case

ACCOUNTS = ("kinetic", "elastic", "joint", "contact", "friction", "fracture", "damping",
            "gravity_work", "external_work", "residual")
SERIES = ("contact_energy", "friction_energy", "joint_energy", "fracture_energy",
          "damping_energy", "gravity_work", "external_work")


def collision_case(interval, fields):
    """Two blocks meeting at 3 m/s with friction: contact, stick springs."""
    return {
        "name": "two-blocks",
        "materials": {"rock": {"density": 2700, "young": 1e9, "poisson": 0.25, "friction": 0.4}},
        "parts": [
            {"name": "a", "material": "rock", "velocity": [2.0, 0.3],
             "rectangle": {"origin": [0, 0], "size": [0.1, 0.05], "divisions": [8, 4]}},
            {"name": "b", "material": "rock", "velocity": [-1.0, 0],
             "rectangle": {"origin": [0.1002, 0.01], "size": [0.06, 0.05], "divisions": [5, 4]}},
        ],
        "time": {"end": 0.003, "safety": 0.5},
        "output": {"interval": interval, "fields": fields},
    }


class TrustworthyNumbers(DaemonTestCase):
    PREFIX = "fdemd-trust-"

    def test_output_interval_and_fields_leave_the_state_bit_identical(self):
        st1, p1 = self.run_case(collision_case(1e-4, ["position", "velocity"]))
        st2, p2 = self.run_case(collision_case(0.37e-4, ["position", "velocity", "stress"]))
        self.assertEqual(st1["step"], st2["step"])
        self.assertEqual(st1["time"], st2["time"])
        self.assertEqual(st1["dt"], st2["dt"])
        with h5py.File(p1, "r") as f1, h5py.File(p2, "r") as f2:
            for name in ("position", "velocity"):
                a, b = f1["/snapshots/" + name][-1], f2["/snapshots/" + name][-1]
                self.assertTrue(np.array_equal(a, b), "final %s differs" % name)
            self.assertEqual(f1["/snapshots/step"][-1], f2["/snapshots/step"][-1])
            # every snapshot: the first step at or after k * interval, at its real time
            dt = st2["dt"]
            times, steps = f2["/snapshots/time"][...], f2["/snapshots/step"][...]
            for k in range(1, len(times) - 1):
                due = k * 0.37e-4
                self.assertGreaterEqual(times[k], due - 1e-9 * dt)
                self.assertLess(times[k], due + dt * (1 + 1e-9), (k, times[k], due))
                self.assertAlmostEqual(times[k], steps[k] * dt, delta=1e-6 * dt * steps[k])
            self.assertAlmostEqual(times[-1], 0.003, delta=1e-12)
            # the same step in both files holds the same bits
            s1 = list(f1["/snapshots/step"][...])
            common = [s for s in s1 if s in set(steps)]
            self.assertGreaterEqual(len(common), 2)
            for s in common:
                i, j = s1.index(s), list(steps).index(s)
                self.assertTrue(np.array_equal(f1["/snapshots/position"][i],
                                               f2["/snapshots/position"][j]), s)

    def test_undamped_cantilever_with_a_non_dividing_interval_stays_bounded(self):
        case = {
            "name": "cantilever",
            "materials": {"steel": {"density": 7800, "young": 2e11, "poisson": 0.0}},
            "parts": [{"name": "beam", "material": "steel",
                       "rectangle": {"origin": [0, 0], "size": [0.5, 0.05], "divisions": [10, 2]}}],
            "constraints": [{"box": [-0.001, -1, 0.001, 1], "fix": ["x", "y"]}],
            "gravity": [0, -9.81],
            "time": {"end": 0.03, "safety": 1.0},
            "output": {"fields": ["position"]},
        }
        probe = self.d.create(case)
        dt = probe["dt"]
        self.d.request("DELETE", "/cases/" + probe["id"])
        # a snapshot every 1.5 steps at the stable step itself: the old
        # worker cut every other step to half, and the alternating steps
        # blew this beam up within 81 steps
        case["output"]["interval"] = 1.5 * dt
        # ~3100 snapshots, each made durable (fsynced) before the next: the
        # pace is the disk's, 7-21 s alone and over 60 s on a busy machine
        st, path = self.run_case(case, timeout=240)
        with h5py.File(path, "r") as f:
            pos = f["/snapshots/position"][...]
            time = f["/snapshots/time"][...]
            tip = np.argmax(f["/mesh/position0"][:, 0] + f["/mesh/position0"][:, 1])
            y = pos[:, tip, 1] - pos[0, tip, 1]
            kin = f["/snapshots/kinetic_energy"][...]
        self.assertTrue(np.all(np.isfinite(y)))
        first, last = time < 0.01, time > 0.02
        # undamped, several periods: the swing neither grows nor dies
        amp_first = y[first].max() - y[first].min()
        amp_last = y[last].max() - y[last].min()
        self.assertLess(amp_last, 1.05 * amp_first, (amp_first, amp_last))
        self.assertGreater(amp_last, 0.9 * amp_first, (amp_first, amp_last))
        self.assertLess(kin.max(), 1.05 * kin[first].max())
        self.assertLess(abs(st["energy"]["residual"]), 0.01 * abs(st["energy"]["gravity_work"]),
                        st["energy"])

    def test_every_energy_account_in_the_status_and_the_file(self):
        st, path = self.run_case(collision_case(1e-4, ["position"]))
        energy = st["energy"]
        for key in ACCOUNTS:
            self.assertIn(key, energy)
        self.assertGreaterEqual(energy["friction"], 0)
        self.assertGreater(energy["friction"], 0, "blocks with friction slid without it")
        e0 = 0.5 * 2700 * (0.1 * 0.05 * (2.0 ** 2 + 0.3 ** 2) + 0.06 * 0.05 * 1.0)
        self.assertLess(abs(energy["residual"]), 0.01 * e0, energy)
        with h5py.File(path, "r") as f:
            s = len(f["/snapshots/time"])
            for name in SERIES:
                self.assertEqual(f["/snapshots/" + name].shape, (s,), name)
            # the last row is the status' figures
            self.assertAlmostEqual(f["/snapshots/friction_energy"][-1], energy["friction"],
                                   delta=1e-9 * e0)
            self.assertAlmostEqual(f["/snapshots/contact_energy"][-1], energy["contact"],
                                   delta=1e-9 * e0)
            self.assertTrue(np.all(np.diff(f["/snapshots/friction_energy"][...]) >= 0))

    def test_end_below_one_step_and_huge_density_end_at_time_end(self):
        base = tiny_case("short")
        st = self.d.create(base)
        dt = st["dt"]
        self.d.request("DELETE", "/cases/" + st["id"])
        short = tiny_case("short", end=0.3 * dt, interval=0.1 * dt)
        st, path = self.run_case(short)
        self.assertEqual(st["step"], 1)
        self.assertEqual(st["time"], 0.3 * dt)
        heavy = tiny_case("heavy", end=1e-3)
        heavy["materials"]["rock"]["density"] = 1e300
        st, path = self.run_case(heavy)
        self.assertAlmostEqual(st["time"], 1e-3, delta=1e-15)
        with h5py.File(path, "r") as f:
            self.assertAlmostEqual(f["/snapshots/time"][-1], 1e-3, delta=1e-15)
            self.assertTrue(np.all(np.isfinite(f["/snapshots/position"][...])))


class PauseAndRestart(DaemonTestCase):
    """A pause frees the case's model (--max-memory): the run goes on from
    the checkpoint, and must reach the bits of a run that never paused."""
    PREFIX = "fdemd-trust-pause-"

    def final_state(self, case_id):
        status, body = self.d.json("GET", "/cases/%s/state?fields=position,velocity" % case_id)
        self.assertEqual(status, 200, body)
        return body

    def test_pause_and_resume_reach_the_bits_of_an_uninterrupted_run(self):
        case = self.d.case_lasting(4.0, name="paused")
        case["materials"]["rock"]["friction"] = 0.4
        case["parts"][0]["velocity"] = [0.5, -1]
        straight = self.d.create(case, start=True)
        straight = self.d.wait_state(straight["id"], "finished", timeout=60)
        paused = self.d.create(case, start=True)
        pauses = 0
        for _ in range(2):
            time.sleep(0.3)
            status, body = self.d.json("POST", "/cases/%s/pause" % paused["id"])
            self.assertIn(status, (200, 409), body)  # 409: it had finished
            st = self.d.wait_state(paused["id"], ("paused", "finished"))
            if st["state"] == "finished":
                break
            pauses += 1
            status, body = self.d.json("POST", "/cases/%s/start" % paused["id"])
            self.assertEqual(status, 200, body)
        paused = self.d.wait_state(paused["id"], "finished", timeout=60)
        self.assertGreaterEqual(pauses, 1, "finished before it could be paused")
        self.assertEqual(straight["step"], paused["step"])
        a, b = self.final_state(straight["id"]), self.final_state(paused["id"])
        self.assertEqual(a["step"], b["step"])
        self.assertEqual(a["position"], b["position"])
        self.assertEqual(a["velocity"], b["velocity"])
        self.assertEqual(straight["energy"], paused["energy"])
