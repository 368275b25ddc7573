"""test_estimate.py - run times a user can plan with (contract 6.2, issue 33
item 5, issue 34 item 4): `estimated_seconds` against the measured run,
`eta` and `cpu_share` while running, and shortened case ids in fdemctl and the Python client.

Every bundled example is sized by a dry run and then run through the daemon,
and the wall time it took (the status' `elapsed`) must be within a factor
of 2 of the estimate: 0.5 <= measured / estimated <= 2. The full examples
run for minutes (the arc-loaded 3D disc for several), so each runs here with
an earlier end (SHORT_ENDS): chosen so that the run still goes through the
phases the whole example does (the split of a disc, a specimen's failure,
a tunnel's wall breaking after its excavation, a pile settling), and the
estimate is of that same shortened document. docs/performance.md has the
same table for the whole examples.

Two dry runs of one document agree within a factor of 1.3 (one 50 ms
sample once gave 115 s and 3,300 s). `eta` is null before a case runs, a
number that falls while it runs, and null again once it has finished.

Both are measurements of wall time, which a test must never wait on
(docs/testing.md): on a loaded machine a run's wall time swings 2-9x in
minutes. So `make test` runs them only when FDEMD_ESTIMATES=1, which
`make estimates` sets (a quiet machine, minutes: every example runs); the
rest of this file (eta's presence and fall, short ids) always runs.
"""
import json
import os
import re
import sys
import time
import unittest

from fdemd_harness import SLOW, DaemonTestCase, tiny_case

# The wall-time figures (the examples' ratio, the eta's fall against the
# clock) only on request: `make estimates`.
MEASURE = os.environ.get("FDEMD_ESTIMATES") == "1"

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
EXAMPLES = os.path.join(ROOT, "examples")
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
from fdemd_client import AmbiguousIdError, Client  # noqa: E402

# End times (s) of the shortened runs, and why each still shows what the
# whole example does; the others run whole.
SHORT_ENDS = {
    # contact from the start (platens) and the split at the peak, 0.47 ms
    "brazilian-disc": 0.0006,
    # the 3D disc's peak at 0.21 ms, joints broken after it
    "brazilian-disc-3d": 0.0003,
    # the discs fall from rest and pile up from about 0.25 s (0.8 s in all)
    "disc-pile": 0.4,
    # peak at 1.48 ms, the joint set broken through by 2.4 ms
    "jointed-block": 0.002,
    # the lower spheres reach the floor in the first 0.07 s (0.7 s)
    "sphere-pile": 0.2,
    # excavation at 2 ms; the wall breaks during the 10 ms release (40 ms
    # in all): 16 joints by 8 ms, 364 by 15.4 ms, 446 by the end
    "staged-tunnel": 0.016,
    # peak at 0.22 ms, shear failure after it (0.4 ms)
    "uniaxial-compression": 0.0003,
    # joints soften from 0.15 ms, the load falls by 0.33 ms (0.4 ms)
    "uniaxial-prism-3d": 0.0003,
}

# Examples not run here, and why. None since the estimate prices the
# phase after fracture (issue 34 item 4): the three whose fracture comes
# late run whole, minutes each on a busy machine (tunnel-region breaks in
# the last fifth of its run, drift-3d from 3.5 ms of 8, the arc-loaded 3D
# disc at a third of its run).
NOT_RUN = {}

# The examples run under the sanitizers: contact between bodies, a 2D and
# a 3D fracturing specimen, an elastic gmsh model.
SAN_EXAMPLES = ("collision", "incline", "tunnel", "brazilian-disc", "brazilian-disc-3d")


def example_names():
    return sorted(f[:-5] for f in os.listdir(EXAMPLES) if f.endswith(".json"))


def shortened(name):
    with open(os.path.join(EXAMPLES, name + ".json")) as f:
        doc = json.load(f)
    end = SHORT_ENDS.get(name)
    if end is not None:
        doc["time"]["end"] = end
        stages = doc.get("stages")
        if stages:
            stages[-1]["end"] = end
    return doc


class EstimateTest(DaemonTestCase):
    """One daemon, one case at a time: a run is timed alone."""

    DAEMON_ARGS = ("--max-running", "1")

    def url(self):
        return "http://127.0.0.1:%d" % self.d.port

    def setUp(self):
        self.client = Client(self.url())

    def test_every_example_within_a_factor_of_2(self):
        if not MEASURE:
            self.skipTest("a wall-time measurement: make estimates (FDEMD_ESTIMATES=1)")
        names = [n for n in example_names() if (SLOW == 1.0 or n in SAN_EXAMPLES)
                 and n not in NOT_RUN]
        rows, bad = [], []
        # A fresh daemon knows its disk from one fsynced write at start-up
        # (docs/api.md, Dry run); a first run whose pace its 41 snapshots
        # set lets it time real ones, as any daemon that has run a case has.
        warm = tiny_case("disk", end=0.0005, interval=0.0005 / 40)
        self.client.wait(self.client.submit(warm, start=True), interval=0.05,
                         timeout=60 * SLOW)
        for name in names:
            doc = shortened(name)
            first = self.client.dry_run(doc)
            second = self.client.dry_run(doc)
            estimates = (first["estimated_seconds"], second["estimated_seconds"])
            spread = max(estimates) / min(estimates)
            case_id = self.client.submit(doc, start=True)
            final = self.client.wait(case_id, interval=0.1, timeout=600 * SLOW)
            self.assertEqual(final["state"], "finished", name)
            measured = final["elapsed"]
            ratio = measured / second["estimated_seconds"]
            rows.append("%-28s estimate %8.2f s, %8.2f s again (x%.2f); measured %8.2f s, "
                        "ratio %.2f" % (name, estimates[0], estimates[1], spread, measured,
                                        ratio))
            print(rows[-1], file=sys.stderr, flush=True)
            if not 0.5 <= ratio <= 2.0:
                bad.append("%s: measured/estimated %.2f" % (name, ratio))
            if spread > 1.3:
                bad.append("%s: two dry runs differ by x%.2f" % (name, spread))
            if spread > 1.3 or not 0.5 <= ratio <= 2.0:  # what each was made of
                for r in (first, second):
                    print("    %s" % json.dumps(r["estimate"], sort_keys=True), file=sys.stderr)
            self.client.delete(case_id)
        self.assertEqual(bad, [])

    def fracturing_band(self, name, velocity):
        """tiny_case() with joints only in a band two cells high around
        y = 0.05 (a fluid-driven crack's region): 48 joints, 10 of them on
        the line y = 0.05, 2 on the vertical x = 0.05 (kgd's layout)."""
        case = tiny_case(name, end=0.004)
        case["materials"]["rock"]["fracture"] = {
            "tensile_strength": 2e6, "cohesion": 6e6, "friction_angle": 30,
            "energy_I": 50, "energy_II": 250}
        case["parts"][0]["fracture"] = {"box": [-1, 0.04, 1, 0.06]}
        case["parts"][0]["velocity"] = velocity
        return case

    def test_dry_run_prices_breaks_on_the_joints_plane_and_repeats(self):
        # at rest: nothing breaks in the probe's own steps, so the share
        # (docs/api.md, Dry run): 3 % of the joints break, each with its
        # mending of the contact list, half that held broken on average
        first = self.client.dry_run(self.fracturing_band("band", [0, 0]))
        second = self.client.dry_run(self.fracturing_band("band", [0, 0]))
        self.assertEqual(first["joints"], 48)
        for r in (first, second):
            e = r["estimate"]
            # the crack runs along the band (y: 10 joints), not across it
            # (x: 2), and is the half of them nearest the joints' centre
            self.assertEqual(e["cracked_joints"], 5, e)
            self.assertEqual(e["broken_seen"], 0, e)
            self.assertAlmostEqual(e["breaks"], 0.03 * 48, places=9)
            self.assertAlmostEqual(e["broken_joints"], 0.5 * 0.03 * 48, places=9)
            self.assertGreater(e["break_detection_seconds"], 0, e)
        # that a repeated dry run gives the same figure within the stated
        # band is a wall-time figure, checked by make estimates on every
        # example: here, where the sanitizers and a busy CI machine move
        # each timing window, it failed at 1.57x (the priced counts above
        # are what stays the same)
        # crushed against its base from the first step: the joints its own
        # steps broke, at that rate, set how many break (more than the
        # share's 1.44), at most all
        crushed = self.client.dry_run(self.fracturing_band("crushed", [0, -1]))
        e = crushed["estimate"]
        self.assertGreater(e["broken_seen"], 0, e)
        self.assertGreaterEqual(e["breaks"], max(e["broken_seen"], 0.03 * 48), e)
        self.assertLessEqual(e["breaks"], crushed["joints"], e)
        self.assertAlmostEqual(e["broken_joints"], 0.5 * e["breaks"], places=9)

    def test_status_keeps_the_estimate(self):
        case_id = self.client.submit(tiny_case("estimated", end=0.002))
        status = self.client.status(case_id)
        self.assertGreater(status["estimated_seconds"], 0)
        self.assertIsNone(status["eta"])
        self.assertIsNone(status["cpu_share"])
        # a restart reads it back from status.json
        self.assertEqual(self.d.stop()[0], 0)
        self.d.start()
        again = Client(self.url()).status(case_id)
        self.assertEqual(again["estimated_seconds"], status["estimated_seconds"])

    def test_eta_and_cpu_share_while_running_null_after(self):
        case = self.d.case_lasting(4.0 * SLOW, name="eta")
        case_id = self.client.submit(case, start=True)
        etas, shares = [], []
        deadline = time.monotonic() + 60 * SLOW
        while time.monotonic() < deadline:
            s = self.client.status(case_id)
            if s["state"] != "running":
                break
            if s["eta"] is not None:
                etas.append((time.monotonic(), s["eta"], s["progress"]))
            if s["cpu_share"] is not None:
                shares.append(s["cpu_share"])
            time.sleep(0.25)
        self.assertGreaterEqual(len(etas), 5, etas)
        self.assertTrue(all(e >= 0 for _, e, _ in etas), etas)
        self.assertLess(etas[-1][1], etas[0][1], etas)
        # it says how long is left: the wall time between two samples is
        # about what the eta fell by (within a factor of 2), on a machine
        # whose load does not swing during the run: make estimates
        if MEASURE:
            fell = etas[0][1] - etas[-1][1]
            waited = etas[-1][0] - etas[0][0]
            self.assertGreater(fell, 0.5 * waited, etas)
            self.assertLess(fell, 2.0 * waited, etas)
        final = self.client.wait(case_id, interval=0.1, timeout=60 * SLOW)
        self.assertEqual(final["state"], "finished")
        self.assertIsNone(final["eta"])
        # the stepping thread's CPU a wall second: a share of one core
        # (the clocks are read a few instructions apart: 1 % of slack)
        self.assertGreater(len(shares), 0)
        self.assertTrue(all(0 < x <= 1.01 for x in shares), shares)
        self.assertIsNone(final["cpu_share"])


class ShortIdTest(DaemonTestCase):
    """fdemctl and the Python client take a unique prefix of an id."""

    def url(self):
        return "http://127.0.0.1:%d" % self.d.port

    def setUp(self):
        self.client = Client(self.url())

    def two_sharing_a_first_digit(self):
        """Creates cases until two ids share their first digit (hex ids: at
        most 17); returns them."""
        seen = {}
        for k in range(17):
            case_id = self.client.submit(tiny_case("prefix-%d" % k))
            if case_id[0] in seen:
                return seen[case_id[0]], case_id
            seen[case_id[0]] = case_id
        self.fail("17 hex ids without a shared first digit")

    def unique_prefix(self, case_id):
        ids = [c["id"] for c in self.client.list()]
        for n in range(1, len(case_id) + 1):
            if sum(i.startswith(case_id[:n]) for i in ids) == 1:
                return case_id[:n]
        return case_id

    def test_fdemctl_unique_ambiguous_and_unknown_prefix(self):
        a, b = self.two_sharing_a_first_digit()
        prefix = self.unique_prefix(b)
        self.assertLess(len(prefix), len(b))
        r = self.d.fdemctl("status", prefix)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertRegex(r.stdout, r"(?m)^id\s+%s$" % re.escape(b))
        r = self.d.fdemctl("start", prefix)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.split(), [b, "running"])
        r = self.d.fdemctl("status", a[0])                 # shared by a and b
        self.assertEqual(r.returncode, 2)
        self.assertIn("ambiguous", r.stderr)
        self.assertIn(a, r.stderr)
        self.assertIn(b, r.stderr)
        self.assertEqual(r.stdout, "")
        r = self.d.fdemctl("delete", a[0])                 # nothing deleted
        self.assertEqual(r.returncode, 2)
        self.assertIn(a, [c["id"] for c in self.client.list()])
        r = self.d.fdemctl("status", "xyz")                # no id has it: the server's 404
        self.assertEqual(r.returncode, 1)
        self.assertIn("404", r.stderr)
        r = self.d.fdemctl("status", "")
        self.assertEqual(r.returncode, 2)

    def test_python_client_resolves_a_prefix(self):
        a, b = self.two_sharing_a_first_digit()
        self.assertEqual(self.client.resolve_id(self.unique_prefix(a)), a)
        self.assertEqual(self.client.resolve_id(a), a)
        with self.assertRaises(AmbiguousIdError) as e:
            self.client.resolve_id(a[0])
        self.assertIn(a, e.exception.matches)
        self.assertIn(b, e.exception.matches)
        self.assertEqual(self.client.resolve_id("xyz"), "xyz")
        with self.assertRaises(ValueError):
            self.client.resolve_id("")

    def test_fdemctl_list_shows_cpu_speed_and_eta(self):
        case_id = self.client.submit(self.d.case_lasting(3.0 * SLOW, name="listed"), start=True)
        deadline = time.monotonic() + 30 * SLOW
        row = None
        while time.monotonic() < deadline:
            r = self.d.fdemctl("list")
            self.assertEqual(r.returncode, 0, r.stderr)
            header = r.stdout.splitlines()[0].split()
            self.assertEqual(header[-3:], ["CPU", "STEPS/S", "ETA"])
            rows = [line.split() for line in r.stdout.splitlines()[1:]]
            row = next(x for x in rows if x[0] == case_id)
            if row[-1] != "-":
                break
            time.sleep(0.2)
        self.assertRegex(row[-1], r"^\d+s$|^\d+m\d\ds$")
        self.assertGreater(float(row[-2]), 0)
        self.assertRegex(row[-3], r"^\d+%$")
        self.client.stop(case_id)


if __name__ == "__main__":
    unittest.main()
