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
  exactly it).

And contract 6.1's "boundary_stress" and "traction" (BoundaryStressTest),
2D and 3D:

- a column whose K0 in-situ stress grows with depth as gravity asks, held
  by nothing but the matching boundary_stress, stays at rest (kinetic
  below 1e-6 of the stored energy, stresses within 1 %);
- a block on rollers loaded by a boundary_stress and a traction, both
  ramped by an amplitude, reports a(t_n) sigma . n A and a(t_n) t A on the
  faces' current areas (1e-5) and ends holding the field (1 %);
- bad input is one 422 with a problem at each pointer at fault."""
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


# ---------------------------------------------------------------- 6.1
# "boundary_stress" and "traction" (contract 6.1) through the daemon.

RHO, YOUNG, NU, GRAVITY = 2600.0, 2e10, 0.25, 9.81


def column_case(dimension):
    """A column 1 x 2 m (3D 1 x 1 x 2 m) under gravity whose elements hold
    a K0 in-situ stress growing with depth as gravity asks (div sigma +
    rho g = 0) and some uniform shear, held by nothing but the matching
    "boundary_stress" on its whole outline: it must stay at rest."""
    rg = RHO * GRAVITY
    if dimension == 2:
        value, gradient = [-1e6, -2e6, 0.3e6], [0.5 * rg, rg, 0]
        shape = {"rectangle": {"origin": [0, 0], "size": [1, 2], "divisions": [4, 8]}}
        gravity = [0, -GRAVITY]
    else:
        value = [-1e6, -1.5e6, -2e6, 0.3e6, -0.2e6, 0.1e6]
        gradient = [0.5 * rg, 0.8 * rg, rg, 0, 0, 0]
        shape = {"box": {"origin": [0, 0, 0], "size": [1, 1, 2], "divisions": [3, 3, 6]}}
        gravity = [0, 0, -GRAVITY]
    field = {"value": value, "gradient": gradient, "reference": 2}
    part = {"name": "column", "material": "rock", "initial_stress": field}
    part.update(shape)
    return {
        "name": "column-at-rest-%dd" % dimension,
        "dimension": dimension,
        "materials": {"rock": {"density": RHO, "young": YOUNG, "poisson": NU}},
        "parts": [part],
        "constraints": [{"part": "column", "boundary_stress": field}],
        "gravity": gravity,
        "time": {"end": 0.004},
        "output": {"interval": 0.0005, "fields": ["position", "stress"]},
    }


def ramp_table(T, points=21):
    """(1 - cos)/2 from 0 to 1 over T: starts and ends without a kink."""
    return [[T * k / (points - 1), 0.5 * (1 - np.cos(np.pi * k / (points - 1)))]
            for k in range(points)]


def ramped_block_case(dimension):
    """A 1 m block on rollers at x = 0, y = 0 (3D also z = 0), loaded on its
    far x face by the "boundary_stress" of a K0 field and on its top by the
    "traction" the same field puts there, both ramped smoothly over ten
    periods: afterwards every element holds the field (uniform: the
    gradient is zero, so the rollers need carry nothing tangential)."""
    T = 0.01
    if dimension == 2:
        field = [-4e6, -10e6, 0]
        shape = {"rectangle": {"origin": [0, 0], "size": [1, 1], "divisions": [6, 6]}}
        rollers = [{"box": [-1, -1, 1e-6, 2], "fix": ["x"]}, {"box": [-1, -1, 2, 1e-6], "fix": ["y"]}]
        far = [1 - 1e-6, -1, 2, 2]
        top, traction = [-1, 1 - 1e-6, 2, 2], [0, -10e6]
    else:
        field = [-4e6, -6e6, -10e6, 0, 0, 0]
        shape = {"box": {"origin": [0, 0, 0], "size": [1, 1, 1], "divisions": [4, 4, 4]}}
        rollers = [{"box": [-1, -1, -1, 1e-6, 2, 2], "fix": ["x"]},
                   {"box": [-1, -1, -1, 2, 1e-6, 2], "fix": ["y"]},
                   {"box": [-1, -1, -1, 2, 2, 1e-6], "fix": ["z"]},
                   {"box": [-1, 1 - 1e-6, -1, 2, 2, 2], "pressure": 6e6, "amplitude": ramp_table(T)}]
        far = [1 - 1e-6, -1, -1, 2, 2, 2]
        top, traction = [-1, -1, 1 - 1e-6, 2, 2, 2], [0, 0, -10e6]
    part = {"name": "block", "material": "rock"}
    part.update(shape)
    constraints = rollers + [
        {"box": far, "boundary_stress": {"value": field}, "amplitude": ramp_table(T)},
        {"box": top, "traction": traction, "amplitude": ramp_table(T)}]
    return {
        "name": "ramped-boundary-stress-%dd" % dimension,
        "dimension": dimension,
        "materials": {"rock": {"density": RHO, "young": YOUNG, "poisson": NU, "damping": 0.05}},
        "parts": [part],
        "constraints": constraints,
        "time": {"end": 0.016},
        "output": {"interval": 0.001, "fields": ["position", "stress"]},
    }, field, T


def face_area(x, x0, axis):
    """Current area (2D: length) of the unit block's face at x0[axis] = 1,
    per snapshot of the positions x (S, N, D): the chord between its end
    nodes in 2D, the shoelace of its outline in the other two axes in 3D
    (the normal component of its area vector; the face stays flat to
    second order, which is all its area differs by)."""
    on = np.abs(x0[:, axis] - 1) < 1e-9
    other = [d for d in range(x0.shape[1]) if d != axis]
    if len(other) == 1:
        ends = np.flatnonzero(on)[np.argsort(x0[on, other[0]])[[0, -1]]]
        return np.abs(x[:, ends[1], other[0]] - x[:, ends[0], other[0]])
    u, v = x0[:, other[0]], x0[:, other[1]]
    edge = on & ((np.abs(u) < 1e-9) | (np.abs(u - 1) < 1e-9) | (np.abs(v) < 1e-9) |
                 (np.abs(v - 1) < 1e-9))
    loop = np.flatnonzero(edge)
    loop = loop[np.argsort(np.arctan2(v[loop] - 0.5, u[loop] - 0.5))]
    xu, xv = x[:, loop, other[0]], x[:, loop, other[1]]
    return 0.5 * np.abs((xu * np.roll(xv, -1, axis=1) - np.roll(xu, -1, axis=1) * xv).sum(axis=1))


class BoundaryStressTest(DaemonTestCase):
    PREFIX = "fdemd-bstress-"

    def test_column_held_by_boundary_stress_stays_at_rest(self):
        for dimension in (2, 3):
            st, path = self.run_case(column_case(dimension), timeout=120 * SLOW)
            with h5py.File(path, "r") as f:
                s = f["/snapshots/stress"][...]
                kinetic = f["/snapshots/kinetic_energy"][...]
                elastic = f["/snapshots/elastic_energy"][...]
            change = (np.abs(s - s[0]).max(axis=2) / np.abs(s[0]).max(axis=1)).max()
            print("%dD column: kinetic/stored at most %.3g, stress change %.3g %%"
                  % (dimension, (kinetic / elastic).max(), 100 * change), flush=True)
            self.assertGreaterEqual(len(kinetic), 8)
            self.assertLess((kinetic / elastic).max(), 1e-6)
            self.assertLess(change, 0.01)
            self.assertLess(abs(st["energy"]["residual"]), 1e-6 * st["energy"]["elastic"])

    def test_ramped_boundary_stress_and_traction_load_a_block(self):
        for dimension in (2, 3):
            case, field, T = ramped_block_case(dimension)
            st, path = self.run_case(case, timeout=180 * SLOW)
            dt = st["dt"]
            with h5py.File(path, "r") as f:
                time = f["/snapshots/time"][...]
                s = f["/snapshots/stress"][...]
                force = f["/snapshots/constraint_force"][...]
                x, x0 = f["/snapshots/position"][...], f["/mesh/position0"][...]
            # the applied force is a(t_n) sigma . n A on the far face and
            # a(t_n) t A on the top, t_n the start of the snapshot's last
            # step and A the face's current area (from the snapshot's
            # positions, a step later: 1e-6 off at most)
            table = np.array(ramp_table(T))
            a = np.interp(time[1:] - dt, table[:, 0], table[:, 1])
            k = len(case["constraints"]) - 2
            area_far = face_area(x[1:], x0, 0)
            area_top = face_area(x[1:], x0, dimension - 1)
            want_far = np.outer(a * area_far, [field[0]] + [0] * (dimension - 1))
            want_top = np.outer(a * area_top, case["constraints"][-1]["traction"])
            off = []
            for got, want in ((force[1:, k], want_far), (force[1:, k + 1], want_top)):
                off.append(np.abs(got - want).max() / np.abs(want).max())
                self.assertLess(off[-1], 1e-5, (got, want))
            print("%dD ramped block: faces shrank to %.6f and %.6f m%s; applied forces off "
                  "a(t_n) sigma.n A by %.2g and %.2g" % (dimension, area_far[-1], area_top[-1],
                                                         "^2" if dimension == 3 else "", *off),
                  flush=True)
            # after the ramp every element holds the field
            worst = np.abs(s[-1] - np.array(field)).max() / np.abs(field).max()
            print("%dD ramped block: stress off the field by %.3g %% of its largest component"
                  % (dimension, 100 * worst), flush=True)
            self.assertLess(worst, 0.01)
            energy = st["energy"]
            self.assertLess(abs(energy["residual"]), 1e-3 * energy["external_work"])

    def post_problem(self, case):
        status, headers, data = self.d.request("POST", "/cases", case,
                                               {"Content-Type": "application/json"})
        self.assertEqual(status, 422, data[:300])
        self.assertEqual(headers.get("content-type"), "application/problem+json")
        return json.loads(data)

    def assertPointers(self, constraints, pointers, words=(), dimension=2):
        """A case (column_case without its constraints, plus these) is
        refused with 422 and a problem at each pointer (exactly these)."""
        case = column_case(dimension)
        case["constraints"] = constraints
        problem = self.post_problem(case)
        got = sorted(e["pointer"] for e in problem["errors"])
        self.assertEqual(got, sorted(pointers), json.dumps(problem)[:600])
        text = json.dumps(problem).lower()
        for word in words:
            self.assertIn(word.lower(), text)

    def test_bad_boundary_stress_and_traction(self):
        on = {"part": "column"}

        def c(**action):
            return dict(on, **action)
        at = "/constraints/0/boundary_stress"
        self.assertPointers([c(boundary_stress={"value": [1, 2]})], [at + "/value"],
                            ["[sxx, syy, sxy]"])
        self.assertPointers([c(boundary_stress={"value": [0, 0, 0]})], [at + "/value"],
                            ["[sxx, syy, szz, syz, sxz, sxy]"], dimension=3)
        self.assertPointers([c(boundary_stress={"value": [0, "x", 0]})], [at + "/value/1"])
        self.assertPointers([c(boundary_stress={"value": [0, 0, 0], "gradient": [0, 1, 0]})],
                            [at + "/gradient"], ["reference"])
        self.assertPointers([c(boundary_stress={"value": [0, 0, 0], "gradiant": [0, 1, 0]})],
                            [at + "/gradiant"], ["gradient"])
        self.assertPointers([c(boundary_stress={"gradient": [0, 1, 0], "reference": 0})], [at],
                            ["value"])
        self.assertPointers([c(boundary_stress=[0, 0, 0])], [at], ["object"])
        self.assertPointers([c(boundary_stress={"value": [0, 0, 0], "gradient": [0, 1e300, 0],
                                                "reference": -1e10})],
                            [at + "/gradient"], ["syy", "lowest"])
        self.assertPointers([c(boundary_stress={"value": [0, 0, 0]}, pressure=1e6)],
                            ["/constraints/0"], ["exactly one"])
        self.assertPointers([c(traction=[1e6])], ["/constraints/0/traction"])
        self.assertPointers([c(traction=[1e6, 0, 0])], ["/constraints/0/traction"],
                            ["dimension"])
        self.assertPointers([c(traction="up")], ["/constraints/0/traction"])
        self.assertPointers([c(traction=[0, 1e6], fix=["x"])], ["/constraints/0"],
                            ["exactly one"])
        self.assertPointers([c(traction=[0, 1e6], amplitude=[[1, 0], [0, 1]])],
                            ["/constraints/0/amplitude/1/0"])
        # one interior node selects no boundary edge
        self.assertPointers([{"box": [0.49, 0.99, 0.51, 1.01], "boundary_stress": {"value": [0, 0, 0]}}],
                            ["/constraints/0"], ["boundary edge", "boundary stress"])
        # every problem in one answer
        self.assertPointers([c(boundary_stress={"value": [1, 2]}), c(traction=[1, "y"]),
                             c(boundary_stress={"value": [0, 0, 0], "gradient": [0, 0, 0, 0, 0, 0],
                                                "reference": 0}, amplitude=[[0, 1]])],
                            [at + "/value", "/constraints/1/traction/1", "/constraints/2/boundary_stress/gradient"],
                            dimension=2)
