"""Fracture in a region (contract 6.1) through the daemon: a part's
"fracture" as a box selector, a gmsh group or a list of them, in 2D and 3D.
The dry run's joint count is the brute-force count of interior edges
(faces) whose two element centroids lie in the region; a pulled bar that
may fracture only in its middle runs to the end, breaks only there, and
its result file has the region's joints; a region holding every element
is the whole fracturing part; bad regions are one 422 naming each problem
at its pointer."""
import copy
import json
import os

import h5py

from fdemd_harness import DaemonTestCase

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")
FRACTURE = {"tensile_strength": 1e6, "cohesion": 3e6, "friction_angle": 30,
            "energy_I": 10, "energy_II": 50}
ROCK = {"density": 2700, "young": 3e10, "poisson": 0.25, "damping": 0.1, "friction": 0.3,
        "fracture": FRACTURE}


def read(path):
    with open(os.path.join(ROOT, path)) as f:
        return f.read()


def bar_case(fracture, end=2e-3):
    """A 2 m x 0.2 m bar of 20 x 2 cells, its left end fixed, its right end
    pulled at 2 m/s."""
    return {
        "name": "region-bar",
        "materials": {"rock": dict(ROCK)},
        "parts": [{"name": "bar", "material": "rock", "fracture": fracture,
                   "rectangle": {"origin": [0, 0], "size": [2, 0.2], "divisions": [20, 2]}}],
        "constraints": [{"box": [-1, -1, 1e-9, 1], "fix": ["x", "y"]},
                        {"box": [2 - 1e-9, -1, 3, 1], "velocity": [2, None]}],
        "time": {"end": end},
        "output": {"interval": end / 4, "fields": ["position", "damage"]},
    }


def rectangle_mesh(nx, ny, w, h):
    """fdem_mesh_rectangle's triangles (alternating diagonals) as nodes and
    triangles, for the brute-force counts."""
    nodes = [[w * i / nx, h * j / ny] for j in range(ny + 1) for i in range(nx + 1)]
    tris = []
    for j in range(ny):
        for i in range(nx):
            a, b = j * (nx + 1) + i, j * (nx + 1) + i + 1
            c, d = a + nx + 1, b + nx + 1
            if (i + j) % 2 == 0:
                tris += [[a, b, d], [a, d, c]]
            else:
                tris += [[a, b, c], [b, d, c]]
    return nodes, tris


def region_joints(nodes, elems, inside):
    """Interior faces (edges) whose two elements are both inside."""
    faces = {}
    for e, el in enumerate(elems):
        for off in range(len(el)):
            key = tuple(sorted(v for k, v in enumerate(el) if k != off))
            faces.setdefault(key, []).append(e)
    return sum(1 for pair in faces.values() if len(pair) == 2 and all(inside[e] for e in pair))


def centroids_in(nodes, elems, box):
    dim = len(nodes[0])
    out = []
    for el in elems:
        c = [sum(nodes[v][d] for v in el) / len(el) for d in range(dim)]
        out.append(all(box[d] <= c[d] <= box[dim + d] for d in range(dim)))
    return out


class FractureRegionTest(DaemonTestCase):
    PREFIX = "fdemd-region-"

    def dry(self, case):
        status, body = self.d.json("POST", "/cases?dry_run=true", case)
        self.assertEqual(status, 200, body)
        return body

    def problems(self, case):
        status, body = self.d.json("POST", "/cases", case)
        self.assertEqual(status, 422, body)
        return {e["pointer"]: e["message"] for e in body["errors"]}

    def test_box_region_counts_its_joints(self):
        nodes, tris = rectangle_mesh(8, 6, 8.0, 6.0)
        box = [2, 1.5, 6, 4.5]
        case = bar_case({"box": box})
        case["parts"][0]["rectangle"] = {"origin": [0, 0], "size": [8, 6], "divisions": [8, 6]}
        case["constraints"] = []
        want = region_joints(nodes, tris, centroids_in(nodes, tris, box))
        whole = copy.deepcopy(case)
        whole["parts"][0]["fracture"] = True
        plain = copy.deepcopy(case)
        plain["parts"][0]["fracture"] = False
        got, all_joints, none = self.dry(case), self.dry(whole), self.dry(plain)
        self.assertEqual(got["joints"], want)
        self.assertGreater(want, 0)
        self.assertLess(got["joints"], all_joints["joints"])
        self.assertLess(none["nodes"], got["nodes"])
        self.assertLess(got["nodes"], all_joints["nodes"])
        # a list whose union is every element is the whole part
        every = copy.deepcopy(case)
        every["parts"][0]["fracture"] = [{"box": [-1, -1, 4, 7]}, {"box": [4, -1, 9, 7]}]
        self.assertEqual(self.dry(every)["joints"], all_joints["joints"])
        self.assertEqual(self.dry(every)["nodes"], all_joints["nodes"])

    def test_3d_box_region(self):
        case = {
            "name": "region-3d", "dimension": 3,
            "materials": {"rock": dict(ROCK)},
            "parts": [{"name": "block", "material": "rock",
                       "fracture": {"box": [0.25, -1, -1, 0.75, 1, 1]},
                       "box": {"origin": [0, 0, 0], "size": [1, 0.5, 0.5],
                               "divisions": [4, 2, 2]}}],
            "time": {"end": 1e-4},
        }
        whole = copy.deepcopy(case)
        whole["parts"][0]["fracture"] = True
        got, all_joints = self.dry(case), self.dry(whole)
        self.assertGreater(got["joints"], 0)
        self.assertLess(got["joints"], all_joints["joints"])
        self.assertLess(got["nodes"], all_joints["nodes"])

    def test_gmsh_group_region(self):
        case = bar_case({"group": "stiff"})
        del case["parts"][0]["rectangle"]
        case["parts"][0]["gmsh"] = read("tests/data/bar_groups_v41.msh")
        case["constraints"] = []
        whole = copy.deepcopy(case)
        whole["parts"][0]["fracture"] = True
        got, all_joints = self.dry(case), self.dry(whole)
        self.assertGreater(got["joints"], 0)
        self.assertLess(got["joints"], all_joints["joints"])

    def test_group_materials_outside_the_region_need_no_fracture(self):
        case = bar_case({"group": "stiff"})
        del case["parts"][0]["rectangle"]
        case["parts"][0]["gmsh"] = read("tests/data/bar_groups_v41.msh")
        case["parts"][0]["materials"] = {"soft": "plain"}
        case["materials"]["plain"] = {"density": 2000, "young": 1e9, "poisson": 0.2}
        case["constraints"] = []
        self.assertGreater(self.dry(case)["joints"], 0)
        case["parts"][0]["fracture"] = {"group": "soft"}
        p = self.problems(case)
        self.assertTrue(any("fracture region" in m for m in p.values()), p)

    def test_pulled_bar_breaks_inside_its_region(self):
        box = [0.8, -1, 1.2, 1]
        st, path = self.run_case(bar_case({"box": box}))
        self.assertGreater(st["joints"], 0)
        with h5py.File(path, "r") as f:
            joints = f["/mesh/joints"][...]
            damage = f["/snapshots/damage"][-1]
            x0 = f["/mesh/position0"][...]
        self.assertEqual(len(joints), st["joints"])
        self.assertTrue((damage >= 1).any(), "the bar should have broken")
        # every joint node (so every crack) lies in the region's x range
        xs = x0[joints.reshape(-1), 0]
        self.assertGreaterEqual(xs.min(), 0.8 - 1e-9)
        self.assertLessEqual(xs.max(), 1.2 + 1e-9)
        self.assertGreaterEqual(st["fragments"], 2)

    def test_bad_regions_are_one_answer(self):
        outside = [[0, 0], [1, 0], [0, 1], [1, 1]]
        case = {
            "name": "bad-regions",
            "materials": {"rock": dict(ROCK),
                          "plain": {"density": 2700, "young": 3e10, "poisson": 0.25}},
            "parts": [
                {"name": "bar", "material": "rock", "fracture": [{"box": [0, 0, 1, 1]},
                                                                 {"group": "no such"}],
                 "gmsh": read("tests/data/bar_groups_v41.msh")},
                {"name": "far", "material": "rock", "fracture": {"box": [5, 5, 6, 6]},
                 "mesh": {"nodes": [[x + 10, y] for x, y in outside],
                          "triangles": [[0, 1, 2], [1, 3, 2]]}},
                {"name": "unbreakable", "material": "plain", "fracture": {"box": [0, 0, 1, 1]},
                 "rectangle": {"origin": [20, 0], "size": [1, 1], "divisions": [2, 2]}},
                {"name": "typo", "material": "rock", "fracture": {"boxx": [0, 0, 1, 1]},
                 "rectangle": {"origin": [30, 0], "size": [1, 1], "divisions": [2, 2]}},
                {"name": "empty", "material": "rock", "fracture": [],
                 "rectangle": {"origin": [40, 0], "size": [1, 1], "divisions": [2, 2]}},
                {"name": "no groups", "material": "rock", "fracture": {"group": "x"},
                 "rectangle": {"origin": [50, 0], "size": [1, 1], "divisions": [2, 2]}},
            ],
            "time": {"end": 1e-4},
        }
        p = self.problems(case)
        self.assertIn("/parts/0/fracture/1", p)
        self.assertIn("no such", p["/parts/0/fracture/1"])
        self.assertIn("/parts/1/fracture", p)
        self.assertIn("outside the part", p["/parts/1/fracture"])
        self.assertIn("/parts/2/fracture", p)
        self.assertIn("fracture", p["/parts/2/fracture"])
        self.assertIn("/parts/3/fracture/boxx", p)  # the unknown key itself
        self.assertIn("/parts/4/fracture", p)
        self.assertIn("/parts/5/fracture", p)
        self.assertIn("gmsh", p["/parts/5/fracture"])
        self.assertEqual(len(p), 6, json.dumps(p, indent=1))

    def test_generated_shape_region_outside(self):
        case = bar_case({"box": [5, 5, 6, 6]})
        p = self.problems(case)
        self.assertEqual(list(p), ["/parts/0/fracture"])
        self.assertIn("outside the part", p["/parts/0/fracture"])
        listed = bar_case([{"box": [0, 0, 1, 1]}, {"box": [5, 5, 6, 6]}])
        self.assertEqual(list(self.problems(listed)), ["/parts/0/fracture/1"])


if __name__ == "__main__":
    import unittest
    unittest.main()
