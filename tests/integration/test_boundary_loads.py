"""The rock-engineering load examples run through the daemon as a user runs
them (contract 5.3): submitted over HTTP, stepped to the end, result.h5
downloaded and read with h5py, each against its closed form:

- wave-absorb.json: a plane P pulse leaves through a Lysmer end with less
  than 5 % of its energy left in the bar; without the absorbing
  constraint more than 80 % stays (a free end reflects it all);
- slope-gravity-ramp.json: under gravity ramped over eleven periods the
  slope ends with a kinetic energy below 10^-3 of its elastic energy,
  where the same gravity switched on at once swings through the static
  state with about the static elastic energy as kinetic energy (one mode:
  exactly it)."""
import copy
import json
import os

import h5py
import numpy as np

from fdemd_harness import ROOT, SLOW, DaemonTestCase


def example(name):
    with open(os.path.join(ROOT, "examples", name + ".json")) as f:
        return json.load(f)


class BoundaryLoadExamples(DaemonTestCase):
    PREFIX = "fdemd-loads-"

    def run_case(self, case):
        st = self.d.create(case, start=True)
        final = self.d.wait_state(st["id"], ("finished", "failed", "stopped"), timeout=240 * SLOW)
        self.assertEqual(final["state"], "finished", final.get("error"))
        self.dt = final["dt"]
        status, _, data = self.d.request("GET", "/cases/%s/result.h5" % st["id"])
        self.assertEqual(status, 200)
        path = os.path.join(self.tmp, st["id"] + ".h5")
        with open(path, "wb") as f:
            f.write(data)
        with h5py.File(path, "r") as f:
            return {k: f["/snapshots/" + k][...] for k in
                    ("time", "kinetic_energy", "elastic_energy", "external_work",
                     "damping_energy", "gravity_work", "constraint_force")}

    def test_pulse_leaves_through_the_absorbing_end(self):
        case = example("wave-absorb")
        s = self.run_case(case)
        left = (s["kinetic_energy"][-1] + s["elastic_energy"][-1]) / s["external_work"][-1]
        print("wave-absorb: %.4g J/m in, %.3g %% left, dashpots took %.4g J/m"
              % (s["external_work"][-1], 100 * left, s["damping_energy"][-1]), flush=True)
        self.assertLess(left, 0.05)
        self.assertGreater(s["damping_energy"][-1], 0.95 * s["external_work"][-1])
        # the pressure's applied force is reported: 1 MPa x 0.1 m along +x
        # times the amplitude at the start of the step the snapshot ends
        table = np.array(case["constraints"][1]["amplitude"])
        t_n = s["time"][1:-1] - self.dt
        want = 1e5 * np.interp(t_n, table[:, 0], table[:, 1])
        got = s["constraint_force"][1:-1, 1, 0]
        self.assertTrue(np.allclose(got, want, rtol=0, atol=1e-6 * 1e5), np.abs(got - want).max())
        self.assertTrue(np.allclose(s["constraint_force"][:, 1, 1], 0, atol=1e-9))
        free = copy.deepcopy(case)
        free["constraints"].pop()
        free["name"] += "-free"
        s = self.run_case(free)
        left = (s["kinetic_energy"][-1] + s["elastic_energy"][-1]) / s["external_work"][-1]
        self.assertGreater(left, 0.80)

    def test_slope_settles_under_ramped_gravity(self):
        case = example("slope-gravity-ramp")
        ramp_end = case["gravity_amplitude"][-1][0]
        s = self.run_case(case)
        after = s["time"] > ramp_end
        static = s["elastic_energy"][-1]
        kinetic = s["kinetic_energy"][after].max()
        print("slope: elastic %.5g J/m, largest kinetic after the ramp %.3g J/m"
              % (static, kinetic), flush=True)
        self.assertLess(kinetic, 1e-3 * static)
        self.assertAlmostEqual(s["gravity_work"][-1] / static, 1.0, delta=0.01)
        at_once = copy.deepcopy(case)
        del at_once["gravity_amplitude"]
        at_once["name"] += "-at-once"
        s = self.run_case(at_once)
        self.assertGreater(s["kinetic_energy"].max(), 0.5 * static)
