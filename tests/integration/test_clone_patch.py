"""test_clone_patch.py - clones by JSON Patch (RFC 6902, contract 6.2;
issue 33 item 4) through the daemon, fdemctl and the Python client.

A parametric study: a stored case whose part embeds its mesh (nodes and
triangles, 30 times the size of the patch) is cloned with a patch that
changes only /parts/0/material and the value of one constraint. The clone
stores exactly the source document with those two changes, and runs with
them: its stable step is the source's times sqrt(E_source / E_clone)
(dt ~ h / c, c ~ sqrt(E / rho), the only change), and its top edge,
driven at the patched velocity, has moved v * t at the end. A failing
operation (a `test` included) is one 422 at the operation's index and
creates nothing; a dry run answers what the clone would be and creates
nothing either."""
import json
import math
import os
import sys
import unittest

from fdemd_harness import DaemonTestCase

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
from fdemd_client import Client, FdemdError  # noqa: E402

JSON_PATCH = {"Content-Type": "application/json-patch+json"}
SOFT, STIFF = 1e9, 4e9
WIDTH, HEIGHT, NX, NY = 0.1, 0.05, 20, 10
END = 2e-4


def grid_mesh():
    """An explicit mesh (nodes, triangles) of the WIDTH x HEIGHT block."""
    nodes = [[WIDTH * i / NX, HEIGHT * j / NY] for j in range(NY + 1) for i in range(NX + 1)]
    triangles = []
    for j in range(NY):
        for i in range(NX):
            a = j * (NX + 1) + i
            b, c, d = a + 1, a + NX + 1, a + NX + 2
            triangles += [[a, b, d], [a, d, c]]
    return {"nodes": nodes, "triangles": triangles}


def study_case(name="study"):
    """A block with its mesh in the document, fixed at the base, its top
    edge pushed down at 0.1 m/s."""
    top = [-1, HEIGHT - 1e-6, 1, HEIGHT + 1e-6]
    return {
        "name": name,
        "materials": {"soft": {"density": 2500, "young": SOFT, "poisson": 0.25},
                      "stiff": {"density": 2500, "young": STIFF, "poisson": 0.25}},
        "parts": [{"name": "sample", "material": "soft", "mesh": grid_mesh()}],
        "constraints": [{"box": [-1, -1e-6, 1, 1e-6], "fix": ["x", "y"]},
                        {"box": top, "velocity": [0, -0.1]}],
        "time": {"end": END},
        "output": {"interval": END / 4, "fields": ["position", "displacement"]},
    }


STUDY_PATCH = [
    {"op": "test", "path": "/parts/0/material", "value": "soft"},
    {"op": "replace", "path": "/parts/0/material", "value": "stiff"},
    {"op": "replace", "path": "/constraints/1/velocity/1", "value": -0.2},
]


def patched_by_hand(case):
    want = json.loads(json.dumps(case))
    want["parts"][0]["material"] = "stiff"
    want["constraints"][1]["velocity"][1] = -0.2
    return want


class JsonPatchCloneTests(DaemonTestCase):
    PREFIX = "fdemd-clone-patch-"

    def case_count(self):
        return len(self.d.json("GET", "/cases")[1]["cases"])

    def clone(self, source, patch, query="", headers=JSON_PATCH):
        body = patch if isinstance(patch, bytes) else json.dumps(patch).encode()
        return self.d.json("POST", "/cases/%s/clone%s" % (source, query), body, headers=headers)

    def top_displacement(self, case_id):
        """Mean y displacement of the top edge's nodes now."""
        status, state = self.d.json("GET", "/cases/%s/state?fields=position,displacement" % case_id)
        self.assertEqual(status, 200, state)
        top = [u[1] for x, u in zip(state["position"], state["displacement"])
               if abs(x[1] - u[1] - HEIGHT) < 1e-9]
        self.assertEqual(len(top), NX + 1)
        return sum(top) / len(top), state["time"]

    def test_a_parametric_study_changes_one_part_and_one_constraint(self):
        d = self.d
        case = study_case()
        source = d.create(case)["id"]
        patch_size = len(json.dumps(STUDY_PATCH))
        self.assertGreater(len(json.dumps(case)), 30 * patch_size, "the mesh is not resent")
        status, st = self.clone(source, STUDY_PATCH, "?start=true")
        self.assertEqual(status, 201, st)
        want = patched_by_hand(case)
        self.assertEqual(d.json("GET", "/cases/%s/case" % st["id"])[1], want)
        self.assertEqual(d.json("GET", "/cases/%s/case" % source)[1], case, "source untouched")
        # The material: dt ~ h sqrt(rho / E), nothing else changed.
        ratio = st["dt"] / d.status(source)["dt"]
        self.assertLess(abs(ratio - math.sqrt(SOFT / STIFF)), 1e-12 * ratio, ratio)
        # The constraint: the top edge moved v t at the patched v.
        d.wait_state(st["id"], "finished", timeout=60)
        uy, t = self.top_displacement(st["id"])
        self.assertEqual(t, END)
        self.assertLess(abs(uy - (-0.2 * END)), 1e-9 * 0.2 * END, uy)

    def test_a_dry_run_answers_what_the_clone_would_be_and_creates_nothing(self):
        d = self.d
        source = d.create(study_case("dry"))["id"]
        count = self.case_count()
        status, source_sizing = d.json("POST", "/cases?dry_run=true", study_case("dry"))
        self.assertEqual(status, 200, source_sizing)
        status, sizing = self.clone(source, STUDY_PATCH, "?dry_run=true")
        self.assertEqual(status, 200, sizing)
        self.assertEqual((sizing["nodes"], sizing["elements"]), ((NX + 1) * (NY + 1), 2 * NX * NY))
        ratio = sizing["dt"] / source_sizing["dt"]
        self.assertLess(abs(ratio - 0.5), 1e-12, ratio)
        self.assertEqual(sizing["steps"], math.ceil(END / sizing["dt"] - 1e-9))
        # invalid once patched: the same 422 as the clone would get
        status, problem = self.clone(source, [{"op": "replace", "path": "/parts/0/material",
                                               "value": "granit"}], "?dry_run=true")
        self.assertEqual(status, 422, problem)
        self.assertIn("/parts/0/material", [e["pointer"] for e in problem["errors"]])
        self.assertEqual(self.case_count(), count)

    def test_a_failing_operation_is_422_at_its_index_and_creates_nothing(self):
        d = self.d
        source = d.create(study_case("fails"))["id"]
        count = self.case_count()
        failing = [
            # a test that does not hold, after operations that succeeded
            (STUDY_PATCH + [{"op": "test", "path": "/parts/0/material", "value": "soft"}],
             "/3", 'test failed, so the patch changed nothing: /parts/0/material is "stiff", '
                   'not "soft"'),
            ([{"op": "remove", "path": "/constraints/0"}, {"op": "remove", "path": "/parts/7"}],
             "/1", "remove failed, so the patch changed nothing: path /parts/7 does not exist "
                   "(/parts has 1 element)"),
            ([{"op": "add", "path": "/output/fields/9", "value": "stress"}],
             "/0", '"9" is not a place in the array /output/fields: it has 2 elements'),
            ([{"op": "delete", "path": "/name"}], "/0/op", 'unknown op "delete"'),
            ([{"op": "replace", "path": "name", "value": "x"}], "/0/path",
             "must be \"\" (the whole document) or start with \"/\""),
            ({"name": "not an array"}, "", "an array of operations"),
        ]
        for patch, pointer, message in failing:
            status, problem = self.clone(source, patch, "?start=true")
            self.assertEqual(status, 422, problem)
            self.assertEqual(problem["title"], "Invalid patch")
            self.assertEqual([e["pointer"] for e in problem["errors"]], [pointer], problem)
            self.assertIn(message, problem["errors"][0]["message"])
        # every malformed operation at once
        status, problem = self.clone(source, [{"op": "copy", "path": "/a"}, {"path": "/b"}])
        self.assertEqual([e["pointer"] for e in problem["errors"]], ["/0/from", "/1/op"], problem)
        # the patched document is checked as any submitted one
        status, problem = self.clone(source, [{"op": "replace", "path": "/time/end", "value": -1}])
        self.assertEqual(status, 422, problem)
        self.assertEqual([e["pointer"] for e in problem["errors"]], ["/time/end"])
        self.assertEqual(d.json("POST", "/cases/%s/clone" % source, b"[{]",
                                headers=JSON_PATCH)[0], 400)
        self.assertEqual(self.case_count(), count)
        self.assertEqual(self.clone("0123456789abcdef", [])[0], 404)

    def test_the_content_type_decides_and_merge_patch_stays_the_default(self):
        d = self.d
        case = study_case("types")
        source = d.create(case)["id"]
        for content_type in ("application/json-patch+json; charset=utf-8",
                             "Application/JSON-Patch+JSON"):
            status, st = self.clone(source, STUDY_PATCH, headers={"Content-Type": content_type})
            self.assertEqual(status, 201, st)
            self.assertEqual(d.json("GET", "/cases/%s/case" % st["id"])[1], patched_by_hand(case))
        status, st = self.clone(source, [], headers=JSON_PATCH)
        self.assertEqual((status, st["name"]), (201, "types"))
        # application/json, none, or curl's form type: a merge patch
        for headers in ({}, {"Content-Type": "application/json"},
                        {"Content-Type": "application/x-www-form-urlencoded"},
                        {"Content-Type": "application/merge-patch+json"}):
            status, st = self.clone(source, {"name": "merged"}, headers=headers)
            self.assertEqual((status, st["name"]), (201, "merged"))
        status, problem = self.clone(source, STUDY_PATCH, headers={"Content-Type": "application/json"})
        self.assertEqual(status, 422, problem)
        self.assertIn("application/json-patch+json", problem["errors"][0]["message"])


class ExamplePatchTests(DaemonTestCase):
    PREFIX = "fdemd-clone-example-"

    def test_the_example_patch_of_the_uniaxial_specimen(self):
        """examples/uniaxial-compression.weaker.json-patch: a weaker rock
        (cohesion halved, a copy of "rock") and platens at half the speed,
        without resending the 70 KB gmsh text."""
        with open(os.path.join(ROOT, "examples", "uniaxial-compression.json")) as f:
            case = json.load(f)
        with open(os.path.join(ROOT, "examples", "uniaxial-compression.weaker.json-patch")) as f:
            patch = json.load(f)
        source = self.d.create(case)["id"]
        client = Client("http://127.0.0.1:%d" % self.d.port)
        sizing = client.clone(source, patch, dry_run=True)
        self.assertEqual(sizing["elements"], self.d.status(source)["elements"])
        new_id = client.clone(source, patch)
        want = json.loads(json.dumps(case))
        want["name"] = "uniaxial-compression-weaker"
        want["materials"]["weaker"] = dict(case["materials"]["rock"])
        want["materials"]["weaker"]["fracture"] = dict(case["materials"]["rock"]["fracture"],
                                                       cohesion=1.5e6)
        want["parts"][0]["material"] = "weaker"
        want["constraints"][0]["velocity"][1] = -0.025
        want["constraints"][1]["velocity"][1] = 0.025
        self.assertEqual(client.case(new_id), want)
        self.assertEqual(client.case(source), case)
        self.assertGreater(len(json.dumps(case)), 100 * len(json.dumps(patch)))


class JsonPatchClientTests(DaemonTestCase):
    PREFIX = "fdemd-clone-patch-clients-"

    def ctl(self, *args, stdin=None):
        return self.d.fdemctl(*args, stdin=stdin, cwd=self.tmp)

    def test_python_client(self):
        client = Client("http://127.0.0.1:%d" % self.d.port)
        case = study_case("py")
        source = client.submit(case)
        count = len(client.list())
        sizing = client.clone(source, STUDY_PATCH, dry_run=True)
        self.assertLess(abs(sizing["dt"] / client.status(source)["dt"] - 0.5), 1e-12)
        self.assertEqual(len(client.list()), count)
        with self.assertRaises(FdemdError) as raised:
            client.clone(source, STUDY_PATCH + [{"op": "test", "path": "/name", "value": "x"}])
        self.assertEqual(raised.exception.status, 422)
        self.assertEqual(raised.exception.errors[0]["pointer"], "/3")
        with self.assertRaises(FdemdError) as raised:
            client.clone(source, [{"op": "replace", "path": "/time/end", "value": "late"}],
                         dry_run=True)
        self.assertEqual(raised.exception.errors[0]["pointer"], "/time/end")
        self.assertEqual(len(client.list()), count)
        new_id = client.clone(source, STUDY_PATCH)
        self.assertEqual(client.case(new_id), patched_by_hand(case))
        path = os.path.join(self.tmp, "study.json-patch")
        with open(path, "w") as f:
            f.write("\n  " + json.dumps(STUDY_PATCH))
        self.assertEqual(client.case(client.clone(source, path)), patched_by_hand(case))
        self.assertEqual(client.case(client.clone(source, {"name": "merge"}))["name"], "merge")
        with self.assertRaises(ValueError):
            client.clone(source, [], start=True, dry_run=True)

    def test_fdemctl(self):
        case = study_case("ctl")
        source = self.d.create(case)["id"]
        path = os.path.join(self.tmp, "patch.json")
        with open(path, "w") as f:
            json.dump(STUDY_PATCH, f)
        count = len(self.d.json("GET", "/cases")[1]["cases"])
        r = self.ctl("clone", source, path, "--dry-run")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("231 nodes, 400 elements", r.stdout)
        self.assertIn("estimated time", r.stdout)
        self.assertEqual(len(self.d.json("GET", "/cases")[1]["cases"]), count)
        r = self.ctl("clone", source, path)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.d.json("GET", "/cases/%s/case" % r.stdout.strip())[1],
                         patched_by_hand(case))
        r = self.ctl("clone", source, "-",
                     stdin=' [{"op": "test", "path": "/parts/0/material", "value": "stiff"}]')
        self.assertEqual(r.returncode, 1)
        self.assertIn('/0: test failed, so the patch changed nothing: /parts/0/material is "soft"',
                      r.stderr)
        r = self.ctl("clone", source, "-", stdin='{"name": "merged"}')
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.d.status(r.stdout.strip())["name"], "merged")
        self.assertEqual(self.ctl("clone", source, path, "--dry-run", "--start").returncode, 2)
        self.assertEqual(len(self.d.json("GET", "/cases")[1]["cases"]), count + 2)


if __name__ == "__main__":
    unittest.main()
