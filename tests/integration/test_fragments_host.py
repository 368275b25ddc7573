"""test_fragments_host.py - fragments a user can use (issue 33 item 6)
through the daemon, fdemctl and the Python client, and principal stresses
named for a rock mechanic.

A rock fall in miniature: a fixed slope slab and two blocks resting apart
above it, each part one fragment of known area. GET /cases/ID/fragments
with ?exclude_host=true leaves out the slab (held by its fix constraint)
and the sieve curve then runs over the blocks alone, at their mass
fractions by hand (1/3, then 1); ?parts= keeps the named parts. A tunnel
in miniature: a free rock mass holding 8/9 of the model's mass is the host
by mass, with no constraint at all. In 3D the same rule on boxes.

Principal stresses: a block with an in-situ stress of -10 / -2 MPa
(tension positive) at t = 0 has principal values [-2, -10] MPa, the last
named sigma1 (the most compressive) in the state's principal_stress_names
and in the attributes of /snapshots/principal_stress; in 3D [-2, -5, -10]
MPa, sigma3, sigma2, sigma1."""
import json
import math
import os
import subprocess
import sys
import unittest

from fdemd_harness import SLOW, DaemonTestCase, fetched_result

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
from fdemd_client import Client  # noqa: E402

PLOT = os.path.join(ROOT, "clients", "python", "plot_fragments.py")
RHO = 2500.0
MATERIALS = {"rock": {"density": RHO, "young": 1e10, "poisson": 0.25}}


def rectangle(name, origin, size, divisions=(4, 2)):
    return {"name": name, "material": "rock",
            "rectangle": {"origin": list(origin), "size": list(size), "divisions": list(divisions)}}


def rock_fall():
    """slope (1 x 0.1, fixed), block (0.1 x 0.1), boulder (0.2 x 0.1)."""
    return {
        "name": "rock-fall",
        "materials": MATERIALS,
        "parts": [rectangle("slope", (0, 0), (1.0, 0.1), (10, 2)),
                  rectangle("block", (0.2, 0.2), (0.1, 0.1)),
                  rectangle("boulder", (0.6, 0.2), (0.2, 0.1))],
        "constraints": [{"part": "slope", "fix": ["x", "y"]}],
        "time": {"end": 1e-5},
    }


def diameter(area):
    return math.sqrt(4 * area / math.pi)


class FragmentSelectionTests(DaemonTestCase):
    PREFIX = "fdemd-fragments-host-"

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.fall = cls.d.create(rock_fall())["id"]

    def fragments(self, case_id, query=""):
        status, body = self.d.json("GET", "/cases/%s/fragments%s" % (case_id, query))
        self.assertEqual(status, 200, body)
        return body

    def check_curve(self, body, points):
        """The sieve curve is `points` [(diameter, passing)] to 1e-12."""
        got = [(p["diameter"], p["passing"]) for p in body["distribution"]]
        self.assertEqual(len(got), len(points), got)
        for (d, p), (want_d, want_p) in zip(got, points):
            self.assertLess(abs(d - want_d), 1e-12 * want_d, (d, want_d))
            self.assertLess(abs(p - want_p), 1e-12, (p, want_p))

    def test_everything_without_a_query(self):
        body = self.fragments(self.fall)
        pieces = body["fragments"]
        self.assertEqual([(f["id"], f["part"], f["held"]) for f in pieces],
                         [(0, 0, True), (1, 1, False), (2, 2, False)])
        for f, area in zip(pieces, (0.1, 0.01, 0.02)):
            self.assertLess(abs(f["mass"] - RHO * area), 1e-9 * RHO * area)
        self.assertNotIn("host", body)
        # the slab is 10 of the 13 parts of mass: the curve a user could not use
        self.check_curve(body, [(diameter(0.01), 1 / 13), (diameter(0.02), 3 / 13),
                                (diameter(0.1), 1.0)])

    def test_exclude_host_leaves_out_the_fixed_slope(self):
        body = self.fragments(self.fall, "?exclude_host=true")
        self.assertEqual([f["id"] for f in body["fragments"]], [1, 2])
        self.assertEqual(body["host"], [0])
        self.check_curve(body, [(diameter(0.01), 1 / 3), (diameter(0.02), 1.0)])
        self.assertEqual(self.fragments(self.fall, "?exclude_host=false"), self.fragments(self.fall))

    def test_parts_keep_the_named_parts(self):
        body = self.fragments(self.fall, "?parts=boulder")
        self.assertEqual([f["id"] for f in body["fragments"]], [2])
        self.check_curve(body, [(diameter(0.02), 1.0)])
        body = self.fragments(self.fall, "?parts=boulder,block&exclude_host=true")
        self.assertEqual([f["id"] for f in body["fragments"]], [1, 2])
        self.assertEqual(body["host"], [])
        body = self.fragments(self.fall, "?parts=slope&exclude_host=1")
        self.assertEqual((body["fragments"], body["distribution"], body["host"]), ([], [], [0]))

    def test_a_mass_holding_most_of_the_model_is_the_host(self):
        case = {"name": "tunnel", "materials": MATERIALS,
                "parts": [rectangle("rock mass", (0, 0), (0.2, 0.1)),
                          rectangle("chip", (0.5, 0), (0.05, 0.05), (2, 2))],
                "time": {"end": 1e-5}}
        case_id = self.d.create(case)["id"]
        body = self.fragments(case_id, "?exclude_host=true")
        self.assertEqual(([f["id"] for f in body["fragments"]], body["host"]), ([1], [0]))
        self.assertFalse(any(f["held"] for f in self.fragments(case_id)["fragments"]))
        self.check_curve(body, [(diameter(0.0025), 1.0)])
        body = self.fragments(case_id, "?parts=rock%20mass")
        self.assertEqual([f["id"] for f in body["fragments"]], [0])

    def test_3d_boxes(self):
        box = lambda name, x, size: {"name": name, "material": "rock",  # noqa: E731
                                     "box": {"origin": [x, 0, 0], "size": size,
                                             "divisions": [2, 1, 1]}}
        case = {"name": "boxes", "dimension": 3, "materials": MATERIALS,
                "parts": [box("base", 0, [0.4, 0.4, 0.1]), box("cube", 1, [0.1, 0.1, 0.1]),
                          box("slab", 2, [0.2, 0.1, 0.1])],
                "constraints": [{"part": "base", "fix": ["x", "y", "z"]}],
                "time": {"end": 1e-5}}
        case_id = self.d.create(case)["id"]
        body = self.fragments(case_id, "?exclude_host=true")
        self.assertEqual(([f["id"] for f in body["fragments"]], body["host"]), ([1, 2], [0]))
        sphere = lambda v: (6 * v / math.pi) ** (1 / 3)  # noqa: E731
        self.check_curve(body, [(sphere(0.001), 1 / 3), (sphere(0.002), 1.0)])

    def test_bad_queries_are_400(self):
        for query, says in (("?parts=slab", 'no part named "slab"; its parts are "slope", '
                                             '"block", "boulder"'),
                            ("?parts=", "comma-separated list of part names"),
                            ("?parts=block,,boulder", "comma-separated list"),
                            ("?exclude_host=maybe", "?exclude_host= takes true or false"),
                            ("?host=true", 'unknown query parameter "host"')):
            status, problem = self.d.json("GET", "/cases/%s/fragments%s" % (self.fall, query))
            self.assertEqual(status, 400, query)
            self.assertIn(says, problem["detail"], query)

    def test_clients(self):
        client = Client("http://127.0.0.1:%d" % self.d.port)
        self.assertEqual(client.fragments(self.fall, parts=["block", "boulder"], exclude_host=True),
                         self.fragments(self.fall, "?parts=block,boulder&exclude_host=true"))
        self.assertEqual(client.fragments(self.fall, parts="boulder"),
                         self.fragments(self.fall, "?parts=boulder"))
        r = self.d.fdemctl("fragments", self.fall, "--exclude-host")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("2 fragments", r.stdout)
        self.assertIn("left out as the host body: 1 fragment (id 0)", r.stdout)
        self.assertIn("33.33 %", r.stdout)
        r = self.d.fdemctl("fragments", self.fall, "--parts", "boulder", "--json")
        self.assertEqual(json.loads(r.stdout), self.fragments(self.fall, "?parts=boulder"))
        r = self.d.fdemctl("fragments", self.fall, "--parts", "slab")
        self.assertEqual(r.returncode, 1)
        self.assertIn('no part named "slab"', r.stderr)

    def test_plot_fragments(self):
        status, _, data = self.d.request("GET", "/cases/%s/result.h5" % self.fall)
        self.assertEqual(status, 200)
        path = os.path.join(self.tmp, "fall.h5")
        with open(path, "wb") as f:
            f.write(data)

        def plot(*args):
            return subprocess.run(["/usr/bin/python3", PLOT] + list(args) +
                                  ["-o", os.path.join(self.tmp, "plot"), "--print"],
                                  capture_output=True, text=True, timeout=120 * SLOW)
        r = plot(path, "--parts", "block,boulder")
        self.assertEqual(r.returncode, 0, r.stderr)
        drawn = json.loads(r.stdout)
        self.assertEqual(drawn["fragments"], 2)
        self.check_curve(drawn, [(diameter(0.01), 1 / 3), (diameter(0.02), 1.0)])
        url = "http://127.0.0.1:%d" % self.d.port
        r = plot("--server", url, "--case", self.fall, "--exclude-host")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(json.loads(r.stdout)["distribution"],
                         self.fragments(self.fall, "?exclude_host=true")["distribution"])
        r = plot(path, "--exclude-host")
        self.assertEqual(r.returncode, 2)
        self.assertIn("needs --server", r.stderr)
        r = plot(path, "--parts", "slab")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("no part named 'slab'", r.stderr)


class PrincipalStressNamesTests(DaemonTestCase):
    PREFIX = "fdemd-principal-names-"

    def stressed_block(self, dimension):
        if dimension == 2:
            part = rectangle("block", (0, 0), (0.1, 0.1))
            value = [-10e6, -2e6, 0]
        else:
            part = {"name": "block", "material": "rock",
                    "box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1], "divisions": [1, 1, 1]}}
            value = [-2e6, -5e6, -10e6, 0, 0, 0]
        part["initial_stress"] = {"value": value}
        case = {"name": "in-situ", "materials": MATERIALS, "parts": [part], "time": {"end": 1e-5},
                "output": {"fields": ["position", "stress", "principal_stress"]}}
        if dimension == 3:
            case["dimension"] = 3
        return self.d.create(case)["id"]

    def check(self, dimension, want, names):
        case_id = self.stressed_block(dimension)
        status, state = self.d.json("GET", "/cases/%s/state?fields=principal_stress" % case_id)
        self.assertEqual(status, 200, state)
        self.assertEqual(state["principal_stress_names"], names)
        for row in state["principal_stress"]:
            for got, value in zip(row, want):
                self.assertLess(abs(got - value), 1e-9 * 10e6, (row, want))
        sigma1 = [row[names.index("sigma1")] for row in state["principal_stress"]]
        self.assertTrue(all(abs(s + 10e6) < 1e-9 * 10e6 for s in sigma1), sigma1)
        with fetched_result(self.d, case_id) as f:
            ds = f["/snapshots/principal_stress"]
            self.assertEqual([n.decode() for n in ds.attrs["rock_mechanics_names"]], names)
            order = ds.attrs["order"]
            self.assertIn("the last column the most compressive, which is sigma1", order)
            self.assertLess(abs(ds[0, 0, -1] + 10e6), 1e-9 * 10e6)

    def test_2d(self):
        self.check(2, [-2e6, -10e6], ["sigma3", "sigma1"])

    def test_3d(self):
        self.check(3, [-2e6, -5e6, -10e6], ["sigma3", "sigma2", "sigma1"])


if __name__ == "__main__":
    unittest.main()
